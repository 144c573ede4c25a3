"""The percolation and leakage study of thesis Sec. 2.4.2-2.4.5.

RMD surfaces of lateral size L (0.1 mm), fractal dimensions D in {2.1, ..., 2.9} with the
same seed across D (and across resolutions m = 2..8), loaded by the BEM in ``n_steps``
equal approach steps from first contact to ``Delta = h_s`` (the peak-to-valley height);
at each step the free-volume network (Alg. 1: V*, V_p*, V_np*), the spectral moments of
the deformed topography (m0*, m2*) and the Reynolds leak rate.

:func:`leakage_task` is the pure per-task function (one surface, all steps) that the
study runner of :mod:`roughfe.study` executes (analysis ``"leakage"``), and
:func:`summarise` turns the records of many tasks into means, standard deviations and
the fits of Eq. 2.17.
"""
from __future__ import annotations

import collections
from typing import Iterable, Optional

import numpy as np

from ..bem import Material
from ..bem.memory import check_sweep_memory
from ..errors import InputError
from ..surfaces.rmd import rmd_surface
from ..surfaces.stats import spectral_moments
from ..surfaces.surface import SIZE_RANGE, Surface
from .analysis import leakage_sweep

#: thesis values (Sec. 2.4): fractal dimensions and resolutions
THESIS_D = (2.1, 2.3, 2.5, 2.7, 2.9)
THESIS_M = (2, 3, 4, 5, 6, 7, 8)

#: keys averaged by :func:`summarise` per (D, m, step)
AVERAGED = ("delta_star", "separation_star", "area_fraction", "mean_pressure",
            "free_volume_star", "percolating_volume_star", "trapped_volume_star",
            "m0_star", "m2_star", "leak_rate", "hydraulic_aperture")


def leakage_task(D: float, m: int, seed: int, n_steps: int = 6, L: float = 1.0e-4,
                 E: float = 1.0e9, nu: float = 0.3, mu: float = 1.0e-3,
                 pressure_drop: float = 1.0, reynolds: bool = True,
                 direction: str = "both", kernel: str = "auto") -> list:
    """Leakage of one RMD surface over ``n_steps`` approach steps (Sec. 2.4).

    Parameters
    ----------
    D : float
        Fractal dimension in (2, 3).
    m : int
        RMD resolution: ``2**m + 1`` points per side.
    seed : int
        Seed of the RMD generator (keep it fixed across D and m, as the thesis does).
    n_steps : int
        Approaches ``Delta_k = k h_s / n_steps``, k = 1..n_steps (m), ``h_s`` the
        peak-to-valley height (the thesis' six "equipoised" steps up to ``Delta = h_s``;
        ``Delta = 0`` is the single-point first contact and is not solved).
    L : float
        Lateral size in m (RMD nodes span L end to end).
    E, nu : float
        Young's modulus (Pa) and Poisson ratio of the elastic body (rigid counterpart).
    mu : float
        Viscosity (Pa s) for the Reynolds solve.
    pressure_drop : float
        ``p_in - p_out`` in Pa (the leak rate is proportional to it).
    reynolds : bool
        Solve the Reynolds equation at every step (False: network only).
    direction : {"x", "y", "both"}
        Flow directions (the thesis unites both).
    kernel : str
        BEM influence operator (see :func:`roughfe.bem.solve_contact`).

    Returns
    -------
    list of dict
        One JSON-safe record per step with ``D, m, seed, step, delta, delta_star,
        mean_pressure, area_fraction, mean_plane_separation, separation_star (d/sigma),
        m0_star, m2_star`` and the fields of :meth:`LeakageResult.record`
        (``free_volume_star``, ``percolating_volume_star``, ``trapped_volume_star``,
        ``percolates_x/y``, ``percolates_reynolds_x/y``, ``leak_rate``, ...).
    """
    material = leakage_inputs(D=D, m=m, n_steps=n_steps, L=L, E=E, nu=nu, mu=mu,
                              pressure_drop=pressure_drop, reynolds=reynolds,
                              direction=direction, kernel=kernel)
    n_steps = int(n_steps)
    surface = rmd_surface(int(m), float(D), float(L), rng=int(seed))
    sigma = float(np.std(surface.heights))
    h_s = float(np.ptp(surface.heights))
    m0_ref, m2_ref, _ = spectral_moments(surface)
    deltas = h_s * np.arange(1, n_steps + 1) / n_steps
    sweep = leakage_sweep(surface, material, deltas=deltas, kernel=kernel,
                          direction=direction, mu=mu, pressure_drop=pressure_drop,
                          reynolds=reynolds, sigma=sigma)
    records = []
    for rec, c in zip(sweep.records(), sweep.contacts):
        # deformed topography of the elastic rough body seen from the rigid plane: the gap
        m0, m2, _ = spectral_moments(Surface(c.gap, surface.size, surface.periodic))
        rec.update({"D": float(D), "m": int(m), "seed": int(seed),
                    "delta_star": float(c.delta / h_s),
                    "separation_star": float(c.mean_plane_separation / sigma),
                    "m0_star": float(m0 / m0_ref), "m2_star": float(m2 / m2_ref)})
        records.append(rec)
    return records


def _fit_g(v_star, vp_star):
    """Least-squares slope through the origin of ``V_p* = g V*`` (Eq. 2.17a)."""
    den = float(np.dot(v_star, v_star))
    return float(np.dot(v_star, vp_star) / den) if den > 0 else None


def _fit_beta(v_star, vnp_star):
    """``V_np* = (V*)^beta`` (Eq. 2.17b) fitted in log-log through the origin.

    Only points with ``0 < V* < 1`` and ``V_np* > 0`` enter (the power law has no
    information at ``V* = 1`` and a zero trapped volume has no logarithm).
    """
    v, w = np.asarray(v_star, float), np.asarray(vnp_star, float)
    ok = (v > 0) & (v < 1) & (w > 0)
    if ok.sum() < 1:
        return None, int(ok.sum())
    x, y = np.log(v[ok]), np.log(w[ok])
    return float(np.dot(x, y) / np.dot(x, x)), int(ok.sum())


def _stats(values):
    vals = np.array([v for v in values if v is not None], dtype=float)
    if vals.size == 0:
        return None, None
    return float(vals.mean()), float(vals.std(ddof=1)) if vals.size > 1 else 0.0


def leakage_inputs(*, D, m, n_steps, L, E, nu, mu, pressure_drop, reynolds, direction,
                   kernel):
    """The input check of :func:`leakage_task` (its keywords without ``seed``): the RMD
    parameters, the step count, the fluid and the flow directions checked, the
    :class:`Material` returned; no surface is generated (the study runner calls it on
    every task before submitting any, :func:`roughfe.study.analyses.check_parameters`)."""
    from ..bem.operators import check_kernel_name
    from ..errors import check_finite_positive, check_in_open_interval, check_int
    from ..surfaces.rmd import _check_m
    from .analysis import _direction_list

    check_in_open_interval("D (fractal dimension)", D, 2.0, 3.0)
    _check_m(m)
    check_int("n_steps", n_steps, 1)
    check_finite_positive("L (m)", L)
    from ..surfaces.surface import _as_size
    _as_size(L, 1)      # the surfaces' size range (1e308 failed every task on the workers)
    span = L * (2 ** m + 1) / 2 ** m        # the RMD nodes' size, (2^m + 1) L / 2^m
    if span > SIZE_RANGE[1]:                # L = 1e6 m passed and failed every task
        raise InputError(f"L = {L:g} m with m = {m}: the RMD surface spans (2^m + 1) / 2^m L "
                         f"= {span:g} m, beyond the largest lateral size {SIZE_RANGE[1]:g} m")
    check_finite_positive("mu (Pa s)", mu)
    if not isinstance(reynolds, (bool, np.bool_)):
        raise InputError(f"reynolds must be true or false, got {reynolds!r}")
    # the Reynolds solve's own rule (no wall velocity here: > 0), and the junction leak
    # rate's without Reynolds too (a negative drop gave negative junction leak rates)
    check_finite_positive("pressure_drop (Pa)", pressure_drop)
    _direction_list(direction)
    check_kernel_name(kernel)
    # the fields the sweep keeps; last, after every check of the values (a study on a
    # remote scheduler notes this machine's shortage and goes on: runner.run_study)
    check_sweep_memory((2 ** int(m) + 1,) * 2, int(n_steps))
    return Material(E, nu)


def summarise(records: Iterable[dict]) -> dict:
    """Means, standard deviations and fits over the records of many :func:`leakage_task` runs.

    Parameters
    ----------
    records : iterable of dict
        Step records (each with ``D``, ``m``, ``step`` and the leakage fields).

    Returns
    -------
    dict
        JSON-safe: ``curves`` -- one entry per (D, m, step) with ``n`` and
        ``<key>_mean``/``<key>_std`` for :data:`AVERAGED` (Fig. 14-15, 19-22 and Q vs A*);
        ``fits`` -- per (D, m) the slope ``g`` of ``V_p* = g V*`` and the exponent
        ``beta`` of ``V_np* = (V*)^beta`` (Eq. 2.17, Fig. 24; the thesis writes the
        dimensional ``V_np``, which cannot be a power of a dimensionless number: we use
        ``V_np*``) with the thesis' approximation ``1 - beta/10`` beside ``g``;
        ``percolation`` -- how often the network (its corner rule) and the Reynolds
        scheme disagree on "percolates" (never with the defaults: FV and
        ``corner_rule="closed"``).
    """
    records = list(records)
    if not records:
        raise InputError("summarise needs at least one record")
    groups = collections.defaultdict(list)
    sets = collections.defaultdict(list)
    for r in records:
        groups[(float(r["D"]), int(r["m"]), int(r["step"]))].append(r)
        sets[(float(r["D"]), int(r["m"]))].append(r)
    curves = []
    for (D, m, step), rs in sorted(groups.items()):
        row = {"D": D, "m": m, "step": step, "n": len(rs)}
        for key in AVERAGED:
            row[f"{key}_mean"], row[f"{key}_std"] = _stats(r.get(key) for r in rs)
        curves.append(row)
    fits = []
    for (D, m), rs in sorted(sets.items()):
        v = np.array([r["free_volume_star"] for r in rs], float)
        vp = np.array([r["percolating_volume_star"] for r in rs], float)
        vnp = np.array([r["trapped_volume_star"] for r in rs], float)
        beta, n_beta = _fit_beta(v, vnp)
        fits.append({"D": D, "m": m, "n_records": len(rs), "g": _fit_g(v, vp),
                     "beta": beta, "n_beta_points": n_beta,
                     "one_minus_beta_over_10": None if beta is None else 1.0 - beta / 10.0})
    n_cmp = n_dis = 0
    disagreements = []
    for r in records:
        for d in ("x", "y"):
            a, b = r.get(f"percolates_{d}"), r.get(f"percolates_reynolds_{d}")
            if a is None or b is None:
                continue
            n_cmp += 1
            if bool(a) != bool(b):
                n_dis += 1
                disagreements.append({"D": r["D"], "m": r["m"], "seed": r.get("seed"),
                                      "step": r["step"], "direction": d,
                                      "network": bool(a), "reynolds": bool(b)})
    return {"n_records": len(records), "curves": curves, "fits": fits,
            "percolation": {"n_compared": n_cmp, "n_disagree": n_dis,
                            "fraction_disagree": (n_dis / n_cmp) if n_cmp else None,
                            "disagreements": disagreements}}


#: most replicas (surfaces per D and m) of :func:`study_grid`: 500 x the thesis' 20 (at
#: the thesis' m = 8, one task is a BEM sweep of seconds to minutes); 10^11 built the
#: list of replicas first and ended in "not enough memory" (round 2, session 33)
MAX_SURFACES = 10000


def study_grid(D: Optional[Iterable[float]] = None, m: Optional[Iterable[int]] = None,
               n_surfaces: int = 2) -> dict:
    """The study spec grid of Sec. 2.4: D, m and ``replica`` (one seed per replica,
    the same across D and m). Defaults: the thesis' D and m; ``n_surfaces`` replicas
    (the thesis uses 20; at most :data:`MAX_SURFACES`)."""
    n = int(n_surfaces)
    if not 1 <= n <= MAX_SURFACES:
        raise InputError(f"n_surfaces (surfaces per D and m; `roughfe leak-study "
                         f"--surfaces`) must be an integer in 1..{MAX_SURFACES} (the thesis "
                         f"used 20), got {n_surfaces!r}")
    return {"D": [float(d) for d in (THESIS_D if D is None else D)],
            "m": [int(k) for k in (THESIS_M if m is None else m)],
            "replica": list(range(n))}
