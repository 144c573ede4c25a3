"""Leak rate through a gap field from the Reynolds equation (thesis Eq. 2.10-2.12).

Two discretisations of one equation, chosen by ``scheme``:

* ``"fv"`` (default): cell-centred finite volumes with the harmonic mean of ``h^3``
  between face neighbours (:mod:`roughfe.leakage.finite_volume`): no conduction through
  corner contacts, the same percolation verdict as the free-volume network with
  ``corner_rule="closed"``; pressure per cell.
* ``"fe"``: the dolfinx cross-check (:mod:`roughfe.fem.reynolds`, Q1 pressure at the cell
  corners, gap constant per cell): two open cells touching at a corner share a pressure
  node and exchange fluid, so on rough gaps near the percolation threshold it leaks more
  than the FV scheme; on smooth (or refined) gap fields both converge at second order to
  the same leak rate (docs/theory/04_leakage.md).

Both solve with CG + BoomerAMG and return the leak rate, the hydraulic aperture and the
pressure and flux fields as a frozen :class:`ReynoldsResult`. The flux per unit width is
Eq. 2.11 divided by the (constant) density, ``q = h U/2 - h^3/(12 mu) grad p`` (m^2/s),
at the cell centres.

Without wall motion the flow is linear in the drop and in ``1/mu``: :func:`reynolds_flow`
solves at a unit drop and viscosity and scales the result (:func:`from_unit_drop`), so
that the hydraulic aperture and the flow imbalance do not depend on them and no drop or
viscosity that a float holds overflows inside the solve; a leak rate beyond the float
range itself is refused (:func:`roughfe.errors.check_leak_scale`).
:func:`scaled_reynolds_fv` is the same for the raw finite-volume solve at absolute
pressures (the two-way coupling, :mod:`roughfe.leakage.fsi`).
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, replace
from typing import Mapping, Optional

import numpy as np

from ..errors import (FlowImbalanceWarning, InputError, check_finite_nonnegative,
                      check_finite_positive, check_leak_scale, check_real_array, times_ratio)
from ..fem.reynolds import check_reynolds_data, solve_reynolds_fe
from ..frozen import ReadOnlyArrays, compact_repr, read_only_arrays
from .finite_volume import FVSolution, solve_reynolds_fv

SCHEMES = ("fv", "fe")

#: Largest ``|inlet_flow - outlet_flow| / |leak_rate|`` that :func:`reynolds_flow` passes
#: without a :class:`~roughfe.errors.FlowImbalanceWarning`. The boundary flows carry the
#: error of the pressure solve (CG rtol 1e-10, and round-off) times ``R``, the ratio of the
#: inlet faces' conductance to the leak's: <= 1e-9 on most gaps; beyond 1e-6 either the
#: tolerance (a 10 x 9 random gap, conductances 2.7e5 apart: 2.8e-6 at rtol 1e-10, 4e-10
#: at 1e-14) or round-off (a 128^2 crop of sur-2 at 10 MPa: 2.8e-6 at any rtol).
FLOW_IMBALANCE_TOL = 1e-6


@dataclass(frozen=True, eq=False)
class ReynoldsResult(ReadOnlyArrays):
    """Steady Reynolds flow through a gap field (Eq. 2.12).

    Attributes
    ----------
    direction : {"x", "y"}
        Axis of the imposed pressure drop (inlet at coordinate 0).
    scheme : {"fv", "fe"}
        Discretisation (see the module docstring).
    leak_rate : float
        Volumetric leak rate ``Q`` in m^3/s: without wall motion the viscous dissipation
        over the drop, both schemes (no round-off cancellation;
        docs/theory/04b_leakage_ii.md); with it "fv" the mean of the boundary flows, "fe"
        the consistent weak-form flux.
    hydraulic_aperture : float or None
        ``h_eff = (12 mu Q L_flow / (W dp))^(1/3)`` in m: the parallel-plate gap with the
        same leak rate (0 when nothing flows; None without a pressure drop).
    inlet_flow, outlet_flow : float
        Flow through the inlet and the outlet (m^3/s); equal up to the solver tolerance
        except near the percolation threshold, where the one on the side of the large
        open reservoir is round-off of the pressure drop (:attr:`flow_imbalance`).
    pressure : ndarray, shape (nx, ny) for "fv", (nx+1, ny+1) for "fe"
        Pressure in Pa per cell ("fv") or at the cell corners ("fe"); NaN where the
        inlet/outlet data do not determine it (inside contact, trapped pockets).
    flux : ndarray, shape (nx, ny, 2)
        Flux per unit width ``q`` at the cell centres (m^2/s), components (x, y).
    percolates : bool
        Inlet and outlet connected through open cells: face neighbours for "fv", also
        cells touching at a corner for "fe" (Q1).
    pressure_drop, mu : float
        ``p_in - p_out`` (Pa) and viscosity (Pa s).
    flow_length, width : float
        Domain length along and across the flow (m).
    success, message, nit : bool, str, int
        Linear solver report.
    """

    direction: str
    scheme: str
    leak_rate: float
    hydraulic_aperture: Optional[float]
    inlet_flow: float
    outlet_flow: float
    pressure: np.ndarray
    flux: np.ndarray
    percolates: bool
    pressure_drop: float
    mu: float
    flow_length: float
    width: float
    success: bool
    message: str
    nit: int

    __repr__ = compact_repr

    def __post_init__(self):       # a result never changes: its arrays read-only
        read_only_arrays(self)     # in place (copies: +0.45 GB at 4096^2 Reynolds)

    @property
    def pressure_at(self) -> str:
        """``"cells"`` (FV) or ``"nodes"`` (FE): where :attr:`pressure` lives."""
        return "cells" if self.scheme == "fv" else "nodes"

    @property
    def flow_imbalance(self) -> Optional[float]:
        """``|inlet_flow - outlet_flow| / |leak_rate|``; None when the leak rate is 0.

        Above :data:`FLOW_IMBALANCE_TOL` the boundary flows (and the flux field by the
        large-conductance boundary) are at the round-off of the pressure drop; the leak
        rate without wall motion (either scheme) does not rest on them, one with a sliding
        wall is uncertain by about this fraction."""
        if self.leak_rate == 0.0:
            return None
        return abs(self.inlet_flow - self.outlet_flow) / abs(self.leak_rate)

    @property
    def flux_magnitude(self) -> np.ndarray:
        """``|q|`` per cell (m^2/s)."""
        return np.hypot(self.flux[..., 0], self.flux[..., 1])


def hydraulic_aperture(leak_rate: float, *, mu: float, pressure_drop: float,
                       flow_length: float, width: float) -> float:
    """Parallel-plate gap with the same leak rate, ``(12 mu Q L / (W dp))^(1/3)`` (m).

    Inverts the exact parallel-plate law ``Q = h^3 W dp / (12 mu L)``; returns 0 for
    ``Q <= 0``.
    """
    dp = check_finite_positive("pressure_drop", pressure_drop)
    mu = check_finite_positive("mu (Pa s)", mu)
    flow_length = check_finite_positive("flow_length (m)", flow_length)
    width = check_finite_positive("width (m)", width)
    return float(np.cbrt(max(leak_rate, 0.0) * 12.0 * mu * flow_length / (width * dp)))


def from_unit_drop(p_out: float, pressure_drop: float, mu: float, pressure, leak_rate, *flows):
    """A Reynolds solution without wall motion at ``p_in = 1``, ``p_out = 0`` and ``mu = 1``
    scaled to the drop ``dp`` (Pa) and viscosity ``mu`` (Pa s): Eq. 2.12 is linear in the
    pressure and ``q = -h^3 / (12 mu) grad p``, so the pressure is ``p_out + dp p`` and every
    flow (leak rate, boundary flows, flux fields: m^3/s or m^2/s) is times ``dp / mu``
    (:func:`roughfe.errors.times_ratio`; the leak rate through
    :func:`roughfe.errors.check_leak_scale`). Returns ``(pressure, leak_rate, *flows)``."""
    return (p_out + pressure_drop * pressure, check_leak_scale(leak_rate, pressure_drop, mu),
            *(times_ratio(v, pressure_drop, mu) for v in flows))


def scaled_reynolds_fv(gap, spacing, *, mu: float, p_in: float, p_out: float,
                       initial=None, **options) -> FVSolution:
    """:func:`~roughfe.leakage.finite_volume.solve_reynolds_fv` without wall motion at any
    pressures and viscosity a float holds: solved at a unit drop and viscosity and scaled
    (:func:`from_unit_drop`), as :func:`reynolds_flow` does. ``p_in < p_out`` (reversed
    flow) and ``p_in = p_out`` (no flow: the pressure ``p_out`` on the live cells, no
    flux) are allowed. ``initial`` (Pa, absolute) starts the CG as there; ``options``:
    ``direction``, ``periodic``, ``petsc_options``, ``solver``.

    Solved at the given ``mu`` and pressures, a viscosity of 1e300 Pa s gave a leak rate of
    0 and a pressure field of underflowed transmissibilities, 1e-300 Pa s a NaN solve, a
    drop of 1e200 Pa an overflowed dissipation (round 2, session 34). A leak rate beyond
    the normal float range is an :class:`~roughfe.errors.InputError`.
    """
    g, _, mu, _ = check_reynolds_data(gap, spacing, mu, p_in, p_out,
                                      options.get("direction", "x"), (0.0, 0.0))
    dp = float(p_in) - float(p_out)
    if not np.isfinite(dp):
        raise InputError(f"p_in - p_out must be finite (Pa), got {p_in!r} - {p_out!r}")
    if initial is not None:     # the start in the unit solve's scale (NaN kept)
        initial = check_real_array("initial pressure", initial, unit="Pa", allow_nan=True)
        initial = times_ratio(initial - float(p_out), 1.0, dp) if dp else initial - p_out
    unit = solve_reynolds_fv(g, spacing, mu=1.0, p_in=1.0 if dp else 0.0, p_out=0.0,
                             initial=initial, **options)
    pressure, leak, flux, q_in, q_out = from_unit_drop(
        float(p_out), dp, mu, unit.pressure, unit.leak_rate, unit.flux, unit.inlet_flow,
        unit.outlet_flow)
    return replace(unit, pressure=pressure, flux=flux, inlet_flow=float(q_in),
                   outlet_flow=float(q_out), leak_rate=float(leak))


def cell_flux(pressure, gap, spacing, *, mu: float, wall_velocity=(0.0, 0.0)) -> np.ndarray:
    """Flux per unit width at the cell centres, ``q = h U/2 - h^3/(12 mu) grad p`` (Eq. 2.11).

    Parameters
    ----------
    pressure : ndarray, shape (nx+1, ny+1)
        Q1 nodal pressure (Pa), finite.
    gap : ndarray, shape (nx, ny)
        Gap per cell (m).
    spacing : (float, float)
        ``(dx, dy)`` in m.

    Returns
    -------
    ndarray, shape (nx, ny, 2)
        ``(q_x, q_y)`` in m^2/s.
    """
    p = np.asarray(pressure, dtype=float)
    dx, dy = spacing
    dpdx = 0.5 * ((p[1:, :-1] - p[:-1, :-1]) + (p[1:, 1:] - p[:-1, 1:])) / dx
    dpdy = 0.5 * ((p[:-1, 1:] - p[:-1, :-1]) + (p[1:, 1:] - p[1:, :-1])) / dy
    h = np.asarray(gap, dtype=float)
    k = h**3 / (12.0 * mu)
    u = np.asarray(wall_velocity, dtype=float)
    return np.stack([0.5 * h * u[0] - k * dpdx, 0.5 * h * u[1] - k * dpdy], axis=-1)


def reynolds_flow(gap, spacing, *, direction: str = "x", mu: float = 1e-3,
                  pressure_drop: float = 1.0, p_out: float = 0.0, periodic: bool = False,
                  wall_velocity=(0.0, 0.0), h_min: float = 0.0, scheme: str = "fv",
                  petsc_options: Optional[Mapping] = None) -> ReynoldsResult:
    """Solve Eq. 2.12 on a gap field and return the leak rate and the flow fields.

    Parameters
    ----------
    gap : ndarray, shape (nx, ny)
        Gap in m per grid cell (0 in contact), e.g. ``ContactResult.gap``.
    spacing : (float, float)
        Grid spacing ``(dx, dy)`` in m.
    direction : {"x", "y"}
        Flow axis; the inlet is the side at coordinate 0.
    mu : float
        Dynamic viscosity in Pa s (water at 20 C: 1.0e-3).
    pressure_drop : float
        ``p_in - p_out`` in Pa (>= 0; 0 only with a wall velocity).
    p_out : float
        Outlet pressure in Pa (the leak rate depends only on the drop).
    periodic : bool
        Periodic side walls; no-flux walls otherwise.
    wall_velocity : (float, float)
        Sliding velocity of one wall in m/s (Couette term).
    h_min : float
        Optional minimum gap (m); 0 by default (a positive value biases the flux).
    scheme : {"fv", "fe"}
        Cell-centred finite volumes (default) or the Q1 finite-element cross-check.
    petsc_options : mapping, optional
        Overrides of :data:`roughfe.fem.petsc_tools.CG_AMG`.

    Returns
    -------
    ReynoldsResult
    """
    dp = float(pressure_drop)
    if not (np.isfinite(dp) and dp >= 0):
        raise InputError(f"pressure_drop must be finite and >= 0 (Pa), got {pressure_drop!r}")
    if scheme not in SCHEMES:
        raise InputError(f"scheme must be one of {SCHEMES}, got {scheme!r}")
    # the gap as given is checked before the h_min clip (a negative, interpenetrating
    # gap became a conducting film of h_min); a masked or complex gap is refused
    g, _, _, u = check_reynolds_data(gap, spacing, mu, p_out + dp, p_out, direction,
                                     wall_velocity)
    if dp == 0 and not np.any(u != 0):
        raise InputError("pressure_drop is 0 and there is no wall velocity: nothing drives the flow")
    h_min = check_finite_nonnegative("h_min (m)", h_min)
    h = np.maximum(g, h_min) if h_min > 0 else g
    # without wall motion the flow is linear in the drop and in 1/mu: solved at a unit drop
    # and viscosity (the pressure a fraction of the drop) and scaled, so that no drop or
    # viscosity a float holds overflows or underflows inside the solve (--pressure-drop
    # 1e308: the dissipation dp^2 overflowed, Q and h_eff null; --mu 1e308: h_eff 0)
    unit = dp > 0 and not np.any(u != 0)
    mu_s, p_in_s, p_out_s = (1.0, 1.0, 0.0) if unit else (mu, p_out + dp, p_out)
    if scheme == "fv":
        sol = solve_reynolds_fv(h, spacing, direction=direction, mu=mu_s, p_in=p_in_s,
                                p_out=p_out_s, periodic=periodic, wall_velocity=wall_velocity,
                                petsc_options=petsc_options)
        leak, flux = sol.leak_rate, sol.flux
    else:
        sol = solve_reynolds_fe(h, spacing, direction=direction, mu=mu_s, p_in=p_in_s,
                                p_out=p_out_s, periodic=periodic, wall_velocity=wall_velocity,
                                petsc_options=petsc_options)
        leak = sol.flow_rate
        flux = cell_flux(sol.pressure_pinned, h, spacing, mu=mu_s, wall_velocity=wall_velocity)
    nx, ny = h.shape
    lengths = (nx * spacing[0], ny * spacing[1])
    axis = 0 if direction == "x" else 1
    flow_length, width = lengths[axis], lengths[1 - axis]
    aperture = (hydraulic_aperture(leak, mu=mu_s, pressure_drop=1.0 if unit else dp,
                                   flow_length=flow_length, width=width) if dp > 0 else None)
    pressure, q_in, q_out = sol.pressure, sol.inlet_flow, sol.outlet_flow
    if unit:                                    # refused when Q is beyond the floats
        pressure, leak, flux, q_in, q_out = from_unit_drop(p_out, dp, mu, pressure, leak,
                                                           flux, q_in, q_out)
    result = ReynoldsResult(
        direction=direction, scheme=scheme, leak_rate=float(leak), hydraulic_aperture=aperture,
        inlet_flow=float(q_in), outlet_flow=float(q_out), pressure=pressure,
        flux=flux, percolates=sol.percolates, pressure_drop=dp, mu=float(mu),
        flow_length=flow_length, width=width, success=sol.success, message=sol.message,
        nit=sol.nit)
    imbalance = result.flow_imbalance
    if imbalance is not None and imbalance > FLOW_IMBALANCE_TOL:
        dissipation = not np.any(u != 0)          # both schemes
        warnings.warn(FlowImbalanceWarning(
            f"Reynolds flow along {direction} ({scheme}): inlet flow {result.inlet_flow:.3e} "
            f"and outlet flow {result.outlet_flow:.3e} m^3/s differ by {imbalance:.1e} of "
            f"the leak rate {leak:.3e} m^3/s (> {FLOW_IMBALANCE_TOL:g}): an open reservoir "
            "at the inlet or outlet conducts far more than the path through the contact "
            "(near the percolation threshold, or gaps orders of magnitude apart), so the "
            "pressure drop across its boundary faces is at the linear solver's tolerance "
            "or the round-off of the drop; "
            + ("the leak rate is the viscous dissipation and keeps the solver tolerance, "
               "the boundary flows and the flux there do not" if dissipation else
               "the leak rate is uncertain by about that fraction")), stacklevel=2)
    return result
