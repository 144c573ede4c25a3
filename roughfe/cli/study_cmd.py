"""``roughfe study run|status|collect``: parameter studies on local, dask or MPI executors.

``run`` executes the missing tasks of a TOML spec (resumable: rerun the same command
after an interruption); ``status`` reports what a study folder holds; ``collect`` writes
its tidy table (CSV, plus Parquet when pyarrow is installed). Under MPI run::

    mpirun -n K python -m mpi4py.futures $(which roughfe) study run SPEC.toml --executor mpi
"""
from __future__ import annotations

import sys

from ..study import (ANALYSES, collect, genome_db_to_sqlite, load_spec, run_study,
                     study_status)
from .options import add_run_options, add_runner_options, log_of, show_progress


def _run(args) -> int:
    spec = load_spec(args.spec, output=args.output)
    summary = run_study(spec, executor=args.executor, workers=args.workers,
                        scheduler=args.scheduler, progress=show_progress(args),
                        log=log_of(args))
    if not args.quiet:            # the summary line itself is run_study's last log line
        print(f"results in {spec.output}; `roughfe study status {spec.output}` lists "
              f"failures, `roughfe study collect {spec.output}` writes the table")
    return 0 if summary.complete else 1


def _status(args) -> int:
    status = study_status(args.outdir)
    print(status.describe())
    return 0 if status.n_done == status.n_tasks else 1


def _collect(args) -> int:
    paths, n_rows, missing, note = collect(args.outdir, parquet=not args.no_parquet)
    for path in paths:
        print(f"wrote {path}")
    print(f"{n_rows} rows")
    if note:
        print(note)
    if args.genome_db:
        n = genome_db_to_sqlite(args.outdir, args.genome_db)
        print(f"inserted {n} new genome(s) into {args.genome_db}")
    if missing:
        print(f"warning: {missing} task(s) have no result yet and are not in the table",
              file=sys.stderr)
        return 1
    return 0


def register(sub):
    p = sub.add_parser("study", help="run parameter studies (local, dask or MPI), resumable",
                       description="Parameter studies over a grid written in a TOML "
                                   "spec: `run` computes the missing tasks (resumable: rerun "
                                   "after an interruption), `status` lists what is done or "
                                   "failed, `collect` writes the tidy table. Runs on a local "
                                   "process pool, dask or MPI (mpirun -n K python -m "
                                   "mpi4py.futures $(which roughfe) study run SPEC.toml "
                                   "--executor mpi).")
    ssub = p.add_subparsers(dest="study_command", metavar="ACTION")
    ssub.required = True

    analyses = "; ".join(f"{k}: {a.description}" for k, a in ANALYSES.items())
    r = ssub.add_parser(
        "run", help="run the missing tasks of a study spec (TOML)",
        description="Run every task of SPEC whose result is missing. Safe to rerun after an "
                    f"interruption. Analyses: {analyses}.")
    r.add_argument("spec", metavar="SPEC.toml", help="study spec ([study], [grid], [fixed])")
    add_runner_options(r)
    r.add_argument("-o", "--output", default=None, metavar="OUTDIR",
                   help="results folder (overrides [study] output)")
    add_run_options(r, figures=False)
    r.set_defaults(func=_run)

    s = ssub.add_parser("status", help="tasks done, failed (with errors) and missing; cost")
    s.add_argument("outdir", metavar="OUTDIR", help="study results folder")
    s.set_defaults(func=_status)

    c = ssub.add_parser("collect", help="write OUTDIR/table.csv (and .parquet with pyarrow)")
    c.add_argument("outdir", metavar="OUTDIR", help="study results folder")
    c.add_argument("--no-parquet", action="store_true", help="write CSV only")
    c.add_argument("--genome-db", metavar="DB.sqlite", default=None,
                   help="genome_db studies: also insert the finished genomes into this SQLite "
                        "genome database (created if missing; existing labels are skipped)")
    c.set_defaults(func=_collect)
