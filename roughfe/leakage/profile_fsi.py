"""Two-way fluid-structure coupling along a 1D channel: a profile against an elastic body,
BEM or FEM (issue 12 Sec. 5; thesis Ch. 5 names the fluid-structure interaction as future
work).

Problem
-------
A rigid profile ``h(x)`` (samples ``x_i = i dx``, ``0 <= x <= W = (n-1) dx``) faces a
plane-strain elastic body; fluid enters the channel between them at ``x = 0`` at the
absolute pressure ``p_in`` and leaves at ``x = W`` at ``p_out``. The fluid pressure
``p_f(x)`` loads the body, whose deformation ``u`` (m, away from the profile) changes the
gap

    g = max h - h - Delta + u[p_f + p_c],      p_c >= 0, g >= 0, p_c g = 0   (Eq. 2.5)

and ``p_f`` is the 1D Reynolds solution on ``g`` (:func:`roughfe.leakage.channel.channel_flow`,
exact for the piecewise-linear gap). ``Delta`` is the half-plane approach from first
contact of the undeformed surfaces (m): negative values are a clearance. The unknown is
the nodal fluid pressure; ``x = G(x)`` (one body solve + one Reynolds solve) is found by
the Anderson loop shared with the surface coupling
(:func:`roughfe.optim.anderson.anderson_fixed_point`), from the one-way state (``x = 0``)
to a relative residual ``tol`` (default 1e-8).

Two bodies with the same boundary-value problem (the FEM body's reference problem, see
docs/theory/03_fem_validation.md):

* ``method="bem"``: the periodic plane-strain half-plane (spectral kernel,
  :func:`roughfe.bem.contact.surface_displacement`, contact by
  :func:`roughfe.bem.solve_contact`) on the evenly mirrored profile (period 2W); the
  rollers of the FEM body are its symmetry planes and the mirrored fluid pressure is the
  even extension of ``p_f``. Zero mean displacement by convention. The non-periodic
  strip kernel is *not* this problem (a half-plane loaded on ``[0, W]`` only, whose
  displacement is defined up to a constant), so it is not used as the reference.
* ``method="fem"``: :class:`roughfe.fem.fluid.FluidLoadedBody` (dolfinx, the pressure as
  a Neumann traction on the top facets, contact by the SNES VI), ``Delta`` imposed as the
  half-plane approach (layer compliance removed with the total mean traction), so its
  trapezoidal mean displacement is zero too.

Before closure (``min g > 0``) the contact is inactive and the state is ``"open"``. In 1D
any contact closes the channel (no contact islands can be by-passed): the leak rate is
then 0 and the pocket pressures depend on the trapped fluid, which this 1D model does not
follow. An iterate whose gap closes is refused (the plain iterate is tried); if that
closes too the result has ``state = "closed"``, ``leak_rate = 0`` and the last body
solution, without a converged fluid pressure.

Mean gap. With ``Delta`` imposed and zero mean elastic displacement, the (trapezoidal)
mean gap of an open channel is ``max h - mean h - Delta`` for both bodies: a check of the
mean-level convention (exact to round-off), not of the elasticity. The leak rate, the
throat (minimum) gap and the displacement field test the elasticity.
"""
from __future__ import annotations

import contextlib
from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from ..errors import InputError, NoConvergenceError, check_finite_positive, check_instance
from ..model import Material
from ..optim.anderson import REFERENCES as ANDERSON_REFERENCES
from ..optim.anderson import RejectedIterate, anderson_fixed_point, check_options
from ..surfaces import Surface
from .channel import ChannelFlow, channel_flow, check_absolute_pressures, trapezoid_mean

METHODS = ("bem", "fem")
REFERENCES = ANDERSON_REFERENCES + (
    "Reynolds flow in a 1D channel: Hamrock B.J. et al. (2004) Fundamentals of Fluid Film "
    "Lubrication, Ch. 7",)


@dataclass(frozen=True, eq=False)
class ChannelCoupledResult:
    """A coupled (two-way) state of a 1D channel (module docstring).

    Attributes
    ----------
    method : {"bem", "fem"}
    state : {"open", "closed"}
    x : ndarray (n,)
        Sample positions (m).
    gap : ndarray (n,)
        Coupled gap (m).
    displacement : ndarray (n,)
        Elastic displacement of the body's top (m, away from the profile; zero
        trapezoidal mean).
    fluid_pressure : ndarray (n,)
        Absolute fluid pressure (Pa).
    flow : ChannelFlow
        Reynolds solution on the coupled gap.
    approach : float
        Half-plane approach Delta (m; negative: clearance).
    inlet_pressure, outlet_pressure, mu : float
    leak_rate : float
        Coupled flux per unit width (m^2/s); 0 when closed.
    one_way_leak_rate : float
        Flux of the one-way state (no fluid load on the body).
    mean_gap, min_gap : float
        Trapezoidal mean and minimum of the gap (m).
    mean_fluid_pressure : float
        Trapezoidal mean fluid pressure (Pa).
    iterations : int
        Coupled iterations (body + Reynolds solves after the one-way one).
    residual : float
        Final relative coupled residual.
    residual_history : tuple of float
    contact : object
        The last body solve: :class:`HalfPlaneState` (BEM) or
        :class:`~roughfe.model.ContactResult` (FEM; its ``pressure`` is the solid contact
        pressure).
    """

    method: str
    state: str
    x: np.ndarray
    gap: np.ndarray
    displacement: np.ndarray
    fluid_pressure: np.ndarray
    flow: ChannelFlow
    approach: float
    inlet_pressure: float
    outlet_pressure: float
    mu: float
    leak_rate: float
    one_way_leak_rate: float
    mean_gap: float
    min_gap: float
    mean_fluid_pressure: float
    iterations: int
    residual: float
    residual_history: tuple
    contact: object
    references: tuple = field(default=REFERENCES)

    def record(self) -> dict:
        """JSON-safe scalars."""
        return {"method": self.method, "state": self.state, "approach": self.approach,
                "inlet_pressure": self.inlet_pressure, "outlet_pressure": self.outlet_pressure,
                "leak_rate": self.leak_rate, "leak_rate_one_way": self.one_way_leak_rate,
                "mean_gap": self.mean_gap, "min_gap": self.min_gap,
                "mean_fluid_pressure": self.mean_fluid_pressure,
                "coupled_iterations": self.iterations, "coupled_residual": self.residual}


class _Closed(RejectedIterate):
    """The gap of an iterate closes the channel."""


class MirroredHalfPlane:
    """The BEM body of the channel: the periodic half-plane below the evenly mirrored
    profile (module docstring). Same ``solve``/``close`` as
    :class:`roughfe.fem.fluid.FluidLoadedBody`.
    """

    def __init__(self, profile: Surface, material: Material):
        from ..fem.mesh import mirrored_profile

        self.profile, self.material = profile, material
        self.mirror = mirrored_profile(profile)
        self.n = profile.heights.size

    def close(self):
        """Nothing to free (the operators are cached by :mod:`roughfe.bem.contact`)."""

    def _mirror(self, values):
        return np.concatenate([values, values[-2:0:-1]])

    def solve(self, pressure, approach: float):
        """Contact of the half-plane under the fluid ``pressure`` (Pa, nodal) at the
        approach ``approach`` (m); a :class:`~roughfe.model.ContactResult` of the mirrored
        profile (its first ``n`` samples are the channel's)."""
        from ..bem import solve_contact
        from ..bem.contact import surface_displacement

        h = self.mirror.heights
        u_f = surface_displacement(self.mirror, self.material, self._mirror(pressure),
                                   "spectral")
        shifted = Surface(h - u_f, self.mirror.size, periodic=True)
        # the dry contact of the heights h - H p_f; its approach Delta' = Delta + max(h -
        # H p_f) - max h (the gap u_c + max h - h + H p_f - Delta is unchanged)
        d_shift = float(approach) + float(shifted.heights.max()) - float(h.max())
        if d_shift <= 0:          # open: no contact, the gap is the fluid's deformation
            gap = float(h.max()) - h - float(approach) + u_f
            return HalfPlaneState(u_f, gap, np.zeros(h.shape, bool), None)
        c = solve_contact(shifted, self.material, delta=d_shift, kernel="spectral",
                          compute_stiffness=False)
        return HalfPlaneState(u_f + c.displacement, c.gap, c.contact, c)


@dataclass(frozen=True, eq=False)
class HalfPlaneState:
    """State of :class:`MirroredHalfPlane` (mirrored samples): total displacement (fluid
    + contact, m), gap (m), contact mask and the dry contact solve of the shifted heights
    (:class:`~roughfe.model.ContactResult`, None when open)."""

    displacement: np.ndarray
    gap: np.ndarray
    contact: np.ndarray
    contact_result: object


def coupled_channel(profile: Surface, material: Material, approach: float, *,
                    p_in: float, p_out: float, mu: float = 1e-3, method: str = "bem",
                    growth: float = 0.05, depth: Optional[float] = None, fem_options=None,
                    tol: float = 1e-8, max_iter: int = 60, anderson: int = 5,
                    relaxation: float = 1.0) -> ChannelCoupledResult:
    """Two-way coupled 1D channel flow and elastic deformation (module docstring).

    Parameters
    ----------
    profile : Surface
        1D profile, heights (m), sampled at ``x_i = i dx`` (its ``spacing``).
    material : roughfe.model.Material
        Elastic body (Pa); the profile is rigid.
    approach : float
        Half-plane approach Delta (m) from first contact; negative: clearance.
    p_in, p_out : float
        Absolute fluid pressures at ``x = 0`` and ``x = W`` (Pa, >= 0).
    mu : float
        Viscosity (Pa s).
    method : {"bem", "fem"}
        Elastic body: mirrored periodic half-plane (BEM) or dolfinx body (FEM).
    growth, depth : float
        FEM mesh: element-size growth with depth and body depth (m; default 2 W), see
        :func:`roughfe.fem.mesh_profile`.
    fem_options : roughfe.fem.FemSolverOptions, optional
    tol, max_iter, anderson, relaxation
        Coupled residual, iteration limit, Anderson memory and mixing
        (:func:`roughfe.optim.anderson.anderson_fixed_point`).

    Returns
    -------
    ChannelCoupledResult

    Raises
    ------
    InputError
        Bad input (named).
    NoConvergenceError
        The coupled residual did not reach ``tol``; ``result`` holds the last state.
    """
    check_instance("profile", profile, Surface, "a roughfe Surface")
    check_instance("material", material, Material, "a roughfe.model.Material")
    if profile.ndim != 1 or profile.heights.size < 3:
        raise InputError(f"the channel coupling needs a 1D profile of >= 3 samples, got a "
                         f"surface of shape {profile.shape}")
    if method not in METHODS:
        raise InputError(f"method must be one of {METHODS}, got {method!r}")
    if not np.isfinite(approach):
        raise InputError(f"approach must be finite (m), got {approach!r}")
    p_in, p_out = check_absolute_pressures(p_in, p_out)
    mu = check_finite_positive("mu", mu)
    tol, max_iter, anderson, relaxation = check_options(tol, max_iter, anderson, relaxation)
    n = profile.heights.size
    dx = profile.spacing[0]
    if method == "bem":
        body = MirroredHalfPlane(profile, material)
    else:
        from ..fem import mesh_profile
        from ..fem.fluid import FluidLoadedBody

        pmesh = mesh_profile(profile, growth=growth, depth=depth)
        body = FluidLoadedBody(pmesh, material, fem_options)
    last = {}

    def G(x):
        c = body.solve(x, approach)
        gap = np.where(c.contact[:n], 0.0, np.maximum(c.gap[:n], 0.0))
        flow = channel_flow(gap, dx, p_in=p_in, p_out=p_out, mu=mu)
        last.update(body=c, gap=gap, flow=flow)
        if flow.closed:
            raise _Closed()
        return flow.pressure

    with contextlib.closing(body):
        x = np.zeros(n)
        try:
            gx = G(x)
        except _Closed:
            return _result(method, "closed", last, approach, mu, 0.0, 0, float("nan"), ())
        one_way = last["flow"].leak_rate
        fp = anderson_fixed_point(G, x, gx, tol=tol, max_iter=max_iter, memory=anderson,
                                  relaxation=relaxation)
        if fp.status == "rejected":
            return _result(method, "closed", last, approach, mu, one_way, fp.iterations,
                           fp.residual, fp.residuals)
        out = _result(method, "open", last, approach, mu, one_way, fp.iterations,
                      fp.residual, fp.residuals)
    if fp.status == "max_iter":
        raise NoConvergenceError(
            f"channel fluid-structure coupling ({method}): relative residual "
            f"{fp.residual:.3e} after {fp.iterations} iterations (tolerance {tol:.1e})",
            result=out)
    return out


def _result(method, state, last, approach, mu, one_way, it, res, residuals):
    flow, gap, c = last["flow"], last["gap"], last["body"]
    n = gap.size
    return ChannelCoupledResult(
        method=method, state=state, x=flow.x, gap=gap,
        displacement=np.asarray(c.displacement)[:n].copy(), fluid_pressure=flow.pressure,
        flow=flow, approach=float(approach), inlet_pressure=flow.inlet_pressure,
        outlet_pressure=flow.outlet_pressure, mu=mu, leak_rate=flow.leak_rate,
        one_way_leak_rate=one_way, mean_gap=trapezoid_mean(gap), min_gap=float(gap.min()),
        mean_fluid_pressure=flow.mean_pressure, iterations=int(it), residual=float(res),
        residual_history=tuple(residuals), contact=c)
