"""``roughfe genome natural``: sequence a row of a measured topography (thesis Sec.
3.4.2); registered by :mod:`roughfe.cli.genome_cmd`, split from it (round 2, session 32)
to keep each command module under the 500-line limit."""
from __future__ import annotations

from pathlib import Path

from .options import material_from_args, output_folder_of, surface_from_args


def _check_line(args, surface):
    """``--row``/``--axis`` within the surface read, else an InputError in the options'
    words (the library's names a Python call)."""
    from ..errors import InputError
    if surface.ndim == 1:
        if args.row is not None or args.axis != "x":
            raise InputError(f"--row/--axis pick a line of a topography (2D); {args.surface} "
                             f"is a profile of {surface.shape[0]} samples, sequenced as it is "
                             f"(drop --row and --axis)")
        return
    lines = surface.shape[1 if args.axis == "x" else 0]
    if args.row is not None and not 0 <= args.row < lines:
        raise InputError(f"--row {args.row}: {args.surface} ({surface.shape[0]} x "
                         f"{surface.shape[1]}) has rows 0..{lines - 1} along {args.axis} "
                         f"(default: the central one, {lines // 2})")


def _natural(args) -> int:
    from ..genomics.genome import save_genome
    from ..genomics.natural import (nested_acquisitions, sequence_measured,
                                    sequencing_time_estimate)
    from .genome_cmd import _print_sequencing, _sequence_figures   # (genome_cmd imports us)
    from ..surfaces.io import save_surface
    from ..writers import write_json
    surface = surface_from_args(args)
    material = material_from_args(args)
    _check_line(args, surface)
    folder = output_folder_of(args, "genome natural")
    if not args.quiet:     # before the run (sur-2: 111 s without a word; a review)
        acq = nested_acquisitions(surface, args.fractions, args.nodes, row=args.row,
                                  axis=args.axis)
        line = (f"row {args.row if args.row is not None else 'central'} along {args.axis}"
                if surface.ndim == 2 else "the profile")
        print(f"{line}: acquisitions of "
              + ", ".join(f"{a.shape[0]} nodes (stride {a.metadata['stride']})" for a in acq)
              + f"; the lattice fit takes up to ~{sequencing_time_estimate(acq):.0f} s on a "
              f"row that is not WM-like (an exact WM profile: a fraction of that)"
              + (f", then {2 * len(args.kernels)} A(p), K(p) sweeps of {args.steps} steps"
                 if args.kernels else ""), flush=True)
    res = sequence_measured(surface, fractions=args.fractions, n_nodes=args.nodes,
                            seed=args.seed, kernels=args.kernels, n_steps=args.steps,
                            rms_tolerance=args.tolerance, youngs_modulus=material.E_star,
                            row=args.row, axis=args.axis)
    with folder as out:
        stem = Path(args.surface).stem
        for k, a in enumerate(res.acquisitions):
            save_surface(a, out / f"{stem}_acq{k + 1}.npz")
        if not args.no_figures:
            from ..plotting import genomics as gp
            _sequence_figures(res.sequencing, out, f"{stem}_")
            if res.curves:
                gp.plot_measured_vs_sequenced(res.curves, out / f"{stem}_curves.png",
                                              title=f"{stem}: measured vs sequenced")
        save_genome(res.sequencing.genome, out / f"{stem}_genome.json")
        write_json(out / f"{stem}_report.json", res.report())
    _print_sequencing(res.sequencing)
    print("  measured samples per acquisition: "
          + ", ".join(str(a.metadata["measured_points"]) for a in res.acquisitions))
    for k, v in res.curves.items():
        d = v["difference"]
        if "note" in d:
            print(f"  {k} kernel: A(p), K(p) not compared: {d['note']}")
        else:
            print(f"  {k} kernel: A(p) differs by up to {100 * d['A']:.3g} %, "
                  f"K(p) by {100 * d['K']:.3g} %")
    print(f"outputs -> {out}")
    return 0 if res.success or not args.strict else 1
