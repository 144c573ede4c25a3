"""The one GCMMA driver (Svanberg 2002, globally convergent MMA) of roughfe.

:func:`gcmma` runs the outer/inner loop of GCMMA with mmapy's ``gcmmasub``,
``asymp``, ``concheck`` and ``raaupdate`` on a box-bounded problem. The variables are
mapped to the unit box; the model function ``y(x)`` is a vector (a score, or residuals)
whose derivatives come from ``jacobian(x)`` or from forward differences of step ``eps``
in unit-box units (the step flips inward at the upper bound). Two formulations of the
MMA subproblem are offered, both "maximise a similarity score s <= 1":

``form="square"`` (thesis Sec. 4.3.1)
    ``y = [s]``; minimise ``f0 = (1 - s)^2`` with one inactive constraint ``f1 = -1``
    (``a = 0, c = 1000, d = 1``). For ``s`` in (0, 1] this is maximising ``s^2`` as the
    thesis does, and unlike ``-s^2`` it stays right when a poor start has ``s < 0``.
``form="minimax"`` (Svanberg 2002, Sec. 6)
    ``y = r`` (residuals, Eq. 4.1 is ``s = 1 - max_j |r_j|``); the infinity norm is not
    differentiable, so ``min max_j |r_j|`` is written ``min z  s.t.  +-r_j(x) - z <= 0``
    (``f0 = 0``, ``a0 = a_j = 1``, ``c_j = 1000``, ``d_j = 0``). Every residual has its
    own derivative, at the cost of the same ``n + 1`` evaluations as the gradient of s.

The best point ever evaluated is returned (GCMMA is not monotone on a non-smooth
objective). A run takes its ``n_it`` outer iterations (the thesis' fixed budgets; a stop
at the first small step changed the thesis stages' results: a step of zero is not a
fixed point of MMA, whose asymptotes move on) and is called converged (``success``
True) when its last step moved no variable by more than ``xtol`` (unit-box units), else
it stopped at the budget (``success`` False, the message says which). Svanberg's test is the KKT residual
of the original problem; it needs the derivatives at the last iterate, n + 1 more
evaluations with forward differences, so the step is tested instead. A score that is
not finite counts as -inf (never the best); a model function that is not finite at the
start or at an iterate stops the run there (the subproblem cannot be built from it;
``success`` False). :func:`gcmma_maximize` and :func:`gcmma_minimax` are the two forms with the
call signatures used by :mod:`roughfe.genomics.design`.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np

from ..errors import InputError
from .values import finite_or_worst

FORMS = ("square", "minimax")
REFERENCES = ("Svanberg K. (2002) SIAM J. Optim. 12(2):555-573 (GCMMA)",)


@dataclass(frozen=True, eq=False)
class GcmmaResult:
    """Best point of a GCMMA run (scipy-like report).

    Attributes
    ----------
    x, x0 : ndarray
        Best and starting point (in the caller's units).
    fun, fun0 : float
        Score at ``x`` and at ``x0``.
    history : tuple of float
        Score at the start and after every outer iteration.
    nit : int
        Outer iterations.
    nfev : int
        Evaluations of the model function (forward differences included).
    success, message
        scipy-like report: ``success`` is True when the run converged (the last outer
        step moved no variable by more than ``xtol`` in the unit box), False when it
        stopped at the budget ``n_it`` or at a non-finite model function.
    njev : int
        Calls of the user's ``jacobian`` (0 with forward differences).
    """

    x: np.ndarray
    fun: float
    x0: np.ndarray
    fun0: float
    history: tuple
    nit: int
    nfev: int
    success: bool
    message: str
    njev: int = 0


def _inside(u):
    """Keep a GCMMA iterate in the unit box (the subproblem can return round-off or, on a
    degenerate subproblem, non-finite values outside it)."""
    return np.clip(np.nan_to_num(u, nan=0.5, posinf=1.0, neginf=0.0), 0.0, 1.0)


def _square_form(n, n_y):
    """``y = [s]`` -> (f0, f), (df0/du, df/du) of min (1 - s)^2 with an inactive constraint."""
    if n_y != 1:
        raise InputError(f"form 'square' needs a single score, the function returned {n_y} values")

    def values(y):
        return np.array([[(1.0 - y[0]) ** 2]]), -np.ones((1, 1))

    def derivatives(y, dy):
        return (-2.0 * (1.0 - y[0]) * dy[0]).reshape(n, 1), np.zeros((1, n))
    return 1, np.zeros((1, 1)), 1000.0 * np.ones((1, 1)), np.ones((1, 1)), values, derivatives


def _minimax_form(n, n_y):
    """``y = r`` -> (f0, f), (df0/du, df/du) of min z s.t. +-r_j - z <= 0 (Svanberg Sec. 6)."""
    m = 2 * n_y

    def values(y):
        return np.zeros((1, 1)), np.concatenate([y, -y]).reshape(-1, 1)

    def derivatives(y, dy):
        return np.zeros((n, 1)), np.vstack([dy, -dy])
    return m, np.ones((m, 1)), 1000.0 * np.ones((m, 1)), np.zeros((m, 1)), values, derivatives


def gcmma(fun: Callable[[np.ndarray], np.ndarray], x0, lower, upper, *, form: str,
          score: Optional[Callable[[np.ndarray], float]] = None, n_it: int = 5,
          eps: float = 0.02, jacobian: Optional[Callable] = None, y0=None,
          max_inner: int = 5, label: str = "GCMMA", xtol: float = 1e-9) -> GcmmaResult:
    """Run ``n_it`` outer GCMMA iterations on ``fun`` in the box [lower, upper].

    Parameters
    ----------
    fun : callable
        ``x -> y`` (array_like): ``[s]`` for ``form="square"``, the residuals ``r`` for
        ``form="minimax"``.
    x0, lower, upper : array_like
        Start and bounds (any units; upper > lower for every variable).
    form : {"square", "minimax"}
        The subproblem (see the module notes).
    score : callable, optional
        ``y -> s`` reported and maximised (best point kept). Default: ``y[0]`` (square),
        ``1 - max |y|`` (minimax).
    n_it : int
        Outer iterations at most (the budget).
    eps : float
        Forward-difference step in unit-box units when ``jacobian`` is None.
    jacobian : callable, optional
        ``x -> dy/dx`` with shape (len(y), len(x)).
    y0 : array_like, optional
        ``fun(x0)`` if known (saves one evaluation).
    max_inner : int
        Inner (conservativity) iterations per outer iteration.
    label : str
        Prefix of the message.
    xtol : float
        Called converged when the last outer step moved no variable by more than ``xtol``
        (unit box); the run takes its ``n_it`` iterations all the same.

    Returns
    -------
    GcmmaResult
    """
    from mmapy import asymp, concheck, gcmmasub, raaupdate
    if form not in FORMS:
        raise InputError(f"form must be one of {FORMS}, got {form!r}")
    x0 = np.asarray(x0, float)
    lo, hi = np.asarray(lower, float), np.asarray(upper, float)
    width = hi - lo
    if np.any(width <= 0):
        raise InputError("GCMMA bounds need upper > lower for every variable")
    if score is None:
        score = (lambda y: float(y[0])) if form == "square" else \
            (lambda y: 1.0 - float(np.max(np.abs(y))))
    n = x0.size
    count = {"nfev": 0, "njev": 0}

    def y_of(u):
        count["nfev"] += 1
        return np.atleast_1d(np.asarray(fun(lo + u.ravel() * width), float))

    def dy_of(u, y):
        """dy/du (len(y), n) in unit-box units."""
        if jacobian is not None:
            count["njev"] += 1
            return np.atleast_2d(np.asarray(jacobian(lo + u.ravel() * width), float)) \
                * width[None, :]
        dy = np.empty((y.size, n))
        for j in range(n):
            up = u.copy()
            step = eps if up[j, 0] + eps <= 1.0 else -eps
            up[j, 0] += step
            dy[:, j] = (y_of(up) - y) / step
        return dy

    def score_of(y):
        return finite_or_worst(float(score(y)))

    def result(best_u, best_s, s0, history, it, converged, why):
        return GcmmaResult(lo + best_u.ravel() * width, best_s, x0, s0, tuple(history), it,
                           count["nfev"], converged, f"{label}: {it} outer iterations, {why}, "
                           f"best s = {best_s:.6f} (start {s0:.6f})", count["njev"])

    u = ((x0 - lo) / width).reshape(n, 1)
    y = y_of(u) if y0 is None else np.atleast_1d(np.asarray(y0, float))
    make = _square_form if form == "square" else _minimax_form
    m, a, c, d, values, derivatives = make(n, y.size)
    a0 = 1.0
    s0 = score_of(y)
    best_u, best_s, history = u.copy(), s0, [s0]
    if not np.all(np.isfinite(y)):
        return result(u, s0, s0, history, 0, False, "stopped: the model function is not "
                      "finite at the start")
    xmin, xmax = np.zeros((n, 1)), np.ones((n, 1))
    low, upp = xmin.copy(), xmax.copy()
    xold1, xold2 = u.copy(), u.copy()
    raa0, raa, raa0eps, raaeps, epsimin = 0.01, 0.01 * np.ones((m, 1)), 1e-6, \
        1e-6 * np.ones((m, 1)), 1e-7
    f0val, fval = values(y)
    df0dx, dfdx = derivatives(y, dy_of(u, y))
    it, why, converged = 0, f"stopped at the budget n_it = {int(n_it)}", False
    for it in range(1, int(n_it) + 1):
        low, upp, raa0, raa = asymp(it, n, u, xold1, xold2, xmin, xmax, low, upp, raa0, raa,
                                    raa0eps, raaeps, df0dx, dfdx)
        xmma, *_, f0app, fapp = gcmmasub(m, n, it, epsimin, u, xmin, xmax, low, upp, raa0, raa,
                                         f0val, df0dx, fval, dfdx, a0, a, c, d)
        xmma = _inside(xmma)
        y_new = y_of(xmma)
        f0new, fnew = values(y_new)
        conserv = concheck(m, epsimin, f0app, f0new, fapp, fnew)
        inner = 0
        while conserv == 0 and inner < max_inner:
            inner += 1
            raa0, raa = raaupdate(xmma, u, xmin, xmax, low, upp, f0new, fnew, f0app, fapp,
                                  raa0, raa, raa0eps, raaeps, epsimin)
            xmma, *_, f0app, fapp = gcmmasub(m, n, it, epsimin, u, xmin, xmax, low, upp, raa0,
                                             raa, f0val, df0dx, fval, dfdx, a0, a, c, d)
            xmma = _inside(xmma)
            y_new = y_of(xmma)
            f0new, fnew = values(y_new)
            conserv = concheck(m, epsimin, f0app, f0new, fapp, fnew)
        step = float(np.max(np.abs(np.clip(xmma, 0.0, 1.0) - u)))
        xold2, xold1, u, y = xold1, u, np.clip(xmma, 0.0, 1.0), y_new
        s = score_of(y)
        history.append(s)
        if s > best_s:
            best_u, best_s = u.copy(), s
        if not np.all(np.isfinite(y)):
            why = "stopped: the model function is not finite at the last iterate"
            break
        converged = step <= xtol
        why = (f"converged (last step {step:.1e} <= xtol = {xtol:g})" if converged else
               f"stopped at the budget n_it = {int(n_it)} (last step {step:.1e} > xtol)")
        if it < n_it:
            f0val, fval = f0new, fnew
            df0dx, dfdx = derivatives(y, dy_of(u, y))
    return result(best_u, best_s, s0, history, it, converged, why)


def gcmma_maximize(fun: Callable[[np.ndarray], float], x0, lower, upper, *, n_it: int = 5,
                   eps: float = 0.02, grad: Optional[Callable] = None, f0=None,
                   max_inner: int = 5) -> GcmmaResult:
    """Maximise a score ``s = fun(x) <= 1`` in a box: :func:`gcmma` with ``form="square"``
    (minimise ``(1 - s)^2``, thesis Sec. 4.3.1); ``grad(x) -> ds/dx`` replaces the
    forward differences, ``f0 = fun(x0)`` saves one evaluation."""
    jac = None if grad is None else (lambda x: np.asarray(grad(x), float)[None, :])
    return gcmma(lambda x: [fun(x)], x0, lower, upper, form="square", n_it=n_it, eps=eps,
                 jacobian=jac, y0=None if f0 is None else [f0], max_inner=max_inner)


def gcmma_minimax(residuals: Callable[[np.ndarray], np.ndarray], score: Callable, x0, lower,
                  upper, *, n_it: int = 5, eps: float = 0.02, max_inner: int = 5,
                  jacobian: Optional[Callable] = None) -> GcmmaResult:
    """Minimise ``max_j |r_j(x)|`` in a box: :func:`gcmma` with ``form="minimax"``
    (Svanberg 2002, Sec. 6). ``score(r) -> s`` reports the score of a residual vector;
    ``jacobian(x) -> (r, dr/dx)`` replaces the forward differences."""
    jac = None if jacobian is None else (lambda x: jacobian(x)[1])
    return gcmma(residuals, x0, lower, upper, form="minimax", score=score, n_it=n_it, eps=eps,
                 jacobian=jac, max_inner=max_inner, label="GCMMA min-max")
