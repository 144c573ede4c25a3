"""Anderson-accelerated fixed-point iteration ``x = G(x)`` (no physics here).

Type II Anderson acceleration with memory ``m`` and mixing ``beta`` (Walker & Ni 2011):
with the residuals ``r_k = G(x_k) - x_k`` and the differences ``dR``, ``dX`` of the last
``m + 1`` iterates and residuals, ``gamma = argmin ||r_k - dR gamma||`` and

    x_{k+1} = x_k + beta r_k - (dX + beta dR) gamma.

``m = 0`` is the relaxed Picard iteration ``x + beta r``. The residual is
``||G(x) - x|| / ||G(x)||`` (2-norms). ``G`` may refuse an iterate by raising
:class:`RejectedIterate` (e.g. an extrapolated fluid pressure that would lift the body
off, or close a channel): the memory is cleared and ``G`` is tried on the damped steps
``x_k + beta r_k / 2^j``, ``j = 0 .. backoff`` (the first one it accepts is taken); if
``G`` refuses all of them, the iteration stops with ``status = "rejected"`` at the last
accepted iterate. A refusal is then a property of ``G`` near ``x_k``, not of the one
full step ``G(x_k)``: until round 2, session 24 only the plain iterate ``G(x_k)`` was
tried, which on the first iteration is the refused point itself (``x_1 = x_0 + r_0``),
so one refused Picard step stopped the loop (a channel reported closed with q = 0 where
the damped iteration finds it open, docs/theory/04c_profile_fsi.md). The caller decides
whether the refused state is one (a closed channel, lift-off) or raises.

Used by the fluid-structure couplings of :mod:`roughfe.leakage.fsi` (surfaces) and
:mod:`roughfe.leakage.profile_fsi` (profiles, BEM and FEM bodies): one loop for all.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np

from ..errors import InputError, check_finite_positive, check_int

REFERENCES = ("Walker H.F., Ni P. (2011) SIAM J. Numer. Anal. 49:1715-1735 (Anderson)",)


class RejectedIterate(Exception):
    """Raised by ``G`` when it cannot be evaluated at an iterate."""


@dataclass(frozen=True, eq=False)
class FixedPoint:
    """Outcome of :func:`anderson_fixed_point`.

    Attributes
    ----------
    x, gx : ndarray
        Last iterate and ``G(x)``.
    status : {"converged", "max_iter", "rejected"}
        Residual <= tol; iteration limit reached; ``G`` refused every damped step from
        the last accepted iterate ``x`` (module docstring).
    iterations : int
        Evaluations of ``G`` after the first (refused ones included).
    residual : float
        Last relative residual.
    residuals : tuple of float
        Residual history (one per evaluated iterate).
    """

    x: np.ndarray
    gx: np.ndarray
    status: str
    iterations: int
    residual: float
    residuals: tuple

    @property
    def converged(self) -> bool:
        return self.status == "converged"


def check_options(tol, max_iter, memory, relaxation) -> tuple:
    """The options of :func:`anderson_fixed_point`, checked before any work is done:
    ``(tol, max_iter, memory, relaxation)`` as (float, int, int, float); InputError naming
    the bad one."""
    tol = check_finite_positive("tol", tol)
    if not (0 < relaxation <= 1):
        raise InputError(f"relaxation must be in (0, 1], got {relaxation!r}")
    max_iter = check_int("max_iter (fixed-point iterations)", max_iter, 1)
    memory = check_int("anderson (the Anderson memory)", memory, 0)
    return tol, max_iter, memory, float(relaxation)


def anderson_fixed_point(G: Callable[[np.ndarray], np.ndarray], x0, gx0=None, *,
                         tol: float = 1e-8, max_iter: int = 60, memory: int = 5,
                         relaxation: float = 1.0, floor: float = 0.0,
                         backoff: int = 4) -> FixedPoint:
    """Solve ``x = G(x)`` from ``x0`` (module docstring).

    Parameters
    ----------
    G : callable
        ndarray -> ndarray of the same shape; may raise :class:`RejectedIterate`.
    x0 : ndarray
        Starting iterate.
    gx0 : ndarray, optional
        ``G(x0)`` when the caller has it already (not evaluated again).
    tol : float
        Relative residual to reach.
    max_iter : int
        Evaluations of ``G`` allowed after the first.
    memory : int
        Anderson memory ``m`` (0: relaxed Picard).
    relaxation : float
        Mixing ``beta`` in (0, 1].
    floor : float
        The residual is ``||G(x) - x|| / max(||G(x)||, floor)``: a norm below which the
        iterate counts as small (the caller's scale of x; 0: purely relative, which asks
        digits of a field that is noise next to the scale the problem resolves).
    backoff : int
        Halvings of the damped step ``beta r`` tried after a refused iterate (>= 0).

    Returns
    -------
    FixedPoint
        Never raises on non-convergence: the caller reads ``status`` and raises its own
        :class:`~roughfe.errors.NoConvergenceError` with its partial result.
    """
    backoff = check_int("backoff (step halvings after a refused iterate)", backoff, 0)
    x = np.asarray(x0, dtype=float)
    gx = G(x) if gx0 is None else np.asarray(gx0, dtype=float)
    hist_x: list = []
    hist_r: list = []
    residuals: list = []
    it = 0
    status: Optional[str] = None
    while status is None:
        r = gx - x
        res = float(_norm(r) / max(_norm(gx), floor, 1e-300))
        residuals.append(res)
        if res <= tol:
            status = "converged"
            break
        if it >= max_iter:
            status = "max_iter"
            break
        hist_x.append(x.ravel())
        hist_r.append(r.ravel())
        del hist_x[:-(memory + 1)], hist_r[:-(memory + 1)]
        x_new = x + relaxation * r
        if len(hist_r) > 1:
            dR = np.diff(np.array(hist_r), axis=0).T
            dX = np.diff(np.array(hist_x), axis=0).T
            gamma, *_ = np.linalg.lstsq(dR, r.ravel(), rcond=None)
            x_new = x_new - ((dX + relaxation * dR) @ gamma).reshape(x.shape)
        it += 1
        try:
            x, gx = x_new, G(x_new)
        except RejectedIterate:
            hist_x.clear()
            hist_r.clear()
            evaluations, step = _damped_step(G, x, r, x_new, relaxation, backoff)
            it += evaluations
            if step is None:
                status = "rejected"
            else:
                x, gx = step
    return FixedPoint(x=x, gx=gx, status=status, iterations=it, residual=residuals[-1],
                      residuals=tuple(residuals))


def _norm(v) -> float:
    """The 2-norm of ``v`` computed on ``v / max|v|`` (as BLAS nrm2 scales): its squares
    neither overflow nor underflow (a field of 1e200 Pa gave an inf norm and a NaN
    residual, one of 1e-190 Pa a zero norm and a fixed point at the first iterate)."""
    top = float(np.max(np.abs(v))) if np.size(v) else 0.0
    return top * float(np.linalg.norm(v / top)) if 0.0 < top < np.inf else top


def _damped_step(G, x, r, refused, relaxation, backoff) -> tuple:
    """The first of ``x + relaxation r / 2^j`` (``j = 0 .. backoff``; ``refused`` itself
    skipped) that ``G`` accepts: ``(evaluations, (x_j, G(x_j)))``, or
    ``(evaluations, None)`` when it refuses all of them."""
    evaluations = 0
    for j in range(backoff + 1):
        trial = x + (relaxation / 2.0 ** j) * r
        if np.array_equal(trial, refused):
            continue
        evaluations += 1
        try:
            return evaluations, (trial, G(trial))
        except RejectedIterate:
            pass
    return evaluations, None
