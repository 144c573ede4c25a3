"""The single-target stages of ``validation/design_study.py``: macro/micro roughness of
the Table 1 genome (Alg. 2), SOG/GCO/CCO for y_t1 (thesis stages, the refine stage, the
global stage without it, optimiser variants) and for y_t2, with their report lines.
Pressures in Pa. A helper module of the study, not a study of its own.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from roughfe.genomics import database as db
from roughfe.genomics import design as de
from roughfe.genomics.genome import realize, table1_genome
from roughfe.genomics.macro_micro import macro_micro
from roughfe.plotting import design as dplot

from _design_checks import run_design_checked
from _design_global import yt1_without_refine


def table1_macro_micro(out, lines):
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


def stage_table(results):
    """Markdown rows of the GCMMA stages of every candidate of ``results``."""
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


def single_target_t1(entries, t1, settings, out, opts, pbar1, lines, reproducible,
                      goal) -> dict:
    """SOG/GCO/CCO for y_t1 at ``pbar1`` (Pa): the thesis stages, the refine stage,
    :func:`yt1_without_refine` (``goal``: the s its seed spread counts) and the optimiser
    variants; appends the report to ``lines`` and the rescore errors to
    ``reproducible``. Returns ``{"thesis_t1", "best_t1", "free"}``: the best s with the
    thesis stages only, the best s with GCMMA 3, the global-stage study."""
    print("== y_t1", flush=True)
    res1 = []
    for m in ("sog", "gco", "cco"):
        r, err = run_design_checked(f"yt1_{m}", m, entries, [t1], settings, out, opts, pbar1)
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
    free = yt1_without_refine(res1, t1, settings, out, goal)
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
    lines += stage_table(res1) + ["", "![](design/stages_yt1.png) ![](design/curves_yt1.png)", "",
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
            r, err = run_design_checked(f"yt1_{m}_v{k}", m, entries, [t1], settings, out, o, pbar1)
            reproducible.append(err)
            cells.append(f"{de.combined_score(r.best.scores):.4f} ({r.nit})")
            best_variant[(label, m)] = r
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    lines.append("")
    thesis_t1 = max([c.stages[2] for r in ref1 for c in r.candidates] +
                    [de.combined_score(r.best.scores) for r in best_variant.values()])
    best_t1 = max([de.combined_score(r.best.scores) for r in ref1] +
                  [de.combined_score(r.best.scores) for r in best_variant.values()])
    return {"thesis_t1": thesis_t1, "best_t1": best_t1, "free": free}


def single_target_t2(entries, t2, settings, out, opts, lines, reproducible) -> None:
    """SOG/GCO/CCO for y_t2 at its pbar, then the refine stage; appends the report to
    ``lines`` and the rescore errors to ``reproducible``."""
    print("== y_t2", flush=True)
    pbar2 = t2.metadata["pbar"]
    res2 = []
    for m in ("sog", "gco", "cco"):
        r, err = run_design_checked(f"yt2_{m}", m, entries, [t2], settings, out, opts, pbar2)
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
    lines += stage_table(res2) + ["", "![](design/stages_yt2.png) ![](design/curves_yt2.png)", ""]
