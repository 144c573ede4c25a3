"""The global stages of ``validation/design_study.py`` beyond the thesis (issue 14 section
2): y_t1 without the refine stage (the thesis stages, then IPOP-CMA-ES on the strict
score), the spread of a seeded stage's verdict over CMA-ES seeds (this stage's and the
M-CCO global stage's), and one more M-CCO round on min(f at p_t, interpolated f). A
helper module of the study, not a study of its own.
"""
from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from roughfe.genomics import design as de

from _design_checks import strict_error


#: y_t1 without the refine stage (issue 14 section 2): the global stage
#: (``design.search_global``) on the best thesis-stage candidate of SOG, GCO and CCO,
#: every phase and every chromosome amplitude (log scale, x exp(+-0.3)) as variables
YT1_GLOBAL = de.GlobalSearchOptions(n_eval=10000, sigma=0.5, amplitudes=0.3, seed=0)


def yt1_without_refine(results, t1, settings, out: Path, goal: float) -> dict:
    """SOG/GCO/CCO for y_t1 *without* the refine stage: the thesis stages (GCMMA 0-2,
    ``results``) followed by the global stage :data:`YT1_GLOBAL`, which maximises s
    solved at the target pressures (IPOP-CMA-ES, batched exact BEM). Per method: the
    strict s and the interpolated s (Eq. 4.1 as the thesis stages score it) of the best
    candidate, the thesis-stage values, CPU, and the differences to independent BEM runs
    of the saved design (hand-written load-controlled BEM for the strict s, a fresh sweep
    for the interpolated s); then :func:`seed_spread` of the best method's global stage
    (``goal``: the s it counts). Returns ``{"rows": [...], "errors": [...], "spread":
    {...}, "lines": [...]}``."""
    rows, errors = [], []
    for r in results:
        strict0 = max(de.combined_score(de.rescore_at_target_pressures(c.design, [t1], settings))
                      for c in r.candidates)
        t0 = time.process_time()
        rg = de.search_global(r, settings, YT1_GLOBAL)
        cpu = time.process_time() - t0
        folder = out / f"yt1_{r.method}_global"
        de.write_design_result(rg, settings, folder)
        errors.append(strict_error(rg, [t1], settings, folder))
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
    rb = results[best]

    def at_seed(seed):
        rs = de.search_global(rb, settings, replace(YT1_GLOBAL, seed=seed))
        return {"strict s": rs.best.at_targets[0],
                "interpolated s": de.combined_score(rs.best.scores)}

    spread = {"method": rb.method, **seed_spread(
        at_seed, {"strict s": rows[best]["strict"], "interpolated s": rows[best]["interpolated"]},
        YT1_GLOBAL.seed, goal, f"Seed spread of the global stage ({rb.method.upper()}, the "
        f"best method at seed {YT1_GLOBAL.seed}; session 27 with B D z sampling: strict "
        "0.988 / 0.941 / 0.986 / 0.970)")}
    return {"rows": rows, "errors": errors, "spread": spread,
            "lines": lines + [""] + spread["lines"]}


#: further CMA-ES seeds of the study's seeded global stages (the y_t1 stage without
#: GCMMA 3 and the M-CCO global stage), after the study's own seed: their spread
SPREAD_SEEDS = (1, 2, 3)


def seed_spread(run, first: dict, seed0: int, goal: float, head: str) -> dict:
    """How much of a seeded stage's verdict is the seed's: ``run(seed)`` runs the stage
    at one of :data:`SPREAD_SEEDS` and returns its scores ``{label: value}`` (Eq. 4.1 s
    or f, dimensionless) under the labels of ``first``, the scores of the study's own run
    at seed ``seed0`` (not run again). Per label: the values (seed ``seed0`` first), the
    mean, the median and ``n_met``, the number of seeds with a value >= ``goal``;
    ``cpu_s``: the CPU time (s) of the further seeds. Reported, not a target: the study's
    verdict stays seed ``seed0``'s. Returns ``{"seeds", "values", "mean", "median",
    "n_met", "goal", "cpu_s", "lines"}`` (``head``: the sentence above the table)."""
    values = {k: [float(v)] for k, v in first.items()}
    cpu = 0.0
    for seed in SPREAD_SEEDS:
        t0 = time.process_time()
        got = run(seed)
        cpu += time.process_time() - t0
        for k, v in values.items():
            v.append(float(got[k]))
        print(f"  seed {seed}: " + ", ".join(f"{k} {v[-1]:.4f}" for k, v in values.items()),
              flush=True)
    seeds = [seed0, *SPREAD_SEEDS]
    mean = {k: float(np.mean(v)) for k, v in values.items()}
    median = {k: float(np.median(v)) for k, v in values.items()}
    n_met = {k: int(np.count_nonzero(np.asarray(v) >= goal)) for k, v in values.items()}
    lines = [f"{head}. Reported, not a target: the verdict above is CMA-ES seed {seed0}'s; "
             f"{cpu:.0f} s CPU for seeds {', '.join(map(str, SPREAD_SEEDS))}.", "",
             "| CMA-ES seed | " + " | ".join(map(str, seeds)) + f" | mean | median | >= {goal} |",
             "|---" * (len(seeds) + 4) + "|"]
    lines += [f"| {k} | " + " | ".join(f"{x:.4f}" for x in v) + f" | {mean[k]:.4f} | "
              f"{median[k]:.4f} | {n_met[k]} of {len(v)} |" for k, v in values.items()]
    return {"seeds": seeds, "values": values, "mean": mean, "median": median,
            "n_met": n_met, "goal": goal, "cpu_s": cpu, "lines": lines + [""]}


def spread_note(spread: dict, label: str) -> str:
    """One line of :func:`seed_spread`'s result for the goals list: the values under
    ``label`` per seed and how many reach the goal."""
    v = spread["values"][label]
    return (f"seeds {', '.join(map(str, spread['seeds']))}: {label} "
            f"{' / '.join(f'{x:.4f}' for x in v)}, {spread['n_met'][label]} of {len(v)} "
            f">= {spread['goal']}")


def curve_table(hist, marks, head: str, label: str) -> list:
    """Markdown rows of a search curve ``hist`` (rows: evaluations spent, best so far)
    read at the evaluation counts ``marks`` that it reached."""
    marks = [n for n in marks if n <= hist[-1, 0]]
    at = [float(hist[np.searchsorted(hist[:, 0], n, side="right") - 1, 1]) for n in marks]
    return [f"| {head} | " + " | ".join(map(str, marks)) + " |", "|---" * (len(marks) + 1) + "|",
            f"| {label} | " + " | ".join(f"{v:.4f}" for v in at) + " |"]


def min_round(rg, settings, options: de.GlobalSearchOptions) -> dict:
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
             *curve_table(hist, (100, 300, 1000, 2000, 3000, 4000, 5000, 10000),
                          "evaluations (strict + interpolated)",
                          "best min(f at p_t, interpolated f)"), ""]
    return {"result": rgm, "cpu_s": cpu, "history": hist, "f_min": f_min, "lines": lines}
