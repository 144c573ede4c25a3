"""A (1+1) evolution strategy in the unit box, for staircase objectives.

Generic (no physics): maximise ``fun(u)`` over ``u`` in [0, 1]^n. One parent, one
Gaussian offspring per evaluation, step ``sigma`` adapted by Rechenberg's 1/5 success
rule (x 1.5 on success, x 1.5^(-1/4) on failure), offspring clipped to the box. Equal
values are accepted, so the search walks across the plateaus of a piecewise-constant
objective (a count of contact nodes has no gradient to follow); when the step collapses
below ``restart_below`` it is reset to ``sigma`` (a restart from the current parent).

``fun`` may return a tuple: values are then compared lexicographically, so a second,
smooth measure breaks the ties of the first without ever trading it away. A value that
is not finite (NaN, +-inf; in a tuple, each such element) counts as -inf, the worst,
the start's too (a NaN start compared false with everything and froze the run).

There is no convergence test: a run always stops at its budget of ``n_eval``
evaluations (``EsResult.message`` says so, with the step resets, each a local
convergence of the step).

Reference: Rechenberg I. (1973) Evolutionsstrategie, Frommann-Holzboog; Beyer H.-G.,
Schwefel H.-P. (2002) Natural Computing 1:3-52 (the (1+1)-ES and the 1/5 rule).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from ..errors import InputError
from .values import finite_or_worst


@dataclass(frozen=True)
class EsResult:
    """Best point of a (1+1)-ES run: ``x`` (unit box), its value ``fun`` (as returned by
    the objective, non-finite values as -inf), the start value ``fun0``, ``nfev``
    evaluations, ``n_improved`` strict improvements, ``n_restarts`` step resets and
    ``message``, why the run stopped (always the budget: see the module notes)."""

    x: np.ndarray
    fun: Any
    fun0: Any
    nfev: int
    n_improved: int
    n_restarts: int
    message: str = ""


def one_plus_one_es(fun: Callable[[np.ndarray], Any], u0, n_eval: int, *, sigma: float = 0.3,
                    rng=None, restart_below: float = 2e-3, max_step: float = 0.5) -> EsResult:
    """Maximise ``fun`` on [0, 1]^n from ``u0`` with at most ``n_eval`` evaluations
    (the start included); see the module notes. ``rng``: a numpy Generator or a seed."""
    u = np.clip(np.asarray(u0, dtype=float), 0.0, 1.0)
    if int(n_eval) < 1 or not sigma > 0 or u.ndim != 1 or u.size == 0:
        raise InputError(f"n_eval >= 1, sigma > 0 and a non-empty 1D start needed, got "
                         f"{n_eval!r}, {sigma!r}, shape {u.shape}")
    rng = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
    f = f0 = finite_or_worst(fun(u))
    step, n_up, n_restart = float(sigma), 0, 0
    for _ in range(int(n_eval) - 1):
        v = np.clip(u + step * rng.standard_normal(u.size), 0.0, 1.0)
        fv = finite_or_worst(fun(v))
        if fv >= f:                         # ties accepted: move along a plateau
            n_up += fv > f
            u, f, step = v, fv, step * 1.5
        else:
            step *= 1.5 ** -0.25
        if step < restart_below:
            step, n_restart = float(sigma), n_restart + 1
        step = min(step, max_step)
    return EsResult(u, f, f0, int(n_eval), int(n_up), n_restart,
                    f"(1+1)-ES: stopped at the budget of {int(n_eval)} evaluations (no "
                    f"convergence test; {n_restart} step resets), {int(n_up)} improvements")
