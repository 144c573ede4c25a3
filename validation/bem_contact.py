"""BEM contact solver against closed forms, between its solvers, and against Tamaas.

Run: ``roughfe validate bem`` (or ``make validate``); writes ``<outdir>/bem_contact.md``,
``bem_contact.json`` and ``bem_westergaard.png``.

(i) Westergaard (periodic sinusoid, plane strain): contact half-width and mean gap vs
the closed form over s = p/p* and resolutions 64..8192 points per wavelength.
(ii) Hertz sphere (non-periodic surface, Love kernel): contact radius, load-approach,
peak pressure and stiffness at 128^2, 256^2, 512^2.
(iii) Hertz line contact (non-periodic profile, strip kernel): half-width, peak pressure.
(iv) Dense pivoting vs matrix-free PCG on random surfaces (pressures to 1e-8).
(v) Tamaas 2.8 PolonskyKeerRey on the same periodic surface (A*, mean gap), if importable.
"""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from roughfe.bem import Material, solve_contact
from roughfe.reference import hertz_cylinder, hertz_sphere, westergaard
from roughfe.surfaces import Surface
from roughfe.surfaces.spectral import spectral_surface
from roughfe.validation import fraction, report_title, skipped, targets_markdown, within
from roughfe.writers import write_json, write_text

MAT = Material(1.0e9, 0.3)
#: the references' E* = E / (1 - nu^2) (plane strain, rigid indenter), written out here and
#: not read from ``MAT.E_star``: the solver takes its E* from the Material, so a reference
#: computed from the same property could not see an error in it (an E/(1 - nu) or a factor
#: 2 in ``Material.E_star`` passed every row of this study until round 2, session 33)
E_STAR = 1.0e9 / (1.0 - 0.3 ** 2)
#: relative tolerances, each above the discretisation error measured at its resolution
#: (full run, session 33; the report's tables hold every level): Westergaard half-width
#: from the edge law 0.011-0.124 % at 1024 points, mean gap 2.3e-6-1.8e-5 at 1024 (8.1e-4
#: at 256); Hertz sphere at 256^2: contact radius (whole cells) 0.59 %, load and peak
#: pressure 8.1e-5 / 5.9e-5 (2.4e-4 / 2.7e-4 at 128^2), stiffness 0.22 % (0.43 % at
#: 128^2); Hertz line at 2048 points: half-width (whole cells) 0.089 %, peak pressure
#: 1.4e-6 (5.3e-5 at 512). Until session 33 the mean gap had 0.5 %, and load, peak and
#: stiffness shared the radius' 2 % (line: the half-width's 1 %), so an error of 1 % in
#: E* or in a kernel passed them.
TARGETS = {"westergaard_width_1024": 5e-3, "westergaard_gap_1024": 1e-4,
           "hertz_radius_256": 2e-2, "hertz_load_peak_256": 1e-3, "hertz_stiffness_256": 5e-3,
           "line_width_2048": 1e-2, "line_peak_2048": 1e-4, "dense_vs_pk": 1e-8,
           "tamaas": 1e-3}


def _sinusoid(n, lam=1e-3, g=1e-6):
    x = np.arange(n) * lam / n
    return Surface(g * np.cos(2 * np.pi * x / lam), lam, periodic=True)


def _edge_half_width(pressure, dx):
    """Contact half-width from the square-root edge law p^2 ~ (a - x) (contact at x=0)."""
    k = int(np.argmax(pressure == 0)) - 1
    slope = (pressure[k - 1] ** 2 - pressure[k] ** 2) / dx
    return k * dx + pressure[k] ** 2 / slope


def westergaard_cases(ns=(64, 256, 1024, 4096, 8192)):
    rows = []
    p_star = np.pi * E_STAR * 1e-6 / 1e-3
    for n in ns:
        for s in (0.1, 0.3, 0.6, 0.9):
            ref = westergaard(1e-6, 1e-3, E_STAR, s * p_star)
            r = solve_contact(_sinusoid(n), MAT, mean_pressure=ref.mean_pressure)
            rows.append({"n": n, "s": s, "A": r.area_fraction, "A_ref": ref.area_fraction,
                         "width_err": abs(r.area_fraction / ref.area_fraction - 1),
                         "edge_width_err": abs(_edge_half_width(r.pressure, 1e-3 / n)
                                               / ref.half_width - 1),
                         "gap_err": abs(r.mean_gap / ref.mean_gap - 1), "nit": r.nit,
                         "solver": r.solver})
    return rows


def hertz_cases(ns=(128, 256, 512)):
    rows = []
    R, L, delta = 1e-2, 1e-3, 1.5e-6
    ref = hertz_sphere(R, E_STAR, approach=delta)
    for n in ns:
        x = (np.arange(n) - n // 2) * L / n
        X, Y = np.meshgrid(x, x, indexing="ij")
        surf = Surface(-(X ** 2 + Y ** 2) / (2 * R), L)
        t0 = time.perf_counter()
        r = solve_contact(surf, MAT, delta=delta)
        rows.append({"n": n, "time_s": time.perf_counter() - t0, "nit": r.nit,
                     "radius_err": abs(np.sqrt(r.contact_area / np.pi) / ref.contact_radius - 1),
                     "load_err": abs(r.load / ref.load - 1),
                     "peak_err": abs(r.pressure.max() / ref.peak_pressure - 1),
                     "stiffness_err": abs(r.stiffness * L * L / ref.stiffness - 1)})
    return rows


def line_cases(ns=(512, 2048, 8192)):
    rows = []
    R, L = 1e-2, 1e-3
    for n in ns:
        x = (np.arange(n) - n // 2) * L / n
        r = solve_contact(Surface(-x ** 2 / (2 * R), L), MAT, mean_pressure=2e5)
        ref = hertz_cylinder(R, E_STAR, r.load)
        rows.append({"n": n, "width_err": abs(r.contact_area / 2 / ref.contact_radius - 1),
                     "peak_err": abs(r.pressure.max() / ref.peak_pressure - 1)})
    return rows


def solver_cases(seeds=range(3)):
    rows = []
    for seed in seeds:
        for periodic in (True, False):
            surf = spectral_surface(32, 1e-4, 0.8, rms_height=1e-6, rng=seed)
            surf = Surface(surf.heights, surf.size, periodic=periodic)
            d = 0.3 * (surf.heights.max() - surf.heights.mean())
            a = solve_contact(surf, MAT, delta=d, solver="dense", tol=1e-13)
            b = solve_contact(surf, MAT, delta=d, solver="pk", tol=1e-13)
            rows.append({"seed": seed, "periodic": periodic, "A": a.area_fraction,
                         "max_rel_diff": float(np.abs(a.pressure - b.pressure).max()
                                               / a.pressure.max()), "nit_pk": b.nit})
    return rows


def tamaas_case():
    try:
        import tamaas as tm
    except ImportError:
        return None
    n = 256
    surf = spectral_surface(n, 1.0, 0.8, rms_slope=1.0, rng=1)
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [1.0, 1.0], [n, n])
    model.E, model.nu = 1.0, 0.0
    solver = tm.PolonskyKeerRey(model, np.array(surf.heights, order="C"), 1e-10)
    solver.solve(0.05)
    a_t = float((np.asarray(model.traction) > 0).mean())
    g_t = float(np.asarray(model["gap"]).mean())
    r = solve_contact(surf, Material(1.0, 0.0), mean_pressure=0.05, solver="pk")
    return {"A_tamaas": a_t, "A_roughfe": r.area_fraction, "gap_tamaas": g_t,
            "gap_roughfe": r.mean_gap, "A_rel": abs(r.area_fraction / a_t - 1),
            "gap_rel": abs(r.mean_gap / g_t - 1)}


def _figure(rows, path):
    from roughfe.plotting.common import new_figure, save_figure
    fig, ax = new_figure(figsize=(6, 4))
    for s in sorted({r["s"] for r in rows}):
        sel = [r for r in rows if r["s"] == s]
        ax.loglog([r["n"] for r in sel], [max(r["gap_err"], 1e-16) for r in sel], "o-",
                  label=f"mean gap, s = {s}")
    ax.set_xlabel("points per wavelength")
    ax.set_ylabel("relative error vs Westergaard")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return save_figure(fig, path)


def main(outdir: Path, quick: bool = False) -> bool:
    """All cases; ``quick``: Westergaard to 1024 points, Hertz to 256^2, one solver seed, no
    Tamaas (the same targets)."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    if quick:
        w, h, line, sol, tam = (westergaard_cases((256, 1024)), hertz_cases((128, 256)),
                                line_cases((512, 2048)), solver_cases((0,)), None)
    else:
        w, h, line, sol, tam = (westergaard_cases(), hertz_cases(), line_cases(), solver_cases(),
                                tamaas_case())
    measured = {
        "westergaard_width_1024": max(r["edge_width_err"] for r in w if r["n"] == 1024),
        "westergaard_gap_1024": max(r["gap_err"] for r in w if r["n"] == 1024),
        "hertz_radius_256": max(r["radius_err"] for r in h if r["n"] == 256),
        "hertz_load_peak_256": max(max(r["load_err"], r["peak_err"]) for r in h
                                   if r["n"] == 256),
        "hertz_stiffness_256": max(r["stiffness_err"] for r in h if r["n"] == 256),
        "line_width_2048": max(r["width_err"] for r in line if r["n"] == 2048),
        "line_peak_2048": max(r["peak_err"] for r in line if r["n"] == 2048),
        "dense_vs_pk": max(r["max_rel_diff"] for r in sol),
    }
    if tam is not None:
        measured["tamaas"] = max(tam["A_rel"], tam["gap_rel"])
    labels = {"westergaard_width_1024": "Westergaard half-width (1024 points per wavelength)",
              "westergaard_gap_1024": "Westergaard mean gap (1024 points per wavelength)",
              "hertz_radius_256": "Hertz sphere contact radius, whole cells (256^2)",
              "hertz_load_peak_256": "Hertz sphere load and peak pressure (256^2)",
              "hertz_stiffness_256": "Hertz sphere stiffness (256^2)",
              "line_width_2048": "Hertz line half-width, whole cells (2048 points)",
              "line_peak_2048": "Hertz line peak pressure (2048 points)",
              "dense_vs_pk": "dense pivoting vs PCG pressures (32^2)",
              "tamaas": "A* and mean gap vs Tamaas 2.8 (256^2)"}
    closed_form = "; E* = E/(1 - nu^2) of the closed form written out (E_STAR)"
    targets = [within(labels[k], v, TARGETS[k], "relative error, worst over the cases"
                      + ("" if k == "dense_vs_pk" else closed_form))
               for k, v in measured.items()]
    checks = {k: t.met for k, t in zip(measured, targets)}
    if tam is None:                            # a target not run: said and counted
        targets.append(skipped(labels["tamaas"], f"<= {fraction(TARGETS['tamaas'])}",
                               "--quick leaves Tamaas out (the full validation runs it)"
                               if quick else "tamaas not importable (`make validate` "
                               "installs it: the bench extra)"))
    write_json(outdir / "bem_contact.json", {"name": "bem_contact", "quick": quick,
                                             "targets": [t.to_dict() for t in targets],
                                             "westergaard": w, "hertz": h, "line": line,
                                             "solvers": sol, "tamaas": tam, "checks": checks})
    fig = _figure(w, outdir / "bem_westergaard.png")

    def table(rows, keys):
        head = "| " + " | ".join(keys) + " |\n|" + "---|" * len(keys) + "\n"
        return head + "\n".join("| " + " | ".join(
            f"{r[k]:.3g}" if isinstance(r[k], float) else str(r[k]) for k in keys) + " |"
            for r in rows)

    md = (report_title("BEM contact validation", quick, "Westergaard to 1024 points, Hertz "
                       "to 256^2, one solver seed, no Tamaas") + "\n"
          "## Westergaard (periodic profile)\n\n" + table(w, ["n", "s", "A", "A_ref",
                                                              "width_err", "edge_width_err", "gap_err", "nit",
                                                              "solver"])
          + f"\n\n![convergence]({fig.name})\n\n"
          "A* counts whole cells, so its error (width_err) is about 1-2 cells / n; the "
          "half-width located inside the edge cell by the square-root law p^2 ~ (a - x) "
          "(edge_width_err) and the mean gap (an integral) converge fast.\n\n## Hertz sphere (non-periodic, Love kernel)\n\n"
          + table(h, ["n", "radius_err", "load_err", "peak_err", "stiffness_err", "nit",
                      "time_s"])
          + "\n\n## Hertz line contact (non-periodic profile, strip kernel)\n\n"
          + table(line, ["n", "width_err", "peak_err"])
          + "\n\n## Dense pivoting vs matrix-free PCG (32^2, tol 1e-13)\n\n"
          + table(sol, ["seed", "periodic", "A", "max_rel_diff", "nit_pk"])
          + "\n\n## Tamaas PolonskyKeerRey (256^2, p/E* = 0.05, tol 1e-10)\n\n"
          + (table([tam], list(tam)) if tam else
             "not run: --quick leaves Tamaas out (the full validation runs it)" if quick
             else "tamaas not importable: skipped")
          + "\n\n## Targets\n\n" + targets_markdown(targets)
          + "\nEvery tolerance lies above the discretisation error measured at its "
          "resolution (the tables above; the values are in the comment of `TARGETS` in "
          "validation/bem_contact.py). Quantities counted in whole cells (A*, the Hertz "
          "radius, the line half-width) carry about one cell per contact edge; the others "
          "converge fast and have tolerances that an error of 1 % in E* or a kernel "
          "exceeds. The closed forms take E* = E/(1 - nu^2) computed in the script, not "
          "the Material's E_star that the solver uses.\n")
    write_text(outdir / "bem_contact.md", md)
    return all(checks.values())


if __name__ == "__main__":
    import sys
    raise SystemExit(0 if main(Path(sys.argv[1] if len(sys.argv) > 1 else "validation/output"))
                     else 1)
