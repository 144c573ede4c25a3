"""An imposed approach on a periodic elastic surface, solved through load control.

A periodic half-space has zero mean displacement, so an imposed approach Delta fixes the
mean gap, and the mean pressure P is the direction of zero curvature of the primal
problem: :func:`roughfe.bem.periodic.periodic_gap_control` solves it in the gap variable
instead. That dual iteration has none of the load-controlled solver's accelerations (the
coarse-to-fine start, the two-level correction): a 20-step approach sweep of a 1024^2
surface took 1035 of its iterations and 3.6x the CPU of the same steps in load control
(02b, session 17).

Here the load-controlled Polonsky-Keer iteration finds P itself: the solution at an
imposed Delta is the load-controlled solution at the P with Delta(P) = Delta, and Delta(P)
increases with P. :class:`LoadSecant` moves P inside one PK solve by secant steps on
Delta(P), its current estimate being the mean gap on the contact set, each step taken
once that estimate is finer than the step it corrects (the KKT residual, which bounds its
error, below |Delta - Delta(P)| of the height scale).
"""
from __future__ import annotations

import numpy as np

from ..errors import NoConvergenceError
from ..surfaces.surface import Surface
from .coarse_start import COARSE_START_MIN, _coarse_pressure, _coarse_surface, _inject
from .solvers import SolverOutput, kkt_residual

#: the secant's first slope dP/dDelta = P / (SLOPE_LENGTH sigma): the exponential law
#: p ~ exp(-u / (0.5 sigma)) of rough contacts at light load; the secant of the first two
#: estimates replaces it (a 1024^2 sweep took 729 iterations from it and 721 from the
#: slope of a quadratic through the sweep's last three steps)
SLOPE_LENGTH = 0.5
#: the load path is taken when its start's contact fraction is at most this; beyond it
#: the gap-variable CG, whose unknowns are the few open points, is faster (cold solves,
#: CPU gap / load: 1024^2 H = 0.5 1.12 at a start A* of 0.55 and 0.75 at 0.69; 512^2
#: 1.08 at 0.46 and 0.61 at 0.61; 02b, session 17)
MAX_START_AREA = 0.5


class LoadSecant:
    """The ``approach`` hook of :func:`roughfe.bem.pk.polonsky_keer`: moves the mean
    pressure (Pa) towards the one whose approach is ``delta`` (m).

    Called with the relative KKT residual and the current Delta (m) of the iteration;
    returns a new mean pressure, or None to leave it. It moves when the offset
    eps = delta - Delta exceeds ``delta_tol`` (m) and the residual is at most
    max(|eps| / ``scale``, ``floor``): the estimate of Delta is then finer than eps.
    The step is eps times the secant of the last two (Delta, P) pairs of its moves,
    ``slope`` (Pa/m) before there are two; a step to P <= 0 halves P instead. ``moves``
    counts the moves."""

    def __init__(self, delta, mean_pressure, slope, delta_tol, scale, floor):
        self.delta, self.pressure, self.slope = float(delta), float(mean_pressure), float(slope)
        self.delta_tol, self.scale, self.floor = float(delta_tol), float(scale), float(floor)
        self.moves, self._last = 0, None

    def __call__(self, res, current):
        eps = self.delta - current
        if abs(eps) <= self.delta_tol or res > max(abs(eps) / self.scale, self.floor):
            return None
        if self._last is not None:
            d0, p0 = self._last
            if current != d0:
                k = (self.pressure - p0) / (current - d0)
                if k > 0:
                    self.slope = k
        self._last = (current, self.pressure)
        new = self.pressure + self.slope * eps
        self.pressure = new if new > 0 else 0.5 * self.pressure
        self.moves += 1
        return self.pressure


def approach_start(surface: Surface, material, delta, initial, coarse_correction=None):
    """Initial pressure (Pa, grid) and mean pressure (Pa) of a solve by load at the
    imposed approach ``delta`` (m) on a periodic surface, or None (no estimate: the
    caller solves in the gap variable).

    ``initial`` (a sweep's predicted pressure) gives both. Otherwise the same approach
    on the grid coarsened by 2 (:func:`~roughfe.bem.coarse_start._coarse_surface`, the
    rigid flat at the same height above the mean plane, Delta_c = Delta - max h + max
    h_c; recursively, to ``COARSE_START_TOL``), its pressure injected on 2 x 2 blocks:
    a surface below ``COARSE_START_MIN`` points per axis, or one whose coarse version
    does not touch the flat, has none; nor has a start in contact on more than
    ``MAX_START_AREA`` of the grid."""
    if initial is not None:
        return _fit(np.maximum(np.asarray(initial, dtype=float), 0.0))
    shape = surface.shape
    if surface.ndim != 2 or min(shape) < COARSE_START_MIN or any(n % 2 for n in shape):
        return None
    coarse = _coarse_surface(surface)
    h, hc = surface.heights, coarse.heights
    dc = delta - float(h.max()) + float(hc.max())
    if dc <= 0:
        return None
    return _fit(_inject(_coarse_pressure(coarse, material, coarse_correction, delta=dc),
                        shape))


def _fit(p):
    """(p, its mean) when p has contact on at most ``MAX_START_AREA`` of the grid."""
    area = np.count_nonzero(p) / p.size
    return (p, float(p.mean())) if 0 < area <= MAX_START_AREA else None


def approach_by_load(solve, h, hmax, scale, delta, mean_pressure, sigma, tol):
    """Displacement control of a periodic elastic surface through load control.

    ``solve(mean_pressure, tol, approach)`` runs the load-controlled PK (returns its
    :class:`~roughfe.bem.solvers.SolverOutput`) with a :class:`LoadSecant` hook that
    starts at ``mean_pressure`` (Pa) with the slope of ``SLOPE_LENGTH`` times the rms
    height ``sigma`` (m). Each half of ``tol`` goes to one part of the answer: the
    load-controlled residual (tol / 2) and the approach, |Delta - delta| <= tol / 2 of
    ``scale`` (m). The output is at the imposed ``delta`` (m), its residual the
    displacement-control one of Eq. 2.5-2.6 (gap u - h + max h - delta), then below
    ``tol``; NoConvergenceError (with that output) otherwise."""
    slope = mean_pressure / (SLOPE_LENGTH * sigma)
    hook = LoadSecant(delta, mean_pressure, slope, 0.5 * tol * scale, scale, 0.5 * tol)
    out = solve(mean_pressure, 0.5 * tol, hook)
    p, u = out.pressure, out.displacement
    res = float(kkt_residual(p, u - h + (hmax - delta), scale))
    result = SolverOutput(p, u, delta, out.nit, res, "pk", out.n_products)
    if not res <= tol:
        raise NoConvergenceError(
            f"imposed approach through load control: KKT residual {res:.3e} after "
            f"{out.nit} iterations ({hook.moves} moves of the load), tolerance {tol:.1e}",
            result=result)
    return result
