"""The grid check: a sweep solved again on the same surface ``factor`` times finer.

A contact result on a measured grid carries a discretisation error that no property of
the one solution predicts (docs/theory/02, "Discretisation error at a fixed surface";
measured on eleven surfaces, 1x / 2x / 4x band-limited refinements, changes fine /
coarse - 1): with every patch "resolved" (``patch_width`` 7-25 grid points,
:mod:`roughfe.bem.patches`) A* by counting points fell by 10-20 % to the 4x grid on
di-1.di and on generated surfaces rough to the grid scale, by 3-5 % on surfaces smooth
there (x3p-2, a roll-off at a quarter of the Nyquist wavenumber) and by 32-56 % on a
window of sur-2 (its PSD turns up in the last octave: a noise floor); K and the mean gap
moved by < 3.2 % and < 1.2 % except on sur-2 (up to 16 %); the adhesive pull-off by
-1.2 to +6.7 % (its sign and size unrelated to the A* change). The contact's perimeter
per contact point ordered the A* errors (Spearman 0.95) but gave them only within a
factor 3 (6-18 % at 1-1.5 cell faces per contact point, 18-56 % at 2-4). So the check is
explicit: :func:`grid_check` solves the refined surface
(:func:`roughfe.surfaces.resample.refined`, no new roughness) at the same loads and
reports the relative change of each quantity; ``roughfe contact --grid-check`` runs it.

The change to the 2x grid is a lower bound of the error: the change to the 4x grid was
1.2-1.75x the change to the 2x grid in all 33 measured cases (the differences shrink by
0.2-0.75 per halving of the spacing), and the pull-off and A* under adhesion alike.

Non-adhesive sweeps are compared at the same mean pressures (load control on the fine
grid: A*(p), K(p) and the mean gap at p, the curves a user reads), the loading steps in
partial contact with p > 0; adhesive sweeps at the same rigid planes (each approach
shifted by the rise of the highest point under refinement: the same absolute flat, not
the same distance below a summit the finer grid makes higher): A* and the mean pressure
there (relative to the largest |p| of the compared steps: it passes through zero), with
the pull-off of the unloading branch when it was traced.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from ..errors import InputError, check_int
from ..frozen import Frozen, compact_repr
from ..model import Material, SweepResult
from ..surfaces.resample import refined
from ..surfaces.surface import Surface
from ..writers import finite_or_none

#: relative change of A*, K, the mean gap, the pull-off (fine over coarse less 1) or the
#: adhesive mean pressure above which the grid check says that the grid does not resolve
#: the surface: the 2x change was 0.57-0.83 of the change to the 4x grid (module
#: docstring), so 5 % marks a grid whose answer is at least ~6-9 % off
GRID_CHANGE_LIMIT = 0.05
#: the refinement of :func:`grid_check` (the option's 2x: 4x the points of a surface)
GRID_CHECK_FACTOR = 2
#: the quantities compared, and their names in the note and in results.json
QUANTITIES = {"area_fraction": "A*", "stiffness": "K", "mean_gap": "mean gap",
              "mean_pressure": "p", "pull_off_pressure": "pull-off"}


@dataclass(frozen=True, eq=False)
class GridCheck(Frozen):
    """A sweep against the same surface ``factor`` times finer (SI).

    Attributes
    ----------
    factor : int
        Refinement per axis.
    shape : tuple
        The fine grid.
    steps : ndarray of int
        The coarse sweep's steps compared (indices into its results).
    mean_pressure, delta : ndarray
        Their mean pressures (Pa) and approaches (m), coarse grid.
    coarse, fine : dict
        Per quantity the two grids' values, one per compared step: ``area_fraction``,
        ``stiffness`` (Pa/m) and ``mean_gap`` (m); adhesive: ``area_fraction`` and
        ``mean_pressure`` (Pa), and with the unloading branch ``pull_off_pressure``
        (Pa, one value).
    limit : float
        :data:`GRID_CHANGE_LIMIT`.
    """

    factor: int
    shape: tuple
    steps: np.ndarray
    mean_pressure: np.ndarray
    delta: np.ndarray
    coarse: dict
    fine: dict
    limit: float = GRID_CHANGE_LIMIT

    __repr__ = compact_repr

    def change(self, quantity: str) -> np.ndarray:
        """fine / coarse - 1 per compared step (NaN where undefined: K infinite or not
        computed, a zero mean gap); the adhesive mean pressure, which passes through
        zero between tensile and compressive states, as (fine - coarse) / the largest
        |coarse| of the compared steps."""
        a = np.atleast_1d(np.asarray(self.coarse[quantity], float))
        b = np.atleast_1d(np.asarray(self.fine[quantity], float))
        scale = (np.full(a.shape, np.abs(a).max()) if quantity == "mean_pressure"
                 else a)           # a pull-off (< 0) 2 % more tensile: +2 %
        ok = np.isfinite(a) & np.isfinite(b) & (scale != 0)
        out = np.full(a.shape, np.nan)
        out[ok] = (b[ok] - a[ok]) / scale[ok]
        return out

    def largest(self) -> dict:
        """The largest |change| per quantity, signed, with its step: ``{quantity:
        (change, step or None)}`` (quantities without a finite change left out)."""
        out = {}
        for q in self.coarse:
            c = self.change(q)
            if not np.isfinite(c).any():
                continue
            k = int(np.nanargmax(np.abs(c)))
            out[q] = (float(c[k]), None if q == "pull_off_pressure" else int(self.steps[k]))
        return out

    @property
    def flagged(self) -> bool:
        """True when a quantity changed by more than the limit."""
        return any(abs(c) > self.limit for c, _ in self.largest().values())

    def note(self) -> Optional[str]:
        """The sentence of a flagged check (None otherwise)."""
        if not self.flagged:
            return None
        worst = ", ".join(f"{QUANTITIES[q]} {100 * c:+.3g} %" + ("" if k is None else
                                                                 f" (step {k})")
                          for q, (c, k) in self.largest().items() if abs(c) > self.limit)
        return (f"the same surface {self.factor}x finer (band-limited) changes {worst}: "
                f"more than {100 * self.limit:g} %, the grid does not resolve the "
                f"surface (measured: the change to a 4x grid was 1.2-1.75x the change "
                f"to the 2x grid, docs/theory/02)")

    def describe(self) -> dict:
        """JSON-safe summary (results.json ``derived.grid_check``)."""
        steps = []
        for i, k in enumerate(self.steps):
            row = {"step": int(k), "mean_pressure": float(self.mean_pressure[i]),
                   "delta": float(self.delta[i])}
            for q in self.coarse:
                if q == "pull_off_pressure":
                    continue
                c = self.change(q)[i]
                row[q] = finite_or_none(self.coarse[q][i])
                row[q + "_fine"] = finite_or_none(self.fine[q][i])
                row[q + "_change"] = finite_or_none(c)
            steps.append(row)
        out = {"factor": self.factor, "shape": list(self.shape), "limit": self.limit,
               "method": "band-limited (Fourier) refinement of the same surface, "
                         "roughfe.surfaces.resample.refined",
               "steps": steps,
               "largest_change": {q: {"change": c, "step": k}
                                  for q, (c, k) in self.largest().items()},
               "flagged": self.flagged, "note": self.note()}
        if "pull_off_pressure" in self.coarse:
            out["pull_off_pressure"] = finite_or_none(self.coarse["pull_off_pressure"])
            out["pull_off_pressure_fine"] = finite_or_none(self.fine["pull_off_pressure"])
            out["pull_off_pressure_change"] = finite_or_none(
                self.change("pull_off_pressure")[0])
        return out


def grid_check(surface: Surface, material: Material, sweep: SweepResult, *,
               factor: int = GRID_CHECK_FACTOR, adhesion=None, unload: bool = False,
               kernel: str = "auto", tol: Optional[float] = None,
               **options) -> GridCheck:
    """Solve ``sweep`` (of ``surface``) again on ``refined(surface, factor)`` and compare.

    Parameters
    ----------
    surface : Surface
        The surface the sweep was solved on.
    sweep : SweepResult
        Its sweep: :func:`roughfe.bem.contact_sweep` / ``response`` (BEM), or with
        ``adhesion`` the sweep of :func:`roughfe.bem.adhesion.adhesive_sweep`.
    factor : int
        Refinement per axis, >= 2 (default 2: 4x the points of a surface, 3-5x the
        sweep's CPU: 3.4-3.9x measured at 128^2-256^2, 3-4.6x adhesive).
    adhesion : AdhesionLaw, optional
        The sweep is adhesive: the loading approaches are solved again with this law at
        the same rigid planes, and with ``unload`` the unloading branch to the pull-off.
    kernel, tol, **options
        The sweep's solver options (:func:`roughfe.bem.contact_sweep`: ``solver``,
        ``hardness``, ``coarse_correction``, ``max_iter``; adhesive: ``max_iter``,
        ``spring``); ``unload`` of a non-adhesive sweep is not repeated (its loading
        steps are compared).
    """
    factor = check_int("grid check factor (an integer >= 2)", factor, 2)
    if not isinstance(sweep, SweepResult):
        raise InputError(f"grid_check compares a SweepResult, got {type(sweep).__name__}")
    if any(r.method != "bem" for r in sweep.results):
        raise InputError("the grid check solves the BEM on the refined surface: a FEM "
                         "sweep's grid is its mesh (refine the mesh)")
    fine_surface = refined(surface, factor)
    loading = [i for i, r in enumerate(sweep.results) if not r.unloading]
    if adhesion is not None:
        return _adhesive(surface, fine_surface, material, sweep, loading, factor,
                         adhesion, unload, kernel, tol, options)
    from .sweep import contact_sweep
    steps = [i for i in loading if sweep.results[i].mean_pressure > 0
             and 0 < sweep.results[i].area_fraction < 1]
    if not steps:
        raise InputError("the grid check compares steps in partial contact under a "
                         "positive load: this sweep has none")
    p = [float(sweep.results[i].mean_pressure) for i in steps]
    order = np.argsort(p, kind="stable")     # warm starts go up in load
    fine = contact_sweep(fine_surface, material, pressures=[p[k] for k in order],
                         kernel=kernel, **({} if tol is None else {"tol": tol}), **options)
    back = np.empty(len(steps), int)
    back[order] = np.arange(len(steps))
    fine_results = [fine.results[k] for k in back]
    return _result(factor, fine_surface, steps, sweep, fine_results,
                   ("area_fraction", "stiffness", "mean_gap"))


def _adhesive(surface, fine_surface, material, sweep, loading, factor, law, unload,
              kernel, tol, options):
    from .adhesion import adhesive_sweep
    rise = float(fine_surface.heights.max() - surface.heights.max())
    deltas = [float(sweep.results[i].delta) + rise for i in loading]
    fine = adhesive_sweep(fine_surface, material, law, deltas, unload=unload, kernel=kernel,
                          **({} if tol is None else {"tol": tol}), **options)
    pull = ({"pull_off_pressure": (sweep.pull_off_pressure, fine.pull_off_pressure)}
            if unload else {})
    # at an imposed approach the mean gap of a periodic cell is imposed too (mean u = 0):
    # the load is the answer
    return _result(factor, fine_surface, loading, sweep, fine.sweep.results[:len(loading)],
                   ("area_fraction", "mean_pressure"), pull)


def _result(factor, fine_surface, steps, sweep, fine_results, quantities, whole=None):
    """The GridCheck of the coarse ``steps`` against ``fine_results`` (one per step);
    ``whole``: values of the whole sweep, ``{quantity: (coarse, fine)}``."""
    coarse = [sweep.results[i] for i in steps]
    pick = (lambda rs, q: np.array([getattr(r, q) for r in rs], float))
    values = {q: (pick(coarse, q), pick(fine_results, q)) for q in quantities}
    values.update({q: (np.array([a], float), np.array([b], float))
                   for q, (a, b) in (whole or {}).items()})
    return GridCheck(factor=factor, shape=tuple(fine_surface.shape),
                     steps=np.asarray(steps, int),
                     mean_pressure=pick(coarse, "mean_pressure"), delta=pick(coarse, "delta"),
                     coarse={q: a for q, (a, _) in values.items()},
                     fine={q: b for q, (_, b) in values.items()})
