"""FEM vs BEM by convergence: refinement study of both methods.

Run: ``roughfe validate fem`` (with ``bem_vs_fem.py``) or ``python validation/fem_convergence.py
OUTDIR [--profile NAME] [--resume]``; writes ``<outdir>/fem_convergence.md``,
``fem_convergence.json`` and ``fem_convergence_<profile>.png``. Every level is also written
to ``<outdir>/fem_convergence_levels/<profile>_r<r>.json`` as it finishes; ``--resume``
reuses those of the same settings (r = 8 costs tens of CPU minutes), so the two profiles
can run as two processes and be assembled by a last run with ``--resume``.

Question: do the FEM (dolfinx, SNES VI) and the BEM (periodic plane-strain, spectral
kernel, mirrored profile) converge to the same contact solution of the same geometry, and
is their difference at every resolution explained by their own discretisation errors?

Geometry: the piecewise-linear profile through the samples of the thesis Table 1 genome
(10x, 512 nodes) and of the RMD profile (D = 1.5, 513 nodes) of ``bem_vs_fem.py``. Level
r = 1, 2, 4, 8 samples that same polyline r times finer (the profile is not re-generated:
the geometry is fixed, only its discretisation is refined):

* BEM: grid spacing dx / r on the mirrored polyline;
* FEM: every element size divided by r: top elements dx / r, growth with depth
  ``GROWTH_1 / r`` (size(d) = (dx + GROWTH_1 d) / r), depth H_d = 2 W unchanged.

Both are load-controlled at the same three mean pressures p (those of the native BEM at
Delta = 0.5, 0.7, 0.9 of max h - mean h) and at p (1 -+ K_WINDOW), so A*, K and the mean
gap (Eq. 2.8) are compared at equal load. A* is the contact length with sub-element
edges (``roughfe.fem.contact_length``) / W.

K is the window stiffness K = -(p+ - p-) / (g(p+) - g(p-)) over p+- = p (1 -+ 5 %), the
tangent dp/dDelta (Eq. 2.7) averaged over that load window (Delta = const - mean gap in
load control). The tangent itself (exact incremental, frozen contact set) is reported but
not gated, because at few contact patches it is not a converged quantity of the
continuum problem at an arbitrary load. Measured on the Table 1 profile (BEM, periodic
plane strain, r up to 64): the lowest study load (161.6 MPa) lies within 1 % of the load
at which one more asperity (a polyline vertex at x = 612.5 um) touches; across that 1 %
the tangent K jumps by 3 % (7.54 -> 7.77e14 Pa/m at r = 64; 10 % at another onset 4 %
lower). In plane strain a patch of width a adds a stiffness ~ 1 / ln(L / a), which
vanishes only logarithmically as a -> 0, so a one-node patch (a = dx / r) at an onset
carries a stiffness the continuum patch (a << dx / r) does not have, and the tangent
converges like 1 / ln r: BEM 7.458 / 7.838 / 7.787 / 7.777 / 7.767e14 at r = 4 / 8 / 16 /
32 / 64 (the vertex enters contact at r = 8, the FEM's not yet at r = 8: FEM/BEM - 1 =
-2.74 % there). A one-sided 1 % perturbation of the load (or of the discretisation) moves
the tangent by more than the 1 % target, in both methods. The window stiffness at the same
load converges: BEM 7.557 / 7.596 / 7.610 / 7.612 / 7.613e14 (r = 4 ... 64), and it is
the same tangent averaged over a load range where a measurement would take it.

For every method, quantity and load: observed orders and the Richardson limit of the
finest three levels (``roughfe.validation.richardson``; fallback when not asymptotic: the
finest value; the uncertainty at least 1.25x the larger of the last two differences in both
branches since round 2, session 43, calibrated by ``richardson_calibration.py``), and the
estimated discretisation error of every level, |Q_r - Q_lim| + uncertainty.

Targets (met / NOT met): per profile, the FEM and BEM limits agree within 1 % (A*) and
1 % (window K) at every load; at every r the FEM-BEM difference of A*, window K and mean
gap is within the sum of the two estimated discretisation errors. The tangent K rows of
the report are information.

Resuming an interrupted level: while a level's FEM runs, its finished loads are
checkpointed after every load (of the nine window loads) in
``fem_convergence_levels/<profile>_r<r>.fem-partial.npz`` (:mod:`roughfe.fem.checkpoint`,
written atomically): the finished loads' results and the displacement field the next
load starts its Newton from (every load is warm-started from the previous one), with the
DOF layout, loads, guesses and solver options it belongs to. ``--resume`` continues an
unfinished level after its last finished load, with results equal bit for bit to an
uninterrupted run's (the BEM half and the mesh are recomputed: seconds); a run without
``--resume`` deletes the file and starts the level afresh. The file is removed once the
level file is written; a level counts as finished only by its ``.json`` file.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _fem_cases import MATERIAL, rmd_profile_case, table1_profile  # noqa: E402
from _refinement import (FRACTIONS, K_WINDOW, load_window, refined,  # noqa: E402
                         study_pressures, window_quantities)

from roughfe.bem import contact_sweep  # noqa: E402
from roughfe.fem import fem_contact_sweep, mesh_profile, mirrored_profile  # noqa: E402
from roughfe.fem.checkpoint import SweepCheckpoint  # noqa: E402
from roughfe.plotting.common import new_figure, save_figure  # noqa: E402
from roughfe.surfaces import Surface  # noqa: E402
from roughfe.validation import Target, percent, richardson, targets_markdown  # noqa: E402
from roughfe.writers import write_json, write_text  # noqa: E402

LEVELS = (1, 2, 4, 8)
GROWTH_1 = 0.2                 # element-size growth with depth at r = 1 (divided by r)
QUANTITIES = {"area": "A* (sub-element edges)",
              "stiffness": "K = -dp/d(mean gap) over p (1 -+ 5 %)",
              "mean_gap": "mean gap",
              "stiffness_tangent": "tangent K = dp/dDelta (information)"}
LIMIT_TARGETS = {"area": 0.01, "stiffness": 0.01}
#: gated at every level (the tangent K is reported, not gated: see the module docstring)
LEVEL_TARGETS = ("area", "stiffness", "mean_gap")
#: the per-load checkpoint of an unfinished level: ``<profile>_r<r>`` + this suffix, beside
#: the finished level files ``<profile>_r<r>.json`` (see the module docstring)
PARTIAL_SUFFIX = ".fem-partial.npz"


def level(surface: Surface, r: int, pressures, guesses=None, checkpoint=None) -> dict:
    """BEM and FEM at refinement r, solved at :func:`load_window` of ``pressures``: A*,
    K (window secant and tangent), mean gap at ``pressures``.

    ``guesses``: imposed FEM approaches of a coarser level (one per window load) to start
    the load control from. ``checkpoint``: the FEM sweep's per-load checkpoint file
    (:mod:`roughfe.fem.checkpoint`; resumed when it holds finished loads of this level);
    the FEM ``cpu_seconds`` then include the CPU seconds of the resumed loads.
    """
    s = refined(surface, r)
    n = s.shape[0]
    loads = load_window(pressures)
    out = {"r": r, "n_nodes": n}
    c0, t0 = time.process_time(), time.perf_counter()
    bem = contact_sweep(mirrored_profile(s), MATERIAL, pressures=loads, kernel="spectral")
    out["bem"] = {**window_quantities(bem, n), "cpu_seconds": time.process_time() - c0}
    c0 = time.process_time()
    pm = mesh_profile(s, growth=GROWTH_1 / r)
    c_mesh = time.process_time() - c0
    ckpt = None if checkpoint is None else SweepCheckpoint(checkpoint)
    fem = fem_contact_sweep(pm, MATERIAL, pressures=loads, guesses=guesses, checkpoint=ckpt)
    if ckpt is not None and (ckpt.resumed_steps or ckpt.not_used):
        print(f"[fem convergence] r = {r}: " + (
            f"FEM resumed after load {ckpt.resumed_steps} of {loads.size} from {ckpt.path}"
            if ckpt.resumed_steps else f"{ckpt.path} not used: {ckpt.not_used}"), flush=True)
    out["fem"] = {**window_quantities(fem, n), "delta_applied": fem.delta_applied.tolist(),
                  "snes_iterations": [int(x.nit) for x in fem.results],
                  "n_cells": pm.n_cells, "growth": GROWTH_1 / r, "cpu_seconds_mesh": c_mesh,
                  "cpu_seconds": time.process_time() - c0
                  + (ckpt.resumed_cpu_seconds if ckpt else 0.0)}
    out["wall_seconds"] = time.perf_counter() - t0
    return out


def analyse(levels: list) -> dict:
    """Richardson per method, quantity and load; FEM-BEM differences per level."""
    n_loads = len(levels[0]["bem"]["area"])
    ratio = levels[1]["r"] / levels[0]["r"]
    out = {}
    for q in QUANTITIES:
        per_load = []
        for k in range(n_loads):
            rich = {m: richardson([lv[m][q][k] for lv in levels], ratio) for m in ("bem", "fem")}
            diff = [abs(lv["fem"][q][k] - lv["bem"][q][k]) for lv in levels]
            allowed = [eb + ef for eb, ef in zip(rich["bem"].errors, rich["fem"].errors)]
            per_load.append({
                "bem": rich["bem"].to_dict(), "fem": rich["fem"].to_dict(),
                "limit_rel_diff": rich["fem"].limit / rich["bem"].limit - 1,
                "limit_diff_within_uncertainty": bool(
                    abs(rich["fem"].limit - rich["bem"].limit)
                    <= rich["fem"].uncertainty + rich["bem"].uncertainty),
                "level_abs_diff": diff, "level_allowed": allowed,
                "level_rel_diff": [lv["fem"][q][k] / lv["bem"][q][k] - 1 for lv in levels],
                "level_within": [bool(d <= a) for d, a in zip(diff, allowed)]})
        out[q] = per_load
    return out


def profile_targets(name: str, analysis: dict, levels: list) -> list:
    rows = []
    rs = ", ".join(str(lv["r"]) for lv in levels)
    for q, limit in LIMIT_TARGETS.items():
        rel = [a["limit_rel_diff"] for a in analysis[q]]
        worst = max(rel, key=abs)
        fallback = [m for a in analysis[q] for m in ("bem", "fem") if not a[m]["asymptotic"]]
        reason = (f"Richardson limits of r = {rs}, worst of {len(rel)} loads"
                  + (f"; {len(fallback)} of {2 * len(rel)} sequences not asymptotic "
                     "(finest value used)" if fallback else ""))
        rows.append(Target(f"{name}: {QUANTITIES[q]} limits FEM vs BEM",
                           f"<= {percent(limit, 0)}", percent(worst, 3),
                           bool(abs(worst) <= limit), reason, worst))
    for q in LEVEL_TARGETS:
        bad = [(levels[i]["r"], k) for k, a in enumerate(analysis[q])
               for i, ok in enumerate(a["level_within"]) if not ok]
        ratio = max(d / a if a > 0 else np.inf for x in analysis[q]
                    for d, a in zip(x["level_abs_diff"], x["level_allowed"]))
        rows.append(Target(
            f"{name}: {QUANTITIES[q]} FEM-BEM difference within the discretisation errors",
            "every r: |F - B| <= e_F + e_B", f"max |F - B| / (e_F + e_B) = {ratio:.2f}",
            not bad, ("all levels and loads" if not bad else
                      "exceeded at (r, load) " + ", ".join(f"({r}, {k})" for r, k in bad)),
            ratio))
    return rows


def plot_convergence(name: str, pressures, levels: list, analysis: dict, path: Path):
    r = np.array([lv["r"] for lv in levels], float)
    fig, axes = new_figure(ncols=len(QUANTITIES), figsize=(4.2 * len(QUANTITIES), 3.8))
    for ax, q in zip(np.atleast_1d(axes), QUANTITIES):
        for k, a in enumerate(analysis[q]):
            for m, style in (("bem", "o-"), ("fem", "s--")):
                lim = a[m]["limit"]
                err = np.abs(np.array(a[m]["values"]) / lim - 1)
                ax.loglog(r, np.maximum(err, 1e-8), style, color=f"C{k}",
                          label=f"{m.upper()} p = {pressures[k] / 1e6:.3g} MPa")
        ax.loglog(r, 0.05 / r, "k:", label="order 1")
        ax.set_xlabel("refinement r")
        ax.set_ylabel(f"|Q_r / Q_lim - 1|, Q = {QUANTITIES[q]}")
    np.atleast_1d(axes)[0].legend(fontsize=6)
    fig.suptitle(f"{name}: convergence under refinement (own Richardson limit)")
    save_figure(fig, path)


def write_report(outdir: Path, cases: dict, rows: list) -> Path:
    L = ["# FEM vs BEM by convergence\n",
         "Generated by `validation/fem_convergence.py` (`roughfe validate fem`). " +
         __doc__.split("\n\n", 2)[2].split("Targets (met")[0].replace("``", "`"), "",
         "## Targets\n", targets_markdown(rows)]
    for name, c in cases.items():
        L.append(f"## {name}\n")
        L.append("| r | nodes | FEM cells | FEM SNES its | CPU s BEM / FEM (mesh) |")
        L.append("|---|---|---|---|---|")
        for lv in c["levels"]:
            L.append(f"| {lv['r']} | {lv['n_nodes']} | {lv['fem']['n_cells']} | "
                     f"{lv['fem']['snes_iterations']} | {lv['bem']['cpu_seconds']:.1f} / "
                     f"{lv['fem']['cpu_seconds']:.1f} ({lv['fem']['cpu_seconds_mesh']:.1f}) |")
        L.append("")
        for q, label in QUANTITIES.items():
            L.append(f"### {label}\n")
            L.append("| p (MPa) | method | " + " | ".join(f"r = {lv['r']}" for lv in c["levels"])
                     + " | orders | limit | uncertainty | limit FEM/BEM - 1 |")
            L.append("|---|---|" + "---|" * len(c["levels"]) + "---|---|---|---|")
            for k, a in enumerate(c["analysis"][q]):
                for m in ("bem", "fem"):
                    rr = a[m]
                    orders = ", ".join("n/a" if o is None else f"{o:.2f}" for o in rr["orders"])
                    tail = percent(a["limit_rel_diff"], 3) if m == "fem" else ""
                    L.append(f"| {c['pressures'][k] / 1e6:.4g} | {m.upper()} | "
                             + " | ".join(f"{v:.6g}" for v in rr["values"])
                             + f" | {orders}{'' if rr['asymptotic'] else ' (fallback)'} | "
                             f"{rr['limit']:.6g} | {rr['uncertainty']:.2g} | {tail} |")
                L.append(f"| | FEM/BEM - 1 | " + " | ".join(
                    f"{100 * d:+.3f} %{'' if ok else ' (!)'}" for d, ok in
                    zip(a["level_rel_diff"], a["level_within"])) + " | | | | |")
            L.append("")
        L.append(f"![convergence](fem_convergence_{name}.png)\n")
    return write_text(outdir / "fem_convergence.md", "\n".join(L) + "\n")


PROFILES = {"table1_10x": table1_profile, "rmd": rmd_profile_case}


def _settings(name: str, r: int, pressures) -> dict:
    return {"profile": name, "r": r, "growth_r1": GROWTH_1, "k_window": K_WINDOW,
            "pressures": list(map(float, pressures))}


def profile_levels(store: Path, name: str, surface: Surface, pressures, levels,
                   resume: bool = False) -> list:
    """The levels of one profile, each solved (and written to ``store``) or, with
    ``resume``, read from its level file of the same settings; an unfinished level
    resumes from its per-load checkpoint (see the module docstring)."""
    lv = []
    for r in levels:
        path = store / f"{name}_r{r}.json"
        settings = _settings(name, r, pressures)
        old = json.loads(path.read_text()) if resume and path.is_file() else None
        if old is not None and old.get("settings") == settings:
            lv.append(old["level"])
            print(f"[fem convergence] {name} r = {r}: reused {path}", flush=True)
            continue
        partial = store / f"{name}_r{r}{PARTIAL_SUFFIX}"
        if not resume:
            partial.unlink(missing_ok=True)     # a fresh run does not resume loads
        lv.append(level(surface, r, pressures, lv[-1]["fem"]["delta_applied"] if lv else None,
                        checkpoint=partial))
        write_json(path, {"settings": settings, "level": lv[-1]})
        partial.unlink(missing_ok=True)
        print(f"[fem convergence] {name} r = {r}: A* BEM {lv[-1]['bem']['area']} "
              f"FEM {lv[-1]['fem']['area']} ({lv[-1]['wall_seconds']:.0f} s wall, FEM "
              f"{lv[-1]['fem']['cpu_seconds']:.0f} s CPU)", flush=True)
    return lv


def run(outdir: Path, levels=LEVELS, profiles=None, resume: bool = False) -> tuple[bool, list]:
    """The study; returns (all targets met, target rows). ``resume``: reuse the level files
    of the same settings and resume an unfinished level (see the module docstring)."""
    outdir = Path(outdir)
    store = outdir / "fem_convergence_levels"
    store.mkdir(parents=True, exist_ok=True)
    cases, rows = {}, []
    for name in profiles or PROFILES:
        surf = PROFILES[name]()
        pressures = study_pressures(surf)
        lv = profile_levels(store, name, surf, pressures, levels, resume)
        analysis = analyse(lv)
        cases[name] = {"pressures": pressures.tolist(), "levels": lv, "analysis": analysis}
        rows += profile_targets(name, analysis, lv)
        plot_convergence(name, pressures, lv, analysis, outdir / f"fem_convergence_{name}.png")
    ok = all(t.met for t in rows)
    write_json(outdir / "fem_convergence.json",
               {"name": "fem_convergence", "targets": [t.to_dict() for t in rows],
                "levels": list(levels), "growth_r1": GROWTH_1, "fractions": list(FRACTIONS),
                "k_window": K_WINDOW,
                "cases": cases})
    write_report(outdir, cases, rows)
    return ok, rows


def run_parallel(outdir: Path, profiles, resume: bool = False, levels=LEVELS) -> None:
    """Run every profile as its own process (this script with ``--profile``; each writes
    its level files), at most ``os.cpu_count()`` at a time. Raises when one fails
    (exit status other than 0 = met / 1 = NOT met, e.g. 3 = raised)."""
    import roughfe
    env = dict(os.environ)
    root = str(Path(roughfe.__file__).resolve().parents[1])   # the same roughfe in the children
    env["PYTHONPATH"] = os.pathsep.join(x for x in (root, env.get("PYTHONPATH")) if x)
    todo, running = list(profiles), []
    while todo or running:
        while todo and len(running) < max(1, os.cpu_count() or 1):
            name = todo.pop(0)
            cmd = [sys.executable, str(Path(__file__).resolve()), str(outdir), "--profile", name,
                   "--levels", *map(str, levels)]
            running.append((name, subprocess.Popen(cmd + (["--resume"] if resume else []),
                                                   env=env)))
        name, proc = running.pop(0)
        if proc.wait() not in (0, 1):
            for _, other in running:
                other.kill()
            raise RuntimeError(f"fem_convergence --profile {name} failed with exit status "
                               f"{proc.returncode} (its output is above)")


def main(outdir, resume: bool = False) -> bool:
    """The study (``roughfe validate fem``). With more than one CPU the profiles run as
    parallel processes (:func:`run_parallel`); this process then assembles their levels."""
    outdir = Path(outdir)
    if len(PROFILES) > 1 and (os.cpu_count() or 1) > 1:
        (outdir / "fem_convergence_levels").mkdir(parents=True, exist_ok=True)
        run_parallel(outdir, list(PROFILES), resume)
        resume = True
    return run(outdir, resume=resume)[0]


if __name__ == "__main__":
    import argparse
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("outdir", nargs="?", default="validation/output")
    parser.add_argument("--profile", choices=list(PROFILES), action="append")
    parser.add_argument("--levels", type=int, nargs="+", default=list(LEVELS))
    parser.add_argument("--resume", action="store_true")
    a = parser.parse_args()
    try:
        met = run(Path(a.outdir), tuple(a.levels), a.profile, a.resume)[0]
    except Exception:   # noqa: BLE001 -- exit 3, told apart from 1 = a target NOT met
        import traceback
        traceback.print_exc()
        sys.exit(3)
    sys.exit(0 if met else 1)
