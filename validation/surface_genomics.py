"""Surface genomics: sequencing recovery over seeds, the noise table, chromosome
mechanics of the measured files, and surface design scores from a 2D genome database.

Run: ``roughfe validate surface-genomics`` (or ``make validate``); writes
``<outdir>/surface_genomics.md`` and ``surface_genomics.json`` (target rows in the schema
of :mod:`roughfe.validation`). ``--quick`` (``make validate-quick``, CI; 30-45 s CPU
measured) runs the reduced case named in its report: every row of (i)-(iii), (v) and the
designs' reproduction is the full run's target, judged; the design goals and design-run
CPU rows, set for the full budgets, are "not run" rows (``_targets``).

(i)   Exact recovery: MWM surfaces (M = 3 ridges, gamma = 1.8, H = 0.8, random lambda1,
      angles, anisotropy and phases per seed) realised at L and L/2.5 (N = 48) and
      sequenced over 5 seeds; genes and phases against the truth, acquisitions to round-off.
(ii)  Noise table: the same (2 seeds) with white noise of 0.1, 1 and 3 % of the rms height:
      M, largest angle error, gamma error and the misfit relative to the noise level.
(iii) Chromosome mechanics of the five measured files: band chromosomes (gamma = 2^(1/2),
      plane removed) on a grid thinned to <= 48 points per side, BEM curves of every band
      and TD/BU partial sum (8 approaches each); the bands sum exactly to the detrended
      surface, and the TD sum of all bands, swept as its own surface, has the complete
      surface's K(p) (c_n = 1 and K itself, to the bounds of SUM_CURVE_TOL).
(iv)  Surface design: a 2D genome database (``roughfe db build --dim 2``: 48 genomes,
      64 x 64 periodic realisations, M = 3 ridges, Sobol angles and anisotropy, H in
      [0.1, 1.5], E = 210 MPa, 10 approaches to 0.8 of full contact), period L that of the
      evenly mirrored x3p-2 window (259.7 um). Targets: K(p) and A(p) of (a) y_t1, a
      3-ridge genome outside the database, and (b) the measured x3p-2 (every fourth point,
      163 x 163 over the full 82.98 x 204.48 um, plane removed, evenly mirrored and solved
      with the periodic BEM on the database spacing: the designs' own setting, see
      docs/theory/surface-design.md; the window alone on the half-space is solved too, to
      check that its K is the interface in series with the window's bulk compliance).
      SOG/GCO/CCO on K, M-CCO on K and A; for x3p-2 the chromosome amplitudes matched to
      its spectrum (match_spectrum, + 3 matched database genomes; per wave for M-CCO); each
      followed by the search at the target pressures (phases and chromosome amplitudes;
      100 sweeps per candidate, 300 where that paid: SEARCH_LONG; x3p-2 M-CCO keeps its
      300 sweeps before the global stage, which keeps the start when it finds nothing
      better) and, for the runs in
      GLOBAL, the global stage (IPOP-CMA-ES, GLOBAL[run] batched strict evaluations of
      the best candidate, first step GLOBAL_SIGMA[run], chromosome amplitudes
      GLOBAL_AMPLITUDES[run], first population GLOBAL_POPSIZE[run] and the short waves'
      modulation by the long-wave height GLOBAL_MODULATION[run] where given).
      Goals (issue 15): s >= 0.98 on K and f >= 0.9 on K+A, scored at the target's own
      pressures (load-controlled BEM), every score reproduced from the saved design's
      heights by the hand-written Eq. 4.1 of design_study (the same BEM solver: a check
      of the scoring and of the saved design, not of the BEM); a design run < 30 min CPU.
(v)   The strict scoring path itself (``score_at_target_pressures``: Eq. 4.2, load
      control, K by Eq. 2.7, A by node count) on a surface with a closed form: an oblique
      cosine wave (Westergaard's problem along the wave) against Westergaard's K(p) and
      A(p) for twice its amplitude (Eq. 4.2 factor eta = 2), each score within the
      discretisation error measured at 256^2 (WESTERGAARD_SCORE). The reference owes
      nothing to the BEM or the designs; it does not see a pure scale of E* or of the
      kernel, which Eq. 4.2 removes by construction (``roughfe validate bem`` checks
      those).
"""
from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np
import scipy.optimize

from roughfe.genomics import database as gdb
from roughfe.genomics.design import (Design, GlobalSearchOptions, combined_score,
                                     target_surface, thesis_targets)
from roughfe.genomics.design.targets import score_at_target_pressures
from roughfe.genomics.similarity import Target as ResponseTarget
from roughfe.surfaces import Surface
from roughfe.surfaces.io import load_surface, save_surface
from roughfe.validation import (Target, percent, report_title, reported, skipped,
                               targets_markdown)
from roughfe.writers import write_json, write_text

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _design_checks import strict_scores_of_surface  # noqa: E402
from _surface_cases import (TOPOGRAPHIES, _cpu, _thinned, measured_mechanics,  # noqa: E402
                            measured_targets, noise_table, recovery, surface_database)
# GLOBAL is read from the study by tests/test_surface_genomics_study.py
from _surface_design_chain import (DIRECTIONAL, GLOBAL, SEARCH, SEARCH_LONG,  # noqa: E402, F401
                                   design_chain)

MEASURED = ("x3p-2.x3p", "sur-2.sur", "opd-1.opd", "plu-1.plu", "di-1.di")
GOAL_S, GOAL_F, RUN_CPU_S = 0.98, 0.9, 1800.0

#: x3p-2 (650 x 650) is solved on every fourth point (163 x 163, same size) as a target
X3P_POINTS = 163
#: nodes per side of the surface database (the cost of the whole study is set by the
#: shared 2-core machine: see the docs page), Sobol points (x 2 phase matrices) and the
#: H range: x3p-2 has H = 0.22-0.32, below the thesis range [0.5, 1.5]
DB_NODES, DB_POINTS, DB_HURST = 64, 24, (0.1, 1.5)
#: the TD sum of all bands against the complete surface (swept as its own surface by
#: band_mechanics; it was the complete surface's own curve, c_n = 1 by construction).
#: Their heights differ by the reconstruction error e (the "bands sum to the surface" row:
#: <= 1e-12 of the peak-valley ptp, measured 1-4e-16). To first order a height change of
#: at most e ptp moves the approach of each step Delta_j = j ptp / n by <= 4 e ptp (the
#: field, its first contact and its ptp), so p_j by <= 4 m n e relative (p ~ Delta^m,
#: m <= 4.3 on these curves), and each solve adds its relative KKT residual tau = 1e-10;
#: K_j = (p_{j+1} - p_{j-1}) / (2 ptp / n) (Eq. 2.7, central differences) turns that into
#: max |dK| / max K <= n (4 m n e + tau) (p_max <= K_max ptp on a convex p(Delta)): 8e-10
#: at n = 8, measured 3.2e-10 (x3p-2; 6e-13-7.5e-11 the other files). Pearson's c is
#: then 1 - c <= (max |dK| / std K)^2 / 2 <= 1e-16 (max K / std K <= 16.2, sur-2): the
#: round-off of the coefficient itself (measured 0 and 1.1e-16). Gates: 1 - c <= 1e-12
#: and max |dK| / max K <= 1e-6, each ~10^3 above what e and tau allow; K is gated as
#: well because c cannot see a sum off by a factor (K -> a K leaves c = 1). A is
#: reported, not gated: a node whose pressure is at the residual's level can enter or
#: leave the contact set, 1 / N^2 = 4.5e-4 of A at 47^2, unrelated to e.
SUM_CURVE_TOL = {"c": 1e-12, "K": 1e-6}
#: (v) the strict scoring path against Westergaard: the wave cos(2 pi (2 x + y) / L) of
#: amplitude 1 um on 256^2 (L the designs' period), 10 approaches to 0.8 of full contact,
#: targets the closed form for 2 um (eta = 2), K of the closed form by the same central
#: differences (Eq. 2.7; the exact derivative differs by 14 % at the one-sided ends).
#: Measured 1 - s on 64^2 / 128^2 / 256^2 (session 33): K 0.665 / 0.111 / 0.054 % (the
#: BEM's discretisation), A 13.6 / 8.2 / 4.2 % (the node count of the first load, A ~ 9 %:
#: a wave on an n^2 grid has n phase classes, so A moves in steps of 1/n); eta = 1 gives
#: the same to 3 digits. Tolerances just above the 256^2 numbers
WESTERGAARD_WAVE, WESTERGAARD_NODES = (2, 1), 256
WESTERGAARD_SCORE = {"K": 6e-4, "A": 0.045}
#: why the x3p-2 K rows (SOG, GCO, CCO: s >= GOAL_S) are NOT met since session 34, said by
#: their reason when they are (session 35, one run each of this study's chain on the
#: session-34 database; docs/theory/surface-design.md, "Session 35"). The target (41 x 100)
#: changed by its Nyquist line in y alone: Surface.resampled keeps it since 506c9a6; the old
#: target is the new one without it to 2e-15 of its rms, K per step to 2e-9. The same chain
#: on the old target gives SOG 0.9842032061, GCO 0.9841654508 and CCO 0.9822368650, the
#: session-28 numbers to every digit, so nothing else moved. On the new target the global
#: stage reaches the goal with a larger budget (one run each, seed 0, GLOBAL's other
#: settings): SOG 0.9759 at 8000 evaluations (the study's), 0.97992 at 16000, 0.98049 at
#: 24000 (1115 s CPU for the run);
#: CCO 0.9763 at 8000, 0.9806 at 12000, 0.98304 at 16000 (750 s); GCO stays at 0.9503 from
#: 6000 to 16000 (its IPOP runs stall, as in session 8, whose seeds 0-2 gave 0.9842-0.9471 on
#: the old target), from the start SOG and CCO take to the goal. GLOBAL is left as it is.
#: The target's K(p) at this spacing depends on where its nodes sit: the same band-limited
#: window on nodes moved by half a cell scores s 0.83 (y) / -0.97 (x) against it; the
#: Nyquist line is one such term (c cos(pi t) on nodes moved by t cells)
X3P_K_MISS = ("measured in session 35: the target moved in session 34 by its Nyquist line in y "
              "alone (Surface.resampled keeps it since 506c9a6; 0.04 % of its variance, K at "
              "step 1 +5.9 %; the target's own surface without the line scores s 0.971 against "
              "it; no design carries a Nyquist line); the same chain on the old target gives "
              "the session-28 s to every digit (SOG 0.9842, GCO 0.9842, CCO 0.9822); on this "
              "target a longer global stage meets the goal (SOG 0.9805 at 24000 global "
              "evaluations, CCO 0.9830 at 16000; GCO's run stalls at 0.9503): a search limit, "
              "not a ceiling of the design family; the target's K(p) itself depends on where "
              "its 41 x 100 nodes sit (the same window on nodes moved by half a cell: s 0.83 in"
              " y, -0.97 in x against it), see docs/theory/surface-design.md, session 35")


def westergaard_scoring(settings, wave=WESTERGAARD_WAVE, n=WESTERGAARD_NODES, stretch=2.0,
                        n_steps=10, amplitude=1e-6):
    """(v): ``score_at_target_pressures`` of the wave h = g cos(2 pi (m x + k y) / L)
    (``wave`` = (m, k), g = ``amplitude``, L = ``settings.length``, ``n``^2 periodic
    points) against the closed form of Westergaard's problem along the wave (wavelength
    lambda = L / hypot(m, k)) for the amplitude ``stretch`` g (Eq. 4.2 factor eta =
    ``stretch``): at the approaches Delta_j = j / n_steps top_fraction g', s_j solves
    Delta / g' = s - s ln s (the mean gap g' (1 - s + s ln s)), p_j = s_j p*, p* = pi E*
    g' / lambda, A_j = (2 / pi) arcsin(sqrt(s_j)) and K_j the central differences of p_j
    over Delta_j (Eq. 2.7, one-sided at the ends), written out here. Returns 1 - s of
    the K and the A target and the pressures (Pa)."""
    e_star = settings.youngs_modulus / (1.0 - settings.poisson ** 2)
    big = stretch * amplitude
    lam = settings.length / np.hypot(*wave)
    deltas = np.arange(1, n_steps + 1) / n_steps * settings.top_fraction * big
    s = np.array([scipy.optimize.brentq(lambda v, r=d / big: v - v * np.log(v) - r,
                                        1e-15, 1.0 - 1e-15, xtol=1e-16) for d in deltas])
    p = s * np.pi * e_star * big / lam
    k = np.empty_like(p)
    k[1:-1] = (p[2:] - p[:-2]) / (deltas[2:] - deltas[:-2])
    k[0], k[-1] = ((p[1] - p[0]) / (deltas[1] - deltas[0]),
                   (p[-1] - p[-2]) / (deltas[-1] - deltas[-2]))
    x = np.arange(n) * settings.length / n
    phase = 2 * np.pi * (wave[0] * x[:, None] + wave[1] * x[None, :]) / settings.length
    surface = Surface(amplitude * np.cos(phase), (settings.length, settings.length),
                      periodic=True)
    t0 = _cpu()
    scores = score_at_target_pressures(
        surface, [ResponseTarget(p, k, "K", "Westergaard K"),
                  ResponseTarget(p, 2 / np.pi * np.arcsin(np.sqrt(s)), "A", "Westergaard A")],
        settings)
    return {"wave": list(wave), "n": n, "eta": stretch, "amplitude": amplitude,
            "wavelength": lam, "pressures": p.tolist(), "one_minus_s_K": 1.0 - scores[0],
            "one_minus_s_A": 1.0 - scores[1], "cpu_s": _cpu() - t0}


def design_runs(entries, settings, targets_k, target_a, pbar, search, outdir, tag,
                surface=None, long=None, quick=False):
    """SOG/GCO/CCO on K, M-CCO on K and A (:func:`design_chain` each, ``search`` sweeps
    per candidate or ``long[method]`` where given), every design saved and re-scored from
    its saved heights (``strict_scores_of_surface`` of the design study's checks,
    ``validation/_design_checks.py``: contact_sweep, Eq. 4.2,
    K, A and Eq. 4.1 written out, not through the design package; the BEM solver is the
    same, so this checks the scoring and the saved design, not the BEM)."""
    rows = []
    for method in ("sog", "gco", "cco", "mcco"):
        targets = [targets_k, target_a] if method == "mcco" else [targets_k]
        t0 = _cpu()
        sweeps = (long or {}).get(method, search)
        res, stage = design_chain(entries, settings, targets, pbar, tag, method, surface,
                                  sweeps, quick)
        cpu = _cpu() - t0
        best = res.best
        saved = outdir / f"surface_design_{tag}_{method}"
        write_json(saved.with_suffix(".json"), best.design.to_dict())
        save_surface(best.design.surface(), saved.with_suffix(".npz"))
        # the saved heights (not the design) read back and scored by the hand-written
        # Eq. 4.1 of design_study (it was score_at_target_pressures, the function that gave
        # best.at_targets, on the same heights: 0.0 by construction); the same BEM solver
        heights = load_surface(saved.with_suffix(".npz"))
        independent = strict_scores_of_surface(heights, targets, settings)
        again = Design.from_dict(json.loads(saved.with_suffix(".json").read_text()))
        assert np.array_equal(again.surface().heights, heights.heights)
        rows.append({"target": tag, "method": method, "origin": best.origin,
                     "stages": list(best.stages), "scores_interpolated": list(best.scores),
                     "scores_at_target_pressures": list(best.at_targets),
                     "f": combined_score(best.at_targets),
                     "independent": list(independent),
                     "reproduced": float(np.max(np.abs(np.subtract(independent,
                                                                   best.at_targets)))),
                     "bem_sweeps": int(res.nit), "cpu_s": cpu, "search_sweeps": sweeps,
                     **stage,
                     "matching": None if surface is None else
                     ("wave" if (tag, method) in DIRECTIONAL else "chromosome")})
    return rows


def main(outdir: Path, quick: bool = False) -> bool:
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    t_start = time.perf_counter()
    seeds = range(2) if quick else range(5)
    rec = recovery(seeds)
    noise = noise_table(range(1) if quick else range(2))
    mech = measured_mechanics(MEASURED[:1] if quick else MEASURED, n_max=32 if quick else 48,
                              n_steps=5 if quick else 8)
    x3p = load_surface(TOPOGRAPHIES / "x3p-2.x3p")
    measured = _thinned(x3p, 64 if quick else X3P_POINTS)
    # the designs' period: that of the mirrored window (the target's own periodic setting)
    length = float(np.sqrt(np.prod(measured.mirrored().size)))
    n_nodes, n_steps = (16, 5) if quick else (DB_NODES, 10)
    settings, db_info = surface_database(outdir / ("surface_db_quick.sqlite" if quick else
                                                   "surface_db.sqlite"), length,
                                         2 if quick else DB_POINTS, 1 if quick else 2,
                                         n_nodes, n_steps, DB_HURST)
    entries = gdb.load_entries(outdir / ("surface_db_quick.sqlite" if quick else
                                         "surface_db.sqlite"))
    search = 5 if quick else SEARCH

    def long(tag):
        return {} if quick else {m: n for (t, m), n in SEARCH_LONG.items() if t == tag}

    t1, _, t3, curve = thesis_targets(settings)
    designs = design_runs(entries, settings, t1, t3, 0.4 * curve.p_max, search, outdir, "y_t1",
                          long=long("y_t1"), quick=quick)
    tk, ta, x3p_info = measured_targets(measured, settings)
    designs += design_runs(entries, settings, tk, ta, 0.4 * tk.p_max, search, outdir,
                           "x3p-2", target_surface(measured, settings), long=long("x3p-2"),
                           quick=quick)
    west = westergaard_scoring(settings)
    rows = _targets(rec, noise, mech, designs, db_info, x3p_info, west, quick=quick)
    ok = all(r.met for r in rows if r.met is not None)
    report = {"targets": [r.to_dict() for r in rows], "quick": quick, "recovery": rec,
              "noise": noise, "measured_mechanics": mech, "database": db_info,
              "settings": settings.to_dict(), "designs": designs,
              "x3p_target": x3p_info, "westergaard_scoring": west,
              "wall_s": time.perf_counter() - t_start}
    write_json(outdir / "surface_genomics.json", report)
    write_text(outdir / "surface_genomics.md", _markdown(report, rows))
    return ok


def _row(name, target, measured, met, reason="", value=None):
    return Target(name=name, target=target, measured=measured, met=bool(met), reason=reason,
                  value=value)


def _targets(rec, noise, mech, designs, db_info, x3p, west, quick=False):
    """The target rows. ``quick`` (the reduced case: a 16^2 5-step database, 5 search
    sweeps per candidate, global stages capped at 12 evaluations): the design goals (s >= GOAL_S, f >= GOAL_F)
    and the design-run CPU rows are judged on the full budgets, so they are
    :func:`~roughfe.validation.skipped` rows ("not run", never met; the reduced designs'
    scores stay in the report's table); every other row is the full run's target."""
    rows = []
    exact = [r for r in rec if r["M_exact"]]
    worst = max((max(r["gene_error"], r["phase_error_rad"], r["angle_error_rad"]) for r in exact),
                default=np.inf)
    rows.append(_row(f"recovery over {len(rec)} seeds: genes, angles, phases",
                     "M exact, <= 1e-8 on every seed", f"{len(exact)}/{len(rec)} M exact, worst "
                     f"{worst:.1e}", len(exact) == len(rec) and worst <= 1e-8, value=worst))
    rms = max((r["rms_error"] for r in exact), default=np.inf)
    rows.append(_row("recovery: acquisitions reproduced", "<= 1e-10 relative rms",
                     f"{rms:.1e}", rms <= 1e-10, value=rms))
    one = [r for r in noise if r["noise"] == 0.01]
    ang = max((r["angle_error_deg"] or np.inf) for r in one)
    gam = max((r["gamma_error"] or np.inf) for r in one)
    rows.append(_row("1 % noise: M exact, angles, gamma", "M exact, <= 0.5 deg, <= 0.5 %",
                     f"M exact {sum(r['M_exact'] for r in one)}/{len(one)}, {ang:.3f} deg, "
                     f"{percent(gam, 3)}", all(r["M_exact"] for r in one) and ang <= 0.5
                     and gam <= 0.005, value=ang))
    fit = [r["misfit_over_noise"] for r in one]
    rows.append(_row("1 % noise: misfit at the noise level", "0.8-1.2 x noise",
                     f"{min(fit):.3f}-{max(fit):.3f}", all(0.8 <= v <= 1.2 for v in fit)))
    done = {k: v for k, v in mech.items() if "skipped" not in v}
    err = max((v["sum_error"] for v in done.values()), default=np.inf)
    rows.append(_row(f"measured files ({len(done)}): bands sum to the surface",
                     "<= 1e-12 of peak-valley", f"{err:.1e}", err <= 1e-12 and len(done) > 0,
                     value=err))
    # a NaN (the sum's sweep failed) fails the row: Python's min() had skipped it
    c = np.array([v["c_td_last"] for v in done.values()], float)
    dk = np.array([v["td_last_K_deviation"] for v in done.values()], float)
    da = np.array([v["td_last_A_deviation"] for v in done.values()], float)
    gap = float(np.max(1.0 - c)) if c.size and not np.isnan(c).any() else np.nan
    worst_k = float(np.max(dk)) if dk.size and not np.isnan(dk).any() else np.nan
    worst_a = float(np.max(da)) if da.size and not np.isnan(da).any() else np.nan
    part = all(v["partition"] for v in done.values())
    rows.append(_row("measured files: TD sum of all bands (its own sweep) = complete, Alg. 2 "
                     "partitions", f"1 - c_n <= {SUM_CURVE_TOL['c']:g} and K within "
                     f"{SUM_CURVE_TOL['K']:g} of max K, macro + micro = all bands",
                     f"max 1 - c = {gap:.1e}, K within {worst_k:.1e} (A {worst_a:.1e}, "
                     f"reported), partition {part}",
                     gap <= SUM_CURVE_TOL["c"] and worst_k <= SUM_CURVE_TOL["K"] and part
                     and len(done) > 0,
                     "the sum of the bands differs from the surface by sum_error (row above); "
                     "bounds: SUM_CURVE_TOL in validation/surface_genomics.py", gap))
    rows.append(reported(Target(
        f"surface database cost per genome ({db_info['n_nodes']}^2, M = 3, 10 steps)",
        "reported", f"{db_info['cpu_per_genome_s']:.1f} s CPU ({db_info['computed']} "
        "computed)", None, "computed this run; 0 computed means the database was reused",
        db_info["cpu_per_genome_s"]), "a cost, no criterion"))
    w = x3p["window"]
    rows.append(_row("x3p-2 window alone (non-periodic): 1/K = 1/K_periodic + C (window bulk "
                     "compliance)", "within 10 % beyond step 1",
                     f"{percent(w['series_deviation_max'], 1)}; K_window <= "
                     f"{w['K_range'][1]:.3g} Pa/m vs 1/C = {1 / w['compliance_m_per_Pa']:.3g}",
                     w["series_deviation_max"] <= 0.1,
                     "why the target is the mirrored (periodic) window: the window's own K "
                     "is its lateral size", w["series_deviation_max"]))
    wave = f"cos 2 pi ({west['wave'][0]} x + {west['wave'][1]} y) / L, {west['n']}^2"
    for q, what in (("K", "the BEM's discretisation: 0.665 / 0.111 / 0.054 % on 64^2 / "
                          "128^2 / 256^2"),
                    ("A", "the node count at the first load (A ~ 9 %, steps of 1/n): "
                          "13.6 / 8.2 / 4.2 % on 64^2 / 128^2 / 256^2")):
        v = west[f"one_minus_s_{q}"]
        rows.append(_row(f"strict scoring path (Eq. 4.2 eta = {west['eta']:g}, load control, "
                         f"Eq. 4.1) vs Westergaard's closed form {q}(p), {wave}: 1 - s",
                         f"<= {percent(WESTERGAARD_SCORE[q], 3)}", percent(v, 3),
                         v <= WESTERGAARD_SCORE[q],
                         f"reference independent of the BEM; tolerance just above {what} "
                         "(WESTERGAARD_SCORE)", v))
    reduced = ("the reduced case's designs (16^2 database, 5 search sweeps, global "
               "stages of <= 12 evaluations) are not judged on the full budgets' goals; "
               "`roughfe validate surface-genomics` (without --quick) runs them")
    for d in designs:
        label = f"{d['target']} {d['method']}"
        if quick:
            what, goal = (("f on K+A", GOAL_F) if d["method"] == "mcco" else ("s on K", GOAL_S))
            rows.append(skipped(f"{label}: {what} at the target pressures", f">= {goal}",
                                reduced))
        elif d["method"] == "mcco":
            rows.append(_row(f"{label}: f on K+A at the target pressures", f">= {GOAL_F}",
                             f"{d['f']:.4f} (s_K {d['scores_at_target_pressures'][0]:.4f}, "
                             f"s_A {d['scores_at_target_pressures'][1]:.4f})",
                             d["f"] >= GOAL_F, _reason(d), d["f"]))
        else:
            why = (f"{_reason(d)}; {X3P_K_MISS}" if d["target"] == "x3p-2"
                   and d["f"] < GOAL_S else _reason(d))
            rows.append(_row(f"{label}: s on K at the target pressures", f">= {GOAL_S}",
                             f"{d['f']:.4f}", d["f"] >= GOAL_S, why, d["f"]))
        rows.append(_row(f"{label}: score reproduced from the saved heights by the "
                         "hand-written Eq. 4.1 (same BEM solver)", "<= 1e-9",
                         f"{d['reproduced']:.1e}", d["reproduced"] <= 1e-9,
                         "checks the saved design and the scoring code, not the BEM "
                         "(both sides solve with it); the BEM's physics: row (v) and "
                         "`roughfe validate bem`", d["reproduced"]))
        if quick:
            rows.append(skipped(f"{label}: design run CPU", f"< {RUN_CPU_S:.0f} s",
                                "the budget is the full run's; " + reduced))
            continue
        rows.append(_row(f"{label}: design run CPU", f"< {RUN_CPU_S:.0f} s",
                         f"{d['cpu_s']:.0f} s ({d['bem_sweeps']} BEM sweeps)",
                         d["cpu_s"] < RUN_CPU_S, value=d["cpu_s"]))
    return rows


def _stages(stages):
    """The GCMMA stages' scores as text; a spectrum-matched candidate's stages after the
    first are NaN (None once in JSON: no GCMMA stage ran, its first is the Alg. 3 score,
    docs/guide/03), said in words instead of "nan"."""
    ran = [s for s in stages[1:] if s is not None and np.isfinite(s)]
    if stages[1:] and not ran:
        return f"Alg. 3 score {stages[0]:.3f} (no GCMMA stage ran)"
    text = ", ".join("-" if s is None or not np.isfinite(s) else f"{s:.3f}" for s in stages)
    return f"GCMMA stages {text} (interpolated on the design's own steps)"


def _reason(d):
    match = f", spectrum matched per {d['matching']}" if d.get("matching") else ""
    return (f"from {d['origin']}; {_stages(d['stages'])}{match}, then the search at the target "
            f"pressures ({d['search_sweeps']} sweeps per candidate)"
            + (f", then IPOP-CMA-ES ({d['global_evaluations']} strict evaluations, batched, "
               f"one run, seed {GlobalSearchOptions.seed}, sigma {d['global_sigma']:g}, "
               + (f"chromosome amplitudes x exp(+-{d['global_amplitudes']:g})"
                  if d.get("global_amplitudes") else "part weights +-30 %")
               + (f", population {d['global_popsize']}" if d.get("global_popsize") else "")
               + (f", short-wave modulation +-{d['global_modulation']:g}"
                  if d.get("global_modulation") else "")
               + ")"
               if d.get("global_evaluations") else ""))


def _markdown(report, rows) -> str:
    lines = [report_title("Surface genomics (issue 15)", report["quick"], "2 recovery seeds, "
                          "1 noise seed, one measured file at <= 32 points, x3p-2 at 64 "
                          "points, a 16^2 5-step database (2 Sobol pairs), 5 search sweeps "
                          "per candidate"),
             f"Generated by `validation/surface_genomics.py`; wall {report['wall_s']:.0f} s.", "",
             targets_markdown(rows), "", "## Noise table", "",
             "| noise | seed | M exact | angle error (deg) | gamma error | misfit / noise |",
             "|---|---|---|---|---|---|"]
    for r in report["noise"]:
        ang = "n/a" if r["angle_error_deg"] is None else f"{r['angle_error_deg']:.4f}"
        gam = "n/a" if r["gamma_error"] is None else f"{r['gamma_error']:.2e}"
        lines.append(f"| {percent(r['noise'], 1)} | {r['seed']} | {r['M_exact']} | {ang} | {gam} "
                     f"| {r['misfit_over_noise']:.3f} |")
    lines += ["", "## Chromosome mechanics of the measured files", "",
              "| file | grid | bands | macro | sweeps | CPU (s) |", "|---|---|---|---|---|---|"]
    for name, v in report["measured_mechanics"].items():
        if "skipped" in v:
            lines.append(f"| {name} | skipped: {v['skipped']} | | | | |")
            continue
        lines.append(f"| {name} | {v['shape'][0]} x {v['shape'][1]} | {v['n_bands']} | "
                     f"{v['macro']} | {v['sweeps']} | {v['cpu_s']:.1f} |")
    lines += ["", "## Designs", "",
              "| target | method | origin | s interpolated | s at target pressures | f | "
              "sweeps | CPU (s) |", "|---|---|---|---|---|---|---|---|"]
    for d in report["designs"]:
        lines.append(f"| {d['target']} | {d['method']} | {d['origin']} | "
                     + " ".join(f"{s:.4f}" for s in d["scores_interpolated"]) + " | "
                     + " ".join(f"{s:.4f}" for s in d["scores_at_target_pressures"])
                     + f" | {d['f']:.4f} | {d['bem_sweeps']} | {d['cpu_s']:.0f} |")
    x = report["x3p_target"]
    w = x["window"]
    lines += ["", f"x3p-2 target: {x['shape'][0]} x {x['shape'][1]} points, mirrored to "
              f"{x['solved_shape'][0]} x {x['solved_shape'][1]} (periodic BEM), p_max = "
              f"{x['p_max']:.4g} Pa, A* at p_max = {x['A_at_p_max']:.4f}, K "
              f"{x['K_range'][0]:.3g}-{x['K_range'][1]:.3g} Pa/m, {x['cpu_s']:.0f} s CPU. "
              f"The window alone (non-periodic): p_max = {w['p_max']:.4g} Pa, A* = "
              f"{w['A_at_p_max']:.4f}, K {w['K_range'][0]:.3g}-{w['K_range'][1]:.3g} Pa/m, "
              f"bulk compliance C = {w['compliance_m_per_Pa']:.3g} m/Pa (1/C = "
              f"{1 / w['compliance_m_per_Pa']:.3g} Pa/m).", ""]
    return "\n".join(lines)


if __name__ == "__main__":
    import sys
    sys.exit(0 if main(Path(sys.argv[1] if len(sys.argv) > 1 else "validation/output"),
                       quick="--quick" in sys.argv) else 1)
