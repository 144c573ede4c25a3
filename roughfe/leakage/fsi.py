"""Two-way fluid-structure coupling of a rough contact and its leakage (issue 12; thesis
Ch. 5 names the fluid-structure interaction as future work).

Problem
-------
A rigid rough surface (heights ``h``) against an elastic half-space (BEM); a fluid at the
absolute pressures ``p_in`` (inlet side) and ``p_out`` (outlet side) fills the free
volume; the external mean pressure ``p_ext`` (total load / nominal area) is carried by
the solid contact and the fluid together. The fluid pressure ``p_f`` acts on the whole
nominal area (effective-stress principle: in a contact spot the pore pressure is the
limit of the surrounding film's, below) and the solid contact carries the effective
pressure ``p_c >= 0`` on top of it: the body's normal traction is ``p_c + p_f``, its
displacement ``u = H (p_c + p_f)``, and

* the gap is that of the **dry** contact of the heights ``h - H p_f`` (a known traction
  on a half-space is a shift of the heights; ``H`` from
  :func:`roughfe.bem.contact.surface_displacement`), solved under the mean contact
  pressure ``mean(p_c) = p_ext - mean(p_f)`` (the existing BEM solver,
  :func:`roughfe.bem.solve_contact`, warm-started);
* the fluid pressure is the Reynolds solution (Eq. 2.12, cell-centred finite volumes,
  :mod:`roughfe.leakage.finite_volume`, solved at a unit drop and viscosity and scaled:
  :func:`roughfe.leakage.reynolds.scaled_reynolds_fv`; the pressure does not depend on
  ``mu``, the leak rates are ``1/mu``) on the gap regularised by a film of
  ``h_reg`` (default ``1e-3`` times the rms height) in the contact cells, and the
  trapped-pocket pressure (below) in the pockets. The film conducts ``(h_reg/h)^3 ~ 1e-9``
  of an open cell: it leaves the open-film pressure unchanged to that order, defines the
  pressure inside contact spots as the limit of the surrounding film's (with the fluid on
  open cells only the exactness below fails: 0.5 % gap error, measured), and keeps the
  fluid load continuous in the gap (else cells that open and close jump the load by up to
  ``p_in/2`` and the fixed point cycles, measured). The leak rate is the unregularised
  FV solve on the final gap.

The unknown is the fluid-pressure field ``x`` (Pa per cell); ``G(x)`` is a contact solve
plus a Reynolds solve. ``x = G(x)`` is solved by Anderson acceleration
(:func:`roughfe.optim.anderson.anderson_fixed_point`) from the previous step's fluid
pressure (else 0) to ``||G(x) - x|| / max(||G(x)||, p_ext sqrt(N)) <= tol`` (default 1e-8;
N cells: a fluid pressure far below ``p_ext`` is resolved to ``tol p_ext``, the scale
the contact resolves); an extrapolated
iterate that would lift the body off is refused and damped steps towards it are tried
(:mod:`roughfe.optim.anderson`). The one-way leak rate is that of the dry contact at
``p_ext``.

Exactness. On a periodic surface with ``p_in = p_out = p_f`` (no flow) the coupled
contact is the dry contact at ``p_ext - p_f``, point by point, with the solid contact
pressure ``sigma_dry + p_f``: a uniform traction does not change the gap of a periodic
half-space, and that state satisfies every contact condition (uniqueness). Tested.

States. ``state = "contact"``; ``"lift-off"`` when the fluid alone would carry more than
``p_ext``: every damped step ``x + beta r / 2^j`` (``j <= 4``) from the last contact
state ``x`` has ``mean >= p_ext``, so its own fluid pressure ``G(x)`` carries more than
``p_ext`` (until round 2, session 24 one refused full step sufficed, on the first
iteration the same point twice; 28 cases of 32^2 near lift-off, measured: the same
states, lift-off now after 8-21 evaluations instead of 1-5): the surfaces separate, the
gap and leak rate are unbounded (reported as None), not an error. A coupling that does not
reach ``tol`` in ``max_iter`` iterations raises :class:`~roughfe.errors.NoConvergenceError`
naming the residual reached.

Trapped fluid
-------------
Pockets (:mod:`roughfe.leakage.pockets`): wet components (gap > ``h_reg``) reaching
neither inlet nor outlet. ``trapped`` selects their law:

* ``"volume"`` (default): a sealed pocket keeps its fluid: incompressible
  (``bulk_modulus=inf``, its volume is kept) or a liquid of bulk modulus ``K``
  (``P = P_c + K ln(V_c/V)``). The default because a pocket sealed by contact holds a
  fixed mass of liquid, and a liquid's volume hardly changes under the pressures of a
  contact (water: K = 2.2 GPa); keeping the pressure at closure instead lets the pocket be
  crushed at constant pressure, which only a gas near K -> 0 does.
* ``"pressure"``: the pocket keeps its pressure at closure (the ``K -> 0`` limit of an
  open pocket; a pocket squeezed shut keeps no fluid here, with any ``K > 0`` its
  pressure rises to the solid contact pressure that opens it).
* ``"film"`` (extra, not in the issue): drained pockets, the regularised film's pressure
  (a leaky seal; also the state in which a pocket closes).

Pocket pressures are unknowns (one per pocket): for ``"volume"`` each evaluation of
``G`` ends with a Newton step on them with the BEM pocket compliance
(:class:`roughfe.leakage.pockets.PocketNewton`); Anderson then treats pockets and film
alike, and at its fixed point the pocket volumes are exact.

The pocket cells are frozen during one fixed-point solve (a pass) so that ``G`` is a
continuous map; after the pass the pockets of the coupled gap are found again
(:func:`roughfe.leakage.pockets.transfer`: merge, split, reopening, new pockets closing
or cavities opening at this load), and the pass is repeated with them until the cells
no longer change (``pockets_settled``; membership rules: :mod:`roughfe.leakage.pockets`),
else they stop after ``max_passes`` or when a layout already solved in this step comes
back (a cycle).
Why round 2's first ``"pressure"`` model stalled in sweeps: docs/theory/04b_leakage_ii.md.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from ..errors import InputError, NoConvergenceError, check_finite_positive, check_int
from ..optim.anderson import RejectedIterate, anderson_fixed_point, check_options
from ..surfaces import Surface
from .channel import check_absolute_pressures
from .finite_volume import FVSolution, reynolds_fv_solver
from .pockets import SEALED, TRAPPED_MODELS, PocketNewton, Pockets, transfer
from .reynolds import scaled_reynolds_fv

REFERENCES = (
    "Anderson acceleration: Walker & Ni, SIAM J. Numer. Anal. 49 (2011) 1715",
    "Critical junction: Lorenz & Persson, EPL 86 (2009) 44006",
    "Reynolds leakage of rough contacts: Dapp & Muser, Sci. Rep. 6 (2016) 19513",
)


@dataclass(frozen=True, eq=False)
class FluidState:
    """Fluid state at the end of a load step: the reference of the next step.

    Attributes
    ----------
    pressure : ndarray
        Fluid pressure per cell (Pa).
    pockets : Pockets
        Sealed pockets and their fluid (:class:`roughfe.leakage.pockets.Pockets`).
    """

    pressure: np.ndarray
    pockets: Pockets


@dataclass(frozen=True, eq=False)
class CoupledResult:
    """One coupled (two-way) contact + Reynolds state.

    Attributes
    ----------
    state : {"contact", "lift-off"}
    contact : roughfe.model.ContactResult or None
        The final contact solve (of the shifted heights ``h - H p_f``): its ``gap`` and
        ``contact`` are the coupled ones, its ``pressure`` the *solid* contact pressure
        ``p_c`` on top of the fluid pressure (Pa); its ``delta``,
        ``mean_plane_separation`` and ``free_volume_star`` are those of the shifted
        heights (use :attr:`approach`). None at lift-off.
    approach : float or None
        Approach ``Delta`` of the rigid surface from first contact of the undeformed
        surfaces (m), the one-way contact's ``delta``: ``contact.delta - (max(h - H p_f)
        - max h)`` (periodic: ``max h - mean h - mean gap``, zero mean displacement).
        None at lift-off.
    flow : FVSolution or None
        Reynolds solution on the coupled gap (absolute pressures).
    fluid_pressure : ndarray
        Fluid pressure per cell (Pa): film Reynolds pressure and the pocket pressures; at
        lift-off the field of a wide uniform gap (linear from ``p_in`` to ``p_out``).
    external_pressure, inlet_pressure, outlet_pressure, mu : float
        ``p_ext``, ``p_in``, ``p_out`` (Pa), viscosity (Pa s).
    trapped, bulk_modulus : str, float
        Trapped-fluid model and the liquid's bulk modulus (Pa; inf: incompressible).
    leak_rate : float or None
        Coupled leak rate (m^3/s; negative for ``p_in < p_out``: reversed flow).
    one_way_leak_rate : float or None
        Leak rate of the one-way solution (dry contact at ``p_ext``).
    fluid_load_fraction : float
        ``mean(p_f) / p_ext``: share of the external load carried by the fluid (flowing
        and trapped) over the nominal area (at lift-off that of the open field).
    contact_load_fraction : float
        ``mean(p_c) / p_ext``: the solid's share (``contact + fluid = 1`` to the coupled
        residual).
    trapped_load_fraction : float
        Share carried by the pockets (part of ``fluid_load_fraction``).
    pocket_volume : float
        Fluid volume in the pockets (m^3; the network's ``trapped_volume`` of the same
        step is another quantity: the free volume of the components reaching no edge).
    pocket_pressures, pocket_volumes : tuple of float
        Pressure (Pa) and fluid volume (m^3) of each pocket, largest pocket first.
    pocket_labels : ndarray of int
        Per cell: ``k >= 1`` in the k-th pocket of ``pocket_pressures`` (largest first),
        0 elsewhere (all 0 at lift-off). With ``"film"`` the drained pockets that those
        lists report (the reference for the next step, ``fluid_state.pockets``, has none).
    pockets_new, pockets_released, pockets_merged, pocket_passes : int
        Pockets that hold no liquid of the previous state (sealed off from the flowing
        film in this step, or, on unloading, cavities opened in this step among contact
        spots: both start from their drained state), pockets reopened to inlet/outlet,
        merges (each summed over the passes); fixed-point solves with frozen pocket
        cells.
    pockets_settled : bool
        The pocket cells of the last pass are those of its solution.
    coupled_iterations : int
        Evaluations of ``G`` after the one-way solve (all passes).
    residual : float
        Final relative coupled residual.
    residual_history : tuple of float
    fluid_state : FluidState
        Reference for the next load step.
    """

    state: str
    contact: Optional[object]
    approach: Optional[float]
    flow: Optional[FVSolution]
    fluid_pressure: np.ndarray
    external_pressure: float
    inlet_pressure: float
    outlet_pressure: float
    mu: float
    trapped: str
    bulk_modulus: float
    leak_rate: Optional[float]
    one_way_leak_rate: Optional[float]
    fluid_load_fraction: float
    contact_load_fraction: float
    trapped_load_fraction: float
    pocket_volume: float
    pocket_pressures: tuple
    pocket_volumes: tuple
    pocket_labels: np.ndarray
    pockets_new: int
    pockets_released: int
    pockets_merged: int
    pocket_passes: int
    pockets_settled: bool
    coupled_iterations: int
    residual: float
    residual_history: tuple
    fluid_state: FluidState
    references: tuple = field(default=REFERENCES)

    def record(self) -> dict:
        """JSON-safe scalars of the coupled step (keys documented in
        docs/theory/04b_leakage_ii.md)."""
        return {"fsi_state": self.state, "external_pressure": self.external_pressure,
                "inlet_pressure": self.inlet_pressure, "outlet_pressure": self.outlet_pressure,
                "trapped_fluid": self.trapped, "bulk_modulus": self.bulk_modulus,
                "leak_rate_coupled": self.leak_rate, "leak_rate_one_way": self.one_way_leak_rate,
                "fluid_load_fraction": self.fluid_load_fraction,
                "contact_load_fraction": self.contact_load_fraction,
                "trapped_load_fraction": self.trapped_load_fraction,
                "pocket_volume": self.pocket_volume,
                "pocket_pressures": list(self.pocket_pressures),
                "pocket_volumes": list(self.pocket_volumes),
                "pockets_new": self.pockets_new, "pockets_released": self.pockets_released,
                "pockets_merged": self.pockets_merged, "pocket_passes": self.pocket_passes,
                "pockets_settled": self.pockets_settled,
                "coupled_iterations": self.coupled_iterations,
                "coupled_residual": self.residual}


class _LiftOff(RejectedIterate):
    """The fluid alone would carry the external load."""


def coupled_leakage(surface: Surface, material, external_pressure: float, *,
                    p_in: float, p_out: float, mu: float = 1e-3, direction: str = "x",
                    trapped: str = "volume", bulk_modulus: float = np.inf,
                    history: Optional[FluidState] = None, tol: float = 1e-8,
                    max_iter: int = 60, anderson: int = 5, relaxation: float = 1.0,
                    kernel: str = "auto", contact_tol: float = 1e-11,
                    h_reg: Optional[float] = None, max_passes: int = 8,
                    jacobian_pockets: int = 16) -> CoupledResult:
    """Two-way coupled contact and Reynolds flow at one external pressure (module docstring).

    Parameters
    ----------
    surface : Surface
        2D rough surface (heights in m).
    material : roughfe.model.Material
        Elastic body (Pa).
    external_pressure : float
        ``p_ext`` > 0 (Pa): total load / nominal area.
    p_in, p_out : float
        Absolute fluid pressures at the inlet (coordinate 0) and outlet (Pa, >= 0).
    mu : float
        Viscosity (Pa s).
    direction : {"x", "y"}
        Flow axis.
    trapped : {"volume", "pressure", "film"}
        Trapped-pocket model (:mod:`roughfe.leakage.pockets`).
    bulk_modulus : float
        Bulk modulus of the liquid (Pa) for ``"volume"``; inf (default): incompressible.
    history : FluidState, optional
        Reference state (previous load step); default: no pocket (first contact).
    tol : float
        Relative coupled residual to reach.
    max_iter : int
        Coupled iterations allowed per pass.
    anderson : int
        Anderson memory (0: plain fixed point).
    relaxation : float
        Mixing ``beta`` in (0, 1] of the Anderson/Picard update ``x + beta r``.
    kernel : str
        BEM kernel (:func:`roughfe.bem.solve_contact`).
    contact_tol : float
        Tolerance of each contact solve (below ``tol``).
    h_reg : float, optional
        Film in contact cells (m); default ``1e-3`` times the rms height.
    max_passes, jacobian_pockets : int
        Pocket passes allowed; pockets (largest first) with an exact BEM compliance.

    Returns
    -------
    CoupledResult

    Raises
    ------
    InputError
        Bad input (named).
    NoConvergenceError
        The coupled residual did not reach ``tol`` (``result``: the last state).
    """
    from ..bem import solve_contact
    from ..bem.contact import surface_displacement

    if not isinstance(surface, Surface) or surface.ndim != 2:
        raise InputError(f"coupled leakage needs a 2D Surface, got {surface!r}")
    p_ext = check_finite_positive("external pressure", external_pressure)
    p_in, p_out = check_absolute_pressures(p_in, p_out)
    if trapped not in TRAPPED_MODELS:
        raise InputError(f"trapped must be one of {TRAPPED_MODELS}, got {trapped!r}")
    if not (bulk_modulus > 0) or (trapped != "volume" and np.isfinite(bulk_modulus)):
        raise InputError(f"bulk modulus must be > 0 (Pa; inf: incompressible) and belongs to "
                         f"trapped='volume', got {bulk_modulus!r} with {trapped!r}")
    if direction not in ("x", "y"):
        raise InputError(f"direction must be 'x' or 'y', got {direction!r}")
    mu = check_finite_positive("mu", mu)
    tol, max_iter, anderson, relaxation = check_options(tol, max_iter, anderson, relaxation)
    max_passes = check_int("max_passes (pocket passes)", max_passes, 1)
    jacobian_pockets = check_int("jacobian_pockets", jacobian_pockets, 0)
    axis = 0 if direction == "x" else 1
    # the residual's scale: a fluid field at the external pressure. Relative to |G(x)|
    # alone, a fluid pressure far below p_ext (p_in -> 0: the dry contact) was asked for
    # digits the contact mechanics, which resolves pressures on the scale of p_ext, does
    # not carry (the volume model's pockets stalled at 1e-6 with p_in = 1 Pa)
    floor = p_ext * np.sqrt(surface.heights.size)
    spacing = surface.spacing
    cell = float(np.prod(spacing))
    h = surface.heights
    if history is not None and history.pressure.shape != h.shape:
        raise InputError(f"history has shape {history.pressure.shape}, the surface {h.shape}")
    frozen = (history.pockets if history is not None and trapped in SEALED
              else Pockets.none(h.shape))
    h_reg = check_finite_positive("h_reg", 1e-3 * float(np.std(h)) if h_reg is None else h_reg)
    last = {"contact": None, "flow": None, "fluid": None}   # fluid: start of the next FV solve

    def G(x, newton):
        """One contact solve and one Reynolds solve for the fluid traction x."""
        p_contact = p_ext - float(x.mean())
        if p_contact <= 0:
            raise _LiftOff()
        shifted = Surface(h - surface_displacement(surface, material, x, kernel),
                          surface.size, surface.periodic)
        # the approach of the shifted heights' contact is Delta + max(h - H p_f) - max h
        shift = float(shifted.heights.max() - h.max())
        c = solve_contact(shifted, material, mean_pressure=p_contact, kernel=kernel,
                          tol=contact_tol, compute_stiffness=False,
                          initial=last["contact"].pressure)
        gap = np.where(c.contact, 0.0, c.gap)
        last["fluid"] = y = scaled_reynolds_fv(
            np.maximum(gap, h_reg), spacing, direction=direction, mu=mu, p_in=p_in, p_out=p_out,
            periodic=surface.periodic, initial=last["fluid"], solver=krylov).pressure
        if frozen.n:
            lab = frozen.labels
            p_pocket = frozen.pressure if newton is None else newton(x, gap, c, p_ext)
            y = np.where(lab >= 0, p_pocket[np.maximum(lab, 0)], y)
        last.update(contact=c, gap=gap, shift=shift)
        return y

    def _flow(gap):
        return scaled_reynolds_fv(gap, spacing, direction=direction, mu=mu, p_in=p_in,
                                  p_out=p_out, periodic=surface.periodic, initial=last["fluid"])

    # one Reynolds solver for the loop: every cell is live, so it keeps its AMG hierarchy
    with reynolds_fv_solver() as krylov:
        # the one-way state (dry contact at p_ext); the iteration starts from the previous
        # step's fluid pressure (pocket pressures near their solution), else from 0
        dry = solve_contact(surface, material, mean_pressure=p_ext, kernel=kernel, tol=contact_tol,
                            compute_stiffness=False)
        last.update(contact=dry, shift=0.0)
        one_way = _flow(np.where(dry.contact, 0.0, dry.gap)).leak_rate
        x = (np.array(history.pressure, dtype=float) if history is not None
             and history.pressure.mean() < p_ext else np.zeros(h.shape))
        residuals, counts = [], {"new": 0, "released": 0, "merged": 0}
        it, passes, state, settled, solved = 0, 0, "contact", False, []
        while True:
            newton = (PocketNewton(frozen, bulk_modulus, cell, material.E_star, jacobian_pockets)
                      if trapped == "volume" and frozen.n else None)
            try:
                gx = G(x, newton)
            except _LiftOff:
                state = "lift-off"
                break
            fp = anderson_fixed_point(lambda v: G(v, newton), x, gx, tol=tol, max_iter=max_iter,
                                      memory=anderson, relaxation=relaxation, floor=floor)
            it += fp.iterations
            residuals += fp.residuals
            x, gx = fp.x, fp.gx
            if fp.status == "max_iter":
                last["flow"] = _flow(last["gap"])
                last["next"], last["report"] = None, frozen
                partial = _result("contact", last, gx, p_ext, p_in, p_out, mu, one_way, it,
                                  fp.residual, residuals, cell, trapped, bulk_modulus, counts,
                                  passes + 1, False)
                raise NoConvergenceError(
                    f"fluid-structure coupling: relative residual {fp.residual:.3e} after "
                    f"{fp.iterations} iterations of pocket pass {passes + 1} (tolerance "
                    f"{tol:.1e}, Anderson memory {anderson})", result=partial)
            if fp.status == "rejected":
                state = "lift-off"
                break
            nxt, cnt = transfer(frozen, last["gap"], gx, cell, h_reg, axis=axis,
                                periodic=surface.periodic,
                                bulk_modulus=bulk_modulus if trapped == "volume" else 0.0)
            passes += 1
            for key in counts:
                counts[key] += cnt[key]
            settled = trapped not in SEALED or nxt.same_cells(frozen)
            # a layout already solved in this step would repeat its pass: a cycle, stop
            cycle = not settled and any(nxt.same_cells(s) for s in solved)
            if settled or cycle or passes >= max_passes:
                break
            solved.append(frozen)
            frozen, x = nxt, gx
        if state == "contact":
            last["flow"] = _flow(last["gap"])
            last["next"] = nxt if trapped in SEALED else Pockets.none(h.shape)
            last["report"] = frozen if trapped in SEALED else nxt
        return _result(state, last, gx if state == "contact" else x, p_ext, p_in, p_out, mu,
                       one_way, it, residuals[-1] if residuals else float("nan"), residuals, cell,
                       trapped, bulk_modulus, counts, passes, settled, axis)


def _result(state, last, fluid, p_ext, p_in, p_out, mu, one_way, it, res, residuals, cell,
            trapped, bulk_modulus, counts, passes, settled, axis=0):
    common = dict(external_pressure=p_ext, inlet_pressure=p_in, outlet_pressure=p_out, mu=mu,
                  trapped=trapped, bulk_modulus=float(bulk_modulus), one_way_leak_rate=one_way,
                  **{f"pockets_{key}": n for key, n in counts.items()}, pocket_passes=passes,
                  pockets_settled=bool(settled), coupled_iterations=it,
                  residual=res, residual_history=tuple(residuals))
    if state == "lift-off":
        # the surfaces apart: the Reynolds field of a wide, uniform gap, linear from p_in
        # to p_out along the flow (it was max(p_in, p_out) everywhere beside a fluid load
        # fraction of 1, a field whose mean was not the load it reported)
        n = fluid.shape[axis]
        ramp = p_in + (p_out - p_in) * (np.arange(n) + 0.5) / n
        p_f = np.broadcast_to(ramp.reshape([-1 if a == axis else 1 for a in range(fluid.ndim)]),
                              fluid.shape).copy()
        return CoupledResult(
            state=state, contact=None, approach=None, flow=None, fluid_pressure=p_f,
            leak_rate=None,
            fluid_load_fraction=float(p_f.mean() / p_ext), contact_load_fraction=0.0,
            trapped_load_fraction=0.0,
            pocket_volume=0.0, pocket_pressures=(), pocket_volumes=(),
            pocket_labels=np.zeros(p_f.shape, dtype=np.int32),
            fluid_state=FluidState(pressure=p_f, pockets=Pockets.none(p_f.shape)), **common)
    c, sol = last["contact"], last["flow"]
    gap = np.where(c.contact, 0.0, c.gap)
    report = last.get("report")
    lab = report.labels if report is not None else np.full(gap.shape, -1)
    n = report.n if report is not None else 0
    in_pocket = lab >= 0
    pocket_p, pocket_v = [], []
    numbered = np.zeros(gap.shape, dtype=np.int32)    # 1.. in the order of the lists
    if n:
        area = np.bincount(lab[in_pocket], minlength=n)
        order = np.argsort(-area, kind="stable")
        pocket_p = (np.bincount(lab[in_pocket], fluid[in_pocket], n) / area)[order]
        pocket_v = (np.bincount(lab[in_pocket], gap[in_pocket], n) * cell)[order]
        rank = np.empty(n, dtype=np.int32)
        rank[order] = np.arange(1, n + 1, dtype=np.int32)
        numbered[in_pocket] = rank[lab[in_pocket]]
    nxt = last.get("next")
    return CoupledResult(
        state=state, contact=c, approach=float(c.delta - last["shift"]), flow=sol,
        fluid_pressure=fluid, leak_rate=sol.leak_rate,
        fluid_load_fraction=float(fluid.mean() / p_ext),
        contact_load_fraction=float(c.pressure.mean() / p_ext),
        trapped_load_fraction=float(fluid[in_pocket].sum() / fluid.size / p_ext),
        pocket_volume=float(gap[in_pocket].sum() * cell),
        pocket_pressures=tuple(float(v) for v in pocket_p),
        pocket_volumes=tuple(float(v) for v in pocket_v), pocket_labels=numbered,
        fluid_state=FluidState(pressure=fluid,
                               pockets=nxt if nxt is not None else Pockets.none(gap.shape)),
        **common)
