"""The printed summary of ``roughfe contact``: the material line, one table row per step
(the BEM's delta, p, A*, K, mean gap and iterations beside the theory's A*), the notes on
the patches, the grid check, the theory's basis, a single asperity, ``--mirror``, a
non-periodic window and the adhesive pull-off."""
from __future__ import annotations

import numpy as np

from ..bem.patches import MIN_PATCH_POINTS
from ..theory import theory_area_fraction
from .contact_grid import print_grid_check
from .options import fmt_or_dash, print_surface_notes
from .plausibility import persson_basis


def print_summary(args, surface, material, sweep, doc, grid=None, *, adhesive=None,
                  maugis=None, stickiness=None) -> None:
    """Print the summary of a contact sweep ``sweep`` with its results.json ``doc``."""
    print_surface_notes(args, surface)
    print(f"{args.method.upper()}, E = {material.E:.4g} Pa, nu = {material.nu:g}, "
          f"E* = E / (1 - nu^2) = {material.E_star:.4g} Pa (--E, --nu)")
    plastic = args.hardness is not None      # the plastic share of A* beside it
    cap = doc["derived"]["persson"].get("single_asperity")
    theory = "hertz" if cap is not None else "persson"
    # a sphere's hardness run: the capped Hertz approach beside delta (first loading)
    capped = any(t.get("capped_hertz_approach") is not None for t in doc["steps"])
    print(f"{'delta (m)':>12s} " + (f"{'delta Hertz':>12s} " if capped else "")
          + f"{'p (Pa)':>12s} {'A*':>8s} "
          + (f"{'A*plastic':>9s} " if plastic else "")
          + f"{'K (Pa/m)':>12s} {'gap (m)':>12s} {'nit':>5s} "
          + f"{'A* ' + theory.capitalize():>10s} {'patch':>6s}")
    for s, k, t in zip(sweep.to_records(), sweep.stiffness, doc["steps"]):
        # inf at full periodic contact; "-" where it was not computed (adhesion); A* theory:
        # with a hardness the plastic interface's (first loading), theory_area_fraction
        k = f"{k:12.4e}" if not np.isnan(k) else f"{'-':>12s}"
        pl = (f"{fmt_or_dash(t.get('plastic_area_fraction'), '.3g'):>9s} " if plastic
              else "")
        ref = (f"{fmt_or_dash(t.get('capped_hertz_approach'), '.4e'):>12s} " if capped
               else "")
        print(f"{s['delta']:12.4e} {ref}{s['mean_pressure']:12.4e} {s['area_fraction']:8.3g} "
              f"{pl}{k} {s['mean_gap']:12.4e} {s['iterations']:5d} "
              f"{fmt_or_dash(theory_area_fraction(t), '.3g'):>10s} "
              f"{fmt_or_dash(s.get('patch_width'), '.3g'):>6s}")
    print(f"patch: load-weighted width of the contact patches in grid points (patch_width in "
          f"results.json; below {MIN_PATCH_POINTS:g} not resolved; a resolved width does not "
          f"bound the grid's error of A*: --grid-check measures it)")
    if capped:
        print(f"delta Hertz: the approach of Hertz's sphere capped at the hardness H_p = "
              f"{args.hardness:.4g} Pa at the step's load, counted from the highest grid "
              f"point as delta is (capped_hertz_approach in results.json; first loading "
              f"only; A* Hertz is its A*)")
    print_grid_check(args, grid)
    persson_basis(args, surface, doc["derived"]["persson"])
    if cap is not None:
        print(f"one smooth asperity ({cap['shape']}, principal radii "
              f"{', '.join(f'{r:.4g}' for r in cap['radii'])} m): Persson's random-roughness "
              f"theory does not apply; "
              + ("Maugis' sphere (derived.maugis_sphere)" if maugis is not None else
                 "the adhesive single-asperity theory is not evaluated for this law"
                 if adhesive is not None else
                 "Hertz's A* and K beside the results (hertz_*, capped_hertz_* in results.json)"
                 if cap["radius"] is not None else "no Hertz line (not round)"))
    if args.mirror:
        print("--mirror: the fields and the load, contact area and contact count are of the "
              "mirrored period (2 (n - 1) points per axis, "
              f"{2 ** surface.ndim}x the window's area); p, A*, K and the gaps are the "
              "window's")
    window = doc["derived"].get("window_compliance")
    if window is not None:     # a measured (non-periodic) window: K includes its bulk
        share = sorted({round(v, 2) for v in doc["derived"]["bulk_share"] if v is not None})
        print(f"non-periodic window: bulk compliance C = {window:.4e} m/Pa (1/C = "
              f"{1 / window:.4e} Pa/m); bulk deflection C p / Delta = "
              + ("-" if not share else f"{share[0]:.2f}" if len(share) == 1 else
                 f"{share[0]:.2f}..{share[-1]:.2f}")
              + " (derived.window_compliance, bulk_share in results.json)")
    if adhesive is not None:
        limit = (f"{args.max_unload_steps}" if args.max_unload_steps is not None else
                 "the default 4 x the loading steps")
        pull = (("no tensile state: the surfaces separated without a pull-off force (0)"
                 if adhesive.pull_off_force == 0 and adhesive.detached else
                 f"pull-off force {adhesive.pull_off_force:.4e} "
                 + ("(detached)" if adhesive.detached else
                    f"(NOT detached: a bound; trace further with --max-unload-steps N, "
                    f"more than {limit})"))
                if args.unload else "pull-off force not traced (--unload traces it)")
        print(f"{pull}; " + (stickiness.verdict() if stickiness is not None else
                             "Pastewka-Robbins stickiness not evaluated: "
                             + doc["derived"]["stickiness"]["why"]))
