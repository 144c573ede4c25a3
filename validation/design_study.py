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

import json
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from roughfe.bem import contact_sweep
from roughfe.genomics import database as db
from roughfe.genomics import design as de
from roughfe.genomics.genome import realize, table1_genome
from roughfe.genomics.macro_micro import macro_micro, top_approach
from roughfe.genomics.target_csv import write_target_csv
from roughfe.model import Material
from roughfe.plotting import design as dplot
from roughfe.study import build_genome_db
from roughfe.validation import Target, report_title, reported, targets_markdown
from roughfe.writers import write_json, write_text

GOALS = {"s_yt1": 0.98, "f_multi": 0.9, "reproducible": 1e-6}
PBAR_T1 = 0.8 / 1.6                      # thesis pbar = 0.8e-4 of p_max^t ~ 1.6e-4
PBAR_SWEEP = np.linspace(0.5, 1.1, 7) / 1.6
#: wider M-CCO start pool (beyond the thesis, see ``design.mcco``)
MCCO_POOL = {"pool": 8, "swap": True, "weights": (0.5, 1.0, 2.0)}
#: the stage beyond the thesis that searches on f at the target pressures
#: (``design.search_at_target_pressures``): BEM sweeps per candidate and run, and the
#: independent runs of its multi-start
SEARCH_EVAL = 400
SEARCH_STARTS = 4
#: the global stage (``design.search_global``, IPOP-CMA-ES on the batched strict score):
#: strict evaluations per round for the best thesis-stage candidate, first step (rad),
#: rounds (each IPOP-CMA-ES run from the best design of the round before; measured in
#: docs/theory/06_design.md: one round 0.8938, two rounds 0.90+)
GLOBAL_EVAL = 20000
GLOBAL_SIGMA = 0.5
GLOBAL_ROUNDS = 2
#: one more global round (issue 14 section 2, session 6) from that stage's design, on
#: min(f at p_t, interpolated f) (``score="min"``: the batched strict and interpolated
#: scores of each design, ~1.8 strict evaluations each), so that one design meets the
#: goal under both scorings; measured in docs/theory/06_design.md
GLOBAL_MIN = de.GlobalSearchOptions(n_eval=5000, sigma=GLOBAL_SIGMA, seed=0, score="min")


def strict_scores_from_file(design_json: Path, targets, settings) -> list:
    """Independent check of a strict score: reload the saved ``design.json`` and score it
    with :func:`strict_scores_from_dict`."""
    return strict_scores_from_dict(json.loads(Path(design_json).read_text()), targets, settings)


def strict_scores_from_dict(design_dict: dict, targets, settings) -> list:
    """Independent check of a strict score of a saved design (its JSON object):
    :func:`strict_scores_of_surface` of its realisation."""
    return strict_scores_of_surface(de.Design.from_dict(design_dict).surface(), targets,
                                    settings)


def strict_scores_of_surface(surf, targets, settings) -> list:
    """Independent check of a strict score (Eq. 4.1 at the targets' own pressures) of a
    saved design's heights, profile or surface: solve them with
    :func:`roughfe.bem.contact_sweep` (one approach to the database's last approach for
    p_max -- the peak-valley height of a profile, ``top_fraction`` of full contact of a
    periodic surface, :func:`~roughfe.genomics.macro_micro.top_approach` -- Eq. 4.2
    factor eta, then load control at ``p_t / eta``), A = contact nodes / nodes, K by
    central differences, Eq. (4.1) -- each written out here, not through the design
    package (its :func:`~roughfe.genomics.design.score_at_target_pressures` is what is
    checked; the BEM solver is the same)."""
    mat = Material(settings.youngs_modulus, settings.poisson)
    top = contact_sweep(surf, mat, deltas=(top_approach(surf, settings.kernel,
                                                        settings.top_fraction),),
                        kernel=settings.kernel, compute_stiffness=False)
    eta = targets[0].p_max / top.results[-1].mean_pressure
    p_t = np.unique(np.concatenate([t.pressure for t in targets]))
    sw = contact_sweep(surf, mat, pressures=tuple(p_t / eta), kernel=settings.kernel,
                       compute_stiffness=False)
    solved = np.array([r.mean_pressure for r in sw.results])
    if not np.allclose(solved * eta, p_t, rtol=1e-6):
        raise RuntimeError(f"load control missed the target pressures: {solved * eta} vs "
                           f"{p_t} Pa")
    # K of the surface solved (Eq. 4.2 stretches p by eta and leaves K = dp/dDelta as it
    # is: heights x eta give p x eta at Delta x eta); it was differenced on p x eta, K x
    # eta, unseen while the designs checked had eta = 1 to round-off (Eq. 4.2-rescaled)
    dl = np.array([r.delta for r in sw.results])
    k = np.empty_like(solved)
    k[1:-1] = (solved[2:] - solved[:-2]) / (dl[2:] - dl[:-2])
    k[0] = (solved[1] - solved[0]) / (dl[1] - dl[0])
    k[-1] = (solved[-1] - solved[-2]) / (dl[-1] - dl[-2])
    a = np.array([np.count_nonzero(r.contact) for r in sw.results]) / surf.heights.size
    out = []
    for t in targets:
        y = np.interp(t.pressure, p_t, k if t.quantity == "K" else a)   # t's own pressures
        out.append(1.0 - float(np.max(np.abs((t.values - y) / t.values))))
    return out


def _strict_error(result, targets, settings, folder: Path) -> float:
    """Largest difference between the best candidate's strict scores (as reported in
    ``result.json``) and :func:`strict_scores_from_file` of its saved design."""
    saved = json.loads((folder / "result.json").read_text())["candidates"][0]
    again = strict_scores_from_file(folder / "design.json", targets, settings)
    return float(np.max(np.abs(np.subtract(again, saved["scores_at_target_pressures"]))))


#: the target's neighbourhood (issue 14): rms phase noise (rad) on the y_t1 genome's own
#: phases, draws per level, draws of random phases with its genes, generator seed
NEIGHBOURHOOD = {"sigmas": (0.01, 0.03, 0.1, 0.3), "draws": 12, "random_draws": 40, "seed": 5}


def target_neighbourhood(entries, targets, settings, folder: Path) -> dict:
    """Is f >= 0.9 at the target pressures reachable, and how wide is its basin?

    Strict f (:func:`de.rescore_at_target_pressures`) of (a) the y_t1 genome itself with
    every phase moved by N(0, sigma) (``NEIGHBOURHOOD["draws"]`` draws per sigma), (b)
    genomes with the target's genes (gamma, H, lambda = L, M = 1) and uniformly random
    phases, (c) every database genome alone (Eq. 4.2-rescaled). The unperturbed target
    genome is saved and re-scored by :func:`strict_scores_from_file` (hand-written
    load-controlled BEM): f must be 1."""
    rng = np.random.default_rng(NEIGHBOURHOOD["seed"])
    g = de.target_genome_t1(settings)
    d = de.Design((de.DesignPart(g, tuple(range(g.n_first, g.n_last + 1)), 1.0, "y_t1"),), 1.0,
                  settings.length, settings.n_nodes, "y_t1", settings.dim)
    write_json(folder / "target_genome_design.json", d.to_dict())
    f_self = de.combined_score(strict_scores_from_file(folder / "target_genome_design.json",
                                                       targets, settings))

    def f_of(design):
        return de.combined_score(de.rescore_at_target_pressures(design, targets, settings))

    keys = d.keys("all")
    x0 = d.phase_values(keys)
    noise = {float(sg): [f_of(d.with_phases(keys, x0 + sg * rng.standard_normal(x0.size)))
                         for _ in range(NEIGHBOURHOOD["draws"])] for sg in NEIGHBOURHOOD["sigmas"]}
    random_f = [f_of(d.with_phases(keys, rng.uniform(0, 2 * np.pi, x0.size)))
                for _ in range(NEIGHBOURHOOD["random_draws"])]
    db_f = [f_of(de.entry_design(e, settings)) for e in entries]
    return {"f_target_genome": f_self, "n_phases": int(x0.size), "phase_noise": noise,
            "random_phases": random_f, "database_alone": db_f,
            "database_best": entries[int(np.argmax(db_f))].label}


def _neighbourhood_lines(nb) -> list:
    lines = ["### Is f >= 0.9 at the target pressures reachable? (issue 14)", "",
             f"The y_t1 genome itself scores f = {nb['f_target_genome']:.6f} at p_t (saved and "
             "re-scored by the hand-written load-controlled BEM). Its neighbourhood, every one "
             f"of its {nb['n_phases']} phases moved by N(0, sigma):", "",
             "| sigma (rad) | median f | min f | max f | share f >= 0.9 |", "|---|---|---|---|---|"]
    for sg, f in nb["phase_noise"].items():
        f = np.asarray(f)
        lines.append(f"| {sg:g} | {np.median(f):.3f} | {f.min():.3f} | {f.max():.3f} | "
                     f"{np.mean(f >= 0.9):.2f} |")
    rf, dbf = np.asarray(nb["random_phases"]), np.asarray(nb["database_alone"])
    lines += ["", f"The target's genes (gamma, H, lambda, M) with random phases "
              f"({rf.size} draws): median f {np.median(rf):.3f}, best {rf.max():.3f}. Every "
              f"database genome alone (Eq. 4.2): best f {dbf.max():.3f} ({nb['database_best']}). "
              "So the set f >= 0.9 around the target is a few hundredths of a radian wide in "
              "every phase, and the genes alone do not place a design in it.", ""]
    return lines


#: y_t1 without the refine stage (issue 14 section 2): the global stage
#: (``design.search_global``) on the best thesis-stage candidate of SOG, GCO and CCO,
#: every phase and every chromosome amplitude (log scale, x exp(+-0.3)) as variables
YT1_GLOBAL = de.GlobalSearchOptions(n_eval=10000, sigma=0.5, amplitudes=0.3, seed=0)


def yt1_without_refine(results, t1, settings, out: Path) -> dict:
    """SOG/GCO/CCO for y_t1 *without* the refine stage: the thesis stages (GCMMA 0-2,
    ``results``) followed by the global stage :data:`YT1_GLOBAL`, which maximises s
    solved at the target pressures (IPOP-CMA-ES, batched exact BEM). Per method: the
    strict s and the interpolated s (Eq. 4.1 as the thesis stages score it) of the best
    candidate, the thesis-stage values, CPU, and the differences to independent BEM runs
    of the saved design (hand-written load-controlled BEM for the strict s, a fresh sweep
    for the interpolated s). Returns ``{"rows": [...], "errors": [...], "lines": [...]}``."""
    rows, errors = [], []
    for r in results:
        strict0 = max(de.combined_score(de.rescore_at_target_pressures(c.design, [t1], settings))
                      for c in r.candidates)
        t0 = time.process_time()
        rg = de.search_global(r, settings, YT1_GLOBAL)
        cpu = time.process_time() - t0
        folder = out / f"yt1_{r.method}_global"
        de.write_design_result(rg, settings, folder)
        errors.append(_strict_error(rg, [t1], settings, folder))
        errors.append(float(np.max(np.abs(np.subtract(de.rescore(rg.best.design, [t1], settings),
                                                       rg.best.scores)))))
        hist = np.asarray(rg.search_history[0])
        rows.append({"method": r.method, "thesis": de.combined_score(r.best.scores),
                     "thesis_strict": strict0, "strict": rg.best.at_targets[0],
                     "interpolated": de.combined_score(rg.best.scores),
                     "n_eval": int(hist[-1, 0]), "cpu_s": cpu, "origin": rg.best.origin,
                     "history": hist.tolist(), "message": rg.message})
        print(f"  {r.method} + global: {rg.message} [{cpu:.0f} s CPU, strict error "
              f"{errors[-2]:.1e}]", flush=True)
    lines = ["### y_t1 without the refine stage: thesis stages + global stage (issue 14)", "",
             "The thesis stages (GCMMA 0-2) of each method, then `design.search_global` on "
             "the best candidate by s at the target pressures: IPOP-CMA-ES over every phase "
             f"and every chromosome amplitude (x exp(+-{YT1_GLOBAL.amplitudes:g})), sigma "
             f"{YT1_GLOBAL.sigma:g}, {YT1_GLOBAL.n_eval} strict evaluations (a generation "
             "solved together by the batched exact BEM), seed "
             f"{YT1_GLOBAL.seed}; CLI `roughfe design --method M --target y_t1 --global cmaes "
             f"--global-amplitudes {YT1_GLOBAL.amplitudes:g} --global-eval "
             f"{YT1_GLOBAL.n_eval}`. No GCMMA 3. 'strict s': solved at the target pressures "
             "(load control; reproduced by the hand-written BEM from design.json); "
             "'interpolated s': Eq. (4.1) on the design's own n_t approaches, as the thesis "
             "stages and the refine row are scored.", "",
             "| method | thesis stages s (strict) | + global: strict s | + global: "
             "interpolated s | evaluations | CPU (s) | best candidate |",
             "|---|---|---|---|---|---|---|"]
    lines += [f"| {w['method'].upper()} | {w['thesis']:.4f} ({w['thesis_strict']:.4f}) | "
              f"{w['strict']:.4f} | {w['interpolated']:.4f} | {w['n_eval']} | {w['cpu_s']:.0f} "
              f"| {w['origin']} |" for w in rows]
    best = max(range(len(rows)), key=lambda k: rows[k]["strict"])
    spread = yt1_seed_spread(results[best], rows[best]["strict"], t1, settings)
    return {"rows": rows, "errors": errors, "spread": spread,
            "lines": lines + [""] + spread["lines"]}


#: further CMA-ES seeds of the global stage of the best method (after :data:`YT1_GLOBAL`'s)
YT1_SPREAD_SEEDS = (1, 2, 3)


def yt1_seed_spread(result, strict0: float, t1, settings) -> dict:
    """The global stage of :func:`yt1_without_refine` on the same method with the seeds
    :data:`YT1_SPREAD_SEEDS`: the y_t1 "without GCMMA 3" target is judged at seed 0 (the
    study's seed), and this says how much of that verdict is the seed's (session 27:
    seeds 0-3 of SOG gave 0.988 / 0.941 / 0.986 / 0.970). Reported, not a target.
    Returns ``{"method", "seeds", "strict", "n_met", "cpu_s", "lines"}``."""
    strict, cpu = [strict0], 0.0
    for seed in YT1_SPREAD_SEEDS:
        t0 = time.process_time()
        rg = de.search_global(result, settings, replace(YT1_GLOBAL, seed=seed))
        cpu += time.process_time() - t0
        strict.append(float(rg.best.at_targets[0]))
        print(f"  {result.method} + global, seed {seed}: strict s {strict[-1]:.4f}", flush=True)
    seeds = (YT1_GLOBAL.seed, *YT1_SPREAD_SEEDS)
    n_met = sum(v >= GOALS["s_yt1"] for v in strict)
    lines = [f"Seed spread of the global stage ({result.method.upper()}, the best method at "
             f"seed {YT1_GLOBAL.seed}; reported, not a target: the verdict above is seed "
             f"{YT1_GLOBAL.seed}'s; {cpu:.0f} s CPU):", "",
             "| CMA-ES seed | " + " | ".join(map(str, seeds)) + " | mean | >= "
             f"{GOALS['s_yt1']} |", "|---" * (len(seeds) + 3) + "|",
             "| strict s | " + " | ".join(f"{v:.4f}" for v in strict)
             + f" | {np.mean(strict):.4f} | {n_met} of {len(strict)} |", ""]
    return {"method": result.method, "seeds": list(seeds), "strict": strict, "n_met": n_met,
            "cpu_s": cpu, "lines": lines}


def _curve_table(hist, marks, head: str, label: str) -> list:
    """Markdown rows of a search curve ``hist`` (rows: evaluations spent, best so far)
    read at the evaluation counts ``marks`` that it reached."""
    marks = [n for n in marks if n <= hist[-1, 0]]
    at = [float(hist[np.searchsorted(hist[:, 0], n, side="right") - 1, 1]) for n in marks]
    return [f"| {head} | " + " | ".join(map(str, marks)) + " |", "|---" * (len(marks) + 1) + "|",
            f"| {label} | " + " | ".join(f"{v:.4f}" for v in at) + " |"]


def min_round(rg, settings, options: de.GlobalSearchOptions = GLOBAL_MIN) -> dict:
    """One more global round from the best design of ``rg`` (the M-CCO global stage) on
    min(f at p_t, interpolated f) (``options.score == "min"``): per design of a
    generation the strict and the interpolated scores, batched, sharing the p_max solve
    (``design.score_batch``). Returns ``{"result", "cpu_s", "history", "f_min",
    "lines"}``: the DesignResult, its CPU time, the best-so-far curve (evaluations, best
    min), the min of its best design's two f and the report lines."""
    t0 = time.process_time()
    rgm = de.search_global(rg, settings, options)
    cpu = time.process_time() - t0
    hist = np.asarray(rgm.search_history[0])
    b = rgm.best
    f_min = min(de.combined_score(b.at_targets), de.combined_score(b.scores))
    lines = [f"Then one more round from that design on min(f at p_t, interpolated f) "
             f"(`search_global(..., score=\"min\")`, sigma {options.sigma:g}, seed "
             f"{options.seed}, {options.n_eval} evaluations): each design of a generation is "
             "solved at the target pressures and along its own n_t approaches (the thesis "
             "scoring, displacement control), both batched and sharing the p_max solve "
             f"(`design.score_batch`). {rgm.message}. CPU {cpu:.0f} s. Its design: f at p_t "
             f"{de.combined_score(b.at_targets):.4f} ({b.at_targets[0]:.4f}, "
             f"{b.at_targets[1]:.4f}), interpolated f {de.combined_score(b.scores):.4f} "
             f"({b.scores[0]:.4f}, {b.scores[1]:.4f}), both reproduced from design.json "
             "(hand-written BEM, fresh sweep).", "",
             *_curve_table(hist, (100, 300, 1000, 2000, 3000, 4000, 5000, 10000),
                           "evaluations (strict + interpolated)",
                           "best min(f at p_t, interpolated f)"), ""]
    return {"result": rgm, "cpu_s": cpu, "history": hist, "f_min": f_min, "lines": lines}


def _table1(out, lines):
    """Alg. 2 for the 10x realisation of Table 1 (H = 0.75) and with H = 0.85 (Figs. 47-52)."""
    lines += ["## Macro/micro roughness of the Table 1 genome (Alg. 2, Figs. 47-52)", "",
              "Genome: A = 1, gamma = 1.5, M = 8, lambda = L = 1 mm, N = 512, n_t = 20, phases "
              "from seed 0 (the thesis gives none); H = 0.75 and H = 0.85 with the same Phi.", "",
              "| H | macro chromosomes (c_n > 0.95, K) | chromosomes with c_n(A) > 0.95 | thesis |",
              "|---|---|---|---|"]
    settings = db.DatabaseSettings(length=1e-3, n_nodes=512)
    thesis = {0.75: "n = 1..5 (Fig. 47; 1..6 in Fig. 48)", 0.85: "n = 1..10 (Fig. 50)"}
    found = {}
    for H in (0.75, 0.85):
        g = replace(table1_genome(rng=0), H=H)
        mm = macro_micro(g, settings)
        found[H] = list(mm.macro)
        a_ok = [int(n) for n, c in zip(mm.chromosomes, mm.corr_a) if c > 0.95]
        lines.append(f"| {H} | {list(mm.macro)} | {a_ok} | {thesis[H]} |")
        dplot.plot_macro_micro(mm, out / f"table1_H{H}_correlation.png",
                               title=f"Table 1 genome, H = {H}: c_n")
        tot = realize(g, settings.length, settings.n_nodes)
        zl = realize(g, settings.length, settings.n_nodes, chromosomes=mm.macro) if mm.macro else None
        zs = realize(g, settings.length, settings.n_nodes, chromosomes=mm.micro) if mm.micro else None
        x = tot.metadata["x0"] + np.arange(tot.shape[0]) * tot.spacing[0]
        from roughfe.genomics.macro_micro import profile_response
        resp = {"Z": mm.curve}
        for name, s in (("Z_L", zl), ("Z_S", zs)):
            if s is not None:
                resp[name] = profile_response(s, youngs_modulus=settings.youngs_modulus)
        dplot.plot_macro_micro_profiles(
            x, tot.heights, zl.heights if zl is not None else 0 * x,
            zs.heights if zs is not None else 0 * x, resp,
            out / f"table1_H{H}_macro_micro.png", title=f"H = {H}")
    lines += ["", "![](design/table1_H0.75_correlation.png) ![](design/table1_H0.85_correlation.png)",
              "", "![](design/table1_H0.75_macro_micro.png)", ""]
    return found


def _run(name, method, entries, targets, settings, out, options, pbar=None):
    t0 = time.perf_counter()
    r = de.run_design(method, entries, targets, settings, pbar=pbar, options=options)
    de.write_design_result(r, settings, out / name)
    again = de.rescore(r.best.design, targets, settings)
    err = float(np.max(np.abs(np.asarray(again) - np.asarray(r.best.scores))))
    print(f"  {name}: {r.message} [{r.nit} sweeps, {time.perf_counter() - t0:.1f} s, "
          f"rescore error {err:.1e}]", flush=True)
    return r, err


def _stage_table(results):
    rows = ["| method | candidate | origin | GCMMA 0 | GCMMA 1 | GCMMA 2 | GCMMA 3 (refined) | "
            "BEM sweeps | time (s) |",
            "|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        for k, c in enumerate(r.candidates, 1):
            st = list(c.stages) + ([float("nan")] if len(c.stages) == 3 else [])
            rows.append(f"| {r.method.upper()} | {k} | {c.origin} | " +
                        " | ".join(f"{s:.4f}" for s in st) +
                        (f" | {r.nit} | {r.elapsed:.1f} |" if k == 1 else " | | |"))
    return rows


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
    r, err = _run("yt1_sog", "sog", entries, [t1], settings, out, fast, PBAR_T1 * t1.p_max)
    start = max(c.stages[0] for c in r.candidates)          # best score at GCMMA 0
    gain = de.combined_score(r.best.scores) - start
    # the search at the target pressures (beyond the thesis), a 2-start run of 8 sweeps
    strict0 = max(de.combined_score(de.rescore_at_target_pressures(c.design, [t1], settings))
                  for c in r.candidates)
    rs = de.search_at_target_pressures(r, settings, n_eval=8, starts=2)
    de.write_design_result(rs, settings, out / "yt1_sog_search")
    strict = de.combined_score(rs.best.at_targets)
    err_strict = _strict_error(rs, [t1], settings, out / "yt1_sog_search")
    # the global stage (beyond the thesis): IPOP-CMA-ES on the batched strict score
    rg = de.search_global(r, settings, n_eval=60, seed=0)
    de.write_design_result(rg, settings, out / "yt1_sog_global")
    strict_g = de.combined_score(rg.best.at_targets)
    err_strict = max(err_strict, _strict_error(rg, [t1], settings, out / "yt1_sog_global"))
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
    _table1(out, lines)

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
    print("== y_t1", flush=True)
    pbar1 = PBAR_T1 * t1.p_max
    res1 = []
    for m in ("sog", "gco", "cco"):
        r, err = _run(f"yt1_{m}", m, entries, [t1], settings, out, opts, pbar1)
        res1.append(r)
        reproducible.append(err)
    print("== y_t1, refinement stage (beyond the thesis)", flush=True)
    ref1 = []
    for r in res1:
        rr = de.refine(r, settings)
        de.write_design_result(rr, settings, out / f"yt1_{r.method}_refined")
        err = float(np.max(np.abs(np.asarray(de.rescore(rr.best.design, [t1], settings))
                                  - np.asarray(rr.best.scores))))
        reproducible.append(err)
        print(f"  {rr.message} [{rr.nit} sweeps, {rr.elapsed:.1f} s, rescore error {err:.1e}]",
              flush=True)
        ref1.append(rr)
    print("== y_t1 without refine: thesis stages + global stage (beyond the thesis)", flush=True)
    free = yt1_without_refine(res1, t1, settings, out)
    reproducible += free["errors"]
    res1 = ref1
    dplot.plot_stages(res1, out / "stages_yt1.png", title="y_t1: GCMMA stages 0-2 (thesis) and 3 (refined)")
    dplot.plot_design_curves(res1, out / "curves_yt1.png", title="best designs for y_t1")
    dplot.plot_profiles({r.method: r.best.design.surface() for r in res1}, out / "profiles_yt1.png")
    dplot.plot_psds({r.method: (r.best.design.surface(), r.best.design.spectrum_lines())
                     for r in res1}, out / "psd_yt1.png")
    lines += [f"## Single target y_t1 (Sec. 4.3.1, Figs. 58, 60-62), pbar = {pbar1:.4g} Pa", "",
              "GCMMA settings of the thesis: phases within +-10 % of their start, n_it = 5 "
              "(SOG) / 3 (GCO, CCO) in stage 1 and 1 in stage 2; min-max form with exact "
              "sensitivities on the fixed contact sets (CCO: all genes). GCMMA 3 is an extra "
              "stage beyond the thesis (`roughfe.genomics.design.refine`): 3 rounds x 15 "
              "iterations on all phases, box +-10 % of 2 pi re-centred each round, so phases "
              "may drift beyond +-10 % of their database values.", ""]
    lines += _stage_table(res1) + ["", "![](design/stages_yt1.png) ![](design/curves_yt1.png)", "",
                                   "![](design/profiles_yt1.png)", "", "![](design/psd_yt1.png)", ""]
    lines += free["lines"]

    print("== y_t1, variants of the optimiser", flush=True)
    variants = {"thesis: objective (1-s)^2, finite-difference gradient":
                    replace(opts, formulation="thesis", gradient="fd"),
                "min-max, finite-difference Jacobian": replace(opts, gradient="fd"),
                "min-max, exact sensitivities, phases +-10 % of 2 pi": replace(opts, bound="period"),
                "min-max, exact, +-10 % of 2 pi, 10 + 3 iterations":
                    replace(opts, bound="period", n_it_sog=10, n_it_cross=10, n_it_micro=3)}
    lines += ["### Optimiser variants for y_t1 (best final s, BEM sweeps)", "",
              "| variant | SOG | GCO | CCO |", "|---|---|---|---|"]
    best_variant = {}
    for k, (label, o) in enumerate(variants.items()):
        cells = []
        for m in ("sog", "gco", "cco"):
            r, err = _run(f"yt1_{m}_v{k}", m, entries, [t1], settings, out, o, pbar1)
            reproducible.append(err)
            cells.append(f"{de.combined_score(r.best.scores):.4f} ({r.nit})")
            best_variant[(label, m)] = r
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    lines.append("")
    thesis_t1 = max([c.stages[2] for r in ref1 for c in r.candidates] +
                    [de.combined_score(r.best.scores) for r in best_variant.values()])
    best_t1 = max([de.combined_score(r.best.scores) for r in ref1] +
                  [de.combined_score(r.best.scores) for r in best_variant.values()])

    print("== y_t2", flush=True)
    pbar2 = t2.metadata["pbar"]
    res2 = []
    for m in ("sog", "gco", "cco"):
        r, err = _run(f"yt2_{m}", m, entries, [t2], settings, out, opts, pbar2)
        res2.append(r)
        reproducible.append(err)
    res2 = [de.refine(r, settings) for r in res2]
    for r in res2:
        de.write_design_result(r, settings, out / f"yt2_{r.method}_refined")
        reproducible.append(float(np.max(np.abs(np.asarray(de.rescore(r.best.design, [t2], settings))
                                                - np.asarray(r.best.scores)))))
    dplot.plot_stages(res2, out / "stages_yt2.png", title="y_t2")
    dplot.plot_design_curves(res2, out / "curves_yt2.png", title="best designs for y_t2")
    dplot.plot_profiles({r.method: r.best.design.surface() for r in res2}, out / "profiles_yt2.png")
    dplot.plot_psds({r.method: (r.best.design.surface(), r.best.design.spectrum_lines())
                     for r in res2}, out / "psd_yt2.png")
    lines += [f"## Single target y_t2 (Sec. 4.3.2, Figs. 63-66), pbar = {pbar2:.4g} Pa", ""]
    lines += _stage_table(res2) + ["", "![](design/stages_yt2.png) ![](design/curves_yt2.png)", ""]

    print("== multi-target", flush=True)
    rm, err = _run("mcco", "mcco", entries, [t1, t3], settings, out, opts)
    reproducible.append(err)
    runs = [("thesis stages", rm)]
    # beyond the thesis (a): a wider start pool -- the 8 best genomes of each Alg. 3
    # ranking, both macro/micro role orders, micro amplitude x 0.5 / 1 / 2 -- then the
    # thesis stages on the 3 best starts, then the refinement stage
    rp = de.run_design("mcco", entries, [t1, t3], settings, options=opts, n_best=3, max_set=12,
                       **MCCO_POOL)
    rp2 = de.refine(rp, settings, rounds=6, n_it=20)
    # beyond the thesis (b): 6 cross-overs (instead of 3) from the thesis sets, then the
    # refinement stage with 6 rounds of 20 iterations
    rm2 = de.refine(de.run_design("mcco", entries, [t1, t3], settings, options=opts, n_best=6,
                                  max_set=12), settings, rounds=6, n_it=20)
    # beyond the thesis (c): a derivative-free search of all phases and the part weights on
    # f solved at the target pressures (the strict score), from the thesis stages and from
    # the wide pool + GCMMA 3
    rs = de.search_at_target_pressures(rm, settings, n_eval=SEARCH_EVAL)
    rps = de.search_at_target_pressures(rp2, settings, n_eval=SEARCH_EVAL)
    # (d) the same search as a deterministic multi-start: SEARCH_STARTS runs per candidate
    rms = de.search_at_target_pressures(rm, settings, n_eval=SEARCH_EVAL, starts=SEARCH_STARTS)
    # (e) the global stage: IPOP-CMA-ES on all phases and part weights, f at p_t of a
    # whole generation solved together (bem.batch), from the thesis stages' best candidate
    t0 = time.process_time()
    rg = de.search_global(rm, settings, n_eval=GLOBAL_EVAL, sigma=GLOBAL_SIGMA, seed=0,
                          rounds=GLOBAL_ROUNDS)
    cpu_global = time.process_time() - t0
    # (f) one more round from (e)'s design on min(f at p_t, interpolated f)
    both = min_round(rg, settings)
    rgm, cpu_min, hist_min, f_both = (both[k] for k in ("result", "cpu_s", "history", "f_min"))
    runs += [(f"wide pool ({rp.n_cross} starts), thesis stages", rp), ("wide pool + GCMMA 3 (6 x 20 it.)", rp2),
             ("6 starts + GCMMA 3 (6 x 20 it.)", rm2),
             (f"thesis stages + search at p_t ({SEARCH_EVAL} sweeps per candidate)", rs),
             (f"wide pool + GCMMA 3 + search at p_t ({SEARCH_EVAL} sweeps per candidate)", rps),
             (f"thesis stages + multi-start search at p_t ({SEARCH_STARTS} x {SEARCH_EVAL} "
              f"sweeps per candidate)", rms),
             (f"thesis stages + global search at p_t (IPOP-CMA-ES, {GLOBAL_ROUNDS} rounds x "
              f"{GLOBAL_EVAL} strict evaluations, best candidate)", rg),
             (f"the same + a round on min(f at p_t, interpolated f) ({GLOBAL_MIN.n_eval} "
              f"evaluations, sigma {GLOBAL_MIN.sigma:g})", rgm)]
    strict_errors = []
    folder_of = {id(rm): out / "mcco"}          # where each run's result.json is saved
    for name, r in (("mcco_pool", rp), ("mcco_pool_refined", rp2), ("mcco_refined", rm2),
                    ("mcco_search", rs), ("mcco_pool_refined_search", rps),
                    ("mcco_multistart_search", rms), ("mcco_global", rg),
                    ("mcco_global_min", rgm)):
        de.write_design_result(r, settings, out / name)
        folder_of[id(r)] = out / name
        err = float(np.max(np.abs(np.asarray(de.rescore(r.best.design, [t1, t3], settings))
                                  - np.asarray(r.best.scores))))
        if r.best.at_targets:                # strict scores: reloaded design, hand-written BEM
            strict_errors.append(_strict_error(r, [t1, t3], settings, out / name))
            err = max(err, strict_errors[-1])
        print(f"  {name}: {r.message} [{r.nit} sweeps, {r.elapsed:.0f} s, rescore error "
              f"{err:.1e}]", flush=True)
        reproducible.append(err)
    hist = np.asarray(rg.search_history[0])
    dplot.plot_search_history({"IPOP-CMA-ES from the thesis stages": hist,
                               "+ a round on min(f at p_t, interpolated f)":
                                   hist_min + [hist[-1, 0], 0.0]},
                              out / "search_global.png", goal=GOALS["f_multi"],
                              title="M-CCO (y_t1, y_t3): global search at p_t")
    dplot.plot_design_curves([rm, rm2, rs, rms, rg], out / "curves_mcco.png",
                             title="M-CCO, (y_t1, y_t3)")
    dplot.plot_profiles({f"y{k}": c.design.surface() for k, c in enumerate(rm.candidates, 1)},
                        out / "profiles_mcco.png")
    dplot.plot_psds({f"y{k}": (c.design.surface(), c.design.spectrum_lines())
                     for k, c in enumerate(rm.candidates, 1)}, out / "psd_mcco.png")
    lines += ["## Multi-target (y_t1 for K, y_t3 for A): M-CCO (Sec. 4.4, Table 4, Figs. 68-70)", "",
              "f, s_K, s_A: Eq. (4.1) as everywhere (design sampled at its n_t equal approaches, "
              "interpolated at the target pressures). 'at p_t': the same design solved at the "
              "target's pressures (load control, `design.rescore_at_target_pressures`), so A is "
              "the exact contact-node count there; the target genome itself scores 1 this way. "
              "'search at p_t' (beyond the thesis, `design.search_at_target_pressures`): a (1+1) "
              "evolution strategy that accepts equal scores (it walks across the plateaus of the "
              "node-count staircase) on all phases (whole period) and the part weights (+-30 %), "
              f"maximising f at p_t itself; 'multi-start': {SEARCH_STARTS} independent runs per "
              "candidate (deterministic seeds), the best kept.", "",
              "| run | genome | f | s(y_t1, K) | s(y_t3, A) | f at p_t (s_K, s_A) | macro + micro from | "
              "GCMMA 0/1/2(/3) |",
              "|---|---|---|---|---|---|---|---|"]
    strict = {}
    for label, r in runs:
        saved = json.loads((folder_of[id(r)] / "result.json").read_text())["candidates"]
        for k, c in enumerate(r.candidates, 1):
            sp = de.rescore_at_target_pressures(c.design, [t1, t3], settings)
            strict[(label, k)] = de.combined_score(sp)
            if c.at_targets:             # the search stage's own strict scores, reproduced
                reproducible.append(float(np.max(np.abs(np.asarray(sp) - c.at_targets))))
            # every strict score in the table: the saved candidate, hand-written BEM
            strict_errors.append(float(np.max(np.abs(np.subtract(strict_scores_from_dict(
                saved[k - 1]["design"], [t1, t3], settings), sp)))))
            reproducible.append(strict_errors[-1])
            lines.append(f"| {label} | y_{k} | {de.combined_score(c.scores):.3f} | {c.scores[0]:.3f} | "
                         f"{c.scores[1]:.3f} | {de.combined_score(sp):.3f} ({sp[0]:.3f}, {sp[1]:.3f}) | "
                         f"{c.origin} | " + " / ".join(f"{s:.3f}" for s in c.stages) + " |")
    best_f = max(de.combined_score(r.best.scores) for _, r in runs)
    best_f_thesis = max(c.stages[2] for _, r in runs for c in r.candidates)
    best_f_strict = max(strict.values())
    t_a = np.asarray(t3.values)
    lines += ["", f"Best f = {best_f:.3f}; with the thesis stages only (GCMMA 0-2) {best_f_thesis:.3f}; "
              f"best f with the design solved at the target pressures {best_f_strict:.3f}. "
              f"The first target areas are {', '.join(f'{a * settings.n_nodes:.0f}' for a in t_a[:4])} "
              f"contact nodes out of {settings.n_nodes}: at p_t one node more or less at the "
              "first two points costs 50 % / 20 % of s_A, while the interpolated score credits "
              "fractions of a node.", "",
              "### The M-CCO methods compared (best candidate of each run)", "",
              "| run | BEM sweeps | time (s) | f (interpolated) | f at p_t | strict f reproduced "
              "from design.json |", "|---|---|---|---|---|---|"]
    for label, r in runs:
        f_p = max(strict[(label, k)] for k in range(1, len(r.candidates) + 1))
        lines.append(f"| {label} | {r.nit} | {r.elapsed:.0f} | {de.combined_score(r.best.scores):.3f} "
                     f"| {f_p:.3f} | " + ("yes" if r.best.at_targets else "-") + " |")
    lines += ["", "### Global search at p_t (beyond the thesis, `design.search_global`)", "",
              "IPOP-CMA-ES (own implementation, `roughfe.optim.cmaes`) on every phase and part "
              "weight of the thesis stages' best candidate, maximising f solved at the target "
              "pressures; each generation's profiles are solved together by the batched exact "
              "BEM (`roughfe.bem.batch_exact`, block principal pivoting on stacked systems; the same "
              "contact states as the single solver to round-off). "
              f"{GLOBAL_ROUNDS} rounds of {GLOBAL_EVAL} evaluations: each round is one IPOP "
              "run (restarts with doubled populations return to the round's start) from the "
              "best design of the round before. The design found is scored "
              f"again by one single solve and by the hand-written BEM above. {rg.message}. CPU "
              f"{cpu_global:.0f} s for {int(hist[-1, 0])} strict evaluations.", "",
              *_curve_table(hist, (100, 300, 1000, 3000, 10000, 20000, 30000, 40000, 100000),
                            "strict evaluations", "best f at p_t"), ""]
    lines += both["lines"] + ["![](design/search_global.png)", ""]
    nb = target_neighbourhood(entries, [t1, t3], settings, out)
    reproducible.append(abs(1.0 - nb["f_target_genome"]))
    lines += _neighbourhood_lines(nb)
    lines += ["", f"Largest difference between a reported strict score (every candidate of every "
              f"run above) and the independent load-controlled BEM run of its saved design: "
              f"{max(strict_errors):.1e}.", "",
              "![](design/curves_mcco.png)", "", "![](design/profiles_mcco.png)", ""]

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
    spread_note = (f"{sp['method'].upper()} with seeds {', '.join(map(str, sp['seeds']))}: "
                   f"strict s {' / '.join(f'{v:.4f}' for v in sp['strict'])}, "
                   f"{sp['n_met']} of {len(sp['strict'])} >= {GOALS['s_yt1']}")
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
              f"the verdict is CMA-ES seed {YT1_GLOBAL.seed}'s: {spread_note}",
              f"* best f for (y_t1, y_t3): {best_f:.4f} (goal >= {GOALS['f_multi']}): "
              f"{'met' if ok['f_multi'] else 'NOT met'}; thesis stages only {best_f_thesis:.4f}; "
              f"the same designs solved at the target pressures: best f {best_f_strict:.4f}",
              f"* best f for (y_t1, y_t3) solved at the target pressures: {best_f_strict:.4f} "
              f"(goal >= {GOALS['f_multi']}): "
              f"{'met' if ok['f_multi_at_target_pressures'] else 'NOT met: ' + f_strict_reason}",
              f"* one M-CCO design with both: min(f at p_t, interpolated f) = {f_both:.4f} "
              f"(goal >= {GOALS['f_multi']}): {'met' if ok['f_multi_one_design'] else 'NOT met'}",
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
                             f"{YT1_GLOBAL.seed}; {spread_note}", free_best[k][k])
                      for k in ("strict", "interpolated")),
                    Target("(y_t1, y_t3): best M-CCO f", f">= {GOALS['f_multi']}",
                           f"{best_f:.4f}", ok["f_multi"],
                           f"at the target pressures {best_f_strict:.4f}; thesis stages only "
                           f"{best_f_thesis:.4f} (issue 14 section 2)", best_f),
                    Target("(y_t1, y_t3): best M-CCO f solved at the target pressures",
                           f">= {GOALS['f_multi']}", f"{best_f_strict:.4f}",
                           ok["f_multi_at_target_pressures"], f_strict_reason or
                           "search at p_t (beyond the thesis) included", best_f_strict),
                    Target("(y_t1, y_t3): one M-CCO design, min(f at p_t, interpolated f)",
                           f">= {GOALS['f_multi']}", f"{f_both:.4f}", ok["f_multi_one_design"],
                           f"global stage + a round on the min ({GLOBAL_MIN.n_eval} "
                           f"evaluations, {cpu_min:.0f} s CPU)", f_both),
                    Target("reported scores = independent BEM runs of the saved designs",
                           f"<= {GOALS['reproducible']:.0e}", f"{rep:.1e}", ok["reproducible"],
                           "", rep))],
                "yt1_seed_spread": {k: v for k, v in sp.items() if k != "lines"},
                "yt1_without_refine": {"options": {"n_eval": YT1_GLOBAL.n_eval,
                                                   "sigma": YT1_GLOBAL.sigma,
                                                   "amplitudes": YT1_GLOBAL.amplitudes,
                                                   "seed": YT1_GLOBAL.seed},
                                       "methods": free["rows"]},
                "global_search": {"history": hist.tolist(), "cpu_s": cpu_global,
                                  "n_eval": GLOBAL_EVAL, "sigma": GLOBAL_SIGMA,
                                  "rounds": GLOBAL_ROUNDS,
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
