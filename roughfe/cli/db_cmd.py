"""``roughfe db build|extend|list|map``: the genome database of thesis Sec. 4.1.2.

``build`` and ``extend`` compute the genomes through the study runner
(:func:`roughfe.study.build_genome_db`): local process pool, dask or MPI, with a study
folder beside the database (``DB.study``) so that an interrupted build resumes from its
finished genomes (rerun the same command). Under MPI run::

    mpirun -n K python -m mpi4py.futures $(which roughfe) db build DB --executor mpi
"""
from __future__ import annotations

import sys

DESCRIPTION = """\
The genome database of thesis Sec. 4.1.2 (an SQLite file): each row is a genome with its
A(p), K(p) curves, chromosome correlations and macro chromosomes, computed with the
realisation and contact settings stored in the file.

build computes the genomes of a Sobol design; extend adds genome JSON files; both run on
the study runner (local process pool, dask or MPI) with a study folder beside the
database (DATABASE.study), so an interrupted run resumes when you rerun the same command.
list prints the genomes (read-only); map draws the genetic map. `build --dim 2` makes a
surface database: periodic N x N realisations (default 64 x 64) of genomes with M ridges
whose angles and anisotropy are part of the Sobol design. Under MPI run:

    mpirun -n K python -m mpi4py.futures $(which roughfe) db build DB --executor mpi
"""

from ..genomics.database.settings import THESIS_SETTINGS as THESIS
from .options import (add_material_options, add_output_folder, add_run_options,
                      add_runner_options, log_of, nonnegative_int, output_folder_of,
                      positive_float, positive_int, show_progress)


#: defaults of a surface database (``--dim 2``) where they differ from the thesis profiles:
#: a 64 x 64 periodic grid (about 1.5 s CPU per genome of 3 ridges, 2.5 s wall; measured
#: in round 2, session 32 on the first 2 Sobol genomes), approaches up to 0.8 of
#: full contact (K of a periodic surface diverges at full contact)
SURFACE_DEFAULTS = {"nodes": 64, "top_fraction": 0.8}


def _settings(args):
    from ..genomics.database import DatabaseSettings
    dim2 = args.dim == 2
    nodes = args.nodes if args.nodes is not None else (
        SURFACE_DEFAULTS["nodes"] if dim2 else THESIS.n_nodes)
    top = args.top_fraction if args.top_fraction is not None else (
        SURFACE_DEFAULTS["top_fraction"] if dim2 else THESIS.top_fraction)
    return DatabaseSettings(length=args.length, n_nodes=nodes, youngs_modulus=args.E,
                            poisson=args.nu, n_steps=args.steps, threshold=args.threshold,
                            stiffness=args.stiffness, dim=args.dim, top_fraction=top)


def _runner(args) -> dict:
    return dict(executor=args.executor, workers=args.workers, scheduler=args.scheduler,
                study_dir=args.study_dir, progress=show_progress(args),
                log=log_of(args))


def _report(args, run) -> int:
    if not getattr(args, "quiet", False):
        print(f"{args.database}: {run.describe()}")
    if not run.complete:
        print(f"some genomes failed; `roughfe study status {run.study_dir}` shows why; rerun "
              "the same command to retry them (finished genomes are kept)", file=sys.stderr)
        return 1
    return 0


def _build(args) -> int:
    from ..errors import InputError
    from ..genomics.database import SobolDesign
    from ..study import build_genome_db
    if args.ridges is not None and args.dim != 2:   # was ignored (round 2, session 37)
        raise InputError(f"--ridges {args.ridges} sets the ridges M of a surface genome "
                         "(--dim 2); a profile database (--dim 1) has none: give --dim 2 "
                         "or drop --ridges")
    design = SobolDesign(seed=args.seed, scramble=not args.no_scramble, dim=args.dim,
                         hurst_range=tuple(args.hurst_range),
                         **({"n_ridges": args.ridges} if args.ridges is not None else {}))
    run = build_genome_db(args.database, _settings(args), design, limit=args.limit,
                          **_runner(args))
    return _report(args, run)


def _extend(args) -> int:
    from ..genomics.genome import load_genome
    from ..study import extend_genome_db
    genomes = [load_genome(p) for p in args.genomes]
    run = extend_genome_db(args.database, genomes, labels=args.label or None, **_runner(args))
    return _report(args, run)


def _add_runner_options(p):
    add_runner_options(p)
    p.add_argument("--study-dir", default=None, metavar="DIR",
                   help="study folder of the tasks (default: DATABASE.study); keep it to "
                        "resume an interrupted run")
    add_run_options(p, figures=False)


def _list(args) -> int:
    from ..genomics.database import read_settings, summary_table
    rows = summary_table(args.database)
    if args.json:
        from ..writers import to_json_text
        print(to_json_text({"settings": read_settings(args.database).to_dict(), "genomes": rows}))
        return 0
    print(f"{'label':>7} {'source':>7} {'gamma':>7} {'H':>6} {'n_c':>4} {'p_max (Pa)':>12}  macro n")
    for r in rows:
        print(f"{r['label']:>7} {r['source']:>7} {r['gamma']:7.4f} {r['H']:6.3f} {r['n_c']:4d} "
              f"{r['p_max']:12.5g}  {r['macro']}")
    print(f"{len(rows)} genome(s)")
    return 0


def _map(args) -> int:
    from ..genomics.database import summary_table
    from ..plotting.design import plot_genetic_map, plot_map_summary
    rows = summary_table(args.database)
    if not rows:
        from ..errors import InputError
        raise InputError(f"the genome database {args.database} holds no genomes; add "
                         f"genomes with `roughfe db build` or `roughfe db extend`")
    with output_folder_of(args, "db map") as out:
        a = plot_genetic_map(rows, out / "genetic_map.png")
        b = plot_map_summary(rows, out / "genetic_map_summary.png")
    print(f"wrote {a} and {b}")
    return 0


def register(sub):
    p = sub.add_parser("db", help="genome database: build (Sobol design), extend, list, map",
                       description=DESCRIPTION)
    dsub = p.add_subparsers(dest="db_command", metavar="ACTION")
    dsub.required = True

    b = dsub.add_parser("build", help="build or resume the Sobol genome database (Sec. 4.1.2)")
    b.add_argument("database", help="SQLite file (created if missing; genomes there are kept, "
                                    "an interrupted build resumes)")
    g = b.add_argument_group("realisation and contact settings (stored in the database)")
    g.add_argument("--length", type=positive_float, default=THESIS.length,
                   help="observation length L = lambda (m)")
    g.add_argument("--dim", type=int, choices=(1, 2), default=1,
                   help="1: profiles (thesis); 2: periodic N x N surfaces with M ridges, "
                        "angles and anisotropy in the Sobol design, periodic spectral BEM")
    g.add_argument("--nodes", type=positive_int, default=None,
                   help=f"nodes N per profile (default {THESIS.n_nodes}), or per side of a "
                        f"surface (default {SURFACE_DEFAULTS['nodes']})")
    g.add_argument("--top-fraction", type=positive_float, default=None,
                   help="last approach as a fraction of peak-valley (profiles, default 1) or "
                        f"of full contact (surfaces, default {SURFACE_DEFAULTS['top_fraction']})")
    g.add_argument("--steps", type=positive_int, default=THESIS.n_steps,
                   help="n_t approaches to the peak-valley height")
    g.add_argument("--threshold", type=positive_float, default=THESIS.threshold,
                   help="c_n threshold of Alg. 2")
    g.add_argument("--stiffness", choices=("fd", "exact"), default=THESIS.stiffness,
                   help="K(p) by differences over the steps (thesis) or exact per step")
    add_material_options(b, "material (stored in the database; the thesis used E = 1 MPa: "
                            "pressures scale with E*)")
    s = b.add_argument_group("Sobol design")
    s.add_argument("--seed", type=nonnegative_int, default=20240,
                   help="Sobol scrambling seed (recorded)")
    s.add_argument("--no-scramble", action="store_true", help="unscrambled Sobol sequences")
    s.add_argument("--ridges", type=positive_int, default=None,
                   help="ridges M per surface genome (--dim 2 only; default 3)")
    s.add_argument("--hurst-range", type=positive_float, nargs=2, default=(0.5, 1.5),
                   metavar=("LO", "HI"), help="range of H in the Sobol design (thesis: 0.5 1.5; "
                   "a measured target may need lower H, e.g. x3p-2 has 0.2-0.3)")
    s.add_argument("--limit", type=positive_int, default=None, help="build only the first K genomes")
    _add_runner_options(b)
    b.set_defaults(func=_build)

    e = dsub.add_parser("extend", help="add genome JSON files (e.g. sequenced genomes)")
    e.add_argument("database", help="existing SQLite genome database")
    e.add_argument("genomes", nargs="+", help="roughfe-genome JSON files")
    e.add_argument("--label", action="append", help="label per genome (repeat); default x-<k>")
    _add_runner_options(e)
    e.set_defaults(func=_extend)

    li = dsub.add_parser("list", help="list the genomes with genes, p_max and macro chromosomes")
    li.add_argument("database", help="SQLite genome database")
    li.add_argument("--json", action="store_true", help="print JSON (settings and rows)")
    li.set_defaults(func=_list)

    m = dsub.add_parser("map", help="genetic map (Fig. 54) and its summary (Fig. 55)")
    m.add_argument("database", help="SQLite genome database")
    add_output_folder(m, "output folder for the figures", required=False, default="db-map")
    m.set_defaults(func=_map)
