"""Displacement control of the periodic BEM (Polonsky-Keer CG), elastic and bounded.

The periodic operator has zero mean displacement: an imposed approach Delta is an
imposed mean gap, and the mean pressure is the direction of zero curvature of the
primal problem. :func:`periodic_gap_control` solves the elastic case in the gap
variable; :func:`periodic_bounded_displacement` the case with a hardness, where the box
0 <= p <= H_p makes the primal problem well posed (called by
:func:`roughfe.bem.solve_contact`).
"""
from __future__ import annotations

import functools

import numpy as np

from ..errors import NoConvergenceError
from .pk import polonsky_keer
from .solvers import SolverOutput, kkt_residual


def periodic_bounded_displacement(op, h, hmax, scale, delta, initial, tol, max_iter,
                                  hardness, elastic_state, precond):
    """Periodic displacement control with a hardness (bounded PK on the pressure).

    The elastic state comes first (``elastic_state()``, the caller's elastic solve at
    this Delta: through load control or in the gap variable, :func:`periodic_gap_control`;
    for Delta below max h - mean h): if no pressure exceeds H_p it is the answer.
    Otherwise the bounded CG starts from it clipped to [0, H_p] (``precond``: the CG's
    stiffness preconditioner); the points at the cap fix the mean pressure, the direction
    of zero curvature of the periodic operator that stalls the unbounded primal CG."""
    if initial is None and delta < hmax - float(h.mean()):
        elastic = elastic_state()
        if float(elastic.pressure.max()) <= hardness:
            return elastic
        initial = elastic.pressure
    return polonsky_keer(op.apply_unchecked, h, scale, delta=delta, initial=initial,
                         diagonal=op.diagonal, precond=precond, tol=tol,
                         max_iter=max_iter, offset=-hmax, hardness=hardness)


def periodic_gap_control(op, b, scale, delta, initial, tol, max_iter, stiff):
    """Displacement control on the periodic operator, in the gap variable.

    With mean(u) = 0 an imposed Delta is an imposed mean gap gbar = max h - mean h -
    Delta. The problem min 1/2 u'Ku s.t. gap w = u - s >= 0, mean(w) = gbar (K = H^-1
    the stiffness operator, E*|q|/2, s = Delta + b) has the structure of the
    load-controlled problem with (pressure, compliance) -> (gap, stiffness), and the
    pressure p = K u + pbar is the multiplier (as Tamaas' PolonskyKeerRey does for an
    imposed gap). The primal form would have to find the mean pressure through a
    direction of zero curvature, which stalls the CG. ``stiff`` applies K (Pa/m).
    """
    s = delta + b
    gbar = -float(s.mean())
    compliance = functools.partial(op.convolve_spectrum, spectrum=op.spectrum)
    Ks = stiff(s)
    w0 = None
    if initial is not None and np.any(initial > 0):
        w0 = np.maximum(op.apply(initial) - s, 0.0)
        w0[initial > 0] = 0.0
        if w0.mean() <= 0:
            w0 = None
    pscale = float(np.ptp(Ks)) or 1.0
    diagonal = float(stiff(np.eye(1, b.size).reshape(b.shape)).flat[0])
    # The dual (gap) residual and the primal one of Eq. 2.5 are not the same norm: a dual
    # solve that stops just below ``tol`` can leave the primal residual a little above
    # it (seen once: 2.8e-9 after a 6-iteration warm start from the sweep's secant
    # predictor). Such a solve is continued from its own gap with a 100x tighter dual
    # tolerance, at most twice, before the primal check below may fail.
    nit, dual_tol = 0, tol
    for _ in range(3):
        o = polonsky_keer(stiff, -Ks, pscale, mean_pressure=gbar, initial=w0,
                          diagonal=diagonal, precond=compliance, tol=dual_tol,
                          max_iter=max_iter)
        nit += o.nit
        w = o.pressure
        u = w + s
        p = np.maximum(stiff(u) - o.delta, 0.0)
        p[w > 0] = 0.0
        u = op.apply(p)
        res = kkt_residual(p, u - s, scale)      # the primal residual of Eq. 2.5
        if res <= 10 * tol:
            break
        w0, dual_tol = w, dual_tol / 100.0
    out = SolverOutput(p, u, delta, nit, res, "pk")
    if res > 10 * tol:   # the dual converged; the primal must follow closely
        raise NoConvergenceError(f"Polonsky-Keer CG (gap variable): primal KKT residual "
                                 f"{res:.3e} after {nit} iterations, tolerance {tol:.1e}",
                                 result=out)
    return out
