"""Hand finished studies to the stores of other parts of roughfe.

:func:`genome_db_to_sqlite` puts the entries of a ``genome_db`` or ``genome_entry`` study
into a SQLite genome database of :mod:`roughfe.genomics.database`, so that a database is
built through the study runner (any executor, resumable) and then read by the genomics
tools; ``roughfe db build|extend`` (:mod:`roughfe.study.genome_db`) end with it.
"""
from __future__ import annotations

from ..errors import InputError
from . import store

GENOME_ANALYSES = ("genome_db", "genome_entry")


def genome_db_to_sqlite(outdir, db_path) -> int:
    """Insert the finished entries of the genome study in ``outdir`` into ``db_path``.

    One transaction: labels already in the database are skipped (existing genomes are
    kept), so running it again after the study has progressed adds only the new
    genomes; entries with other settings than the database's or than each other (one
    database holds one set of settings), or two tasks of the study with one label, are
    refused and nothing is inserted (a database file this call created is removed
    again). A new database takes the settings of the first entry.

    Returns
    -------
    int
        Number of genomes inserted.
    """
    from ..genomics import database as gdb

    data = store.read_study(outdir)
    analysis = data["spec_obj"].analysis
    if analysis not in GENOME_ANALYSES:
        raise InputError(f"{outdir} holds a {analysis!r} study; only {GENOME_ANALYSES} "
                         "studies can fill a genome database")
    made = []   # (task, record) of every finished genome
    for task in data["tasks"]:
        result = store.read_result(outdir, task["key"])
        made += [(task, record) for record in (result["records"] if result else [])]
    _check_one_settings(made, outdir)
    _check_one_genome_per_label(made, outdir)
    entries = [record for _, record in made]
    if not entries:
        raise InputError(f"the study in {outdir} has no finished genome yet")
    with gdb.new_file_removed_on_error(db_path):   # a refused import leaves no new file
        con = gdb.connect(db_path, create=True)
        try:
            gdb.write_settings(con, gdb.DatabaseSettings.from_dict(entries[0]["settings"]))
            return gdb.insert_records(con, entries)
        finally:
            con.close()


def _check_one_settings(made, outdir) -> None:
    """InputError naming two tasks and the settings they differ in, unless every record of
    ``made`` (``(task, record)`` pairs) carries one set of database settings."""
    from dataclasses import asdict

    from ..genomics.database import DatabaseSettings

    if not made:
        return
    first, ref = made[0][0], asdict(DatabaseSettings.from_dict(made[0][1]["settings"]))
    for task, record in made[1:]:
        got = asdict(DatabaseSettings.from_dict(record["settings"]))
        differ = [f"{k} ({ref[k]!r} vs {got[k]!r})" for k in ref if ref[k] != got[k]]
        if differ:
            raise InputError(
                f"tasks {first['index']} {first['params']} and {task['index']} "
                f"{task['params']} of the study in {outdir} differ in the database setting "
                f"{', '.join(differ)}; one database holds one set of settings, so nothing "
                "was inserted: collect a study of one setting into each database")


def _check_one_genome_per_label(made, outdir) -> None:
    """InputError naming two tasks of ``made`` (``(task, record)`` pairs) that made one
    genome label (a database holds one genome per label)."""
    made_by = {}
    for task, record in made:
        other = made_by.setdefault(record["label"], task)
        if other is not task:
            given = "label" in other["params"] or "label" in task["params"]
            raise InputError(
                f"tasks {other['index']} {other['params']} and {task['index']} "
                f"{task['params']} of the study in {outdir} both made the genome label "
                f"{record['label']!r}; a database holds one genome per label, so nothing "
                "was inserted: give each task its own label"
                + (" (or leave 'label' out: genome_db labels name the seed and the genes)"
                   if given else ""))
