"""Safeguards of the search direction of the two-level Polonsky-Keer CG
(:func:`roughfe.bem.pk.polonsky_keer` with a ``deflation``): the binding set at p = 0
(round 2, session 10) and the descent guard of the coarse correction (session 12) act
on the direction's values on the free set F only (numpy vectors), never on the iterate;
the stall watch (session 13) drops the correction from a solve that stopped making
progress with it; the conjugation chain (session 43) restarts a direction that has
grown beyond what the gradients justify (any PK solve)."""
from __future__ import annotations

import collections
import itertools

import numpy as np

#: the two-level direction is used only while it keeps at least this share of the descent
#: of the plain one, g . z_2level > DESCENT_GUARD g . (M g); otherwise that iteration takes
#: M g (:func:`_descent_guard`)
DESCENT_GUARD = 0.05
#: a two-level solve whose KKT residual has not halved for this many iterations drops its
#: coarse correction for the rest of the solve (:class:`_StallWatch`)
STALL_WINDOW = 25
#: the Polak-Ribiere coefficients' product since the last restart may exceed the decrease
#: of g . z it implies by at most this factor (:class:`_ConjugationChain`)
CONJUGATION_LIMIT = 100.0


def _descent_guard(gF, zF, z2):
    """The two-level direction ``z2`` if it is still a descent direction worth the name,
    else the plain preconditioned one ``zF`` (both on F, ``gF`` the gradient there), and
    the gradient's dot product with the direction returned (the CG's g . z, computed here
    once).

    The A-DEF2 correction of :mod:`roughfe.bem.deflation` is exact only with the exact
    coarse matrix Z^T H_FF Z solved exactly. The production form approximates the far
    field (N_I N_J K) and solves the coarse system to ``coarse_tol``, so the corrected
    preconditioner is not guaranteed positive definite: g . z2 can fall far below
    g . z = g . M g > 0, or below zero. Then the step length g . t / t . H t goes to 0
    and the Polak-Ribiere beta restarts at every iteration: the solve stalls. Measured
    (round 2, session 12): the ratio g . z2 / g . z is 0.18-0.5 in the first corrected
    iterations of a solve and 0.85-0.98 after that on the ``bench_bem`` surfaces; on
    a band-limited surface resampled to 4096^2 (p/E* = 0.1) it fell to 0.01-0.05 for ten
    iterations (34 iterations instead of 23-27), and resampled to 8192^2 (p/E* = 0.05) it
    turned negative at the 22nd iteration and the residual froze at 9.7e-6 (tau -> 0:
    the solve would have run to ``max_iter``). With the guard at :data:`DESCENT_GUARD` =
    0.05 those take 24 and 27 iterations, and the self-affine surfaces of
    ``benchmarks/bench_bem_growth.py`` keep their iteration counts. A higher threshold
    switches the correction off where it is merely weak, which breaks the conjugacy of
    the flexible CG: 0.1 cost one iteration on two H = 0.5 surfaces at 4096^2, 0.3 a
    factor of 1.5-3 on most surfaces at 1024^2 and 2048^2. Details:
    ``docs/theory/02b_bem_performance.md``, "A stall of the two-level direction".
    """
    gz = float(np.dot(gF, zF))
    if z2 is zF:              # the correction was skipped (the contact-set search)
        return zF, gz
    gz2 = float(np.dot(gF, z2))
    return (z2, gz2) if gz2 > DESCENT_GUARD * gz else (zF, gz)


def _bind_lower(tF, positive, load):
    """Drop the components of the search direction ``tF`` (in place; the step is
    p <- p - tau t) that would push a point of F at p = 0 below zero (``positive``:
    p > 0 on F, bool). This is the binding set of a projected-gradient method (Bertsekas
    1982; More & Toraldo 1991, GPCG) applied to the preconditioned direction: PK's free
    set admits a point at p = 0 whose gap is negative (it interpenetrates), but the
    preconditioned, conjugated direction there may still lower p. Without this rule the
    step gives such a point a negative pressure, the projection clips it back, the step
    is spent and u must be recomputed; the point then leaves F (measured at 2048^2,
    p/E* = 0.05: a third to a half of the points leaving F in each search iteration had
    entered it in the iteration before). In load control the kept components are
    shifted back to zero mean, so that the step keeps the load.

    Not in Polonsky & Keer (1999), whose rule admits the point with the raw direction.
    Used with the two-level correction only (``deflation``), where it was measured to
    pay (4 cold loads p/E* = 0.005-0.1, tol 1e-10, the ``bench_bem`` surface: 1024^2
    94 -> 89 iterations, 2048^2 115 -> 103, one load p/E* = 0.05 at 4096^2 42 -> 33);
    in the plain CG it does not (256^2 117 -> 119, 512^2 147 -> 150). Details:
    ``docs/theory/02b_bem_performance.md``, "The binding set" (session 10).
    """
    bound = tF > 0.0
    bound &= ~positive
    nb = int(np.count_nonzero(bound))
    if not nb:
        return
    tF[bound] = 0.0
    if load and nb < tF.size:
        tF -= float(tF.sum()) / (tF.size - nb)
        tF[bound] = 0.0


class _StallWatch:
    """The last line of defence of the two-level solve: ``stalled(res)`` is True once
    the relative KKT residual ``res`` is no lower than half of what it was ``window``
    iterations ago, at any iteration since then (a sliding window: a start that was
    luckily good, a warm start whose residual rises before it falls, only shift it).

    The descent guard keeps the corrected direction a descent direction, but a
    correction can still be a useless one (a coarse operator far from the Galerkin
    matrix): the steps then shrink and the solve crawls towards ``max_iter`` (20000 in
    :func:`roughfe.bem.solve_contact`, hours at 8192^2). A healthy solve halves its
    residual every 1-3 iterations (1 to 1e-10 in 20-40 iterations at 1024^2-8192^2,
    the slowest phase 0.1-0.2 decades an iteration: 02b, session 12), so 25 without
    halving is a stall, not a slow phase; the plain preconditioned CG (M = E*|q|/2,
    positive definite) then takes over and always converges."""

    def __init__(self, window=None):
        self.window = STALL_WINDOW if window is None else int(window)
        self.history = collections.deque(maxlen=self.window + 1)

    def stalled(self, res):
        h = self.history
        h.append(res)
        return len(h) == h.maxlen and min(itertools.islice(h, 1, None)) > 0.5 * h[0]


class _ConjugationChain:
    """Restart of the CG direction when its conjugation has run away.

    In linear CG the coefficients telescope: beta_1 ... beta_k = (g.z)_k / (g.z)_0 since
    the last restart (Fletcher-Reeves' identity; Polak-Ribiere's beta equals it for a
    quadratic on a fixed set). On a changing contact set they need not, and a set that
    alternates between two states can make the product grow geometrically (beta ~0.2 and
    ~6.9 in turn, measured) while g.z does not fall: the direction t = z + beta t_old
    then grows without bound and the exact line search takes ever smaller steps along
    it. Measured on warm-started 1D sweeps (mirrored RMD profiles, 1024-8192 points,
    round 2, session 43): one load took 1185 iterations instead of 169, five took more
    than 200, and the float32 product of the grown direction overflowed (NaN in the
    FFT, numpy's "invalid value" warning). ``limit`` allows the product to exceed
    (g.z)_k / (g.z)_0 by :data:`CONJUGATION_LIMIT` before that iteration takes beta = 0
    (steepest preconditioned descent, a restart): it never fired on the 2D surfaces of
    ``benchmarks/bench_bem_growth.py`` (H = 0.8 and 0.5, 256^2 to 1024^2, 4 loads: every
    count unchanged) and brought the 1D sweeps to 169 iterations at the worst load
    (all iterations -2.7 %, no warning). Scalars only: no pass over the grid."""

    def __init__(self, limit: float = CONJUGATION_LIMIT, rows=None):
        # per CG (``rows`` None) or per row of a batched CG (:mod:`roughfe.bem.batch`)
        self.limit = limit
        self.product = 1.0 if rows is None else np.ones(rows)
        self.gz_start = np.nan if rows is None else np.full(rows, np.nan)
        self.restarts = 0

    def beta(self, beta, gz, rows=None):
        """``beta`` for the iteration whose new g.z is ``gz``, or 0 (a restart); arrays
        of the batch rows ``rows`` (indices) for a batched chain."""
        single = rows is None
        prod = self.product if single else self.product[rows]
        start = self.gz_start if single else self.gz_start[rows]
        reset = (beta == 0) | ~np.isfinite(start)
        prod = np.where(reset, 1.0, prod * beta)
        start = np.where(reset, gz, start)
        fire = ~reset & (prod * start > self.limit * gz)
        self.restarts += int(np.count_nonzero(fire))
        prod, start = np.where(fire, 1.0, prod), np.where(fire, gz, start)
        beta = np.where(fire, 0.0, beta)
        if single:
            self.product, self.gz_start = float(prod), float(start)
            return float(beta)
        self.product[rows], self.gz_start[rows] = prod, start
        return beta
