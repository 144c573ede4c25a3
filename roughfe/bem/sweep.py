"""Warm-started loading sweeps: A(p), K(p), V*(d/sigma) (thesis Sec. 2.2.2-2.2.3).

:func:`contact_sweep` solves a sequence of approaches Delta (default: ``n_steps``
equispaced from h_pv/n to the peak-to-valley height h_pv, as in the thesis; for a
periodic surface up to max h - mean h, where contact becomes full) or of mean
pressures, each step starting from the previous one (:func:`contact_sweep`). The
result type is the one :class:`roughfe.model.SweepResult` (re-exported here with
:data:`RECORD_KEYS` and :func:`central_differences`).
"""
from __future__ import annotations

import dataclasses

import numpy as np

from .. import progress
from ..errors import InputError
from ..model import RECORD_KEYS, Loading, Material, SweepResult, central_differences
from ..surfaces.stats import rms_slope
from ..surfaces.surface import Surface
from .contact import _check_surface, _choose_kernel, _coarse_start, solve_contact
from .memory import check_sweep_memory

__all__ = ["contact_sweep", "default_deltas", "SweepResult",
           "RECORD_KEYS", "central_differences"]

def default_deltas(surface: Surface, n_steps: int, periodic: bool) -> np.ndarray:
    """``n_steps`` equispaced approaches k/n * Delta_max, k = 1..n (m): Delta_max is the
    peak-to-valley height, or max h - mean h (full contact) with a periodic kernel."""
    h = surface.heights
    top = float(h.max() - h.mean()) if periodic else float(np.ptp(h))
    return top * np.arange(1, n_steps + 1) / n_steps


def _predicted_pressure(results, target, key, branch):
    """Initial pressure (Pa) of the next step of a sweep, or None (cold start).

    The previous step's pressure; on an elastic sweep in the approach (no hardness, no
    unloading branch) after two steps with contact, the secant extrapolation
    p_j + (Delta - Delta_j) / (Delta_j - Delta_{j-1}) (p_j - p_{j-1}), clipped at 0: the
    contact patches grow between steps, and the predictor moves their pressure along.
    Only the start changes: every step is solved to the same tolerance. Measured on the
    20-step sweeps of 256^2 partial sums of a measured surface (di-1.di, Love kernel):
    11-12 % fewer CG iterations (598 -> 532, 622 -> 544).
    """
    if not results or not results[-1].n_contact:
        return None
    last = results[-1]
    if branch or key != "delta" or len(results) < 2 or not results[-2].n_contact:
        return last.pressure
    before = results[-2]
    step = last.delta - before.delta
    if not step > 0:
        return last.pressure
    p = last.pressure - before.pressure
    p *= (float(target) - last.delta) / step
    p += last.pressure
    np.maximum(p, 0.0, out=p)
    return p


def contact_sweep(surface: Surface, material: Material, *, n_steps: int = 20, deltas=None,
                  pressures=None, kernel: str = "auto", solver: str = "auto",
                  tol: float = 1e-10, max_iter=None, compute_stiffness: bool = True,
                  hardness=None, unload: bool = False,
                  coarse_correction=None) -> SweepResult:
    """Warm-started sequence of contact solutions.

    Elastic load-controlled steps on a periodic surface (2D, >= 256 points per axis)
    start from the coarse-to-fine chain of :func:`roughfe.bem.contact._coarse_start`,
    each grid level corrected by its own solution of the previous step; other steps
    from the previous pressure, elastic steps in the approach from the secant
    extrapolation of the two previous ones (:func:`_predicted_pressure`); on a periodic
    2D surface such a step is solved through load control, the load moved to the
    imposed approach inside the solve (:mod:`roughfe.bem.approach`: the default
    20-step sweep 2.1-3.0x faster at 512^2-2048^2). Measured
    (H = 0.8 surfaces of ``benchmarks/bench_bem.py``, p/E* = 0.005, 0.01, 0.05, 0.1, tol
    1e-10, against 4 cold solves): fine iterations 512^2 147 -> 142, 1024^2 94 -> 93,
    2048^2 115 -> 112, CPU even within the noise (docs/theory/02b_bem_performance.md);
    the previous pressure alone had made the sweep dearer than cold (159, 121, 147
    iterations; 2048^2 593 against 503 convolution-equivalents): loads 2-5x apart
    open new contact patches, which the fine CG then has to find. With a ``hardness``
    the plastic displacement is carried from step to step (it is permanent);
    ``unload`` appends the unloading
    branch: the same steps in reverse order, below the highest one, with the plastic
    displacement of the loading branch (its steps have ``unloading=True``).

    Parameters
    ----------
    surface, material, kernel, solver, tol, max_iter, compute_stiffness, coarse_correction
        As in :func:`roughfe.bem.solve_contact`.
    n_steps : int
        Number of equispaced approaches (default 20, as in the thesis) when neither
        ``deltas`` nor ``pressures`` is given.
    deltas : sequence of float, optional
        Approaches Delta >= 0 (m), solved in the order given (negative ones, apart:
        :func:`roughfe.bem.adhesion.adhesive_sweep`).
    pressures : sequence of float, optional
        Mean pressures > 0 (Pa), solved in the order given.
    hardness : float, optional
        H_p (Pa) of a perfectly plastic interface (see :func:`roughfe.bem.solve_contact`).
    unload : bool
        Append the unloading branch.
    """
    _check_surface(surface)
    if deltas is not None and pressures is not None:
        raise InputError("give at most one of deltas (m) or pressures (Pa)")
    # one validation of the loading for every method (roughfe.model.Loading)
    loading = (Loading(deltas=deltas) if deltas is not None else
               Loading(pressures=pressures) if pressures is not None else
               Loading(n_steps=n_steps))
    loading.require_contact()      # approaches apart: adhesion only (adhesive_sweep)
    n_load = (loading.n_steps if loading.kind == "n_steps" else
              len(np.atleast_1d(getattr(loading, loading.kind))))
    periodic = _choose_kernel(surface, kernel) == "spectral"     # the kernel's grid
    check_sweep_memory(surface.shape, 2 * n_load - 1 if unload else n_load, periodic)
    if loading.kind == "n_steps":
        deltas = default_deltas(surface, loading.n_steps, periodic)
    else:
        deltas = getattr(loading, loading.kind)
    key = "mean_pressure" if loading.controls_pressure else "delta"
    steps = [(float(v), False) for v in deltas]
    if unload and np.any(np.diff(np.asarray(deltas, dtype=float)) <= 0):
        # the branch below the highest step: given 3, 2, 1 um the unloading steps were
        # flagged as loading and the reloading 1 -> 3 um as unloading
        raise InputError(f"unload appends the unloading branch (the steps in reverse order "
                         f"below the highest one): give the loading branch, increasing "
                         f"{'mean pressures' if key == 'mean_pressure' else 'approaches'}, "
                         f"got {[float(v) for v in deltas]}")
    if unload:
        steps += [(float(v), True) for v in deltas[-2::-1]]
    branch = unload or hardness is not None
    results = []
    plastic = None
    # elastic load-controlled steps on the periodic kernel: the coarse-to-fine start of
    # every grid level corrected by that level's previous solution (_coarse_start)
    levels = ({} if key == "mean_pressure" and not branch and solver in ("auto", "pk")
              else None)
    for v, unloading in progress.iterate(steps, "BEM load steps"):
        initial = None if levels is None else _coarse_start(
            surface, material, v, None, levels, coarse_correction, kernel)
        if initial is None:
            initial = _predicted_pressure(results, v, key, branch)
        r = solve_contact(surface, material, **{key: v}, kernel=kernel, solver=solver,
                          tol=tol, max_iter=max_iter, initial=initial,
                          compute_stiffness=compute_stiffness, hardness=hardness,
                          plastic_displacement=plastic,
                          coarse_correction=coarse_correction)
        if branch:
            r = dataclasses.replace(r, unloading=unloading)
        results.append(r)
        plastic = r.plastic_displacement
        if levels is not None:
            levels[surface.shape] = r.pressure
    return SweepResult.from_results(results, rms_slope=rms_slope(surface),
                                    length=surface.size[0])
