"""Non-periodic BEM on fast FFT grids (round 2, session 15). Two grids changed:

* the DC-FFT grid of each axis of the product H p is the first length >= 2n - 1 whose FFT
  is fast (``roughfe.bem.operators.padded_length``), not 2n;
* the preconditioner (Strang's circulant) lives on the first fast length >= n
  (``InfluenceOperator.precond_shape``), zero-padded, not on the n-point grid itself.

2n carries every prime factor of n. The thesis' RMD grids have 2**m + 1 points per side
(257 = a prime: 514 = 2 x 257), and instrument files come in any size (563 x 484 in the
shared Digital Surf file). Each case below is one non-periodic surface with the Love kernel
(``kernel="auto"``), taken through a 6-step displacement sweep (``contact_sweep``,
deltas 0.1-0.6 of the peak-to-valley height, tol 1e-10, E = 1 GPa, nu = 0.3). The sweep
runs twice in this process:

* on the fast grids, the production code;
* with ``padded_length`` patched to 2n and ``precond_shape`` to the grid itself, the
  layout before (called "2n" below).

The order of the two alternates over two rounds, and the reported CPU (process CPU time)
is the smaller of the two rounds. The product's padding changes only its rounding and the
preconditioner only the search direction, never the converged answer: the two give the
same contact areas and pressures, with different iteration counts (the preconditioner).

Targets of a case:

* the fast grids are not slower: CPU(2n) / CPU(fast) >= 0.95 (1 within the scatter of
  the CPU timer), per case where the layouts differ (a grid whose n is already a fast
  length, e.g. 512 or 640 points, has one layout only and is skipped, saying so);
* the same answer: the largest difference in A* is 0, and the loads agree to
  ``SAME_LOAD`` = 1e-8 relative. The two are independent solves to a relative KKT
  residual of 1e-10 that take different search directions, so their loads differ at
  that level (measured: up to 8.1e-10 on sur-2), not at the rounding of one product;
* the mean speed-up over the cases is recorded, with no target.

The measured files come from ``../shared/data/topographies`` (``ROUGHFE_TOPOGRAPHIES``
overrides the folder); a file that is missing is skipped, and the report says so.

Usage::

    .venv/bin/python benchmarks/bench_bem_padding.py [--quick]

``--quick``: the RMD 129^2 and 257^2 cases only (a few seconds). Writes
``benchmarks/output/bench_bem_padding.json``.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from _cases import (TOPOGRAPHIES, paired_runs, paired_targets,  # noqa: E402
                    surface_of)  # benchmarks/_cases.py
from _report import write_report  # noqa: E402  (benchmarks/_report.py)

TOL = 1e-10
#: the fast grid is "not slower" when CPU(2n) / CPU(fast) >= this: 1 within the ~5 %
#: scatter of process CPU times of one sweep on this machine (set before measuring)
NOT_SLOWER = 0.95
SAME_LOAD = 1e-8     #: the loads of the two layouts, relative difference at most
STEPS = tuple(np.linspace(0.1, 0.6, 6))


def sweep(surface, double):
    """CPU, iterations, A* and loads of the 6-step sweep; ``double``: 2n padding."""
    from roughfe.bem import Material, contact_sweep, operators
    fast, pshape = operators.padded_length, operators.InfluenceOperator.precond_shape
    if double:
        operators.padded_length = lambda n, real=True: 2 * int(n)
        operators.InfluenceOperator.precond_shape = property(lambda op: op.shape)
    clear_operator_cache()           # an operator of the other layout must not be reused
    try:
        deltas = tuple(s * float(np.ptp(surface.heights)) for s in STEPS)
        c0 = time.process_time()
        sw = contact_sweep(surface, Material(1e9, 0.3), deltas=deltas, tol=TOL,
                           compute_stiffness=False)
        cpu = time.process_time() - c0
    finally:
        operators.padded_length = fast
        operators.InfluenceOperator.precond_shape = pshape
        clear_operator_cache()
    return {"cpu_s": cpu, "nit": [int(r.nit) for r in sw.results],
            "A*": [float(r.area_fraction) for r in sw.results],
            "mean_pressure": [float(r.mean_pressure) for r in sw.results]}


def _fast(shape):
    """Whether every axis of ``shape`` is its own fast FFT length (the preconditioner's grid
    is then the grid itself)."""
    from roughfe.bem.operators import fast_length
    last = len(shape) - 1
    return all(fast_length(n, real=a == last) == n for a, n in enumerate(shape))


def clear_operator_cache():
    """Forget the cached operators, so that the next sweep builds its own layout."""
    from roughfe.bem import contact
    for cached in (contact._operator, contact._inverse_spectrum, contact._inverse_spectrum32):
        cached.cache_clear()


def run_case(case):
    """The two sweeps of one case, or the reason it was not timed (a str)."""
    from roughfe.bem.operators import padded_length
    surface = surface_of(case)
    if surface is None:
        return f"not found in {TOPOGRAPHIES}"
    padded = [padded_length(n, real=k == surface.ndim - 1) for k, n in enumerate(surface.shape)]
    if padded == [2 * n for n in surface.shape] and _fast(surface.shape):
        return (f"{surface.shape[0]} x {surface.shape[1]}: n and 2n are already fast "
                f"lengths (the same grids), nothing to compare")
    return {"case": f"{case[0]} {case[1]}", "shape": list(surface.shape), "padded": padded,
            **paired_runs(lambda mode: sweep(surface, mode == "2n"), "fast", "2n")}

def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="RMD 129^2 and 257^2 only")
    ap.add_argument("--output", type=Path, default=HERE / "output" / "bench_bem_padding.json")
    args = ap.parse_args(argv)
    cases = [("rmd", 7), ("rmd", 8)]
    if not args.quick:
        cases += [("rmd", 9), ("file", "sur-2.sur"), ("file", "x3p-2.x3p"),
                  ("file", "opd-1.opd"), ("file", "plu-1.plu"), ("file", "di-1.di")]
    rows, targets, skipped = [], [], []
    for case in cases:
        r = run_case(case)
        if isinstance(r, str):
            skipped.append({"name": f"{case[0]} {case[1]}", "reason": r})
            print(f"{case[0]} {case[1]}: skipped, {r}", flush=True)
            continue
        rows.append(r)
        print(f"{r['case']:16s} {tuple(r['shape'])} padded {tuple(r['padded'])}: "
              f"2n {r['cpu_s']['2n']:.2f} s, fast {r['cpu_s']['fast']:.2f} s "
              f"(x{r['speedup']:.2f}); iterations {sum(r['nit']['2n'])} / "
              f"{sum(r['nit']['fast'])}; max|dA*| {r['max|dA*|']:.1e}, "
              f"max dp/p {r['max dp/p']:.1e}", flush=True)
        label = f"{r['case']} {r['shape'][0]} x {r['shape'][1]}"
        targets += paired_targets(label, r, "CPU of the 2n layout / the fast grids",
                                  NOT_SLOWER, 0.0, SAME_LOAD)
    mean = float(np.exp(np.mean(np.log([r["speedup"] for r in rows])))) if rows else None
    write_report(args.output, "bench_bem_padding", targets, rows,
                 {"cpu_s": "s (process CPU time of the 6-step sweep, the smaller of two "
                           "rounds)", "speedup": "CPU(2n) / CPU(fast)",
                  "nit": "iterations per step", "max dp/p": "relative load difference"},
                 extra={"tol": TOL, "steps": list(STEPS), "geometric_mean_speedup": mean},
                 skipped=skipped)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
