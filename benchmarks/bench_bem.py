"""Speed of the BEM contact solver, against Tamaas' PolonskyKeerRey when importable.

Periodic self-affine surfaces (H = 0.8, unit rms slope, seed 1, L = 1 m, E* = 1 Pa:
everything is dimensionless) at mean pressures p/E* giving A* of about 1 %, 10 %, 20 %,
solved by roughfe (``solver="pk"``: preconditioned Polonsky-Keer CG) and by Tamaas at
the same tolerance on the same heights. Prints the wall time of each, their ratio, the
iteration counts and the relative differences in A* and mean gap; also times a 20-step
sweep of a 512-point profile. The machine's load inflates every time (both codes alike).

    .venv/bin/python benchmarks/bench_bem.py [--sizes 256 512 1024 2048]
        [--pressures 0.005 0.05 0.1] [--tamaas-max 1024] [--tol 1e-10]
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time

import numpy as np

from roughfe.bem import Material, contact_sweep, solve_contact
from roughfe.surfaces.spectral import spectral_profile, spectral_surface


def _tamaas(heights, pressure, tol):
    try:
        import tamaas as tm
    except ImportError:
        return None
    n = heights.shape[0]
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [1.0, 1.0], [n, n])
    model.E, model.nu = 1.0, 0.0
    solver = tm.PolonskyKeerRey(model, np.array(heights, order="C"), tol)
    # Tamaas logs its iterations on stderr: catch fd 2 to count them
    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile(mode="w+") as log:
        os.dup2(log.fileno(), 2)
        try:
            t0 = time.perf_counter()
            solver.solve(pressure)
            elapsed = time.perf_counter() - t0
        finally:
            sys.stderr.flush()
            os.dup2(saved, 2)
            os.close(saved)
        log.seek(0)
        rows = [ln.split() for ln in log.read().splitlines()]
    its = [int(r[0]) for r in rows if r and r[0].isdigit()]
    nit = its[-1] if its else None
    p = np.array(model.traction, copy=True).reshape(heights.shape)
    gap = np.array(model["gap"], copy=True).reshape(heights.shape) if "gap" in model else None
    return elapsed, float((p > 0).mean()), (float(gap.mean()) if gap is not None else np.nan), nit


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[256, 512, 1024, 2048])
    ap.add_argument("--pressures", type=float, nargs="+", default=[0.005, 0.05, 0.1])
    ap.add_argument("--tamaas-max", type=int, default=1024,
                    help="largest n for which Tamaas is run too (it is slow at 2048^2)")
    ap.add_argument("--tol", type=float, default=1e-10)
    args = ap.parse_args(argv)
    mat = Material(1.0, 0.0)
    print(f"{'n':>5s} {'p/E*':>7s} {'A*':>7s} {'roughfe s':>10s} {'nit':>5s} "
          f"{'tamaas s':>9s} {'t-nit':>5s} {'ratio':>6s} {'dA*/A*':>9s} {'dgap/gap':>9s}",
          flush=True)
    for n in args.sizes:
        surf = spectral_surface(n, 1.0, 0.8, rms_slope=1.0, rng=1)
        for pm in args.pressures:
            t0 = time.perf_counter()
            r = solve_contact(surf, mat, mean_pressure=pm, solver="pk", tol=args.tol,
                              compute_stiffness=False)
            t_r = time.perf_counter() - t0
            tm = _tamaas(surf.heights, pm, args.tol) if n <= args.tamaas_max else None
            if tm is None:
                print(f"{n:5d} {pm:7.3f} {r.area_fraction:7.4f} {t_r:10.2f} {r.nit:5d}",
                      flush=True)
                continue
            t_t, a_t, g_t, nit_t = tm
            print(f"{n:5d} {pm:7.3f} {r.area_fraction:7.4f} {t_r:10.2f} {r.nit:5d} "
                  f"{t_t:9.2f} {nit_t if nit_t is not None else -1:5d} {t_r / t_t:6.2f} {abs(r.area_fraction / a_t - 1):9.1e} "
                  f"{abs(r.mean_gap / g_t - 1):9.1e}", flush=True)
    prof = spectral_profile(512, 1e-3, 0.8, rms_height=1e-6, rng=3)
    best = np.inf
    for _ in range(3):
        t0 = time.perf_counter()
        sw = contact_sweep(prof, Material(1e9, 0.3), n_steps=20)
        best = min(best, time.perf_counter() - t0)
    print(f"512-point periodic profile, 20-step sweep with exact stiffness: {best:.3f} s "
          f"(best of 3, solver {sw.results[0].solver}, {sw.nit} pivoting steps)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
