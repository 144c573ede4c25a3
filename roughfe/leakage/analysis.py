"""Leakage of one contact state: free-volume network (Alg. 1) plus Reynolds flow (Eq. 2.12).

:func:`analyse_leakage` takes a gap field, its contact mask and the grid spacing (for
example the fields of a :class:`roughfe.model.ContactResult`, see
:func:`leakage_of_contact`) and returns a frozen :class:`LeakageResult`; its
:meth:`LeakageResult.record` is the JSON-safe summary written per load step.
"""
from __future__ import annotations

import inspect
from dataclasses import dataclass
from typing import Mapping, Optional

import numpy as np

from .. import progress
from ..errors import (InputError, check_finite_nonnegative, check_finite_positive, check_instance,
                      check_real_array)
from ..frozen import FrozenMapping, compact_repr
from ..model import ContactResult
from ..theory.beside import UNITS as PERSSON_UNITS
from .junction import CriticalConstriction, critical_constriction
from .network import NetworkResult, free_volume_network
from .reynolds import ReynoldsResult, reynolds_flow

REFERENCES = (
    "Algorithm 1, Eq. 2.8, 2.15-2.17: thesis 'Surface roughness genomics', Sec. 2.4",
    "Reynolds equation Eq. 2.10-2.12: Hamrock, Schmid & Jacobson, Fundamentals of Fluid "
    "Film Lubrication (2004)",
    "Saddle points in leakage: Dapp & Muser, EPL 109 (2015) 44001",
)


#: the keys of :meth:`roughfe.leakage.junction.CriticalConstriction.record`, per direction
#: (``_x``, ``_y``) and, unsuffixed, the first analysed direction's
_JUNCTION_KEYS = ("critical_gap", "critical_position", "critical_width",
                  "parent_channel_length", "critical_at_edge")


def _direction_list(direction) -> tuple:
    if direction == "both":
        return ("x", "y")
    if isinstance(direction, str):
        direction = (direction,)
    out = tuple(dict.fromkeys(direction))
    if not out or any(d not in ("x", "y") for d in out):
        raise InputError(f"direction must be 'x', 'y' or 'both', got {direction!r}")
    return out


@dataclass(frozen=True, eq=False)
class LeakageResult:
    """Network and flow analysis of one gap field.

    Attributes
    ----------
    network : NetworkResult
        Free volume ``V`` and its percolating/trapped parts (Eq. 2.8, 2.15-2.16).
    flows : dict
        :class:`ReynoldsResult` per flow direction (empty when Reynolds was skipped).
    directions : tuple of str
        Analysed flow directions.
    constrictions : dict
        :class:`~roughfe.leakage.junction.CriticalConstriction` per flow direction (the
        critical gap, junction, width and parent channel; empty when not computed).
    mu, pressure_drop : float
        Viscosity (Pa s) and ``p_in - p_out`` (Pa) of the flow problem.
    size : (float, float)
        Domain size (m).
    references : tuple of str
    """

    network: NetworkResult
    flows: Mapping[str, ReynoldsResult]
    directions: tuple
    constrictions: Mapping[str, CriticalConstriction]
    mu: float
    pressure_drop: float
    size: tuple
    references: tuple = REFERENCES

    __repr__ = compact_repr          # one line: the network and flows by their types

    def __post_init__(self):
        for name in ("flows", "constrictions"):
            object.__setattr__(self, name, FrozenMapping(getattr(self, name)))

    @property
    def leak_rate(self) -> Optional[float]:
        """Mean of the leak rates over the solved directions (m^3/s); None if not solved."""
        if not self.flows:
            return None
        return float(np.mean([f.leak_rate for f in self.flows.values()]))

    @property
    def hydraulic_aperture(self) -> Optional[float]:
        """Mean hydraulic aperture over the solved directions (m); None if not solved."""
        vals = [f.hydraulic_aperture for f in self.flows.values()]
        if not vals or any(v is None for v in vals):
            return None
        return float(np.mean(vals))

    @property
    def success(self) -> bool:
        return all(f.success for f in self.flows.values())

    def record(self) -> dict:
        """JSON-safe scalars: percolation flags, volumes, leak rates per direction.

        ``percolates_<d>`` is the network verdict (its corner rule);
        ``leak_rate_critical_junction`` (unsuffixed) is the mean of the per-direction
        junction leak rates, as ``leak_rate``; the unsuffixed ``critical_gap``,
        ``critical_position``, ``critical_width``, ``parent_channel_length`` and
        ``critical_at_edge`` (the junction within one cell of a non-periodic window edge)
        are the first analysed direction's junction (``_x``/``_y`` keys for each);
        ``percolates_reynolds_<d>`` the one of the Reynolds scheme (FV: face neighbours;
        FE: Q1 corner conduction); ``flow_imbalance_<d>`` its
        ``|inlet - outlet| / |leak rate|`` (above 1e-6 a boundary flow is round-off,
        :attr:`~roughfe.leakage.reynolds.ReynoldsResult.flow_imbalance`); ``leak_rate`` and
        ``hydraulic_aperture`` are means over the solved directions.
        """
        net = self.network
        rec = {
            "free_volume": net.volume,
            "percolating_volume": net.percolating_volume,
            "trapped_volume": net.trapped_volume,
            "free_volume_star": net.free_volume_star,
            "percolating_volume_star": net.percolating_volume_star,
            "trapped_volume_star": net.trapped_volume_star,
            # the part of the trapped (non-percolating) volume that no open path joins to
            # inlet or outlet; the rest are dead ends open to the flow
            "sealed_volume": net.sealed_volume,
            "sealed_volume_star": net.sealed_volume_star,
            "leak_rate": self.leak_rate,
            "hydraulic_aperture": self.hydraulic_aperture,
        }
        for d in ("x", "y"):
            rec[f"percolates_{d}"] = net.percolates(d)
            flow = self.flows.get(d)
            rec[f"leak_rate_{d}"] = None if flow is None else flow.leak_rate
            rec[f"hydraulic_aperture_{d}"] = None if flow is None else flow.hydraulic_aperture
            rec[f"percolates_reynolds_{d}"] = None if flow is None else flow.percolates
            # |inlet - outlet| / |leak rate| (ReynoldsResult.flow_imbalance; a
            # FlowImbalanceWarning above 1e-6); None without through-flow (both ~round-off)
            rec[f"flow_imbalance_{d}"] = (
                None if flow is None or not flow.percolates else flow.flow_imbalance)
            rec[f"reynolds_nit_{d}"] = None if flow is None else flow.nit
            con = self.constrictions.get(d)
            for key, val in (con.record() if con is not None else
                             dict.fromkeys(_JUNCTION_KEYS)).items():
                rec[f"{key}_{d}"] = val
            rec[f"leak_rate_critical_junction_{d}"] = (
                None if con is None else con.leak_rate_junction(
                    mu=self.mu, pressure_drop=self.pressure_drop,
                    length=self.size[0 if d == "x" else 1], width=self.size[1 if d == "x" else 0]))
        # unsuffixed: the junction leak rate as leak_rate, the mean over the analysed
        # directions (the first direction's alone read "sealed", 0, beside a positive Q
        # that flowed along y); the geometry of the first direction's junction
        first = self.directions[0]
        for key in _JUNCTION_KEYS:
            rec[key] = rec[f"{key}_{first}"]
        rates = [rec[f"leak_rate_critical_junction_{d}"] for d in self.directions]
        rec["leak_rate_critical_junction"] = (
            None if any(q is None for q in rates) else float(np.mean(rates)))
        return rec


def analyse_leakage(gap, contact, spacing, *, direction="both", periodic: bool = False,
                    sigma: Optional[float] = None, mu: float = 1e-3,
                    pressure_drop: float = 1.0, reynolds: bool = True,
                    wall_velocity=(0.0, 0.0), gap_tol: float = 0.0, scheme: str = "fv",
                    corner_rule: str = "closed", junction: bool = True,
                    petsc_options: Optional[Mapping] = None) -> LeakageResult:
    """Network (Alg. 1) and Reynolds (Eq. 2.12) analysis of a gap field.

    Parameters
    ----------
    gap : ndarray, shape (nx, ny)
        Gap in m (>= 0).
    contact : ndarray of bool or None
        Contact mask; None: closed where ``gap <= gap_tol``.
    spacing : (float, float)
        ``(dx, dy)`` in m.
    direction : {"x", "y", "both"} or sequence
        Flow direction(s); ``U_p`` is the union over them (Sec. 2.4.2).
    periodic : bool
        Periodic side walls (network and flow).
    sigma : float, optional
        Rms height of the undeformed surface (m), for the dimensionless volumes.
    mu, pressure_drop : float
        Viscosity (Pa s) and ``p_in - p_out`` (Pa).
    reynolds : bool
        Solve the Reynolds equation (False: network only).
    wall_velocity : (float, float)
        Couette wall velocity (m/s).
    gap_tol : float
        Free-volume threshold (m). The Reynolds solve uses ``h = 0`` on closed cells.
    scheme : {"fv", "fe"}
        Reynolds discretisation: cell-centred finite volumes (default) or the Q1 dolfinx
        cross-check (:func:`roughfe.leakage.reynolds_flow`).
    corner_rule : {"closed", "saddle"}
        Diagonal-only contacts in the network: ``"closed"`` (default) is the connectivity
        of the FV scheme, so network and Reynolds agree on percolation; ``"saddle"`` is
        the thesis' rule (Fig. 13).
    junction : bool
        Find the critical constriction per direction
        (:func:`roughfe.leakage.junction.critical_constriction`).
    petsc_options : mapping, optional
        PETSc options for the Reynolds solve.
    """
    dirs = _direction_list(direction)
    # checked whether or not Reynolds runs: the junction leak rate takes them too (mu = 0
    # was a ZeroDivisionError in record(), a negative drop a negative leak rate)
    mu = check_finite_positive("mu (Pa s)", mu)
    pressure_drop = check_finite_nonnegative("pressure_drop (Pa)", pressure_drop)
    g = check_real_array("gap", gap, 2)     # a masked or complex gap is refused, not read
    net = free_volume_network(g, contact, spacing, directions=dirs, periodic=periodic,
                              sigma=sigma, gap_tol=gap_tol, corner_rule=corner_rule)
    flows = {}
    h = np.where(net.open, g, 0.0)
    if reynolds:
        flows = {d: reynolds_flow(h, spacing, direction=d, mu=mu, pressure_drop=pressure_drop,
                                  periodic=periodic, wall_velocity=wall_velocity,
                                  scheme=scheme, petsc_options=petsc_options) for d in dirs}
    cons = ({d: critical_constriction(h, spacing, direction=d, periodic=periodic) for d in dirs}
            if junction else {})
    size = (g.shape[0] * float(spacing[0]), g.shape[1] * float(spacing[1]))
    return LeakageResult(network=net, flows=flows, directions=dirs, constrictions=cons,
                         mu=float(mu), pressure_drop=float(pressure_drop), size=size)


def leakage_of_contact(contact_result, **kwargs) -> LeakageResult:
    """:func:`analyse_leakage` on a :class:`roughfe.model.ContactResult` (surfaces only).

    Uses its ``gap``, ``contact``, ``spacing``, ``periodic`` and ``rms_height`` (sigma);
    keyword arguments are passed on (``direction``, ``mu``, ``pressure_drop``, ...).
    """
    check_instance("contact_result", contact_result, ContactResult,
                   "a roughfe.model.ContactResult (solve_contact, response)")
    if np.ndim(contact_result.gap) != 2:
        raise InputError("leakage needs a 2D surface; got a contact result of a profile")
    allowed = [k for k in inspect.signature(analyse_leakage).parameters
               if k not in ("gap", "contact", "spacing")]
    unknown = sorted(set(kwargs) - set(allowed))
    if unknown:    # theory's critical_junction says viscosity; here it is mu (Pa s)
        hint = "; the viscosity (Pa s) is mu" if "viscosity" in unknown else ""
        raise InputError(f"unknown option(s) {unknown} for leakage_of_contact; allowed: "
                         f"{allowed}{hint}")
    kwargs.setdefault("periodic", bool(contact_result.periodic))
    kwargs.setdefault("sigma", float(contact_result.rms_height))
    return analyse_leakage(contact_result.gap, contact_result.contact,
                           tuple(contact_result.spacing), **kwargs)


@dataclass(frozen=True, eq=False)
class LeakageSweep:
    """Contact (BEM) and leakage results over a sequence of loads on one surface.

    Attributes
    ----------
    contacts : tuple of roughfe.model.ContactResult
    leakages : tuple of LeakageResult
    """

    contacts: tuple
    leakages: tuple

    __repr__ = compact_repr

    @property
    def success(self) -> bool:
        return all(c.success for c in self.contacts) and all(lk.success for lk in self.leakages)

    def records(self) -> list:
        """One JSON-safe dict per step: contact scalars + :meth:`LeakageResult.record`.
        No ``stiffness``: the leakage sweep does not compute it (a null there read as the
        infinite stiffness of full contact, which results.json writes as null)."""
        out = []
        for k, (c, lk) in enumerate(zip(self.contacts, self.leakages)):
            scalars = c.scalars()
            scalars.pop("stiffness", None)
            scalars["iterations"] = scalars.pop("nit")    # the name of contact's records
            rec = {"step": k, **scalars,
                   "separation_star": float(c.mean_plane_separation / c.rms_height),
                   "contact_success": bool(c.success)}
            rec.update(lk.record())       # the network's free volume replaces the BEM one
            out.append(rec)
        return out


def leakage_sweep(surface, material, *, deltas=None, pressures=None, kernel: str = "auto",
                  contact_options=None, **leak_kwargs) -> LeakageSweep:
    """BEM contact at each approach or mean pressure, then :func:`leakage_of_contact`.

    Parameters
    ----------
    surface : roughfe.surfaces.Surface
        2D surface (heights in m).
    material : roughfe.model.Material
        Elastic body (Pa).
    deltas, pressures : sequence of float
        Approaches Delta (m) or mean contact pressures (Pa); exactly one.
    kernel : str
        BEM influence operator (:func:`roughfe.bem.solve_contact`).
    contact_options : dict, optional
        Interface physics of the contact solve, passed to :func:`roughfe.response.response`:
        ``hardness`` (Pa), ``adhesion`` (an AdhesionLaw; approaches only), ``unload``
        (the unloading steps follow the loading ones).
    **leak_kwargs
        Passed to :func:`analyse_leakage` (``direction``, ``mu``, ``pressure_drop``,
        ``reynolds``, ``sigma``, ...).
    """
    from ..model import Loading
    from ..response import response

    if surface.ndim != 2:
        raise InputError(f"leakage needs a 2D surface, got {surface!r}")
    if (deltas is None) == (pressures is None):
        raise InputError("give exactly one of deltas (m) or pressures (Pa)")
    loading = Loading(deltas=deltas) if deltas is not None else Loading(pressures=pressures)
    sweep = response(surface, material, loading, kernel=kernel, compute_stiffness=False,
                     **(contact_options or {}))
    leaks = tuple(_leakage_of_step(k, c, leak_kwargs) for k, c in
                  enumerate(progress.iterate(sweep.results, "leakage steps")))
    return LeakageSweep(contacts=tuple(sweep.results), leakages=leaks)


def _leakage_of_step(k, contact, leak_kwargs):
    """:func:`leakage_of_contact` of step ``k`` (from 0, as the records), its warnings
    re-issued with the step and its load named (a Reynolds flow imbalance said neither:
    a user's review, round 2, session 29)."""
    import warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        leak = leakage_of_contact(contact, **leak_kwargs)
    for w in caught:
        message = (f"step {k} (p = {contact.mean_pressure:.4g} Pa, Delta = "
                   f"{contact.delta:.4g} m): {w.message}")
        warnings.warn(message, w.category, stacklevel=2)
    return leak


#: units of the step-record keys of ``roughfe leak`` (results.json ``units``), by name
#: without its direction suffix (``_x``/``_y``); "1" dimensionless
_RECORD_UNITS = {
    "step": "index (from 0)", "delta": "m", "load": "N", "mean_pressure": "Pa",
    "external_pressure": "Pa", "contact_area": "m^2", "n_contact": "count",
    "patch_width": "grid points (load-weighted contact patch width)",
    "mean_gap": "m", "mean_plane_separation": "m", "residual": "1 (relative KKT residual)",
    "iterations": "count", "separation_star": "1 (d / sigma)", "contact_success": "bool",
    "unloading": "bool (a step of the unloading path, --unload)",
    "persson_stiffness": PERSSON_UNITS["persson_stiffness"],
    "hydraulic_aperture": "m", "percolates": "bool", "percolates_reynolds": "bool",
    "flow_imbalance": "1 (|inlet flow - outlet flow| / leak rate)", "reynolds_nit": "count",
    "critical_position": "m (x, y of the junction centre)", "critical_width": "m",
    "critical_at_edge": "bool (the junction lies within one cell of a non-periodic window's "
                        "edge: the constriction may be the cut's, not the surface's)",
    "parent_channel_length": "m", "fsi_state": "label", "coupled_iterations": "count",
    "stiffness": "Pa/m", "trapped_fluid": "label (pocket law)", "bulk_modulus": "Pa",
    "leak_rate_coupled": "m^3/s", "pocket_pressures": "Pa (one per pocket)",
    "pocket_volumes": "m^3 (one per pocket)", "pockets_new": "count",
    "pockets_released": "count", "pockets_merged": "count", "pocket_passes": "count",
    "pockets_settled": "bool", "coupled_residual": "1 (relative)",
}


def record_units(keys) -> dict:
    """The unit of each step-record key in ``keys`` (SI; volumes ``*_volume`` m^3, their
    ``*_volume_star`` V / (A_n sigma), sigma the rms height of the undeformed surface;
    ``*_fraction`` 1, ``*_rate`` m^3/s, ``*_gap`` m, ``*_pressure`` Pa, ``*_stiffness``
    Pa/m); keys of no known
    kind are left out."""
    out = {}
    for key in keys:
        base = key[:-2] if key.endswith(("_x", "_y")) else key
        unit = _RECORD_UNITS.get(base)
        if unit is None:
            for suffix, u in (("_volume_star", "1 (V / (A_n sigma))"), ("_volume", "m^3"),
                              ("_fraction", "1"), ("_rate", "m^3/s"),
                              ("leak_rate_critical_junction", "m^3/s"), ("_gap", "m"),
                              ("_pressure", "Pa"), ("_one_way", "m^3/s"),
                              ("_stiffness", "Pa/m")):
                if base.endswith(suffix):
                    unit = u
                    break
        if unit is not None:
            out[key] = unit
    return out
