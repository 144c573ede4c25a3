"""Roughness design study (thesis Chapter 4): macro/micro roughness of the Table 1 case,
the 60-genome Sobol database and its genetic map, SOG/GCO/CCO for y_t1 and y_t2,
M-CCO for (y_t1, y_t3), the sensitivity to pbar, and reproducibility of every score.

Run: ``roughfe validate design`` (or ``make validate``); writes ``<outdir>/design_study.md``,
figures and per-run result folders in ``<outdir>/design/``.

Targets (issue 7): s >= 0.98 for y_t1 with at least one method, f >= 0.9 for the
multi-target case, and every reported score equal (1e-6) to the score of an independent
BEM run of the saved design.
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from roughfe.genomics import database as db
from roughfe.genomics import design as de
from roughfe.genomics.target_csv import write_target_csv
from roughfe.plotting import design as dplot
from roughfe.study import build_genome_db
from roughfe.validation import Target, report_title, reported, targets_markdown
from roughfe.writers import write_json, write_text

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _design_checks import run_design_checked, strict_error  # noqa: E402
from _design_global import YT1_GLOBAL, spread_note  # noqa: E402
from _design_multi import (GLOBAL_EVAL, GLOBAL_MIN, GLOBAL_ROUNDS,  # noqa: E402
                           GLOBAL_SEED, GLOBAL_SIGMA, multi_target)
from _design_single import single_target_t1, single_target_t2, table1_macro_micro  # noqa: E402

GOALS = {"s_yt1": 0.98, "f_multi": 0.9, "reproducible": 1e-6}
PBAR_T1 = 0.8 / 1.6                      # thesis pbar = 0.8e-4 of p_max^t ~ 1.6e-4
PBAR_SWEEP = np.linspace(0.5, 1.1, 7) / 1.6


def quick_case(outdir: Path) -> bool:
    """``make validate-quick``: one design stage. A 6-genome database (128 nodes, 12 loads),
    SOG for y_t1 with one GCMMA iteration per stage, then the search at the target
    pressures (2 starts x 8 sweeps) and the global search (60 evaluations). Targets: the
    reported scores (interpolated and strict) equal independent BEM runs of the saved
    design (1e-6). Each stage's gain over the best start is reported, not a target: a
    stage keeps its start when it does not improve, so the gain is >= 0 by construction."""
    out = outdir / "design_quick"
    out.mkdir(parents=True, exist_ok=True)
    settings = db.DatabaseSettings(n_nodes=128, n_steps=12)
    path = out / "genomes.sqlite"
    build_genome_db(path, settings, limit=6, workers=1, progress=False)
    entries = db.load_entries(path)
    t1 = de.thesis_targets(settings)[0]
    fast = de.GcmmaOptions(n_it_sog=1, n_it_cross=1, n_it_micro=1, n_micro=2)
    r, err = run_design_checked("yt1_sog", "sog", entries, [t1], settings, out, fast, PBAR_T1 * t1.p_max)
    start = max(c.stages[0] for c in r.candidates)          # best score at GCMMA 0
    gain = de.combined_score(r.best.scores) - start
    # the search at the target pressures (beyond the thesis), a 2-start run of 8 sweeps
    strict0 = max(de.combined_score(de.rescore_at_target_pressures(c.design, [t1], settings))
                  for c in r.candidates)
    rs = de.search_at_target_pressures(r, settings, n_eval=8, starts=2)
    de.write_design_result(rs, settings, out / "yt1_sog_search")
    strict = de.combined_score(rs.best.at_targets)
    err_strict = strict_error(rs, [t1], settings, out / "yt1_sog_search")
    # the global stage (beyond the thesis): IPOP-CMA-ES on the batched strict score
    rg = de.search_global(r, settings, n_eval=60, seed=0)
    de.write_design_result(rg, settings, out / "yt1_sog_global")
    strict_g = de.combined_score(rg.best.at_targets)
    err_strict = max(err_strict, strict_error(rg, [t1], settings, out / "yt1_sog_global"))
    # the stages keep their start when they do not improve (algorithms.py, search.py):
    # their gains are >= 0 by construction, reported beside the two real targets
    monotone = "a stage keeps its start when it does not improve, so >= 0 by construction"
    rows = [Target("SOG stage for y_t1 (quick): score after GCMMA >= best start", ">= 0",
                   f"{gain:+.4f}", bool(gain >= 0), f"6-genome database, s = "
                   f"{de.combined_score(r.best.scores):.4f}", gain),
            Target("reported score = independent BEM run of the saved design", "<= 1e-6",
                   f"{err:.1e}", bool(err <= GOALS["reproducible"]), "", err),
            Target("search at p_t (quick, 2 x 8 sweeps): strict s >= best start", ">= 0",
                   f"{strict - strict0:+.4f}", bool(strict >= strict0),
                   f"strict s = {strict:.4f}", strict - strict0),
            Target("global search at p_t (quick, IPOP-CMA-ES, 60 evaluations): strict s >= "
                   "best start", ">= 0", f"{strict_g - strict0:+.4f}", bool(strict_g >= strict0),
                   f"strict s = {strict_g:.4f}", strict_g - strict0),
            Target("strict score = independent load-controlled BEM run of the saved design",
                   "<= 1e-6", f"{err_strict:.1e}", bool(err_strict <= GOALS["reproducible"]),
                   "design.json reloaded, bem.contact_sweep at the target pressures",
                   err_strict)]
    rows = [reported(t, monotone) if ">= best start" in t.name else t for t in rows]
    write_json(outdir / "design_study.json", {"name": "design_study", "quick": True,
                                              "targets": [t.to_dict() for t in rows]})
    write_text(outdir / "design_study.md", report_title(
        "Roughness design", True, "one design stage on a 6-genome database (128 nodes, 12 "
        "loads): SOG for y_t1 with one GCMMA iteration per stage, the search at the target "
        "pressures (2 starts x 8 sweeps) and the global search (60 evaluations)") + "\n"
        + targets_markdown(rows))
    return all(t.met for t in rows if t.met is not None)


def main(outdir: Path, quick: bool = False) -> bool:
    outdir = Path(outdir)
    if quick:
        return quick_case(outdir)
    out = outdir / "design"
    out.mkdir(parents=True, exist_ok=True)
    lines = ["# Roughness design study (thesis Chapter 4)", "",
             "Machine note: 2 cores shared with other jobs; times are wall-clock and inflated.", ""]
    t_start = time.perf_counter()
    print("== Table 1 macro/micro", flush=True)
    table1_macro_micro(out, lines)

    print("== database", flush=True)
    settings = db.DatabaseSettings()
    path = out / "genomes.sqlite"
    t0 = time.perf_counter()
    n_new = build_genome_db(path, settings, workers=2, progress=False).n_inserted
    t_db = time.perf_counter() - t0
    entries = db.load_entries(path)
    rows = db.summary_table(path)
    dplot.plot_genetic_map(rows, out / "genetic_map.png")
    dplot.plot_map_summary(rows, out / "genetic_map_summary.png")
    macro_share = [np.mean([n in r["macro"] for r in rows]) for n in range(1, 11)]
    lines += ["## Genome database and genetic map (Sec. 4.1.2, Figs. 53-55)", "",
              f"{len(entries)} genomes (Sobol design {db.SobolDesign().to_dict()}), L = N-node "
              f"settings {settings.to_dict()}; built {n_new} now in {t_db:.0f} s (2 workers).", "",
              "Share of genomes in which chromosome n is macro-scale, n = 1..10: " +
              ", ".join(f"{s:.2f}" for s in macro_share), "",
              "![](design/genetic_map.png)", "", "![](design/genetic_map_summary.png)", ""]

    t1, t2, t3, _ = de.thesis_targets(settings)
    for t in (t1, t2, t3):
        write_target_csv(out / f"{t.name}.csv", t)
    dplot.plot_database_curves(entries, [t1, t2], out / "database_K_targets.png")
    dplot.plot_database_curves(entries, [t1, t3], out / "database_KA_targets.png")
    g1 = de.Y_T1_GENES
    lines += ["## Targets (Sec. 4.3)", "",
              f"* y_t1 = K(p) of the genome gamma = {g1['gamma']}, H = {g1['H']}, A = 1, M = 1, "
              f"phases `default_rng({g1['phase_seed']}).uniform(0, 2 pi)` (not in the database); "
              f"p_max^t = {t1.p_max:.4g} Pa.",
              f"* y_t2: K linear from y_t1(p_1) to y_t1(pbar) at pbar = {t2.metadata['pbar']:.4g} Pa "
              f"(= 0.53/1.6 p_max^t: the thesis' 0.53e-4 of p_max ~ 1.6e-4 read off Figs. 57-59), "
              "then flat.",
              "* y_t3 = A(p) of the y_t1 genome (the multi-target pair is attainable).",
              "", "![](design/database_K_targets.png)", ""]

    opts = de.GcmmaOptions()
    reproducible = []
    single = single_target_t1(entries, t1, settings, out, opts, PBAR_T1 * t1.p_max, lines,
                              reproducible, GOALS["s_yt1"])
    thesis_t1, best_t1, free = (single[k] for k in ("thesis_t1", "best_t1", "free"))
    single_target_t2(entries, t2, settings, out, opts, lines, reproducible)
    multi = multi_target(entries, t1, t3, settings, out, opts, lines, reproducible,
                         GOALS["f_multi"])
    best_f, best_f_thesis, best_f_strict, f_both, t_a, nb = (
        multi[k] for k in ("best_f", "best_f_thesis", "best_f_strict", "f_both", "t_a", "nb"))
    rg, rgm, hist, hist_min, cpu_global, cpu_min, msp = (
        multi[k] for k in ("rg", "rgm", "hist", "hist_min", "cpu_global", "cpu_min", "spread"))

    print("== pbar sensitivity", flush=True)
    best = {"gco": [], "cco": []}
    n_cross = {"gco": [], "cco": []}
    n_above = {"gco": [], "cco": []}
    pbars = PBAR_SWEEP * t1.p_max
    for pb in pbars:
        for m, fn in (("gco", de.gco), ("cco", de.cco)):
            r = fn(entries, t1, pb, settings, options=opts)
            best[m].append(de.combined_score(r.best.scores))
            n_cross[m].append(r.n_cross)
            n_above[m].append(r.n_cross_above)
        print(f"  pbar {pb:.4g}: GCO {best['gco'][-1]:.4f}, CCO {best['cco'][-1]:.4f}", flush=True)
    dplot.plot_pbar_sensitivity(pbars, best, n_cross, n_above, out / "pbar_sensitivity.png")
    lines += ["## Sensitivity to pbar (Fig. 59)", "",
              "| pbar (Pa) | GCO best s | CCO best s | U3 GCO (> 0.95) | U3 CCO (> 0.95) |",
              "|---|---|---|---|---|"]
    lines += [f"| {pb:.4g} | {bg:.4f} | {bc:.4f} | {ng} ({ag}) | {nc} ({ac}) |"
              for pb, bg, bc, ng, ag, nc, ac in zip(pbars, best["gco"], best["cco"],
                                                    n_cross["gco"], n_above["gco"],
                                                    n_cross["cco"], n_above["cco"])]
    lines += ["", "![](design/pbar_sensitivity.png)", ""]

    rep = max(reproducible)
    ok = {"s_yt1": best_t1 >= GOALS["s_yt1"], "f_multi": best_f >= GOALS["f_multi"],
          "f_multi_at_target_pressures": best_f_strict >= GOALS["f_multi"],
          "f_multi_one_design": f_both >= GOALS["f_multi"],
          "reproducible": rep <= GOALS["reproducible"]}
    free_best = {k: max(free["rows"], key=lambda w: w[k]) for k in ("strict", "interpolated")}
    for k in ("strict", "interpolated"):
        ok[f"s_yt1_without_refine_{k}"] = free_best[k][k] >= GOALS["s_yt1"]
    free_detail = "; ".join(f"{w['method'].upper()} {w['strict']:.4f} strict / "
                            f"{w['interpolated']:.4f} interpolated" for w in free["rows"])
    free_cpu = sum(w["cpu_s"] for w in free["rows"])
    sp = free["spread"]
    yt1_note = f"{sp['method'].upper()} with {spread_note(sp, 'strict s')}"
    # the M-CCO rows are seed GLOBAL_SEED's; their spread is reported beside them
    mcco_note = {k: (f"the verdict is CMA-ES seed {GLOBAL_SEED}'s; global stage at "
                     + spread_note(msp, label) + " (reported, not a target)")
                 for k, label in (("f_multi", "best interpolated f"),
                                  ("f_multi_at_target_pressures", "best f at p_t"),
                                  ("f_multi_one_design", "min of the two, round on the min"))}
    noise = {sg: float(np.median(f)) for sg, f in nb["phase_noise"].items()}
    f_strict_reason = ("" if ok["f_multi_at_target_pressures"] else
                       f"A(p) at the first target points is {t_a[0] * settings.n_nodes:.0f} / "
                       f"{t_a[1] * settings.n_nodes:.0f} / {t_a[2] * settings.n_nodes:.0f} contact "
                       "nodes: one node off costs 50 / 20 / 12.5 % of s_A; the best design found "
                       "(search at p_t included) does not match those counts and K together; "
                       "the target genome's own phases moved by sigma = "
                       + ", ".join(f"{sg:g}" for sg in noise) + " rad give median f "
                       + ", ".join(f"{v:.2f}" for v in noise.values())
                       + f"; its genes with random phases at best {max(nb['random_phases']):.2f}; "
                       f"the best database genome alone {max(nb['database_alone']):.2f}")
    lines += ["## Goals", "",
              f"* best s for y_t1 with the thesis stages only (GCMMA 0-2, any variant): "
              f"{thesis_t1:.4f}",
              f"* best s for y_t1 including GCMMA 3 (refined): {best_t1:.4f} (goal >= {GOALS['s_yt1']}): "
              f"{'met' if ok['s_yt1'] else 'NOT met'}",
              f"* best s for y_t1 without GCMMA 3 (thesis stages + global stage, "
              f"{YT1_GLOBAL.n_eval} evaluations per method, {free_cpu:.0f} s CPU in all): solved "
              f"at the target pressures {free_best['strict']['strict']:.4f} "
              f"({free_best['strict']['method'].upper()}), interpolated "
              f"{free_best['interpolated']['interpolated']:.4f} "
              f"({free_best['interpolated']['method'].upper()}) (goal >= {GOALS['s_yt1']}): "
              + ", ".join(f"{k} {'met' if ok[f's_yt1_without_refine_{k}'] else 'NOT met'}"
                          for k in ("strict", "interpolated")) + f" ({free_detail}); "
              f"the verdict is CMA-ES seed {YT1_GLOBAL.seed}'s: {yt1_note}",
              f"* best f for (y_t1, y_t3): {best_f:.4f} (goal >= {GOALS['f_multi']}): "
              f"{'met' if ok['f_multi'] else 'NOT met'}; thesis stages only {best_f_thesis:.4f}; "
              f"the same designs solved at the target pressures: best f {best_f_strict:.4f}; "
              + mcco_note["f_multi"],
              f"* best f for (y_t1, y_t3) solved at the target pressures: {best_f_strict:.4f} "
              f"(goal >= {GOALS['f_multi']}): "
              f"{'met' if ok['f_multi_at_target_pressures'] else 'NOT met: ' + f_strict_reason}"
              f"; {mcco_note['f_multi_at_target_pressures']}",
              f"* one M-CCO design with both: min(f at p_t, interpolated f) = {f_both:.4f} "
              f"(goal >= {GOALS['f_multi']}): {'met' if ok['f_multi_one_design'] else 'NOT met'}"
              f"; {mcco_note['f_multi_one_design']}",
              f"* largest difference between a reported score and an independent BEM run of the "
              f"saved design: {rep:.1e} (goal <= {GOALS['reproducible']:.0e}): "
              f"{'met' if ok['reproducible'] else 'NOT met'}",
              f"* total wall time {time.perf_counter() - t_start:.0f} s", ""]
    write_text(outdir / "design_study.md", "\n".join(lines) + "\n")
    write_json(outdir / "design_study.json",
               {"best_s_yt1": best_t1, "best_s_yt1_thesis_stages": thesis_t1, "best_f_multi": best_f, "best_f_multi_thesis_stages": best_f_thesis,
                "best_f_multi_at_target_pressures": best_f_strict, "max_rescore_error": rep,
                "goals": GOALS, "met": ok, "name": "design_study", "quick": False,
                "targets": [t.to_dict() for t in (
                    Target("y_t1: best s of SOG/GCO/CCO (incl. GCMMA 3)", f">= {GOALS['s_yt1']}",
                           f"{best_t1:.4f}", ok["s_yt1"], f"thesis stages only {thesis_t1:.4f}",
                           best_t1),
                    *(Target(f"y_t1 without GCMMA 3: best {k} s of SOG/GCO/CCO + global stage",
                             f">= {GOALS['s_yt1']}", f"{free_best[k][k]:.4f}",
                             ok[f"s_yt1_without_refine_{k}"],
                             f"{free_detail}; {YT1_GLOBAL.n_eval} evaluations per method, "
                             f"{free_cpu:.0f} s CPU (issue 14 section 2); CMA-ES seed "
                             f"{YT1_GLOBAL.seed}; {yt1_note}", free_best[k][k])
                      for k in ("strict", "interpolated")),
                    Target("(y_t1, y_t3): best M-CCO f", f">= {GOALS['f_multi']}",
                           f"{best_f:.4f}", ok["f_multi"],
                           f"at the target pressures {best_f_strict:.4f}; thesis stages only "
                           f"{best_f_thesis:.4f} (issue 14 section 2); {mcco_note['f_multi']}",
                           best_f),
                    Target("(y_t1, y_t3): best M-CCO f solved at the target pressures",
                           f">= {GOALS['f_multi']}", f"{best_f_strict:.4f}",
                           ok["f_multi_at_target_pressures"], (f_strict_reason or
                           "search at p_t (beyond the thesis) included") + "; "
                           + mcco_note["f_multi_at_target_pressures"], best_f_strict),
                    Target("(y_t1, y_t3): one M-CCO design, min(f at p_t, interpolated f)",
                           f">= {GOALS['f_multi']}", f"{f_both:.4f}", ok["f_multi_one_design"],
                           f"global stage + a round on the min ({GLOBAL_MIN.n_eval} "
                           f"evaluations, {cpu_min:.0f} s CPU); "
                           + mcco_note["f_multi_one_design"], f_both),
                    Target("reported scores = independent BEM runs of the saved designs",
                           f"<= {GOALS['reproducible']:.0e}", f"{rep:.1e}", ok["reproducible"],
                           "", rep))],
                "yt1_seed_spread": {k: v for k, v in sp.items() if k != "lines"},
                "mcco_seed_spread": {k: v for k, v in msp.items() if k != "lines"},
                "yt1_without_refine": {"options": {"n_eval": YT1_GLOBAL.n_eval,
                                                   "sigma": YT1_GLOBAL.sigma,
                                                   "amplitudes": YT1_GLOBAL.amplitudes,
                                                   "seed": YT1_GLOBAL.seed},
                                       "methods": free["rows"]},
                "global_search": {"history": hist.tolist(), "cpu_s": cpu_global,
                                  "n_eval": GLOBAL_EVAL, "sigma": GLOBAL_SIGMA,
                                  "rounds": GLOBAL_ROUNDS, "seed": GLOBAL_SEED,
                                  "message": rg.message},
                "global_search_min": {"history": hist_min.tolist(), "cpu_s": cpu_min,
                                      "n_eval": GLOBAL_MIN.n_eval, "sigma": GLOBAL_MIN.sigma,
                                      "seed": GLOBAL_MIN.seed, "f_min": f_both,
                                      "message": rgm.message},
                "target_neighbourhood": {**nb, "phase_noise": {f"{k:g}": v for k, v in
                                                              nb["phase_noise"].items()}},
                "pbar_sweep": {"pbar": pbars.tolist(), "best": best, "n_cross": n_cross,
                               "n_above": n_above}})
    print(f"best s(y_t1) = {best_t1:.4f}, best f = {best_f:.4f}, rescore error {rep:.1e}")
    return all(ok.values())


if __name__ == "__main__":
    sys.exit(0 if main(Path(sys.argv[1] if len(sys.argv) > 1 else "validation/output")) else 1)
