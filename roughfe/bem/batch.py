"""Many contact problems at once: a batched Polonsky-Keer solver (thesis Eq. 2.5-2.6).

A design search (and a database build) solves the *same* influence operator for
hundreds of different rigid profiles. One problem of N = 512 points costs about a
millisecond of Python per solve in :func:`roughfe.bem.solve_contact`, almost none of it
arithmetic. Here B problems are stacked as rows of arrays ``(B, *shape)``: every
operator product is one FFT over the trailing axes of the whole stack, every inner
product a reduction along them, and the free sets and convergence are per-row masks,
so B rows cost little more than a few (measured in ``docs/theory/06_design.md``).

The algorithm is the Polonsky & Keer (1999) constrained conjugate gradient of
:func:`roughfe.bem.pk.polonsky_keer` (elastic form, Strang-circulant preconditioner,
Polak-Ribiere+ conjugation on the free set, PK's rescaling to the load after each step)
with the same relative KKT residual (:mod:`roughfe.bem.solvers`), so a converged row is
the same contact state as a single solve; what differs is only the bookkeeping:
vectors are full rows masked to the free set instead of gathered index arrays, and a
row leaves the iteration when its residual is below ``tol`` on a freshly computed
displacement.

Conventions as in :mod:`roughfe.bem.solvers`: heights ``h`` (m), gap
``w = H p + max h - h - Delta`` >= 0, pressure p >= 0 (Pa), complementarity; load
control imposes the mean pressure per row and Delta is the mean of ``H p + max h - h``
over the contact set.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.fft

from ..errors import InputError, NoConvergenceError
from ..model import Material, central_differences
from .operators import WORKERS, InfluenceOperator, influence_operator


@dataclass(frozen=True, eq=False)
class BatchState:
    """Solutions of B contact problems: ``pressure`` (Pa) and ``displacement`` (m),
    shape ``(B, *grid)``; per row the approach ``delta`` (m), ``mean_pressure`` (Pa),
    ``n_contact`` (points with p > 0), CG iterations ``nit`` and the relative KKT
    ``residual``."""

    pressure: np.ndarray
    displacement: np.ndarray
    delta: np.ndarray
    mean_pressure: np.ndarray
    n_contact: np.ndarray
    nit: np.ndarray
    residual: np.ndarray
    #: :func:`solve_batch_exact` only: per row its final pivoting set and the solutions
    #: x_c, x_1 on it, so that the next step of a sweep starts without a solve
    pivots: tuple = None


@dataclass(frozen=True, eq=False)
class BatchSweep:
    """Load-approach sweeps of B profiles at ``m`` steps each, arrays ``(B, m)``:
    ``delta`` (m), ``mean_pressure`` (Pa), ``area_fraction`` (-) and the stiffness
    ``stiffness`` = dp/dDelta (Pa/m) by central differences over the steps
    (:func:`roughfe.model.central_differences`, as :func:`roughfe.bem.contact_sweep`
    reports it with ``compute_stiffness=False``); ``nit`` CG iterations per row."""

    delta: np.ndarray
    mean_pressure: np.ndarray
    area_fraction: np.ndarray
    stiffness: np.ndarray
    nit: np.ndarray


class BatchOperator:
    """``u = H p`` for a stack of pressures ``(B, *shape)`` (one FFT over the trailing
    axes of the stack) and its Strang-circulant approximate inverse (the CG
    preconditioner of :meth:`InfluenceOperator.inverse_spectrum`)."""

    def __init__(self, op: InfluenceOperator):
        self.op = op
        self.shape = tuple(op.shape)
        self.axes = tuple(range(-len(self.shape), 0))
        self.fft_shape = tuple(op.fft_shape)
        self.inverse = op.inverse_spectrum()

    def apply(self, p):
        ph = scipy.fft.rfftn(p, s=self.fft_shape, axes=self.axes, workers=WORKERS)
        ph *= self.op.spectrum
        u = scipy.fft.irfftn(ph, s=self.fft_shape, axes=self.axes, workers=WORKERS)
        return u[(Ellipsis,) + tuple(slice(0, n) for n in self.shape)]

    def precondition(self, g):
        gh = scipy.fft.rfftn(g, axes=self.axes, workers=WORKERS)
        gh *= self.inverse
        return scipy.fft.irfftn(gh, s=self.shape, axes=self.axes, workers=WORKERS)


def _rows(x, B, name):
    x = np.asarray(x, dtype=float)
    x = np.broadcast_to(x, (B,)) if x.ndim == 0 else x
    if x.shape != (B,) or not np.all(np.isfinite(x)) or np.any(x < 0):
        raise InputError(f"{name} must be finite and >= 0, one value per row ({B}), got "
                         f"shape {x.shape}")
    return x


def solve_batch(op: InfluenceOperator, heights, *, delta=None, mean_pressure=None,
                initial=None, tol: float = 1e-10, max_iter: int = 2000) -> BatchState:
    """Solve B elastic contact problems on one operator, Eq. 2.5-2.6, by a batched
    Polonsky-Keer CG (see the module notes).

    Parameters
    ----------
    op : InfluenceOperator
        The operator (:func:`roughfe.bem.influence_operator`) of every row.
    heights : ndarray, shape (B, *op.shape)
        The rigid surfaces' heights (m), one per row.
    delta, mean_pressure : float or ndarray (B,)
        Exactly one: the approach from first contact (m; displacement control) or the
        mean pressure (Pa; load control), per row.
    initial : ndarray, optional
        Starting pressures (Pa), e.g. the previous step of a sweep.
    tol : float
        Relative KKT residual of every row (:func:`roughfe.bem.solvers.kkt_residual`).
    max_iter : int
        CG iterations; a row above ``tol`` after them raises NoConvergenceError.
    """
    h = np.asarray(heights, dtype=float)
    if h.ndim != len(op.shape) + 1 or h.shape[1:] != tuple(op.shape) or h.shape[0] < 1 \
            or not np.all(np.isfinite(h)):
        raise InputError(f"heights must be finite, shape (B, {', '.join(map(str, op.shape))}),"
                         f" got {h.shape}")
    if (delta is None) == (mean_pressure is None):
        raise InputError("give exactly one of delta (m) or mean_pressure (Pa)")
    B = h.shape[0]
    shape = h.shape
    ax = tuple(range(1, h.ndim))
    load = mean_pressure is not None
    hmax = h.max(axis=ax, keepdims=True)
    c = h - hmax                                    # gap = u - c - Delta
    scale = np.ptp(h.reshape(B, -1), axis=1)
    if np.any(scale == 0):
        raise InputError("a row of heights is flat: no rough-contact solution")
    bop = BatchOperator(op)
    n = int(np.prod(op.shape))
    if load:
        pm = _rows(mean_pressure, B, "mean_pressure")
        if np.any(pm == 0):
            raise InputError("mean_pressure must be > 0 in every row")
        target = pm * n
    else:
        dl = _rows(delta, B, "delta")
    if initial is not None:        # pressures or a BatchState (its pressures)
        p = np.clip(np.array(getattr(initial, "pressure", initial), dtype=float).reshape(shape),
                    0.0, None)
    elif load:
        p = np.broadcast_to(pm.reshape((B,) + (1,) * len(ax)), shape).copy()
    else:
        p = np.clip((dl.reshape((B,) + (1,) * len(ax)) + c) / op.diagonal, 0.0, None)
    if load:
        s = p.sum(axis=ax)
        p[s == 0] = pm[s == 0].reshape((-1,) + (1,) * len(ax))
        p *= (target / p.sum(axis=ax)).reshape((B,) + (1,) * len(ax))

    def col(x):                     # per-row scalar broadcast over the grid
        return x.reshape((-1,) + (1,) * len(ax))

    u = bop.apply(p)
    t = np.zeros(shape)
    g_old = np.zeros(shape)
    gz_old = np.zeros(B)
    fresh = np.ones(B, bool)        # u = H p recomputed (not updated) this iteration
    d = np.zeros(B) if load else dl.copy()
    res = np.full(B, np.inf)
    nit = np.zeros(B, int)
    act = np.arange(B)              # rows still iterating
    for it in range(1, max_iter + 1):
        pa, ua, ca = p[act], u[act], c[act]
        g = ua - ca
        S = pa > 0
        nS = S.sum(axis=ax)
        if load:
            da = np.where(nS > 0, np.where(S, g, 0).sum(axis=ax) / np.maximum(nS, 1),
                          g.min(axis=ax))
            d[act] = da
        else:
            da = d[act]
        w = g - col(da)
        sp = pa.sum(axis=ax)
        comp = np.where(sp > 0, (pa * np.abs(w)).sum(axis=ax) / (np.where(sp > 0, sp, 1)
                                                                  * scale[act]), 0.0)
        res_a = np.maximum(comp, np.maximum(0.0, -w.min(axis=ax)) / scale[act])
        res[act] = res_a
        nit[act] = it
        done = (res_a <= tol) & fresh[act]
        fresh[act] = False
        redo = (res_a <= tol) & ~done   # converged on an updated u: confirm on a fresh one
        keep = ~done
        if not keep.any():
            break
        act, pa, ua, g, w, S = act[keep], pa[keep], ua[keep], g[keep], w[keep], S[keep]
        redo = redo[keep]
        F = S | (w < 0)
        gF = np.where(F, w, 0.0)
        nF = np.maximum(F.sum(axis=ax), 1)
        if load:
            gF -= np.where(F, col(gF.sum(axis=ax) / nF), 0.0)
        z = np.where(F, bop.precondition(gF), 0.0)
        if load:
            z -= np.where(F, col(z.sum(axis=ax) / nF), 0.0)
        gz = (gF * z).sum(axis=ax)
        go = gz_old[act]
        beta = np.where(go > 0, np.maximum(0.0, (gz - (z * g_old[act] * F).sum(axis=ax))
                                           / np.where(go > 0, go, 1.0)), 0.0)
        ta = np.where(F, col(beta) * t[act] + z, 0.0)
        gz_old[act] = gz
        g_old[act] = gF
        gt = (gF * ta).sum(axis=ax)
        r = bop.apply(ta)
        tr = (ta * r).sum(axis=ax)
        tau = np.where(tr > 0, gt / np.where(tr > 0, tr, 1.0), 0.0)
        pa = pa - col(tau) * ta
        clipped = (pa < 0).any(axis=ax)
        np.clip(pa, 0.0, None, out=pa)
        alpha = np.ones(act.size)
        if load:
            sF = pa.sum(axis=ax)
            alpha = np.where(sF > 0, target[act] / np.where(sF > 0, sF, 1.0), 1.0)
            empty = sF <= 0                     # every pressure clipped: spread on F
            pa[empty] = np.where(F[empty], col(target[act][empty] / nF[empty]), 0.0)
            clipped |= empty
            pa *= col(np.where(empty, 1.0, alpha))
        t[act] = ta
        p[act] = pa
        # u follows the step unless the projection moved p off the line (then H p again)
        ua = col(alpha) * (ua - col(tau) * r)
        again = clipped | redo | (it % 50 == 0)
        if again.any():
            ua[again] = bop.apply(pa[again])
        u[act] = ua
        fresh[act] = again
    else:
        bad = np.flatnonzero(res > tol)
        raise NoConvergenceError(
            f"batched Polonsky-Keer CG: {bad.size} of {B} rows above tol {tol:.1e} after "
            f"{max_iter} iterations (largest relative KKT residual {res.max():.3e})",
            result=None)
    n_contact = (p > 0).reshape(B, -1).sum(axis=1)
    return BatchState(p, u, d.copy(), p.reshape(B, -1).mean(axis=1), n_contact, nit, res)


def _exact_ok(op) -> bool:
    return not op.periodic and len(op.shape) == 1 and op.shape[0] <= 4096


def _gather(F, width=0):
    """Indices (R, m) of the True entries of each row of ``F`` (R, n), then of False
    ones as padding, and the mask of the True ones (R, m); m = the largest row count
    (at least 1, at least ``width``)."""
    m = min(max(int(F.sum(axis=1).max()), 1, int(width)), F.shape[1])
    order = np.argsort(~F, axis=1, kind="stable")[:, :m]
    return order, np.take_along_axis(F, order, axis=1)


#: rows per stacked LAPACK call of the direct solves, grouped by set size (a group is
#: padded to its largest set)
DIRECT_GROUP = 16


def _set_solutions(Hd, c, F, basis=None, rows=None):
    """Solutions ``x`` (R, m, 2) of ``H_FF x = [c_F, 1]`` for every row's set ``F``
    (R, n), on the slots ``idx`` (R, m) where ``valid`` (R, m); returns (idx, valid, x).

    Direct: the systems gathered, padded with the identity and solved by LAPACK together,
    in groups of :data:`DIRECT_GROUP` rows of similar set size. With a ``basis``
    (idx_U, valid_U, G) of all B rows (``rows``: which of them ``F`` holds): G = H_UU^-1
    of a set U per row (the state at the largest load of a sweep); a row whose F lies in
    U and leaves fewer points of U out than it holds takes the Schur complement instead,
    ``H_FF^-1 = G_FF - G_FR G_RR^-1 G_RF`` (one small solve of |R| unknowns and products
    with G, no factorisation of H_FF)."""
    R = F.shape[0]
    use = np.zeros(R, bool)
    if basis is not None:
        iu, vu = basis[0][rows], basis[1][rows]
        fm = vu & np.take_along_axis(F, iu, axis=1)
        rm = vu & ~fm
        use = (fm.sum(axis=1) == F.sum(axis=1)) & (rm.sum(axis=1) < fm.sum(axis=1))
    width = iu.shape[1] if use.any() else 0
    idx, valid = _gather(F, width)
    x = np.zeros(idx.shape + (2,))

    def rhs_of(cc, i, v):
        return np.stack([np.where(v, np.take_along_axis(cc, i, axis=1), 0.0),
                         v.astype(float)], axis=-1)

    d = np.flatnonzero(~use)
    d = d[np.argsort(F[d].sum(axis=1), kind="stable")]
    for g in range(0, d.size, DIRECT_GROUP):
        dg = d[g:g + DIRECT_GROUP]
        i, v = _gather(F[dg])
        m = i.shape[1]
        A = np.where(v[:, :, None] & v[:, None, :], Hd[i[:, :, None], i[:, None, :]],
                     np.eye(m))
        x[dg, :m] = np.linalg.solve(A, rhs_of(c[dg], i, v))
    if use.any():
        s_ = np.flatnonzero(use)
        whole = s_.size == basis[2].shape[0] and np.array_equal(rows[s_], s_)
        iu, fm, rm = iu[s_], fm[s_], rm[s_]
        G = basis[2] if whole else basis[2][rows[s_]]      # no copy of every row's G
        y = G @ rhs_of(c[s_], iu, fm)
        ir, vr = _gather(rm)
        if vr.any():
            r = ir.shape[1]
            Gur = np.take_along_axis(G, ir[:, None, :], axis=2)
            Grr = np.take_along_axis(Gur, ir[:, :, None], axis=1)
            Grr = np.where(vr[:, :, None] & vr[:, None, :], Grr, np.eye(r))
            yr = np.where(vr[..., None], np.take_along_axis(y, ir[..., None], axis=1), 0.0)
            Gur = np.where(vr[:, None, :], Gur, 0.0)
            y = y - Gur @ np.linalg.solve(Grr, yr)
        M = iu.shape[1]
        x[s_] = 0.0
        x[s_, :M] = np.where(fm[..., None], y, 0.0)
        idx[s_], valid[s_] = 0, False
        idx[s_, :M], valid[s_, :M] = iu, fm
        if idx.shape[1] > M:                   # padding slots: nodes outside U (not in F)
            out = np.argsort(_members(iu, F.shape[1]), axis=1, kind="stable")
            idx[s_, M:] = out[:, :idx.shape[1] - M]
    return idx, valid, x


def _members(idx, n):
    """(R, n) bool: the nodes named by each row of ``idx``."""
    out = np.zeros((idx.shape[0], n), bool)
    np.put_along_axis(out, idx, True, axis=1)
    return out


def solve_batch_exact(op: InfluenceOperator, heights, *, delta=None, mean_pressure=None,
                      initial=None, max_exchanges: int = 60, basis=None) -> BatchState:
    """The exact solution of B contact problems of a non-periodic profile operator by
    batched block principal pivoting (Judice & Pires 1994, as
    :func:`roughfe.bem.solvers.lcp_bpp`), displacement or load control.

    On a contact set F the gap vanishes, ``H_FF p_F = c_F + Delta`` with
    ``c = h - max h``: two right-hand sides give ``p_F = x_c + Delta x_1``. Displacement
    control fixes Delta; load control takes the Delta whose p_F carries the load,
    ``Delta = (n P - sum x_c) / sum x_1`` (P(Delta) is linear on a fixed set, so this is
    the Newton step of :func:`roughfe.bem.solvers.dense_solve` taken exactly). Then every
    row exchanges its infeasible points at once (p < 0 in F, w < 0 off F); when their
    number stops falling (3 tries) only the last one, Murty's rule. The systems of all
    rows are stacked, padded to the largest set with the identity, and solved together
    (LAPACK on (B, m, m)); the gaps come from one batched FFT product. ``initial``
    pressures give the starting sets (a warm start: the previous step of a sweep needs
    one or two exchanges); without them the set starts at the highest point (load
    control) or at the points that :func:`solve_batch` (the CG, to 1e-4) puts in
    contact. A row that does not settle in ``max_exchanges`` is finished by the CG.
    Dense: the operator as an n x n matrix (n <= 4096 points). ``basis``: the inverse of
    H on a superset of the contact sets per row (:func:`set_inverse` of a state at a
    larger load), so that most sets are solved by a small Schur complement
    (:func:`_set_solutions`).
    """
    h = np.asarray(heights, dtype=float)
    if not _exact_ok(op):
        raise InputError("solve_batch_exact takes a non-periodic profile operator of at most "
                         f"4096 points, got {op.name!r} on {op.shape}")
    if h.ndim != 2 or h.shape[1] != op.shape[0] or not np.all(np.isfinite(h)):
        raise InputError(f"heights must be finite, shape (B, {op.shape[0]}), got {h.shape}")
    if (delta is None) == (mean_pressure is None):
        raise InputError("give exactly one of delta (m) or mean_pressure (Pa)")
    B, n = h.shape
    load = mean_pressure is not None
    c = h - h.max(axis=1, keepdims=True)
    scale = np.ptp(h, axis=1)
    if np.any(scale == 0):
        raise InputError("a row of heights is flat: no rough-contact solution")
    if load:
        target = _rows(mean_pressure, B, "mean_pressure") * n
    else:
        dl = _rows(delta, B, "delta")
    cached = None
    if isinstance(initial, BatchState) and initial.pivots is not None:
        F, *cached = (a.copy() for a in initial.pivots)
    elif initial is not None:
        F = np.asarray(getattr(initial, "pressure", initial), dtype=float).reshape(B, n) > 0
    elif load:
        F = c >= 0
    else:
        F = solve_batch(op, h, delta=dl, tol=1e-4).pressure > 0
    if load and cached is None:
        F |= c >= 0
    sets = [np.zeros((B, 1), np.intp), np.zeros((B, 1), bool), np.zeros((B, 1, 2))]
    Hd = op.dense()
    bop = BatchOperator(op)
    p = np.zeros((B, n))
    d = np.zeros(B) if load else dl.copy()
    ninf = np.full(B, n + 1)
    backup = np.full(B, 3)
    nit = np.zeros(B, int)
    act = np.arange(B)
    for it in range(1, max_exchanges + 1):
        Fa = F[act]
        if it == 1 and cached is not None:     # the warm set was solved by the last step
            idx, valid, x = cached
        else:
            try:
                idx, valid, x = _set_solutions(Hd, c[act], Fa, basis, act)
            except np.linalg.LinAlgError:
                break                          # a singular set: the CG finishes these rows
        R, m = idx.shape
        if load:
            da = (target[act] - x[..., 0].sum(axis=1)) / x[..., 1].sum(axis=1)
        else:
            da = d[act]
        pF = np.where(valid, x[..., 0] + da[:, None] * x[..., 1], 0.0)
        pa = np.zeros((R, n))
        ri, si = np.nonzero(valid)              # padding slots name no point of F
        pa[ri, idx[ri, si]] = pF[ri, si]
        w = bop.apply(pa) - c[act] - da[:, None]
        w[Fa] = 0.0
        eps = 1e-12 * scale[act][:, None]
        tiny = 1e-12 * np.maximum(pa.max(axis=1), 0.0)[:, None]
        bad = (Fa & (pa < -tiny)) | (~Fa & (w < -eps))
        nbad = bad.sum(axis=1)
        p[act], d[act], nit[act] = np.maximum(pa, 0.0), da, it
        ok = nbad == 0
        if ok.any():                           # keep the final set's solutions
            rows = act[ok]
            mm = max(m, sets[0].shape[1])
            for k, a in enumerate((idx, valid, x)):
                if sets[k].shape[1] < mm:
                    pad = np.zeros((B, mm - sets[k].shape[1]) + a.shape[2:], a.dtype)
                    sets[k] = np.concatenate([sets[k], pad], axis=1)
                sets[k][rows] = 0
                sets[k][rows, :m] = a[ok]
        fewer = nbad < ninf[act]
        bk = backup[act]
        full = ~ok & (fewer | (bk > 0))
        ninf[act] = np.where(fewer, nbad, ninf[act])
        backup[act] = np.where(fewer, 3, np.where(full, bk - 1, bk))
        flip = np.where(full[:, None], bad, False)
        single = ~ok & ~full
        if single.any():                       # Murty: the last infeasible index only
            last = n - 1 - np.argmax(bad[single][:, ::-1], axis=1)
            flip[np.flatnonzero(single), last] = True
        F[act] = Fa ^ flip
        act = act[~ok]
        if act.size == 0:
            break
    if act.size:                               # not settled: the CG from the last sets
        kw = {"mean_pressure": target[act] / n} if load else {"delta": dl[act]}
        st = solve_batch(op, h[act], initial=np.where(F[act], np.maximum(p[act], 1e-300),
                                                      0.0), **kw)
        p[act], d[act] = st.pressure, st.delta
    u = bop.apply(p)
    w = u - c - d[:, None]
    sp = p.sum(axis=1)
    res = np.maximum(np.where(sp > 0, (p * np.abs(w)).sum(axis=1) / (np.where(sp > 0, sp, 1)
                                                                       * scale), 0.0),
                     np.maximum(0.0, -w.min(axis=1)) / scale)
    pivots = None if act.size else (F, *sets)
    return BatchState(p, u, d, p.mean(axis=1), (p > 0).sum(axis=1), nit, res, pivots)


def set_inverse(op: InfluenceOperator, state: BatchState) -> tuple:
    """The ``basis`` of :func:`solve_batch_exact` from a state it returned: per row the
    slots of its final pivoting set and the inverse of H on them (padded with the
    identity), ``(idx, valid, G)``."""
    if state.pivots is None:
        raise InputError("set_inverse needs a settled state of solve_batch_exact")
    _, idx, valid, _ = state.pivots
    m = idx.shape[1]
    A = np.where(valid[:, :, None] & valid[:, None, :],
                 op.dense()[idx[:, :, None], idx[:, None, :]], np.eye(m))
    return idx, valid, np.linalg.inv(A)


def batch_operator(shape, size, material: Material, kernel: str) -> InfluenceOperator:
    """The operator of :func:`solve_batch` for grids of ``shape`` and ``size`` (m)."""
    return influence_operator(shape, size, material.E_star, kernel)


def batch_sweep(op: InfluenceOperator, heights, pressures, *, method: str = "auto",
                tol: float = 1e-10, max_iter: int = 2000, top=None) -> BatchSweep:
    """Load-controlled sweeps of B surfaces: row ``b`` solved at the increasing mean
    pressures ``pressures[b]`` (Pa, shape (B, m)), each step warm-started from the
    previous one; A = contact points / all points, K = dp/dDelta by central differences
    over the steps. ``method``: "exact" (:func:`solve_batch_exact`, pivoting), "pk"
    (:func:`solve_batch`, the CG to ``tol``), "auto" = exact for a non-periodic profile
    of at most 4096 points, else pk. ``top``: a state of :func:`solve_batch_exact` of
    the same rows at a load at least the last one (e.g. the p_max solve of Eq. 4.2):
    its contact sets contain the sweep's, and their inverses (:func:`set_inverse`) turn
    the pivoting solves into small Schur complements (exact as well)."""
    if method not in ("auto", "exact", "pk"):
        raise InputError(f"method must be 'auto', 'exact' or 'pk', got {method!r}")
    if method == "auto":
        method = "exact" if _exact_ok(op) else "pk"
    h = np.asarray(heights, dtype=float)
    pr = np.asarray(pressures, dtype=float)
    if pr.ndim != 2 or pr.shape[0] != h.shape[0] or pr.shape[1] < 2 \
            or np.any(np.diff(pr, axis=1) <= 0):
        raise InputError(f"pressures must be (B, m >= 2), increasing along each row, got "
                         f"shape {pr.shape}")
    B, m = pr.shape
    n = int(np.prod(op.shape))
    dl, pm, a = np.empty((B, m)), np.empty((B, m)), np.empty((B, m))
    nit = np.zeros(B, int)
    st = None
    basis = set_inverse(op, top) if method == "exact" and getattr(top, "pivots", None) \
        is not None else None
    for j in range(m):
        st = solve_batch_exact(op, h, mean_pressure=pr[:, j], initial=st, basis=basis) \
            if method == "exact" \
            else solve_batch(op, h, mean_pressure=pr[:, j], initial=st, tol=tol,
                             max_iter=max_iter)
        dl[:, j], pm[:, j], a[:, j] = st.delta, st.mean_pressure, st.n_contact / n
        nit += st.nit
    k = np.array([central_differences(x, y) for x, y in zip(dl, pm)])
    return BatchSweep(dl, pm, a, k, nit)
