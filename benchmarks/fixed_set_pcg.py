"""Research script (issue 16 section 1; not in the package, not in ``make bench``): the
*linear* part of the BEM contact problem alone. On a fixed set I, how many iterations
does the preconditioned CG need, and does that number grow with n on the growth
surfaces? Measured in round 2, session 39 (docs/theory/02b_bem_performance.md, "The
linear solve on a fixed set, measured").

The system (Eq. 2.5 with the set known; u = H p in m, heights h in m, p in Pa):

    (H p)_I - h_I = Delta 1,     p = 0 off I,     sum p = n P,

solved from the uniform pressure on I (p = nP / |I|; ``--from coarse``: the
coarse-to-fine start's pressure, zero off I, rescaled to the load) by the inner solve of
``benchmarks/pdas_eisenstat_walker.py`` (``inner_solve``: flexible Polak-Ribiere+ CG,
exact steps, the gradient's mean on I removed for the load), with one of two
preconditioners: the production M = E*|q|/2 alone (float32), or M with the production
two-level correction (``BlockDeflation(op, 8, settle=1)``: on a fixed set it acts at
every iteration) behind the descent guard; ``--edge-weight S CAP`` adds the one-level
D M D with a weight on the patches' edges (:class:`EdgeWeighted`). The count is the
number of iterations to ||g_I|| <= eta ||g_I^0|| for eta = 1e-2, 1e-3, 1e-6 (one solve
per eta, from the same start).

The sets: ``start``, the set the production solve starts its fine search from (the
coarse-to-fine start's {p > 0} + {w < 0}: the first set of the Newton loop), and
``converged``, the contact set {p > 0} of the production solution (``solve_contact``,
tol 1e-10). The surfaces are those of ``benchmarks/bench_bem_growth.py`` (one octave
more per doubling of n, unit rms slope, L = 1 m, E* = 1), one load p/E* = 0.05.

Usage (from the repository root)::

    nice -n 10 .venv/bin/python benchmarks/fixed_set_pcg.py --n 1024 2048 4096 \
        --hurst 0.8 --set start --output /tmp/fixed_set.json
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
sys.path.insert(0, str(HERE))

from roughfe.bem import solve_contact  # noqa: E402
from roughfe.bem.coarse_start import _coarse_start  # noqa: E402
from roughfe.bem.deflation import BlockDeflation  # noqa: E402
from roughfe.errors import InputError  # noqa: E402
from roughfe.writers import write_json  # noqa: E402
from pdas_eisenstat_walker import MAT, Fine, growth_surface, inner_solve  # noqa: E402

ETAS = (1e-2, 1e-3, 1e-6)
SETS = ("start", "converged")
MAX_IT = 400


class NoCorrection:
    """The one-level preconditioner: M g, no coarse correction (``inner_solve``'s
    deflation interface)."""

    @staticmethod
    def correct(F, gF, zF, apply_free, free_mask=None, pressure=None):
        return zF


class EdgeWeighted(Fine):
    """``Fine`` whose preconditioner is D M D, D = diag(min(d, cap)^s / rms), d the
    Euclidean distance (pixels, periodic) of each point of I to the nearest point off I:
    a weight on the edges of the contact patches in the manner of the weighted
    preconditioners of screen problems (Hiptmair, Jerez-Hanckes and Urzua-Torres), whose
    solutions are singular at the edges as d^(-1/2) (Eq. 2.5's pressure on a fixed set,
    negative pressures allowed)."""

    def __init__(self, surface, mask, s, cap):
        super().__init__(surface)
        from scipy import ndimage
        m = mask.reshape(self.shape)
        d = ndimage.distance_transform_edt(np.pad(m, 1, mode="wrap"))[1:-1, 1:-1]
        D = np.where(m, np.clip(d, 1.0, cap) ** s, 0.0)     # d >= 1 on I
        self.D = (D / np.sqrt(np.mean(D[m] ** 2))).reshape(-1).astype(np.float32)

    def M(self, x):
        return self.D * super().M(self.D * x)


def fixed_set(surface, load, which):
    """The set I (bool mask, flat) of ``which`` (module docstring) and the coarse-to-fine
    start's pressure (flat, at the load; zero off I)."""
    p = _coarse_start(surface, MAT, load, None, kernel="spectral").reshape(-1)
    p = p * (load * p.size / float(p.sum()))
    if which == "converged":
        res = solve_contact(surface, MAT, mean_pressure=load, tol=1e-10,
                            compute_stiffness=False)
        mask = np.asarray(res.pressure).reshape(-1) > 0
        p = np.where(mask, p, 0.0)
        return mask, p * (load * p.size / float(p.sum()))
    fine = Fine(surface)
    g = fine.H(p) - fine.h
    w = g - float(g[p > 0].mean())
    return (p > 0) | (w < 0), p


def iterations(surface, mask, load, two_level, start=None, weight=None):
    """Iterations of the fixed-set CG to each of :data:`ETAS` (None: not in MAX_IT),
    from ``start`` (flat pressure, zero off I) or the uniform pressure on I; ``weight``
    (s, cap): the edge-weighted preconditioner D M D of :class:`EdgeWeighted`."""
    fine = Fine(surface) if weight is None else EdgeWeighted(surface, mask, *weight)
    I = np.flatnonzero(mask)
    counts = []
    for eta in ETAS:
        if start is None:
            p = np.zeros(fine.h.size)
            p[I] = load * p.size / I.size
        else:
            p = start.copy()
        u = fine.H(p)
        corr = BlockDeflation(fine.op, 8, settle=1.0) if two_level else NoCorrection()
        its, _, capped = inner_solve(fine, corr, p, u, I, mask, eta, load * p.size,
                                     MAX_IT, 0.0, False)
        counts.append(None if capped else its)
    return counts


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, nargs="+", default=[1024, 2048])
    ap.add_argument("--hurst", type=float, default=0.8)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--load", type=float, default=0.05, help="p/E* (default 0.05)")
    ap.add_argument("--set", choices=SETS, default="start", dest="which")
    ap.add_argument("--from", choices=("uniform", "coarse"), default="uniform",
                    dest="origin", help="the CG's first iterate: the uniform pressure on "
                    "I, or the coarse-to-fine start's (zero off I, at the load)")
    ap.add_argument("--edge-weight", type=float, nargs=2, action="append", default=[],
                    metavar=("S", "CAP"), help="also the one-level D M D with D = min(d, "
                    "CAP)^S (d: distance to the set's edge in pixels); repeatable")
    ap.add_argument("--output", type=Path, default=None)
    args = ap.parse_args(argv)
    bad = [n for n in args.n if n < 64 or n & (n - 1)]
    if bad:
        raise InputError(f"--n {bad}: the growth surfaces need powers of two >= 64")
    rows = []
    for n in args.n:
        t0 = time.perf_counter()
        surface = growth_surface(n, args.hurst, args.seed)
        mask, coarse = fixed_set(surface, args.load, args.which)
        start = coarse if args.origin == "coarse" else None
        row = {"n": n, "hurst": args.hurst, "seed": args.seed, "load": args.load,
               "set": args.which, "from": args.origin, "set_size": int(mask.sum()),
               "etas": list(ETAS), "M": iterations(surface, mask, args.load, False, start),
               "M_two_level": iterations(surface, mask, args.load, True, start)}
        for s, cap in args.edge_weight:
            row[f"DMD_s{s:g}_cap{cap:g}"] = iterations(surface, mask, args.load, False,
                                                       start, (s, cap))
        row["wall_s"] = time.perf_counter() - t0
        rows.append(row)
        print(f"n = {n}: |I| = {row['set_size']}, iterations to eta = "
              f"{'/'.join(f'{e:g}' for e in ETAS)}: M {row['M']}, "
              f"M + two-level {row['M_two_level']}"
              + "".join(f", {k} {v}" for k, v in row.items() if k.startswith("DMD"))
              + f" ({row['wall_s']:.0f} s)", flush=True)
    if args.output is not None:
        write_json(args.output, {"script": "fixed_set_pcg", "rows": rows})
    return 0


if __name__ == "__main__":
    sys.exit(main())
