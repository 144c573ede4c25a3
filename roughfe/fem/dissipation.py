"""Krylov solves continued until the viscous dissipation of their answer keeps the solver
tolerance: the leak rate of both Reynolds schemes near the percolation threshold
(:mod:`roughfe.leakage.finite_volume`, :mod:`roughfe.fem.reynolds`;
docs/theory/04b_leakage_ii.md section 1).

Without wall motion the leak rate is the viscous dissipation over the drop,
``Q = D(x) / dp`` with ``D(x) = x^T A x`` (W; the Dirichlet problem's full operator, ``x =
p - p_out``). For an inexact answer ``x = x* + e`` (``e`` zero on the Dirichlet data) the
cross term ``e^T A x*`` is the exact residual on the unknowns, 0, so ``D(x) = D(x*) +
e^T A e``: the error is second order and an upper bound. A Krylov tolerance rtol (relative
to the right-hand side, the lift's flow into the unknowns) leaves ``e^T A e`` about
``rtol^2 S`` with ``S`` the dissipation of the lift itself (the boundary values with 0
inside: ``dp^2 sum T_in`` for finite volumes), a relative error ``rtol^2 R`` with ``R = S /
D``. Near the percolation threshold the open reservoirs conduct (h / u_c)^3 ~ 1e8-1e15
times more than the junction and R reaches 1e20, so where ``rtol R > 1`` the solve goes on
from its answer (same matrix and preconditioner) to ``rtol sqrt(rtol / R)``, not below
:data:`RTOL_FLOOR`.
"""
from __future__ import annotations

from typing import Callable, Optional

import numpy as np

from ..errors import available_memory

#: Tightest relative tolerance a solve is continued to for the leak rate near the
#: percolation threshold: on a 64^2 pinhole wall the leak rate is the same at 1e-14 and
#: 1e-17, the round-off floor.
RTOL_FLOOR = 1e-15

#: Most unknowns a broken-down Krylov solve is redone by MUMPS LU for (a 1024^2 grid).
DIRECT_MAX_UNKNOWNS = 2 ** 20

#: Memory a MUMPS LU solve is assumed to need per unknown (B): measured 0.7 kB per unknown
#: in all (peak RSS 249 MB, 65 MB before) on a 512^2 five-point Reynolds system; x3 for
#: the n log n fill growth up to :data:`DIRECT_MAX_UNKNOWNS` and a margin.
DIRECT_BYTES_PER_UNKNOWN = 2048


def _solve(solver, matrix, rhs, x0=None, *, own: bool = False, rtol=None):
    """``solver.solve``; a breakdown redone by MUMPS LU if small enough (module docstring).

    Returns
    -------
    (ndarray, int, bool, str, str, bool)
        Solution, Krylov iterations, converged flag, Krylov report, what the fallback did
        (``""``: not needed) and whether the solution is a direct one (the fallback's or
        the caller's own ``preonly`` solver: no continuation, a tolerance means nothing
        there).
    """
    from petsc4py import PETSc

    from .petsc_tools import LU_MUMPS, KrylovSolver, reason_name

    x, nit, success, message = solver.solve(matrix, rhs, x0, own=own, rtol=rtol)
    if solver.types.startswith("preonly/"):       # the caller's own direct solve
        return x, nit, success, message, "", True
    if success or solver.reason == PETSc.KSP.ConvergedReason.DIVERGED_MAX_IT:
        return x, nit, success, message, "", False
    n = len(rhs)
    broke = (f"; {solver.types} broke down "
             f"({reason_name(PETSc.KSP.ConvergedReason, solver.reason)})")
    if n > DIRECT_MAX_UNKNOWNS or n * DIRECT_BYTES_PER_UNKNOWN > available_memory():
        return x, nit, False, message, (
            f"{broke}; no MUMPS LU fallback for {n} unknowns (at most "
            f"{DIRECT_MAX_UNKNOWNS} and {DIRECT_BYTES_PER_UNKNOWN} B each of the available "
            f"memory)"), False
    with KrylovSolver(f"{solver.name}_lu", defaults=LU_MUMPS) as direct:
        x, _, success, report = direct.solve(matrix, rhs)
    return x, nit, success, message, f"{broke}; solved by MUMPS LU: {report}", True


def solve_for_dissipation(solver, matrix, rhs, x0=None, *, own: bool = False,
                          evaluate: Callable, scale: Optional[float] = None):
    """Solve ``A x = b`` with a :class:`~roughfe.fem.petsc_tools.KrylovSolver`, then
    continue it until the dissipation of ``x`` keeps the solver's tolerance (module
    docstring).

    Parameters
    ----------
    solver : KrylovSolver
        The solver (its ``rtol`` is the tolerance of the first solve and of the leak rate).
    matrix, rhs, x0, own
        As :meth:`KrylovSolver.solve`.
    evaluate : callable
        ``evaluate(x) -> (power, data)``: the dissipation ``D(x)`` in W and anything else
        computed with it (e.g. the face flows), returned for the last ``x``.
    scale : float, optional
        The dissipation ``S`` of the lift (W); None: no continuation (a sliding wall,
        no through-flow, nothing to keep).

    Returns
    -------
    (ndarray, int, bool, str, float, object)
        Solution, Krylov iterations in all, converged flag, report (naming a MUMPS LU
        fallback after a breakdown), ``D(x)`` and ``data``.
    """
    x, nit, success, message, fallback, direct = _solve(solver, matrix, rhs, x0, own=own)
    power, data = evaluate(x)
    rtol = solver.rtol
    for _ in range(2 if scale is not None else 0):   # 2: the first R may be low (Q high)
        ratio = scale / power if power > 0 else np.inf
        if direct or not (success and rtol > RTOL_FLOOR and rtol * ratio > 1.0):
            break
        rtol = max(np.sqrt(rtol / ratio), RTOL_FLOOR)
        x, more, success, message, fallback, direct = _solve(solver, matrix, rhs, x, rtol=rtol)
        nit += more
        message += f"; continued to rtol {rtol:.1e} for the leak rate: {nit} in all"
        power, data = evaluate(x)
    return x, nit, success, message + fallback, power, data
