"""Displacement control of the periodic BEM (Polonsky-Keer CG), elastic and bounded.

The periodic operator has zero mean displacement: an imposed approach Delta is an
imposed mean gap, and the mean pressure is the direction of zero curvature of the
primal problem. :func:`periodic_gap_control` solves the elastic case in the gap
variable; :func:`periodic_bounded_displacement` the case with a hardness, where the box
0 <= p <= H_p makes the primal problem well posed (called by
:func:`roughfe.bem.solve_contact`).
"""
from __future__ import annotations

import dataclasses
import functools

import numpy as np
import scipy.fft
import scipy.optimize

from ..errors import NoConvergenceError
from .operators import WORKERS, _irfftn_owned
from .pk import polonsky_keer
from .solvers import SolverOutput, kkt_residual


def periodic_full_contact(op, h):
    """Zero-mean pressure p' with H p' = h - mean h (exact: the spectral stiffness).

    The half-spectrum of h divided by the compliance spectrum in place (its only zero is
    the mean mode, set to zero): no zero-mean copy of h and no cached float64 stiffness
    spectrum (two fields fewer in memory while a load-controlled solve runs)."""
    hh = scipy.fft.rfftn(h, workers=WORKERS)
    hh.flat[0] = 0.0
    np.divide(hh, op.spectrum, out=hh, where=op.spectrum > 0)
    return _irfftn_owned(hh, h.shape)


def periodic_bounded_displacement(op, h, hmax, scale, delta, initial, tol, max_iter,
                                  hardness, elastic_state, precond):
    """Periodic displacement control with a hardness (bounded PK on the pressure).

    The elastic state comes first (``elastic_state()``, the caller's elastic solve at
    this Delta: through load control or in the gap variable, :func:`periodic_gap_control`;
    for Delta below max h - mean h): if no pressure exceeds H_p it is the answer.
    Otherwise the bounded CG starts from it clipped to [0, H_p] (``precond``: the CG's
    stiffness preconditioner); the points at the cap fix the mean pressure, the direction
    of zero curvature of the periodic operator that stalls the unbounded primal CG.
    Where they fix it poorly (few points at the cap beyond the elastic full contact,
    Delta >= max h - mean h: there the CG gets ``PRIMAL_BUDGET`` iterations) or the CG
    does not converge, the load bracket of :func:`bounded_approach_by_load` solves it."""
    beyond = delta >= hmax - float(h.mean())
    if initial is None and not beyond:
        elastic = elastic_state()
        if float(elastic.pressure.max()) <= hardness:
            return elastic
        initial = elastic.pressure
    spent = 0
    try:
        return polonsky_keer(op.apply_unchecked, h, scale, delta=delta, initial=initial,
                             diagonal=op.diagonal, precond=precond, tol=tol,
                             max_iter=min(max_iter, PRIMAL_BUDGET) if beyond else max_iter,
                             offset=-hmax, hardness=hardness)
    except NoConvergenceError as exc:  # the load bracket does not depend on that direction
        spent = exc.result.nit if exc.result is not None else 0
    out = bounded_approach_by_load(op, h, hmax, scale, delta, tol, max_iter, hardness,
                                   precond)
    return dataclasses.replace(out, nit=out.nit + spent)       # every iteration counted


#: iterations of the primal bounded CG beyond the elastic full contact before the load
#: bracket takes over (measured on 64^2 surfaces, H_p = 5 E* gbar: 16-39 where it
#: converged; where it did not it diverged or crawled to 20000)
PRIMAL_BUDGET = 300


#: load-controlled solves at most in :func:`bounded_approach_by_load` (measured: 6-12
#: on a 64^2 surface beyond full contact, H_p = 0.1 E*)
MAX_LOAD_SOLVES = 60


class _Solved(Exception):
    """Raised inside the root finder when a load-controlled state meets ``tol``."""


def bounded_approach_by_load(op, h, hmax, scale, delta, tol, max_iter, hardness, precond):
    """Periodic displacement control with a hardness H_p (Pa) through load control.

    Beyond the elastic full contact (Delta >= max h - mean h) every point touches and
    the mean pressure P is set by the plastic points alone: the primal CG in Delta then
    moves along the near-null uniform pressure; its conjugation overflowed and returned
    NaN pressures (a 64^2 surface at H_p = 0.1 E*: 3 of 15 steps; round 2, session 31).
    Here P is the unknown of a scalar equation instead: the load-controlled bounded CG
    (well posed: the load fixes the mean) gives the approach Delta(P), nondecreasing
    from max h - max h at P = 0 to max h - min h at P = H_p (every point plastic), flat
    at max h - mean h while the full elastic contact lasts. Delta(P) = ``delta`` is
    solved by Brent's method (scipy's brentq) on the bracket from the end of that plateau
    (P = H_p - max p', p' the zero-mean full-contact pressure) to H_p, each solve
    started from the last one's pressure at tol / 2. It stops at the first state whose
    displacement-control residual (bounded form of Eq. 2.5-2.6, the output's) is at most
    ``tol``; NoConvergenceError after ``MAX_LOAD_SOLVES`` solves without one."""
    if delta >= hmax - float(h.min()):   # every point plastic: p = H_p, u = 0 (zero mean)
        return SolverOutput(np.full(h.shape, float(hardness)), np.zeros(h.shape), delta, 0,
                            0.0, "closed form")
    # the bracket's lower end: P (Pa), Delta(P) - delta (m) and the first solve's start
    lo, f_lo, last = 0.0, hmax - float(h.max()) - delta, None      # first contact
    p0 = periodic_full_contact(op, h)
    onset = float(hardness) - float(p0.max())    # the first point yields in full contact
    if onset >= -float(p0.min()) and delta >= hmax - float(h.mean()):
        if delta <= (hmax - float(h.mean())) * (1 + 1e-12):
            # on the plateau: any P in [p_full, onset] holds this Delta; the least, as the
            # elastic closed form of solve_contact takes it
            p0 -= float(p0.min())
            return SolverOutput(p0, h - float(h.mean()), delta, 0, 0.0, "closed form")
        lo, f_lo, last = onset, hmax - float(h.mean()) - delta, p0 + onset   # f_lo < 0
    del p0
    state = {"nit": 0, "products": 0, "solves": 0, "out": None, "res": np.inf}

    def offset(P):
        state["out"] = out = polonsky_keer(
            op.apply_unchecked, h, scale, mean_pressure=P,
            initial=last if state["out"] is None else state["out"].pressure,
            diagonal=op.diagonal, precond=precond, tol=0.5 * tol, max_iter=max_iter,
            offset=-hmax, hardness=hardness)
        state["nit"] += out.nit
        state["products"] += out.n_products
        state["solves"] += 1
        state["res"] = float(kkt_residual(out.pressure, out.displacement - h + (hmax - delta),
                                          scale, upper=hardness))
        if state["res"] <= tol:
            raise _Solved
        return out.delta - delta

    f_hi = hmax - float(h.min()) - delta         # P = H_p: every point plastic
    try:
        scipy.optimize.brentq(lambda P: f_lo if P == lo else f_hi if P == hardness
                              else offset(P), lo, float(hardness), xtol=1e-300,
                              rtol=4 * np.finfo(float).eps, maxiter=MAX_LOAD_SOLVES)
    except (_Solved, RuntimeError):
        pass
    out = state["out"]
    if out is None:        # the bracket collapsed before any solve (round-off)
        raise NoConvergenceError(f"imposed approach {delta:.6g} m with a hardness: no "
                                 f"load-controlled solve inside [{lo:.6g}, {hardness:.6g}] Pa")
    result = SolverOutput(out.pressure, out.displacement, delta, state["nit"],
                          state["res"], "pk", state["products"])
    if not state["res"] <= tol:
        raise NoConvergenceError(
            f"imposed approach with a hardness through load control: KKT residual "
            f"{state['res']:.3e} after {state['solves']} load-controlled solves "
            f"({state['nit']} iterations), tolerance {tol:.1e}", result=result)
    return result


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
