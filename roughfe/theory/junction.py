"""Lorenz & Persson's critical-junction leak estimate from the PSD of a surface (SI: Pa,
m, Pa s, m^3/s), built on Persson's A(q, p) and u(p) of :mod:`roughfe.theory.persson`.

Critical junction (Lorenz & Persson 2009)
-----------------------------------------
Increasing the magnification, A(q, p) falls from 1; the contact area stops percolating
at ``A(q_c, p) = A_c``. Lorenz & Persson take the site-percolation threshold A_c ~ 0.42
(used here, changeable). The fluid then flows through the critical junction, whose
surface separation is the mean separation of the roughness *below* the critical scale
pressed by the local pressure on the contact patches at that scale:

    u_c = u(p_c; |q| > q_c),     p_c = p / A(q_c, p)                                   (4)

(Eq. (2) with the PSD restricted to ``|q| > q_c`` and ``m`` summed from ``q_c``; Lorenz
& Persson add a small term ``u1`` for the deformation of the junction, omitted here).
Each square of the nominal contact holds one critical junction; a seal of length Lx (the
direction of the pressure drop) and width Ly holds Ly/Lx such squares in parallel, each
a narrow gap of height u_c, so

    Q = (Ly / Lx) * (Delta P / eta) * u_c^3 / 12          (m^3/s)                     (5)

(Delta P in Pa, eta in Pa s, u_c in m). For a profile (1D) every contact point seals,
so no critical junction exists; :func:`critical_junction` accepts surfaces only.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.special

from ..errors import (InputError, check_finite_positive, check_in_open_interval,
                      check_leak_scale)
from ..surfaces.surface import Surface
from .persson import (GAMMA_DEFAULT, PERCOLATION_THRESHOLD, REFERENCES, _arrays, _pressures,
                      _spectrum, mean_separation)


@dataclass(frozen=True, eq=False)
class CriticalJunction:
    """Lorenz & Persson's critical-junction leak estimate at one pressure, Eqs. (4)-(5).

    Attributes
    ----------
    mean_pressure : float
        p (Pa).
    q_c : float
        Wavenumber at which A(q, p) falls to the percolation threshold (rad/m); NaN when
        the contact still percolates at full magnification (sealed: u_c = Q = 0); the
        first wavenumber (an upper bound) when A is below A_c already there.
    area_fraction_c : float
        A(q_c, p) (-).
    pressure_c : float
        Local pressure p / A(q_c, p) on the junction (Pa).
    u_c : float
        Surface separation at the critical junction (m).
    leak_rate : float
        Q, Eq. (5) (m^3/s).
    geometry_factor : float
        Ly/Lx (-).
    pressure_drop, viscosity : float
        Delta P (Pa), eta (Pa s).
    threshold : float
        A_c used (-).
    sealed : bool
        True when the real contact percolates (A(q1, p) >= A_c).
    """

    mean_pressure: float
    q_c: float
    area_fraction_c: float
    pressure_c: float
    u_c: float
    leak_rate: float
    geometry_factor: float
    pressure_drop: float
    viscosity: float
    threshold: float
    sealed: bool
    references: tuple = REFERENCES


def _geometry_factor(source, direction: str = "x") -> float:
    """Width over length along the pressure drop of a surface: ``Ly/Lx`` for flow along x
    (axis 0), ``Lx/Ly`` along y; 1 for a bare PSD."""
    if direction not in ("x", "y"):
        raise InputError(f"direction must be 'x' or 'y', got {direction!r}")
    if isinstance(source, Surface) and source.ndim == 2:
        lx, ly = source.size
        return ly / lx if direction == "x" else lx / ly
    return 1.0


def _leak_rate(geometry_factor, u_c, pressure_drop, viscosity, p_c) -> float:
    """Eq. (5), ``Q = (Ly/Lx) u_c^3 / 12 * Delta P / eta`` (m^3/s), the ratio
    ``Delta P / eta`` applied last without an intermediate overflow
    (:func:`roughfe.errors.check_leak_scale`, the rule of the Reynolds leak rates): written
    as one product, Delta P = 1e300 Pa with eta = 1e-20 Pa s gave inf for a Q of 5e299
    m^3/s (64^2 surface, 1 MPa); a Q beyond the normal floats (Delta P 1e-308 Pa: 0.0 or
    a subnormal) is an InputError naming the Delta P / eta the junction allows. A u_c that
    overflowed (p -> 0, where u(p) grows like -ln p: 1e-200 Pa on a 1 um surface) is an
    InputError naming the pressure (it was blamed on Delta P / eta, round 2, session 37)."""
    if not np.isfinite(u_c):
        raise InputError(f"the junction pressure p_c = {p_c:.3g} Pa is below what Persson's "
                         f"u(p) resolves: the mean separation there overflows (u grows like "
                         f"-ln p as p -> 0)")
    return check_leak_scale(geometry_factor * u_c ** 3 / 12.0, pressure_drop, viscosity)


def critical_junction(source, e_star, mean_pressure, pressure_drop, viscosity, *,
                      direction="x", geometry_factor=None, threshold=PERCOLATION_THRESHOLD,
                      gamma=GAMMA_DEFAULT) -> CriticalJunction:
    """Critical-junction leak rate of Lorenz & Persson (2009), Eqs. (4)-(5).

    Parameters
    ----------
    source : Surface or PowerSpectrum
        A 2D surface (a profile has no leak path once in contact).
    e_star : float
        E* (Pa).
    mean_pressure : float
        Nominal contact pressure p > 0 (Pa).
    pressure_drop : float
        Fluid pressure drop Delta P > 0 across the seal (Pa).
    viscosity : float
        Dynamic viscosity eta > 0 (Pa s).
    direction : {"x", "y"}
        Axis of the pressure drop (x = axis 0); sets the default geometry factor.
    geometry_factor : float, optional
        Width over length along the pressure drop; default from the surface size
        (``Ly/Lx`` along x, ``Lx/Ly`` along y), 1 for a bare PSD.
    threshold : float
        Percolation threshold A_c of the contact area, default 0.42.
    gamma : float
        As in :func:`persson`.

    Returns
    -------
    CriticalJunction
    """
    psd = _spectrum(source)
    if psd.ndim != 2:
        raise InputError("critical_junction needs a surface (2D): on a profile any contact "
                         "point seals the flow")
    if geometry_factor is None:
        geometry_factor = _geometry_factor(source, direction)
    geometry_factor = check_finite_positive("geometry_factor Ly/Lx", geometry_factor)
    threshold = check_in_open_interval("threshold A_c", threshold, 0.0, 1.0)
    dp = check_finite_positive("pressure_drop (Pa)", pressure_drop)
    eta = check_finite_positive("viscosity (Pa s)", viscosity)
    if np.ndim(mean_pressure) != 0:
        raise InputError(f"mean_pressure must be one number (Pa), got {mean_pressure!r}")
    p = float(_pressures(mean_pressure)[0])
    e = check_finite_positive("e_star (Pa)", e_star)
    q, q2, power = _arrays(psd)
    m = np.cumsum(q2 * power)                        # m(q) with the bin fully resolved
    a = scipy.special.erf(np.sqrt(2.0) * p / (e * np.sqrt(m)))
    below = np.flatnonzero(a < threshold)
    common = dict(mean_pressure=p, geometry_factor=geometry_factor, pressure_drop=dp,
                  viscosity=eta, threshold=threshold)
    if below.size == 0:
        return CriticalJunction(q_c=float("nan"), area_fraction_c=float(a[-1]),
                                pressure_c=p / float(a[-1]), u_c=0.0, leak_rate=0.0,
                                sealed=True, **common)
    k = int(below[0])
    if k == 0:
        # A < A_c already at the first wavenumber: A(q) falls from 1 (no roughness
        # resolved) to a[0] within the first band, so it crosses A_c there; the junction
        # carries p / A_c and all the roughness lies below its scale. (Until round 2,
        # session 28 the junction was loaded by p / a[0]: at light load a[0] ~ p, so
        # p_c, u_c and Q stopped depending on p -- 3.6e-24 m^3/s from 1 MPa to 1 GPa on
        # di-1, 200x below Reynolds.) q_c is reported as q[0], its upper bound.
        q_c, a_c = float(q[0]), threshold
        p_c = p / a_c
        u_c = float(mean_separation(q, power, e, p_c, gamma, q2=q2)[0])
        leak = _leak_rate(geometry_factor, u_c, dp, eta, p_c)
        return CriticalJunction(q_c=q_c, area_fraction_c=a_c, pressure_c=p_c, u_c=u_c,
                                leak_rate=leak, sealed=False, **common)
    else:   # log-linear interpolation of A(q) between the bracketing wavenumbers
        t = (a[k - 1] - threshold) / (a[k - 1] - a[k])
        q_c = float(np.exp(np.log(q[k - 1]) + t * (np.log(q[k]) - np.log(q[k - 1]))))
        a_c = threshold
    p_c = p / a_c
    u_c = float(mean_separation(q, power, e, p_c, gamma, q_min=q_c, q2=q2)[0])
    leak = _leak_rate(geometry_factor, u_c, dp, eta, p_c)
    return CriticalJunction(q_c=q_c, area_fraction_c=a_c, pressure_c=p_c, u_c=u_c,
                            leak_rate=leak, sealed=False, **common)
