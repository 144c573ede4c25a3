"""CMA-ES with increasing population restarts (IPOP), for batched objectives.

Generic (no physics): maximise ``fun`` over R^n, where ``fun`` takes a whole
population ``X`` of shape (lambda, n) and returns its lambda values, so that an
objective which costs little more for a batch than for one point (the batched contact
solver of :mod:`roughfe.bem.batch`) is called once per generation.

The (mu/mu_w, lambda)-CMA-ES with cumulative step-size adaptation, rank-one and rank-mu
covariance updates and the default strategy parameters of Hansen's tutorial (Hansen
N. (2016) The CMA Evolution Strategy: A Tutorial, arXiv:1604.00772, Table 1 and
Fig. 6; written from the equations there, the samples drawn through the symmetric
root C^(1/2) rather than B D, so that a seed's path does not depend on the BLAS). A run
stops when its step ``sigma`` times the largest axis of C falls below ``tol_x``, when
the best value has not risen for ``10 + 30 n / lambda`` generations, or at the budget;
then it restarts from ``x0`` with twice the population (Auger A., Hansen N. (2005) A
restart CMA evolution strategy with increasing population size, CEC 2005, 1769-1776),
until ``n_eval`` evaluations are spent. The best point over all runs is returned with
the curve of the best value against the evaluations spent, and why each run stopped
(``stops``: "converged" on ``tol_x``, "stalled", or "budget" when the evaluations left
could not pay for another generation). A value that is not finite (x0's too) counts as
-inf, the worst.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..errors import InputError
from .values import finite_or_worst


@dataclass(frozen=True)
class CmaResult:
    """Best point ``x`` and value ``fun`` over all runs; ``fun0`` the value of ``x0``
    (-inf if not finite); ``nfev`` evaluations, ``n_runs`` runs (restarts + 1),
    ``popsizes`` the population of each run, ``history``: rows (evaluations spent, best
    value so far) after every generation; ``stops``: why each run stopped ("converged":
    sigma times the largest axis of C below ``tol_x``; "stalled": no rise of the run's
    best for ``10 + 30 n / lambda`` generations; "budget": the evaluations left could not
    pay for its next generation), and ``message`` saying so."""

    x: np.ndarray
    fun: float
    fun0: float
    nfev: int
    n_runs: int
    popsizes: tuple
    history: np.ndarray
    stops: tuple = ()
    message: str = ""


def _symmetric(Bm, d) -> np.ndarray:
    """``B diag(d) B^T`` of the eigenvectors ``Bm`` (columns) of C: with ``d = D`` the
    symmetric root C^(1/2), with ``d = 1/D`` C^(-1/2). Both are functions of C alone, so
    samples ``z C^(1/2)`` (z ~ N(0, I), the distribution N(0, C) of the tutorial's
    ``B D z``) do not depend on the signs, order or basis within a repeated eigenvalue
    that LAPACK picks for the eigenvectors: after the first update C = (1 - c1 - cmu) I
    + a rank <= mu + 1 term, whose repeated eigenvalue left the search's path to the
    BLAS (reference BLAS and OpenBLAS drew other points from the second generation on)."""
    return (Bm * d) @ Bm.T


def _run(fun, x0, sigma0, lam, budget, rng, tol_x, best, history, spent):
    """One CMA-ES run of population ``lam`` from ``x0``; updates ``best`` = [x, f] and
    ``history`` in place and returns the evaluations it spent and why it stopped."""
    n = x0.size
    mu = lam // 2
    w = math.log(mu + 0.5) - np.log(np.arange(1, mu + 1))
    w /= w.sum()
    mueff = 1.0 / float(np.sum(w ** 2))
    cs = (mueff + 2) / (n + mueff + 5)
    ds = 1 + 2 * max(0.0, math.sqrt((mueff - 1) / (n + 1)) - 1) + cs
    cc = (4 + mueff / n) / (n + 4 + 2 * mueff / n)
    c1 = 2 / ((n + 1.3) ** 2 + mueff)
    cmu = min(1 - c1, 2 * (mueff - 2 + 1 / mueff) / ((n + 2) ** 2 + mueff))
    chi = math.sqrt(n) * (1 - 1 / (4 * n) + 1 / (21 * n * n))
    m, sigma = x0.copy(), float(sigma0)
    C, ps, pc = np.eye(n), np.zeros(n), np.zeros(n)
    stall_limit = 10 + int(math.ceil(30 * n / lam))
    run_best, stall, used, g = -np.inf, 0, 0, 0
    while used + lam <= budget:
        D2, Bm = np.linalg.eigh(C)
        D = np.sqrt(np.maximum(D2, 1e-300))
        y = rng.standard_normal((lam, n)) @ _symmetric(Bm, D)
        X = m + sigma * y
        f = np.asarray(fun(X), dtype=float)
        if f.shape != (lam,):
            raise InputError(f"the objective must return {lam} values, got shape {f.shape}")
        f = finite_or_worst(f)
        used += lam
        g += 1
        order = np.argsort(-f, kind="stable")
        if f[order[0]] > best[1]:
            best[0], best[1] = X[order[0]].copy(), float(f[order[0]])
        history.append((spent + used, best[1]))
        if f[order[0]] > run_best:
            run_best, stall = float(f[order[0]]), 0
        else:
            stall += 1
        yw = w @ y[order[:mu]]
        m = m + sigma * yw
        ps = (1 - cs) * ps + math.sqrt(cs * (2 - cs) * mueff) * (_symmetric(Bm, 1 / D) @ yw)
        hs = np.linalg.norm(ps) / math.sqrt(1 - (1 - cs) ** (2 * g)) < (1.4 + 2 / (n + 1)) * chi
        pc = (1 - cc) * pc + hs * math.sqrt(cc * (2 - cc) * mueff) * yw
        ys = y[order[:mu]]
        C = ((1 - c1 - cmu) * C + c1 * (np.outer(pc, pc) + (1 - hs) * cc * (2 - cc) * C)
             + cmu * (ys.T * w) @ ys)
        C = 0.5 * (C + C.T)
        sigma *= math.exp(cs / ds * (np.linalg.norm(ps) / chi - 1))
        if sigma * float(D.max()) < tol_x:
            return used, "converged"
        if stall >= stall_limit:
            return used, "stalled"
    return used, "budget"


def ipop_cmaes(fun: Callable[[np.ndarray], np.ndarray], x0, sigma0: float, n_eval: int, *,
               popsize: int = 0, rng=None, tol_x: float = 1e-4,
               max_popsize: int = 4096) -> CmaResult:
    """Maximise ``fun`` (batched, see the module notes) from ``x0`` with step ``sigma0``
    and at most ``n_eval`` evaluations (``x0`` itself included). ``popsize``: the first
    run's lambda (default ``4 + 3 ln n``), doubled at each restart up to ``max_popsize``.
    ``rng``: a numpy Generator or a seed."""
    x0 = np.asarray(x0, dtype=float)
    if x0.ndim != 1 or x0.size < 1 or not np.all(np.isfinite(x0)) or not sigma0 > 0 \
            or int(n_eval) < 2:
        raise InputError(f"a finite non-empty 1D x0, sigma0 > 0 and n_eval >= 2 needed, got "
                         f"shape {x0.shape}, {sigma0!r}, {n_eval!r}")
    rng = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
    lam = int(popsize) or 4 + int(3 * math.log(x0.size))
    lam = max(lam, 4)
    f0 = float(finite_or_worst(np.asarray(fun(x0[None, :]), dtype=float)[:1])[0])
    best, history, spent, sizes, stops = [x0.copy(), f0], [(1, f0)], 1, [], []
    while spent + lam <= n_eval:
        sizes.append(lam)
        used, why = _run(fun, x0, sigma0, lam, n_eval - spent, rng, tol_x, best, history,
                         spent)
        spent += used
        stops.append(why)
        lam = min(2 * lam, int(max_popsize))
    runs = ", ".join(f"{k} {w}" for k, w in zip(sizes, stops)) or "none"
    message = (f"IPOP-CMA-ES: {spent} of {int(n_eval)} evaluations, stopped at the budget "
               f"(too few left for a run of population {lam}); runs by population: {runs}")
    return CmaResult(best[0], best[1], f0, spent, len(sizes), tuple(sizes), np.array(history),
                     tuple(stops), message)
