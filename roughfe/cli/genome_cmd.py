"""``roughfe genome example|realize|sequence|mechanics|natural``: surface roughness genomics I.

Each subcommand parses, calls one library function of :mod:`roughfe.genomics`, writes
its outputs (atomically) and prints a summary; figures come from
:mod:`roughfe.plotting.genomics`.
"""
from __future__ import annotations

from pathlib import Path

from ..genomics.chromosomes import reconstruction, validity_monte_carlo
from ..genomics.genome import SCALES, load_genome, realize, save_genome, table1_genome
from ..genomics.mechanics import THESIS_YOUNGS_MODULUS, chromosome_mechanics
from ..genomics.natural import DEFAULT_FRACTIONS, sequence_measured
from ..genomics.sequencing import sequence_profiles
from ..surfaces.io import load_surface, save_surface
from ..writers import write_json
from .common import add_surface_options, surface_from_args


def _print_genome(g, prefix="  "):
    print(f"{prefix}A = {g.A:.6g} m^(1-H)   H = {g.H:.6g}   gamma = {g.gamma:.8g}   "
          f"lambda1 = {g.lambda1:.8g} m   M = {g.M}   n = {g.n_first}..{g.n_last}")


def _example(args) -> int:
    g = table1_genome(rng=args.seed, n_max=args.n_max)
    save_genome(g, args.output)
    print(f"Table 1 genome (phases from seed {args.seed}) -> {args.output}")
    _print_genome(g)
    return 0


def _realize(args) -> int:
    g = load_genome(args.genome)
    s = realize(g, length=args.length, scale=args.scale, n_nodes=args.nodes,
                chromosomes=args.chromosomes)
    save_surface(s, args.output)
    m = s.metadata
    print(f"realised L = {m['length']:.6g} m, N = {m['n_nodes']}, chromosomes "
          f"{m['chromosomes'][0]}..{m['chromosomes'][-1]} (Eq. 3.5: n_s = {m['n_s']}, n_f = {m['n_f']}) "
          f"-> {args.output}")
    return 0


def _sequence_figures(res, outdir: Path, stem: str):
    from ..plotting import genomics as gp
    outdir.mkdir(parents=True, exist_ok=True)
    paths = [gp.plot_sequenced_profiles(res, outdir / f"{stem}_profiles.png"),
             gp.plot_spectra(res, outdir / f"{stem}_psd.png")]
    g = res.genome
    for order in ("td", "bu"):
        rec = reconstruction(g, float(res.lengths[0]), len(res.x[0]), order=order)
        paths.append(gp.plot_reconstruction(rec, outdir / f"{stem}_{order}.png"))
    return paths


def _print_sequencing(res):
    print("sequenced genome:")
    _print_genome(res.genome)
    for k, (L, r, e) in enumerate(zip(res.lengths, res.ranges, res.rms_errors)):
        print(f"  acquisition {k + 1}: L = {L:.6g} m, n = {r[0]}..{r[1]}, relative rms error "
              f"{100 * e:.4g} %")
    print(f"  PSD-only estimates (thesis): gamma = {res.gamma_psd:.5g}, H (peak slope) = {res.H_psd:.4g}")
    print(f"  {'success' if res.success else 'FAILED quality check'}: {res.message}")


def _sequence(args) -> int:
    surfaces = [load_surface(p) for p in args.profiles]
    res = sequence_profiles(surfaces, seed=args.seed, M=args.ridges, rms_tolerance=args.tolerance)
    out = Path(args.output)
    save_genome(res.genome, out)
    write_json(out.with_name(out.stem + "_report.json"), res.report())
    _print_sequencing(res)
    if not args.no_figures:
        figdir = Path(args.figures) if args.figures else out.parent
        for p in _sequence_figures(res, figdir, out.stem):
            print(f"  figure {p}")
    print(f"genome -> {out}")
    return 0 if res.success or not args.strict else 1


def _mechanics(args) -> int:
    from ..plotting import genomics as gp
    g = load_genome(args.genome)
    out = Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    length = args.length if args.length is not None else g.length_of(args.scale)
    for kernel in args.kernels:
        mech = chromosome_mechanics(g, length=length, n_nodes=args.nodes,
                                    youngs_modulus=args.youngs_modulus, poisson=args.poisson,
                                    kernel=kernel, n_steps=args.steps,
                                    max_chromosomes=args.max_chromosomes)
        write_json(out / f"mechanics_{kernel}.json", mech.to_dict())
        gp.plot_chromosome_curves(mech, out / f"chromosomes_{kernel}.png")
        gp.plot_td_bu(mech, out / f"td_bu_A_{kernel}.png", "A")
        gp.plot_td_bu(mech, out / f"td_bu_K_{kernel}.png", "K")
        gp.plot_correlations(mech, out / f"correlations_{kernel}.png")
        print(f"{kernel} kernel: {mech.message}, {mech.elapsed:.1f} s")
        print("  c_n TD (K): " + " ".join(f"{v:.3f}" for v in mech.c_td["K"]))
        print("  c_n BU (K): " + " ".join(f"{v:.3f}" for v in mech.c_bu["K"]))
    print(f"curves, c_n and figures -> {out}")
    return 0


def _natural(args) -> int:
    from ..plotting import genomics as gp
    surface = surface_from_args(args)
    out = Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    res = sequence_measured(surface, fractions=args.fractions, n_nodes=args.nodes, seed=args.seed,
                            kernels=args.kernels, n_steps=args.steps,
                            rms_tolerance=args.tolerance)
    stem = Path(args.surface).stem
    for k, a in enumerate(res.acquisitions):
        save_surface(a, out / f"{stem}_acq{k + 1}.npz")
    save_genome(res.sequencing.genome, out / f"{stem}_genome.json")
    write_json(out / f"{stem}_report.json", res.report())
    _print_sequencing(res.sequencing)
    print("  measured samples per acquisition: "
          + ", ".join(str(a.metadata["measured_points"]) for a in res.acquisitions))
    for k, v in res.curves.items():
        d = v["difference"]
        print(f"  {k} kernel: A(p) differs by up to {100 * d['A']:.3g} %, K(p) by {100 * d['K']:.3g} %")
    _sequence_figures(res.sequencing, out, stem)
    if res.curves:
        gp.plot_measured_vs_sequenced(res.curves, out / f"{stem}_curves.png",
                                      title=f"{stem}: measured vs sequenced")
    print(f"outputs -> {out}")
    return 0


def _validity(args) -> int:
    from ..plotting import genomics as gp
    res = validity_monte_carlo(range(2, 21), args.trials, rng=args.seed)
    gp.plot_validity(res, args.output)
    print("M      : " + " ".join(f"{m:5d}" for m in res.M))
    print("Eq 3.10: " + " ".join(f"{100 * v:5.1f}" for v in res.valid_fraction))
    print("arccos : " + " ".join(f"{100 * v:5.1f}" for v in res.arccos_fraction))
    print(f"figure -> {args.output}")
    return 0


def _length_or_scale(p):
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument("--scale", choices=sorted(SCALES), help="named scale: L = lambda1, lambda1/2, lambda1/10")
    g.add_argument("--length", type=float, help="observation length L (m)")


def register(sub):
    top = sub.add_parser("genome", help="surface roughness genomics: realise, sequence, chromosome mechanics",
                         description=__doc__)
    gs = top.add_subparsers(dest="genome_command", metavar="ACTION")
    gs.required = True

    p = gs.add_parser("example", help="write the Table 1 genome (A=1, H=0.75, gamma=1.5, M=8, lambda1=1 mm)")
    p.add_argument("-o", "--output", required=True, help="genome JSON file")
    p.add_argument("--seed", type=int, default=0, help="seed of the (unpublished) phases")
    p.add_argument("--n-max", type=int, default=22, help="last chromosome with a phase (22 covers 100x)")
    p.set_defaults(func=_example)

    p = gs.add_parser("realize", help="realise a genome as a profile (Eq. 3.1, 3.5)")
    p.add_argument("genome", metavar="GENOME.json")
    _length_or_scale(p)
    p.add_argument("--nodes", type=int, default=512, help="number of nodes N (delta = L/(N-1))")
    p.add_argument("--chromosomes", type=int, nargs="+", help="sum only these chromosome indices")
    p.add_argument("-o", "--output", required=True, help="profile .npz (roughfe surface format)")
    p.set_defaults(func=_realize)

    p = gs.add_parser("sequence", help="sequence a genome from 2-3 nested acquisitions (Sec. 3.3.1)")
    p.add_argument("profiles", nargs="+", metavar="PROFILE.npz",
                   help="acquisitions of the same profile (same N, nested windows centred on x = 0)")
    p.add_argument("-o", "--output", required=True, help="sequenced genome JSON (+ _report.json)")
    p.add_argument("--seed", type=int, default=0, help="seed of the M likelihood and the phase draws")
    p.add_argument("--ridges", type=int, default=None, help="impose M (default: maximum likelihood)")
    p.add_argument("--tolerance", type=float, default=0.05, help="relative rms error of a WM-like profile")
    p.add_argument("--figures", default=None, help="figure folder (default: next to the genome)")
    p.add_argument("--no-figures", action="store_true", help="skip the figures")
    p.add_argument("--strict", action="store_true", help="exit 1 when the quality check fails")
    p.set_defaults(func=_sequence)

    p = gs.add_parser("mechanics", help="A(p), K(p) of a realisation, its chromosomes and TD/BU sums (Fig. 36-39)")
    p.add_argument("genome", metavar="GENOME.json")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--scale", choices=sorted(SCALES), default="10x", help="named scale (default 10x)")
    g.add_argument("--length", type=float, help="observation length L (m)")
    p.add_argument("--nodes", type=int, default=512, help="number of nodes N")
    p.add_argument("--kernels", nargs="+", default=["thesis", "strip"],
                   help="BEM kernels: thesis (Eq. 2.4) and/or strip (plane strain)")
    p.add_argument("--youngs-modulus", type=float, default=THESIS_YOUNGS_MODULUS, help="E (Pa), thesis 210 MPa")
    p.add_argument("--poisson", type=float, default=0.0, help="Poisson ratio")
    p.add_argument("--steps", type=int, default=20, help="equal approaches up to the peak-valley amplitude")
    p.add_argument("--max-chromosomes", type=int, default=10, help="single-chromosome curves (thesis: 10)")
    p.add_argument("-o", "--output", required=True, help="output folder")
    p.set_defaults(func=_mechanics)

    p = gs.add_parser("natural", help="sequence the central row of a measured topography (Sec. 3.4.2)")
    add_surface_options(p)
    p.add_argument("--fractions", type=float, nargs="+", default=list(DEFAULT_FRACTIONS),
                   help="nested window lengths as fractions of the row (default 1 0.5 0.2)")
    p.add_argument("--nodes", type=int, default=512, help="nodes per acquisition")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--kernels", nargs="*", default=["thesis", "strip"], help="BEM kernels for A(p), K(p)")
    p.add_argument("--steps", type=int, default=20)
    p.add_argument("--tolerance", type=float, default=0.05)
    p.add_argument("-o", "--output", required=True, help="output folder")
    p.set_defaults(func=_natural)

    p = gs.add_parser("validity", help="Monte Carlo of Eq. 3.10 (Fig. 29)")
    p.add_argument("--trials", type=int, default=1000)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("-o", "--output", required=True, help="figure (.png)")
    p.set_defaults(func=_validity)
