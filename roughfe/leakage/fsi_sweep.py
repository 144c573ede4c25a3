"""Load sweeps of the two-way fluid-structure coupling of :mod:`roughfe.leakage.fsi`: each
step's fluid state the trapped-fluid reference of the next (:func:`coupled_sweep`), and
the free-volume network and critical constriction of every coupled gap
(:func:`coupled_leakage_sweep`, :class:`CoupledSweep`). SI units (Pa, m, m^3/s).
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..errors import NoConvergenceError
from ..surfaces import Surface
from .fsi import coupled_leakage


def coupled_sweep(surface: Surface, material, external_pressures, **kwargs) -> tuple:
    """:func:`coupled_leakage` over increasing external pressures (Pa), each step's fluid
    state the trapped-fluid reference of the next. A lift-off step (the fluid carries the
    whole load: the gap is open everywhere) traps nothing, so the next step starts from
    first contact (no reference); a larger external pressure can close the contact again.

    Returns a tuple of :class:`CoupledResult`.
    """
    out = []
    history = kwargs.pop("history", None)
    for p in external_pressures:
        try:
            r = coupled_leakage(surface, material, p, history=history, **kwargs)
        except NoConvergenceError:
            if history is None:
                raise
            # the previous step's fluid pressure can be a poor start: 64^2, p_in = 20 MPa,
            # 35 MPa after 30 MPa stopped 60 iterations short, while from zero it took 21
            # (measured, docs/theory/04b). Again from zero, with the previous pockets
            r = coupled_leakage(surface, material, p, **kwargs, history=replace(
                history, pressure=np.zeros_like(history.pressure)))
        out.append(r)
        history = None if r.state == "lift-off" else r.fluid_state
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
        and critical constriction of the coupled gap; ``leak_rate`` is the coupled one.

        The contact scalars mean what the one-way records' keys mean: ``delta`` is the
        approach of the rigid surface from first contact of the undeformed surfaces
        (:attr:`CoupledResult.approach`), ``mean_plane_separation`` is ``max h - mean h -
        delta`` and ``free_volume_star`` is ``mean_gap / sigma`` with the heights ``h``
        of the surface, not those of the internal dry problem on ``h - H p_f`` (until
        round 2, session 24 they were copied from it: 32^2, p_ext 30 MPa, p_in 20 MPa,
        delta 2.424 um where the approach is 2.586 um)."""
        out = []
        h = self.surface.heights
        sigma = float(np.std(h))
        for k, (r, lk) in enumerate(zip(self.results, self.leakages)):
            rec = {"step": k}
            if r.contact is not None:
                rec.update(r.contact.scalars())
                rec["iterations"] = rec.pop("nit")        # the name of contact's records
                separation = float(h.max() - h.mean() - r.approach)
                rec.update(delta=r.approach, mean_plane_separation=separation,
                           free_volume_star=float(r.contact.mean_gap / sigma),
                           separation_star=separation / sigma,
                           contact_success=bool(r.contact.success))   # as one-way records
            if lk is not None:
                rec.update(lk.record())
            rec.update(r.record())
            rec["leak_rate"] = r.leak_rate
            if lk is not None:
                d = lk.directions[0]
                rec[f"leak_rate_{d}"] = r.leak_rate
                # the parallel-plate gap of the coupled leak rate (the network analysis
                # solves no Reynolds, so it left None: a seals review)
                rec["hydraulic_aperture"] = rec[f"hydraulic_aperture_{d}"] = \
                    _coupled_aperture(r, self.surface.size, d)
                # the coupled Reynolds solve's own report, as the one-way records give it
                # (null here: the network analysis above solves none)
                rec.update(_flow_report(r.flow, d))
            out.append(rec)
        return out


def _flow_report(flow, direction) -> dict:
    """``percolates_reynolds_<d>``, ``flow_imbalance_<d>`` (``|inlet - outlet| / |Q|``,
    None without through-flow) and ``reynolds_nit_<d>`` of a coupled step's FV solution."""
    imbalance = None
    if flow.percolates and flow.leak_rate != 0.0:
        imbalance = abs(flow.inlet_flow - flow.outlet_flow) / abs(flow.leak_rate)
    return {f"percolates_reynolds_{direction}": bool(flow.percolates),
            f"flow_imbalance_{direction}": imbalance,
            f"reynolds_nit_{direction}": int(flow.nit)}


def _coupled_aperture(result, size, direction):
    """``(12 mu |Q| L / (W |p_in - p_out|))^(1/3)`` (m) of a coupled step: the gap of the
    parallel plates that leak as much (reversed flow by its magnitude); None without a
    leak rate or a pressure drop."""
    from .reynolds import hydraulic_aperture

    drop = abs(result.inlet_pressure - result.outlet_pressure)
    if result.leak_rate is None or drop == 0:
        return None
    length, width = size if direction == "x" else size[::-1]
    return hydraulic_aperture(abs(result.leak_rate), mu=result.mu, pressure_drop=drop,
                              flow_length=length, width=width)


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
