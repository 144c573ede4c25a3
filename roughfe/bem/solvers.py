"""Solvers of the contact problem, thesis Eq. 2.5-2.6, on an influence operator.

The problem, with u = H p (:mod:`roughfe.bem.operators`), heights h and approach Delta:

    gap   w = H p - s,    s = Delta + h - max(h)    (the "interference", m)
    p >= 0,  w >= 0,  p . w = 0                     (LCP, Eq. 2.5)
    <=>  min_p  1/2 p'Hp - s'p  s.t. p >= 0          (QP, Eq. 2.6)

Displacement control imposes Delta; load control imposes the mean pressure and Delta
is its Lagrange multiplier. Solvers here work on ``b = h - max(h)`` (m) and return
``SolverOutput``; the physics post-processing lives in :mod:`roughfe.bem.contact`.

Convergence (every solver): the relative KKT residual

    r = max( sum_i p_i |w_i| / (sum_i p_i * h_pv),  max_i(-w_i, 0) / h_pv )

(pressure-weighted mean gap on the contact set and the largest penetration, both over
the peak-to-valley height h_pv; p >= 0 and, in load control, the load hold exactly).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.optimize

from ..errors import NoConvergenceError


@dataclass(frozen=True, eq=False)
class SolverOutput:
    """Raw solution: pressure p (Pa), displacement u = Hp (m), approach Delta (m)."""

    pressure: np.ndarray
    displacement: np.ndarray
    delta: float
    nit: int
    residual: float
    solver: str


def kkt_residual(p, w, scale):
    """Relative KKT residual (see the module docstring); ``scale`` in m."""
    sp = float(np.sum(p))
    comp = float(np.sum(p * np.abs(w))) / (sp * scale) if sp > 0 else 0.0
    feas = max(0.0, -float(np.min(w))) / scale
    return max(comp, feas)


def _fail(name, nit, res, tol, p, u, delta, solver):
    out = SolverOutput(p, u, float(delta), nit, res, solver)
    raise NoConvergenceError(
        f"{name} did not converge: relative KKT residual {res:.3e} after {nit} iterations, "
        f"tolerance {tol:.1e}", result=out)


# -- dense: block principal pivoting (own active set) and scipy NNLS -----------------------
def solve_spd(a, rhs):
    try:
        return scipy.linalg.cho_solve(scipy.linalg.cho_factor(a, check_finite=False), rhs,
                                      check_finite=False)
    except np.linalg.LinAlgError:
        # singular sub-block (periodic operator on the whole grid): minimum-norm solution
        return np.linalg.lstsq(a, rhs, rcond=None)[0]


def lcp_bpp(H, s, passive=None, *, tol=1e-12, max_iter=None):
    """Solve w = H p - s, p, w >= 0, p.w = 0 by block principal pivoting.

    Júdice & Pires (1994), in the NNLS form of Kim & Park (2011): exchange all
    infeasible indices at once, fall back to a single exchange when their number stops
    decreasing (guarantees finite termination for a positive definite H). A good
    ``passive`` set (warm start: the previous contact set) converges in few steps.
    Each step solves H_FF p_F = s_F by Cholesky. Returns ``(p, nit)``.
    """
    n = s.size
    F = np.zeros(n, bool) if passive is None else np.asarray(passive, bool).copy()
    max_iter = max_iter or 10 * n + 50
    ninf, backup = n + 1, 3
    scale = max(float(np.max(np.abs(s))), 1e-300)
    p = np.zeros(n)
    for it in range(1, max_iter + 1):
        p[:] = 0.0
        if F.any():
            p[F] = solve_spd(H[np.ix_(F, F)], s[F])
        w = H[:, F] @ p[F] - s
        w[F] = 0.0
        eps = tol * scale
        bad = (F & (p < -tol * max(float(np.max(p)), 0.0))) | (~F & (w < -eps))
        nbad = int(bad.sum())
        if nbad == 0:
            return np.maximum(p, 0.0), it
        if nbad < ninf:
            ninf, backup = nbad, 3
            F ^= bad
        elif backup > 0:
            backup -= 1
            F ^= bad
        else:
            j = np.flatnonzero(bad).max()
            F[j] = ~F[j]
    raise NoConvergenceError(f"block principal pivoting: {nbad} infeasible indices after "
                             f"{max_iter} exchanges")


def lcp_nnls(H, s):
    """Bemporad & Paggi (2015): Cholesky H = C'C, then Lawson-Hanson NNLS on
    || C p - C^-T s ||  (scipy.optimize.nnls). Needs H positive definite. scipy does not
    report its iterations: ``nit`` counts NNLS calls (1)."""
    C = scipy.linalg.cholesky(H, lower=False, check_finite=False)
    d = scipy.linalg.solve_triangular(C, s, trans="T", check_finite=False)
    p, _ = scipy.optimize.nnls(C, d, maxiter=50 * s.size)
    return p, 1


def dense_solve(H, b, scale, *, delta=None, mean_pressure=None, initial=None, method="bpp",
                tol=1e-10, max_iter=100):
    """Dense solve in displacement (``delta``) or load (``mean_pressure``) control.

    Load control: the mean pressure P(Delta) is convex and piecewise linear in Delta
    with slope the exact stiffness K(Delta), so Newton's method on Delta (warm-started
    pivoting at each step) ends in finitely many steps at the exact state.
    """
    n = b.size
    passive = None if initial is None else np.asarray(initial).ravel() > 0

    def at(d):
        s = d + b
        if method == "nnls":
            p, it = lcp_nnls(H, s)
        else:
            p, it = lcp_bpp(H, s, passive)
        return p, it

    if delta is not None:
        p, nit = at(float(delta))
        u = H @ p
        res = kkt_residual(p, u - b - delta, scale)
        if res > tol:
            _fail(f"dense {method}", nit, res, tol, p, u, delta, method)
        return SolverOutput(p, u, float(delta), nit, res, method)

    target = float(mean_pressure)
    d = 0.0
    if initial is not None and np.any(passive):
        c = passive
        d = float(np.mean((H[np.ix_(c, c)] @ np.asarray(initial).ravel()[c]) - b[c]))
    lo, hi = 0.0, np.inf
    nit = 0
    for k in range(max_iter):
        p, it = at(d)
        passive = p > 0
        nit += it
        pm = float(p.mean())
        if abs(pm - target) <= tol * target:
            break
        if pm < target:
            lo = max(lo, d)
        else:
            hi = min(hi, d)
        if passive.any():
            x = solve_spd(H[np.ix_(passive, passive)], np.ones(int(passive.sum())))
            slope = float(x.sum()) / n
        else:
            slope = 0.0
        d_new = d + (target - pm) / slope if slope > 0 else np.nan
        if not (lo <= d_new <= hi) or not np.isfinite(d_new):
            d_new = 2 * lo + scale if not np.isfinite(hi) else 0.5 * (lo + hi)
        d = d_new
    else:
        u = H @ p
        _fail(f"dense {method} (load control)", nit, abs(pm - target) / target, tol, p, u, d,
              method)
    p = p * (target / pm) if pm > 0 else p
    u = H @ p
    w = u - b - d
    res = kkt_residual(p, w, scale)
    if res > tol:
        _fail(f"dense {method} (load control)", nit, res, tol, p, u, d, method)
    return SolverOutput(p, u, d, nit, res, method)


# -- matrix-free: Polonsky & Keer constrained conjugate gradients ------------------------
def polonsky_keer(apply, b, scale, *, delta=None, mean_pressure=None, initial=None,
                  diagonal=1.0, precond=None, tol=1e-10, max_iter=10000):
    """Polonsky & Keer (1999) constrained CG with FFT operator products.

    The CG runs on the free set F = {p > 0} + {p = 0, g < 0} (points in contact and
    penetrating points: the latter are PK's "overlap" points, here they enter the
    search direction directly). After each exact line search the pressure is clipped
    at zero. The conjugation uses the Polak-Ribiere+ beta, max(0, g.(z - z_old)) /
    g_old.z_old, on the direction masked to F: it restarts itself when the free set or
    the gradient changes much, instead of a forced restart at every clip (Fletcher-
    Reeves with forced restarts took 83 -> 131 -> 264 iterations at 512^2 -> 2048^2,
    A* = 10 %; PR+ 50 -> 63 at 512^2 -> 1024^2).

    Load control (``mean_pressure``): the gap and the search direction are projected on
    zero mean over F and the pressure is rescaled to the load after each step; Delta
    is the mean of ``u - b`` over the contact set at convergence. Displacement control
    (``delta``): the plain projected CG on Eq. 2.6 (needs a positive definite H).

    ``precond`` (a linear map M ~ H^-1, e.g. the stiffness operator E*|q|/2) makes it a
    preconditioned CG (direction from z = P_F M P_F g, beta = g.z / g_old.z_old): on
    rough surfaces it cuts the iterations 3-4 fold and they grow much more slowly with
    n. ``diagonal`` (m/Pa, H_ii) scales the first trial pressure in displacement
    control.

    The displacement is updated without a transform (u <- a (u - tau H t)) when no clip
    happened, recomputed otherwise and every 50 iterations; convergence is always
    confirmed on a recomputed u. Returns a :class:`SolverOutput`.
    """
    load = mean_pressure is not None
    if initial is not None:
        p = np.maximum(np.array(initial, dtype=float).reshape(b.shape), 0.0)
        if load:
            pm = p.mean()
            p = np.full(b.shape, float(mean_pressure)) if pm <= 0 else p * (mean_pressure / pm)
    elif load:
        p = np.full(b.shape, float(mean_pressure))
    else:
        p = np.maximum(-(delta + b), 0.0) / diagonal
    t = np.zeros_like(p)
    gz_old, F_old, z_old = 1.0, None, None
    res = np.inf
    d = float(delta) if not load else 0.0
    u, exact = None, False
    for it in range(1, max_iter + 1):
        if u is None or it % 50 == 0:
            u, exact = apply(p), True
        g = u - b
        S = p > 0
        if load:
            nS = int(np.count_nonzero(S))
            d = float(np.sum(g, where=S)) / nS if nS else float(g.min())
        g -= d
        res = kkt_residual(p, g, scale)
        if res <= tol:
            if exact:
                return SolverOutput(p, u, d, it, res, "pk")
            u = None          # confirm on a freshly computed displacement
            continue
        F = S | (g < 0)
        nF = int(np.count_nonzero(F))
        gm = g * F
        if load:
            gm -= float(gm.sum()) / nF
            gm *= F
        if precond is not None:
            z = precond(gm)
            z *= F
            if load:
                z -= float(z.sum()) / nF
                z *= F
        else:
            z = gm
        gz = float(np.vdot(gm, z))
        if F_old is not None and gz_old > 0:
            # Polak-Ribiere+ (restarts itself when the set or the gradient changes)
            beta = max(0.0, (gz - float(np.vdot(gm, z_old))) / gz_old)
            t *= F
            t *= beta
            t += z
        else:
            t = z.copy()
        gz_old, F_old, z_old = gz, F, z
        r = apply(t)
        tr = float(np.vdot(r, t))
        tau = float(np.vdot(gm, t)) / tr if tr > 0 else 0.0
        p -= tau * t
        clipped = float(p.min()) < 0.0
        if clipped:
            np.maximum(p, 0.0, out=p)
        alpha = 1.0
        if load:
            pm = float(p.mean())
            alpha = mean_pressure / pm if pm > 0 else 1.0
            p *= alpha
        if clipped:
            u = apply(p)
            exact = True
        else:
            u -= tau * r
            u *= alpha
            exact = False
    _fail("Polonsky-Keer CG", max_iter, res, tol, p, apply(p), d, "pk")


def restricted_cg(apply, mask, rhs, *, precond=None, tol=1e-8, max_iter=2000):
    """Solve (H x)_S = rhs_S for x supported on the set S = ``mask`` by (preconditioned) CG.

    H_SS is positive definite when S is a proper subset of a periodic grid or any subset
    for a non-periodic kernel. ``precond`` (M ~ H^-1) is applied as P_S M P_S.
    Returns ``(x, nit)``.
    """
    x = np.zeros(mask.shape)
    r = np.where(mask, rhs, 0.0)
    r0 = float(np.sqrt(np.vdot(r, r)))
    z = r if precond is None else precond(r) * mask
    d = z.copy()
    rz = float(np.vdot(r, z))
    for it in range(1, max_iter + 1):
        if np.sqrt(float(np.vdot(r, r))) <= tol * r0:
            return x, it
        q = apply(d) * mask
        alpha = rz / float(np.vdot(d, q))
        x += alpha * d
        r -= alpha * q
        z = r if precond is None else precond(r) * mask
        rz_new = float(np.vdot(r, z))
        d *= rz_new / rz
        d += z
        rz = rz_new
    raise NoConvergenceError(f"stiffness CG: residual {np.sqrt(np.vdot(r, r)) / r0:.2e} after "
                             f"{max_iter} iterations")
