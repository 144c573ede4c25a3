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
  :mod:`roughfe.leakage.finite_volume`) on the gap regularised by a film of
  ``h_reg`` (default ``1e-3`` times the rms height) in the contact cells, and the
  trapped-pocket pressure (below) in the pockets. The regularised film conducts
  ``(h_reg/h)^3 ~ 1e-9`` of a typical open cell: it leaves the open-film pressure
  unchanged to that order, defines the pressure inside contact spots as the limit of the
  surrounding film's, and makes the fluid load a continuous function of the gap (with
  the fluid acting on open cells only, or with an extension of the open-cell pressure
  into the spots, cells that open and close jump the load by up to half of ``p_in`` and
  the fixed point cycles: measured on 32^2 and 64^2 surfaces). The leak rate is the
  unregularised FV solve on the final gap.

Why the pressure acts under contact spots: with the fluid pressure on the open cells
only and the solid stress ``>= 0`` on contact cells, a contact spot may carry less than
the fluid around it (which would invade it), and the uniform-pressure exactness below
fails (measured: 0.5 % gap error, different contact sets).

The unknown is the fluid-pressure field ``x`` (Pa, one value per cell); one evaluation
``G(x)`` is a contact solve plus a Reynolds solve. The fixed point ``x = G(x)`` is found
with Anderson acceleration (type II, memory ``anderson``; Walker & Ni 2011), starting
from the one-way solution (``x = 0``: dry contact at ``p_ext``, then Reynolds); the
coupled residual is ``||G(x) - x|| / ||G(x)||`` (2-norms), required ``<= tol`` (default
1e-8). An extrapolated iterate that would lift the body off is replaced by the plain
iterate (memory cleared).

Exactness. On a periodic surface with ``p_in = p_out = p_f`` (no flow) the coupled
contact is the dry contact at ``p_ext - p_f``, point by point, with the solid contact
pressure ``sigma_dry + p_f``: a uniform traction does not change the gap of a periodic
half-space, and that state satisfies every contact condition (uniqueness). Tested.

States. ``state = "contact"``; ``"lift-off"`` when the fluid alone would carry more than
``p_ext`` (``mean(p_f) >= p_ext`` at a plain iterate): the surfaces separate, the gap
and leak rate are unbounded (reported as None), not an error. A coupling that does not
reach ``tol`` in ``max_iter`` iterations raises :class:`~roughfe.errors.NoConvergenceError`
naming the residual reached.

Trapped fluid
-------------
Pockets are open cells whose face-connected component reaches neither inlet nor outlet
(cells open by less than ``h_reg`` count as closed here).

* ``trapped="film"`` (default): a pocket's pressure is the regularised film's, the limit
  of its surroundings (a drained pocket); the fluid load is then a continuous function of
  the gap and the fixed point converges robustly (load sweeps on 32^2-64^2 surfaces in
  5-17 iterations).
Their fluid was trapped when they closed; the **reference state** (``history``) holds the
per-cell fluid pressure and fluid volume of the previous load step (for the first step:
the first-contact state, gap ``max h - h``, with its Reynolds pressure). Per pocket:

* ``trapped="pressure"``: the pocket keeps its pressure at closure: the volume-weighted
  mean over its cells of the incoming iterate's fluid pressure (the reference state's at
  the first evaluation). The coupled iteration is then a pseudo-time loading path from
  the one-way state: a pocket that closes during the iteration keeps the pressure it had
  when it closed, and the fluid pressure stays a continuous function of the iterate
  (with the previous step's pressure instead, a closing pocket jumps between two
  pressures and the fixed point cycles: measured on a 64^2 surface);
* ``trapped="volume"`` (the pocket keeps its fluid mass, incompressible or with a bulk
  modulus) is NOT implemented: a first version (pocket pressure as an unknown updated with
  the compliance of a pressurised penny, Anderson-accelerated) diverged on a 32^2 load
  sweep (residual 1.6 after 60 iterations), see docs/theory/leakage.md.

Per step: trapped volume, pocket pressures, the load carried by trapped fluid.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from ..errors import InputError, NoConvergenceError, check_finite_positive
from ..optim.anderson import RejectedIterate, anderson_fixed_point, check_options
from ..surfaces import Surface
from .channel import check_absolute_pressures
from .finite_volume import FVSolution, components_reaching, solve_reynolds_fv

TRAPPED_MODELS = ("film", "pressure")
REFERENCES = (
    "Anderson acceleration: Walker & Ni, SIAM J. Numer. Anal. 49 (2011) 1715",
    "Critical junction: Lorenz & Persson, EPL 86 (2009) 44006",
    "Reynolds leakage of rough contacts: Dapp & Muser, Sci. Rep. 6 (2016) 19513",
)


@dataclass(frozen=True, eq=False)
class FluidState:
    """Per-cell fluid pressure (Pa) of a load step: the reference of the trapped-fluid
    model for the next step."""

    pressure: np.ndarray


@dataclass(frozen=True, eq=False)
class CoupledResult:
    """One coupled (two-way) contact + Reynolds state.

    Attributes
    ----------
    state : {"contact", "lift-off"}
    contact : roughfe.model.ContactResult or None
        The final contact solve (of the shifted heights): its ``gap`` and ``contact`` are
        the coupled ones, its ``pressure`` the *solid* contact pressure ``p_c`` on top of the fluid pressure (Pa). None
        at lift-off.
    flow : FVSolution or None
        Reynolds solution on the coupled gap (absolute pressures).
    fluid_pressure : ndarray
        Fluid pressure per cell (Pa): Reynolds pressure, pocket pressures and the
        harmonic extension into the contact spots.
    external_pressure, inlet_pressure, outlet_pressure, mu : float
        ``p_ext``, ``p_in``, ``p_out`` (Pa), viscosity (Pa s).
    leak_rate : float or None
        Coupled leak rate (m^3/s; negative for ``p_in < p_out``: reversed flow).
    one_way_leak_rate : float or None
        Leak rate of the one-way solution (dry contact at ``p_ext``).
    fluid_load_fraction : float
        ``mean(p_f) / p_ext``: share of the external load carried by the fluid pressure
        (over the nominal area; the solid carries ``mean(p_c) / p_ext``, the rest).
    trapped_load_fraction : float
        Share carried by the trapped pockets.
    trapped_volume : float
        Fluid volume in the pockets (m^3).
    pocket_pressures : tuple of float
        Pressure of each pocket (Pa), largest pocket first.
    coupled_iterations : int
        Evaluations of ``G`` after the one-way solve.
    residual : float
        Final relative coupled residual.
    residual_history : tuple of float
    fluid_state : FluidState
        Reference for the next load step's trapped-fluid model.
    """

    state: str
    contact: Optional[object]
    flow: Optional[FVSolution]
    fluid_pressure: np.ndarray
    external_pressure: float
    inlet_pressure: float
    outlet_pressure: float
    mu: float
    leak_rate: Optional[float]
    one_way_leak_rate: Optional[float]
    fluid_load_fraction: float
    trapped_load_fraction: float
    trapped_volume: float
    pocket_pressures: tuple
    coupled_iterations: int
    residual: float
    residual_history: tuple
    fluid_state: FluidState
    references: tuple = field(default=REFERENCES)

    def record(self) -> dict:
        """JSON-safe scalars of the coupled step."""
        return {"fsi_state": self.state, "external_pressure": self.external_pressure,
                "inlet_pressure": self.inlet_pressure, "outlet_pressure": self.outlet_pressure,
                "leak_rate_coupled": self.leak_rate, "leak_rate_one_way": self.one_way_leak_rate,
                "fluid_load_fraction": self.fluid_load_fraction,
                "trapped_load_fraction": self.trapped_load_fraction,
                "trapped_volume": self.trapped_volume,
                "pocket_pressures": list(self.pocket_pressures),
                "coupled_iterations": self.coupled_iterations,
                "coupled_residual": self.residual}


class _LiftOff(RejectedIterate):
    """The fluid alone would carry the external load."""


def _pockets(open_cells, connected, periodic, axis):
    """Labels (-1 elsewhere) of the trapped pockets and their count."""
    o = open_cells & ~connected
    if not o.any():
        return np.full(o.shape, -1), 0
    lab, _, _ = components_reaching(o if axis == 0 else o.T, periodic=periodic)
    lab = lab if axis == 0 else lab.T
    used, inv = np.unique(lab[o], return_inverse=True)
    out = np.full(o.shape, -1)
    out[o] = inv
    return out, used.size


def first_contact_state(surface: Surface, *, direction: str = "x", mu: float = 1e-3,
                        p_in: float, p_out: float) -> FluidState:
    """Reference fluid state at first contact: gap ``max h - h``, its Reynolds pressure."""
    h = surface.heights
    gap = h.max() - h
    sol = solve_reynolds_fv(gap, surface.spacing, direction=direction, mu=mu, p_in=p_in,
                            p_out=p_out, periodic=surface.periodic)
    p = np.where(sol.connected, sol.pressure, 0.5 * (p_in + p_out))
    return FluidState(pressure=p)


def coupled_leakage(surface: Surface, material, external_pressure: float, *,
                    p_in: float, p_out: float, mu: float = 1e-3, direction: str = "x",
                    trapped: str = "film",
                    history: Optional[FluidState] = None, tol: float = 1e-8,
                    max_iter: int = 60, anderson: int = 5, relaxation: float = 1.0,
                    kernel: str = "auto", contact_tol: float = 1e-11,
                    h_reg: Optional[float] = None) -> CoupledResult:
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
    trapped : {"film", "pressure"}
        Trapped pockets: ``"film"`` (default) take the regularised film's pressure (the
        limit of their surroundings: drained pockets); ``"pressure"`` keep their pressure
        at closure (may not converge in load sweeps: pockets that open and close jump).
    history : FluidState, optional
        Reference state (previous load step); default :func:`first_contact_state`.
    tol : float
        Relative coupled residual to reach.
    max_iter : int
        Coupled iterations allowed.
    anderson : int
        Anderson memory (0: plain fixed point).
    relaxation : float
        Mixing ``beta`` in (0, 1] of the Anderson/Picard update ``x + beta r``.
    kernel : str
        BEM kernel (:func:`roughfe.bem.solve_contact`).
    contact_tol : float
        Tolerance of each contact solve (below ``tol``).
    h_reg : float, optional
        Film regularising the fluid-pressure field in contact cells (m); default
        ``1e-3`` times the rms height of the surface.

    Returns
    -------
    CoupledResult

    Raises
    ------
    InputError
        Bad input (named).
    NoConvergenceError
        The coupled residual did not reach ``tol``; ``result`` holds the last state.
    """
    from ..bem import solve_contact
    from ..bem.contact import surface_displacement

    if not isinstance(surface, Surface) or surface.ndim != 2:
        raise InputError(f"coupled leakage needs a 2D Surface, got {surface!r}")
    p_ext = check_finite_positive("external pressure", external_pressure)
    p_in, p_out = check_absolute_pressures(p_in, p_out)
    if trapped not in TRAPPED_MODELS:
        raise InputError(f"trapped must be one of {TRAPPED_MODELS}, got {trapped!r}")
    if direction not in ("x", "y"):
        raise InputError(f"direction must be 'x' or 'y', got {direction!r}")
    mu = check_finite_positive("mu", mu)
    tol, max_iter, anderson, relaxation = check_options(tol, max_iter, anderson, relaxation)
    axis = 0 if direction == "x" else 1
    spacing = surface.spacing
    cell = float(np.prod(spacing))
    h = surface.heights
    if history is None:
        history = first_contact_state(surface, direction=direction, mu=mu, p_in=p_in,
                                      p_out=p_out)
    h_reg = check_finite_positive("h_reg", 1e-3 * float(np.std(h)) if h_reg is None else h_reg)
    last = {"contact": None, "flow": None, "pockets": (np.full(h.shape, -1), 0)}

    def G(x, first=False):
        """One contact solve and one Reynolds solve for the fluid traction x."""
        p_contact = p_ext - float(x.mean())
        if p_contact <= 0:
            raise _LiftOff()
        shifted = Surface(h - surface_displacement(surface, material, x, kernel),
                          surface.size, surface.periodic)
        prev = last["contact"]
        c = solve_contact(shifted, material, mean_pressure=p_contact, kernel=kernel,
                          tol=contact_tol, compute_stiffness=False,
                          initial=None if prev is None else prev.pressure)
        gap = np.where(c.contact, 0.0, c.gap)
        film = solve_reynolds_fv(np.maximum(gap, h_reg), spacing, direction=direction, mu=mu,
                                 p_in=p_in, p_out=p_out, periodic=surface.periodic)
        y = film.pressure
        # cells open by less than the film count as closed for the pocket topology (else a
        # cell flickering between contact and a sub-film gap splits and merges pockets)
        wet = gap > h_reg
        lab_all, t_in, t_out = components_reaching(wet if axis == 0 else wet.T,
                                                   periodic=surface.periodic)
        lab_all = lab_all if axis == 0 else lab_all.T
        connected = np.zeros(gap.shape, bool)
        connected[lab_all >= 0] = (t_in | t_out)[lab_all[lab_all >= 0]]
        lab, n = _pockets(wet, connected, surface.periodic, axis)
        if n and trapped == "pressure":
            inp = lab >= 0
            vol = np.bincount(lab[inp], gap[inp], n)
            # pressure at closure: the pocket cells' pressure in the incoming iterate (the
            # previous step's field at the first evaluation), weighted by the current gap
            ref = history.pressure if first else x
            p_pocket = np.bincount(lab[inp], (gap * ref)[inp], n) / vol
            y = np.where(lab >= 0, p_pocket[np.maximum(lab, 0)], y)
        last.update(contact=c, gap=gap, pockets=(lab, n))
        return y

    def _flow(gap):
        return solve_reynolds_fv(gap, spacing, direction=direction, mu=mu, p_in=p_in,
                                 p_out=p_out, periodic=surface.periodic)

    x = np.zeros(h.shape)
    gx = G(x, first=True)
    one_way = _flow(last["gap"]).leak_rate
    fp = anderson_fixed_point(G, x, gx, tol=tol, max_iter=max_iter, memory=anderson,
                              relaxation=relaxation)
    it, gx, residuals = fp.iterations, fp.gx, list(fp.residuals)
    if fp.status == "max_iter":
        last["flow"] = _flow(last["gap"])
        partial = _result("contact", last, gx, p_ext, p_in, p_out, mu, one_way, it,
                          fp.residual, residuals, cell)
        raise NoConvergenceError(
            f"fluid-structure coupling: relative residual {fp.residual:.3e} after {it} "
            f"iterations (tolerance {tol:.1e}, Anderson memory {anderson})", result=partial)
    state = "lift-off" if fp.status == "rejected" else "contact"
    if state == "contact":
        last["flow"] = _flow(last["gap"])
    return _result(state, last, gx, p_ext, p_in, p_out, mu, one_way, it,
                   residuals[-1], residuals, cell)


def _result(state, last, fluid, p_ext, p_in, p_out, mu, one_way, it, res, residuals, cell):
    if state == "lift-off":
        p_f = np.full(fluid.shape, max(p_in, p_out))
        return CoupledResult(
            state=state, contact=None, flow=None, fluid_pressure=p_f, external_pressure=p_ext,
            inlet_pressure=p_in, outlet_pressure=p_out, mu=mu, leak_rate=None,
            one_way_leak_rate=one_way, fluid_load_fraction=1.0, trapped_load_fraction=0.0,
            trapped_volume=0.0, pocket_pressures=(), coupled_iterations=it, residual=res,
            residual_history=tuple(residuals),
            fluid_state=FluidState(pressure=p_f))
    c, sol = last["contact"], last["flow"]
    lab, n = last["pockets"]
    gap = np.where(c.contact, 0.0, c.gap)
    in_pocket = lab >= 0
    pocket_p = []
    if n:
        area = np.bincount(lab[in_pocket], minlength=n)
        p_sum = np.bincount(lab[in_pocket], fluid[in_pocket], n)
        pocket_p = [float(v) for v in (p_sum / area)[np.argsort(-area)]]
    state_next = FluidState(pressure=fluid)
    return CoupledResult(
        state=state, contact=c, flow=sol, fluid_pressure=fluid, external_pressure=p_ext,
        inlet_pressure=p_in, outlet_pressure=p_out, mu=mu, leak_rate=sol.leak_rate,
        one_way_leak_rate=one_way, fluid_load_fraction=float(fluid.mean() / p_ext),
        trapped_load_fraction=float(fluid[in_pocket].sum() / fluid.size / p_ext),
        trapped_volume=float(gap[in_pocket].sum() * cell), pocket_pressures=tuple(pocket_p),
        coupled_iterations=it, residual=res, residual_history=tuple(residuals),
        fluid_state=state_next)


def coupled_sweep(surface: Surface, material, external_pressures, **kwargs) -> tuple:
    """:func:`coupled_leakage` over increasing external pressures (Pa), each step's fluid
    state the trapped-fluid reference of the next. Stops after a lift-off step.

    Returns a tuple of :class:`CoupledResult`.
    """
    out = []
    history = kwargs.pop("history", None)
    for p in external_pressures:
        r = coupled_leakage(surface, material, p, history=history, **kwargs)
        out.append(r)
        if r.state == "lift-off":
            break
        history = r.fluid_state
    return tuple(out)


@dataclass(frozen=True, eq=False)
class CoupledSweep:
    """Coupled results over a load sweep and the network/junction analysis of each
    coupled gap (:func:`roughfe.leakage.analyse_leakage`, Reynolds not re-solved)."""

    surface: Surface
    results: tuple
    leakages: tuple

    @property
    def success(self) -> bool:
        return all(r.state in ("contact", "lift-off") for r in self.results)

    def records(self) -> list:
        """One JSON-safe dict per step: contact scalars (``mean_pressure`` is the solid's
        effective pressure), the coupled scalars (:meth:`CoupledResult.record`), the network
        and critical constriction of the coupled gap; ``leak_rate`` is the coupled one."""
        out = []
        sigma = float(np.std(self.surface.heights))
        for k, (r, lk) in enumerate(zip(self.results, self.leakages)):
            rec = {"step": k}
            if r.contact is not None:
                rec.update(r.contact.scalars())
                rec["separation_star"] = float(r.contact.mean_plane_separation / sigma)
            if lk is not None:
                rec.update(lk.record())
            rec.update(r.record())
            rec["leak_rate"] = r.leak_rate
            if lk is not None:
                rec[f"leak_rate_{lk.directions[0]}"] = r.leak_rate
            out.append(rec)
        return out


def coupled_leakage_sweep(surface: Surface, material, external_pressures, *,
                          direction: str = "x", **kwargs) -> CoupledSweep:
    """:func:`coupled_sweep`, then the free-volume network and critical constriction of
    each coupled gap (``corner_rule="closed"``, as the FV scheme).

    ``kwargs`` go to :func:`coupled_leakage` (``p_in``, ``p_out``, ``mu``, ``trapped``, ...).
    """
    from .analysis import analyse_leakage

    results = coupled_sweep(surface, material, external_pressures, direction=direction,
                            **kwargs)
    leaks = []
    for r in results:
        if r.contact is None:
            leaks.append(None)
            continue
        leaks.append(analyse_leakage(
            r.contact.gap, r.contact.contact, surface.spacing, direction=direction,
            periodic=surface.periodic, sigma=float(np.std(surface.heights)), mu=r.mu,
            pressure_drop=abs(r.inlet_pressure - r.outlet_pressure), reynolds=False))
    return CoupledSweep(surface=surface, results=results, leakages=tuple(leaks))
