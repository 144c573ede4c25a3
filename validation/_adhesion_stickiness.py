"""The stickiness cases of ``validation/adhesion_maugis.py``: the Pastewka-Robbins
criterion, Eq. (10) (:mod:`roughfe.theory.stickiness`), against the adhesive BEM's verdict
on rough surfaces (:func:`stickiness_cases`), and the criterion's domain without adhesion
(:func:`bandwidth_scan`, docs/theory/07_adhesion_persson.md, "The criterion's domain").

Lengths in m, pressures in Pa, works of adhesion in J/m^2; wavenumbers in units of
q0 = 2 pi / L. Imported by the study script (a helper module, not a study of its own).
"""
import time
from dataclasses import dataclass

import numpy as np

from roughfe.bem import solve_contact
from roughfe.bem.adhesion import AdhesionLaw, adhesive_sweep
from roughfe.model import Material
from roughfe.surfaces.spectral import spectral_surface
from roughfe.surfaces.stats import rms_slope
from roughfe.surfaces.surface import Surface
from roughfe.theory.stickiness import KAPPA_REP, load_balance, pastewka_robbins

STICKY_AREA = 0.01     # A* at which the secant of A*(p) is read (the proportional prefactor)
STICKY_WINDOW = (0.005, 0.02)   # small-load window of the tangent dp/dA* (cross-check)
STICKY_FACTORS = (1 / 16, 1 / 8, 1 / 4, 1 / 2, 2.0)   # w / w_PR (C = 1 at w_PR: not sampled)
STICKY_THINNER = (0.5, 0.25)   # shorter ranges / Delta_r of the thinner-ring check


@dataclass(frozen=True)
class StickySurface:
    """One surface family of the stickiness comparison (periodic self-affine, H = 0.8,
    10 nm rms, L = 10 um; lengths in m, wavenumbers in units of q0 = 2 pi / L).

    ``roll_off`` q_r / q0 and ``bandwidth`` q_s / q_r of the PSD; ``grids`` (seed, grid
    sides), the surface generated on the finest and sampled exactly on the coarser ones;
    the range Delta_r is ``range`` (m) or, when ``range_over_edge_gap`` is set, that
    multiple of g0 = (16/3) h'^2 / h'' of the finest grid's surface (Monti, Sanner &
    Pastewka 2021); ``approaches`` None loads in 12 steps from 0.05 to 0.5 of the highest
    peak, else (lo, hi, steps): ``steps`` approaches from lo to hi times the non-adhesive
    approach at A* = STICKY_AREA (the steps where the secant is read); ``unload`` traces
    the unloading branch to separation on the coarsest grid (pull-off, reported)."""

    label: str
    roll_off: float
    bandwidth: float
    grids: tuple
    range: float = None
    range_over_edge_gap: float = None
    approaches: tuple = None
    unload: bool = False


#: the narrow band of sessions 4-5: Delta_r = h_rms / 2, Delta_r / g0 = 0.15 (outside the
#: criterion's domain); reported, not a target (docs/theory/07_adhesion_persson.md)
STICKY_NARROW = StickySurface("narrow band (q_s/q_r = 16, Delta_r = 5 nm)", 2.0, 16.0,
                              ((3, (128, 256)), (4, (128, 256))), range=5e-9, unload=True)
#: inside the criterion's domain: a wide band, Delta_r / g0 = 0.06 (< 0.1), h_rms / Delta_r
#: ~ 20; 4 cells per shortest wavelength (ring ~1.4 cells; the 8-cell check is in docs/07)
STICKY_WIDE = StickySurface("wide band (q_s/q_r = 128, Delta_r / g0 = 0.06)", 1.0, 128.0,
                            ((3, (512,)), (4, (512,))), range_over_edge_gap=0.06,
                            approaches=(0.35, 1.35, 8))


def _branch(results):
    """(A*, p) of the states with contact, sorted by area (a loading branch)."""
    return np.array(sorted((r.area_fraction, r.mean_pressure) for r in results if r.n_contact)).T


def _pressure_at_area(results, area):
    """Mean pressure (Pa) at the area fraction ``area``, interpolated along a loading
    branch; when the branch jumped into contact beyond ``area`` the pressure of its
    smallest contact state (the secant's sign is what is read)."""
    a, p = _branch(results)
    return float(np.interp(area, a, p))


def _tangent(results, window=STICKY_WINDOW):
    """Least-squares line ``p = p0 + s A*`` through the loading states with A* in
    ``window``: the tangent s (Pa) of the area-load line at small load and the load p0
    (Pa) at which its area vanishes; NaN when fewer than 3 states lie in the window
    (the branch jumped into contact beyond it)."""
    a, p = _branch(results)
    m = (a >= window[0]) & (a <= window[1])
    if m.sum() < 3:
        return float("nan"), float("nan"), int(m.sum())
    s, p0 = np.polyfit(a[m], p[m], 1)
    return float(s), float(p0), int(m.sum())


def _threshold(works, s_bem):
    """Work of adhesion (J/m^2) at which S_BEM crosses 1, interpolated in log w between
    the bracketing cases (NaN when the cases do not bracket it)."""
    pts = [(w, s) for w, s in zip(works, s_bem) if np.isfinite(s)]
    for (w0, s0), (w1, s1) in zip(pts, pts[1:]):
        if s0 < 1.0 <= s1:
            return float(np.exp(np.interp(1.0, [s0, s1], np.log([w0, w1]))))
    return float("nan")


def _at_area(elastic, values, area=STICKY_AREA):
    """``values`` (one per elastic state) interpolated at the area fraction ``area``."""
    a = np.array([r.area_fraction for r in elastic])
    order = np.argsort(a)
    return float(np.interp(area, a[order], np.asarray(values, float)[order]))


def _approaches(surface, mat, case):
    """Loading approaches (m) of ``case`` on ``surface`` (see :class:`StickySurface`)."""
    if case.approaches is None:
        return np.linspace(0.05, 0.5, 12) * float(surface.heights.max() - surface.heights.mean())
    lo, hi, steps = case.approaches
    return np.linspace(lo, hi, steps) * _states_near_area(surface, mat)[-1].delta


def _states_near_area(surface, mat, extra_if_off=None):
    """Non-adhesive load-controlled states that bracket A* = STICKY_AREA: the first at
    p = STICKY_AREA h'_rms E* / KAPPA_REP, the second one secant step on (A* ~ p), and a
    third when ``extra_if_off`` is given and the second misses STICKY_AREA by more than
    that relative amount."""
    p = STICKY_AREA * rms_slope(surface) * mat.E_star / KAPPA_REP
    states = []
    while len(states) < 2 or (extra_if_off is not None and len(states) < 3 and abs(
            states[-1].area_fraction / STICKY_AREA - 1) > extra_if_off):
        states.append(solve_contact(surface, mat, mean_pressure=p, compute_stiffness=False))
        p *= STICKY_AREA / states[-1].area_fraction
    return states


def stickiness_cases(case=STICKY_WIDE, factors=STICKY_FACTORS):
    """Pastewka-Robbins Eq. (10) against the adhesive BEM on rough surfaces.

    Periodic self-affine surfaces of the family ``case`` (:class:`StickySurface`: H = 0.8,
    10 nm rms, L = 10 um, roll-off and cut-off of the case; one realisation per seed,
    generated on the finest grid and sampled exactly on the coarser ones), E* = 1.33 MPa,
    Maugis-Dugdale law of range Delta_r, works of adhesion ``factors`` x w_PR (the work
    at which Eq. (10) gives C = 1).

    BEM verdict: the sign of the prefactor of the area-load line (Pastewka & Robbins'
    abstract: the area is initially proportional to the load, the prefactor changes sign
    when the surfaces become sticky), read as the secant at A* = 1 %: sticky when the
    loading branch needs a tensile or zero mean pressure to hold A* = 1 %,
    ``p_adh(1 %) <= 0``; ``S_BEM = 1 - p_adh / p_el`` at that area (against the
    non-adhesive sweep; sticky iff S_BEM >= 1) and its threshold w_BEM (S_BEM = 1,
    interpolated in log w). Cross-checks: the tangent ``dp/dA*`` over A* in
    ``STICKY_WINDOW`` (``S_tan = 1 - s_adh / s_el``, threshold w_tan; its intercept is the
    load at which the area vanishes); the load balance behind Eq. (10) with the
    attractive area measured on the non-adhesive contact at A* = 1 %
    (:func:`roughfe.theory.stickiness.load_balance`, threshold w_LB), against the thin
    Hertzian ring Eq. (10) assumes (also for the shorter ranges ``STICKY_THINNER`` x
    Delta_r). The pull-off pressure of the unloading branch (growing steps until
    separation) is reported beside it on the coarsest grid when ``case.unload``: a finite
    pull-off is not the paper's criterion (Ciavarella & Papangelo 2018)."""
    mat = Material(1e6, 0.5)
    q0 = 2 * np.pi / 1e-5
    q_short = case.roll_off * case.bandwidth
    out = []
    for seed, ns in case.grids:
        fine = spectral_surface(max(ns), 1e-5, 0.8, rms_height=1e-8, q_roll=case.roll_off * q0,
                                q_short=q_short * q0, rng=seed)
        dr = (case.range if case.range_over_edge_gap is None else case.range_over_edge_gap
              * 1e-9 / pastewka_robbins(fine, mat.E_star, 1e-4, 1e-9).range_over_edge_gap)
        for n in ns:
            k = max(ns) // n
            s = Surface(fine.heights[::k, ::k], fine.size, periodic=True)
            t0 = time.process_time()
            deltas = _approaches(s, mat, case)
            elastic = [solve_contact(s, mat, delta=d, compute_stiffness=False) for d in deltas]
            p_el = _pressure_at_area(elastic, STICKY_AREA)
            s_el, p0_el, _ = _tangent(elastic)
            w_pr = 1e-4 * pastewka_robbins(s, mat.E_star, 1e-4, dr).criterion
            touching = [r for r in elastic if r.n_contact]
            ranges = []
            for rng_ in (dr,) + tuple(f * dr for f in STICKY_THINNER):
                lbs = [load_balance(r, rng_) for r in touching]
                pr_r = pastewka_robbins(s, mat.E_star, 1e-4, rng_)
                ranges.append({
                    "range": rng_, "range_over_edge_gap": pr_r.range_over_edge_gap,
                    "attractive_over_repulsive_measured": _at_area(
                        touching, [b.attractive_over_repulsive for b in lbs]),
                    "attractive_over_repulsive_ring": pr_r.attractive_over_repulsive,
                    "w_load_balance": _at_area(touching, [b.threshold_work for b in lbs]),
                    "w_pr": 1e-4 * pr_r.criterion})
            w_lb = ranges[0]["w_load_balance"]
            cases = []
            for f in factors:
                w = f * w_pr
                law = AdhesionLaw("md", w, dr)
                pr = pastewka_robbins(s, mat.E_star, w, dr)
                unloads = case.unload and n == min(ns)
                sw = adhesive_sweep(s, mat, law, deltas, unload=unloads, max_unload_steps=30)
                loading = [r for r in sw.sweep.results if not r.unloading]
                p_adh = _pressure_at_area(loading, STICKY_AREA)
                s_adh, p0_adh, n_win = _tangent(loading)
                first = min(r.area_fraction for r in loading if r.n_contact)
                cases.append({"work_of_adhesion": w, "w_over_w_pr": f,
                              "criterion_pastewka_robbins": pr.criterion,
                              "sticky_pastewka_robbins": pr.sticky,
                              "tabor_parameter": pr.tabor_parameter,
                              "pressure_adhesive_at_area": p_adh,
                              "stickiness_bem": 1.0 - p_adh / p_el,
                              "sticky_bem": bool(p_adh <= 0),
                              "agree": bool(pr.sticky == (p_adh <= 0)),
                              "tangent": s_adh, "tangent_states": n_win,
                              "pressure_at_vanishing_area": p0_adh,
                              "stickiness_tangent": 1.0 - s_adh / s_el,
                              "stickiness_load_balance": w / w_lb,
                              "jumped_in_beyond_area": bool(first > STICKY_AREA),
                              "pull_off_pressure": sw.pull_off_pressure if unloads else None,
                              "detached": sw.detached if unloads else None})
            print(f"stickiness {case.label}, seed {seed}, {n}^2: " + ", ".join(
                f"{c['w_over_w_pr']:g} w_PR: S_BEM {c['stickiness_bem']:.3f} / tangent "
                f"{c['stickiness_tangent']:.3f}" for c in cases), flush=True)
            works = [c["work_of_adhesion"] for c in cases]
            w_bem = _threshold(works, [c["stickiness_bem"] for c in cases])
            w_tan = _threshold(works, [c["stickiness_tangent"] for c in cases])
            kappa = STICKY_AREA * pr.rms_slope * mat.E_star / p_el
            out.append({"seed": seed, "n": n,
                        "cells_per_shortest_wavelength": n / (case.roll_off * case.bandwidth),
                        "rms_slope": pr.rms_slope, "rms_curvature": pr.rms_curvature,
                        "range": dr, "rms_height_over_range": 1e-8 / dr,
                        "ring_cells": pr.ring_width / (s.size[0] / n),
                        "ring_over_half_width": pr.ring_over_half_width,
                        "range_over_edge_gap": pr.range_over_edge_gap,
                        "tabor_parameter_at_w_pr": pastewka_robbins(
                            s, mat.E_star, w_pr, dr).tabor_parameter,
                        "pressure_elastic_at_area": p_el, "tangent_elastic": s_el,
                        "pressure_elastic_at_vanishing_area": p0_el,
                        "elastic_area_fractions": [r.area_fraction for r in elastic],
                        "kappa_rep_measured": kappa,
                        "w_pr": w_pr, "w_bem": w_bem, "w_bem_over_w_pr": w_bem / w_pr,
                        "w_tangent_over_w_pr": w_tan / w_pr,
                        "w_load_balance_over_w_pr": w_lb / w_pr,
                        "w_bem_over_w_load_balance": w_bem / w_lb,
                        # Eq. (10) with the measured kappa_rep: C ~ 1/kappa, w_PR ~ 2/kappa
                        "w_bem_over_w_pr_measured_kappa": w_bem / w_pr * kappa / KAPPA_REP,
                        # w_LB / w_PR = (kappa_rep / kappa) x ring / measured A_att / A_rep
                        "attractive_area_over_ring": ranges[0][
                            "attractive_over_repulsive_measured"] / ranges[0][
                            "attractive_over_repulsive_ring"],
                        "thinner_rings": ranges,
                        "cases": cases, "cpu_s": time.process_time() - t0})
    for seed, ns in case.grids:
        g = {r["n"]: r for r in out if r["seed"] == seed}
        for key in ("w_bem_over_w_pr", "w_tangent_over_w_pr", "w_load_balance_over_w_pr"):
            g[max(ns)]["refinement_" + key] = (g[max(ns)][key] / g[min(ns)][key] - 1
                                               if len(ns) > 1 else None)
    return {"label": case.label,
            "surface": f"periodic self-affine, H = 0.8, rms height 10 nm, L = 10 um, roll-off "
                       f"{case.roll_off:g} q0, cut-off {q_short:g} q0",
            "bandwidth": case.bandwidth, "E_star": mat.E_star, "factors": factors,
            "area_fraction": STICKY_AREA, "tangent_window": list(STICKY_WINDOW), "grids": out}


#: (q_s / q_r, roll-off / q0, seed, cells per shortest wavelength) of the bandwidth scan
BANDWIDTH_SCAN = tuple((b, 2.0, seed, 8) for b in (16, 32, 64, 128) for seed in (3, 4)) + tuple(
    (b, 2.0, seed, 4) for b in (128, 256, 512) for seed in (3, 4))


def bandwidth_scan(cases=BANDWIDTH_SCAN, range_over_edge_gap=0.06):
    """The criterion's domain, non-adhesive: at A* = STICKY_AREA, kappa_rep, the measured
    attractive area over Eq. (10)'s ring and w_LB / w_PR against the bandwidth q_s / q_r
    (docs/theory/07_adhesion_persson.md, "The criterion's domain"; not run by ``main``:
    the 4096^2 cases take ~40 s CPU and 2 GB each). Each surface (H = 0.8, 10 nm rms,
    L = 10 um) is generated on its own grid; Delta_r = ``range_over_edge_gap`` x g0; two
    load-controlled solves bracket A* (a third when the second misses it by > 3 %), and
    the quantities are interpolated linearly in A*."""
    mat = Material(1e6, 0.5)
    q0 = 2 * np.pi / 1e-5
    out = []
    for band, roll, seed, cells in cases:
        n = int(round(roll * band * cells))
        t0 = time.process_time()
        s = spectral_surface(n, 1e-5, 0.8, rms_height=1e-8, q_roll=roll * q0,
                             q_short=roll * band * q0, rng=seed)
        dr = range_over_edge_gap * 1e-9 / pastewka_robbins(
            s, mat.E_star, 1e-4, 1e-9).range_over_edge_gap
        pr = pastewka_robbins(s, mat.E_star, 1e-4, dr)
        states = _states_near_area(s, mat, extra_if_off=0.03)
        lbs = [load_balance(r, dr) for r in states]
        p_el = _at_area(states, [r.mean_pressure for r in states])
        att = _at_area(states, [b.attractive_over_repulsive for b in lbs])
        out.append({"bandwidth": band, "roll_off": roll, "seed": seed, "n": n,
                    "cells_per_shortest_wavelength": cells, "range": dr,
                    "rms_height_over_range": 1e-8 / dr,
                    "ring_cells": pr.ring_width / (1e-5 / n),
                    "kappa_rep_measured": STICKY_AREA * pr.rms_slope * mat.E_star / p_el,
                    "attractive_over_repulsive_measured": att,
                    "attractive_over_repulsive_ring": pr.attractive_over_repulsive,
                    "attractive_area_over_ring": att / pr.attractive_over_repulsive,
                    "w_load_balance_over_w_pr": _at_area(
                        states, [b.threshold_work for b in lbs]) / (1e-4 * pr.criterion),
                    "cpu_s": time.process_time() - t0})
        r = out[-1]
        print(f"bandwidth scan q_s/q_r {band:g} (roll-off {roll:g} q0), seed {seed}, {n}^2: "
              f"ring {r['ring_cells']:.1f} cells, h_rms/Delta_r "
              f"{r['rms_height_over_range']:.1f}, kappa_rep {r['kappa_rep_measured']:.2f}, "
              f"A_att/A_rep measured / ring {r['attractive_area_over_ring']:.2f}, w_LB/w_PR "
              f"{r['w_load_balance_over_w_pr']:.3f}, {r['cpu_s']:.1f} s CPU", flush=True)
    return out



def print_stickiness(study):
    """One line per grid of a :func:`stickiness_cases` study, then its ranges and works."""
    for g in study["grids"]:
        print(f"stickiness {study['label']}, seed {g['seed']} {g['n']}^2 (ring "
              f"{g['ring_cells']:.1f} cells, d/a {g['ring_over_half_width']:.2f}, Delta_r/g0 "
              f"{g['range_over_edge_gap']:.3f}, h_rms/Delta_r {g['rms_height_over_range']:.1f}, "
              f"kappa_rep {g['kappa_rep_measured']:.2f}, "
              f"A_att/A_rep measured / ring {g['attractive_area_over_ring']:.2f}): "
              f"w_PR {g['w_pr']:.3g}, w_BEM {g['w_bem']:.3g} J/m^2 "
              f"(ratio {g['w_bem_over_w_pr']:.3f}; tangent {g['w_tangent_over_w_pr']:.3f}; "
              f"load balance {g['w_load_balance_over_w_pr']:.3f}), {g['cpu_s']:.0f} s CPU",
              flush=True)
        for t in g["thinner_rings"]:
            print(f"    range {t['range']:.3g} m (range / g0 {t['range_over_edge_gap']:.3f}): "
                  f"A_att/A_rep measured "
                  f"{t['attractive_over_repulsive_measured']:.3f}, ring "
                  f"{t['attractive_over_repulsive_ring']:.3f}; w_LB / w_PR "
                  f"{t['w_load_balance'] / t['w_pr']:.3f}", flush=True)
        for c in g["cases"]:
            print(f"    w = {c['work_of_adhesion']:.3g} ({c['w_over_w_pr']:.3g} w_PR): C_PR "
                  f"{c['criterion_pastewka_robbins']:.3f}, S_BEM {c['stickiness_bem']:.3f}, "
                  f"sticky PR {c['sticky_pastewka_robbins']} / BEM {c['sticky_bem']}, "
                  f"pull-off {c['pull_off_pressure']}", flush=True)
