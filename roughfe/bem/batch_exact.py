"""Batched exact contact solutions of profiles: block principal pivoting on stacked
systems (thesis Eq. 2.5-2.6), the Schur complement of a superset's inverse, and
warm-started load sweeps of B profiles (the states of :mod:`roughfe.bem.batch`).

The single dense solver (:func:`roughfe.bem.solvers.dense_solve`) spends about a
millisecond of Python per solve on a 512-point profile; here the pivoting steps of B
profiles are one stacked LAPACK call and one batched FFT product each, and the result
is the same exact contact state (tested against the single solver to round-off).
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError, check_real_array
from ..model import central_differences
from .batch import BatchOperator, BatchState, BatchSweep, _rows, solve_batch
from .operators import InfluenceOperator
from .solvers import kkt_residual


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
    h = check_real_array("heights", heights, 2)
    if not _exact_ok(op):
        raise InputError("solve_batch_exact takes a non-periodic profile operator of at most "
                         f"4096 points, got {op.name!r} on {op.shape}")
    if h.shape[1] != op.shape[0]:
        raise InputError(f"heights must have shape (B, {op.shape[0]}), got {h.shape}")
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
        F = check_real_array("initial pressure", getattr(initial, "pressure", initial),
                             unit="Pa").reshape(B, n) > 0
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
    res = kkt_residual(p, w, scale, axis=1)
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


def batch_sweep(op: InfluenceOperator, heights, pressures=None, *, deltas=None,
                method: str = "auto", tol: float = 1e-10, max_iter: int = 2000,
                top=None) -> BatchSweep:
    """Sweeps of B surfaces, each step warm-started from the previous one: row ``b``
    solved at the increasing mean pressures ``pressures[b]`` (Pa, shape (B, m); load
    control) or at the increasing approaches ``deltas[b]`` (m, shape (B, m);
    displacement control, e.g. the n_t equal approaches of a design's own sweep, Sec.
    4.2.1); exactly one of the two. A = contact points / all points, K = dp/dDelta by
    central differences over the steps. ``method``: "exact" (:func:`solve_batch_exact`,
    pivoting), "pk" (:func:`solve_batch`, the CG to ``tol``), "auto" = exact for a
    non-periodic profile of at most 4096 points, else pk. ``top``: a state of
    :func:`solve_batch_exact` of the same rows at a load at least the last one (e.g. the
    p_max solve of Eq. 4.2): its contact sets contain the sweep's, and their inverses
    (:func:`set_inverse`) turn the pivoting solves into small Schur complements (exact
    as well)."""
    if method not in ("auto", "exact", "pk"):
        raise InputError(f"method must be 'auto', 'exact' or 'pk', got {method!r}")
    if (pressures is None) == (deltas is None):
        raise InputError("batch_sweep: give exactly one of pressures (Pa) or deltas (m)")
    if method == "auto":
        method = "exact" if _exact_ok(op) else "pk"
    key, name = ("mean_pressure", "pressures") if deltas is None else ("delta", "deltas")
    h = check_real_array("heights", heights, len(op.shape) + 1)
    pr = check_real_array(name, pressures if deltas is None else deltas, 2,
                          "Pa" if deltas is None else "m")
    if pr.shape[0] != h.shape[0] or pr.shape[1] < 2 \
            or np.any(np.diff(pr, axis=1) <= 0):
        raise InputError(f"{name} must be (B, m >= 2), increasing along each row, got "
                         f"shape {pr.shape}")
    B, m = pr.shape
    n = int(np.prod(op.shape))
    dl, pm, a = np.empty((B, m)), np.empty((B, m)), np.empty((B, m))
    nit = np.zeros(B, int)
    st = None
    basis = set_inverse(op, top) if method == "exact" and getattr(top, "pivots", None) \
        is not None else None
    for j in range(m):
        st = solve_batch_exact(op, h, **{key: pr[:, j]}, initial=st, basis=basis) \
            if method == "exact" \
            else solve_batch(op, h, **{key: pr[:, j]}, initial=st, tol=tol,
                             max_iter=max_iter)
        dl[:, j], pm[:, j], a[:, j] = st.delta, st.mean_pressure, st.n_contact / n
        nit += st.nit
    k = np.array([central_differences(x, y) for x, y in zip(dl, pm)])
    return BatchSweep(dl, pm, a, k, nit)
