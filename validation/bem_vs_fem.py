"""BEM vs FEM (dolfinx) cross-validation of rough-profile contact: A(p), K(p), pressures.

Run: ``roughfe validate fem`` (or ``make validate``); writes ``<outdir>/bem_vs_fem.md``,
its PNGs and ``bem_vs_fem.json``.

The FEM body (roughfe.fem) is a plane-strain layer of width W = (n-1) dx and depth
H_d = 2 W with rollers on its sides and bottom, meshed by gmsh with the profile spacing
dx at the top and a gentle growth of the element size with depth. Rollers are exact
symmetry planes of the periodic problem of the evenly mirrored profile (period 2 W), so
the BEM reference is the periodic plane-strain BEM (kernel "spectral") on the mirrored
profile. The finite depth shortens the layer by p H_d / M (exact for the uniform part,
Betti for the mean), which is subtracted from the FEM approach.

Cases: (i) the Westergaard cosine against the closed form, (ii) the 10x realisation of
the thesis Table 1 genome (Eq. 3.1, 512 nodes, phases from seed 0), (iii) an RMD profile
(D = 1.5, 513 nodes, seed 1). Methods: BEM, FEM-VI (SNES vinewtonrsls), FEM-penalty
(k = 1e4), FEM-VI on formulation (b) (the profile as the real top boundary), and the
thesis kernel (Eq. 2.4) on the same profile for comparison.

A* is compared two ways: by counting contact nodes (tributary lengths; edges quantised to
dx) and, as the primary metric, by the contact length with each edge located inside its
element from the edge pressure and gap (``roughfe.fem.contact_length``). At native
sampling the A* of the two discretisations differs where contact patches are single nodes
(RMD); whether they agree on the contact problem itself is decided by the refinement study
of ``fem_convergence.py`` (issue 14 section 1: converged limits within 1 %), which replaces
the round-1 "A* within 2 % at native / 2x / 4x sampling" targets: the native A* rows here
are reported for information.

Westergaard targets (against the closed forms, worst of 10 loads at 513 nodes): the FEM
half-width within 0.5 %, its mean gap within 0.25 % and its exact incremental K within
0.4 % (measured 0.22 % and 0.37 %: tolerances just above the discretisation error, see
TARGETS).

``quick=True`` (``make validate-quick``): the Westergaard case only (one FEM case, one
resolution, its three targets).
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from roughfe.bem import contact_sweep
from roughfe.fem import mesh_profile, mirrored_profile
from roughfe.fem.contact import FemSolverOptions, contact_edge, fem_contact_sweep
from roughfe.plotting import fem as fplot
from roughfe.reference import westergaard
from roughfe.surfaces import Surface
from roughfe.validation import Target, fraction, percent, report_title, skipped, within
from roughfe.writers import write_json

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _fem_cases import (GROWTH, MATERIAL, MIN_CONTACT, applied_for,  # noqa: E402
                        neighbour_gap_difference, patch_stats, rel_diff, rmd_profile_case,
                        subcell_area, table1_profile)
from _fem_mpi import mpi_case  # noqa: E402
from _fem_report import write_report  # noqa: E402

#: Westergaard (513 nodes): the FEM's mean gap and exact incremental K against the closed
#: forms, worst of the 10 loads, set just above the error measured at this resolution
#: (session 33; 257 / 513 / 1025 nodes): mean gap 0.252 / 0.223 / 0.207 % (at p/p* = 0.70,
#: where the mean gap is 5 % of g: the FEM's pressure is 0.051 / 0.044 / 0.042 % above the
#: BEM's at equal approach at every load, a bias of the graded mesh that the top spacing
#: hardly moves, amplified p / (K gbar) = 5x there), K 0.85 / 0.37 / 0.31 % (the discrete
#: contact edge; the BEM's K 0.90 / 0.42 / 0.28 %)
TARGETS = {"westergaard_width": 0.005, "westergaard_mean_gap": 0.0025,
           "westergaard_stiffness": 0.004, "stiffness": 0.03, "vi_penalty": 0.005}


# -- (i) Westergaard ----------------------------------------------------------------------
def westergaard_case(outdir: Path, n=513, wavelength=1e-3, amplitude=1e-6):
    """Half-period cosine with rollers = Westergaard's periodic problem."""
    dx = (wavelength / 2) / (n - 1)
    x = np.arange(n) * dx
    surf = Surface(amplitude * np.cos(2 * np.pi * x / wavelength), n * dx,
                   metadata={"case": "westergaard"})
    t0 = time.perf_counter()
    pm = mesh_profile(surf, growth=GROWTH)
    t_mesh = time.perf_counter() - t0
    deltas = amplitude * np.linspace(0.05, 0.95, 10)    # half-plane approach; full contact: g
    t0 = time.perf_counter()
    fem = fem_contact_sweep(pm, MATERIAL, applied_deltas=applied_for(
        mirrored_profile(surf), deltas, pm), keep_fields=(4,))
    t_fem = time.perf_counter() - t0
    bem = contact_sweep(mirrored_profile(surf), MATERIAL, deltas=fem.delta, kernel="spectral")
    rows, err_fem, err_bem, ratio, err_sub = [], [], [], [], []
    pairs = []
    for k, (rf, rb) in enumerate(zip(fem.results, bem.results)):
        ref_f = westergaard(amplitude, wavelength, MATERIAL.E_star, rf.mean_pressure)
        ref_b = westergaard(amplitude, wavelength, MATERIAL.E_star, rb.mean_pressure)
        a_f = contact_edge(x, rf.gap, rf.contact)
        a_b = contact_edge(x, rb.gap[:n], rb.contact[:n])
        err_fem.append(a_f / ref_f.half_width - 1)
        err_bem.append(a_b / ref_b.half_width - 1)
        err_sub.append((subcell_area(rf, n) * x[-1] / ref_f.half_width - 1,
                        subcell_area(rb, n) * x[-1] / ref_b.half_width - 1))
        ratio.append(rf.mean_pressure / ref_f.full_contact_pressure)
        s_ref = ratio[-1]                                    # K = d p / d(g - gbar)
        k_ref = -ref_f.full_contact_pressure / (amplitude * np.log(s_ref)) if s_ref < 1 else np.nan
        rows.append((ratio[-1], rf.n_contact, ref_f.half_width, a_f, err_fem[-1], err_bem[-1],
                     rf.mean_gap / ref_f.mean_gap - 1, rf.mean_pressure / rb.mean_pressure - 1,
                     rf.stiffness / k_ref - 1, rb.stiffness / k_ref - 1))
        if k in (1, 4, 8):
            pairs.append((f"p/p* = {ratio[-1]:.2f}", rf.pressure, ref_f.pressure(x)))
    fplot.plot_westergaard(np.array(ratio), {"FEM-VI": err_fem, "BEM (spectral)": err_bem},
                           x, pairs, outdir / "bem_vs_fem_westergaard.png")
    fplot.render_deformed_mesh(fem.results[4].fields, outdir / "bem_vs_fem_westergaard_mesh.png",
                               title=f"Westergaard sinusoid, FEM-VI at p/p* = {ratio[4]:.2f} "
                                     f"(p = {fem.results[4].mean_pressure:.3g} Pa)")
    max_err = float(np.max(np.abs(err_fem)))

    def worst(values):                 # the value of largest magnitude, its sign kept
        v = np.asarray(values, float)
        return float(v[np.nanargmax(np.abs(v))])
    table = np.array(rows, float)
    return {"rows": rows, "max_width_error_fem": max_err,
            "mean_gap_error_fem": worst(table[:, 6]),
            "mean_gap_error_bem": worst([rb.mean_gap / westergaard(
                amplitude, wavelength, MATERIAL.E_star, rb.mean_pressure).mean_gap - 1
                for rb in bem.results]),
            "stiffness_error_fem": worst(table[:, 8]), "stiffness_error_bem": worst(table[:, 9]),
            "pressure_fem_over_bem": [float(table[:, 7].min()), float(table[:, 7].max())],
            "max_width_error_bem": float(np.max(np.abs(err_bem))),
            "max_length_error_subcell": [float(np.max(np.abs(np.array(err_sub)[:, k])))
                                         for k in (0, 1)],
            "n_cells": pm.n_cells, "n_nodes": n, "time_mesh": t_mesh, "time_fem": t_fem,
            "ok": max_err <= TARGETS["westergaard_width"]}


def profile_case(name, surf, outdir: Path, n_steps=12):
    h = surf.heights
    n = h.size
    mirrored = mirrored_profile(surf)
    top = float(h.max() - np.mean(mirrored.heights))
    t0 = time.perf_counter()
    pm = mesh_profile(surf, growth=GROWTH)
    pm_b = mesh_profile(surf, growth=GROWTH, formulation="profile")
    timings = {"mesh (a)+(b)": time.perf_counter() - t0}
    applied = applied_for(mirrored, top * np.geomspace(0.05, 0.9, n_steps), pm)
    keep = (3 * n_steps // 4,)
    sweeps = {}
    for label, mesh, opts in (("FEM-VI", pm, FemSolverOptions(method="vi")),
                              ("FEM-penalty", pm, FemSolverOptions(method="penalty",
                                                                   penalty_factor=1e4))):
        t0 = time.perf_counter()
        sweeps[label] = fem_contact_sweep(mesh, MATERIAL, applied_deltas=applied,
                                          options=opts, keep_fields=keep)
        timings[label] = time.perf_counter() - t0
    vi, pen = sweeps["FEM-VI"], sweeps["FEM-penalty"]
    t0 = time.perf_counter()
    bem = contact_sweep(mirrored, MATERIAL, deltas=vi.delta, kernel="spectral")  # equal Delta
    timings["bem"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    sweeps["FEM-VI (b)"] = vb = fem_contact_sweep(pm_b, MATERIAL, vi.delta,   # equal Delta
                                                  options=FemSolverOptions(method="vi"))
    timings["FEM-VI (b)"] = time.perf_counter() - t0
    thesis = contact_sweep(surf, MATERIAL, pressures=bem.mean_pressure, kernel="thesis")

    # Compare where >= MIN_CONTACT nodes touch in both, at exactly equal half-plane Delta
    # (the BEM is solved at the FEM's Delta) and, for A(p), also with the BEM curve
    # interpolated at the FEM pressure.
    n_bem = np.array([int(r.contact[:n].sum()) for r in bem.results])   # profile nodes
    mask = (vi.n_contact >= MIN_CONTACT) & (n_bem >= MIN_CONTACT)
    inner = mask.copy()
    inner[[0, -1]] = False                 # one-sided differences at the ends: no K there
    node_flips = np.array([int(np.sum(rb.contact[:n] != rf.contact))
                           for rb, rf in zip(bem.results, vi.results)])
    sub_bem = np.array([subcell_area(r, n) for r in bem.results])
    sub_vi = np.array([subcell_area(r, n) for r in vi.results])
    sub_pen = np.array([subcell_area(r, n) for r in pen.results])
    # checks of the comparison itself: same Delta, same samples and weights, no tolerance
    hr = float(np.std(h))
    checks = {
        "max |Delta_BEM / Delta_FEM - 1|": float(np.max(rel_diff(bem.delta, vi.delta))),
        "max |A*_BEM(mirrored) - A*_BEM(first half, trapezoid weights)|": float(max(
            abs(r.area_fraction - (np.sum(r.contact[1:n - 1]) + 0.5 * (r.contact[0] + r.contact[n - 1]))
                / (n - 1)) for r in bem.results)),
        "vertices within 1e-6 rms of touching, open or unloaded (BEM + FEM)": int(sum(
            np.sum(~r.contact[:n] & (r.gap[:n] < 1e-6 * hr))
            + np.sum(r.contact[:n] & (r.pressure[:n] < 1e-6 * r.mean_pressure))
            for r in (*bem.results, *vi.results))),
    }
    flipped = [(float(rf.pressure[i] / rf.mean_pressure), float(rb.gap[i] / hr))
               for rb, rf in zip(bem.results, vi.results) for i in
               np.flatnonzero(rb.contact[:n] != rf.contact) if rf.contact[i]]
    checks["differing vertices: FEM p / p_mean (range)"] = (
        [min(f[0] for f in flipped), max(f[0] for f in flipped)] if flipped else [])
    checks["differing vertices: BEM gap / rms height (range)"] = (
        [min(f[1] for f in flipped), max(f[1] for f in flipped)] if flipped else [])
    checks["differing vertices open in the FEM, in contact in the BEM"] = int(sum(
        np.sum(rb.contact[:n] & ~rf.contact) for rb, rf in zip(bem.results, vi.results)))
    stats = [patch_stats(r.contact[:n]) for r, m in zip(bem.results, mask) if m]
    near_far = [neighbour_gap_difference(rb, rf, n)
                for rb, rf, m in zip(bem.results, vi.results, mask) if m]
    grid = {"mean_patch_size": [s[1] for s in stats],
            "single_node_fraction": [s[2] / s[0] for s in stats if s[0]],
            "gap_diff_next_to_contact": float(np.nanmedian([g[0] for g in near_far]))
            if near_far else float("nan"),
            "gap_diff_far_from_contact": float(np.nanmedian([g[1] for g in near_far]))
            if near_far else float("nan")}
    area_sub = "A* sub-element contact edges, equal delta: FEM-VI vs BEM"
    area_cnt = "A* node count, equal delta: FEM-VI vs BEM"
    k_key = "K(p) at equal delta: FEM-VI vs BEM, exact incremental (frozen contact set)"
    diffs = {
        "p(delta): FEM-VI vs BEM": rel_diff(vi.mean_pressure, bem.mean_pressure)[mask],
        area_sub: rel_diff(sub_vi, sub_bem)[mask],
        area_cnt: rel_diff(vi.area_fraction, bem.area_fraction)[mask],
        "A(p) node count, BEM interpolated at the FEM p": rel_diff(
            vi.area_fraction, np.interp(vi.mean_pressure, bem.mean_pressure,
                                        bem.area_fraction))[mask],
        k_key: rel_diff(vi.stiffness, bem.stiffness)[mask],
        "K(p) at equal delta: FEM-VI vs BEM, central differences": rel_diff(
            vi.stiffness_fd, bem.stiffness_fd)[inner],
        "p: FEM-penalty vs FEM-VI (equal imposed approach)": rel_diff(
            pen.mean_pressure, vi.mean_pressure)[mask],
        "A* node count: FEM-penalty vs FEM-VI": rel_diff(pen.area_fraction, vi.area_fraction)[mask],
        "A* sub-element: FEM-penalty vs FEM-VI": rel_diff(sub_pen, sub_vi)[mask],
        "K: FEM-penalty vs FEM-VI": rel_diff(pen.stiffness, vi.stiffness)[mask],
        "p: formulation (b) vs (a)": rel_diff(vb.mean_pressure, vi.mean_pressure)[mask],
        "A* node count at equal delta: formulation (b) vs (a)": rel_diff(vb.area_fraction,
                                                                     vi.area_fraction)[mask],
        "A(p): thesis kernel Eq. 2.4 vs plane-strain BEM": rel_diff(
            thesis.area_fraction, bem.area_fraction)[mask],
    }
    diffs = {k: (float(v.max()) if v.size else float("nan")) for k, v in diffs.items()}
    ok = {"stiffness": diffs[k_key] <= TARGETS["stiffness"],
          "vi_penalty": max(diffs["p: FEM-penalty vs FEM-VI (equal imposed approach)"],
                            diffs["A* node count: FEM-penalty vs FEM-VI"])
          <= TARGETS["vi_penalty"]}

    curves = [{"label": "BEM plane strain (mirrored, spectral)", "marker": "s",
               "mean_pressure": bem.mean_pressure, "area_fraction": bem.area_fraction,
               "stiffness": bem.stiffness}]
    for label, sw in sweeps.items():
        curves.append({"label": label, "mean_pressure": sw.mean_pressure,
                       "area_fraction": sw.area_fraction, "stiffness": sw.stiffness})
    curves.append({"label": "BEM thesis kernel Eq. 2.4", "marker": "x",
                   "mean_pressure": thesis.mean_pressure, "area_fraction": thesis.area_fraction,
                   "stiffness": thesis.stiffness})
    fplot.plot_area_stiffness(curves, outdir / f"bem_vs_fem_{name}_curves.png", title=name)
    series = []
    colors = ("C0", "C1", "C2")
    for c, k in zip(colors, (n_steps // 4, n_steps // 2, n_steps - 1)):
        p_mpa = vi.mean_pressure[k] / 1e6
        series.append({"label": f"BEM p = {p_mpa:.3g} MPa", "pressure": bem.results[k].pressure[:n],
                       "color": c})
        series.append({"label": f"FEM-VI p = {p_mpa:.3g} MPa", "pressure": vi.results[k].pressure,
                       "color": c, "style": "points"})
    fplot.plot_pressures(vi.results[0].x, series, outdir / f"bem_vs_fem_{name}_pressure.png",
                         title=f"{name}: pressure at three loads")
    fplot.render_deformed_mesh(vi.results[keep[0]].fields, outdir / f"bem_vs_fem_{name}_mesh.png",
                               title=f"{name}, FEM-VI at p = "
                                     f"{vi.results[keep[0]].mean_pressure:.3g} Pa")
    table = [(float(bem.mean_pressure[k]), int(n_bem[k]), int(vi.n_contact[k]),
              int(node_flips[k]), float(bem.area_fraction[k]), float(vi.area_fraction[k]),
              float(sub_bem[k]), float(sub_vi[k]), float(pen.area_fraction[k]),
              float(vb.area_fraction[k]), float(bem.stiffness[k]), float(vi.stiffness[k]),
              int(vi.results[k].nit), int(pen.results[k].nit))
             for k in range(n_steps)]
    ratio_a = thesis.area_fraction[mask] / bem.area_fraction[mask]
    ratio_k = thesis.stiffness[mask] / bem.stiffness[mask]
    thesis_ratio = {"area": [float(ratio_a.min()), float(ratio_a.max())] if mask.any() else [],
                    "stiffness": [float(ratio_k.min()), float(ratio_k.max())] if mask.any() else []}
    return {"diffs": diffs, "ok": bool(all(ok.values())), "ok_by_target": ok, "table": table,
            "keys": {"area_sub": area_sub, "area_cnt": area_cnt, "stiffness": k_key},
            "checks": checks, "grid": grid, "thesis_ratio": thesis_ratio,
            "max_node_flips": int(node_flips[mask].max()) if mask.any() else 0,
            "timings": timings,
            "n_cells": pm.n_cells, "n_nodes": n, "n_compared": int(mask.sum()),
            "metadata": {k: v for k, v in surf.metadata.items() if k in ("generator", "seed",
                                                                          "length", "n_s", "n_f")}}


def target_rows(west, cases, mpi) -> list:
    """The target rows of the JSON schema (roughfe.validation)."""
    rows = [within("Westergaard: FEM contact half-width", west["max_width_error_fem"],
                   TARGETS["westergaard_width"],
                   f"worst of 10 loads, {west['n_nodes']} nodes (BEM "
                   f"{percent(west['max_width_error_bem'])})"),
            within("Westergaard: FEM mean gap vs g (1 - s + s ln s)", west["mean_gap_error_fem"],
                   TARGETS["westergaard_mean_gap"],
                   f"worst of 10 loads (largest at high load, where the mean gap is small), "
                   f"{west['n_nodes']} nodes; measured 0.252 / 0.223 / 0.207 % on 257 / 513 / "
                   "1025 nodes: the FEM's p is 0.04-0.05 % above the BEM's at equal approach "
                   f"(here {fraction(west['pressure_fem_over_bem'][0])} to "
                   f"{fraction(west['pressure_fem_over_bem'][1])}), amplified p / (K gbar) = "
                   f"5x at p/p* = 0.70 (BEM {fraction(abs(west['mean_gap_error_bem']))})"),
            within("Westergaard: FEM stiffness K (exact incremental) vs -p* / (g ln s)",
                   west["stiffness_error_fem"], TARGETS["westergaard_stiffness"],
                   f"worst of 10 loads, {west['n_nodes']} nodes; measured 0.85 / 0.37 / 0.31 % "
                   "on 257 / 513 / 1025 nodes, the discrete contact edge (BEM "
                   f"{fraction(abs(west['stiffness_error_bem']))})")]
    for name, c in cases.items():
        d, key = c["diffs"], c["keys"]
        rows.append(within(f"{name}: K FEM-VI vs BEM at native sampling", d[key["stiffness"]],
                           TARGETS["stiffness"], f"exact incremental, worst of "
                           f"{c['n_compared']} loads with >= {MIN_CONTACT} contact nodes"))
        rows.append(within(f"{name}: FEM-VI vs FEM-penalty (p, A* node count)", max(
            d["p: FEM-penalty vs FEM-VI (equal imposed approach)"],
            d["A* node count: FEM-penalty vs FEM-VI"]), TARGETS["vi_penalty"],
            "equal imposed approach, penalty k = 1e4"))
    name = "FEM-VI: 2 MPI ranks vs serial (p, A*, K)"
    if mpi.get("ok") is None:                  # not checked (--quick, no mpirun): counted
        rows.append(skipped(name, "<= 1e-8", mpi.get("note", "not run")))
    else:
        rows.append(Target(name, "<= 1e-8", f"{mpi.get('max_rel_diff', float('nan')):.1e}",
                           bool(mpi["ok"]), mpi.get("note", ""), mpi.get("max_rel_diff")))
    return rows


def main(outdir, quick: bool = False) -> bool:
    """All cases; ``quick``: the Westergaard case only."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    west = westergaard_case(outdir)
    print(f"westergaard: max width error FEM {west['max_width_error_fem']:.4%}")
    cases = {}
    profiles = () if quick else (("table1_10x", table1_profile()), ("rmd", rmd_profile_case()))
    for name, surf in profiles:
        cases[name] = profile_case(name, surf, outdir)
        print(f"{name}: " + ", ".join(f"{k} {v:.3%}" for k, v in cases[name]["diffs"].items()))
    mpi = ({"ok": None, "note": "--quick leaves the MPI check out (the full validation runs "
                                "it)"} if quick else mpi_case())
    print(f"mpi: {mpi.get('max_rel_diff', mpi.get('note'))}")
    rows = target_rows(west, cases, mpi)
    write_json(outdir / "bem_vs_fem.json",
               {"name": "bem_vs_fem", "quick": quick,
                "targets": [t.to_dict() for t in rows], "westergaard": west,
                "cases": cases, "mpi": mpi, "tolerances": TARGETS})
    title = report_title("BEM vs FEM (dolfinx) cross-validation", quick, "the Westergaard "
                         "case only: no Table 1 or RMD profile, no MPI check")
    write_report(outdir, title, west, cases, {"mpi": mpi}, TARGETS)
    return all(t.met for t in rows if t.met is not None)


if __name__ == "__main__":
    sys.exit(0 if main(Path(sys.argv[1] if len(sys.argv) > 1 else "validation/output")) else 1)
