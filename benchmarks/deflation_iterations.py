"""Outer iterations of the Polonsky-Keer CG with and without the two-level (deflation)
coarse correction in the real, contact-set-changing loop (issue 16 §1).

The same cold, load-controlled solves as ``bench_bem.py`` (H = 0.8 periodic surfaces,
unit rms slope, seed 1, E* = 1, tol 1e-10, loads p/E* = 0.005, 0.01, 0.05, 0.1), each
from the same coarse-to-fine start, once with the production preconditioner M = E*|q|/2
and once with :class:`roughfe.bem.deflation.ProbedBlockDeflation` added. The deflated
solve is the *reference* two-level method (its coarse matrix probed by
``(2 radius + 1)^2`` or more fine products per iteration and factorised densely), so
its time is not a speed figure: the script reports iterations, operator products and
the agreement of the two solutions (A*, max |dp| / max p). It is not part of
``make bench`` (minutes at 512^2, the dense coarse factorisation grows as k^3).

Usage::

    .venv/bin/python benchmarks/deflation_iterations.py [--sizes 256 512] [--block 8]
        [--radius 1] [--loads ...] [--output benchmarks/output/deflation_iterations.json]
"""
from __future__ import annotations

import argparse
import functools
import os
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
LOADS = (0.005, 0.01, 0.05, 0.1)
TOL = 1e-10


def solve_pair(surface, pm, block, radius, method="production"):
    """The plain and the deflated solve of one load from the same coarse start
    (``method``: "production", :class:`~roughfe.bem.deflation.BlockDeflation`, or
    "reference", :class:`~roughfe.bem.deflation.ProbedBlockDeflation`)."""
    from roughfe.bem import Material
    from roughfe.bem.contact import _cg_preconditioner, _coarse_start, _operator
    from roughfe.bem.deflation import BlockDeflation, ProbedBlockDeflation
    from roughfe.bem.pk import polonsky_keer

    mat = Material(1.0, 0.0)
    op = _operator(surface.shape, surface.size, mat.E_star, "spectral")
    h = surface.heights
    start = _coarse_start(surface, mat, pm, None)
    rows = {}
    for name, deflation in (("plain", None),
                            ("deflated", BlockDeflation(op, block)
                             if method == "production"
                             else ProbedBlockDeflation(op, block, radius))):
        c0 = time.process_time()
        out = polonsky_keer(op.apply, h, float(np.ptp(h)), mean_pressure=pm,
                            initial=None if start is None else start.copy(),
                            diagonal=op.diagonal, precond=_cg_preconditioner(op),
                            tol=TOL, max_iter=20000, offset=-float(h.max()),
                            apply_single=functools.partial(op.apply, single=True),
                            deflation=deflation)
        rows[name] = {"nit": out.nit, "n_products": out.n_products,
                      "A*": float(np.mean(out.pressure > 0)),
                      "cpu_s": time.process_time() - c0, "pressure": out.pressure}
    p0, p1 = rows["plain"].pop("pressure"), rows["deflated"].pop("pressure")
    return {"p/E*": pm, **{f"{k}_{name}": v for name, r in rows.items() for k, v in r.items()},
            "max|dp|/max p": float(np.abs(p1 - p0).max() / p0.max())}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[256, 512])
    ap.add_argument("--loads", type=float, nargs="+", default=list(LOADS))
    ap.add_argument("--block", type=int, default=8)
    ap.add_argument("--radius", type=int, default=1)
    ap.add_argument("--method", choices=("production", "reference"), default="production")
    ap.add_argument("--output", type=Path,
                    default=HERE / "output" / "deflation_iterations.json")
    args = ap.parse_args(argv)
    from roughfe.surfaces.spectral import spectral_surface
    from roughfe.writers import write_json

    tables = []
    for n in args.sizes:
        surface = spectral_surface(n, 1.0, 0.8, rms_slope=1.0, rng=1)
        rows = [solve_pair(surface, pm, args.block, args.radius, args.method)
                for pm in args.loads]
        for r in rows:
            print(f"n = {n} p/E* = {r['p/E*']}: iterations {r['nit_plain']} -> "
                  f"{r['nit_deflated']}, products {r['n_products_plain']} -> "
                  f"{r['n_products_deflated']}, CPU {r['cpu_s_plain']:.2f} -> "
                  f"{r['cpu_s_deflated']:.2f} s, A* {r['A*_plain']:.6g} / "
                  f"{r['A*_deflated']:.6g}, max|dp|/max p {r['max|dp|/max p']:.2e}",
                  flush=True)
        tables.append({"n": n, "method": args.method, "block": args.block,
                       "radius": args.radius, "rows": rows,
                       "cpu_plain": sum(r["cpu_s_plain"] for r in rows),
                       "cpu_deflated": sum(r["cpu_s_deflated"] for r in rows),
                       "nit_plain": sum(r["nit_plain"] for r in rows),
                       "nit_deflated": sum(r["nit_deflated"] for r in rows)})
        t = tables[-1]
        print(f"n = {n}: {t['nit_plain']} -> {t['nit_deflated']} iterations, CPU "
              f"{t['cpu_plain']:.2f} -> {t['cpu_deflated']:.2f} s ({len(rows)} loads)",
              flush=True)
    write_json(args.output, {"tol": TOL, "load_average": os.getloadavg()[0],
                             "tables": tables})
    print(f"wrote {args.output}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
