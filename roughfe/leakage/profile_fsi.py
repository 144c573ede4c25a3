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
follow. An iterate whose gap closes is refused, and the Anderson loop tries damped steps
towards it (:mod:`roughfe.optim.anderson`). If every one of them closes too, the closed
state is reported only when it is self-consistent: the body under that state's own fluid
pressure (``p_in`` before the first closed sample, ``p_out`` after the last, their mean
between) closes the channel again. Then the result has ``state = "closed"``,
``leak_rate = 0`` and that body solution, without a converged fluid pressure; otherwise
NoConvergenceError (neither state holds). A one-way state that is closed is checked the
same way and, if its own pressure opens the channel, the iteration starts from that
pressure. Lift-off (load control) likewise. Until round 2, session 24 one refused full
step gave "closed": the reversed wavy channel of ``validation/fsi_fem.py`` at
``Delta = -2 um`` read ``q = 0`` where it is open (throat 0.85 um, q = -5.7e-6 m^2/s).

Two controls
------------
* ``approach=Delta`` (position control). With zero mean elastic displacement the
  (trapezoidal) mean gap of an open channel is then ``max h - mean h - Delta`` for both
  bodies: a check of the mean-level convention (exact to round-off), not of the
  elasticity. The leak rate, the throat (minimum) gap and the displacement field test it.
* ``external_pressure=p_ext`` (load control, issue 12: total load / nominal length, carried
  by contact and fluid together). Before closure the contact carries nothing, so the fluid
  alone balances the load: ``mean(p_f) = p_ext`` (a hydrostatic film). With the contact
  inactive the gap is ``s - Delta`` with the shape ``s = max h - h + u[p_f]``; every
  evaluation of ``G`` solves the scalar balance for ``Delta`` exactly (Brent's method on the
  open range ``Delta < min s``) before the Reynolds solve, so the mean gap is an output.
  The mean fluid pressure of an open channel lies between ``(p_in + p_out)/2`` (wide open:
  linear pressure) and its value at closure (the pressure on the throat's far side); a
  ``p_ext`` above that range needs contact: ``state = "closed"``; below it the fluid lifts
  the body off: ``state = "lift-off"`` (no equilibrium: ``leak_rate`` and the gaps None),
  both reported only when self-consistent (above).
  If the mean pressure is not monotone in ``Delta`` the balance takes one of its roots.
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

STATES = ("open", "closed", "lift-off")

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
    state : {"open", "closed", "lift-off"}
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
        Half-plane approach Delta (m; negative: clearance) of ``gap``, so that ``gap =
        max h - h - approach + displacement`` where open; solved for under load control,
        where a ``"closed"`` state is the channel at closure (its approach a lower bound:
        the contact that would carry the rest of the load is not solved) and a
        ``"lift-off"`` state the trial channel of no equilibrium.
    external_pressure : float or None
        ``p_ext`` (Pa) under load control, None under position control.
    inlet_pressure, outlet_pressure, mu : float
    leak_rate : float or None
        Coupled flux per unit width (m^2/s); 0 when closed, None at lift-off.
    one_way_leak_rate : float or None
        Flux of the one-way state (no fluid load on the body; under load control the rigid
        channel balanced by its own fluid pressure).
    mean_gap, min_gap : float or None
        Trapezoidal mean and minimum of the gap (m); None at lift-off.
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
    external_pressure: Optional[float]
    inlet_pressure: float
    outlet_pressure: float
    mu: float
    leak_rate: Optional[float]
    one_way_leak_rate: Optional[float]
    mean_gap: Optional[float]
    min_gap: Optional[float]
    mean_fluid_pressure: float
    iterations: int
    residual: float
    residual_history: tuple
    contact: object
    references: tuple = field(default=REFERENCES)

    def record(self) -> dict:
        """JSON-safe scalars."""
        return {"method": self.method, "state": self.state, "approach": self.approach,
                "external_pressure": self.external_pressure,
                "inlet_pressure": self.inlet_pressure, "outlet_pressure": self.outlet_pressure,
                "leak_rate": self.leak_rate, "leak_rate_one_way": self.one_way_leak_rate,
                "mean_gap": self.mean_gap, "min_gap": self.min_gap,
                "mean_fluid_pressure": self.mean_fluid_pressure,
                "coupled_iterations": self.iterations, "coupled_residual": self.residual}


class _Closed(RejectedIterate):
    """The gap of an iterate closes the channel."""


class _LiftOff(RejectedIterate):
    """The fluid of an open channel carries more than the external load."""


def _balance(shape, dx, p_ext, **flow) -> float:
    """The approach Delta (m) at which the open channel ``shape - Delta`` carries
    ``p_ext`` by its mean fluid pressure (module docstring); _Closed / _LiftOff outside the
    open range."""
    from scipy.optimize import brentq

    top = float(shape.min())
    scale = float(np.ptp(shape)) or abs(top) or 1.0

    def excess(d):
        return channel_flow(shape - d, dx, **flow).mean_pressure - p_ext

    hi, lo = top - 1e-9 * scale, top - 1e3 * scale
    e_hi, e_lo = excess(hi), excess(lo)
    if e_hi > 0 and e_lo > 0:
        raise _LiftOff()
    if e_hi < 0 and e_lo < 0:
        raise _Closed()
    return float(brentq(excess, lo, hi, xtol=1e-15 * scale, maxiter=200))


class MirroredHalfPlane:
    """The BEM body of the channel: the periodic half-plane below the evenly mirrored
    profile (module docstring). Same ``solve``/``close`` as
    :class:`roughfe.fem.fluid.FluidLoadedBody`.
    """

    def __init__(self, profile: Surface, material: Material):
        from ..fem.mesh import mirrored_profile

        self.profile, self.material = profile, material
        self.mirror = mirrored_profile(profile)

    def close(self):
        """Nothing to free (the operators are cached by :mod:`roughfe.bem.contact`)."""

    def _mirror(self, values):
        return np.concatenate([values, values[-2:0:-1]])

    def solve(self, pressure, approach: float):
        """Contact of the half-plane under the fluid ``pressure`` (Pa, nodal) at the
        approach ``approach`` (m): a :class:`HalfPlaneState` of the mirrored profile (its
        first ``n`` samples are the channel's)."""
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


def coupled_channel(profile: Surface, material: Material, approach: Optional[float] = None,
                    *, external_pressure: Optional[float] = None,
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
    approach : float, optional
        Half-plane approach Delta (m) from first contact; negative: clearance.
    external_pressure : float, optional
        Or: the external mean pressure p_ext (Pa), carried by the fluid before closure
        (module docstring). Give exactly one of the two.
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
        The coupled residual did not reach ``tol``, or the iteration stopped at a closed
        (lift-off) state that its own fluid pressure does not keep closed (lifted off);
        ``result`` holds the last state.
    """
    check_instance("profile", profile, Surface, "a roughfe Surface")
    check_instance("material", material, Material, "a roughfe.model.Material")
    if profile.ndim != 1 or profile.heights.size < 3:
        raise InputError(f"the channel coupling needs a 1D profile of >= 3 samples, got a "
                         f"surface of shape {profile.shape}")
    if method not in METHODS:
        raise InputError(f"method must be one of {METHODS}, got {method!r}")
    if (approach is None) == (external_pressure is None):
        raise InputError("give exactly one of approach (the half-plane approach Delta, m) or "
                         "external_pressure (the external mean pressure, Pa)")
    if approach is not None and not np.isfinite(approach):
        raise InputError(f"approach must be finite (m), got {approach!r}")
    p_ext = None if external_pressure is None else check_finite_positive(
        "external pressure", external_pressure)
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
    flow_args = {"p_in": p_in, "p_out": p_out, "mu": mu}
    # the body is solved at the imposed approach, or (load control: the contact is inactive
    # before closure, so the shape of the gap does not depend on it) with a clearance below
    # the last balanced approach: the height range, doubled while the body still touches
    last = {"approach": 0.0 if approach is None else float(approach),
            "clearance": 0.0 if p_ext is None else float(np.ptp(profile.heights)) or 1e-6}

    def G(x):
        for _ in range(30):
            trial = last["approach"] - last["clearance"]
            c = body.solve(x, trial)
            contact = np.asarray(c.contact[:n])
            if p_ext is None or not contact.any():
                break
            last["clearance"] *= 2.0
        gap = np.where(contact, 0.0, np.maximum(c.gap[:n], 0.0))
        if p_ext is not None and not contact.any():
            shape = np.asarray(c.gap[:n]) + trial
            try:
                last["approach"] = _balance(shape, dx, p_ext, **flow_args)
            except RejectedIterate as exc:
                # no open balance: report the channel at closure (touching at its throat;
                # the contact that would carry the rest of the load is not solved) or, at
                # lift-off, the trial channel (no equilibrium)
                # `at`: the approach of the gap reported (it was the last balanced one, or
                # 0 before any: the closed channel's gap and approach disagreed, 0.29 um
                # on the 65-node wavy channel of tests/test_leakage_output_review.py)
                lifted = isinstance(exc, _LiftOff)
                gap = gap if lifted else shape - shape.min()
                last.update(body=c, gap=gap, flow=channel_flow(gap, dx, **flow_args),
                            state="lift-off" if lifted else "closed",
                            at=trial if lifted else float(shape.min()))
                raise
            gap = shape - last["approach"]
            trial = last["approach"]
        flow = channel_flow(gap, dx, **flow_args)
        last.update(body=c, gap=gap, flow=flow, state="closed" if flow.closed else "open",
                    at=trial)
        if flow.closed:
            raise _Closed()
        return flow.pressure

    def own_pressure(one_way, it, residual, residuals):
        """G at the fluid pressure of the last, refused evaluation (a closed channel or
        lift-off; the evaluation kept in ``last``): its value if accepted, None if refused
        into the same state (which is then self-consistent); NoConvergenceError if
        refused into the other one."""
        refused = last["state"]
        try:
            return G(last["flow"].pressure)
        except RejectedIterate:
            if last["state"] == refused:
                return None
            raise NoConvergenceError(
                f"channel fluid-structure coupling ({method}): a {refused} state gives "
                f"{last['state']} under its own fluid pressure",
                result=_result(method, last, p_ext, mu, one_way, it + 1, residual,
                               residuals)) from None

    with contextlib.closing(body):
        x = np.zeros(n)
        extra = 0
        try:
            gx = G(x)
            one_way = last["flow"].leak_rate
        except RejectedIterate:
            one_way = None if last["state"] == "lift-off" else last["flow"].leak_rate
            # the one-way state refused: the coupled one if its own fluid pressure keeps
            # it, else the iteration starts from that pressure
            x, extra = last["flow"].pressure, 1
            gx = own_pressure(one_way, 0, float("nan"), ())
            if gx is None:
                return _result(method, last, p_ext, mu, one_way, extra, float("nan"), ())
        fp = anderson_fixed_point(G, x, gx, tol=tol, max_iter=max_iter, memory=anderson,
                                  relaxation=relaxation)
        it = fp.iterations + extra
        if fp.status == "rejected":
            # every damped step from the last accepted iterate was refused: that state only
            # if its own fluid pressure gives it again (until round 2, session 24 a channel
            # was reported closed after one refused full step, where it is open)
            refused = last["state"]
            if own_pressure(one_way, it, fp.residual, fp.residuals) is not None:
                raise NoConvergenceError(
                    f"channel fluid-structure coupling ({method}): every damped step from "
                    f"the iterate at relative residual {fp.residual:.3e} is {refused}, but "
                    f"the {refused} state's own fluid pressure does not keep it {refused} "
                    f"(try a smaller relaxation)",
                    result=_result(method, last, p_ext, mu, one_way, it + 1, fp.residual,
                                   fp.residuals))
            it += 1
        out = _result(method, last, p_ext, mu, one_way, it, fp.residual, fp.residuals)
    if fp.status == "max_iter":
        raise NoConvergenceError(
            f"channel fluid-structure coupling ({method}): relative residual "
            f"{fp.residual:.3e} after {fp.iterations} iterations (tolerance {tol:.1e})",
            result=out)
    return out


def _result(method, last, p_ext, mu, one_way, it, res, residuals):
    """The result of the last evaluated iterate (the converged one when open)."""
    state, gap, c, flow = last["state"], last["gap"], last["body"], last["flow"]
    n = gap.size
    lifted = state == "lift-off"
    return ChannelCoupledResult(
        method=method, state=state, x=flow.x, gap=gap,
        displacement=np.asarray(c.displacement)[:n].copy(), fluid_pressure=flow.pressure,
        flow=flow, approach=float(last["at"]), external_pressure=p_ext,
        inlet_pressure=flow.inlet_pressure, outlet_pressure=flow.outlet_pressure, mu=mu,
        leak_rate=None if lifted else flow.leak_rate, one_way_leak_rate=one_way,
        mean_gap=None if lifted else trapezoid_mean(gap),
        min_gap=None if lifted else float(gap.min()),
        mean_fluid_pressure=flow.mean_pressure, iterations=int(it), residual=float(res),
        residual_history=tuple(residuals), contact=c)
