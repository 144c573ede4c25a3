"""Parameter studies at scale: one runner on local processes, Dask distributed or MPI.

A study (:class:`StudySpec`, read from TOML by :func:`load_spec`) names an analysis of
the explicit registry :data:`ANALYSES`, a parameter grid (cartesian product) and fixed
parameters, and an output folder. :func:`run_study` runs the missing tasks on an
executor (``local``, ``dask`` or ``mpi``), storing each result atomically under a
content key, so that an interrupted study resumes to the same table; :func:`study_status`
reports progress and failures; :func:`collect` writes one tidy table;
:func:`build_genome_db` and :func:`extend_genome_db` fill a SQLite genome database.

Example
-------
>>> from roughfe.study import spec_from_mapping, run_study, collect
>>> spec = spec_from_mapping({"study": {"analysis": "selftest", "output": "studies/demo"},
...                           "grid": {"x": [0.0, 1.0], "y": [1.0, 2.0]}})
>>> summary = run_study(spec, executor="local", workers=2)      # doctest: +SKIP
>>> collect("studies/demo")                                     # doctest: +SKIP
"""
from .analyses import ANALYSES, Analysis, selftest_task
from .executors import EXECUTORS, make_executor
from .exports import genome_db_to_sqlite
from .genome_db import GenomeDbRun, build_genome_db, extend_genome_db
from .runner import StudySummary, execute_task, run_study
from .spec import StudySpec, Task, derive_seed, load_spec, spec_from_mapping
from .store import StudyStatus, study_status
from .tables import collect, table_rows

__all__ = [
    "ANALYSES", "Analysis", "EXECUTORS", "GenomeDbRun", "StudySpec", "StudyStatus",
    "StudySummary", "Task", "build_genome_db", "collect", "derive_seed", "execute_task",
    "extend_genome_db", "genome_db_to_sqlite", "load_spec",
    "make_executor", "run_study",
    "selftest_task", "spec_from_mapping", "study_status", "table_rows",
]
