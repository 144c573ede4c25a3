"""Calibration of the Richardson uncertainty on sequences with a known limit.

Run: ``roughfe validate fem`` (after ``bem_vs_fem.py``, before ``fem_convergence.py``) or
``python validation/richardson_calibration.py OUTDIR``; writes
``<outdir>/richardson_calibration.md`` and ``.json``; every profile's levels are kept in
``<outdir>/richardson_calibration_profiles/D<D>_s<s>.json`` as it finishes and reused by
a later run with the same settings (about 50 s CPU per profile).

Question: are the uncertainties of :func:`roughfe.validation.richardson` -- the claims
that the every-level rows of ``fem_convergence.py`` rest on -- right? Its two branches:
(F_s - 1) |Q_fine - limit| with F_s = 1.25 when the finest three levels converge
monotonically at an order in [0.5, 4] ("asymptotic"), otherwise 3 times the last
difference ("fallback"; Roache 1998, the grid convergence index for an unobserved order),
and since the first protocol below 3 times the larger of the last two differences.

Protocols (docs/validation/fem-convergence.md, "Calibrating the Richardson uncertainty"
and "A second protocol", each committed before the run it judges): the BEM half of
``fem_convergence.py`` (periodic plane strain, spectral kernel, mirrored polyline refined
r times; ``validation/_refinement.py``) on RMD profiles that are not the study's, at
their three study loads, for the three gated quantities (A* with sub-element edges,
window K, mean gap). Estimate: ``richardson`` of r = 1, 2, 4, 8, 16. Reference: r = 256,
uncertain by u_ref = max(|Q_256 - Q_128|, |Q_128 - Q_64|). Each claim is covered, missed
or undecided (:func:`roughfe.validation.judge_claim`); a branch is calibrated when
covered / (covered + missed) >= 0.90 over >= 20 decided sequences.

* First protocol, 24 profiles (D = 1.3, 1.5, 1.7; seeds 2-9): the fallback (then 3x the
  last difference) covered 83.6 %, the asymptotic branch 30.1 %; the candidate 3x the
  larger of the last two differences covered 65 of 65 and replaced the fallback.
* Second protocol, 24 fresh profiles (seeds 10-17): the adopted fallback covered 67 of
  67; of two candidates for the asymptotic branch, A (asymptotic only with the last two
  orders within 25 %) covered 28.8 %, B (its uncertainty floored at the fallback's) 149
  of 149 and replaced it.
* Third protocol: the floor's factor 1.25 (the smallest of a grid covering >= 95 % of
  the first two sets in each branch), tested on 24 more profiles (seeds 18-25): 97.9 %
  (asymptotic) and 96.9 % (fallback) covered; it replaced the factor 3.

The target rows judge the current ``richardson`` on the three sets (the first two are
its fitting data, the third its test); the rows of the floor 3x and of Roache's index
alone, as it was before session 43, are reported, not targets. No reduced case (``--quick`` leaves it out): the unit tests check
the judging (tests/test_validation_tools.py).
"""
from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _refinement import load_window, refined, study_pressures, window_quantities  # noqa: E402
from _fem_cases import MATERIAL  # noqa: E402

from roughfe.bem import contact_sweep  # noqa: E402
from roughfe.fem import mirrored_profile  # noqa: E402
from roughfe.surfaces.rmd import rmd_profile  # noqa: E402
from roughfe.validation import (SAFETY_FALLBACK, SAFETY_OBSERVED, Target,  # noqa: E402
                                judge_claim, judge_richardson, richardson,
                                targets_markdown)
from roughfe.writers import write_json, write_text  # noqa: E402

#: (fractal dimension D, RMD seed) of the first protocol; D = 1.5 seed 1 is
#: fem_convergence's profile: left out
PROFILES = tuple((d, s) for d in (1.3, 1.5, 1.7) for s in range(2, 10))
#: the second protocol's fresh profiles (never run before it was written)
FRESH_PROFILES = tuple((d, s) for d in (1.3, 1.5, 1.7) for s in range(10, 18))
#: the third protocol's test profiles (of the floor factor 1.25, fitted on the others)
THIRD_PROFILES = tuple((d, s) for d in (1.3, 1.5, 1.7) for s in range(18, 26))
ESTIMATE_LEVELS = (1, 2, 4, 8, 16)           # the levels of fem_convergence
REFERENCE_LEVELS = (64, 128, 256)            # the reference and its own uncertainty
QUANTITIES = ("area", "stiffness", "mean_gap")
CALIBRATED = 0.90                            # covered / decided, per branch
MIN_DECIDED = 20
#: fem_convergence's RMD profile at 1744 MPa, BEM, r = 1 ... 16 (session 36), continued
STUDY_RMD = {"D": 1.5, "seed": 1, "load_index": 2}


def profile_levels(d: float, seed: int, levels, folder: Path) -> dict:
    """BEM window quantities of one RMD profile at every r of ``levels`` (kept in a JSON
    file per profile; reused when its settings match)."""
    path = folder / f"D{d:g}_s{seed}.json"
    settings = {"D": d, "seed": seed, "levels": list(levels)}
    if path.is_file():
        old = json.loads(path.read_text())
        if old.get("settings") == settings:
            return old
    surface = rmd_profile(9, d, 1e-3, rng=seed, rms_height=1e-6)
    pressures = study_pressures(surface)
    c0 = time.process_time()
    values = {q: [] for q in QUANTITIES}
    for r in levels:
        s = refined(surface, r)
        sweep = contact_sweep(mirrored_profile(s), MATERIAL, pressures=load_window(pressures),
                              kernel="spectral")
        got = window_quantities(sweep, s.shape[0])
        for q in QUANTITIES:
            values[q].append(got[q])
    out = {"settings": settings, "pressures": pressures.tolist(), "values": values,
           "cpu_seconds": time.process_time() - c0}
    write_json(path, out)
    return out


def estimates(values) -> dict:
    """The limit and uncertainty claimed by ``current``
    (:func:`roughfe.validation.richardson`: the floor of 1.25x the larger of the last two
    differences), by ``floor3`` (the floor of 3x adopted by the first two protocols) and
    by ``roache``, the grid convergence index alone as it was before session 43 (a
    quarter of the extrapolation step when asymptotic, 3x the last difference
    otherwise). Each: ``(branch, limit, uncertainty)``."""
    est = richardson(values)
    q = np.asarray(values, float)
    branch = "asymptotic" if est.asymptotic else "fallback"
    quarter = (SAFETY_OBSERVED - 1.0) * abs(q[-1] - est.limit) if est.asymptotic else 0.0
    gci = quarter if est.asymptotic else SAFETY_FALLBACK * abs(q[-1] - q[-2])
    floor3 = max(quarter, SAFETY_FALLBACK * float(np.abs(np.diff(q)[-2:]).max()))
    return {"current": (branch, est.limit, est.uncertainty),
            "floor3": (branch, est.limit, floor3), "roache": (branch, est.limit, gci)}


def judge_sequence(q_levels) -> dict:
    """Estimates from :data:`ESTIMATE_LEVELS`, the reference and its uncertainty from
    :data:`REFERENCE_LEVELS`, and every estimator's limit claim judged; the current
    estimator's per-level claim too."""
    q = dict(zip(ESTIMATE_LEVELS + REFERENCE_LEVELS, map(float, q_levels)))
    values = [q[r] for r in ESTIMATE_LEVELS]
    ref = q[REFERENCE_LEVELS[-1]]
    u_ref = max(abs(q[256] - q[128]), abs(q[128] - q[64]))
    est = richardson(values)
    out = {"reference": ref, "reference_error": u_ref, "order": est.order,
           "levels": judge_richardson(est, ref, u_ref)["levels"]}
    for name, (branch, limit, unc) in estimates(values).items():
        out[name] = {"branch": branch, "limit": limit, "uncertainty": unc,
                     "claim": judge_claim(abs(ref - limit), unc, u_ref)}
    return out


def tally(judged, estimator: str, branch: str, claim=None) -> dict:
    """Counts of covered / missed / undecided of ``estimator``'s limit claim (or of the
    current estimator's per-level claim, ``claim="levels"``) in ``branch``."""
    got = [j["levels"] if claim == "levels" else j[estimator]["claim"] for j in judged
           if j[estimator]["branch"] == branch]
    counts = {k: got.count(k) for k in ("covered", "missed", "undecided")}
    decided = counts["covered"] + counts["missed"]
    counts["rate"] = counts["covered"] / decided if decided else float("nan")
    counts["decided"] = decided
    # sharpness: the median of |reference - limit| / U (1: as wide as the error; << 1 wide)
    ratios = [abs(j["reference"] - j[estimator]["limit"]) / j[estimator]["uncertainty"]
              for j in judged if j[estimator]["branch"] == branch
              and j[estimator]["uncertainty"] > 0 and claim is None]
    counts["median_ratio"] = float(np.median(ratios)) if ratios else float("nan")
    return counts


def calibrated_row(name: str, counts: dict, target: bool = True) -> Target:
    """A row: calibrated when >= CALIBRATED of >= MIN_DECIDED decided claims hold
    (``target`` False: reported, not a target)."""
    rate = counts["rate"]
    ok = counts["decided"] >= MIN_DECIDED and rate >= CALIBRATED
    measured = (f"{counts['covered']} covered, {counts['missed']} missed, "
                f"{counts['undecided']} undecided: "
                + (f"{rate:.1%} of the decided" if counts["decided"] else "none decided"))
    criterion = f">= {CALIBRATED:.0%} covered of >= {MIN_DECIDED} decided"
    if not target:
        return Target(name, criterion, measured, None, "reported, not a target", rate)
    if counts["decided"] < MIN_DECIDED:
        return Target(name, criterion, measured, None,
                      f"only {counts['decided']} decided: not judged", rate)
    return Target(name, criterion, measured, ok, "", rate)


def study_sequence(folder: Path) -> dict:
    """fem_convergence's own RMD BEM sequence at its highest load, to r = 256."""
    lv = profile_levels(STUDY_RMD["D"], STUDY_RMD["seed"], ESTIMATE_LEVELS + REFERENCE_LEVELS,
                        folder)
    q = [v[STUDY_RMD["load_index"]] for v in lv["values"]["area"]]
    return {"pressure": lv["pressures"][STUDY_RMD["load_index"]], "area": q,
            **judge_sequence(q)}


def judge_set(profiles, folder: Path, label: str) -> list:
    judged = []
    for k, (d, seed) in enumerate(profiles):
        lv = profile_levels(d, seed, ESTIMATE_LEVELS + REFERENCE_LEVELS, folder)
        print(f"{label} [{k + 1}/{len(profiles)}] D {d:g} seed {seed}: "
              f"{lv['cpu_seconds']:.0f} s CPU", flush=True)
        for q in QUANTITIES:
            for i in range(len(lv["pressures"])):
                j = judge_sequence([v[i] for v in lv["values"][q]])
                judged.append({"set": label, "D": d, "seed": seed, "quantity": q,
                               "load_index": i, **j})
    return judged


def main(outdir) -> bool:
    outdir = Path(outdir)
    folder = outdir / "richardson_calibration_profiles"
    folder.mkdir(parents=True, exist_ok=True)
    sets = {"first": judge_set(PROFILES, folder, "first"),
            "fresh": judge_set(FRESH_PROFILES, folder, "fresh"),
            "third": judge_set(THIRD_PROFILES, folder, "third")}
    counts = {(s, e, b, c): tally(sets[s], e, b, c) for s in sets
              for e in ("current", "floor3", "roache") for b in ("asymptotic", "fallback")
              for c in (None, "levels") if c is None or e == "current"}
    rows = []
    for s, what in (("first", "24 profiles of the first protocol; fitted"),
                    ("fresh", "24 profiles of the second protocol; fitted"),
                    ("third", "24 test profiles of the third protocol")):
        for b in ("asymptotic", "fallback"):
            rows.append(calibrated_row(f"{b} branch, limit within its uncertainty ({what})",
                                       counts[s, "current", b, None]))
    for e, what in (("floor3", "floor 3x (protocols 1-2)"),
                    ("roache", "Roache's GCI alone (before session 43)")):
        for s in ("first", "fresh", "third"):
            for b in ("asymptotic", "fallback"):
                rows.append(calibrated_row(f"{what}, {b} branch, {s} profiles",
                                           counts[s, e, b, None], target=False))
    study = study_sequence(folder)
    judged = sets["first"] + sets["fresh"] + sets["third"]
    write_json(outdir / "richardson_calibration.json",
               {"name": "richardson_calibration", "targets": [t.to_dict() for t in rows],
                "profiles": [list(p) for p in PROFILES],
                "fresh_profiles": [list(p) for p in FRESH_PROFILES],
                "third_profiles": [list(p) for p in THIRD_PROFILES],
                "estimate_levels": ESTIMATE_LEVELS, "reference_levels": REFERENCE_LEVELS,
                "counts": [{"set": s, "estimator": e, "branch": b, "claim": c or "limit", **v}
                           for (s, e, b, c), v in counts.items()],
                "sequences": judged, "study_rmd_1744": study})
    write_report(outdir, rows, counts, judged, study)
    return all(t.met for t in rows if t.met is not None)


def write_report(outdir: Path, rows, counts, judged, study) -> None:
    lines = ["# Calibration of the Richardson uncertainty", "",
             f"{len(judged)} BEM sequences ({len(judged) // 9} RMD profiles "
             f"x 3 loads x {len(QUANTITIES)} quantities), estimate from r = {ESTIMATE_LEVELS}, "
             f"reference r = {REFERENCE_LEVELS[-1]} (protocols: "
             "docs/validation/fem-convergence.md).", "",
             targets_markdown(rows), "",
             "| set | estimator | claim | branch | covered | missed | undecided | "
             "covered of decided | median \\|ref - limit\\| / U |",
             "|---|---|---|---|---|---|---|---|---|"]
    for (s, e, b, c), v in counts.items():
        lines.append(f"| {s} | {e} | {c or 'limit'} | {b} | {v['covered']} | {v['missed']} | "
                     f"{v['undecided']} | {v['rate']:.1%} | {v['median_ratio']:.3f} |")
    lines += ["", "Missed limit claims of the current estimator (|reference - limit| / U):",
              "", "| set | D | seed | quantity | load | branch | order | ratio |",
              "|---|---|---|---|---|---|---|---|"]
    for j in judged:
        c = j["current"]
        if c["claim"] == "missed":
            ratio = abs(j["reference"] - c["limit"]) / c["uncertainty"] if c["uncertainty"] \
                else float("inf")
            lines.append(f"| {j['set']} | {j['D']:g} | {j['seed']} | {j['quantity']} | "
                         f"{j['load_index']} | {c['branch']} | {j['order']:.2f} | "
                         f"{ratio:.2f} |")
    c = study["current"]
    lines += ["", f"fem_convergence's RMD profile, BEM A* at {study['pressure'] / 1e6:.1f} MPa, "
              f"r = {ESTIMATE_LEVELS + REFERENCE_LEVELS}: "
              + ", ".join(f"{v:.6f}" for v in study["area"])
              + f"; the five-level estimate {c['limit']:.6f} +- {c['uncertainty']:.1e} "
              f"({c['branch']}), the reference {study['reference']:.6f} +- "
              f"{study['reference_error']:.1e}: the limit claim {c['claim']}.", ""]
    write_text(outdir / "richardson_calibration.md", "\n".join(lines))


if __name__ == "__main__":
    sys.exit(0 if main(Path(sys.argv[1] if len(sys.argv) > 1 else "validation/output")) else 1)
