"""The automatic choice of the BEM's two-level correction (issue 16 §1, round 2 session 13):
on where the contact has many parts, off where it has few.

``solve_contact(..., coarse_correction=None)`` switches the two-level correction
(:class:`roughfe.bem.deflation.BlockDeflation`) on for periodic, load-controlled surface
solves from 1024^2 to 8192^2, unless the start's contact set has fewer than
``roughfe.bem.coarse_start.CORRECTION_MIN_PARTS`` connected parts (patches plus
non-contact islands): on a sphere or a sinusoid it buys no iterations and costs CPU, on a
rough surface it halves the iterations. Each case is solved three times in this process
(cold, tol 1e-10, E* = 1, L = 1 m): the automatic choice, the correction forced on and
forced off, and the order of the three is alternated over two rounds; the reported CPU is
the smaller of the two rounds (process CPU time). The target row of a case: the automatic
choice costs at most 1.1x the CPU of the faster of on and off. The parts of the start and
the choice itself are deterministic; the CPU figures depend on the machine's load, which
the report records.

Usage::

    .venv/bin/python benchmarks/bench_bem_choice.py [--size 2048] [--quick]

``--quick`` solves two cases at 1024^2 (a sphere and a rough surface, one load each).
Writes ``benchmarks/output/bench_bem_choice.json``.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from _report import write_report  # noqa: E402  (benchmarks/_report.py)

TOL = 1e-10
RATIO = 1.1      #: the automatic choice's CPU over the faster of on / off, at most
MODES = {"auto": None, "on": True, "off": False}


def surface_of(kind, n):
    """The case's periodic surface on n x n points (L = 1 m)."""
    from roughfe.surfaces.shapes import sphere_cap
    from roughfe.surfaces.spectral import spectral_surface
    from roughfe.surfaces.surface import Surface
    if kind == "sphere":                      # R = L, centred: one patch
        s = sphere_cap(n, 1.0, 1.0)
        return Surface(s.heights, s.size, periodic=True)
    if kind == "bisinusoid":                  # amplitude 0.01 L: one patch per peak
        x = (np.arange(n) + 0.5) / n
        h = 0.01 * np.cos(2 * np.pi * x)[:, None] * np.cos(2 * np.pi * x)[None, :]
        return Surface(h, 1.0, periodic=True)
    hurst = {"rough H = 0.8": 0.8, "rough H = 0.5": 0.5}[kind]
    return spectral_surface(n, 1.0, hurst, rms_slope=1.0, rng=1)


def run_case(kind, n, load):
    """Parts of the start, the automatic choice, and iterations / CPU of the three modes."""
    from roughfe.bem import Material, contact, solve_contact
    from roughfe.bem.coarse_start import _coarse_start, _contact_parts
    surface, material = surface_of(kind, n), Material(1.0, 0.0)
    parts = _contact_parts(_coarse_start(surface, material, load, None))
    made = []
    original = contact.BlockDeflation

    def spy(op, block):
        made.append(op.shape)
        return original(op, block)

    cpu = {m: [] for m in MODES}
    nit, area = {}, {}
    for order in (tuple(MODES), tuple(reversed(MODES))):
        for mode in order:
            made.clear()
            contact.BlockDeflation = spy
            try:
                c0 = time.process_time()
                r = solve_contact(surface, material, mean_pressure=load, solver="pk", tol=TOL,
                                  compute_stiffness=False, coarse_correction=MODES[mode])
                cpu[mode].append(time.process_time() - c0)
            finally:
                contact.BlockDeflation = original
            nit[mode] = int(r.nit)
            area[mode] = float(np.count_nonzero(r.pressure > 0)) / r.pressure.size
            if mode == "auto":
                chosen = "on" if (n, n) in made else "off"
    best = {m: min(v) for m, v in cpu.items()}
    return {"case": kind, "n": n, "load": load, "parts": parts, "choice": chosen,
            "nit": nit, "A*": area, "cpu_s": best,
            "ratio": best["auto"] / min(best["on"], best["off"])}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=2048, help="grid points per side")
    ap.add_argument("--quick", action="store_true",
                    help="two cases at 1024^2, one load each (smoke run)")
    ap.add_argument("--output", type=Path, default=HERE / "output" / "bench_bem_choice.json")
    args = ap.parse_args(argv)
    if args.quick:
        n, cases = 1024, [("sphere", 1e-2), ("rough H = 0.8", 0.05)]
    else:
        n = args.size
        cases = [("sphere", 1e-3), ("sphere", 1e-2), ("bisinusoid", 0.005),
                 ("bisinusoid", 0.02), ("rough H = 0.8", 0.005), ("rough H = 0.8", 0.1),
                 ("rough H = 0.5", 0.05), ("rough H = 0.5", 1.0)]
    rows, targets = [], []
    for kind, load in cases:
        r = run_case(kind, n, load)
        rows.append(r)
        print(f"{kind:14s} p/E* = {load:<6g} parts {r['parts']}: auto -> {r['choice']:3s} | "
              + " | ".join(f"{m} {r['nit'][m]} its {r['cpu_s'][m]:.2f} s" for m in MODES),
              flush=True)
        targets.append({"name": f"{kind}, p/E* = {load}, {n}^2 ({r['parts']} parts: "
                                f"{r['choice']}): automatic / faster CPU",
                        "value": round(r["ratio"], 3), "target": RATIO,
                        "met": r["ratio"] <= RATIO})
    write_report(args.output, "bench_bem_choice", targets, rows,
                 {"parts": "connected parts of the start's contact set",
                  "nit": "iterations of the finest grid", "A*": "contact fraction",
                  "cpu_s": "s (process CPU time, the smaller of two rounds)",
                  "ratio": "automatic CPU / the smaller of on and off"},
                 extra={"tol": TOL, "ratio_target": RATIO})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
