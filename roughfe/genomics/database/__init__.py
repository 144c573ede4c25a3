"""The genome database of thesis Sec. 4.1.2: genes, realisation settings, p_max, K(p)/A(p)
curves and the macro/micro classification of every genome, in one SQLite file.

Layout (schema version :data:`SCHEMA_VERSION`, stdlib :mod:`sqlite3`)
--------------------------------------------------------------------
``meta(key, value)``
    ``schema_version``; ``settings`` (JSON of :class:`DatabaseSettings`: the one
    realisation length L, node count N, material and BEM steps shared by every row;
    a surface database records ``"dim": 2`` and its ``top_fraction``, a profile
    database written by any roughfe omits both, read as dim 1 and 1);
    ``sobol`` (JSON of the :class:`SobolDesign` that made the ``sobol`` rows; for
    surfaces with ``dim``, ``n_ridges`` and ``anisotropy_range``).
``genomes``
    one row per genome: ``label`` (unique; ``"i-k"`` = Sobol pair i, phase vector k),
    ``source`` (``sobol`` or ``extend``), the scalar genes (``n_ridges`` = M: 1 for
    Sobol profiles, the genome's own M for an extended one, the ridges of a surface
    genome, whose angles and anisotropy are in its ``genome_json``), ``genome_json`` (the
    versioned Genome JSON of :mod:`roughfe.genomics.genome`), ``p_max`` (Pa, at A as
    stored), ``curve_json`` (K(p), A(p) of the realisation), ``chromosome_curves_json``,
    ``corr_k_json`` / ``corr_a_json`` (c_n of Alg. 2, in the order of the chromosomes
    the window realises: n = n_s..n_f of Eq. 3.5 (or the periodic range) that the
    genome holds, :func:`roughfe.genomics.periodic.realized_chromosomes`),
    ``macro_json`` (chromosome indices n with c_n > threshold) and ``created_utc``.

Profiles (dim 1) are the thesis realisations (N nodes spanning L, non-periodic BEM);
surfaces (dim 2, issue 15) are periodic N x N realisations of period L
(:mod:`roughfe.genomics.periodic`) solved with the periodic spectral BEM, and their
chromosome curves are those of the periodic range. The same tables hold both.

The genomes are computed by the study runner (``roughfe db build|extend`` call
:func:`roughfe.study.build_genome_db`: any executor, a study folder beside the file, so an
interrupted build resumes from its finished genomes). Workers only return JSON-safe records of
:func:`genome_entry_task`; :func:`insert_records` adds them in one transaction, keeping
the genomes already present, after checking their settings against the stored ones.

Modules: :mod:`.settings` (:class:`DatabaseSettings` and :data:`THESIS_SETTINGS`, the one
set of thesis defaults), :mod:`.sobol` (the Sobol design), :mod:`.task` (the pure
per-genome computation) and :mod:`.store` (SQLite storage). Every public name is
importable from ``roughfe.genomics.database``.
"""
from .settings import THESIS_SETTINGS, DatabaseSettings, settings_from
from .sobol import SobolDesign, sobol_tasks
from .store import (SCHEMA_VERSION, DatabaseEntry, check_access, connect, extend_tasks,
                    insert_records, labels, load_entries, new_file_removed_on_error,
                    read_settings, summary_table, write_design, write_settings)
from .task import genome_entry_task, make_genome

__all__ = ["THESIS_SETTINGS", "DatabaseSettings", "settings_from", "SobolDesign", "sobol_tasks",
           "SCHEMA_VERSION", "DatabaseEntry", "check_access", "connect", "extend_tasks",
           "insert_records", "labels", "load_entries", "new_file_removed_on_error",
           "read_settings", "summary_table", "write_design", "write_settings",
           "genome_entry_task", "make_genome"]
