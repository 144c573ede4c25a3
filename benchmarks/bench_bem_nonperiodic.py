"""Non-periodic BEM: the two-level solver against the plain one (round 2, session 16).

Four changes made the solve of a non-periodic surface (Love's kernel on the DC-FFT padded
grid, ``kernel="auto"``) what the periodic one had been since session 6:

* the coarse-to-fine start (``roughfe.bem.coarse_start``: 2 x 2 block means, recursively
  down to 256 points per side, each level solved to 1e-4; in a sweep every level starts
  from its own previous solution);
* the two-level correction on the operator's padded torus
  (``roughfe.bem.padded_deflation.PaddedBlockDeflation``), on by default where the FFT
  grid has 1024^2 to 8192^2 points (``roughfe.bem.contact.DEFLATION_SIDES``) and the
  start's contact has at least 32 parts;
* the same correction in displacement control (``zero_mean=False``: the torus operator
  is positive definite, no zero-mean projection), on by default where the rigid
  interpenetration of a cold approach (or the previous step) has 32 parts;
* padded products in place in the solve's workspace and the split line search
  (``InfluenceOperator.split_product``: t . H t from the forward transform).

Each case runs its loads twice in this process:

* "two-level": the production code (``contact_sweep``, defaults);
* "plain": ``coarse_correction=False`` and no coarse start (``COARSE_START_MIN`` patched
  out of reach): the session-15 solver, except for the in-place products, which both use.

Cases: RMD surfaces (D = 2.3, 2^m + 1 points per side) and the five measured files of
``../shared/data/topographies`` (``ROUGHFE_TOPOGRAPHIES`` overrides the folder; a file
that is missing is skipped, and the report says so). Three kinds of run ("control"):
"load", loads p / (E* h'_rms) = 0.005, 0.01, 0.02, 0.05, 0.1, 0.2 (a warm-started sweep,
``contact_sweep(pressures=)``); "one", one cold load 0.05 (``solve_contact``, the largest
RMD case); "delta", approaches 0.1-0.6 of the peak-to-valley height (6 steps,
``contact_sweep(deltas=)``). Tol 1e-10, E = 1 GPa, nu = 0.3.
The two alternate over two rounds; the reported CPU (process CPU time) is the smaller.

Targets of a case:

* the same answer: the contact fractions of the two differ by at most ``SAME_AREA`` =
  2e-6 (a point or two of a 1025^2 grid; both are independent solves to a relative KKT
  residual of 1e-10) and their loads by at most ``SAME_LOAD`` = 1e-9 relative (imposed
  loads) or ``SAME_LOAD_DELTA`` = 1e-8 (the loads of imposed approaches: measured up to
  8.1e-10 between two such solves, bench_bem_padding);
* where the correction is on by default, the two-level solver is not slower:
  CPU(plain) / CPU(two-level) >= 0.95 (1 within the scatter of the CPU timer). Where it
  is off (an FFT grid below 1024^2 points), the start alone must not be slower either.

Usage::

    .venv/bin/python benchmarks/bench_bem_nonperiodic.py [--quick]

``--quick``: RMD 513^2 only, load and displacement control (~20 s). Writes
``benchmarks/output/bench_bem_nonperiodic.json``.
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
                    run_summary, surface_of)  # benchmarks/_cases.py
from _report import write_report  # noqa: E402  (benchmarks/_report.py)

TOL = 1e-10
NOT_SLOWER = 0.95    #: CPU(plain) / CPU(two-level) at least this
SAME_AREA = 2e-6     #: |A*(two-level) - A*(plain)| at most this
SAME_LOAD = 1e-9     #: relative load difference at most this (load control)
SAME_LOAD_DELTA = 1e-8   #: the same in displacement control
LOADS = (0.005, 0.01, 0.02, 0.05, 0.1, 0.2)   #: p / (E* h'_rms)
ONE_LOAD = 0.05
DELTAS = tuple(np.linspace(0.1, 0.6, 6))       #: approaches / (max h - min h)


def rms_slope_x(surface):
    """h'_rms along the first axis (centred differences), the load's scale."""
    g = np.gradient(surface.heights, surface.spacing[0], axis=0)
    return float(np.sqrt(np.mean(g * g)))


def solve(surface, plain, control):
    """CPU, iterations, A* and loads of the case's steps (``control``: "load", "one" or
    "delta"); ``plain``: the session-15 solver."""
    from roughfe.bem import Material, coarse_start, contact_sweep, solve_contact
    material = Material(1e9, 0.3)
    scale = material.E_star * rms_slope_x(surface)
    lowest = coarse_start.COARSE_START_MIN
    if plain:
        coarse_start.COARSE_START_MIN = 10 ** 9
    kw = dict(tol=TOL, compute_stiffness=False, coarse_correction=False if plain else None)
    try:
        c0 = time.process_time()
        if control == "load":
            results = contact_sweep(surface, material, pressures=[x * scale for x in LOADS],
                                    **kw).results
        elif control == "delta":
            results = contact_sweep(surface, material, deltas=[
                x * float(np.ptp(surface.heights)) for x in DELTAS], **kw).results
        else:
            results = [solve_contact(surface, material, mean_pressure=ONE_LOAD * scale, **kw)]
        cpu = time.process_time() - c0
    finally:
        coarse_start.COARSE_START_MIN = lowest
    return run_summary(cpu, results)


def correction_on(surface) -> bool:
    """Whether the automatic choice can put the correction on (the FFT grid's points)."""
    from roughfe.bem.contact import DEFLATION_SIDES
    from roughfe.bem.operators import padded_length
    lo, hi = DEFLATION_SIDES
    points = np.prod([padded_length(n, real=k == surface.ndim - 1)
                      for k, n in enumerate(surface.shape)], dtype=float)
    return lo * lo <= points <= hi * hi


def run_case(case, control):
    """The two solves of one case, or the reason it was not timed (a str)."""
    from roughfe.bem import solve_contact, Material
    surface = surface_of(case)
    if surface is None:
        return f"not found in {TOPOGRAPHIES}"
    # the operators of every level, built once before the clock runs
    solve_contact(surface, Material(1e9, 0.3), mean_pressure=1e-3 * 1e9 * rms_slope_x(surface),
                  tol=1e-4, compute_stiffness=False)
    steps = {"load": list(LOADS), "one": [ONE_LOAD], "delta": list(DELTAS)}[control]
    return {"case": f"{case[0]} {case[1]}", "shape": list(surface.shape),
            "control": control, "steps": steps,
            "correction_on_by_default": correction_on(surface),
            **paired_runs(lambda mode: solve(surface, mode == "plain", control),
                          "two-level", "plain")}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="RMD 513^2 only")
    ap.add_argument("--output", type=Path,
                    default=HERE / "output" / "bench_bem_nonperiodic.json")
    args = ap.parse_args(argv)
    cases = [(("rmd", 9), "load"), (("rmd", 9), "delta")]
    if not args.quick:
        cases += [(("rmd", 10), "load"), (("rmd", 11), "one")]
        cases += [(("file", f), "load") for f in ("x3p-2.x3p", "plu-1.plu", "di-1.di",
                                                    "sur-2.sur", "opd-1.opd")]
        cases += [(("rmd", 10), "delta"), (("file", "x3p-2.x3p"), "delta"),
                  (("file", "sur-2.sur"), "delta")]
    rows, targets, skipped = [], [], []
    for case, control in cases:
        r = run_case(case, control)
        if isinstance(r, str):
            skipped.append({"name": f"{case[0]} {case[1]}", "reason": r})
            print(f"{case[0]} {case[1]}: skipped, {r}", flush=True)
            continue
        rows.append(r)
        on = "on" if r["correction_on_by_default"] else "off (start only)"
        print(f"{r['case']:14s} {tuple(r['shape'])} {control:5s} correction {on}: plain "
              f"{r['cpu_s']['plain']:.2f} s, two-level {r['cpu_s']['two-level']:.2f} s "
              f"(x{r['speedup']:.2f}); iterations {sum(r['nit']['plain'])} -> "
              f"{sum(r['nit']['two-level'])}; max|dA*| {r['max|dA*|']:.1e}, "
              f"max dp/p {r['max dp/p']:.1e}", flush=True)
        label = (f"{r['case']} {r['shape'][0]} x {r['shape'][1]}, {control} control, "
                 f"{len(r['steps'])} step(s)")
        targets += paired_targets(label, r, f"CPU plain / two-level (correction {on})",
                                  NOT_SLOWER, SAME_AREA,
                                  SAME_LOAD_DELTA if control == "delta" else SAME_LOAD)
    mean = float(np.exp(np.mean(np.log([r["speedup"] for r in rows])))) if rows else None
    write_report(args.output, "bench_bem_nonperiodic", targets, rows,
                 {"cpu_s": "s (process CPU time of the case's loads, the smaller of two "
                           "rounds)", "speedup": "CPU(plain) / CPU(two-level)",
                  "nit": "iterations per load", "max dp/p": "relative load difference"},
                 extra={"tol": TOL, "loads_over_E*_h'rms": list(LOADS),
                        "deltas_over_peak_to_valley": list(DELTAS),
                        "geometric_mean_speedup": mean}, skipped=skipped)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
