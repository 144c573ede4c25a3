"""``roughfe db build|extend`` through the study runner: genomes computed as study tasks.

The tasks are :func:`roughfe.genomics.database.genome_entry_task` calls (analysis
``genome_entry``) in a spec built here; they run on any executor (local, dask, mpi) and
their results are stored in a study folder beside the database (default ``DB.study/``).
An interrupted build therefore resumes from the finished genomes, even those not yet in
the SQLite file; :func:`~roughfe.study.exports.genome_db_to_sqlite` then inserts them
in one transaction. The database's settings (and Sobol design) are checked before any
task runs.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from .exports import genome_db_to_sqlite
from .runner import StudySummary, run_study
from .spec import spec_from_mapping


def default_study_dir(db_path) -> Path:
    """The study folder of a database: ``DB.study`` beside the SQLite file."""
    return Path(str(db_path) + ".study")


@dataclass(frozen=True)
class GenomeDbRun:
    """What one ``db build`` or ``db extend`` did.

    Attributes
    ----------
    summary : StudySummary
        The runner's summary (tasks cached, computed, failed; times; executor).
    n_inserted : int
        Genomes added to the SQLite file by this call.
    n_genomes : int
        Genomes in the SQLite file afterwards.
    study_dir : Path
        The study folder (``roughfe study status`` reads it).
    """

    summary: StudySummary
    n_inserted: int
    n_genomes: int
    study_dir: Path

    @property
    def complete(self) -> bool:
        return self.summary.complete

    def describe(self) -> str:
        """One line: genomes inserted, computed, reused from the study folder, failed."""
        s = self.summary
        if s.n_tasks == 0:
            return f"nothing to compute: the {self.n_genomes} genome(s) are in the database"
        return (f"{self.n_inserted} genome(s) inserted ({s.n_done} computed, {s.n_cached} "
                f"from the study folder {self.study_dir}, {s.n_failed} failed); "
                f"{self.n_genomes} in the database")


def _run(db_path, tasks, settings, name, *, executor, workers, scheduler, study_dir,
         progress, log) -> GenomeDbRun:
    """Run the ``genome_entry`` tasks missing from ``db_path``; import what finished."""
    from ..genomics import database as gdb

    study_dir = default_study_dir(db_path) if study_dir is None else Path(study_dir)
    con = gdb.connect(db_path)
    try:
        present = set(gdb.labels(con))
    finally:
        con.close()
    todo = [t for t in tasks if t["label"] not in present]
    if not todo:
        summary = StudySummary(n_tasks=0, n_cached=0, n_done=0, n_failed=0, n_retries=0,
                               wall_s=0.0, task_s=0.0, executor="nothing to run")
        return GenomeDbRun(summary, 0, len(present), study_dir)
    spec = spec_from_mapping({
        "study": {"name": name, "analysis": "genome_entry", "output": str(study_dir)},
        "grid": {"entry": todo}, "fixed": settings.to_dict()})
    summary = run_study(spec, executor=executor, workers=workers, scheduler=scheduler,
                        progress=progress, log=log)
    n_inserted = 0
    if summary.n_cached + summary.n_done:
        n_inserted = genome_db_to_sqlite(study_dir, db_path)
    return GenomeDbRun(summary, n_inserted, len(present) + n_inserted, study_dir)


def build_genome_db(db_path, settings=None, design=None, *, limit=None, executor="local",
                    workers=None, scheduler=None, study_dir=None, progress=True,
                    log=None) -> GenomeDbRun:
    """Build (or resume) the Sobol genome database of thesis Sec. 4.1.2 with the runner.

    Parameters
    ----------
    db_path : path-like
        SQLite file; created when missing. Its genomes are kept; only missing labels run.
        A file this call created is removed again when the call fails before a genome
        is in it (a task check, the executor or an interrupt refused the build).
    settings, design : DatabaseSettings, SobolDesign, optional
        Defaults: the thesis settings and design. Must match what the file stores
        (checked before any task runs; InputError otherwise).
    limit : int, optional
        Only the first ``limit`` genomes of the design (a reduced database).
    executor, workers, scheduler, progress, log
        As :func:`roughfe.study.run_study`.
    study_dir : path-like, optional
        The study folder (default ``DB.study``); keep it to resume an interrupted build.
    """
    from ..genomics import database as gdb

    settings = gdb.DatabaseSettings() if settings is None else settings
    design = gdb.SobolDesign() if design is None else design
    design.check_phases(settings)                   # before the file or any task
    tasks = gdb.sobol_tasks(design, limit)
    with gdb.new_file_removed_on_error(db_path):   # a refused build leaves no new file
        con = gdb.connect(db_path, create=True)
        try:
            gdb.write_settings(con, settings)
            gdb.write_design(con, design)
        finally:
            con.close()
        return _run(db_path, tasks, settings, "db build", executor=executor,
                    workers=workers, scheduler=scheduler, study_dir=study_dir,
                    progress=progress, log=log)


def extend_genome_db(db_path, genomes, *, labels=None, executor="local", workers=None,
                     scheduler=None, study_dir=None, progress=True, log=None) -> GenomeDbRun:
    """Add genomes (Genome objects or JSON dicts, e.g. sequenced ones) with the runner.

    They are computed with the database's own settings; an empty database (no settings)
    or a label already present is an InputError (see
    :func:`roughfe.genomics.database.extend_tasks`). Other parameters as
    :func:`build_genome_db`.
    """
    from ..genomics import database as gdb

    gdb.check_access(db_path, write=True)    # before the work, not at the inserts
    con = gdb.connect(db_path)
    try:
        tasks = gdb.extend_tasks(con, genomes, labels)
        settings = gdb.read_settings(con)
    finally:
        con.close()
    return _run(db_path, tasks, settings, "db extend", executor=executor, workers=workers,
                scheduler=scheduler, study_dir=study_dir, progress=progress, log=log)
