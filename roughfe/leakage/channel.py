"""Steady Reynolds flow along a 1D channel: the gap of a profile contact (thesis Eq.
2.10-2.12 in one dimension, no wall velocity).

A profile ``h(x)`` against a flat leaves the gap ``g(x)`` (m) at the samples
``x_i = i dx``, ``i = 0 .. n-1``; the fluid enters at ``x = 0`` at the absolute pressure
``p_in`` and leaves at ``x = W = (n-1) dx`` at ``p_out``. In 1D, mass conservation (Eq.
2.10) makes the flux per unit width ``q = -g^3 p' / (12 mu)`` (Eq. 2.11) constant, so

    q = (p_in - p_out) / (12 mu R),   R = integral_0^W dx / g^3,
    p(x) = p_in - (p_in - p_out) R(x) / R,   R(x) = integral_0^x ds / g^3.

The gap between samples is taken linear (the P1 interpolation of the FEM body's top and
the sampling of the BEM), and each segment's integral is exact for it:

    integral over [x_i, x_i+1] of dx / g^3 = dx (g_i + g_i+1) / (2 g_i^2 g_i+1^2),

so ``q`` and the nodal pressures are exact for a piecewise-linear gap (no quadrature
error); a smooth gap sampled at spacing dx is integrated to O(dx^2).

Closure. A sample with ``g = 0`` makes the resistance infinite: ``q = 0`` (in 1D any
contact closes the channel; there are no contact islands that the fluid can go round).
The pressure is then ``p_in`` upstream of the first closed sample and ``p_out``
downstream of the last one; from the first to the last closed sample (contact spots and
the pockets between them, whose pressure depends on the loading history: trapped fluid)
it is set to ``(p_in + p_out) / 2`` (a convention for unconnected cells).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError, check_finite_positive, check_leak_scale, check_real_array


@dataclass(frozen=True, eq=False)
class ChannelFlow:
    """Reynolds flow along a 1D channel (module docstring).

    Attributes
    ----------
    x : ndarray (n,)
        Sample positions (m).
    gap : ndarray (n,)
        Gap (m).
    pressure : ndarray (n,)
        Absolute fluid pressure at the samples (Pa).
    leak_rate : float
        Flux per unit width ``q`` (m^2/s), from inlet to outlet (negative when
        ``p_in < p_out``: reversed flow); 0 when closed.
    resistance : float
        ``R = integral dx / g^3`` (1/m^2); inf when closed.
    closed : bool
        Some sample has zero gap.
    inlet_pressure, outlet_pressure, mu : float
        ``p_in``, ``p_out`` (Pa), viscosity (Pa s).
    """

    x: np.ndarray
    gap: np.ndarray
    pressure: np.ndarray
    leak_rate: float
    resistance: float
    closed: bool
    inlet_pressure: float
    outlet_pressure: float
    mu: float

    @property
    def mean_pressure(self) -> float:
        """Mean fluid pressure over the channel (Pa), trapezoidal (the P1 mean)."""
        return trapezoid_mean(self.pressure)

    @property
    def hydraulic_aperture(self) -> float:
        """Uniform gap of the same leak rate, ``(W / R)^(1/3)`` (m); 0 when closed."""
        return 0.0 if self.closed else float((self.x[-1] / self.resistance) ** (1.0 / 3.0))


def trapezoid_mean(values) -> float:
    """Mean of nodal values over the sampled interval: trapezoidal weights, the exact mean
    of their linear interpolation (end samples weigh half)."""
    v = np.asarray(values, dtype=float)
    return float((v.sum() - 0.5 * (v[0] + v[-1])) / (v.size - 1))


def check_absolute_pressures(p_in, p_out) -> tuple:
    """``(p_in, p_out)`` as floats if both are finite absolute pressures >= 0 (Pa), the
    inputs of the coupled solvers; else InputError naming the bad one."""
    for name, v in (("inlet pressure", p_in), ("outlet pressure", p_out)):
        if not (np.isfinite(v) and v >= 0):
            raise InputError(f"{name} must be a finite absolute pressure >= 0 (Pa), got {v!r}")
    return float(p_in), float(p_out)


def channel_flow(gap, spacing: float, *, p_in: float, p_out: float,
                 mu: float = 1e-3) -> ChannelFlow:
    """Exact 1D Reynolds flow on a piecewise-linear gap (module docstring).

    Parameters
    ----------
    gap : array_like (n,)
        Gap at the samples (m), finite, >= 0, n >= 2.
    spacing : float
        Sample spacing dx (m).
    p_in, p_out : float
        Absolute pressures at ``x = 0`` and ``x = (n-1) dx`` (Pa), finite.
    mu : float
        Dynamic viscosity (Pa s).

    Returns
    -------
    ChannelFlow
    """
    g = check_real_array("the channel gap", gap, 1)
    if g.size < 2:
        raise InputError(f"the channel gap must be a 1D array of at least 2 samples (m), "
                         f"got shape {g.shape}")
    if np.any(g < 0):
        bad = g[g < 0][0]
        raise InputError(f"the channel gap must be finite and >= 0 (m), got {bad!r}")
    dx = check_finite_positive("spacing", spacing)
    mu = check_finite_positive("mu", mu)
    for name, v in (("inlet pressure", p_in), ("outlet pressure", p_out)):
        if not np.isfinite(v):
            raise InputError(f"{name} must be finite (Pa), got {v!r}")
    p_in, p_out = float(p_in), float(p_out)
    x = np.arange(g.size) * dx
    closed = bool(np.any(g == 0))
    if closed:
        shut = np.flatnonzero(g == 0)
        p = np.full(g.size, 0.5 * (p_in + p_out))
        p[:shut[0]] = p_in
        p[shut[-1] + 1:] = p_out
        return ChannelFlow(x, g, p, 0.0, float("inf"), True, p_in, p_out, mu)
    g0, g1 = g[:-1], g[1:]
    seg = dx * (g0 + g1) / (2.0 * g0 ** 2 * g1 ** 2)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    R = float(cum[-1])
    p = p_in - (p_in - p_out) * (cum / R)        # cum / R in [0, 1]: no overflow
    # q = (1 / (12 R)) (p_in - p_out) / mu, the ratio last (errors.check_leak_scale: 12 mu R
    # overflowed to a leak rate of 0.0 in silence at mu 1e300 on a 10 nm gap; one beyond the
    # floats is an InputError)
    q = check_leak_scale(1.0 / (12.0 * R), p_in - p_out, mu)
    return ChannelFlow(x, g, p, q, R, False, p_in, p_out, mu)
