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
from scipy.linalg.blas import daxpy

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
    n_products: int = 0


def kkt_residual(p, w, scale, upper=np.inf):
    """Relative KKT residual (see the module docstring); ``scale`` in m.

    With a finite ``upper`` bound of the pressure (the hardness, Pa) the points at the
    bound may interpenetrate (w <= 0): there only w > 0 violates complementarity, and
    the feasibility term counts only points below the bound.
    """
    sp = float(np.sum(p))
    if not np.isfinite(upper):
        comp = float(np.sum(p * np.abs(w)))
        feas = max(0.0, -float(np.min(w)))
    else:
        sat = p >= upper
        comp = float(np.sum(p * np.where(sat, np.maximum(w, 0.0), np.abs(w))))
        feas = max(0.0, -float(np.min(w, initial=np.inf, where=~sat)))
    comp = comp / (sp * scale) if sp > 0 else 0.0
    return max(comp, feas / scale)


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
    C = scipy.linalg.cholesky(H, lower=False, check_finite=False)
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
                tol=1e-10, max_iter=100, upper=np.inf):
    """Dense solve in displacement (``delta``) or load (``mean_pressure``) control.

    Load control: the mean pressure P(Delta) is convex and piecewise linear in Delta
    with slope the exact stiffness K(Delta), so Newton's method on Delta (warm-started
    pivoting at each step) ends in finitely many steps at the exact state. With a finite
    ``upper`` (hardness, Pa; ``method="nnls"`` only) the slope comes from the points
    strictly between the bounds (the saturated ones no longer respond).
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
    lo, hi = 0.0, np.inf
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
        if not (lo <= d_new <= hi) or not np.isfinite(d_new):
            d_new = 2 * lo + scale if not np.isfinite(hi) else 0.5 * (lo + hi)
        d = d_new
    else:
        u = H @ p
        _fail(f"dense {method} (load control)", nit, abs(pm - target) / target, tol, p, u, d,
              method)
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


# -- matrix-free: Polonsky & Keer constrained conjugate gradients ------------------------
def _rescale_to_load(p, target_sum, upper):
    """Scale the entries of ``p`` (>= 0, in place) below ``upper`` by alpha > 0 so that
    the sum, with the entries at ``upper`` kept there, equals ``target_sum``; scaled
    entries reaching ``upper`` saturate. Returns ``(alpha, saturated)``. The sum is
    concave and piecewise linear in alpha: Newton's method from the unsaturated alpha
    (below the root) increases monotonically and ends after at most as many steps as
    saturating entries."""
    if np.isfinite(upper):
        below = p < upper
        target_sum -= upper * float(p.size - np.count_nonzero(below))
        q = p[below]
    else:
        below, q = None, p
    s = float(q.sum())
    if s <= 0.0:
        return 1.0, False
    alpha = target_sum / s
    saturated = alpha * float(q.max()) > upper
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


def _shift_to_load(x, target_sum, upper):
    """Euclidean projection of ``x`` (in place) on {0 <= x <= upper, sum(x) = target_sum}:
    x <- clip(x + lam, 0, upper) with the shift lam found by safeguarded Newton steps on
    the monotone, piecewise linear sum (bisection when a step leaves the bracket).
    Returns False (x unchanged) when even x = upper everywhere is below the target."""
    if x.size * upper < target_sum:
        return False
    lo, hi = -float(x.max()), upper - float(x.min())
    lam = 0.0
    y = np.empty_like(x)
    for _ in range(200):
        np.add(x, lam, out=y)
        np.clip(y, 0.0, upper, out=y)
        f = float(y.sum()) - target_sum
        if abs(f) <= 1e-15 * target_sum or hi - lo <= 1e-16 * max(abs(lo), abs(hi)):
            break
        if f < 0:
            lo = lam
        else:
            hi = lam
        slope = int(np.count_nonzero((y > 0.0) & (y < upper)))
        step = lam - f / slope if slope else np.nan
        lam = step if lo < step < hi else 0.5 * (lo + hi)
    x[...] = y
    return True


def polonsky_keer(apply, b, scale, *, delta=None, mean_pressure=None, initial=None,
                  diagonal=1.0, precond=None, tol=1e-10, max_iter=10000, offset=0.0,
                  hardness=None, overwrite_initial=False):
    """Polonsky & Keer (1999) constrained CG with FFT operator products, bounded form.

    Solves Eq. 2.5-2.6 for ``0 <= p <= hardness`` with the gap ``w = H p - b - offset -
    Delta`` (``b`` in m; ``offset`` a scalar shift of it, so that a caller can pass the
    heights themselves and save a full-grid copy). Without ``hardness`` (``None`` or
    ``inf``) it is the elastic problem; with it, points at ``p = hardness`` are the
    perfectly plastic interface of Kato-type saturated solvers: there ``w <= 0`` (the
    interpenetration is the plastic displacement ``-w``).

    The CG runs on the free set F = {0 < p < hardness} + {p = 0, w < 0} + {p = hardness,
    w > 0} (points whose pressure may move: PK's "overlap" points enter the search
    direction directly). After each exact line search the pressure is projected on
    [0, hardness] (box projection). The conjugation uses the Polak-Ribiere+ beta,
    max(0, z.(g - g_old)) / g_old.z_old, on the direction masked to F: it restarts itself
    when the free set or the gradient changes much, instead of a forced restart at every
    clip (Fletcher-Reeves with forced restarts took 83 -> 131 -> 264 iterations at 512^2
    -> 2048^2, A* = 10 %; PR+ 50 -> 63 at 512^2 -> 1024^2).

    Load control (``mean_pressure``): the gap and the search direction are projected on
    zero mean over F and the pressure is rescaled to the load after each step
    (saturating at the hardness); Delta is the mean of ``u - b`` over the points with
    0 < p < hardness. Displacement control (``delta``): the plain projected CG on
    Eq. 2.6 (needs a positive definite H).

    ``precond`` (a linear map M ~ H^-1, e.g. the stiffness operator E*|q|/2) makes it a
    preconditioned CG (direction from z = P_F M P_F g): on rough surfaces it cuts the
    iterations 3-4 fold and they grow much more slowly with n. ``diagonal`` (m/Pa, H_ii)
    scales the first trial pressure in displacement control.

    Cost and memory: one product with H and one with M per iteration, plus a third with
    H after an iteration whose projection clipped (u = H p is then recomputed; without a
    clip u <- alpha (u - tau H t), kept with a lazy scale factor, one BLAS axpy). All CG
    vectors live on the free set F (gathered by index); the full-grid fields are p, u,
    the direction t (float64) and the previous masked gradient (float32: the
    preconditioner's input and PR's g_old), plus the transients of one FFT product.
    ``overwrite_initial`` lets the solver use ``initial`` as its pressure array (no
    copy; the caller gives it up). ``nit`` counts iterations, ``n_products`` the
    operator products (H and M).

    Returns a :class:`SolverOutput`.
    """
    load = mean_pressure is not None
    upper = np.inf if hardness is None else float(hardness)
    bounded = np.isfinite(upper)
    shape = b.shape
    n = b.size
    bf = b.reshape(-1)
    products = 0

    def H(x):
        nonlocal products
        products += 1
        return np.ascontiguousarray(apply(x.reshape(shape))).reshape(-1)

    def M(x):
        nonlocal products
        products += 1
        return np.ascontiguousarray(precond(x.reshape(shape))).reshape(-1)

    if initial is not None:
        own = (overwrite_initial and isinstance(initial, np.ndarray)
               and initial.dtype == np.float64 and initial.flags.c_contiguous
               and initial.flags.writeable)
        p = initial.reshape(-1) if own else np.array(initial, dtype=float).reshape(-1)
        np.clip(p, 0.0, upper, out=p)
        if load and not p.any():
            p[:] = mean_pressure
    elif load:
        p = np.full(n, float(mean_pressure))
    else:
        p = -(delta + offset + bf)
        p /= diagonal
        np.clip(p, 0.0, upper, out=p)
    target = float(mean_pressure) * n if load else 0.0
    if load:
        _rescale_to_load(p, target, upper)
        if bounded and float(p.sum()) < target * (1 - 1e-12):
            _shift_to_load(p, target, upper)    # too few points to carry it below the cap
    t = np.zeros(n)              # search direction, zero off F
    # masked gradient of the last iteration, zero off F: the preconditioner's input and
    # the g_old of the Polak-Ribiere beta, both only needed to single precision
    gbuf = np.zeros(n, np.float32)
    mask = np.empty(n, bool)
    F = np.empty(0, np.intp)
    S = np.flatnonzero(p)
    gz_old = 0.0
    res = np.inf
    d = 0.0 if load else float(delta)
    u, us, exact = None, 1.0, False
    for it in range(1, max_iter + 1):
        if u is None or it % 50 == 0:
            u = None
            u, us, exact = H(p), 1.0, True
        g = np.multiply(u, us) if us != 1.0 else u.copy()
        g -= bf
        g -= offset
        gS = g[S]
        pS = p[S]
        free_c = pS < upper if bounded else None
        if load:
            gE = gS[free_c] if bounded else gS
            d = float(gE.mean()) if gE.size else float(g.min())
        # KKT residual (module docstring), bounded form: at p = hardness only w > 0
        # violates complementarity
        wS = gS
        wS -= d               # in place: the gap w on S (gS is not needed any more)
        sp = float(pS.sum())
        if bounded:
            comp = float(np.dot(pS[free_c], np.abs(wS[free_c])))
            comp += float(np.dot(pS[~free_c], np.maximum(wS[~free_c], 0.0)))
            fixed = S[~free_c & (wS <= 0.0)]
        else:
            np.abs(wS, out=wS)
            comp = float(np.dot(pS, wS))
        del gS, wS, pS        # the first iterations of a cold start have S = every point
        np.less(g, d, out=mask)
        pen = np.flatnonzero(mask)
        gpen = g[pen]
        if bounded:
            gpen = gpen[p[pen] < upper]
        del pen
        feas = max(0.0, d - float(gpen.min())) if gpen.size else 0.0
        del gpen
        res = max(comp / (sp * scale) if sp > 0 else 0.0, feas / scale)
        if res <= tol:
            if exact:
                return SolverOutput(p.reshape(shape), (u * us).reshape(shape), d, it, res,
                                    "pk", products)
            u = None          # confirm on a freshly computed displacement
            continue
        mask[S] = True
        del S
        if bounded:           # saturated points pushed further in stay at the bound
            mask[fixed] = False
        F_old, F = F, np.flatnonzero(mask)    # F_old: the support of gbuf and t
        gF = g[F]
        del g
        gF -= d
        if load:
            gF -= gF.mean()
        g_old = gbuf[F]       # previous masked gradient and direction on the new free set
        tF = t[F]
        gbuf[F_old] = 0.0
        t[F_old] = 0.0
        del F_old
        gbuf[F] = gF
        if precond is not None:
            zF = M(gbuf)[F]
            if load:
                zF -= zF.mean()
        else:
            zF = gF.copy()
        gz = float(np.dot(gF, zF))
        beta = max(0.0, (gz - float(np.dot(zF, g_old))) / gz_old) if gz_old > 0 else 0.0
        del g_old             # free-set vectors go as soon as they are used: early on F
        gz_old = gz           # can hold half the grid
        tF *= beta
        tF += zF
        del zF
        t[F] = tF
        gt = float(np.dot(gF, tF))
        del gF
        r = H(t)
        tr = float(np.dot(tF, r[F]))
        tau = gt / tr if tr > 0 else 0.0
        pF = p[F]
        tF *= tau
        pF -= tF
        del tF
        lo, hi = float(pF.min()), float(pF.max())
        clipped = lo < 0.0 or hi > upper
        if clipped:
            np.clip(pF, 0.0, upper, out=pF)
        alpha = 1.0
        if load:
            # back to the load: scale F (PK's rescaling; the fixed saturated points carry
            # fixed.size * upper); if that would cross the cap, project F on the load
            # instead (Euclidean: a shift, clipped to the box), or the whole grid when F
            # cannot carry it
            carried = target - fixed.size * upper if bounded else target
            sF = float(pF.sum())
            alpha = carried / sF if sF > 0 else 0.0
            if sF > 0 and alpha * float(pF.max()) <= upper:
                pF *= alpha
            else:
                alpha, clipped = 1.0, True
                if not bounded:       # every pressure was clipped: spread the load on F
                    pF[:] = carried / pF.size
                elif not _shift_to_load(pF, carried, upper):
                    p[F] = pF
                    _shift_to_load(p, target, upper)
                    pF = p[F]
        p[F] = pF
        S = np.flatnonzero(p) if bounded else F[pF > 0]
        if clipped:
            u = None          # the projection moved p off the line: recompute u = H p
        else:
            daxpy(r, u, a=-tau / us)
            us *= alpha
            exact = False
        del r
    u = H(p)
    _fail("Polonsky-Keer CG", max_iter, res, tol, p.reshape(shape), u.reshape(shape), d, "pk")


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
