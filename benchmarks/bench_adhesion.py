"""Speed of the adhesive BEM solve (roughfe.bem.adhesion) against the elastic one.

A periodic self-affine surface (H = 0.8, rms height 1 um, L = 0.1 mm, n x n), E = 1 GPa,
nu = 0.3, pressed to a mean-plane separation of 0.5 sigma; the exponential law with
w = 0.01 J/m^2 and rho = 20 nm (sigma0 = 0.5 MPa), and the Maugis-Dugdale law with the same
w and h0 (cell-averaged). For each law and each adhesive solver (``pcg``: the
preconditioned projected nonlinear CG, the default; ``lbfgsb``: L-BFGS-B): the cold solve
at that approach and one warm continuation step (Delta + 1 % sigma, started from the
previous state), timed in process CPU seconds (``time.process_time``, all threads: the
shared machine's other processes do not enter), against the elastic solve_contact
(Polonsky-Keer) at the same approaches, cold and warm, run back to back.
Target (issue 13): adhesive within 3x the elastic time at 512^2 (default solver).
With 512 among the sizes, also the non-periodic solve (the padded torus of the Love
kernel) on the measured topography di-1.di (AFM, 512^2, rms slope 0.77; from the
topographies folder, skipped with the reason when it is missing): the default material
(E* = 210 MPa), both laws with w = 0.05 J/m^2 and range 2 nm, the cold solve at 1/3 of
the peak-to-valley height against the elastic solve_contact there (reported, no target:
docs/theory/07_adhesion_persson.md, "Speed").
Writes benchmarks/output/bench_adhesion.json. Run:
``.venv/bin/python benchmarks/bench_adhesion.py [N ...]`` (default 512).
"""
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

from roughfe.bem import solve_contact
from roughfe.bem.adhesion import SOLVERS, AdhesionLaw, solve_adhesive
from roughfe.model import DEFAULT_E, DEFAULT_NU, Material
from roughfe.surfaces.io import load_surface, topographies_folder
from roughfe.surfaces.spectral import spectral_surface

from _report import script_args, write_report  # benchmarks/_report.py

OUT = Path(__file__).resolve().parent / "output" / "bench_adhesion.json"


def _timed(fn):
    c0 = time.process_time()
    r = fn()
    return r, time.process_time() - c0


def case(n, kind, solver):
    s = spectral_surface(n, 1e-4, 0.8, rms_height=1e-6, rng=1)
    h = s.heights
    mat = Material(1e9, 0.3)
    d1 = float(h.max() - h.mean() - 0.5e-6)
    d2 = d1 + 0.01e-6
    law = AdhesionLaw(kind, 0.01, 20e-9)
    e1, te1 = _timed(lambda: solve_contact(s, mat, delta=d1, compute_stiffness=False))
    e2, te2 = _timed(lambda: solve_contact(s, mat, delta=d2, initial=e1.pressure,
                                           compute_stiffness=False))
    a1, ta1 = _timed(lambda: solve_adhesive(s, mat, law, delta=d1, solver=solver))
    a2, ta2 = _timed(lambda: solve_adhesive(s, mat, law, delta=d2, initial=a1, solver=solver))
    return {"n": n, "law": kind, "solver": solver,
            "area_fraction_elastic": e1.area_fraction,
            "area_fraction_adhesive": a1.area_fraction,
            "mean_pressure_elastic": e1.mean_pressure, "mean_pressure_adhesive": a1.mean_pressure,
            "cpu_elastic_cold": te1, "cpu_elastic_warm": te2, "nit_elastic_cold": e1.nit,
            "cpu_adhesive_cold": ta1, "cpu_adhesive_warm": ta2, "nit_adhesive_cold": a1.nit,
            "nit_adhesive_warm": a2.nit, "ratio_cold": ta1 / te1, "ratio_warm": ta2 / te2}


#: the measured non-periodic case (module docstring)
MEASURED = "di-1.di"


def measured_case(kind):
    """The cold non-periodic solve on ``MEASURED`` with the law ``kind``, against the
    elastic solve at the same approach (process CPU seconds and iterations)."""
    s = load_surface(topographies_folder() / MEASURED)
    mat = Material(DEFAULT_E, DEFAULT_NU)
    d = float(np.ptp(s.heights)) / 3.0
    law = AdhesionLaw(kind, 0.05, 2e-9)
    e, te = _timed(lambda: solve_contact(s, mat, delta=d, compute_stiffness=False))
    a, ta = _timed(lambda: solve_adhesive(s, mat, law, delta=d))
    return {"n": s.shape[0], "surface": MEASURED, "kernel": a.kernel, "law": kind,
            "solver": SOLVERS[0], "area_fraction_elastic": e.area_fraction,
            "area_fraction_adhesive": a.area_fraction, "cpu_elastic_cold": te,
            "cpu_adhesive_cold": ta, "nit_elastic_cold": e.nit, "nit_adhesive_cold": a.nit,
            "ratio_cold": ta / te}


def main(sizes):
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print(f"{'n':>5} {'law':>4} {'solver':>6} {'A* el':>7} {'A* adh':>7} {'el cold':>8} {'adh cold':>9} "
          f"{'ratio':>6} {'el warm':>8} {'adh warm':>9} {'ratio':>6} {'nit el/adh':>11}")
    rows = []
    for n in sizes:
        for kind, solver in [(k, v) for k in ("exp", "md") for v in SOLVERS]:
            r = case(n, kind, solver)
            rows.append(r)
            print(f"{n:>5} {kind:>4} {solver:>6} {r['area_fraction_elastic']:>7.4f} "
                  f"{r['area_fraction_adhesive']:>7.4f} {r['cpu_elastic_cold']:>8.2f} "
                  f"{r['cpu_adhesive_cold']:>9.2f} {r['ratio_cold']:>6.1f} "
                  f"{r['cpu_elastic_warm']:>8.2f} {r['cpu_adhesive_warm']:>9.2f} "
                  f"{r['ratio_warm']:>6.1f} {r['nit_elastic_cold']:>5}/{r['nit_adhesive_cold']:<5}",
                  flush=True)
    targets = [{"name": f"adhesive ({r['law']}, {r['solver']}) / elastic CPU time at "
                        f"{r['n']}^2, {kind} solve",
                "value": r[f"ratio_{kind}"], "target": "<= 3",
                "met": bool(r[f"ratio_{kind}"] <= 3)}
               for r in rows if r["n"] == 512 and r["solver"] == SOLVERS[0]
               for kind in ("cold", "warm")]
    skipped = []
    if 512 in sizes and not (topographies_folder() / MEASURED).exists():
        skipped.append({"name": f"non-periodic {MEASURED}",
                        "reason": f"measured file not found: {topographies_folder() / MEASURED}"})
    elif 512 in sizes:
        print(f"{'surface':>8} {'law':>4} {'kernel':>6} {'A* el':>7} {'A* adh':>7} "
              f"{'el cold':>8} {'adh cold':>9} {'ratio':>6} {'nit el/adh':>11}")
        for kind in ("exp", "md"):
            r = measured_case(kind)
            rows.append(r)
            print(f"{'di-1':>8} {kind:>4} {r['kernel']:>6} {r['area_fraction_elastic']:>7.4f} "
                  f"{r['area_fraction_adhesive']:>7.4f} {r['cpu_elastic_cold']:>8.2f} "
                  f"{r['cpu_adhesive_cold']:>9.2f} {r['ratio_cold']:>6.1f} "
                  f"{r['nit_elastic_cold']:>5}/{r['nit_adhesive_cold']:<5}", flush=True)
            targets.append({"name": f"non-periodic {MEASURED} ({r['kernel']}, {r['n']}^2) "
                                    f"adhesive ({kind}, {r['solver']}) / elastic CPU, cold "
                                    f"solve, {r['nit_adhesive_cold']} / "
                                    f"{r['nit_elastic_cold']} iterations",
                            "value": r["ratio_cold"], "target": "reported", "met": None})
    write_report(OUT, "bench_adhesion", targets, rows, {"cpu_*": "s (process CPU time)"},
                 skipped=skipped)
    return 0


if __name__ == "__main__":
    sys.exit(main(script_args(__doc__)[0] or [512]))
