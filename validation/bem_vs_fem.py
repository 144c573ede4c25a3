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

import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from roughfe.bem import Material, contact_sweep
from roughfe.fem import mesh_profile, mirrored_profile
from roughfe.fem.contact import (FemSolverOptions, contact_edge, contact_length,
                                 fem_contact_sweep, p_wave_modulus)
from roughfe.plotting import fem as fplot
from roughfe.reference import westergaard
from roughfe.surfaces import Surface
from roughfe.validation import Target, fraction, report_title, skipped, within
from roughfe.writers import write_json, write_text

MATERIAL = Material(E=210e9, nu=0.3)
GROWTH = 0.03                 # element-size growth with depth (<= 0.14 % on Westergaard)
MIN_CONTACT = 5               # compare A and K only where >= 5 nodes touch (issue 4)
#: Westergaard (513 nodes): the FEM's mean gap and exact incremental K against the closed
#: forms, worst of the 10 loads, set just above the error measured at this resolution
#: (session 33; 257 / 513 / 1025 nodes): mean gap 0.252 / 0.223 / 0.207 % (at p/p* = 0.70,
#: where the mean gap is 5 % of g: the FEM's pressure is 0.051 / 0.044 / 0.042 % above the
#: BEM's at equal approach at every load, a bias of the graded mesh that the top spacing
#: hardly moves, amplified p / (K gbar) = 5x there), K 0.85 / 0.37 / 0.31 % (the discrete
#: contact edge; the BEM's K 0.90 / 0.42 / 0.28 %)
TARGETS = {"westergaard_width": 0.005, "westergaard_mean_gap": 0.0025,
           "westergaard_stiffness": 0.004, "stiffness": 0.03, "vi_penalty": 0.005}


def _rel(a, b):
    return np.abs(np.asarray(a, float) / np.asarray(b, float) - 1.0)


def subcell_area(result, n):
    """A* from the contact length with sub-element edges (:func:`contact_length`) of the
    first n samples (the profile; for the mirrored BEM the first half period)."""
    x = np.arange(n) * result.spacing[0]
    return contact_length(x, result.pressure[:n], result.gap[:n], result.contact[:n],
                          MATERIAL.E_star) / x[-1]


def applied_for(surface_m, targets, pmesh):
    """Approaches to impose on the FEM layer so that its half-plane approach is close to
    ``targets``: target + p_BEM(target) H_d / M. One FEM solve per load (instead of a
    Newton loop); the BEM is then solved at the FEM's own half-plane approach, so the two
    are compared at exactly equal Delta."""
    est = contact_sweep(surface_m, MATERIAL, deltas=targets, kernel="spectral",
                        compute_stiffness=False)
    return np.asarray(targets) + est.mean_pressure * pmesh.depth / p_wave_modulus(MATERIAL)


def patch_stats(contact):
    """Number of contact patches (runs of contact vertices) and their mean size (vertices)."""
    step = np.diff(np.concatenate([[0], np.asarray(contact, np.int8), [0]]))
    sizes = np.flatnonzero(step == -1) - np.flatnonzero(step == 1)
    return int(sizes.size), (float(sizes.mean()) if sizes.size else 0.0), int(np.sum(sizes == 1))


def neighbour_gap_difference(rb, rf, n):
    """Median of g_FEM / g_BEM - 1 (signed) at vertices open in both, (a) next to a vertex in contact
    in both, (b) at least 3 vertices from any contact: how differently the two
    discretisations move the neighbours of a loaded vertex."""
    cb, cf = rb.contact[:n], rf.contact
    both = cb & cf
    open_ = ~cb & ~cf & (rb.gap[:n] > 0)
    near = np.zeros(n, bool)
    near[1:] |= both[:-1]
    near[:-1] |= both[1:]
    far = np.ones(n, bool)
    for k in range(-3, 4):
        far &= ~np.roll(cb | cf, k)
    ratio = rf.gap / np.where(open_, rb.gap[:n], 1.0) - 1.0
    a, b = ratio[open_ & near], ratio[open_ & far]
    return (float(np.median(a)) if a.size else float("nan"),
            float(np.median(b)) if b.size else float("nan"))


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


# -- (ii), (iii) rough profiles -------------------------------------------------------------
def table1_profile():
    from roughfe.genomics.genome import realize, table1_genome
    from roughfe.surfaces.stats import rms_height
    s = realize(table1_genome(rng=0), scale="10x")
    # Eq. 3.1 with A = 1 gives an rms height of 0.7 mm on L = 1 mm (rms slope 27):
    # rescaled to 1 um rms (linear elasticity in formulation (a) is scale-invariant in
    # p / (E* h_rms / L); formulation (b) is reported at the rescaled slope).
    return s.scaled(1e-6 / rms_height(s))


def rmd_profile_case():
    from roughfe.surfaces.rmd import rmd_profile
    return rmd_profile(9, 1.5, 1e-3, rng=1, rms_height=1e-6)


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
        "max |Delta_BEM / Delta_FEM - 1|": float(np.max(_rel(bem.delta, vi.delta))),
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
        "p(delta): FEM-VI vs BEM": _rel(vi.mean_pressure, bem.mean_pressure)[mask],
        area_sub: _rel(sub_vi, sub_bem)[mask],
        area_cnt: _rel(vi.area_fraction, bem.area_fraction)[mask],
        "A(p) node count, BEM interpolated at the FEM p": _rel(
            vi.area_fraction, np.interp(vi.mean_pressure, bem.mean_pressure,
                                        bem.area_fraction))[mask],
        k_key: _rel(vi.stiffness, bem.stiffness)[mask],
        "K(p) at equal delta: FEM-VI vs BEM, central differences": _rel(
            vi.stiffness_fd, bem.stiffness_fd)[inner],
        "p: FEM-penalty vs FEM-VI (equal imposed approach)": _rel(
            pen.mean_pressure, vi.mean_pressure)[mask],
        "A* node count: FEM-penalty vs FEM-VI": _rel(pen.area_fraction, vi.area_fraction)[mask],
        "A* sub-element: FEM-penalty vs FEM-VI": _rel(sub_pen, sub_vi)[mask],
        "K: FEM-penalty vs FEM-VI": _rel(pen.stiffness, vi.stiffness)[mask],
        "p: formulation (b) vs (a)": _rel(vb.mean_pressure, vi.mean_pressure)[mask],
        "A* node count at equal delta: formulation (b) vs (a)": _rel(vb.area_fraction,
                                                                     vi.area_fraction)[mask],
        "A(p): thesis kernel Eq. 2.4 vs plane-strain BEM": _rel(
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


# -- (iv) MPI: 2 ranks give the serial numbers ---------------------------------------------------
_MPI_SCRIPT = """
import json, sys
import numpy as np
from mpi4py import MPI
from roughfe.bem import Material
from roughfe.fem import fem_contact_sweep, mesh_profile
from roughfe.surfaces import Surface
n, lam, g = 129, 1e-3, 1e-6
dx = lam / 2 / (n - 1)
x = np.arange(n) * dx
pm = mesh_profile(Surface(g * np.cos(2 * np.pi * x / lam), n * dx), growth=0.1)
sw = fem_contact_sweep(pm, Material(E=210e9, nu=0.3), applied_deltas=np.array([1.0, 2.0, 3.0]) * g)
if MPI.COMM_WORLD.rank == 0:
    print(json.dumps({"p": sw.mean_pressure.tolist(), "A": sw.area_fraction.tolist(),
                      "K": sw.stiffness.tolist(), "ranks": MPI.COMM_WORLD.size}))
"""


def mpi_case():
    """Run the same small FEM sweep serially and with ``mpirun -n 2``; max relative diff.

    Each run reports its ``MPI.COMM_WORLD.size``: a launcher that starts two singletons
    (an mpi4py built against another MPI) gives two serial runs, equal to the serial one
    by construction; such a run does not count as the check (not met, said why)."""
    mpirun = shutil.which("mpirun")
    if mpirun is None:
        return {"ok": None, "note": "mpirun not found on PATH: the MPI check did not run "
                                    "(it needs an MPI launcher)"}
    env = dict(os.environ, OMPI_MCA_rmaps_base_oversubscribe="1")
    root = str(Path(__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join([root, env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    out = {}
    for ranks in (1, 2):
        cmd = [sys.executable, "-c", _MPI_SCRIPT]
        if ranks > 1:
            cmd = [mpirun, "--allow-run-as-root", "-n", str(ranks), *cmd]
        proc = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)
        lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("{")]
        if proc.returncode != 0 or not lines:
            return {"ok": False, "note": f"{ranks} rank(s) failed: {proc.stderr[-500:]}"}
        out[ranks] = json.loads(lines[-1])
        if out[ranks].get("ranks") != ranks:
            return {"ok": False, "note": f"mpirun -n {ranks} ran on {out[ranks].get('ranks')} "
                                         f"rank(s): not a parallel run (mpi4py and mpirun "
                                         f"of different MPIs?)", "serial": out.get(1)}
    diff = max(float(np.max(_rel(out[2][k], out[1][k]))) for k in ("p", "A", "K"))
    return {"ok": diff < 1e-8, "max_rel_diff": diff, "serial": out[1], "two_ranks": out[2]}


# -- report ---------------------------------------------------------------------------------
def _json_safe(obj):
    if isinstance(obj, dict):
        return {k: _json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_json_safe(v) for v in obj]
    if isinstance(obj, (float, np.floating)):
        return float(obj) if np.isfinite(obj) else None
    return obj


def _fmt(v):
    return f"{100 * v:.2f} %" if np.isfinite(v) else "n/a"


def write_report(outdir: Path, west, cases, extra, quick: bool = False) -> Path:
    L = [report_title("BEM vs FEM (dolfinx) cross-validation", quick, "the Westergaard case "
                      "only: no Table 1 or RMD profile, no MPI check")]
    L.append("Generated by `validation/bem_vs_fem.py` (`roughfe validate fem`). Material "
             f"E = {MATERIAL.E / 1e9:.0f} GPa, nu = {MATERIAL.nu}; plane strain, E* = "
             f"{MATERIAL.E_star / 1e9:.1f} GPa. FEM: P1 triangles (gmsh), top element size = "
             f"profile spacing dx, growth {GROWTH} with depth, depth H_d = 2 W, rollers on the "
             "sides and the bottom; SNES `vinewtonrsls` + MUMPS (line search `basic`), and "
             "penalty k = 1e4 with nodal (GLL) quadrature + Newton.\n")
    L.append("**Why the mirrored BEM.** Rollers (u_x = 0, no shear) are exact symmetry planes "
             "of the periodic problem of the evenly mirrored profile h_0..h_{n-1}, h_{n-2}..h_1 "
             "(period 2 W). The reference is therefore the periodic plane-strain BEM "
             "(kernel `spectral`) on the mirrored profile. The layer of finite depth shortens "
             "by p H_d / M, M = E(1-nu)/((1+nu)(1-2nu)), for the mean pressure (exact: Betti); "
             "the FEM `delta` is the imposed approach minus that shortening, which is the "
             "BEM's zero-mean-displacement approach. K(p) = dp/dDelta "
             "exactly for the converged contact set (one extra linear solve per step in the "
             "FEM, H_cc x = 1 in the BEM) and, as a check, by central differences on the "
             "same Delta grid.\n")
    L.append("## Summary\n")
    L.append("| target | result | status |")
    L.append("|---|---|---|")
    L.append(f"| Westergaard contact width within 0.5 % | FEM {_fmt(west['max_width_error_fem'])}, "
             f"BEM {_fmt(west['max_width_error_bem'])} | {'met' if west['ok'] else 'NOT met'} |")
    for label, key in (("mean gap", "mean_gap"), ("K", "stiffness")):
        limit, v = TARGETS[f"westergaard_{key}"], abs(west[f"{key}_error_fem"])
        L.append(f"| Westergaard {label} within {_fmt(limit)} of the closed form | FEM "
                 f"{_fmt(v)}, BEM {_fmt(abs(west[f'{key}_error_bem']))} | "
                 f"{'met' if v <= limit else 'NOT met'} |")
    for name, c in cases.items():
        d, key = c["diffs"], c["keys"]
        for label, k, limit in (
                ("A* sub-element contact edges, native sampling (info: see "
                 "fem_convergence.md)", "area_sub", None),
                ("A* node count, native sampling (info)", "area_cnt", None),
                ("K within 3 % (exact incremental)", "stiffness", 0.03),
                ("VI vs penalty within 0.5 % (p)", "p: FEM-penalty vs FEM-VI (equal imposed "
                 "approach)", 0.005),
                ("VI vs penalty within 0.5 % (A*)", "A* node count: FEM-penalty vs FEM-VI", 0.005)):
            v = d[key.get(k, k)]
            status = "info" if limit is None else ("met" if v <= limit else "NOT met")
            L.append(f"| {name}: {label} | {_fmt(v)} | {status} |")
    L.append("")
    L.append("## (i) Westergaard cosine\n")
    L.append(f"{west['n_nodes']} nodes on a half wavelength, {west['n_cells']} triangles; mesh "
             f"{west['time_mesh']:.1f} s, 10 FEM-VI steps {west['time_fem']:.1f} s (2 shared "
             "cores, timings inflated). Half-width from the gap (x - a)^(3/2) law (the "
             "sub-element contact length of the rough-profile tables, from the edge pressure "
             "and gap, has max errors FEM "
             f"{_fmt(west['max_length_error_subcell'][0])}, BEM "
             f"{_fmt(west['max_length_error_subcell'][1])}).\n")
    L.append("Stiffness reference: the half-plane approach is delta = g - gbar(p) with "
             "Westergaard's mean gap gbar = g (1 - s + s ln s), s = p/p*, so "
             "K = dp/d delta = -p* / (g ln s).\n")
    L.append("| p/p* | n_contact | a_ref (um) | a_FEM (um) | width error FEM | width error BEM | "
             "FEM mean-gap error | p FEM/BEM - 1 | K error FEM | K error BEM |")
    L.append("|---|---|---|---|---|---|---|---|---|---|")
    for r in west["rows"]:
        L.append(f"| {r[0]:.3f} | {r[1]} | {r[2] * 1e6:.3f} | {r[3] * 1e6:.3f} | {100 * r[4]:+.3f} % "
                 f"| {100 * r[5]:+.3f} % | {100 * r[6]:+.3f} % | {100 * r[7]:+.3f} % "
                 f"| {100 * r[8]:+.2f} % | {100 * r[9]:+.2f} % |")
    L.append(f"\nMax |width error|: FEM {_fmt(west['max_width_error_fem'])}, BEM "
             f"{_fmt(west['max_width_error_bem'])} (target 0.5 %): "
             f"**{'met' if west['ok'] else 'NOT met'}**.\n")
    L.append("![Westergaard](bem_vs_fem_westergaard.png)\n")
    L.append("![deformed mesh](bem_vs_fem_westergaard_mesh.png)\n")
    titles = {"table1_10x": "(ii) Thesis Table 1 genome, 10x realisation",
              "rmd": "(iii) RMD profile"}
    for name, c in cases.items():
        L.append(f"## {titles.get(name, name)}\n")
        L.append(f"{c['n_nodes']} nodes, {c['n_cells']} triangles; metadata {c['metadata']}. "
                 f"Compared at {c['n_compared']} of the loads (those with >= {MIN_CONTACT} "
                 "nodes in contact in both), at exactly equal half-plane Delta: the FEM is "
                 "solved at imposed approaches, the BEM at the FEM's Delta. Timings (s): "
                 + ", ".join(f"{k} {v:.1f}" for k, v in c["timings"].items()) + ".\n")
        L.append("| quantity | max relative difference | target |")
        L.append("|---|---|---|")
        key = c["keys"]
        tgt = {key["stiffness"]: "3 %",
               "p: FEM-penalty vs FEM-VI (equal imposed approach)": "0.5 %",
               "A* node count: FEM-penalty vs FEM-VI": "0.5 %"}
        for k, v in c["diffs"].items():
            L.append(f"| {k} | {_fmt(v)} | {tgt.get(k, 'info')} |")
        L.append("\nTargets: " + ", ".join(f"{k} **{'met' if v else 'NOT met'}**"
                                          for k, v in c["ok_by_target"].items())
                 + f". Largest number of profile nodes whose contact state differs between "
                 f"BEM and FEM-VI at a compared load: {c['max_node_flips']}. n_c counts "
                 "profile nodes (the first half of the mirrored BEM profile). 'A* count' "
                 "is the tributary length of the contact nodes / W (BEM: contact cells of the "
                 "mirrored period / 2(n-1), the same thing); 'A* sub' the contact length with "
                 "the edges located inside the element (`roughfe.fem.contact_length`).\n")
        ch = c["checks"]
        L.append("Checks of the comparison itself: "
                 + "; ".join(f"{k}: {v if not isinstance(v, float) else f'{v:.1e}'}"
                             for k, v in ch.items() if not isinstance(v, list))
                 + "; at the differing nodes the FEM pressure is "
                 + (f"{ch['differing vertices: FEM p / p_mean (range)'][0]:.2g}-"
                    f"{ch['differing vertices: FEM p / p_mean (range)'][1]:.2g} p_mean and the "
                    f"BEM gap {ch['differing vertices: BEM gap / rms height (range)'][0]:.1e}-"
                    f"{ch['differing vertices: BEM gap / rms height (range)'][1]:.1e} rms height"
                    if ch["differing vertices: FEM p / p_mean (range)"] else "n/a")
                 + ".\n")
        g = c["grid"]
        if g["mean_patch_size"]:
            L.append(f"Contact at the compared loads (BEM): mean patch size "
                     f"{min(g['mean_patch_size']):.1f}-{max(g['mean_patch_size']):.1f} nodes, "
                     f"single-node patches {100 * min(g['single_node_fraction']):.0f}-"
                     f"{100 * max(g['single_node_fraction']):.0f} %. Median of g_FEM/g_BEM - 1 at "
                     f"open nodes next to a contact node {100 * g['gap_diff_next_to_contact']:+.2f} %, "
                     f">= 3 nodes from any contact {100 * g['gap_diff_far_from_contact']:+.2f} %"
                     " (median over the compared loads).\n")
        L.append("| p (MPa) | n_c BEM | n_c FEM | nodes differing | A* count BEM | "
                 "A* count FEM-VI | A* sub BEM | A* sub FEM-VI | A* penalty | A* (b) | "
                 "K BEM (MPa/um) | K FEM (MPa/um) | SNES its VI / penalty |")
        L.append("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
        for r in c["table"]:
            L.append(f"| {r[0] / 1e6:.4g} | {r[1]} | {r[2]} | {r[3]} | {r[4]:.4f} | {r[5]:.4f} | "
                     f"{r[6]:.4f} | {r[7]:.4f} | {r[8]:.4f} | {r[9]:.4f} | "
                     f"{r[10] / 1e12:.4g} | {r[11] / 1e12:.4g} | {r[12]} / {r[13]} |")
        L.append("")
        L.append(f"![curves](bem_vs_fem_{name}_curves.png)\n")
        L.append(f"![pressure](bem_vs_fem_{name}_pressure.png)\n")
        L.append(f"![deformed mesh coloured by sigma_yy](bem_vs_fem_{name}_mesh.png)\n")
    mpi = extra.get("mpi", {})
    L.append("## MPI\n")
    if mpi.get("ok") is None:
        L.append(f"{mpi.get('note', 'not run')}.\n")
    else:
        L.append(f"The same FEM-VI sweep (Westergaard, 129 nodes) with `mpirun -n 2` and "
                 f"serially: largest relative difference of p, A*, K "
                 f"{mpi.get('max_rel_diff', float('nan')):.1e} "
                 f"(**{'equal' if mpi['ok'] else 'DIFFERENT'}**). {mpi.get('note', '')}\n")
    if not cases:                 # the reduced case: the sections below read the profiles
        return write_text(outdir / "bem_vs_fem.md", "\n".join(L) + "\n")
    L.append("## Reading the A* differences\n")
    L.append("Question: is the A* difference between BEM and FEM a real disagreement or a "
             "difference in how the two methods define or count the contact area? Measured "
             "(see the 'Checks' lines above):\n")
    L.append("1. *Same Delta, same samples, same weights.* The BEM is solved at the FEM's own "
             "half-plane Delta (difference at round-off). The mirrored BEM has 2(n-1) "
             "samples; its A* (contact samples / 2(n-1)) equals the A* of its first half with "
             "the FEM's trapezoid weights (end nodes dx/2) to round-off at every load, so the "
             "counts are per node and consistent, end nodes included.")
    L.append("2. *No tolerance effect.* BEM contact is p > 0 on a cell, FEM-VI contact is "
             "'gap <= 1e-8 of the height range and nodal reaction > 0'. No node at any load "
             "lies within 1e-6 rms height of touching while open or carries < 1e-6 p_mean "
             "while closed, in either method (count above). The differing nodes are closed with "
             "a positive reaction in the FEM and open with a positive gap in the BEM (ranges "
             "above): the two discrete solutions really differ there.")
    L.append("3. *Sub-element contact edges.* Counting nodes moves each patch edge in jumps of "
             "dx. Locating every edge inside its element from the edge pressure and the "
             "neighbouring gap (square-root law, continuous when a node changes state; "
             "Westergaard errors in section (i)) is the physically right measure of the "
             "contact length and is the primary A* metric above. With it the Table 1 "
             "genome profile agrees to the numbers in the summary; the rough RMD profile "
             "does not.")
    L.append("4. *Why the RMD profile still differs at native sampling.* Its contact is "
             "not resolved by the grid: at the compared loads the patches are 1-2 nodes wide "
             "and most are single nodes (see 'Contact at the compared loads'), so every "
             "contact node carries two edges whose position is set by grid-scale "
             "elasticity. There the two discretisations differ: the BEM spreads a node's "
             "pressure uniformly over its cell (top hat of width dx), the P1 FEM applies a "
             "nodal reaction work-conjugate to the hat function over two elements. On the "
             "RMD profile the FEM leaves the open neighbours of a loaded node closer to the "
             "obstacle (median gap difference next to contact quoted above, against a few "
             "hundredths of a per cent far from contact), so it closes more of them: every "
             "differing node is closed in the FEM and open in the BEM. The refinement study "
             "(fem_convergence.md) shows how both converge as the profile is resolved.")
    L.append("\nConclusion: the node-count A* mixed a counting artefact (edges quantised to "
             "dx) with a real grid-scale discretisation difference. The first is removed by "
             "the sub-element edges. The second remains where the contact patches are "
             "single nodes (RMD at native sampling); it is a resolution limit of both "
             "methods, not a disagreement about the continuum problem: p(Delta) and K agree "
             "to the numbers above; whether the A* of both converge to one limit is "
             "decided by the refinement study (fem_convergence.md, issue 14 section 1).\n")
    L.append("## The thesis kernel (Eq. 2.4)\n")
    L.append("Eq. 2.4, H_ij = 2/(pi E delta) arcsin(delta / (2 |x_i - x_j|)), is the "
             "displacement outside a rigid circular punch of diameter delta in 3D: it decays "
             "as 1/r (Boussinesq), whereas a plane-strain profile has the logarithmic kernel. "
             "It therefore describes a row of patches on a half-space, not a 2D profile; "
             "the rows 'A(p): thesis kernel' above quantify how far its A*(p) is from the "
             "plane-strain BEM and FEM on the same profile (non-periodic, unmirrored).\n")
    for name, c in cases.items():
        tr = c.get("thesis_ratio", {})
        if tr.get("area"):
            L.append(f"* {name}: at equal mean pressure, A*(Eq. 2.4) / A*(plane strain) = "
                     f"{tr['area'][0]:.2f} to {tr['area'][1]:.2f} and K(Eq. 2.4) / "
                     f"K(plane strain) = {tr['stiffness'][0]:.2f} to {tr['stiffness'][1]:.2f} "
                     f"over the compared loads.")
    L.append("")
    return write_text(outdir / "bem_vs_fem.md", "\n".join(L) + "\n")


def target_rows(west, cases, mpi) -> list:
    """The target rows of the JSON schema (roughfe.validation)."""
    rows = [within("Westergaard: FEM contact half-width", west["max_width_error_fem"],
                   TARGETS["westergaard_width"],
                   f"worst of 10 loads, {west['n_nodes']} nodes (BEM "
                   f"{_fmt(west['max_width_error_bem'])})"),
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
               _json_safe({"name": "bem_vs_fem", "quick": quick,
                           "targets": [t.to_dict() for t in rows], "westergaard": west,
                           "cases": cases, "mpi": mpi, "tolerances": TARGETS}))
    write_report(outdir, west, cases, {"mpi": mpi}, quick)
    return all(t.met for t in rows if t.met is not None)


if __name__ == "__main__":
    sys.exit(0 if main(Path(sys.argv[1] if len(sys.argv) > 1 else "validation/output")) else 1)
