"""Imposed approaches on periodic surfaces: through load control against the gap-variable
CG (round 2, session 17).

An imposed approach Delta on a periodic elastic surface was solved by the gap-variable
CG (``roughfe.bem.periodic.periodic_gap_control``), which has neither the coarse-to-fine
start nor the two-level correction. ``roughfe.bem.approach`` solves it with the
load-controlled Polonsky-Keer iteration instead, moving the load by secant steps on
Delta(P) inside the solve (the start: the sweep's predicted pressure, or the same
approach on the coarsened grid).

Each case runs twice in this process, two rounds in alternating order (the smaller CPU
is reported):

* "load": the production code (``contact_sweep`` / ``solve_contact``, defaults);
* "gap": the same with ``roughfe.bem.contact.approach_start`` patched to give no
  estimate, i.e. the gap-variable CG of session 16.

Cases: periodic self-affine surfaces (H = 0.8, unit rms slope, seed 1, L = 1, E* = 1,
tol 1e-10, no stiffness): "sweep", the default sweep of 20 equispaced approaches up to
full contact (``contact_sweep(surface, material)``, as ``roughfe contact`` runs it);
"cold", three cold solves at 0.2, 0.5 and 0.8 of max h - mean h.

Targets of a case: the load path is not slower (CPU(gap) / CPU(load) >= 0.95, 1 within
the scatter of the CPU timer), and it gives the same answer: contact fractions within
``SAME_AREA`` = 2e-6 and loads within ``SAME_LOAD`` = 1e-8 relative (two independent
solves to a relative KKT residual of 1e-10).

Usage::

    .venv/bin/python benchmarks/bench_bem_approach.py [--quick]

``--quick``: 512^2 only (~15 s). The full run adds 1024^2 and 2048^2 (~5 min). Writes
``benchmarks/output/bench_bem_approach.json``.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from _cases import paired_runs, paired_targets, run_summary  # noqa: E402
from _report import write_report  # noqa: E402  (benchmarks/_report.py)

TOL = 1e-10
NOT_SLOWER = 0.95   #: CPU(gap) / CPU(load) at least this
SAME_AREA = 2e-6    #: |A*(load) - A*(gap)| at most this
SAME_LOAD = 1e-8    #: relative load difference at most this
COLD = (0.2, 0.5, 0.8)   #: approaches of the cold solves / (max h - mean h)


def solve(surface, gap, kind):
    """CPU, iterations, A* and loads of the case (``gap``: the gap-variable CG)."""
    from roughfe.bem import Material, contact, contact_sweep, solve_contact
    material = Material(1.0, 0.0)
    start = contact.approach_start
    if gap:
        contact.approach_start = lambda *a, **k: None
    try:
        c0 = time.process_time()
        if kind == "sweep":
            results = contact_sweep(surface, material, tol=TOL,
                                    compute_stiffness=False).results
        else:
            top = float(surface.heights.max() - surface.heights.mean())
            results = [solve_contact(surface, material, delta=x * top, tol=TOL,
                                     compute_stiffness=False) for x in COLD]
        cpu = time.process_time() - c0
    finally:
        contact.approach_start = start
    return run_summary(cpu, results)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="512^2 only")
    ap.add_argument("--output", type=Path, default=HERE / "output" / "bench_bem_approach.json")
    args = ap.parse_args(argv)
    from roughfe.bem import Material, solve_contact
    from roughfe.surfaces.spectral import spectral_surface
    sizes = [512] if args.quick else [512, 1024, 2048]
    rows, targets = [], []
    for n in sizes:
        surface = spectral_surface(n, 1.0, 0.8, rms_slope=1.0, rng=1)
        solve_contact(surface, Material(1.0, 0.0), mean_pressure=1e-3, tol=1e-4,
                      compute_stiffness=False)      # the operators, before the clock runs
        for kind in ("sweep", "cold"):
            r = {"n": n, "kind": kind,
                 **paired_runs(lambda mode: solve(surface, mode == "gap", kind), "load", "gap")}
            rows.append(r)
            print(f"{n}^2 {kind:5s}: gap variable {r['cpu_s']['gap']:.2f} s, load "
                  f"{r['cpu_s']['load']:.2f} s (x{r['speedup']:.2f}); iterations "
                  f"{sum(r['nit']['gap'])} -> {sum(r['nit']['load'])}; max|dA*| "
                  f"{r['max|dA*|']:.1e}, max dp/p {r['max dp/p']:.1e}", flush=True)
            label = f"{n}^2, " + ("the default 20-step approach sweep" if kind == "sweep"
                                   else "3 cold approaches")
            targets += paired_targets(label, r, "CPU gap variable / load path", NOT_SLOWER,
                                      SAME_AREA, SAME_LOAD)
    write_report(args.output, "bench_bem_approach", targets, rows,
                 {"cpu_s": "s (process CPU time of the case, the smaller of two rounds)",
                  "speedup": "CPU(gap variable) / CPU(load path)",
                  "nit": "fine iterations per step", "max dp/p": "relative load difference"},
                 extra={"tol": TOL, "cold_approaches_over_top": list(COLD)})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
