"""How the BEM's iteration count grows with the grid (issue 16 §1): new roughness octaves
against the refinement of one surface.

Two ways of doubling n, both with the production solver (``solve_contact``, ``solver="pk"``,
cold, load control, tol 1e-10, E* = 1, L = 1 m; the iteration counts are deterministic, so
this benchmark times nothing and its verdicts do not depend on the machine's load):

octaves    a new periodic self-affine surface at every n (unit rms slope, roll-off at the
           box, cut-off at the grid's Nyquist wavenumber): each doubling adds one octave of
           roughness, as in ``bench_bem.py`` and the issue's measurements. Several seeds
           and two Hurst exponents, because the count of one surface scatters by a few
           iterations from seed to seed.
refinement one surface generated on a base grid (its roughness ends at the base grid's
           Nyquist wavenumber) and resampled on finer grids by its band-limited Fourier
           interpolant (:meth:`roughfe.surfaces.surface.Surface.resampled`): the same
           continuous surface, resolved by more points. This is the sense in which a
           multigrid-type solver's iterations are "independent of n".

The target of issue 16 is <= 1.15x more iterations per doubling of n; every pair of sizes
is a row with its own met / NOT met, for each surface and for the mean over the seeds.

Usage::

    .venv/bin/python benchmarks/bench_bem_growth.py [--quick]

The full run takes ~20 min of CPU: 4 loads up to 4096^2, and one load (p/E* = 0.05) up
to 4096^2 on the new surfaces and up to 8192^2 on a refined one (~4.5 GB). ``--quick``
(~10 s) solves one load on the refinement of one surface, 1024^2 -> 2048^2. Writes
``benchmarks/output/bench_bem_growth.json``.
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

LOADS = (0.005, 0.01, 0.05, 0.1)
TOL = 1e-10
GROWTH = 1.15


def _solve_loads(surface, loads):
    """Iterations of the cold solves of ``loads`` (p/E*) and their contact fractions."""
    from roughfe.bem import Material, solve_contact
    nit, area = [], []
    for pm in loads:
        r = solve_contact(surface, Material(1.0, 0.0), mean_pressure=pm, solver="pk",
                          tol=TOL, compute_stiffness=False)
        nit.append(int(r.nit))
        area.append(float(np.count_nonzero(r.pressure > 0)) / r.pressure.size)
    return nit, area


def octaves_case(n, hurst, seed, loads):
    """A new self-affine surface at ``n`` (cut-off at its Nyquist wavenumber)."""
    from roughfe.surfaces.spectral import spectral_surface
    c0 = time.process_time()
    s = spectral_surface(n, 1.0, hurst, rms_slope=1.0, rng=seed)
    nit, area = _solve_loads(s, loads)
    return {"kind": "octaves", "n": n, "hurst": hurst, "seed": seed, "nit": nit,
            "total_nit": sum(nit), "A*": area, "cpu_s": time.process_time() - c0}


def refinement_case(base, n, hurst, seed, loads):
    """The surface of the ``base`` grid, resampled on ``n`` points per side."""
    from roughfe.surfaces.spectral import spectral_surface
    c0 = time.process_time()
    # resampled at every n (the base grid: the identity); spectral_surface leaves the
    # Nyquist modes empty, so every n carries exactly the same continuous surface
    s = spectral_surface(base, 1.0, hurst, rms_slope=1.0, rng=seed).resampled((n, n))
    nit, area = _solve_loads(s, loads)
    return {"kind": "refinement", "base": base, "n": n, "hurst": hurst, "seed": seed,
            "nit": nit, "total_nit": sum(nit), "A*": area, "cpu_s": time.process_time() - c0}


def _loads(loads):
    return f"{len(loads)} load" + ("s" if len(loads) > 1 else f" p/E* = {loads[0]}")


def _growth_targets(rows, key, label):
    """One target row per doubling of n for each group of ``rows`` sharing ``key``."""
    groups = {}
    for r in rows:
        groups.setdefault(key(r), {})[r["n"]] = r["total_nit"]
    out = []
    for k, by_n in groups.items():
        ns = sorted(by_n)
        for a, b in zip(ns, ns[1:]):
            if b == 2 * a:
                g = by_n[b] / by_n[a]
                out.append({"name": f"{label(k)}: iteration growth {a}^2 -> {b}^2 "
                                    f"({by_n[a]} -> {by_n[b]})",
                            "value": round(g, 4), "target": GROWTH, "met": g <= GROWTH})
    return out


def _mean_targets(rows, hurst):
    """The growth of the seeds' mean count for one Hurst exponent."""
    by_n = {}
    for r in rows:
        if r["hurst"] == hurst:
            by_n.setdefault(r["n"], []).append(r["total_nit"])
    out = []
    ns = sorted(by_n)
    for a, b in zip(ns, ns[1:]):
        if b == 2 * a and len(by_n[a]) == len(by_n[b]) > 1:
            ma, mb = float(np.mean(by_n[a])), float(np.mean(by_n[b]))
            out.append({"name": f"octaves, H = {hurst}, mean of {len(by_n[a])} seeds: "
                                f"iteration growth {a}^2 -> {b}^2 ({ma:.2f} -> {mb:.2f})",
                        "value": round(mb / ma, 4), "target": GROWTH, "met": mb / ma <= GROWTH})
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true",
                    help="one load on the refined 512^2 surface, 1024^2 -> 2048^2 (smoke run)")
    ap.add_argument("--output", type=Path, default=HERE / "output" / "bench_bem_growth.json")
    args = ap.parse_args(argv)
    # the two-level solver runs from 1024^2 on (``contact.DEFLATION_SIDES``): a pair
    # 512^2 -> 1024^2 would compare two solvers, so every pair starts at 1024^2
    if args.quick:
        sizes, big, seeds, loads = [1024], [], {0.8: [1]}, (0.05,)
        refine = [(512, [1024, 2048], 0.8, 1)]
        refine_big = []
    else:
        sizes, big, seeds, loads = [1024, 2048], [4096], {0.8: [1, 2, 3, 4], 0.5: [1, 2]}, LOADS
        refine = [(512, [1024, 2048, 4096], 0.8, 1), (512, [1024, 2048, 4096], 0.5, 1),
                  (1024, [1024, 2048, 4096], 0.8, 1)]
        # the case that stalled before the descent guard of session 12 (8192^2)
        refine_big = [(1024, [2048, 4096, 8192], 0.8, 1)]
    rows = []
    for hurst, ss in seeds.items():
        for seed in ss:
            for n in sizes:
                rows.append(octaves_case(n, hurst, seed, loads))
                r = rows[-1]
                print(f"octaves    H = {hurst} seed {seed} n = {n:5d}: {r['total_nit']:4d} "
                      f"{r['nit']}  ({r['cpu_s']:.1f} s CPU)", flush=True)
    for hurst, ss in seeds.items():    # one load, the largest grids: p/E* = 0.05
        for seed in (ss if big else []):
            for n in [sizes[-1], *big]:
                rows.append({**octaves_case(n, hurst, seed, (0.05,)), "kind": "octaves-0.05"})
                r = rows[-1]
                print(f"octaves    H = {hurst} seed {seed} n = {n:5d}, p/E* = 0.05: "
                      f"{r['total_nit']:4d}  ({r['cpu_s']:.1f} s CPU)", flush=True)
    for base, ns, hurst, seed in refine:
        for n in ns:
            rows.append(refinement_case(base, n, hurst, seed, loads))
            r = rows[-1]
            print(f"refinement H = {hurst} base {base} n = {n:5d}: {r['total_nit']:4d} "
                  f"{r['nit']}  A* {np.round(r['A*'], 4).tolist()}  ({r['cpu_s']:.1f} s CPU)",
                  flush=True)
    for base, ns, hurst, seed in refine_big:     # one load, up to 8192^2 (~4.5 GB)
        for n in ns:
            rows.append({**refinement_case(base, n, hurst, seed, (0.05,)),
                         "kind": "refinement-0.05"})
            r = rows[-1]
            print(f"refinement H = {hurst} base {base} n = {n:5d}, p/E* = 0.05: "
                  f"{r['total_nit']:4d}  ({r['cpu_s']:.1f} s CPU)", flush=True)
    octave_rows = [r for r in rows if r["kind"] == "octaves"]
    targets = _growth_targets(octave_rows, lambda r: (r["hurst"], r["seed"]),
                              lambda k: f"octaves, H = {k[0]}, seed {k[1]}, {_loads(loads)}")
    for hurst in seeds:
        targets += _mean_targets(octave_rows, hurst)
    one = [r for r in rows if r["kind"] == "octaves-0.05"]
    targets += _growth_targets(one, lambda r: (r["hurst"], r["seed"]),
                               lambda k: f"octaves, H = {k[0]}, seed {k[1]}, p/E* = 0.05")
    for hurst in {r["hurst"] for r in one}:
        targets += [{**t, "name": t["name"].replace("octaves,", "octaves p/E* = 0.05,")}
                    for t in _mean_targets(one, hurst)]
    targets += _growth_targets([r for r in rows if r["kind"] == "refinement"],
                               lambda r: (r["hurst"], r["base"]),
                               lambda k: f"refinement of the {k[1]}^2 surface, H = {k[0]}, "
                                         f"{_loads(loads)}")
    targets += _growth_targets([r for r in rows if r["kind"] == "refinement-0.05"],
                               lambda r: (r["hurst"], r["base"]),
                               lambda k: f"refinement of the {k[1]}^2 surface, H = {k[0]}, "
                                         f"{_loads((0.05,))}")
    write_report(args.output, "bench_bem_growth", targets, rows,
                 {"nit": "iterations of the finest grid per load", "A*": "contact fraction",
                  "cpu_s": "s (process CPU time, generation included)"},
                 extra={"loads": list(loads), "tol": TOL, "growth_target": GROWTH})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
