"""``roughfe design``: design a rough profile (or, on a surface database built with
``db build --dim 2``, a periodic surface) whose K(p) and/or A(p) hit a target (thesis Sec.
4.2-4.4: SOG, GCO, CCO, M-CCO), and ``roughfe design-targets``: write the thesis targets
y_t1, y_t2, y_t3, or the K(p), A(p) of a given (measured) surface, as CSV for a database's
settings."""
from __future__ import annotations

import math
import re
import sys
from dataclasses import replace
from pathlib import Path

from .options import (DETRENDS, add_output_folder, add_run_options, add_scan_axis_option,
                      add_surface_options, surface_file, int_in, nonnegative_float,
                      output_folder_of, positive_float)

BUILTIN = ("y_t1", "y_t2", "y_t3")
#: upper bounds of the stage budgets (none until round 2, session 34: 99999999999 ran as
#: asked). Measured costs (docs/theory/06_design.md, N = 512): the thesis stages are 5 (sog)
#: or 3 GCMMA iterations; --refine 3 was ~900 BEM sweeps; --search 400 with 4 starts 4890
#: sweeps in 219 s. Each bound is 20-250 x the largest budget measured.
MAX_ITERATIONS, MAX_REFINE, MAX_SEARCH, MAX_SEARCH_STARTS = 100, 100, 100000, 100
#: upper bounds of the ``--global`` budgets (none until round 2, session 34, helper char2).
#: Measured (docs/theory/06_design.md, N = 512, ~11 ms per strict evaluation): 20000
#: evaluations per round (225 s), 2 rounds, 1 candidate, first population up to 88.
#: 1e6 evaluations are ~3 h per candidate and round; the others 50-100 x the measured.
MAX_GLOBAL_EVAL, MAX_GLOBAL_POPSIZE, MAX_GLOBAL_CANDIDATES, MAX_GLOBAL_ROUNDS = \
    1000000, 10000, 100, 100
#: upper bounds of ``--spectrum-starts`` and ``--pool`` (none until round 2, session 34,
#: helper char3: 99999999999 ran as asked). --spectrum-starts K adds K candidates of three
#: counted BEM sweeps each (match_spectrum), every one searched again by --search, as
#: --search-starts (bound 100 there); the default and largest measured is 3. --pool 8 made
#: 378 cross-overs instead of 9 (docs/theory/06_design.md), ~6 K^2: 100 is ~60000, and
#: beyond the database's genomes a larger K adds none.
MAX_SPECTRUM_STARTS, MAX_POOL = 100, 100
#: the numeric ``--global-*`` flags (GlobalSearchOptions): flag, type, default, metavar, help
GLOBAL_FLAGS = (
    ("--global-eval", int_in(2, MAX_GLOBAL_EVAL), 20000, "N",
     f"strict evaluations per searched candidate and round, 2..{MAX_GLOBAL_EVAL}"),
    ("--global-amplitudes", nonnegative_float, 0.0, "X",
     "every chromosome's amplitude a variable too, within exp(+-X) of its start (log "
     "scale, X <= 2; 0: part weights +-30%%)"),
    ("--global-popsize", int_in(0, MAX_GLOBAL_POPSIZE), 0, "L",
     "population of the first CMA-ES run, doubled at each restart (0: 4 + 3 ln n), "
     f"0..{MAX_GLOBAL_POPSIZE}"),
    ("--global-candidates", int_in(1, MAX_GLOBAL_CANDIDATES), 1, "K",
     f"search the K best candidates (by strict f), 1..{MAX_GLOBAL_CANDIDATES}"),
    ("--global-rounds", int_in(1, MAX_GLOBAL_ROUNDS), 1, "R",
     "R IPOP-CMA-ES runs, each from the best design of the one before (N evaluations "
     f"each), 1..{MAX_GLOBAL_ROUNDS}"),
    ("--global-genes", nonnegative_float, 0.0, "X",
     "every part's gamma, H, lambda1 a variable too, within +-X (fraction, < 1) of its "
     "start (0: off)"),
    ("--global-modulation", nonnegative_float, 0.0, "X",
     "surfaces: the depth of the short waves' modulation by the long-wave height a "
     "variable too, within +-X of its start (X <= 2; 0: off)"))


def _target(spec, quantity, settings, cache, default):
    from ..genomics.design import thesis_targets
    from ..genomics.target_csv import read_target_csv
    if spec in BUILTIN and not Path(spec).exists():
        if "t" not in cache:
            cache["t"] = thesis_targets(settings)
        t1, t2, t3, _ = cache["t"]
        return {"y_t1": t1, "y_t2": t2, "y_t3": t3}[spec]
    return read_target_csv(spec, quantity, default=default)


def _check_target_names(args) -> None:
    """Refuse a ``--target``/``--second-target`` that looks like a thesis target's name
    (y_t + digits) but is none and no file: ``--target y_t9`` said "target file y_t9 does
    not exist", after the database was read (round 2, session 37)."""
    from ..errors import InputError
    for flag, spec in (("--target", args.target), ("--second-target", args.second_target)):
        if spec is None or spec in BUILTIN or Path(spec).exists() or \
                not re.fullmatch(r"y_t\d+", spec, re.IGNORECASE):
            continue
        raise InputError(f"{flag} {spec}: no thesis target of that name, and no such file; "
                         f"the thesis targets are y_t1 (K(p) of the thesis genome), y_t2 (K "
                         f"linear in p up to pbar, then flat) and y_t3 (A(p) of y_t1's "
                         f"genome); a 'pressure,value' CSV file is also accepted "
                         f"(design-targets writes such files)")


def _dependent_options(args):
    """Rows ``(dest, flag, default, what it needs, whether args have it)`` of the options
    that mean something only with another option or method: given without it, each was
    silently ignored (e.g. ``--gradient exact`` with ``--formulation thesis`` ran finite
    differences)."""
    fd = args.gradient == "fd" or args.formulation == "thesis"
    gcmma_fd = "finite differences (--gradient fd or --formulation thesis)"
    rows = [("pbar", "--pbar", None, "--method gco or cco (Algs. 5 and 6 split the target "
             "there)", args.method in ("gco", "cco")),
            ("second_target", "--second-target", None, "--method mcco", args.method == "mcco"),
            ("second_quantity", "--second-quantity", None, "--second-target (what its CSV "
             "holds)", bool(args.second_target)),       # was ignored (round 2, session 37)
            ("pool", "--pool", 0, "--method mcco", args.method == "mcco"),
            ("eps", "--eps", 0.02, gcmma_fd, fd),
            ("search_starts", "--search-starts", 1, "--search SWEEPS", bool(args.search)),
            ("search_amplitudes", "--search-amplitudes", "part", "--search SWEEPS",
             bool(args.search)),
            ("spectrum_starts", "--spectrum-starts", 3, "--match-spectrum SURFACE",
             bool(args.match_spectrum)),
            ("match_directions", "--match-directions", False, "--match-spectrum SURFACE",
             bool(args.match_spectrum))]
    rows += [(dest, flag, default, "--match-spectrum SURFACE (an option of its file)",
              bool(args.match_spectrum))
             for dest, flag, default in (("size", "--size", None), ("channel", "--channel", None),
                                         ("periodic", "--periodic/--non-periodic", None),
                                         ("detrend", "--detrend", "plane"),
                                         ("scan_axis", "--scan-axis", "x"))]
    globals_ = [(flag, default) for flag, _, default, _, _ in GLOBAL_FLAGS]
    globals_ += [("--global-score", "strict"), ("--global-waves", False)]
    rows += [(flag[2:].replace("-", "_"), flag, default, "--global cmaes",
              bool(args.global_search)) for flag, default in globals_]
    return rows


def _check_options(args):
    """Refuse an option given where it means nothing (:func:`_dependent_options`), then
    set the defaults of those not given (parsed as None to tell "not given" apart), and a
    mistyped thesis target (:func:`_check_target_names`)."""
    from ..errors import InputError
    if args.gradient == "exact" and args.formulation == "thesis":
        raise InputError("--gradient exact needs --formulation minimax: the thesis form "
                         "(1 - s)^2 takes forward differences (--gradient fd)")
    args.gradient = args.gradient or ("fd" if args.formulation == "thesis" else "exact")
    for dest, flag, default, needs, present in _dependent_options(args):
        value = getattr(args, dest)
        if value is not None and (value is not False or dest == "periodic") and not present:
            raise InputError(f"{flag} needs {needs}; it was given without, where it means "
                             f"nothing")
        if value is None:
            setattr(args, dest, default)
    _check_target_names(args)


def _with_p_top(target, p_top):
    """``target`` with ``--target-p-top``; the Target's own check, in the option's words."""
    from ..errors import InputError
    try:
        return replace(target, p_top=p_top)
    except InputError as exc:
        raise InputError(f"--target-p-top {p_top:g} for the target {target.name}: "
                         f"{exc}") from None


#: largest p_max^t / E* of a design's target (Eq. 4.2 rescales the amplitude to reach it):
#: the thesis' own targets reach 1.7 E* (warned of, plausibility.check_target_pressure);
#: 1e3 E* is a strain of ~1000, no elastic contact (--target-p-top 1e308 was a non-
#: convergence line of the dense solver, 1e20 a design of rms slope 4.5e12, exit 0)
MAX_P_TOP_RATIO = 1e3


def _check_p_top(args, targets, settings) -> None:
    """Refuse a target whose p_max^t exceeds :data:`MAX_P_TOP_RATIO` x the database's E*,
    naming ``--target-p-top`` when it gave the pressure."""
    from ..errors import InputError
    from ..model import Material
    e_star = Material(settings.youngs_modulus, settings.poisson).E_star
    for t in targets:
        if t.p_max > MAX_P_TOP_RATIO * e_star:
            what = (f"--target-p-top {args.target_p_top:g} Pa" if args.target_p_top
                    is not None else f"the last pressure {t.p_max:.4g} Pa of --target "
                                     f"{t.name}")
            raise InputError(f"{what} is {t.p_max / e_star:.3g} x the database's E* = "
                             f"{e_star:.4g} Pa: allowed is at most {MAX_P_TOP_RATIO:g} x E* "
                             f"(a strain p / E* far beyond any elastic contact; Pa?)")


def _run(args) -> int:
    from ..errors import InputError
    from ..genomics.database import load_entries, read_settings
    from ..genomics.design import (GcmmaOptions, GlobalSearchOptions, refine,
                                   rescore_at_target_pressures, run_design,
                                   search_at_target_pressures, search_global,
                                   with_solved_scores, write_design_result)
    _check_options(args)            # before the database is read
    global_options = GlobalSearchOptions(
        method=args.global_search or "cmaes", n_eval=args.global_eval,
        popsize=args.global_popsize, amplitudes=args.global_amplitudes,
        waves=args.global_waves,
        n_candidates=args.global_candidates, rounds=args.global_rounds,
        genes=args.global_genes, score=args.global_score,
        modulation=args.global_modulation)   # checked before the database is read
    settings = read_settings(args.db)
    entries = load_entries(args.db)
    spectrum_target = None          # the surface whose spectrum psd.png draws beside
    if args.match_spectrum:         # read, warned of and prepared before the design runs
        from ..genomics.design import target_surface
        from .surface_warnings import plausible_surface
        if settings.dim != 2:       # refused by spectrum_matched only after the design
            raise InputError(f"--match-spectrum needs a surface database (dim 2: periodic "
                             f"2D designs, whose chromosomes take the file's band rms); "
                             f"{args.db} is a profile database (dim 1)")
        surface = surface_file(args, args.match_spectrum)
        plausible_surface(args, surface, args.detrend)   # its warnings, as design-targets;
        spectrum_target = target_surface(surface, settings, detrend=args.detrend)  # detrended
        # Not check_target_surface (design-targets): its size warning is about the file's
        # own K(p) and A(p) as the targets (the longest waves and a window's bulk
        # compliance at its size), while here the targets are --target's curves and the
        # file gives only the rms of its Fourier modes, each to the chromosome nearest in
        # log q, by wavenumber, not by length; its 2D-on-a-profile-database case is
        # refused above. What the file's size does matter for: its modes of wavelength
        # above L, which go to the longest chromosome (round 2, session 37)
        from .plausibility import check_long_waves
        check_long_waves(args, spectrum_target, settings)
    cache = {}
    targets = [_target(args.target, args.quantity, settings, cache, "K")]
    if args.second_target:
        targets.append(_target(args.second_target, args.second_quantity, settings, cache,
                               "A"))
    from .plausibility import check_target_curve
    for t in targets:
        check_target_curve(args, t)
    if args.method == "mcco" and len(targets) == 2 and targets[0].quantity == "A":
        targets.reverse()
    if args.target_p_top is not None:       # Eq. 4.2's p_max^t beyond the last points
        targets = [_with_p_top(t, args.target_p_top) for t in targets]
    _check_p_top(args, targets, settings)
    options = GcmmaOptions(bound=args.bound, formulation=args.formulation, eps=args.eps,
                           gradient=args.gradient,
                           **({"n_it_sog": args.iterations, "n_it_cross": args.iterations}
                              if args.iterations else {}))
    extra = ({"pool": args.pool, "swap": True, "weights": (0.5, 1.0, 2.0)} if args.pool else {})
    with output_folder_of(args, "design") as out:
        result = run_design(args.method, entries, targets, settings, pbar=args.pbar,
                            options=options, **extra)
        if args.refine:
            result = refine(result, settings, rounds=args.refine)
        if spectrum_target is not None:
            from ..genomics.design import match_spectrum
            result = match_spectrum(result, spectrum_target, settings, entries=entries,
                                    n_entries=args.spectrum_starts,
                                    directional=args.match_directions)
        if args.search:
            result = search_at_target_pressures(result, settings, n_eval=args.search,
                                                starts=args.search_starts,
                                                amplitudes=args.search_amplitudes)
        if args.global_search:
            result = search_global(result, settings, global_options)
        if not result.best.at_targets:   # solved at the target pressures: the verdict's
            result = with_solved_scores(result, rescore_at_target_pressures(
                result.best.design, targets, settings))
        strict = result.best.at_targets
        if not args.no_figures:
            from ..plotting.design import (design_title, plot_design_curves, plot_profiles,
                                           plot_psds, plot_stages)
            best = result.best.design
            plot_design_curves([result], out / "curves.png", title=design_title(result))
            plot_stages([result], out / "stages.png", title=design_title(result))
            from ..genomics.design import heights_name
            plot_profiles({result.method: best.surface()},       # 2D: a map, surface.png
                          out / f"{heights_name(best.dim)}.png")
            plot_psds({result.method: (best.surface(), best.spectrum_lines())}, out / "psd.png",
                      target=spectrum_target,
                      target_label=f"target {Path(str(args.match_spectrum)).name} "
                                   "(--match-spectrum)" if spectrum_target else "target")
        paths = write_design_result(result, settings, out)
    print(result.message)
    for k, c in enumerate(result.candidates, 1):
        print(f"  ({k}) {c.origin:>16}  GCMMA 0/1/2{'/3' if len(c.stages) > 3 else ''}: "
              + " ".join("-" if math.isnan(s) else f"{s:.4f}" for s in c.stages)
              + "  per target: " + " ".join(f"{s:.4f}" for s in c.scores))
    print("best design solved at the target pressures (no interpolation): "
          + " ".join(f"{s:.4f}" for s in strict))
    print(f"{result.nit} BEM sweeps in {result.elapsed:.1f} s; wrote {paths['design'].parent}/")
    from .plausibility import check_design
    check_design(args, result.best.design.surface(), targets, settings)
    if not result.success:      # exit 1: the command ran, its check failed (docs/guide/02)
        print("the design is NOT a success (its criterion, in the message above, failed); "
              "the result is written", file=sys.stderr)
        return 1
    if args.strict:
        from ..genomics.design.objective import verdict
        if not verdict(result.best, result.objective.targets).matched:
            print("--strict: the target is NOT matched (result.json 'matched'); the result "
                  "is written", file=sys.stderr)
            return 1
    return 0


#: ``design-targets`` options of its ``--surface`` FILE: (dest, flag, default); given
#: without --surface they were ignored in silence (round 2, session 33)
SURFACE_TARGET_OPTIONS = (("detrend", "--detrend", "plane"), ("boundary", "--boundary", "auto"),
                          ("resolution", "--resolution", "design"), ("size", "--size", None),
                          ("periodic", "--periodic/--non-periodic", None),
                          ("channel", "--channel", None), ("scan_axis", "--scan-axis", "x"))


def _check_target_options(args) -> None:
    """Refuse an option of ``--surface`` given without it, where it means nothing (as
    :func:`_check_options` does for ``design``), then set the defaults (parsed as None)."""
    from ..errors import InputError
    for dest, flag, default in SURFACE_TARGET_OPTIONS:
        if getattr(args, dest) is None:
            setattr(args, dest, default)
        elif args.surface is None:
            raise InputError(f"{flag} needs --surface FILE (the curves of a given surface); "
                             f"it was given without, where it means nothing (the thesis' "
                             f"targets are the database's)")


def _targets(args) -> int:
    from ..genomics.database import read_settings
    from ..genomics.design import surface_targets, thesis_targets
    from ..genomics.target_csv import write_target_csv
    _check_target_options(args)     # before the database is read
    settings = read_settings(args.db)
    if args.surface:
        surface = surface_file(args, args.surface)
        if args.boundary == "window" and surface.periodic:     # was ignored (session 37)
            from ..errors import InputError
            raise InputError(f"--boundary window solves a non-periodic --surface as its "
                             f"window alone on the half-space; {args.surface} is read as "
                             f"periodic, which is solved as it is (periodic BEM): leave "
                             f"--boundary out, or give --non-periodic to take it as a window")
        from .plausibility import check_target_surface
        from .surface_warnings import plausible_surface
        plausible_surface(args, surface, args.detrend)     # its warnings; the library
        check_target_surface(args, surface, settings)      # (target_surface) detrends
        name = Path(args.surface).stem.replace(" ", "_")
        tk, ta, curve = surface_targets(surface, settings, name=name, detrend=args.detrend,
                                        boundary=args.boundary, resolution=args.resolution)
        with output_folder_of(args, "design-targets") as out:
            for t in (tk, ta):
                print(write_target_csv(out / f"{t.name}.csv", t))
        print(f"{args.surface}: p_max^t = {curve.p_max:.6g} Pa, A* at p_max = "
              f"{curve.area_fraction[-1]:.4f} ({len(curve.pressure)} BEM steps)")
        return 0
    t1, t2, t3, _ = thesis_targets(settings)
    with output_folder_of(args, "design-targets") as out:
        for t in (t1, t2, t3):
            print(write_target_csv(out / f"{t.name}.csv", t))
    print(f"pbar of y_t2: {t2.metadata['pbar']:.6g} Pa; p_max^t = {t1.p_max:.6g} Pa")
    from .plausibility import check_target_pressure
    check_target_pressure(args, [t1], settings, "the thesis' targets, Fig. 48-49, are "
                                                "benchmarks of the linear model")
    return 0


def register(sub):
    p = sub.add_parser("design", help="design roughness for a target K(p)/A(p) (SOG/GCO/CCO/M-CCO)",
                       description="Design a rough profile whose K(p) and/or A(p) hit a "
                                   "target (thesis Sec. 4.2-4.4) from a genome database. "
                                   "Writes OUTDIR/result.json (scores, stages), design.json, "
                                   "genome.json (a roughfe-genome for 'genome realize'; for a "
                                   "design of several genomes one genome_partK.json per part), "
                                   "profile.npz (surface.npz for a surface database), "
                                   "curves.csv, stages.csv and the figures (psd.png with the "
                                   "--match-spectrum target's spectrum).")
    p.add_argument("--db", required=True, help="SQLite genome database ('roughfe db build')")
    p.add_argument("--target", required=True,
                   help="CSV 'pressure_Pa,value' or a thesis target y_t1|y_t2|y_t3. Its LAST "
                        "pressure is taken as the pressure at the approach Delta = "
                        "peak-valley amplitude (p_max^t of the amplitude rescaling Eq. 4.2, "
                        "the thesis convention): a measured curve that stops earlier is not "
                        "recovered, even by the genome that produced it, unless "
                        "--target-p-top gives that pressure")
    p.add_argument("--target-p-top", type=positive_float, default=None, metavar="PA",
                   help="the targets' pressure (Pa) at the approach Delta = peak-valley "
                        "amplitude, p_max^t of Eq. 4.2, when their points stop earlier "
                        "(>= the last target pressure; both targets of mcco, one loading; "
                        "default: the last pressure of --target)")
    p.add_argument("--quantity", choices=("K", "A"), default=None,
                   help="what the target CSV holds: stiffness K (Pa/m) or area fraction A "
                        "(default: what the file says, in its comment as design-targets "
                        "writes it or its header's value column, e.g. 'p,A'; else K; a "
                        "disagreement is an error)")
    p.add_argument("--second-target", default=None,
                   help="M-CCO: the second target (CSV or y_t3), usually A(p)")
    p.add_argument("--second-quantity", choices=("K", "A"), default=None,
                   help="what the second target CSV holds (default: what its comment or "
                        "header says; else A)")
    p.add_argument("--method", choices=("sog", "gco", "cco", "mcco"), required=True,
                   help="Alg. 4 (sog), 5 (gco), 6 (cco) or 7 (mcco)")
    p.add_argument("--pbar", type=positive_float, default=None,
                   help="threshold pressure (Pa) splitting [0, pbar] and [pbar, p_max] (gco, "
                        "cco; `roughfe design-targets` prints y_t2's)")
    p.add_argument("--strict", action="store_true",
                   help="exit 1 when the target is NOT matched (the verdict of result.json "
                        "'matched', from the scores solved at the target pressures), as "
                        "`genome sequence --strict`; the result is written all the same")
    g = p.add_argument_group("GCMMA options")
    g.add_argument("--iterations", type=int_in(1, MAX_ITERATIONS), default=None,
                   help=f"outer GCMMA iterations of stage 1, 1..{MAX_ITERATIONS} (default: "
                        f"thesis, 5 sog / 3 others)")
    g.add_argument("--bound", choices=("start", "period"), default="start",
                   help="phase box: +-10%% of the start value (thesis) or of 2 pi")
    g.add_argument("--formulation", choices=("minimax", "thesis"), default="minimax",
                   help="min-max form with residual Jacobian, or (1-s)^2 with its gradient")
    g.add_argument("--gradient", choices=("exact", "fd"), default=None,
                   help="exact sensitivities on the fixed contact sets (default with "
                        "minimax), or finite differences (default and only choice with "
                        "--formulation thesis)")
    g.add_argument("--eps", type=positive_float, default=None,
                   help="finite-difference step in units of the phase box (finite "
                        "differences only; default 0.02)")
    g.add_argument("--refine", type=int_in(0, MAX_REFINE), default=0, metavar="ROUNDS",
                   help=f"extra stage beyond the thesis: ROUNDS x 15 GCMMA iterations on all "
                        f"phases, box (+-10%% of 2 pi) re-centred each round (0: off; at most "
                        f"{MAX_REFINE})")
    g.add_argument("--search", type=int_in(0, MAX_SEARCH), default=0, metavar="SWEEPS",
                   help=f"extra stage beyond the thesis, after --refine: a (1+1) evolution "
                        f"strategy on all phases and part weights maximising the score solved "
                        f"at the target pressures, SWEEPS BEM sweeps per candidate (0: off; at "
                        f"most {MAX_SEARCH})")
    g.add_argument("--search-starts", type=int_in(1, MAX_SEARCH_STARTS), default=None,
                   metavar="K",
                   help=f"--search: K independent runs per candidate (deterministic seeds), "
                        f"the best kept (1..{MAX_SEARCH_STARTS})")
    g.add_argument("--search-amplitudes", nargs="?", const="chromosome", default=None,
                   choices=("part", "chromosome", "wave"), metavar="KIND",
                   help="--search amplitude variables (+-30%%): part (each part's weight, "
                        "default), chromosome (every chromosome's; the value when the option "
                        "is given alone) or wave (surfaces: every ridge of every chromosome)")
    g.add_argument("--global", dest="global_search", choices=("cmaes",), default=None,
                   help="after --search: IPOP-CMA-ES on all phases and the amplitudes of "
                        "--global-amplitudes, on the score at the target pressures (batched "
                        "BEM, profiles and surfaces; beyond the thesis)")
    for flag, kind, default, metavar, text in GLOBAL_FLAGS:
        g.add_argument(flag, type=kind, default=None, metavar=metavar,
                       help=f"--global: {text} (default {default})")
    g.add_argument("--global-score", default=None, metavar="{strict,min}",
                   help="--global: maximise f at the target pressures (strict, default) or "
                        "min(strict f, interpolated f) (min: the thesis scoring on the "
                        "design's own approaches too; checked by GlobalSearchOptions)")
    g.add_argument("--global-waves", action="store_true",
                   help="--global-amplitudes per wave (every ridge of every chromosome, "
                        "surfaces) instead of per chromosome")
    g.add_argument("--match-spectrum", default=None, metavar="SURFACE",
                   help="surface database, beyond the thesis, after --refine and before "
                        "--search: set every chromosome's amplitude to the band rms of this "
                        "(measured) topography, prepared as 'design-targets --surface' "
                        "does by default (--detrend, mirrored, database spacing) after the "
                        "same warnings (offset scan lines, a kept tilt, a unit mistake)")
    g.add_argument("--spectrum-starts", type=int_in(0, MAX_SPECTRUM_STARTS), default=None,
                   metavar="K",
                   help="--match-spectrum: also start from the K best database genomes, "
                        f"spectrum matched (0..{MAX_SPECTRUM_STARTS})")
    g.add_argument("--match-directions", action="store_true",
                   help="--match-spectrum per wave: every (ridge, chromosome) wave gets the "
                        "rms of the target's modes nearest to it in log q and direction "
                        "(default: one rms per chromosome)")
    p.add_argument("--pool", type=int_in(0, MAX_POOL), default=None, metavar="K",
                   help="mcco, beyond the thesis: start pool of the K best genomes of each "
                        "Alg. 3 ranking, both macro/micro orders, micro amplitude x 0.5/1/2 "
                        f"(0: the thesis sets; 0..{MAX_POOL})")
    add_surface_options(p, positional=False)      # of --match-spectrum's file
    p.add_argument("--detrend", choices=DETRENDS, default=None,
                   help="detrending of the --match-spectrum file before its spectrum is "
                        "taken (default: plane; lines / lines-tilt: each scan line along x, "
                        "or --scan-axis, levelled, as design-targets --surface)")
    add_scan_axis_option(p, default=None)         # of --match-spectrum's file (default: x)
    add_output_folder(p)
    add_run_options(p)
    p.set_defaults(func=_run)

    t = sub.add_parser("design-targets", help="write the thesis targets y_t1, y_t2, y_t3 (or the "
                                              "K(p), A(p) of a given surface) as CSV")
    t.add_argument("--db", required=True, help="SQLite genome database (for L, N, E, n_t)")
    t.add_argument("--surface", default=None, metavar="FILE",
                   help="instead of the thesis targets: K(p) and A(p) of this surface (any "
                        "file 'roughfe info' reads, e.g. a measured topography) from its own "
                        "BEM sweep with the database's E, nu and steps; writes NAME_K.csv "
                        "and NAME_A.csv")
    t.add_argument("--detrend", choices=DETRENDS, default=None,
                   help="detrending of --surface before the BEM (default: plane; lines / "
                        "lines-tilt: each scan line along x, or --scan-axis, levelled, as "
                        "roughfe info)")
    add_scan_axis_option(t, default=None)         # of --surface's file (default: x)
    t.add_argument("--boundary", choices=("auto", "periodic", "window"), default=None,
                   help="a non-periodic --surface: its evenly mirrored window with the "
                        "periodic BEM, or the window alone on the half-space (its K then "
                        "includes the window's bulk compliance); auto: the designs' own "
                        "setting, periodic on a surface database (--dim 2), window on a "
                        "profile database (default: auto); a periodic --surface is solved "
                        "as it is (window is refused for it)")
    t.add_argument("--resolution", choices=("design", "full"), default=None,
                   help="a periodic target on a surface database: resampled onto the "
                        "database spacing L/N (the band the designs hold) or at the file's "
                        "own sampling (default: design)")
    add_surface_options(t, positional=False)      # of --surface's file
    add_output_folder(t)
    add_run_options(t, figures=False)
    t.set_defaults(func=_targets)
