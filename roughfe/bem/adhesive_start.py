"""Starts of the adhesive minimisation of :mod:`roughfe.bem.adhesion` (in m, on the
unknowns' grid: the gap, and on a non-periodic grid the displacement of the padding).

* A cold solve starts from the non-adhesive equilibrium at the same approach
  (:func:`elastic_start`).
* A step of a continuation starts from the previous state carried along its branch
  (:func:`continued_start`): the Euler (tangent) predictor of a predictor-corrector
  continuation, with the elastic tangent of the previous contact set held fixed.

Why the tangent and not the previous gap shifted by the change of Delta (the start up to
round 2, session 19): in a quasi-static displacement-controlled experiment the body is
in equilibrium at every instant and the points in contact move with the flat until the
branch they are on ends. The shifted gap is the state of a body that did not respond at
all while the flat moved: it opens every contact point by dDelta at once, a kick that
can throw the state out of a shallow basin before the branch ends (premature
detachment on unloading), and it costs the minimiser the whole elastic response of the
step. Measured (docs/theory/07_adhesion_persson.md, "The continuation's predictor and
the process zone"): the same pull-off as the shifted start on resolved laws at every
step size, 1.3-1.4x fewer iterations per loading step at 512^2 (47 -> 37 exponential,
58 -> 42 Maugis-Dugdale); on a law whose process zone is far below the grid spacing (a
lattice of independent bistable cells) neither start gives a pull-off that converges as
the step shrinks (:func:`roughfe.bem.interface_law.check_resolution` warns).
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError, NoConvergenceError

#: tolerance of the fixed-set rate behind the tangent predictor: it only starts the
#: minimiser (which corrects it to 1e-5 of the traction scale), so a rough rate will do
TANGENT_TOL = 1e-4


def elastic_start(surface, material, op, delta, c, energy):
    """Start of a cold solve (m, on the unknowns' grid): the non-adhesive equilibrium at
    the same approach (Polonsky-Keer, preconditioned: cheap), or the rigid gap when
    there is none (Delta <= 0, or full periodic contact)."""
    from .contact import solve_contact

    h = surface.heights
    rigid = np.maximum(c, 0.0)
    if delta <= 0 or (op.periodic and delta >= float(h.max() - h.mean())):
        if op.periodic:
            return rigid
        x0 = np.zeros(energy.shape)
        x0[energy.phys] = rigid
        return x0
    r = solve_contact(surface, material, delta=delta, kernel=op.name, solver="pk", tol=1e-6,
                      compute_stiffness=False)
    return _on_unknowns(op, energy, r.pressure, r.gap)


def _on_unknowns(op, energy, pressure, gap):
    """The gap ``gap`` on the grid, with (non-periodic) the displacement that
    ``pressure`` causes on the padding."""
    if op.periodic:
        return np.array(gap, float)
    x0 = _padded_displacement(op, pressure)
    x0[energy.phys] = gap
    return x0


def _padded_displacement(op, pressure):
    """H p on the zero-padded grid of a non-periodic operator (m)."""
    return op.convolve_spectrum(np.pad(pressure, [(0, m - n) for n, m in
                                                  zip(op.shape, op.fft_shape)]), op.spectrum)


def continued_start(initial, delta, op, energy):
    """Start of the step from the state ``initial`` to the approach ``delta`` (m): the
    previous gap plus dDelta times its rate on the fixed contact set c of ``initial``,
    ``dg/dDelta = H x - 1`` with ``H_cc x_c = 1`` (x the pressure rate of
    :func:`roughfe.bem.stiffness.unit_load_rate`; zero on c), and the padding's
    displacement plus dDelta times its rate ``(H x)`` there (non-periodic grids).

    Without contact (or with full periodic contact, where the approach does not move the
    state) the rate is the rigid one, -1: the previous gap shifted by the change of
    Delta. So it is when the rate's solve does not converge."""
    from .stiffness import unit_load_rate

    g = np.asarray(initial.gap, float)
    if g.shape != op.shape:
        raise InputError(f"initial state has shape {g.shape}, expected {op.shape}")
    step = float(delta) - float(initial.delta)
    contact = np.asarray(initial.contact, bool)
    rate = None
    if step != 0.0 and contact.any() and not (op.periodic and contact.all()):
        try:
            rate = unit_load_rate(op, contact, tol=TANGENT_TOL)
        except NoConvergenceError:
            rate = None
    pad = None
    if not op.periodic:
        pad = (np.zeros(energy.shape) if initial.fields is None else
               np.array(initial.fields["padded_displacement"], float))
    if rate is None:
        if pad is None:
            return g - step
        pad[energy.phys] = g - step
        return pad
    if op.periodic:
        x0 = g + step * (op.apply(rate) - 1.0)
        x0[contact] = 0.0
        return x0
    w = _padded_displacement(op, rate)
    x0 = pad + step * w
    gap = g + step * (w[energy.phys] - 1.0)
    gap[contact] = 0.0
    x0[energy.phys] = gap
    return x0
