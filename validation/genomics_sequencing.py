"""Genome sequencing (thesis Sec. 3.3-3.4): Table 1 recovery over seeds, Eq. 3.10, measured roughness.

Run: ``roughfe validate sequencing`` (or ``make validate``); writes
``<outdir>/genomics_sequencing.md``, ``genomics_sequencing.json`` and the PNGs.

(i)   Table 1 genome (A = 1, H = 0.75, gamma = 1.5, M = 8, lambda1 = 1 mm; the thesis does
      not publish the phases, so they are drawn from SEEDS), realised at 10x, 20x, 100x
      with N = 512 and sequenced. A(p), K(p) of the sequenced vs true 10x profile (BEM,
      20 equal approaches, E = 210 MPa, thesis kernel Eq. 2.4 and plane-strain strip).
(ii)  Monte Carlo of Eq. 3.10 (Fig. 29).
(iii) Central rows of plu-1.plu and sur-2.sur as nested acquisitions (full, 1/2, 1/5).
(iv)  Chromosome mechanics of the seed-0 10x realisation (Fig. 36-39), both kernels.

Targets. Identifiable genes (see roughfe/genomics/sequencing.py): gamma within 1e-8,
relative rms error <= 1e-10 on every acquisition, A(p) and K(p) of sequenced vs true within
1e-8, on every seed: the realisations are the model's own lattice, so the recovery is
exact (measured over the 20 seeds, round 2, session 33: gamma to 1.5e-16, rms errors
<= 3.0e-14, curves <= 4.7e-14). Until session 33 these were 1 %, 2 % and 2 % (beside the
thesis's 5 % / 3 % rms errors), ~1e12 times the measured values, so a sequencer that
recovered the profile only to 1 % passed them. A, H and M of a *profile* are statistical (the heights depend on the
ridges only through sum_m e^{i phi_mn}); the per-seed errors are reported, and the
target on H is that its mean over the seeds is within 2 % (no bias). "A within 2 %" and
"M exact" per seed are not achievable in principle and are reported, not required.
"""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from roughfe.genomics.chromosomes import reconstruction, validity_monte_carlo
from roughfe.genomics.genome import realize, table1_genome
from roughfe.genomics.mechanics import chromosome_mechanics, curve_difference, response
from roughfe.genomics.natural import sequence_measured
from roughfe.genomics.sequencing import sequence_profiles, thesis_zd_fit
from roughfe.plotting import genomics as gp
from roughfe.surfaces.io import load_surface, topographies_folder
from roughfe.validation import report_title, within
from roughfe.writers import write_json, write_text

SEEDS = tuple(range(20))
KERNELS = ("thesis", "strip")
TOPOGRAPHIES = topographies_folder()
#: exact recovery (module docstring: measured 1.5e-16 / 3.0e-14 / 4.7e-14 over 20 seeds);
#: H_mean is a statistical estimate (the mean over the seeds, its standard error ~0.5 %)
TARGETS = {"gamma": 1e-8, "rms": 1e-10, "curves": 1e-8, "H_mean": 0.02}


def table1_case(outdir: Path, rows_zd: dict, seeds=SEEDS):
    rows = []
    for seed in seeds:
        g = table1_genome(rng=seed)
        acq = [realize(g, scale=s) for s in ("10x", "20x", "100x")]
        t0 = time.perf_counter()
        res = sequence_profiles(acq, seed=seed)
        dt = time.perf_counter() - t0
        seq10 = realize(res.genome, scale="10x")
        curves = {}
        for k in KERNELS:
            curves[k] = curve_difference(response(acq[0], kernel=k), response(seq10, kernel=k))
        G = res.genome
        rows.append({"seed": seed, "gamma": G.gamma, "lambda1": G.lambda1, "H": G.H, "A": G.A,
                     "A0_variance": res.A0,
                     "M": G.M, "H_psd": res.H_psd, "gamma_psd": res.gamma_psd,
                     "rms_errors": res.rms_errors.tolist(), "ranges": [list(r) for r in res.ranges],
                     "curves": curves, "time_s": dt, "success": res.success})
        if seed == seeds[0]:
            zfit = thesis_zd_fit(res, seed=seed)
            rows_zd.update({"M": zfit.M.tolist(), "cost": zfit.cost.tolist(), "P": zfit.P.tolist(),
                            "A_from_alpha": (zfit.alpha * zfit.A0).tolist(), "A0": zfit.A0,
                            "chromosomes": [list(c) for c in zfit.chromosomes]})
            gp.plot_sequenced_profiles(res, outdir / "table1_profiles.png")
            gp.plot_spectra(res, outdir / "table1_psd.png")
            for order in ("td", "bu"):
                gp.plot_reconstruction(reconstruction(G, 1e-3, 512, order), outdir / f"table1_{order}.png")
    return rows


def natural_case(outdir: Path):
    out = {}
    for name in ("plu-1.plu", "sur-2.sur"):
        path = TOPOGRAPHIES / name
        if not path.is_file():
            out[name] = {"skipped": f"{path} not found"}
            continue
        t0 = time.perf_counter()
        res = sequence_measured(load_surface(path), seed=0, kernels=KERNELS)
        stem = path.stem
        gp.plot_sequenced_profiles(res.sequencing, outdir / f"{stem}_profiles.png")
        gp.plot_spectra(res.sequencing, outdir / f"{stem}_psd.png")
        gp.plot_measured_vs_sequenced(res.curves, outdir / f"{stem}_curves.png",
                                      title=f"{name}: measured vs sequenced (10x-like acquisition)")
        rep = res.report()
        rep["time_s"] = time.perf_counter() - t0
        out[name] = rep
    return out


def mechanics_case(outdir: Path):
    g = table1_genome(rng=SEEDS[0])
    out = {}
    for k in KERNELS:
        mech = chromosome_mechanics(g, scale="10x", kernel=k, max_chromosomes=10)
        gp.plot_chromosome_curves(mech, outdir / f"mechanics_chromosomes_{k}.png")
        gp.plot_td_bu(mech, outdir / f"mechanics_td_bu_A_{k}.png", "A")
        gp.plot_td_bu(mech, outdir / f"mechanics_td_bu_K_{k}.png", "K")
        gp.plot_correlations(mech, outdir / f"mechanics_correlations_{k}.png")
        out[k] = {"c_td": {q: v.tolist() for q, v in mech.c_td.items()},
                  "c_bu": {q: v.tolist() for q, v in mech.c_bu.items()},
                  "c_chromosome": {q: v.tolist() for q, v in mech.c_chromosome.items()},
                  "sweeps": mech.nit, "time_s": mech.elapsed}
    return out


def _fmt(v, f=".3g"):
    return "n/a" if v is None else format(v, f)


def measured_section(natural: dict) -> list:
    """Section (iii) of the report, the measured rows; [] when none was sequenced (the
    reduced case)."""
    if not natural:
        return []
    md = ["## (iii) Measured roughness (central rows, nested acquisitions full, 1/2, 1/5, "
          "N = 512)", ""]
    for name, rep in natural.items():
        if "skipped" in rep:
            md.append(f"- {name}: skipped ({rep['skipped']})")
            continue
        s = rep["sequencing"]
        gns = s["genes"]
        md.append(f"- **{name}**: A = {gns['A']:.4g}, H = {gns['H']:.3f}, gamma = {gns['gamma']:.4f}, "
                  f"lambda1 = {1e3 * gns['lambda1']:.4f} mm, M = {gns['M']}; chromosome ranges "
                  f"{s['ranges']}; relative rms errors "
                  + ", ".join(f"{100 * e:.1f} %" for e in s["rms_errors"])
                  + f"; Z_d rms {_fmt(s['zd_rms'] and 1e6 * s['zd_rms'])} um, its relative fit error "
                  f"{_fmt(s['zd_rms_error'])}; measured samples per window {rep['measured_points']}; "
                  "A(p)/K(p) measured vs sequenced: "
                  + "; ".join(f"{k}: dA {100 * d['A']:.1f} %, dK {100 * d['K']:.1f} %"
                              for k, d in rep["curve_differences"].items())
                  + f"; {rep['time_s']:.0f} s. {s['message']}")
    return md + ["", "The WM lattice (one cosine per chromosome, wavenumbers in geometric "
                 "progression) does not describe these measured rows: measured spectra are "
                 "continuous, so the discrete lattice leaves 10-40 % of the rms height "
                 "unexplained and the sequenced genes (H, A) are not physical Hurst/amplitude "
                 "values. Each window is the row's own samples (the finest, 1/5 of the "
                 "row, only its ~110-150 samples: nothing is interpolated since round 2, "
                 "session 32), so the fit has no more data there than the row holds.", ""]


def mechanics_section(mech: dict) -> list:
    """Section (iv) of the report, the chromosome mechanics and its figures; [] when it
    was not computed (the reduced case: its figures are not written either)."""
    if not mech:
        return []
    md = ["## (iv) Chromosome mechanics, seed-0 10x realisation (Fig. 36-39)", ""]
    for k, m in mech.items():
        md.append(f"- {k} kernel ({m['sweeps']} BEM sweeps, {m['time_s']:.0f} s): c_n TD (K) "
                  + " ".join(f"{v:.3f}" for v in m["c_td"]["K"]) + "; c_n BU (K) "
                  + " ".join(f"{v:.3f}" for v in m["c_bu"]["K"]))
    return md + ["", "Figures: mechanics_chromosomes_*.png (Fig. 36), mechanics_td_bu_A_*.png "
                 "(Fig. 37), mechanics_td_bu_K_*.png (Fig. 38), mechanics_correlations_*.png "
                 "(Fig. 39).", ""]


def main(outdir: Path, quick: bool = False) -> bool:
    """All cases; ``quick``: the Table 1 genome on the first 3 seeds only (no measured rows,
    no chromosome mechanics)."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    zd = {}
    rows = table1_case(outdir, zd, SEEDS[:3] if quick else SEEDS)
    val = validity_monte_carlo(range(2, 21), 1000, rng=0)
    gp.plot_validity(val, outdir / "eq3_10_validity.png")
    natural = {} if quick else natural_case(outdir)
    mech = {} if quick else mechanics_case(outdir)

    g_err = max(abs(r["gamma"] / 1.5 - 1) for r in rows)
    rms = max(max(r["rms_errors"]) for r in rows)
    curv = max(max(c["K"], c["A"]) for r in rows for c in r["curves"].values())
    h_vals = np.array([r["H"] for r in rows])
    a_vals = np.array([r["A"] for r in rows])
    h_mean_err = abs(h_vals.mean() / 0.75 - 1)
    n_seeds = f"{len(rows)} seeds"
    targets = [
        within("Table 1: gamma", g_err, TARGETS["gamma"], f"worst of {n_seeds}"),
        within("Table 1: relative rms error of every acquisition", rms, TARGETS["rms"],
               f"worst of {n_seeds} x 10x/20x/100x"),
        within("Table 1: A(p), K(p) sequenced vs true", curv, TARGETS["curves"],
               f"worst of {n_seeds} x both kernels"),
        within("Table 1: mean H over the seeds (no bias)", h_mean_err, TARGETS["H_mean"],
               f"{n_seeds}; H per seed is a statistical estimate (sd "
               f"{h_vals.std(ddof=1) if h_vals.size > 1 else float('nan'):.3f})")]
    checks = {k: t.met for k, t in zip(("gamma", "rms", "curves", "H_mean"), targets)}
    ok = all(checks.values())

    md = [report_title("Genome sequencing (thesis Sec. 3.3-3.4)", quick, "the Table 1 "
                       "genome on the first 3 seeds only; no measured rows (iii) and no "
                       "chromosome mechanics (iv)"),
          "## (i) Table 1 genome, sequenced from 10x/20x/100x (N = 512), per seed of the phases", "",
          "| seed | gamma | lambda1 (mm) | H | A | M | H (PSD peak slope, thesis) | rms 10x / 20x / 100x | "
          "max dA, dK thesis | max dA, dK strip | time (s) |",
          "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        md.append(f"| {r['seed']} | {r['gamma']:.10g} | {1e3 * r['lambda1']:.10g} | {r['H']:.4f} | "
                  f"{r['A']:.4f} | {r['M']} | {r['H_psd']:.3f} | "
                  + " / ".join(f"{e:.1e}" for e in r["rms_errors"]) + " | "
                  + f"{r['curves']['thesis']['A']:.1e}, {r['curves']['thesis']['K']:.1e} | "
                  + f"{r['curves']['strip']['A']:.1e}, {r['curves']['strip']['K']:.1e} | "
                  + f"{r['time_s']:.1f} |")
    md += ["", f"- gamma: max relative error {g_err:.1e} (target {TARGETS['gamma']}): "
               f"{'met' if checks['gamma'] else 'MISSED'}",
           f"- relative rms error: max {rms:.1e} (target {TARGETS['rms']}; thesis 5 % / 3 %): "
           f"{'met' if checks['rms'] else 'MISSED'}",
           f"- A(p), K(p) sequenced vs true: max {curv:.1e} (target {TARGETS['curves']}): "
           f"{'met' if checks['curves'] else 'MISSED'}",
           f"- H: mean {h_vals.mean():.4f} (error {100 * h_mean_err:.2f} %, standard error of the mean "
           f"{100 * h_vals.std(ddof=1) / np.sqrt(h_vals.size) / 0.75:.2f} %, target 2 %: "
           f"{'met' if checks['H_mean'] else 'MISSED'}), std over seeds {h_vals.std(ddof=1):.4f} "
           f"(thesis single run: 0.73); "
           f"per seed within 1 %: {int(np.sum(np.abs(h_vals / 0.75 - 1) <= 0.01))}/{len(rows)}",
           f"- A: median {np.median(a_vals):.3f}, per seed within 2 %: "
           f"{int(np.sum(np.abs(a_vals - 1) <= 0.02))}/{len(rows)} (A is extrapolated to n = 1 "
           "with H, so its spread follows H's)",
           f"- M: {sum(r['M'] == 8 for r in rows)}/{len(rows)} seeds give M = 8 "
           "(not identifiable from a profile: the thesis's P_m is flat in M)", "",
           f"- A0 from the height variance (Eq. 3.13): "
           + ", ".join(f"{r['A0_variance']:.3f}" for r in rows),
           "- Eq. 3.12-3.15 on Z_d (seed 0, Z_d = " + " ".join(f"{'+' if s > 0 else '-'}C_{n}" for n, s in zd["chromosomes"])
           + "), angles fitted directly by least_squares with the analytic Jacobian, 3 random starts per M: "
           "f_m = " + ", ".join(f"M={m}: {c:.1e}" for m, c in zip(zd["M"], zd["cost"]))
           + ". Every M fits Z_d to round-off, so P_m = f_m / sum f_m only ranks round-off; the "
           "implied A = alpha A0 ranges over " + f"[{min(zd['A_from_alpha']):.2f}, {max(zd['A_from_alpha']):.2f}]"
           + " across M (M and A are not identifiable from Z_d).", "",
           "Figures: table1_profiles.png (Fig. 33-35), table1_psd.png (Fig. 27/32), "
           "table1_td.png, table1_bu.png (Fig. 30-31).", "",
           "## (ii) Eq. 3.10 (Fig. 29)", "",
           "M: " + " ".join(str(m) for m in val.M), "",
           "valid (%): " + " ".join(f"{100 * v:.1f}" for v in val.valid_fraction), "",
           "arccos phase right (%): " + " ".join(f"{100 * v:.1f}" for v in val.arccos_fraction), "",
           f"Eq. 3.10 is the identity |g1| <= sqrt(g1^2 + g2^2) (max |M + 2 g3 - g1^2 - g2^2| / M = "
           f"{val.max_identity_error:.1e}); the thesis's 88.5-98 % cannot be reproduced. "
           "Figure: eq3_10_validity.png.", ""]
    md += measured_section(natural) + mechanics_section(mech)
    md += [f"**All targets {'met' if ok else 'NOT met'}"
           + (" in the reduced case" if quick else "") + ".** Timings were measured on a "
           "shared, heavily loaded 2-core machine."]
    write_text(outdir / "genomics_sequencing.md", "\n".join(md) + "\n")
    write_json(outdir / "genomics_sequencing.json",
               {"table1": rows, "zd_ridge_fit": zd, "validity": {"M": val.M.tolist(), "valid": val.valid_fraction.tolist(),
                                             "arccos": val.arccos_fraction.tolist()},
                "natural": natural, "mechanics": mech, "checks": checks, "tolerances": TARGETS,
                "name": "genomics_sequencing", "quick": quick,
                "targets": [t.to_dict() for t in targets]})
    return ok


if __name__ == "__main__":
    import sys
    sys.exit(0 if main(Path(sys.argv[1] if len(sys.argv) > 1 else "validation/output")) else 1)
