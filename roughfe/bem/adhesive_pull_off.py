"""The pull-off of an adhesive unloading branch, refined around its most tensile state.

The unloading branch of :func:`roughfe.bem.adhesion.adhesive_sweep` samples the load
F(Delta) at the loading step in displacement control; its pull-off force was the most
tensile *sample*. Near a smooth minimum the sample misses it by ~F'' h^2 / 8: on a
Maugis-Dugdale sphere (lambda = 2) at steps of 2.6 Maugis approach units it read 11 %
short of Maugis' value, and nothing said so (a user's review, round 2, session 30).

:func:`refine_pull_off` bisects the steps on both sides of the most tensile state, each
new state continued (warm-started, ``unloading=True``) from its neighbour at the larger
approach, as the branch itself is traced, until the steps around the minimum are no
longer than a quarter of the law's range (the length over which the adhesive traction
changes) or :data:`MAX_LEVELS` halvings are made: at most 2 solves per level. A minimum
at the start of the branch (the largest approach, often that of a sticky rough contact)
is refined on its one side. The new states join the branch in order of the approach, so
the records and figures show where the pull-off was found.
"""
from __future__ import annotations

import numpy as np

#: halvings of the steps around the most tensile state (2 solves each)
MAX_LEVELS = 4
#: a load is tensile below -max(PULL_OFF_FLOOR, tol) times the largest |load| of the
#: branch (:func:`tensile_floor`). PULL_OFF_FLOOR is the round-off of the FFT products:
#: the loads of separated states read up to ~1e-12 of the peak load (a 32^2 surface that
#: is not sticky read a pull-off of -1.3e-13 N out of them and bisected them; a user's
#: docs audit, round 2, session 31)
PULL_OFF_FLOOR = 1e-9


def tensile_floor(loads, tol: float) -> float:
    """The load (N, or N/m for a profile) below whose negative a branch's load counts as
    tensile: ``max(PULL_OFF_FLOOR, tol)`` times the largest |load| of ``loads``.

    ``tol`` is the solves' relative traction residual. A state converged to it has its
    load only to about ``tol`` of the branch's loads: the same states solved with another
    BLAS (OpenBLAS against the reference BLAS; round 2, session 42) read loads 6e-8 of
    the peak apart at tol = 1e-5, and the first separated state of a surface that is not
    sticky read -3.2e-9 N against -2.5e-11 N (2e-8 of the peak 0.146 N: the exponential
    law's tail attraction, below what the residual resolves). With the floor at
    PULL_OFF_FLOOR alone that state counted as tensile on one BLAS and not on the other:
    the branch ran on and reported a pull-off of -8.7e-9 N. A pull-off smaller than
    ``tol`` of the peak load is not resolved by the solves and is reported as 0.
    """
    return max(PULL_OFF_FLOOR, float(tol)) * max(abs(float(v)) for v in loads)


def refine_pull_off(branch: list, solve, resolution: float, max_levels: int = MAX_LEVELS):
    """Refine ``branch`` around its most tensile load.

    Parameters
    ----------
    branch : list of (float, ContactResult)
        The unloading branch as (imposed approach Delta (m), state) pairs, largest
        approach first (the first the start of the branch); a state's ``load`` is in N,
        or N/m for a profile (< 0 tensile).
    solve : callable
        ``solve(delta, initial) -> ContactResult``: the unloading state at the approach
        ``delta`` continued from the state ``initial``.
    resolution : float
        Step (m) at and below which the branch counts as resolved: a quarter of the
        law's range.
    max_levels : int
        At most this many halvings.

    Returns
    -------
    list of (float, ContactResult)
        The branch with the new states in their places (largest approach first).
    """
    branch = list(branch)
    for _ in range(max_levels):
        j = int(np.argmin([state.load for _, state in branch]))
        wide = [k for k in (j - 1, j) if 0 <= k and k + 1 < len(branch)
                and branch[k][0] - branch[k + 1][0] > resolution]
        if not wide:
            break
        for k in sorted(wide, reverse=True):        # the later insertion first
            mid = 0.5 * (branch[k][0] + branch[k + 1][0])
            branch.insert(k + 1, (mid, solve(mid, branch[k][1])))
    return branch
