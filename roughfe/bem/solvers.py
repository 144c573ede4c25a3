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

from ..errors import InputError, NoConvergenceError
from .reductions import SERIAL


@dataclass(frozen=True, eq=False)
class SolverOutput:
    """Raw solution: pressure p (Pa), displacement u = Hp (m), approach Delta (m)."""

    pressure: np.ndarray
    displacement: np.ndarray
    delta: float
    nit: int
    residual: float
    solver: str
    n_products: int = 0


def kkt_residual(p, w, scale, upper=np.inf, axis=None):
    """Relative KKT residual (see the module docstring); ``scale`` in m.

    With a finite ``upper`` bound of the pressure (the hardness, Pa) the points at the
    bound may interpenetrate (w <= 0): there only w > 0 violates complementarity, and
    the feasibility term counts only points below the bound. With ``axis`` (the grid
    axes of stacked problems, e.g. ``(1, 2)``) one residual per row is returned as an
    array, ``scale`` then per row (:func:`roughfe.bem.batch.solve_batch`).
    """
    if not np.isfinite(upper):
        comp = np.sum(p * np.abs(w), axis=axis)
        feas = np.maximum(0.0, -np.min(w, axis=axis))
    else:
        sat = p >= upper
        comp = np.sum(p * np.where(sat, np.maximum(w, 0.0), np.abs(w)), axis=axis)
        feas = np.maximum(0.0, -np.min(w, axis=axis, initial=np.inf, where=~sat))
    res = relative_residual(comp, feas, np.sum(p, axis=axis), scale)
    return float(res) if axis is None else res


# -- the pieces of the Polonsky-Keer CG shared by its single-field form (roughfe.bem.pk) and
# its batched form (roughfe.bem.batch): scalars there, per-row arrays here -----------------
def ratio_or_zero(num, den):
    """``num / den`` where ``den > 0``, else 0: scalars (Python arithmetic, ~2 us: the
    single-field CG calls it every iteration; numpy's where costs ~12 us) or arrays."""
    if np.ndim(den) == 0 and np.ndim(num) == 0:
        return num / den if den > 0 else 0.0
    ok = np.asarray(den) > 0
    return np.where(ok, num / np.where(ok, den, 1.0), 0.0)


def relative_residual(comp, feas, total, scale):
    """The relative KKT residual of Eq. 2.5-2.6 from its parts (module docstring):
    max(comp / (total scale), feas / scale) with ``comp`` = sum p |w| (Pa m), ``feas``
    the largest interpenetration (m), ``total`` = sum p (Pa; 0 gives a complementarity
    term of 0) and ``scale`` (m). A non-finite part (a diverged iteration: NaN or inf in
    p or u) gives inf, never a residual that reads as converged (NaN pressures had given
    0 through the zero-total rule; round 2, session 31)."""
    res = np.maximum(ratio_or_zero(comp, total * scale), feas / scale)
    finite = np.isfinite(comp) & np.isfinite(feas) & np.isfinite(total)
    if np.ndim(res) == 0:
        return res if finite else np.inf
    return np.where(finite, res, np.inf)


def pr_beta(numerator, gz_old):
    """Polak-Ribiere+ conjugation coefficient of the preconditioned CG:
    beta = max(0, numerator / gz_old) with numerator = z.(g - g_old) and gz_old =
    g_old.z_old of the last iteration; 0 (a restart: steepest descent) when there is
    none (``gz_old`` <= 0). Restarting itself whenever the new gradient is not conjugate
    keeps the CG correct on a changing free set and for inexact preconditioners."""
    return np.maximum(0.0, ratio_or_zero(numerator, gz_old))


def step_length(gt, tr):
    """Exact line search along the direction t: tau = g.t / t.H t (the minimiser of the
    quadratic energy, Eq. 2.5), 0 when t.H t <= 0 (no descent possible along t)."""
    return ratio_or_zero(gt, tr)


def penetration_start(penetration, diagonal, upper=np.inf):
    """First trial pressure of displacement control (Pa), in place of ``penetration``.

    ``penetration`` = Delta + h - max h (m): how far the rigid surface would enter the
    undeformed body at each point (> 0 where they overlap). Each overlapping point gets
    the pressure that alone would push it back, penetration / H_ii (``diagonal``, m/Pa),
    clipped to [0, ``upper``]; zero elsewhere. It ignores the points' interaction, so
    it overestimates the load, but its support is the rigid-body overlap, a superset of
    the contact set. (The Polonsky-Keer solver once took minus this: pressure in the
    valleys, which cost 1.6x the products of this start; ``tests/test_bem_contact.py``.)
    Used by :func:`roughfe.bem.pk.polonsky_keer` and :func:`roughfe.bem.batch.solve_batch`.
    """
    penetration /= diagonal
    np.clip(penetration, 0.0, upper, out=penetration)
    return penetration


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


def lcp_nnls(H, s, upper=np.inf):
    """Bemporad & Paggi (2015): Cholesky H = C'C, then Lawson-Hanson NNLS on
    || C p - C^-T s ||  (scipy.optimize.nnls). Needs H positive definite. scipy does not
    report its iterations: ``nit`` counts NNLS calls (1).

    A finite ``upper`` (hardness, Pa) bounds 0 <= p <= upper: the same least-squares
    problem by Stark & Parker's bounded-variable least squares (BVLS, the bounded
    Lawson-Hanson active set, ``scipy.optimize.lsq_linear(method="bvls")``).
    """
    try:
        C = scipy.linalg.cholesky(H, lower=False, check_finite=False)
    except np.linalg.LinAlgError:
        raise InputError("solver 'nnls' needs a positive definite influence matrix (a "
                         "Cholesky factor); this one is not: use solver 'pk' or 'dense'"
                         ) from None
    d = scipy.linalg.solve_triangular(C, s, trans="T", check_finite=False)
    if np.isfinite(upper):
        sol = scipy.optimize.lsq_linear(C, d, bounds=(0.0, upper), method="bvls",
                                        lsq_solver="exact", tol=1e-15,
                                        max_iter=50 * s.size)
        p = np.clip(sol.x, 0.0, upper)
        p[sol.active_mask < 0] = 0.0       # exactly on the bounds BVLS left active
        p[sol.active_mask > 0] = upper
        return p, 1
    p, _ = scipy.optimize.nnls(C, d, maxiter=50 * s.size)
    return p, 1


def dense_solve(H, b, scale, *, delta=None, mean_pressure=None, initial=None, method="bpp",
                tol=1e-10, max_iter=100, upper=np.inf, delta_max=np.inf):
    """Dense solve in displacement (``delta``) or load (``mean_pressure``) control.

    Load control: the mean pressure P(Delta) is convex and piecewise linear in Delta
    with slope the exact stiffness K(Delta), so Newton's method on Delta (warm-started
    pivoting at each step) ends in finitely many steps at the exact state. With a finite
    ``upper`` (hardness, Pa; ``method="nnls"`` only) the slope comes from the points
    strictly between the bounds (the saturated ones no longer respond).

    ``delta_max`` (m) bounds the Newton bracket from above: a periodic operator is
    singular (a uniform pressure leaves the zero-mean displacement unchanged), so at its
    full-contact approach max h - mean h the contact matrix of every point is singular
    and beyond it pivoting returns meaningless pressures. Newton on the convex P(Delta)
    overshoots the root from below (a warm start from a much lower load), and without
    the bound it could land there and stall (relative load error 9 after 102 steps,
    measured on a mirrored cosine); a step to or beyond ``delta_max`` is a bisection.
    """
    n = b.size
    passive = None if initial is None else np.asarray(initial).ravel() > 0

    def at(d):
        s = d + b
        if method == "nnls":
            p, it = lcp_nnls(H, s, upper)
        else:
            p, it = lcp_bpp(H, s, passive)
        return p, it

    if delta is not None:
        p, nit = at(float(delta))
        u = H @ p
        res = kkt_residual(p, u - b - delta, scale, upper)
        if res > tol:
            _fail(f"dense {method}", nit, res, tol, p, u, delta, method)
        return SolverOutput(p, u, float(delta), nit, res, method)

    target = float(mean_pressure)
    d = 0.0
    if initial is not None and np.any(passive):
        c = passive
        d = float(np.mean((H[np.ix_(c, c)] @ np.asarray(initial).ravel()[c]) - b[c]))
    lo, hi = 0.0, float(delta_max)
    if not d < hi:
        d = 0.5 * hi
    nit = 0
    for k in range(max_iter):
        p, it = at(d)
        passive = (p > 0) & (p < upper)
        nit += it
        pm = float(p.mean())
        # well inside tol: the final rescaling to the exact load perturbs the KKT
        # residual by about this relative load error
        if abs(pm - target) <= max(1e-2 * tol, 1e-14) * target:
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
        if not (lo <= d_new < hi) or not np.isfinite(d_new):
            d_new = 2 * lo + scale if not np.isfinite(hi) else 0.5 * (lo + hi)
        if d_new == d or np.nextafter(lo, np.inf) >= hi:
            # Delta cannot move by less than one ulp: near full contact (K ~ 1e17 Pa/m)
            # one ulp moves the load by more than 1e-2 tol; the rescaling to the load and
            # the KKT test below decide (this loop ran out of iterations there, swapping
            # Delta between two adjacent floats: 10 of 25 loads above 0.9 p_full at 512
            # points)
            break
        d = d_new
    else:
        u = H @ p
        _fail(f"dense {method} (load control: relative load error, not the KKT residual)",
              nit, abs(pm - target) / target, tol, p, u, d, method)
    if pm > 0:
        _rescale_to_load(p, target * n, upper)
    u = H @ p
    free = (p > 0) & (p < upper)
    if free.any():     # Delta consistent with the rescaled pressure (its multiplier)
        d = float(np.mean(u[free] - b[free]))
    w = u - b - d
    res = kkt_residual(p, w, scale, upper)
    if res > tol:
        _fail(f"dense {method} (load control)", nit, res, tol, p, u, d, method)
    return SolverOutput(p, u, d, nit, res, method)


# -- load projection (dense and matrix-free solvers) ---------------------------------------
def _rescale_to_load(p, target_sum, upper, reduce=SERIAL):
    """Scale the entries of ``p`` (>= 0, in place) below ``upper`` by alpha > 0 so that
    the sum, with the entries at ``upper`` kept there, equals ``target_sum``; scaled
    entries reaching ``upper`` saturate. Returns ``(alpha, saturated)``. The sum is
    concave and piecewise linear in alpha: Newton's method from the unsaturated alpha
    (below the root) increases monotonically and ends after at most as many steps as
    saturating entries. ``reduce``: the sums' and maxima's
    (:mod:`roughfe.bem.reductions`; a distributed one without ``upper`` only)."""
    if np.isfinite(upper):
        if reduce.distributed:
            raise InputError("the distributed rescaling to the load has no upper bound")
        below = p < upper
        target_sum -= upper * float(p.size - np.count_nonzero(below))
        q = p[below]
    else:
        below, q = None, p
    s = reduce.sum(q)
    if s <= 0.0:
        return 1.0, False
    alpha = target_sum / s
    saturated = alpha * reduce.max(q) > upper
    for _ in range(q.size + 1 if saturated else 0):
        free = alpha * q < upper
        slope = float(q.sum(where=free))
        f = alpha * slope + upper * (q.size - int(np.count_nonzero(free))) - target_sum
        if f >= -1e-15 * target_sum or slope <= 0.0:
            break
        alpha -= f / slope
    q *= alpha
    if saturated:
        np.minimum(q, upper, out=q)
    if below is not None:
        p[below] = q
    return alpha, saturated


# -- matrix-free: restricted CG (the Polonsky-Keer solver is in roughfe.bem.pk) -----------
def restricted_cg(apply, mask, rhs, *, precond=None, tol=1e-8, max_iter=2000):
    """Solve (H x)_S = rhs_S for x supported on the set S = ``mask`` by (preconditioned) CG.

    H_SS is positive definite when S is a proper subset of a periodic grid or any subset
    for a non-periodic kernel. ``precond`` (M ~ H^-1) is applied as P_S M P_S.
    Returns ``(x, nit)``.
    """
    x = np.zeros(mask.shape)
    r = np.where(mask, rhs, 0.0)
    r0 = float(np.sqrt(np.vdot(r, r)))
    # M in single precision (the contact solver's float32 preconditioner) gives a float32
    # z: cast, or the direction d and with it the product H d would be float32, and the
    # recursive residual would drift from the true one by ~1e-7 (measured: a true relative
    # residual of 9e-8 where the recursion reported 1e-12)
    z = r if precond is None else np.multiply(precond(r), mask, dtype=np.float64)
    d = z.copy()
    rz = float(np.vdot(r, z))
    for it in range(1, max_iter + 1):
        if np.sqrt(float(np.vdot(r, r))) <= tol * r0:
            return x, it
        q = apply(d) * mask
        alpha = rz / float(np.vdot(d, q))
        x += alpha * d
        r -= alpha * q
        z = r if precond is None else np.multiply(precond(r), mask, dtype=np.float64)
        rz_new = float(np.vdot(r, z))
        d *= rz_new / rz
        d += z
        rz = rz_new
    raise NoConvergenceError(f"stiffness CG: residual {np.sqrt(np.vdot(r, r)) / r0:.2e} after "
                             f"{max_iter} iterations")
