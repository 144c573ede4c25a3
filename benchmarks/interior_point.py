"""Research script (issue 16 section 1; not in the package, not in ``make bench``): a
primal-dual interior-point (barrier) outer loop for the periodic, load-controlled
frictionless BEM contact, measured against the production solver (round 2, session 40;
the "Not tried" list of docs/theory/02b_bem_performance.md).

The problem (Eq. 2.5, load control; u = H p in m, heights h in m, p in Pa): p >= 0, the
gap w = u - h - Delta >= 0, p . w = 0, mean(p) = P. The loop keeps p > 0 and w > 0 as
separate variables (an infeasible start: r_d = u - h - Delta 1 - w need not vanish) and
follows the central path p_i w_i = mu by a plain path-following method (one linear
solve per step), centring parameter sigma fixed (``--sigma``, default 0.1), mu = p . w
/ n; or (``--mehrotra``) by Mehrotra's predictor-corrector: an affine solve (target
p_i w_i = 0) gives its largest step alpha_a and mu_a, sigma = (mu_a / mu)^3, and the
step solves (IP) for the target sigma mu - dp_a dw_a (two solves a step, both counted).
Newton's equations for (dp, dw, dDelta)

    H dp - dDelta 1 - dw = -r_d,   sum dp = 0,   W dp + P dw = sigma mu 1 - P W 1

give, with D = W P^-1 (m/Pa) and dw eliminated,

    (H + D) dp - dDelta 1 = sigma mu / p - w - r_d,   mean(dp) = 0,       (IP)

then dw = sigma mu / p - w - D dp (the complementarity equation kept exactly, so the
inexactness of the solve goes into r_d, which falls by 1 - alpha up to the CG's
residual; taking dw = H dp - dDelta 1 + r_d instead, which puts it into p_i w_i, stalled
at 256^2: steps alpha -> 1e-8 at high-pressure points whose w fell to 1e-16 with
``jacobi``, alpha 0.00 with ``split``), and the step p, w, Delta, u += alpha (dp, dw,
dDelta, H dp) with
alpha = min(1, 0.995 x the largest step keeping p > 0 and w > 0) (fraction to the
boundary). u = H p is tracked: the CG's own products give (H + D) dp, and H dp = that
- D dp (no extra product).

The inner solve of (IP) is the flexible Polak-Ribiere+ CG of
``benchmarks/pdas_eisenstat_walker.py`` (``inner_solve``: exact steps, zero-mean
directions, so dDelta is the mean of the final residual) on the whole grid, from dp = 0,
stopped at ||g|| <= eta_k ||g_0|| (g the zero-mean residual of (IP), g_0 = -P rhs, P the
zero-mean projection), with the forcing

    eta_k = min(0.5, eta (||P r_d|| + sqrt(n) mu / P_mean) / ||g_0||)

(``--eta``, default 0.1): the CG residual a fraction eta of the current infeasibility
plus the central path's gap scale mu / P_mean (m) at every point, so that both go to 0
together (a relative tolerance on ||g_0|| alone does not: g_0 keeps the open gaps w).
The preconditioner (``--prec``):

``jacobi`` (default: the cheapest measured): (H_ii + D_i)^-1 everywhere, no product.
``split``: the grid split into C = {D_i <= kappa H_ii} (``--kappa`` 1: the
    points where the barrier term is small against H's diagonal, "in contact") and the
    rest N. On C the production M = E*|q|/2 (float32) of the gradient restricted to C,
    with the production two-level correction ``BlockDeflation(op, 8, settle=1)`` on C
    (behind the descent guard; its coarse matrix is H's, D_C is left out); on N the
    diagonal (H_ii + D_i)^-1. Block-diagonal: the coupling H_CN is dropped.
``split-d``: ``split`` with D_C in the coarse matrix (:class:`BarrierDeflation`).
``split1``: ``split`` without the two-level correction.
``m``: M = E*|q|/2 on the whole grid (D ignored), no correction.

The start: the production coarse start p_c (``coarse_start._coarse_start``, to 1e-4 on
the grids coarsened by 2), u = H p_c, Delta the mean gap over p_c > 0, w_0 = u - h -
Delta; mu_0 = ``--mu0`` x mean(p_c |w_0|) (the start's own complementarity); pushed onto
the central path point by point with r = p_c - w_0 / H_ii kept: p = (r + sqrt(r^2 + 4
mu_0 / H_ii)) / 2, w = mu_0 / p (the smoothing of Chen-Harker-Kanzow-Smale: p ~ p_c in
contact, w ~ w_0 where open, p w = mu_0 everywhere); p rescaled to the load and u = H p
recomputed (one product).

The end: the IPM runs until mu <= ``--ipm-tol`` x P h_pv (the complementarity part of
the production residual, default 1e-6), or ``--max-outer`` steps. Identification: the
set S = {H_ii p_i > w_i} (an iterate never has p = 0); p zeroed off S, rescaled to the
load, and the production PK (``contact._pk`` with its BlockDeflation, as the fallback of
pdas_eisenstat_walker.py) runs from it to the production KKT residual 1e-10; its
products count. A* is the fraction p > 0 of the PK result, as ``solve_contact``'s, and
must equal production's to 1e-6 relative, else the row is void (``a_star_match``).

Counts: an inner iteration is one product with H (float64), plus one with M (float32)
except with ``jacobi``, plus the correction's one with ``split`` and ``split-d`` (none
at the very first inner iteration); a PK iteration is about 2.6 products. conv-eq:
every fine product (start, inner, polish PK) plus the coarse start's levels weighted
m^2 / n^2 (``benchmarks/_pk_log.py``), the same for the production solve run beside it
(``pdas_eisenstat_walker.production``).

Measured in session 40 (seed 1, defaults unless named; A* equal to production's on every
load run): one load p/E* = 0.05, inner iterations (outer steps) and conv-eq (ratio to
production's), 256^2 / 512^2 / 1024^2 / 2048^2:

* production PK: H = 0.5 38 / 48 / 26 / 31 iterations, 102.2 / 132.8 / 99.6 / 114.3
  conv-eq; H = 0.8 34 / 41 / 23 / 27, 92.2 / 111.4 / 83.8 / 97.3.
* ``jacobi``: H = 0.5 93 (9) / 129 (10) / 155 (10) / 250 (12), 141.2 / 184.8 / 214.6
  (2.15x) / 314.3 (2.75x); H = 0.8 108 (10) / 160 (12) / 243 (13) / 291 (14), 153.2 /
  210.4 / 294.8 (3.52x) / 348.3 (3.58x).
* ``split1``: H = 0.5 74 (10) / 118 (12) / 131 (11) / 200 (13), 194.2 / 288.8 / 321.6
  (3.23x) / 463.3 (4.05x); H = 0.8 80 (10) / 128 (13) / 175 (14) / 282 (19), 205.2 /
  305.4 / 402.8 (4.81x) / 618.3 (6.35x).
* ``jacobi --mehrotra``: H = 0.5 141 (6) / 151 (6) / 213 (6) / 262 (6), 187.2 / 203.8 /
  269.6 (2.71x) / 325.3 (2.85x); H = 0.8 - / 243 (7) / 216 (6) / 339 (7), - / 292.4 /
  268.8 (3.21x) / 390.3 (4.01x).
* H = 0.5, 256^2: ``split`` 440 inner (22 outer), 1365 conv-eq, with kappa 0.01 292
  (12); ``split-d`` 157 (10), 521 conv-eq (512^2: 249 (13), 799); ``split1`` with kappa
  0.1 / 0.01 77 / 100 (10); ``m`` did not reach eta in 200 iterations at any step.

The polish (PK from the identified set, 130-1391 points wrong at 1024^2-2048^2) takes
12-15 PK iterations (34-44 products) at every size. 4 loads (``jacobi``), H = 0.5:
512^2 508 inner (54 outer) + 52 polish, 711.2 conv-eq (production 170 its, 466.2);
1024^2 675 (58) + 52, 890.3 (95 its, 355.3: 2.51x); H = 0.8 512^2 718 (60) + 49, 904.5
(147 its, 398.5); 1024^2 1003 (67) + 51, 1203.7 (87 its, 312.7: 3.85x). The kill
criterion (conv-eq > 2x production's at 1024^2) holds for every variant on both H; the
inner totals grow 1.61x / 1.20x (``jacobi``), 1.53x / 1.61x (``split1``) and 1.23x /
1.57x (``--mehrotra``) from 1024^2 to 2048^2 (H = 0.5 / 0.8).
With Mehrotra the outer count is flat (6-7 steps) but each solve's count grows (the
diagonal preconditioner: 22 -> 29 iterations in the first step, predictor and
corrector, 1024^2 -> 2048^2). Per system (the same iterates, H = 0.5, 512^2, to the
loop's eta_k): ``split1`` 7-8 iterations in steps 1-8, 16-19 in the last two; the
production two-level correction on C (``split``) 10-14 and 29-50, with D_C in its
coarse matrix (``split-d``) 9-15 and 14: the correction does not pay in the early,
loose solves where D_C is not small against H (0-18 % of C has D < 0.01 H_ii in steps 1-5).

Usage (from the repository root; a line per load and a total per n)::

    nice -n 10 .venv/bin/python benchmarks/interior_point.py --n 256 512 1024 2048 \
        --hurst 0.5 --loads 0.05 --output /tmp/ip_h05.json
    nice -n 10 .venv/bin/python benchmarks/interior_point.py --n 512 1024 2048 \
        --hurst 0.8 --loads 0.05 --mehrotra --no-production
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

from roughfe.bem.deflation import BlockDeflation  # noqa: E402
from roughfe.errors import InputError  # noqa: E402
from roughfe.writers import write_json  # noqa: E402
from pdas_eisenstat_walker import (  # noqa: E402
    Fine, beside_production, coarse_start, growth_surface, inner_solve, pk_from,
    production_residual)
from bench_bem_growth import LOADS  # noqa: E402

PRECONDITIONERS = ("split", "split-d", "split1", "m", "jacobi")
FRACTION_TO_BOUNDARY = 0.995


class Barrier:
    """The operator H + D of (IP) and its preconditioner, in the interface
    ``inner_solve`` expects of ``Fine`` (``H``, ``M``, ``h`` = the right-hand side);
    every product counted on the shared ``fine``."""

    def __init__(self, fine, D, rhs, prec, kappa):
        self.fine, self.D, self.h = fine, D, rhs
        self.prec = prec
        self.diag = 1.0 / (fine.c + D)
        self.C = D <= kappa * fine.c if prec.startswith("split") else None

    def H(self, x, single=False):
        out = self.fine.H(x, single)
        return out + (self.D * x).astype(out.dtype)

    def M(self, x):
        if self.prec == "jacobi":
            return self.diag * x
        if self.prec == "m":
            return self.fine.M(x)
        z = self.fine.M(np.where(self.C, x, 0.0).astype(np.float32)).astype(float)
        return np.where(self.C, z, self.diag * x)


class BarrierDeflation(BlockDeflation):
    """The production two-level correction (``BlockDeflation``) whose coarse matrix also
    holds the barrier term: E = Z^T (H_CC + D_C) Z = Z^T H_CC Z + diag(sum of D over each
    block's points in C) (``dsum``, set per outer step; Z's columns are block indicators,
    so D adds to E's diagonal only)."""

    dsum = None

    def _coarse(self, X, counts):
        apply, counts_, diag = super()._coarse(X, counts)
        if self.dsum is None:
            return apply, counts_, diag
        dsum = np.where(counts_ > 0, self.dsum, 0.0)
        return (lambda c: apply(c) + dsum * c), counts_, diag + dsum


class SplitCorrection:
    """The production two-level correction on C only (``inner_solve``'s deflation
    interface; the whole grid is its set I); N keeps the diagonal step."""

    def __init__(self, deflation, barrier):
        self.deflation, self.C = deflation, barrier.C
        self.Ci = np.flatnonzero(barrier.C)
        if isinstance(deflation, BarrierDeflation):
            b = deflation.block
            m0, m1 = deflation.coarse_shape
            d = np.where(barrier.C, barrier.D, 0.0).reshape(m0, b, m1, b)
            deflation.dsum = d.sum(axis=(1, 3))

    def correct(self, F, gF, zF, apply_free, free_mask=None, pressure=None):
        if self.deflation is None or self.Ci.size < 2:
            return zF
        Ci, n = self.Ci, gF.size
        y = np.zeros(n, np.float32)

        def apply_c(xc):
            y[:] = 0.0
            y[Ci] = xc
            return apply_free(y)[Ci]

        zc = self.deflation.correct(Ci, gF[Ci], zF[Ci], apply_c, free_mask=self.C)
        z = zF.copy()
        z[Ci] = zc
        return z - z.mean()


class _NoCorrection:
    @staticmethod
    def correct(F, gF, zF, apply_free, free_mask=None, pressure=None):
        return zF


def interior_start(fine, p_c, target, mu0_factor):
    """The coarse start pushed onto the central path (module docstring): (p, w, Delta,
    u, mu_0)."""
    u = fine.H(p_c)
    g = u - fine.h
    delta = float(g[p_c > 0].mean())
    w0 = g - delta
    mu0 = mu0_factor * float(np.mean(p_c * np.abs(w0)))
    c = fine.c
    r = p_c - w0 / c                        # Pa: > 0 in contact, < 0 open
    p = 0.5 * (r + np.sqrt(r * r + 4.0 * mu0 / c))
    p *= target / float(p.sum())
    w = mu0 / p                             # = c (root - r) / 2, without the cancellation
    return p, w, delta, fine.H(p), mu0


def max_step(x, dx):
    """The largest alpha with x + alpha dx >= 0 (x > 0), inf if none binds."""
    neg = dx < 0
    return float(np.min(-x[neg] / dx[neg])) if neg.any() else np.inf


def interior_point(surface, load, opt):
    """One cold IPM solve of ``load`` (p/E*) with the PK polish; a dict of its counts."""
    c0 = time.process_time()
    fine = Fine(surface)
    n = fine.h.size
    target = load * n
    P = target / n
    p_c, coarse_conv = coarse_start(surface, load, target)
    p, w, delta, u, mu0 = interior_start(fine, p_c, target, opt["mu0"])
    deflation = ({"split": BlockDeflation, "split-d": BarrierDeflation}[opt["prec"]](
        fine.op, 8, settle=1.0) if opt["prec"] in ("split", "split-d") else None)
    everything = np.arange(n)
    full = np.ones(n, bool)
    steps = []
    inner_total = 0
    mu_stop = opt["ipm_tol"] * P * fine.scale
    for _ in range(opt["max_outer"]):
        mu = float(np.dot(p, w)) / n
        r_d = u - fine.h - delta - w
        if mu <= mu_stop:
            break
        D = w / p
        scale_k = float(np.linalg.norm(r_d - r_d.mean())) + np.sqrt(n) * mu / P

        def newton(target_pw):
            """(IP) for the complementarity target ``target_pw`` (p_i w_i after the
            step, to first order): dp, H dp, dw, dDelta, iterations, capped."""
            rhs = target_pw / p - w - r_d
            eta = min(0.5, opt["eta"] * scale_k / float(np.linalg.norm(rhs - rhs.mean())))
            bar = Barrier(fine, D, rhs, opt["prec"], opt["kappa"])
            corr = _NoCorrection() if bar.C is None else SplitCorrection(deflation, bar)
            dp, Adp = np.zeros(n), np.zeros(n)
            its, _, capped = inner_solve(bar, corr, dp, Adp, everything, full, eta,
                                         target, opt["max_inner"], 0.0, False)
            return (dp, Adp - D * dp, target_pw / p - w - D * dp,
                    float((Adp - rhs).mean()), its, capped, bar.C, eta)

        sigma, its_pred = opt["sigma"], 0
        if opt["mehrotra"]:          # the affine predictor sets sigma and the corrector
            dpa, _, dwa, _, its_pred, _, _, _ = newton(np.zeros(n))
            aa = min(1.0, max_step(p, dpa), max_step(w, dwa))
            sigma = (float(np.dot(p + aa * dpa, w + aa * dwa)) / n / mu) ** 3
            dp, Hdp, dw, d_delta, its, capped, C, eta = newton(sigma * mu - dpa * dwa)
        else:
            dp, Hdp, dw, d_delta, its, capped, C, eta = newton(np.full(n, sigma * mu))
        its += its_pred
        inner_total += its
        alpha = min(1.0, FRACTION_TO_BOUNDARY * min(max_step(p, dp), max_step(w, dw)))
        p += alpha * dp
        w += alpha * dw
        u += alpha * Hdp
        delta += alpha * d_delta
        steps.append({"inner": its, "predictor": its_pred, "alpha": alpha, "mu": mu,
                      "sigma": sigma, "eta": eta, "capped": capped,
                      "C": None if C is None else int(np.count_nonzero(C)),
                      "feasibility": float(np.abs(r_d).max()) / fine.scale})
    mu_end = float(np.dot(p, w)) / n
    S = fine.c * p > w
    # the polish: production PK from p on S (its products counted)
    out, converged = pk_from(fine, np.where(S, p, 0.0), load, opt["max_polish"])
    pf = np.ascontiguousarray(out.pressure, dtype=float).reshape(-1)
    uf = np.ascontiguousarray(out.displacement, dtype=float).reshape(-1)
    cpu = time.process_time() - c0
    final_set = pf > 0
    return {"converged": converged, "outer": len(steps), "inner": inner_total,
            "polish_pk_iterations": int(out.nit), "polish_products": int(out.n_products),
            "products": fine.products, "conv_eq": fine.products + coarse_conv,
            "coarse_conv_eq": coarse_conv, "cpu_s": cpu, "mu0": mu0, "mu_end": mu_end,
            "identified": int(np.count_nonzero(S)),
            "identified_wrong": int(np.count_nonzero(S != final_set)),
            "A*": float(np.count_nonzero(final_set)) / n,
            "residual": production_residual(fine, pf, uf), "steps": steps}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, nargs="+", default=[512])
    ap.add_argument("--hurst", type=float, default=0.5)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--loads", type=float, nargs="+", default=list(LOADS))
    ap.add_argument("--sigma", type=float, default=0.1, help="centring parameter")
    ap.add_argument("--mehrotra", action="store_true",
                    help="Mehrotra's predictor-corrector (two solves a step) instead")
    ap.add_argument("--eta", type=float, default=0.1, help="inner relative tolerance")
    ap.add_argument("--prec", choices=PRECONDITIONERS, default="jacobi")
    ap.add_argument("--kappa", type=float, default=1.0,
                    help="split: C = {D_i <= kappa H_ii}")
    ap.add_argument("--mu0", type=float, default=1.0,
                    help="mu_0 as a multiple of the coarse start's mean p |w|")
    ap.add_argument("--ipm-tol", type=float, default=1e-6,
                    help="the IPM stops at mu <= ipm_tol P h_pv; then the PK polish")
    ap.add_argument("--max-inner", type=int, default=200)
    ap.add_argument("--max-outer", type=int, default=60)
    ap.add_argument("--max-polish", type=int, default=2000)
    ap.add_argument("--no-production", action="store_true")
    ap.add_argument("--output", type=Path, default=None)
    a = ap.parse_args(argv)
    bad = [n for n in a.n if n < 256 or n & (n - 1)]
    if bad:
        raise InputError(f"--n {bad}: the growth surfaces with the coarse start need "
                         f"powers of two >= 256")
    if not (0.0 < a.sigma < 1.0 and 0.0 < a.eta < 1.0):
        raise InputError(f"--sigma {a.sigma} and --eta {a.eta} must lie in (0, 1)")
    opt = {"mehrotra": a.mehrotra, "sigma": a.sigma, "eta": a.eta, "prec": a.prec,
           "kappa": a.kappa, "mu0": a.mu0, "ipm_tol": a.ipm_tol,
           "max_inner": a.max_inner, "max_outer": a.max_outer,
           "max_polish": a.max_polish}
    print(f"H = {a.hurst} seed {a.seed}, {opt}", flush=True)
    rows = []
    for n in a.n:
        surface = growth_surface(n, a.hurst, a.seed)
        tot = {"inner": 0, "outer": 0, "polish": 0, "conv_eq": 0.0, "cpu_s": 0.0, "pk": 0,
               "pk_conv_eq": 0.0, "pk_cpu_s": 0.0}
        for load in a.loads:
            row = {"n": n, "hurst": a.hurst, "seed": a.seed, "load": load, "opt": opt,
                   "ipm": interior_point(surface, load, opt)}
            s = row["ipm"]
            line = (f"{n}^2 p/E*={load}: IPM {'ok' if s['converged'] else 'NOT converged'}"
                    f" outer {s['outer']} inner {s['inner']} + polish PK "
                    f"{s['polish_pk_iterations']}, {s['products']} fine products, "
                    f"{s['conv_eq']:.1f} conv-eq, {s['cpu_s']:.1f} s, A* {s['A*']:.7f} "
                    f"(S wrong {s['identified_wrong']})")
            if not a.no_production:
                line += beside_production(row, s, surface, load, tot)
            print(line, flush=True)
            print("    inner per step " + " ".join(str(st["inner"]) for st in s["steps"])
                  + " | alpha " + " ".join(f"{st['alpha']:.2f}" for st in s["steps"])
                  + f" | mu {s['mu0']:.2e} -> {s['mu_end']:.2e}", flush=True)
            tot["inner"] += s["inner"]
            tot["outer"] += s["outer"]
            tot["polish"] += s["polish_pk_iterations"]
            tot["conv_eq"] += s["conv_eq"]
            tot["cpu_s"] += s["cpu_s"]
            rows.append(row)
        print(f"{n}^2 total: IPM {tot['inner']} inner ({tot['outer']} outer) + "
              f"{tot['polish']} polish PK, {tot['conv_eq']:.1f} conv-eq, "
              f"{tot['cpu_s']:.1f} s | PK {tot['pk']} its, "
              f"{tot['pk_conv_eq']:.1f} conv-eq, {tot['pk_cpu_s']:.1f} s", flush=True)
    if a.output is not None:
        a.output.parent.mkdir(parents=True, exist_ok=True)
        write_json(a.output, {"benchmark": "interior_point", "rows": rows})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
