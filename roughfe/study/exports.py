"""Hand finished studies to the stores of other parts of roughfe.

:func:`genome_db_to_sqlite` puts the entries of a ``genome_db`` study into a SQLite genome
database of :mod:`roughfe.genomics.database`, so that a database is built through the
study runner (any executor, resumable) and then read by the genomics tools.
"""
from __future__ import annotations

from ..errors import InputError
from . import store


def genome_db_to_sqlite(outdir, db_path) -> int:
    """Insert the finished entries of the ``genome_db`` study in ``outdir`` into ``db_path``.

    Entries go in task order; labels already in the database are skipped, so running it
    again after the study has progressed adds only the new genomes.

    Returns
    -------
    int
        Number of genomes inserted.
    """
    from ..genomics import database as gdb

    data = store.read_study(outdir)
    analysis = data["spec"]["study"]["analysis"]
    if analysis != "genome_db":
        raise InputError(f"{outdir} holds a {analysis!r} study; only 'genome_db' studies "
                         "can fill a genome database")
    entries = []
    for task in data["tasks"]:
        result = store.read_result(outdir, task["key"])
        if result is not None:
            entries.extend(result["records"])
    if not entries:
        raise InputError(f"the study in {outdir} has no finished genome yet")
    con = gdb.connect(db_path, create=True)
    try:
        # all entries of one database share L, N, material and n_t: checked by genomics
        gdb._set_settings(con, gdb.DatabaseSettings.from_dict(entries[0]["settings"]))
        present = set(gdb.labels(con))
        new = [e for e in entries if e["label"] not in present]
        for entry in new:
            if gdb.DatabaseSettings.from_dict(entry["settings"]) != \
                    gdb.DatabaseSettings.from_dict(entries[0]["settings"]):
                raise InputError(f"genome {entry['label']!r} was computed with other settings "
                                 f"than the first one: {entry['settings']}")
            gdb.insert_record(con, entry)
    finally:
        con.close()
    return len(new)
