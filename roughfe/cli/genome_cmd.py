"""``roughfe genome example|realize|sequence|mechanics|natural|chromosomes|validity``:
surface roughness genomics I (``chromosomes`` in :mod:`roughfe.cli.chromosomes_cmd`).

Each subcommand parses, calls one library function of :mod:`roughfe.genomics`, writes
its outputs (atomically) and prints a summary; figures come from
:mod:`roughfe.plotting.genomics`.
"""
from __future__ import annotations

import math
from pathlib import Path

from .options import (add_detrend_option, add_material_options, add_output_file,
                      add_output_folder, add_run_options, add_surface_options, at_least_three,
                      int_in,
                      material_from_args, nonnegative_int, output_file_of,
                      output_folder_of, positive_float, positive_int, surface_from_args,
                      unit_fraction, warn)

from ..genomics.genome import SCALES
from ..genomics.natural import DEFAULT_FRACTIONS
from .chromosomes_cmd import _chromosomes
from .natural_cmd import _natural
from .repeated import Distinct

#: largest ``genome validity --max-ridges``: the Monte Carlo costs ~ M^3 x trials (M = 200
#: at the default 1000 trials: 11 s; 500: ~3 min and 3 GB); the thesis' Fig. 29 stops at
#: 20. 10^11 was a "not enough memory" line after the list of M was built (session 33).
MAX_RIDGES = 500

def _print_genome(g, prefix="  "):
    print(f"{prefix}A = {g.A:.6g} m^(1-H)   H = {g.H:.6g}   gamma = {g.gamma:.8g}   "
          f"lambda1 = {g.lambda1:.8g} m   M = {g.M}   n = {g.n_first}..{g.n_last}")


def _example(args) -> int:
    from ..genomics.genome import save_genome, table1_genome
    out = output_file_of(args, suffixes=(".json",))
    g = table1_genome(rng=args.seed, n_max=args.n_max)
    save_genome(g, out)
    print(f"Table 1 genome (phases from seed {args.seed}) -> {out}")
    _print_genome(g)
    return 0


def _check_chromosomes(args, g):
    """``--chromosomes`` within the phases the genome file holds, else an InputError that
    names this command's options (the library's message names a Python call)."""
    from ..errors import InputError
    outside = [n for n in args.chromosomes or () if not g.n_first <= n <= g.n_last]
    if outside:
        raise InputError(
            f"--chromosomes {' '.join(map(str, outside))}: {args.genome} holds phases for "
            f"n = {g.n_first}..{g.n_last} only; give indices in that range, or a genome file "
            f"with more chromosomes (the Table 1 example: `roughfe genome example --n-max "
            f"{max(outside)} -o FILE`)")


def _realize(args) -> int:
    from ..errors import InputError
    from ..genomics.genome import load_genome, realize, realize_surface
    from ..genomics.periodic import realization
    from ..surfaces.io import save_surface
    g = load_genome(args.genome)
    out = output_file_of(args, suffixes=(".npz",))
    # a part of a design (genome_partK.json of `roughfe design`) carries its chromosomes,
    # the design's L and N and its dimension: by default it realises its share of the
    # design (the sum of the parts is the designed profile or surface)
    meta = g.metadata or {}
    chromosomes = args.chromosomes or meta.get("chromosomes")
    nodes = args.nodes or int(meta.get("n_nodes", 512))
    length = args.length if (args.length is not None or args.scale is not None) \
        else meta.get("length")
    if length is None and args.scale is None:
        raise InputError("give --length L (m) or --scale (a part of a design has its own L)")
    if meta.get("dim") == 2:
        if args.scale is not None:
            raise InputError("--scale is for profiles; this genome is a part of a periodic "
                             "surface design: give --length (default: the design's)")
        _check_chromosomes(args, g)
        s = realization(g, length, nodes, 2, chromosomes)
    elif g.angles is not None:
        # a surface genome (ridge angles: sequenced from 2D acquisitions, or made with
        # angles): the non-periodic N x N window of Eq. 3.17 the sequencer models; its
        # profile by Eq. 3.1 would ignore the angles (no line of that surface)
        if args.chromosomes:
            raise InputError(f"--chromosomes {' '.join(map(str, args.chromosomes))}: a "
                             f"surface genome (ridge angles) is realised with the Eq. 3.5 "
                             f"chromosomes it holds; --chromosomes is for profiles and parts "
                             f"of a design")
        s = realize_surface(g, g.length_of(args.scale) if args.scale else length, nodes)
    else:
        _check_chromosomes(args, g)
        s = realize(g, length=length, scale=args.scale, n_nodes=nodes, chromosomes=chromosomes)
    save_surface(s, out)
    m = s.metadata
    kind = {1: "", 2: "surface " if not s.periodic else "periodic surface "}[s.ndim]
    print(f"realised {kind}L = {m['length']:.6g} m, "
          f"N = {m['n_nodes']}, chromosomes "
          f"{m['chromosomes'][0]}..{m['chromosomes'][-1]} (Eq. 3.5: n_s = {m['n_s']}, n_f = {m['n_f']}) "
          f"-> {out}")
    held, wanted = m["chromosomes"], (m["n_s"], m["n_f"])
    if not chromosomes and (held[0] > wanted[0] or held[-1] < wanted[1]):
        warn(args, f"band-limited realisation: this window asks for chromosomes "
                   f"{wanted[0]}..{wanted[1]} (Eq. 3.5) but the genome holds only "
                   f"{g.n_first}..{g.n_last} (a sequenced genome holds the band of its data): "
                   f"the realisation lacks the waves of chromosomes "
                   + ", ".join(f"{a}..{b}" for a, b in ((wanted[0], held[0] - 1),
                                                        (held[-1] + 1, wanted[1])) if a <= b))
    return 0


def _sequence_figures(res, outdir: Path, stem: str):
    from ..genomics.chromosomes import reconstruction
    from ..plotting import genomics as gp
    paths = [gp.plot_sequenced_profiles(res, outdir / f"{stem}profiles.png"),
             gp.plot_spectra(res, outdir / f"{stem}psd.png")]
    g = res.genome
    for order in ("td", "bu"):
        rec = reconstruction(g, float(res.lengths[0]), len(res.x[0]), order=order)
        paths.append(gp.plot_reconstruction(rec, outdir / f"{stem}{order}.png"))
    return paths


def _percent_or_undefined(e):
    return f"{100 * e:.4g} %" if math.isfinite(e) else "not defined (no genome fits it)"


def _print_sequencing(res):
    # a failed sequencing says so before its genes, which are then no genome of the data
    print("sequenced genome:" if res.success else
          "sequenced genome (FAILED quality check, see below: the genes are the best fit "
          "found, not a genome of the data):")
    _print_genome(res.genome)
    for k, (L, r, e) in enumerate(zip(res.lengths, res.ranges, res.rms_errors)):
        print(f"  acquisition {k + 1}: L = {L:.6g} m, n = {r[0]}..{r[1]}, relative rms error "
              f"{_percent_or_undefined(e)}")
    if math.isfinite(res.H_stderr):
        support = ("" if res.M_support is None else
                   f"; M = {res.M_support[0]}..{res.M_support[1]} within the likelihood "
                   f"interval (~95 %)")
        print(f"  1-sigma errors (Fisher information, {res.n.size} chromosomes): H +- "
              f"{res.H_stderr:.2g}, ln A +- {res.lnA_stderr:.2g} (A within a factor "
              f"{math.exp(res.lnA_stderr):.3g}){support}")
    print(f"  PSD-only estimates (thesis): gamma = {res.gamma_psd:.5g}, H (peak slope) = {res.H_psd:.4g}")
    print(f"  {'success' if res.success else 'FAILED quality check'}: {res.message}")


def _sequence(args) -> int:
    from ..errors import InputError
    from ..surfaces.io import load_surface
    surfaces = []
    for p in args.profiles:
        if Path(p).suffix.lower() == ".json":
            raise InputError(f"{p} is a JSON file (a genome?), not an acquisition: sequence "
                             f"reads realised profiles or surfaces (.npz, e.g. from `roughfe "
                             f"genome realize GENOME.json -o X.npz`) or instrument files")
        try:
            surfaces.append(load_surface(p))
        except InputError as exc:   # this command has no --size: files must carry theirs
            if "--size" not in str(exc):
                raise
            raise InputError(f"{str(exc).split('; give size')[0]}; `roughfe genome sequence` "
                             f"takes no --size: give files that carry their size (.npz from "
                             f"`roughfe generate` or `genome realize`, instrument files)"
                             ) from None
    dims = sorted({s.ndim for s in surfaces})
    if dims == [2]:
        return _sequence_surfaces(args, surfaces)
    if dims != [1]:
        from ..genomics.sequencing.acquisitions import PROFILE_PATH, SURFACE_PATH
        raise InputError("acquisitions mix profiles (1D) and surfaces (2D): "
                         + ", ".join(f"{p} is {s.ndim}D" for p, s in zip(args.profiles, surfaces))
                         + f"; sequence them apart: {PROFILE_PATH}; {SURFACE_PATH}; a row of a "
                           f"measured surface as profiles: `roughfe genome natural FILE`")
    return _sequence_profiles(args, surfaces)


def _sequence_surfaces(args, surfaces) -> int:
    """2D MWM acquisitions: angles, anisotropy and every phase (issue 15)."""
    from ..genomics.genome import save_genome
    from ..genomics.sequencing import sequence_surfaces
    from ..writers import write_json
    folder = output_folder_of(args, "genome sequence")
    res = sequence_surfaces(surfaces, rms_tolerance=args.tolerance)
    with folder as out:
        write_json(out / "report.json", res.report())
        if res.genome is not None:
            save_genome(res.genome, out / "genome.json")
            if not args.no_figures:
                from ..plotting.genomics import plot_sequenced_surfaces
                print(f"  figure {plot_sequenced_surfaces(res, surfaces, out / 'surfaces.png')}")
    if res.genome is not None:
        print("sequenced surface genome:")
        _print_genome(res.genome)
        print("  ridge angles (deg): " + " ".join(f"{a:.4f}" for a in res.genome.angles * 57.29577951308232))
        print("  anisotropy        : " + " ".join(f"{a:.4f}" for a in res.genome.anisotropy))
    for k, (L, e) in enumerate(zip(res.lengths, res.rms_errors)):
        print(f"  acquisition {k + 1}: L = {L:.6g} m, relative rms error "
              f"{_percent_or_undefined(e)}")
    print(f"  {'success' if res.success else 'FAILED quality check'}: {res.message}")
    print(f"report -> {out / 'report.json'}")
    return 0 if res.success or not args.strict else 1


def _sequence_profiles(args, surfaces) -> int:
    from ..genomics.genome import save_genome
    from ..genomics.sequencing import sequence_profiles
    from ..writers import write_json
    folder = output_folder_of(args, "genome sequence")
    res = sequence_profiles(surfaces, seed=args.seed, M=args.ridges, rms_tolerance=args.tolerance)
    with folder as out:
        if not args.no_figures:
            for p in _sequence_figures(res, out, ""):
                print(f"  figure {p}")
        write_json(out / "report.json", res.report())
        save_genome(res.genome, out / "genome.json")
    _print_sequencing(res)
    print(f"genome -> {out / 'genome.json'}")
    return 0 if res.success or not args.strict else 1


def _mechanics(args) -> int:
    from ..genomics.genome import load_genome
    from ..genomics.mechanics import chromosome_mechanics
    from ..writers import write_json
    g = load_genome(args.genome)
    if g.angles is not None:
        # its Eq. 3.1 profile would ignore the angles: no line of that surface (a review)
        from ..errors import InputError
        raise InputError(f"{args.genome} is a surface genome (ridge angles): `genome "
                         f"mechanics` sweeps the chromosomes of an Eq. 3.1 profile, which "
                         f"would ignore its angles; realise it (`roughfe genome realize`) "
                         f"and take its band chromosomes (`roughfe genome chromosomes`)")
    material = material_from_args(args)
    length = args.length if args.length is not None else g.length_of(args.scale)
    from ..genomics.genome import realize
    from ..surfaces.stats import rms_slope
    from .plausibility import check_curve
    slope = rms_slope(realize(g, length, args.nodes))
    ok = True
    with output_folder_of(args, "genome mechanics") as out:
        for kernel in args.kernels:
            mech = chromosome_mechanics(g, length=length, n_nodes=args.nodes,
                                        youngs_modulus=material.E, poisson=material.nu,
                                        kernel=kernel, n_steps=args.steps,
                                        max_chromosomes=args.max_chromosomes)
            if not args.no_figures:
                from ..plotting import genomics as gp
                gp.plot_chromosome_curves(mech, out / f"chromosomes_{kernel}.png")
                gp.plot_td_bu(mech, out / f"td_bu_A_{kernel}.png", "A")
                gp.plot_td_bu(mech, out / f"td_bu_K_{kernel}.png", "K")
                gp.plot_correlations(mech, out / f"correlations_{kernel}.png")
            write_json(out / f"mechanics_{kernel}.json", mech.to_dict())
            ok = ok and mech.success
            print(f"{kernel} kernel: {mech.message}, {mech.elapsed:.1f} s")
            check_curve(args, f"{kernel} kernel, the complete profile", mech.complete.pressure,
                        material.E_star, slope=slope)
            print("  c_n TD (K): " + " ".join(f"{v:.3f}" for v in mech.c_td["K"]))
            print("  c_n BU (K): " + " ".join(f"{v:.3f}" for v in mech.c_bu["K"]))
    print(f"curves, c_n{'' if args.no_figures else ' and figures'} -> {out}")
    return 0 if ok else 1          # a BEM sweep that did not converge: a check missed


def _validity(args) -> int:
    from ..genomics.chromosomes import validity_monte_carlo
    from ..plotting import genomics as gp
    out = output_file_of(args, suffixes=(".png",))
    res = validity_monte_carlo(range(2, args.max_ridges + 1), args.trials, rng=args.seed)
    gp.plot_validity(res, out)
    print("M      : " + " ".join(f"{m:5d}" for m in res.M))
    print("Eq 3.10: " + " ".join(f"{100 * v:5.1f}" for v in res.valid_fraction))
    print("arccos : " + " ".join(f"{100 * v:5.1f}" for v in res.arccos_fraction))
    print(f"figure -> {out}")
    return 0


def _length_or_scale(p, required=True, default=None):
    g = p.add_mutually_exclusive_group(required=required)
    g.add_argument("--scale", choices=sorted(SCALES), default=default,
                   help="named observation scale: L = lambda1 (10x), lambda1/2 (20x), "
                        "lambda1/10 (100x)")
    g.add_argument("--length", type=positive_float, help="observation length L (m)")


def _add_response_options(p, nargs, kernels_help):
    """``--kernels``, ``--E``/``--nu`` and ``--steps`` of the A(p), K(p) sweeps."""
    p.add_argument("--kernels", nargs=nargs, choices=("thesis", "strip"), action=Distinct,
                   default=["thesis", "strip"], help=kernels_help)
    add_material_options(p)
    p.add_argument("--steps", type=at_least_three, default=20,
                   help="equal approaches up to the peak-valley amplitude, >= 3 (K is "
                        "differenced over them)")


def register(sub):
    top = sub.add_parser("genome", help="surface roughness genomics: realise, sequence, chromosome mechanics",
                         description="Surface roughness genomics (thesis Ch. 3): write the "
                                     "Table 1 genome, realise a genome as a profile, sequence "
                                     "a genome from nested acquisitions or a measured "
                                     "topography, and the contact mechanics of its "
                                     "chromosomes. Genomes are roughfe-genome JSON files.")
    gs = top.add_subparsers(dest="genome_command", metavar="ACTION")
    gs.required = True

    p = gs.add_parser("example", help="write the Table 1 genome (A=1, H=0.75, gamma=1.5, M=8, lambda1=1 mm)",
                      description="Write the genome of thesis Table 1 (A = 1, H = 0.75, "
                                  "gamma = 1.5, M = 8, lambda1 = 1 mm) with seeded phases "
                                  "(the thesis does not publish its phases).")
    add_output_file(p, "genome JSON file to write")
    p.add_argument("--seed", type=nonnegative_int, default=0,
                   help="seed of the (unpublished) phases")
    p.add_argument("--n-max", type=positive_int, default=22,
                   help="last chromosome with a phase (22 covers the 100x scale)")
    p.set_defaults(func=_example)

    p = gs.add_parser("realize", help="realise a genome as a profile (Eq. 3.1, 3.5) or, "
                                      "with ridge angles, a 2D surface (Eq. 3.17)",
                      description="Realise a roughfe-genome JSON as a profile of N nodes over "
                                  "L (Eq. 3.1 with the chromosomes of Eq. 3.5) and save it as "
                                  "a roughfe .npz surface. A genome with ridge angles (e.g. "
                                  "sequenced from 2D acquisitions) is realised as the N x N "
                                  "window of Eq. 3.17 (projected plane waves; beyond the "
                                  "thesis), a part of a periodic surface design as its "
                                  "periodic surface.")
    p.add_argument("genome", metavar="GENOME.json", help="roughfe-genome JSON file")
    _length_or_scale(p, required=False)      # required, unless the genome is a design part
    p.add_argument("--nodes", type=positive_int, default=None,
                   help="number of nodes N (spacing L/(N-1)); default the genome's own "
                        "(metadata n_nodes: a design part's or a sequenced genome's "
                        "acquisitions'), else 512")
    p.add_argument("--chromosomes", type=positive_int, nargs="+",
                   help="sum only these chromosome indices (default: those of Eq. 3.5, or "
                        "the part's own for a part of a design)")
    add_output_file(p, "profile or surface .npz to write (roughfe surface format)")
    p.set_defaults(func=_realize)

    p = gs.add_parser("sequence", help="sequence a genome from nested acquisitions (profiles or 2D surfaces)",
                      description="Sequence a genome from acquisitions at nested lengths: "
                                  "2-3 profiles (Sec. 3.3.1: gamma, lambda1, the chromosome "
                                  "sums, statistical A, H, M) or one or more 2D MWM surfaces "
                                  "(every gene: M, ridge angles, anisotropy and phases). "
                                  "Writes OUTDIR/genome.json, OUTDIR/report.json and figures.")
    p.add_argument("profiles", nargs="+", metavar="ACQUISITION.npz",
                   help="acquisitions of one profile or surface (same N, nested windows "
                        "centred on the origin)")
    p.add_argument("--seed", type=nonnegative_int, default=0,
                   help="seed of the M likelihood and the phase draws")
    p.add_argument("--ridges", type=positive_int, default=None,
                   help="impose M (default: maximum likelihood)")
    p.add_argument("--tolerance", type=unit_fraction, default=0.05,
                   help="relative rms error below which a profile counts as WM-like, in "
                        "(0, 1)")
    p.add_argument("--strict", action="store_true", help="exit 1 when the quality check fails")
    add_output_folder(p)
    add_run_options(p)
    p.set_defaults(func=_sequence)

    p = gs.add_parser("mechanics", help="A(p), K(p) of a realisation, its chromosomes and TD/BU sums (Fig. 36-39)",
                      description="BEM A(p), K(p) of a genome's realisation, of its single "
                                  "chromosomes and of the top-down/bottom-up sums (thesis "
                                  "Sec. 3.4.1, Fig. 36-39). Writes OUTDIR/mechanics_KERNEL.json "
                                  "and the figures.")
    p.add_argument("genome", metavar="GENOME.json", help="roughfe-genome JSON file")
    _length_or_scale(p, required=False, default="10x")
    p.add_argument("--nodes", type=positive_int, default=512, help="number of nodes N")
    _add_response_options(p, "+", "BEM kernels: thesis (Eq. 2.4) and/or strip (plane strain)")
    p.add_argument("--max-chromosomes", type=positive_int, default=10,
                   help="single-chromosome curves (thesis: 10)")
    add_output_folder(p)
    add_run_options(p)
    p.set_defaults(func=_mechanics)

    p = gs.add_parser("natural", help="sequence a row of a measured topography (Sec. 3.4.2)",
                      description="Sequence one row of a measured topography (thesis "
                                  "Sec. 3.4.2; default the central row along x) or a "
                                  "profile: nested windows of it (its own samples, every "
                                  "s-th where a window holds more than --nodes), their "
                                  "genome and report, and the measured vs sequenced A(p), "
                                  "K(p). A profile realised from a genome is sequenced back "
                                  "exactly. The row is levelled by its own least-squares "
                                  "line (an instrument tilt or a removed plane changes "
                                  "nothing), so there is no --detrend.")
    add_surface_options(p)
    p.add_argument("--axis", choices=("x", "y"), default="x",
                   help="direction of the row: along x (heights[:, j]) or y (heights[i, :])")
    p.add_argument("--row", type=nonnegative_int, default=None, metavar="INDEX",
                   help="index of the row across --axis (0-based; default the central one)")
    p.add_argument("--fractions", type=positive_float, nargs="+", default=list(DEFAULT_FRACTIONS),
                   help="nested window lengths as fractions of the row")
    p.add_argument("--nodes", type=positive_int, default=512,
                   help="largest number of nodes per acquisition")
    p.add_argument("--seed", type=nonnegative_int, default=0,
                   help="seed of the M likelihood and phase draws")
    _add_response_options(p, "*", "BEM kernels for A(p), K(p) (none: sequencing only)")
    p.add_argument("--tolerance", type=unit_fraction, default=0.05,
                   help="relative rms error below which a profile counts as WM-like, in "
                        "(0, 1)")
    p.add_argument("--strict", action="store_true",
                   help="exit 1 when the quality check fails (as genome sequence)")
    add_output_folder(p)
    add_run_options(p)
    p.set_defaults(func=_natural)

    p = gs.add_parser("chromosomes", help="band chromosomes of any surface, their A(p), K(p) and Alg. 2",
                      description="Split any surface or profile (measured files included) "
                                  "into band chromosomes: the parts of its Fourier (periodic) "
                                  "or cosine (window) transform in the annuli [q_n, gamma q_n). "
                                  "They sum exactly to the detrended surface. Then the BEM "
                                  "A(p), K(p) of every chromosome and top-down/bottom-up sum, "
                                  "their correlation with the whole surface and the macro/micro "
                                  "split of Alg. 2. Writes OUTDIR/chromosomes.npz "
                                  "(chromosomes, surface, q_bounds, ...), mechanics.json, "
                                  "macro_micro.json and figures.")
    add_surface_options(p)
    add_detrend_option(p, default="plane")    # band_chromosomes' (a tilt fills band 1)
    p.add_argument("--mirror", action="store_true",
                   help="decompose and solve the evenly mirrored window (periodic, "
                        "Surface.mirrored, as `contact --mirror`): the K(p) of a "
                        "non-periodic window is mostly its flat-punch bulk stiffness, the "
                        "same for every band; 4x the points. A non-periodic SURFACE only")
    p.add_argument("--gamma", type=positive_float, default=2 ** 0.5,
                   help="band ratio q_{n+1}/q_n (the genome's gamma when known)")
    add_material_options(p)
    p.add_argument("--steps", type=nonnegative_int, default=20,
                   help="equal approaches per A(p), K(p) curve, >= 3 (K is differenced "
                        "over them; 0: decomposition only). The BEM sweeps dominate the "
                        "run time: about 3 per band (55 for the 19 bands of a 512 x 512 "
                        "grid), each of STEPS solves on the whole grid; the number and a "
                        "rough time estimate are printed before they start")
    p.add_argument("--threshold", type=unit_fraction, default=0.95,
                   help="Alg. 2: c_n of K(p) above which a band is macro-scale roughness "
                        "(checked before the sweeps)")
    add_output_folder(p)
    add_run_options(p)
    p.set_defaults(func=_chromosomes)  # roughfe.cli.chromosomes_cmd

    p = gs.add_parser("validity", help="Monte Carlo of Eq. 3.10 (Fig. 29)",
                      description="Monte Carlo check of the validity condition Eq. 3.10 (thesis "
                                  "Fig. 29): for M = 2..MAX ridges, the fraction of random phase "
                                  "draws for which Eq. 3.10 holds, beside the arccos form.")
    p.add_argument("--trials", type=positive_int, default=1000,
                   help="random phase draws per number of ridges M")
    p.add_argument("--max-ridges", type=int_in(2, MAX_RIDGES), default=20,
                   help="largest number of ridges M (from 2; the cost grows as M^3 x "
                        "trials: 200 at 1000 trials took 11 s)")
    p.add_argument("--seed", type=nonnegative_int, default=0,
                   help="seed of the random phases")
    add_output_file(p, "figure (.png) to write")
    p.set_defaults(func=_validity)
