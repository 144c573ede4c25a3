"""The matrix-free Polonsky-Keer solver of Eq. 2.5-2.6 (thesis Sec. 2.2) on FFT operator
products, elastic or bounded by a hardness (perfectly plastic interface), with the
conventions of :mod:`roughfe.bem.solvers` (residual, :class:`SolverOutput`). Its cost
and memory are measured in ``docs/theory/02b_bem_performance.md``.
"""
from __future__ import annotations

import warnings

import numpy as np

from . import _parallel as par
from ..errors import InputError, NoConvergenceError
from .directions import _ConjugationChain, _StallWatch, _bind_lower, _descent_guard
from .operators import FFTWorkspace
from .reductions import SERIAL
from .pk_passes import (_axpy, _gap_mask, _gap_take, _load_increment,  # noqa: F401
                        _positive_at, _shift_to_load)
from .solvers import (SolverOutput, _fail, _rescale_to_load, penetration_start, pr_beta,
                      relative_residual, step_length)

#: relative KKT residual above which the products with H may be taken in single precision
#: (``apply_single``): a hundred times the float32 rounding of u = H p (~1e-7 of max |u|)
#: when |u| is about the residual's ``scale``; scaled up by Delta / scale where the
#: approach exceeds it (:func:`_single_until`)
SINGLE_PRECISION_RESIDUAL = 1e-5


def _single_until(approach, scale):
    """The relative residual down to which u may be kept in single precision:
    ``SINGLE_PRECISION_RESIDUAL`` times max(1, |Delta| / scale). The float32 rounding
    of u is ~1e-7 of max |u|, and u is about Delta where the approach is far beyond the
    heights (a non-periodic patch pressed into nearly full contact: Delta = 8 cm on
    1 um of roughness). With the fixed threshold the residual of such a solve stalled at
    that rounding, above the threshold, and never went to double precision (20000
    iterations, KKT residual 3e-2; round 2, session 22). Below Delta = scale it is the
    fixed threshold: no solve of the usual range changes."""
    return SINGLE_PRECISION_RESIDUAL * max(1.0, abs(approach) / scale)


def polonsky_keer(apply, b, scale, *, delta=None, mean_pressure=None, initial=None,
                  diagonal=1.0, precond=None, tol=1e-10, max_iter=10000, offset=0.0,
                  hardness=None, overwrite_initial=False, apply_single=None,
                  deflation=None, split=None, approach=None, reduce=SERIAL):
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
    scales the first trial pressure in displacement control
    (:func:`roughfe.bem.solvers.penetration_start`).

    Cost and memory: one product with H and one with M per iteration, plus a third with
    H after an iteration whose projection clipped (u = H p is then recomputed; without a
    clip u <- alpha (u - tau H t), kept with a lazy scale factor, one BLAS axpy). With a
    hardness in load control alpha scales only F, not the saturated points held at the
    cap (p_fixed): then u <- alpha (u - tau H t) + (1 - alpha) H p_fixed, H p_fixed kept
    in one more full-grid field (from its first use) and recomputed when that set
    changes (recomputing u instead took 9 % more products; the plain recursion drifted
    from H p, 2-cycled and overflowed: 122 iterations for a 128-point profile solved in
    16, review, session 25). All CG vectors live on the free set F (gathered by index);
    the full-grid fields are p, u, the direction t (float64) and the previous masked
    gradient (float32: the preconditioner's input and PR's g_old), the FFT workspace of
    the products (one complex half-spectrum) and the kept output r of H t (and of M g,
    as a view), plus the free set's grid mask (a byte a point). The gap u - b is never stored on the
    whole grid: it is computed in cache-sized chunks where it is tested and gathered
    where it is used. After the first iteration no full-grid array is allocated
    (measured at 2048^2: 3.1x fewer page faults, system time 9.9 -> 2.5 s).
    ``overwrite_initial`` lets the solver use ``initial`` as its pressure array (no
    copy; the caller gives it up). ``nit`` counts iterations, ``n_products`` the
    operator products (H and M).

    ``apply_single`` (H in single precision: float32 in and out) makes the iterations
    with a residual above ``SINGLE_PRECISION_RESIDUAL`` (times Delta / scale where that
    exceeds 1: :func:`_single_until`) mixed precision: u and H t are
    float32 (half the FFT work and half the memory of u in the first iterations, where
    the free set is large and most steps clip), the gradient, the CG vectors and p stay
    float64. Below that residual u is recomputed once in double precision and kept in
    float64, while the products stay float32: H t of the (float32) direction t updates u
    by an axpy, and after a clip u += H dp of the pressure's increment dp on F (instead
    of a float64 H p). Their rounding (~1e-7 of |H t| and |H dp|) shrinks with the
    steps, i.e. with the residual: iterative refinement of u. A solution is only
    returned after a freshly computed double-precision u = H p confirmed it, so the
    converged residual, A* and pressures are the float64 ones (measured: 4 loads at
    512^2-2048^2, the same contact sets, pressures within 4e-9 of max p of the
    all-float64 phase, 8 % (2048^2) to 12 % (1024^2) less CPU).

    ``deflation``: a two-level coarse correction of the direction (its ``zero_mean``
    must be the control: True in load control, False in displacement control of a
    positive definite H), an object with ``correct(F, gF, zF, apply_free, free_mask,
    pressure) -> zF``
    that turns the preconditioned gradient ``zF = (M g)_F`` into the two-level one,
    given the flat free-set indices ``F``, the gradient ``gF``, ``apply_free(xF) =
    (H x)_F`` (a counted product, single precision when ``apply_single`` is given),
    F's grid mask (bool) and the pressure p (its contact part: p > 0). The
    Polak-Ribiere beta keeps the CG flexible for such a (possibly inexact)
    preconditioner. The reference form is
    :class:`roughfe.bem.deflation.ProbedBlockDeflation`, the production one
    :class:`roughfe.bem.deflation.BlockDeflation` (used by ``solve_contact`` in its
    measured range), both measured in ``docs/theory/02b_bem_performance.md``. With a
    deflation the direction also drops its steps below p = 0 at the points of F where
    p is 0 (:func:`_bind_lower`, the binding set of projected-gradient methods), keeps
    the correction only where it leaves a descent direction (:func:`_descent_guard`),
    and drops it for good, with a RuntimeWarning, when the residual has not halved for
    ``STALL_WINDOW`` iterations (:class:`~roughfe.bem.directions._StallWatch`).

    ``split`` (optional, the operator's
    :meth:`~roughfe.bem.operators.InfluenceOperator.split_product`): the product H t
    of the line search in two halves. The step length needs only t . H t, which the
    forward transform gives (Parseval); the inverse half, H t itself, is only done
    when the step is kept (u <- u - tau H t). After a clipped step u is recomputed
    anyway, and most steps of the contact-set search clip (measured at 2048^2, 4 cold
    loads: 69 of 99 iterations), so their H t was never used. The energy is that of
    the rounded t (single precision: 1e-7 relative, as the product's).

    ``approach`` (load control only): a callable ``approach(res, Delta) -> float or
    None``, asked after every residual with the current Delta, that may move the mean
    pressure (it returns the new one) to reach an imposed approach
    (:class:`roughfe.bem.approach.LoadSecant`); the solve ends only at a residual below
    ``tol`` where it did not move the load. With a preconditioner the load's increment
    goes onto the contact set as M 1_S (clipped at 0), the pressure change of a nearly
    uniform displacement of S, and the CG restarts from there; a plain rescaling would
    make the gap on S as uneven as u itself (02b, session 17: 815 instead of 945
    iterations on a 1024^2 sweep).

    ``reduce``: where the global reductions come from (sums, dots, means, min/max, the
    point count and with it the load target): :data:`~roughfe.bem.reductions.SERIAL`
    (the whole grid in this process) or a
    :class:`~roughfe.bem.reductions.CommReductions`, for a slab of a grid distributed
    over MPI ranks, ``b`` and every field the rank's slab, ``apply`` and ``precond``
    the distributed products (:mod:`roughfe.bem.distributed`). Distributed: elastic
    load control with a preconditioner only (no hardness, deflation, approach, split
    or single-precision product; an InputError names the one given).

    Returns a :class:`SolverOutput`.
    """
    load = mean_pressure is not None
    if reduce.distributed:
        unfit = [name for name, bad in (
            ("displacement control (delta)", not load), ("a hardness", hardness is not None),
            ("a deflation", deflation is not None), ("an approach hook", approach is not None),
            ("a split product", split is not None), ("apply_single", apply_single is not None),
            ("no preconditioner", precond is None)) if bad]
        if unfit:
            raise InputError(f"the distributed Polonsky-Keer CG runs elastic load control "
                             f"with a preconditioner only; got {', '.join(unfit)}")
    if approach is not None and not load:
        raise InputError("an approach hook moves the load: it needs load control "
                         "(mean_pressure)")
    single = apply_single is not None
    if deflation is not None and getattr(deflation, "zero_mean", True) != load:
        raise InputError("a deflation (coarse correction) must match the control: its "
                         "coarse space is the zero-mean one in load control "
                         "(mean_pressure) only (zero_mean=False for delta)")
    upper = np.inf if hardness is None else float(hardness)
    bounded = np.isfinite(upper)
    shape = b.shape
    n = b.size
    bf = b.reshape(-1)
    products = 0

    # Buffers: every product writes into a kept array ("u": u = H p, "r": H t and, as a
    # view, M g) through one FFT workspace. An iteration allocates no full-grid array:
    # fresh ones cost a page fault per page on first touch (216 of 716 s CPU were
    # system time at 8192^2).
    work = FFTWorkspace()
    work.array((n // shape[-1], shape[-1] // 2 + 1), np.complex128)
    kept = {}
    m_dtype = None

    def buffer(name, dtype):
        """Kept full-grid array ``name`` of ``dtype`` (the float32 arrays of the
        mixed-precision phase are replaced once by float64 ones)."""
        a = kept.get(name)
        if a is None or a.dtype != dtype:
            kept[name] = None        # the old one goes first
            kept[name] = a = np.empty(n, dtype)
        return a

    def product(fn, x, out):
        nonlocal products
        products += 1
        y = fn(x.reshape(shape), out=None if out is None else out.reshape(shape), work=work)
        return np.ascontiguousarray(y).reshape(-1)

    def H(x, name, low32=False):
        if low32:
            return product(apply_single, x, buffer(name, np.float32))
        return product(apply, x, buffer(name, np.float64))

    def M(x):
        nonlocal m_dtype
        if m_dtype is None:          # the first call tells the preconditioner's dtype
            z = product(precond, x, None)
            m_dtype = z.dtype
            return z
        r = buffer("r", np.float32 if single else np.float64)
        out = (r.view(m_dtype)[:n] if r.dtype.itemsize >= m_dtype.itemsize
               else buffer("z", m_dtype))
        return product(precond, x, out)

    def H_free(xF):
        """(H x)_F of x supported on F, in single precision when possible (it only
        steers the search direction)."""
        y = buffer("y", np.float32 if single else np.float64)
        y.fill(0.0)
        y[F] = xF
        return product(apply_single if single else apply, y, y)[F]

    fixed_key = [None]

    def H_fixed(idx):
        """H of the pressure ``upper`` on the saturated points ``idx`` (kept field "f",
        single precision when possible: an increment of u), computed again only when
        that set changes."""
        if fixed_key[0] is None or not np.array_equal(fixed_key[0], idx):
            y = buffer("f", np.float32 if single else np.float64)
            y.fill(0.0)
            y[idx] = upper
            product(apply_single if single else apply, y, y)
            fixed_key[0] = idx
        return kept["f"]

    if initial is not None:
        own = (overwrite_initial and isinstance(initial, np.ndarray)
               and initial.dtype == np.float64 and initial.flags.c_contiguous
               and initial.flags.writeable)
        p = initial.reshape(-1) if own else np.array(initial, dtype=float).reshape(-1)
        np.clip(p, 0.0, upper, out=p)
        if load and not reduce.any(p):
            p[:] = mean_pressure
    elif load:
        p = np.full(n, float(mean_pressure))
    else:
        p = penetration_start(bf + (delta + offset), diagonal, upper)
    target = float(mean_pressure) * reduce.count(n) if load else 0.0
    if load:
        _rescale_to_load(p, target, upper, reduce)
        if bounded and float(p.sum()) < target * (1 - 1e-12):
            _shift_to_load(p, target, upper)    # too few points to carry it below the cap
    # search direction, zero off F: only the input of H t, in single precision when that
    # product is (the free-set copies tF of it are float64)
    t = np.zeros(n, np.float32 if single else np.float64)
    # masked gradient of the last iteration, zero off F: the preconditioner's input and
    # the g_old of the Polak-Ribiere beta, both only needed to single precision
    gbuf = np.zeros(n, np.float32)
    mask = np.empty(n, bool)          # F as a grid mask
    F = np.empty(0, np.intp)
    S = np.flatnonzero(p)
    gz_old = 0.0
    chain = _ConjugationChain()   # restarts a run-away conjugation (directions.py)
    res = np.inf
    # d is Delta + offset: the gap is g - d with g = u - b (offset folded into d: one
    # full-grid pass less per iteration); Delta = d - offset is what is returned
    d = 0.0 if load else float(delta) + offset
    u, us, exact = None, 1.0, False
    low = confirm = False     # u (and H t) in single precision; a final check pending
    watch = None if deflation is None else _StallWatch()
    for it in range(1, max_iter + 1):
        if low and res <= _single_until(d - offset, scale):
            u = None          # near the solution: double precision from here on
        if u is None or it % 50 == 0:
            u = None
            low = (apply_single is not None and not confirm
                   and res > _single_until(d - offset, scale))
            u, us, exact = H(p, "u", low), 1.0, True
            confirm = False
        # the gap g = u - b: on S here, its test g < d (mask) and minimum in one pass
        # below, on F after that (never stored on the whole grid)
        gS = _gap_take(u, us, bf, S)
        pS = par.take(p, S)
        free_c = pS < upper if bounded else None
        if load:
            gE = gS[free_c] if bounded else gS
            d = (float(reduce.mean(gE)) if reduce.size(gE) else reduce.min_of(
                min(par.blocks(n, lambda i, j: _gap_mask(u, us, bf, -np.inf, mask, i, j)))))
        # KKT residual (module docstring), bounded form: at p = hardness only w > 0
        # violates complementarity
        wS = gS
        wS -= d               # in place: the gap w on S (gS is not needed any more)
        sp = reduce.sum(pS)
        if bounded:
            comp = float(np.dot(pS[free_c], np.abs(wS[free_c])))
            comp += float(np.dot(pS[~free_c], np.maximum(wS[~free_c], 0.0)))
            fixed = S[~free_c & (wS <= 0.0)]
        else:
            np.abs(wS, out=wS)
            comp = reduce.dot(pS, wS)
        del gS, wS, pS        # the first iterations of a cold start have S = every point
        gmin = reduce.min_of(min(par.blocks(n, lambda i, j: _gap_mask(u, us, bf, d, mask,
                                                                      i, j))))
        if bounded:           # points at the bound may interpenetrate
            pen = par.flatnonzero(mask)
            gpen = _gap_take(u, us, bf, pen)
            gpen = gpen[p[pen] < upper]
            del pen
            feas = max(0.0, d - float(gpen.min())) if gpen.size else 0.0
            del gpen
        else:                 # the largest penetration, anywhere
            feas = max(0.0, d - gmin)
        res = float(relative_residual(comp, feas, sp, scale))
        if res == np.inf:     # NaN or inf in p or u: the iteration diverged
            raise NoConvergenceError(
                f"Polonsky-Keer CG diverged at iteration {it}: non-finite pressure or "
                f"displacement", result=SolverOutput(p.reshape(shape), u.reshape(shape),
                                                     np.nan, it, res, "pk", products))
        moved = None if approach is None else approach(res, d - offset)
        if moved is not None:         # an imposed approach: the load moves (docstring)
            extra, target = float(moved) * n - target, float(moved) * n
            if precond is not None and _load_increment(p, S, extra, M, gbuf, target):
                u, gz_old = None, 0.0     # gbuf is zero now: the CG restarts
                continue
        elif res <= tol:
            if exact and not low:
                if us != 1.0:
                    u *= us
                return SolverOutput(p.reshape(shape), u.reshape(shape), d - offset,
                                    it, res, "pk", products)
            u = None          # confirm on a freshly computed double-precision displacement
            confirm = True
            continue
        if watch is not None and watch.stalled(res):
            warnings.warn(f"Polonsky-Keer CG: the two-level correction made no progress "
                          f"(KKT residual {res:.2e}, not halved in {watch.window} "
                          f"iterations); dropped at iteration {it}, the plain "
                          f"preconditioned CG goes on", RuntimeWarning, stacklevel=2)
            deflation = watch = None
        par.put(mask, S, True)
        del S
        if bounded:           # saturated points pushed further in stay at the bound
            par.put(mask, fixed, False)
        F_old, F = F, par.flatnonzero(mask)    # F_old: the support of gbuf and t
        gF = _gap_take(u, us, bf, F)
        gF -= d
        if load:
            gF -= reduce.mean(gF)
        g_old = par.take(gbuf, F)   # previous masked gradient and direction on the new F
        tF = par.take(t, F)
        par.put(gbuf, F_old, 0.0)
        par.put(t, F_old, 0.0)
        del F_old
        par.put(gbuf, F, gF)
        # with a deflation: p > 0 on F, the binding set's test below
        positive = None if deflation is None else _positive_at(p, F)
        if precond is not None:
            zF = par.take(M(gbuf), F)
            if load:
                zF -= reduce.mean(zF)
            if deflation is not None:
                zF, gz = _descent_guard(gF, zF, deflation.correct(F, gF, zF, H_free,
                                                                  free_mask=mask,
                                                                  pressure=p))
        else:
            zF = gF.copy()
        if precond is None or deflation is None:
            gz = reduce.dot(gF, zF)
        beta = chain.beta(float(pr_beta(gz - reduce.dot(zF, g_old), gz_old)), gz)
        del g_old             # free-set vectors go as soon as they are used: early on F
        gz_old = gz           # can hold half the grid
        # the new direction on F, float64 (t and zF may be float32)
        tF = np.multiply(tF, beta, dtype=np.float64)
        tF += zF
        del zF
        if positive is not None:   # the binding set: no step below p = 0 where p is 0
            _bind_lower(tF, positive, load)
        del positive
        par.put(t, F, tF)
        gt = reduce.dot(gF, tF)
        del gF
        if split is None:
            r = H(t, "r", single)
            tr = reduce.dot(tF, par.take(r, F))
            finish = None
        else:         # t . H t from the forward transform: H t only if the step is kept
            products += 1
            r = buffer("r", t.dtype)
            tr, finish = split(t.reshape(shape), single=single, out=r.reshape(shape),
                               work=work)
        tau = float(step_length(gt, tr))
        pF = par.take(p, F)
        tF *= tau
        pF -= tF
        del tF
        lo, hi = reduce.min(pF), reduce.max(pF)
        clipped = lo < 0.0 or hi > upper
        if clipped:
            np.clip(pF, 0.0, upper, out=pF)
        alpha, whole = 1.0, False
        if load:
            # back to the load: scale F (PK's rescaling; the fixed saturated points carry
            # fixed.size * upper); if that would cross the cap, project F on the load
            # instead (Euclidean: a shift, clipped to the box), or the whole grid when F
            # cannot carry it
            carried = target - fixed.size * upper if bounded else target
            sF = reduce.sum(pF)
            alpha = carried / sF if sF > 0 else 0.0
            if sF > 0 and alpha * reduce.max(pF) <= upper:
                pF *= alpha
            else:
                alpha, clipped = 1.0, True
                if not bounded:       # every pressure was clipped: spread the load on F
                    pF[:] = carried / reduce.size(pF)
                elif not _shift_to_load(pF, carried, upper):
                    par.put(p, F, pF)
                    _shift_to_load(p, target, upper)
                    pF = par.take(p, F)
                    whole = True      # p moved off F too
        # after a clip in the double-precision phase u is updated by the float32 product
        # of the pressure's increment dp (supported on F): u + H dp (rounding ~1e-7 of
        # |H dp|, which shrinks with the residual) instead of a float64 H p
        step = (pF - par.take(p, F) if clipped and single and not low and not whole
                else None)
        par.put(p, F, pF)
        S = par.flatnonzero(p) if bounded else F[pF > 0]
        if clipped and step is None:
            u = None          # the projection moved p off the line: recompute u = H p
        elif clipped:
            par.blocks(n, lambda i, j: r[i:j].fill(0.0))
            par.put(r, F, step)
            del step
            r = H(r, "r", True)
            _axpy(u, 1.0 / us, r)
            exact = False
        else:
            if finish is not None:
                finish()      # H t into r
            _axpy(u, -tau / us, r)
            us *= alpha
            exact = False
            if bounded and load and fixed.size and alpha != 1.0:
                # alpha scaled F only: the saturated points keep p = upper, so
                # H p = alpha (u - tau H t) + (1 - alpha) H p_fixed
                _axpy(u, (1.0 - alpha) / us, H_fixed(fixed))
        del r, finish
    u = H(p, "u")
    _fail("Polonsky-Keer CG", max_iter, res, tol, p.reshape(shape), u.reshape(shape),
          d - offset, "pk")
