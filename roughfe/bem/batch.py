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
displacement. The exact pivoting solver for profiles and the sweeps are in
:mod:`roughfe.bem.batch_exact`.

Conventions as in :mod:`roughfe.bem.solvers`: heights ``h`` (m), gap
``w = H p + max h - h - Delta`` >= 0, pressure p >= 0 (Pa), complementarity; load
control imposes the mean pressure per row and Delta is the mean of ``H p + max h - h``
over the contact set.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError, NoConvergenceError, check_real_array
from .directions import _ConjugationChain
from .operators import InfluenceOperator, influence_operator
from .solvers import kkt_residual, penetration_start, pr_beta, step_length

#: threads per batched FFT: one. The transforms are many short rows; a second thread
#: only adds a barrier per product, which on a shared machine waits for a free core
#: (measured: the whole search stalled at ~1 % of a core at load 20)
WORKERS = 1


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
    """``u = H p`` for a stack of pressures ``(B, *shape)`` and its Strang-circulant
    approximate inverse (the CG preconditioner of
    :meth:`InfluenceOperator.inverse_spectrum`): the operator's own products over the
    trailing axes of the stack (:func:`roughfe.bem.operators._convolve`, one FFT per
    product for all rows) with ``WORKERS`` threads."""

    def __init__(self, op: InfluenceOperator):
        self.op = op
        self.inverse = op.inverse_spectrum()

    def apply(self, p):
        return self.op.apply_unchecked(p, workers=WORKERS)

    def precondition(self, g):
        return self.op.precondition(g, self.inverse, workers=WORKERS)


def _rows(x, B, name):
    x = check_real_array(name, x, (0, 1), unit="Pa" if name == "mean_pressure" else "m")
    x = np.broadcast_to(x, (B,)) if x.ndim == 0 else x
    if x.shape != (B,) or np.any(x < 0):
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
    h = check_real_array("heights", heights, len(op.shape) + 1)
    if h.shape[1:] != tuple(op.shape) or h.shape[0] < 1:
        raise InputError(f"heights must have shape (B, {', '.join(map(str, op.shape))}),"
                         f" got {h.shape}")
    if (delta is None) == (mean_pressure is None):
        raise InputError("give exactly one of delta (m) or mean_pressure (Pa)")
    B = h.shape[0]
    shape = h.shape
    ax = tuple(range(1, h.ndim))
    load = mean_pressure is not None

    def col(x):                     # per-row scalar broadcast over the grid
        return np.reshape(x, (-1,) + (1,) * len(ax))

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
        p = np.clip(check_real_array("initial pressure", getattr(initial, "pressure", initial),
                                     unit="Pa").reshape(shape), 0.0, None)
    elif load:
        p = np.broadcast_to(col(pm), shape).copy()
    else:
        p = penetration_start(col(dl) + c, op.diagonal)
    if load:
        s = p.sum(axis=ax)
        p[s == 0] = col(pm[s == 0])
        p *= col(target / p.sum(axis=ax))

    u = bop.apply(p)
    t = np.zeros(shape)
    g_old = np.zeros(shape)
    gz_old = np.zeros(B)
    chain = _ConjugationChain(rows=B)   # restarts a run-away conjugation, per row
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
        res_a = kkt_residual(pa, w, scale[act], axis=ax)
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
        beta = chain.beta(pr_beta(gz - (z * g_old[act] * F).sum(axis=ax), go), gz, act)
        ta = np.where(F, col(beta) * t[act] + z, 0.0)
        gz_old[act] = gz
        g_old[act] = gF
        gt = (gF * ta).sum(axis=ax)
        r = bop.apply(ta)
        tr = (ta * r).sum(axis=ax)
        tau = step_length(gt, tr)
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
