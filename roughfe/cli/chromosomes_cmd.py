"""``roughfe genome chromosomes``: band chromosomes of any surface, their A(p), K(p) and
Alg. 2 (issue 15 section 2); registered by :mod:`roughfe.cli.genome_cmd`, split from it
(round 2, session 29) to keep each command module under the 500-line limit."""
from __future__ import annotations

import json
from dataclasses import replace

from .options import (material_from_args, mirrored_if_asked, output_folder_of,
                      surface_from_args, warn)

#: units of the arrays of chromosomes.npz (``genome chromosomes``), stored in the file as
#: ``units`` (a JSON object, as `leak`'s fields/step_NNN.npz); "1": dimensionless
CHROMOSOMES_UNITS = {"chromosomes": "m", "surface": "m", "q_bounds": "rad/m",
                     "indices": "1 (chromosome numbers n)", "energy": "m^2 (mean square)",
                     "size": "m", "gamma": "1", "transform": "", "detrend": ""}


def _chromosomes(args) -> int:
    """Band chromosomes of any surface, their mechanics and Alg. 2 (issue 15 §2)."""
    import numpy as np

    from ..genomics.band_mechanics import band_macro_micro, band_mechanics
    from ..genomics.bands import band_chromosomes
    from ..writers import atomic_path, write_json
    from ..errors import InputError
    if args.steps in (1, 2):
        raise InputError(f"--steps must be 0 (the decomposition only) or >= 3, got "
                         f"{args.steps}: K(p) is differenced over the steps, and "
                         f"{args.steps} give(s) at most one secant (every curve flat, no "
                         f"macro/micro split)")
    surface = mirrored_if_asked(args, surface_from_args(args))
    if args.steps and not surface.periodic:
        warn(args, "the K(p) of a non-periodic window is mostly the window's flat-punch bulk "
                   "stiffness (1/K ~ 1/K_interface + C, as `roughfe contact` says), the same "
                   "for every band, so c_n of K compares bulk-dominated curves; --mirror "
                   "solves the evenly mirrored window, whose K is the interface's")
    material = material_from_args(args)
    # --detrend acted once, on reading (lines / lines-tilt on the measured scan lines,
    # before --mirror); only the mean left (the mirrored map's) is removed here. Until
    # round 2, session 35 the mirrored map's lines were levelled again (by up to
    # 1.6 % of Sq on a 96 x 64 map)
    bands = replace(band_chromosomes(surface, args.gamma, detrend=(
        "none" if args.detrend == "none" else "mean")), detrend=args.detrend)
    folder = output_folder_of(args, "genome chromosomes")
    mech = None
    if args.steps:
        if not args.quiet:   # before the sweeps, which dominate the run time (a review)
            from ..genomics.band_plan import plan_band_sweeps
            plan = plan_band_sweeps(bands, youngs_modulus=material.E, poisson=material.nu,
                                    n_steps=args.steps)
            print(f"mechanics: {plan.summary()}", flush=True)
        mech = band_mechanics(bands, youngs_modulus=material.E, poisson=material.nu,
                              n_steps=args.steps)
        split = band_macro_micro(mech, threshold=args.threshold)
    with folder as out:
        with atomic_path(out / "chromosomes.npz") as tmp:
            np.savez_compressed(tmp, chromosomes=bands.chromosomes,
                                surface=bands.surface.heights, q_bounds=bands.q_bounds,
                                indices=bands.indices, energy=bands.energy,
                                size=np.asarray(bands.surface.size), gamma=bands.gamma,
                                transform=bands.transform, detrend=bands.detrend,
                                units=np.array(json.dumps(CHROMOSOMES_UNITS)))
        if mech is not None:
            write_json(out / "mechanics.json", mech.to_dict())
            write_json(out / "macro_micro.json", {
                "threshold": split.threshold, "macro": list(split.macro),
                "micro": list(split.micro), "c_n_K": split.corr_k, "c_n_A": split.corr_a,
                "chromosomes": split.chromosomes, "success": split.success,
                "message": split.message})
        if not args.no_figures:
            from ..plotting import bands as bp
            paths = [bp.render_band_sums(bands, out / "td.png", "td"),
                     bp.render_band_sums(bands, out / "bu.png", "bu"),
                     bp.render_band_sums(bands, out / "chromosomes.png", "chromosomes"),
                     bp.plot_band_energy(bands, out / "energy.png")]
            if mech is not None:
                paths += [bp.plot_band_curves(mech, out / "curves.png"),
                          bp.plot_band_correlations(mech, out / "correlations.png", split)]
            if not args.quiet:
                for p in paths:
                    print(f"  figure {p}")
    if not args.quiet:
        print(f"{bands.n_chromosomes} band chromosomes (gamma = {bands.gamma:.4g}, "
              f"{bands.transform.upper()}, detrend {bands.detrend}); wavelengths "
              f"{bands.wavelengths()[0]:.4g} .. {bands.wavelengths()[-1]:.4g} m")
        print("  share of <h^2> (%): " + " ".join(f"{100 * e / bands.energy.sum():.2f}"
                                                for e in bands.energy))
        if mech is not None:
            print(f"  {mech.message}; macro bands {list(split.macro)}, micro {list(split.micro)}")
        print(f"outputs -> {out}")
    if mech is not None and (not split.macro or not split.micro):
        c = np.asarray(split.corr_k, float)
        c = c[np.isfinite(c)]
        side = "macro" if not split.micro else "micro"
        warn(args, f"every band is {side} at --threshold {split.threshold:g} (c_n of K "
                   + (f"{c.min():.4f} .. {c.max():.4f}" if c.size else "undefined")
                   + f"): the split does not discriminate here; it depends on --steps and "
                   f"--threshold (docs/theory/surface-genomics.md)")
    return 0 if mech is None or (mech.success and split.success) else 1
