"""Input checks of :func:`roughfe.bem.solve_contact`: what was wrong, which value, what is
allowed (InputError)."""
from __future__ import annotations

import numpy as np

from ..errors import (InputError, check_finite_positive, check_in_open_interval, check_instance,
                      check_real_array)
from ..model import _check_delta, _check_pressure
from ..surfaces.surface import Surface
from .coarse_start import COARSE_START_MIN

#: the smallest relative KKT residual a solve may be asked for: 100 float64 epsilons. The
#: residual of u = H p in double precision stops near 2e-15 (measured: 4.0e-15 at 64^2,
#: 1.8e-15 at 1024^2, periodic H = 0.8, p/E* = 0.05); a tolerance below it was found
#: unreachable only after max_iter (20000) iterations
TOL_FLOOR = 100 * float(np.finfo(float).eps)


def is_flat(surface) -> bool:
    """Whether the heights of ``surface`` are flat for the solver: constant, or so small
    that their mean square underflows (rms height 0 in float64, e.g. 1e-200 m: that had
    passed as rough and ended in a ZeroDivisionError (periodic) or a PK residual of 1e176
    (non-periodic), round 2, session 32). Physically tiny but representable heights are
    solved (the genomics' chromosome whose waves cancel, 3e-22 m on a 1 mm profile, is
    judged flat by its own rule, :func:`roughfe.genomics.macro_micro.is_flat`)."""
    h = surface.heights
    return not float(np.ptp(h)) > 0.0 or not float(np.mean(np.square(h - h.mean()))) > 0.0


def _check_surface(surface):
    check_instance("surface", surface, Surface, "a roughfe Surface")
    if is_flat(surface):
        raise InputError(f"the surface is flat (height range {np.ptp(surface.heights):.3g} m: "
                         f"constant, or below what float64 can square): contact of a flat "
                         f"on a flat is uniform and has no rough-contact solution")


def _check_tol(tol) -> float:
    """The relative KKT tolerance: in [:data:`TOL_FLOOR`, 1)."""
    tol = check_in_open_interval("tol (relative KKT residual)", tol, 0.0, 1.0)
    if tol < TOL_FLOOR:
        raise InputError(f"tol (relative KKT residual) = {tol:g} is below what float64 "
                         f"arithmetic can reach (the residual stops near 2e-15); allowed: "
                         f"{TOL_FLOOR:.1e} <= tol < 1")
    return tol


def _check_target(delta, mean_pressure):
    """The one target of a solve (the checks of :class:`roughfe.model.Loading`: a bool or a
    string is refused, not read as 1 m or parsed)."""
    if (delta is None) == (mean_pressure is None):
        raise InputError("give exactly one of delta (approach, m) or mean_pressure (Pa)")
    if delta is not None:
        return _check_delta("delta", delta), None
    return None, _check_pressure("mean_pressure", mean_pressure)


def _check_hardness(hardness, mean_pressure, plastic_displacement, shape):
    """Validate the hardness (Pa) and a prior plastic displacement (m)."""
    if hardness is None:
        if plastic_displacement is not None:
            raise InputError("plastic_displacement needs a hardness (it is the permanent "
                             "deformation of a perfectly plastic interface)")
        return None, None
    if isinstance(hardness, bool):
        raise InputError(f"hardness must be a number of Pa > 0, got {hardness!r}")
    hp = check_finite_positive("hardness (Pa, the pressure cap of the perfectly plastic "
                               "interface)", hardness)
    if mean_pressure is not None and not mean_pressure < hp:
        raise InputError(f"mean_pressure = {mean_pressure:.6g} Pa must be below the hardness "
                         f"{hp:.6g} Pa (at p = hardness every point is plastic)")
    if plastic_displacement is not None:
        up = check_real_array("plastic_displacement", plastic_displacement)
        if up.shape != shape:
            raise InputError(f"plastic_displacement has shape {up.shape}, expected {shape}")
        if float(up.min()) < 0:
            raise InputError("plastic_displacement (m) must be >= 0")
        plastic_displacement = up
    return hp, plastic_displacement


def _check_coarse_correction(value, op, solver, mean_pressure, hardness, two_level_unfit):
    """``coarse_correction`` of :func:`solve_contact`: None, True or False; True only
    where the two-level correction applies (``two_level_unfit(op, hardness)``: why
    not, or None; an imposed approach on a periodic grid only from ``COARSE_START_MIN``
    points per axis, where it is solved through load control); else an InputError that
    says why."""
    if value is None or value is False:
        return value
    if value is not True:
        raise InputError(f"coarse_correction must be None (automatic), True or False, "
                         f"got {value!r}")
    why = ("solver 'pk'" if solver != "pk" else two_level_unfit(op, hardness))
    if not why and mean_pressure is None and op.periodic and min(op.shape) < COARSE_START_MIN:
        # an imposed approach on a periodic surface takes the correction only where it
        # is solved through load control (roughfe.bem.approach)
        why = (f"load control (mean_pressure), or an imposed approach on a grid of at "
               f"least {COARSE_START_MIN} points per axis (solved through load control), "
               f"got {op.shape}")
    if why:
        raise InputError(f"coarse_correction=True (the two-level correction of the "
                         f"Polonsky-Keer CG) needs {why}")
    return True
