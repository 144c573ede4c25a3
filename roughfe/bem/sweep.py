"""Warm-started loading sweeps: A(p), K(p), V*(d/sigma) (thesis Sec. 2.2.2-2.2.3).

:func:`contact_sweep` solves a sequence of approaches Delta (default: ``n_steps``
equispaced from h_pv/n to the peak-to-valley height h_pv, as in the thesis; for a
periodic surface up to max h - mean h, where contact becomes full) or of mean
pressures, each step starting from the previous pressure.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..surfaces.stats import rms_slope
from ..surfaces.surface import Surface
from .contact import ContactResult, solve_contact
from .material import Material

RECORD_KEYS = ("delta", "load", "mean_pressure", "area_fraction", "n_contact", "stiffness",
               "stiffness_fd", "mean_gap", "mean_plane_separation", "free_volume",
               "free_volume_star", "iterations", "residual")


def central_differences(x, y):
    """dy/dx: (y[i+1] - y[i-1]) / (x[i+1] - x[i-1]) inside, one-sided at the ends; NaN
    where the spacing is zero (e.g. repeated full-contact steps) or fewer than 2 points."""
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    out = np.full(x.shape, np.nan)
    if x.size < 2:
        return out
    with np.errstate(divide="ignore", invalid="ignore"):
        out[1:-1] = (y[2:] - y[:-2]) / (x[2:] - x[:-2])
        out[0] = (y[1] - y[0]) / (x[1] - x[0])
        out[-1] = (y[-1] - y[-2]) / (x[-1] - x[-2])
    out[~np.isfinite(out)] = np.nan
    return out


@dataclass(frozen=True, eq=False)
class SweepResult:
    """A loading sweep (SI units).

    Attributes
    ----------
    results : tuple of ContactResult
        One solution per step.
    delta, mean_pressure, load, area_fraction, stiffness, mean_gap,
    mean_plane_separation, free_volume_star : ndarray
        The step values (see :class:`ContactResult`).
    stiffness_fd : ndarray
        K by central finite differences of mean_pressure over delta (Pa/m); agrees with
        the exact ``stiffness`` away from contact-set changes.
    load_star : ndarray
        P* = p L / (E* sigma), the thesis' dimensionless load (L = size along x).
    pressure_star : ndarray
        p / (E* gbar), gbar the rms slope.
    separation_star : ndarray
        d / sigma.
    rms_height, rms_slope, e_star : float
        sigma (m), gbar, E* (Pa).
    """

    results: tuple
    delta: np.ndarray
    mean_pressure: np.ndarray
    load: np.ndarray
    area_fraction: np.ndarray
    stiffness: np.ndarray
    stiffness_fd: np.ndarray
    mean_gap: np.ndarray
    mean_plane_separation: np.ndarray
    free_volume_star: np.ndarray
    load_star: np.ndarray
    pressure_star: np.ndarray
    separation_star: np.ndarray
    rms_height: float
    rms_slope: float
    e_star: float

    @property
    def success(self) -> bool:
        return all(r.success for r in self.results)

    @property
    def nit(self) -> int:
        return int(sum(r.nit for r in self.results))

    def to_records(self) -> list:
        """One JSON-safe dict per step with the keys ``RECORD_KEYS`` (SI; None for
        non-finite values such as the infinite stiffness at full periodic contact)."""
        recs = []
        for r, kfd in zip(self.results, self.stiffness_fd):
            s = r.scalars()
            rec = {k: s[k] for k in RECORD_KEYS if k in s}
            rec["stiffness_fd"] = float(kfd) if np.isfinite(kfd) else None
            rec["iterations"] = int(r.nit)
            recs.append({k: rec[k] for k in RECORD_KEYS})
        return recs


def default_deltas(surface: Surface, n_steps: int, periodic: bool) -> np.ndarray:
    """``n_steps`` equispaced approaches k/n * Delta_max, k = 1..n (m): Delta_max is the
    peak-to-valley height, or max h - mean h (full contact) with a periodic kernel."""
    h = surface.heights
    top = float(h.max() - h.mean()) if periodic else float(np.ptp(h))
    return top * np.arange(1, n_steps + 1) / n_steps


def contact_sweep(surface: Surface, material: Material, *, n_steps: int = 20, deltas=None,
                  pressures=None, kernel: str = "auto", solver: str = "auto",
                  tol: float = 1e-10, max_iter=None,
                  compute_stiffness: bool = True) -> SweepResult:
    """Warm-started sequence of contact solutions.

    Parameters
    ----------
    surface, material, kernel, solver, tol, max_iter, compute_stiffness
        As in :func:`roughfe.bem.solve_contact`.
    n_steps : int
        Number of equispaced approaches (default 20, as in the thesis) when neither
        ``deltas`` nor ``pressures`` is given.
    deltas : sequence of float, optional
        Approaches Delta >= 0 (m), solved in the order given.
    pressures : sequence of float, optional
        Mean pressures > 0 (Pa), solved in the order given.
    """
    if deltas is not None and pressures is not None:
        raise InputError("give at most one of deltas (m) or pressures (Pa)")
    if deltas is None and pressures is None:
        if int(n_steps) < 1:
            raise InputError(f"n_steps must be >= 1, got {n_steps!r}")
        periodic = surface.periodic and kernel in ("auto", "spectral")
        deltas = default_deltas(surface, int(n_steps), periodic)
    values = np.atleast_1d(np.asarray(deltas if pressures is None else pressures, float))
    if values.ndim != 1 or values.size == 0:
        raise InputError("deltas/pressures must be a non-empty 1D sequence")
    key = "delta" if pressures is None else "mean_pressure"
    results = []
    prev = None
    for v in values:
        r = solve_contact(surface, material, **{key: float(v)}, kernel=kernel, solver=solver,
                          tol=tol, max_iter=max_iter, initial=prev,
                          compute_stiffness=compute_stiffness)
        results.append(r)
        prev = r.pressure if r.n_contact else None
    arr = {k: np.array([getattr(r, k) for r in results], float)
           for k in ("delta", "mean_pressure", "load", "area_fraction", "stiffness",
                     "mean_gap", "mean_plane_separation", "free_volume_star")}
    sigma = results[0].rms_height
    gbar = rms_slope(surface)
    e = material.E_star
    return SweepResult(
        results=tuple(results), **arr,
        stiffness_fd=central_differences(arr["delta"], arr["mean_pressure"]),
        load_star=arr["mean_pressure"] * surface.size[0] / (e * sigma),
        pressure_star=arr["mean_pressure"] / (e * gbar),
        separation_star=arr["mean_plane_separation"] / sigma,
        rms_height=sigma, rms_slope=gbar, e_star=e)
