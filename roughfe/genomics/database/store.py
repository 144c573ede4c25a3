"""SQLite storage of a genome database (schema version :data:`SCHEMA_VERSION`, see
:mod:`roughfe.genomics.database` for the layout)."""
from __future__ import annotations

import datetime as _dt
import json
import os
import re
import sqlite3
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...errors import FileFormatError, InputError, MemoryShortage
from ...frozen import freeze_containers
from ...writers import to_json_text
from ..similarity import ResponseCurve
from .settings import DatabaseSettings
from .sobol import SobolDesign

SCHEMA_VERSION = 1

_SCHEMA = """
CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS genomes (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    label TEXT NOT NULL UNIQUE,
    source TEXT NOT NULL,
    gamma REAL NOT NULL,
    hurst REAL NOT NULL,
    amplitude REAL NOT NULL,
    lambda1 REAL NOT NULL,
    n_ridges INTEGER NOT NULL,
    n_chromosomes INTEGER NOT NULL,
    genome_json TEXT NOT NULL,
    p_max REAL NOT NULL,
    curve_json TEXT NOT NULL,
    chromosome_curves_json TEXT NOT NULL,
    corr_k_json TEXT NOT NULL,
    corr_a_json TEXT NOT NULL,
    macro_json TEXT NOT NULL,
    created_utc TEXT NOT NULL
);
"""


@dataclass(frozen=True, eq=False)
class DatabaseEntry:
    """One genome of the database with its stored responses (read-only view of a row).

    ``curve`` is the realisation's K(p)/A(p) at the stored amplitude gene; ``macro`` and
    ``micro`` are chromosome numbers n (Alg. 2) of the chromosomes realised at the
    database's L and N (:func:`roughfe.genomics.periodic.realized_chromosomes`), in the
    order of ``corr_k``/``corr_a``, the c_n of each (NaN where undefined: a constant
    curve, stored as JSON null).
    """

    label: str
    source: str
    genome: dict
    p_max: float
    curve: ResponseCurve
    chromosome_curves: tuple
    corr_k: np.ndarray
    corr_a: np.ndarray
    macro: tuple
    micro: tuple
    gamma: float = field(default=np.nan)
    hurst: float = field(default=np.nan)

    def __post_init__(self):
        freeze_containers(self)

def _now():
    return _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")


def check_access(path, write: bool) -> None:
    """InputError unless the genome database ``path`` can be read (and with ``write``
    written: the file, and its folder, where SQLite keeps its journal while it writes).

    SQLite said "unable to open database file" as a traceback for a file without read
    permission, and "attempt to write a readonly database" after `db build`/`db extend`
    had computed every genome (round 2, session 37).
    """
    path = Path(path)
    if path.is_file() and not os.access(path, os.R_OK | (os.W_OK if write else 0)):
        raise InputError(f"cannot {'write' if write else 'read'} genome database {path}: "
                         "permission denied")
    folder = path.parent if str(path.parent) else Path(".")
    if write and folder.is_dir() and not os.access(folder, os.W_OK | os.X_OK):
        raise InputError(f"cannot write genome database {path}: its folder {folder} is not "
                         "writable (SQLite writes its journal beside the file)")


def connect(path, *, create=False) -> sqlite3.Connection:
    """Open (or with ``create=True`` create) a genome database and check its schema version.

    Without ``create`` the file is opened read-only and must already hold roughfe's
    tables: a foreign or empty SQLite file is reported (FileFormatError), never written.
    A folder is an InputError in both modes, and so is a file (or, with ``create``, a
    folder) that this process may not read or write (:func:`check_access`).
    """
    path = Path(path)
    if path.is_dir() or not (create or path.is_file()):
        raise InputError(f"genome database {path} does not exist"
                         + (" (it is a folder)" if path.is_dir() else
                            " (build it with 'roughfe db build')"))
    check_access(path, write=create)
    if not create:
        return _connect_read_only(path)
    if path.is_file() and path.stat().st_size:   # SQLite took a 1-byte file as empty and
        with open(path, "rb") as fh:             # overwrote it (round 2, session 33)
            if fh.read(16) != b"SQLite format 3\x00":
                raise FileFormatError(f"{path} is not a roughfe genome database (not an SQLite "
                                      f"file: {path.stat().st_size} bytes of other content); "
                                      "give a new file name")
    path.parent.mkdir(parents=True, exist_ok=True)
    try:       # created by us with 0666 & ~umask (SQLite's own default is 0644)
        os.close(os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
    except FileExistsError:
        pass
    con = sqlite3.connect(str(path), timeout=30.0)
    try:
        with con:
            con.executescript(_SCHEMA)
            row = con.execute("SELECT value FROM meta WHERE key='schema_version'").fetchone()
            if row is None:
                con.execute("INSERT INTO meta VALUES ('schema_version', ?)", (str(SCHEMA_VERSION),))
            elif int(row[0]) != SCHEMA_VERSION:
                raise FileFormatError(f"{path}: genome database schema version {row[0]}, this "
                                      f"roughfe reads version {SCHEMA_VERSION}")
    except sqlite3.DatabaseError as exc:
        con.close()
        raise FileFormatError(f"{path} is not a roughfe genome database: {exc}") from None
    return con


@contextmanager
def new_file_removed_on_error(path):
    """Run the block; when it raises, remove the database file ``path`` if the block
    created it (it did not exist before) and it holds no genome yet.

    A refused ``db build`` or ``study collect --genome-db`` (a design value the tasks
    refuse, an executor that does not start, entries of other settings) left a new file
    with only the settings and design, which then refused the corrected command ("the
    database was built with ..."). A refused call removes what it made.
    """
    path = Path(path)
    existed = path.exists()
    try:
        yield
    except BaseException:
        if not existed and path.is_file() and _n_genomes(path) == 0:
            path.unlink()
        raise


def _n_genomes(path: Path):
    """Genomes in the database file ``path`` (0 for an empty file; None when it cannot be
    read as a genome database)."""
    if path.stat().st_size == 0:
        return 0
    try:
        con = _connect_read_only(path)
    except (FileFormatError, sqlite3.Error):
        return None
    try:
        return con.execute("SELECT COUNT(*) FROM genomes").fetchone()[0]
    finally:
        con.close()


def _connect_read_only(path: Path) -> sqlite3.Connection:
    from urllib.parse import quote

    con = sqlite3.connect(f"file:{quote(str(path.resolve()))}?mode=ro", uri=True, timeout=30.0)
    try:
        tables = {r[0] for r in con.execute("SELECT name FROM sqlite_master WHERE type='table'")}
        if not {"meta", "genomes"} <= tables:
            raise FileFormatError(f"{path} is not a roughfe genome database (no 'meta' and "
                                  "'genomes' tables); build one with 'roughfe db build'")
        row = con.execute("SELECT value FROM meta WHERE key='schema_version'").fetchone()
        if row is None or int(row[0]) != SCHEMA_VERSION:
            raise FileFormatError(f"{path}: genome database schema version "
                                  f"{None if row is None else row[0]}, this roughfe reads "
                                  f"version {SCHEMA_VERSION}")
    except sqlite3.DatabaseError as exc:
        con.close()
        raise FileFormatError(f"{path} is not a roughfe genome database: {exc}") from None
    except BaseException:
        con.close()
        raise
    return con


def _get_meta(con, key):
    row = con.execute("SELECT value FROM meta WHERE key=?", (key,)).fetchone()
    return None if row is None else json.loads(row[0])


def write_settings(con, settings: DatabaseSettings):
    """Store ``settings`` in a new database, or check them against the stored ones.

    Raises
    ------
    InputError
        When the database holds other settings (all genomes share L, N, material, n_t).
    """
    _store_or_check(con, "settings", settings, "settings",
                    " All genomes of one database share L, N, material and n_t.")


def write_design(con, design: SobolDesign):
    """Store the Sobol design of a new database, or check it against the stored one."""
    _store_or_check(con, "sobol", design, "the Sobol design", "")


def _store_or_check(con, key, value, what, hint):
    """Store ``value`` (a dataclass with to_dict/from_dict) under ``key`` in the meta table
    of a new database, or raise InputError naming ``what`` when the stored one differs."""
    stored = _get_meta(con, key)
    if stored is None:
        with con:
            con.execute("INSERT INTO meta VALUES (?, ?)", (key, json.dumps(value.to_dict())))
    elif type(value).from_dict(stored) != value:
        raise InputError(f"the database was built with {what} {stored}; got "
                         f"{value.to_dict()}.{hint}")


def read_settings(path_or_con) -> DatabaseSettings:
    con = path_or_con if isinstance(path_or_con, sqlite3.Connection) else connect(path_or_con)
    stored = _get_meta(con, "settings")
    if stored is None:
        raise InputError("the genome database has no settings yet (it is empty)")
    return DatabaseSettings.from_dict(stored)


def _insert_row(con, record: dict):
    g = record["genome"]
    row = (record["label"], record["source"], float(g["gamma"]), float(g["H"]), float(g["A"]),
           float(g["lambda1"]), int(g["M"]), len(record["corr_k"]), json.dumps(g),
           float(record["p_max"]), json.dumps(record["curve"]),
           json.dumps(record["chromosome_curves"]), to_json_text(record["corr_k"], None),
           to_json_text(record["corr_a"], None), json.dumps(record["macro"]), _now())
    con.execute("INSERT INTO genomes (label, source, gamma, hurst, amplitude, lambda1, "
                "n_ridges, n_chromosomes, genome_json, p_max, curve_json, "
                "chromosome_curves_json, corr_k_json, corr_a_json, macro_json, created_utc) "
                "VALUES (?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?)", row)


def insert_records(con, records) -> int:
    """Insert :func:`genome_entry_task` records in one transaction; return how many.

    Records whose label is already in the database are skipped (the genomes there are
    kept), so importing the same results again adds nothing. Every record must carry the
    database's settings (write them first with :func:`write_settings`); otherwise nothing
    is inserted and InputError names the record.
    """
    settings = read_settings(con)
    present = set(labels(con))
    new = []
    for record in records:
        if DatabaseSettings.from_dict(record["settings"]) != settings:
            raise InputError(f"genome {record['label']!r} was computed with the settings "
                             f"{record['settings']}, the database holds {settings.to_dict()}")
        if record["label"] not in present:
            present.add(record["label"])
            new.append(record)
    with con:
        for record in new:
            _insert_row(con, record)
    return len(new)


def labels(con) -> list:
    return [r[0] for r in con.execute("SELECT label FROM genomes ORDER BY id")]


def extend_tasks(con, genomes, labels_=None) -> list:
    """:func:`genome_entry_task` arguments (label, source, genome_json) to add ``genomes``.

    ``genomes`` are Genome objects or Genome JSON dicts (e.g. sequenced ones); labels
    default to ``"x-<k>"`` with k counting on from the database's size, past any label
    already there. The database must hold settings already (an empty database is an
    error: build it first); a label given twice, already present, or of the Sobol
    design's form ``i-k`` is an error, and so is a genome the database's window cannot
    realise (checked here, before any task runs).
    """
    from .task import genome_entry_inputs
    settings = read_settings(con)
    dicts = [g if isinstance(g, dict) else g.to_dict() for g in genomes]
    if not dicts:
        raise InputError("no genomes given to add to the database")
    for k, d in enumerate(dicts):
        try:
            genome_entry_inputs(genome_json=d, **settings.to_dict())
        except MemoryShortage:   # the runner's to judge: it knows where the tasks run
            pass                 # (a remote scheduler's workers; run_study checks)
        except (InputError, FileFormatError) as exc:
            raise InputError(f"genome {k + 1} of {len(dicts)} cannot join this database "
                             f"(L = {settings.length:g} m, N = {settings.n_nodes}, dim "
                             f"{settings.dim}): {exc}") from None
    have = set(labels(con))
    if labels_ is None:
        labels_, k = [], len(have)
        while len(labels_) < len(dicts):
            k += 1
            if f"x-{k}" not in have:        # a user may have taken x-<k> already
                labels_.append(f"x-{k}")
    if len(labels_) != len(dicts):
        raise InputError(f"{len(labels_)} label(s) for {len(dicts)} genome(s)")
    twice = sorted({lab for lab in labels_ if list(labels_).count(lab) > 1})
    if twice:
        raise InputError(f"label(s) given more than once: {twice}; every genome needs its "
                         f"own label")
    sobol = sorted(lab for lab in labels_ if re.fullmatch(r"\d+-\d+", str(lab)))
    if sobol:
        raise InputError(f"label(s) {sobol} have the form i-k of the Sobol design's genomes "
                         f"(pair i, phase vector k), which a later 'db build' adds; choose "
                         f"another label")
    clash = sorted(set(labels_) & have)
    if clash:
        raise InputError(f"labels already in the database: {clash}")
    return [{"label": lab, "source": "extend", "genome_json": d}
            for lab, d in zip(labels_, dicts)]


def _entry(row, settings: DatabaseSettings) -> DatabaseEntry:
    from ..genome import Genome
    from ..periodic import realized_chromosomes
    (label, source, gamma, hurst, genome_json, p_max, curve_json, chrom_json, ck, ca,
     macro) = row
    genome = json.loads(genome_json)
    # an undefined c_n (a constant curve) is stored null and read back NaN
    ck, macro = np.asarray(json.loads(ck), dtype=float), tuple(json.loads(macro))
    # the chromosomes realised at the database's window (not the genome's first phase
    # column: an extended genome may hold phases below the window)
    ns = realized_chromosomes(Genome.from_dict(genome), settings.length, settings.n_nodes,
                              settings.dim)
    if ns.size != ck.size:
        raise FileFormatError(f"genome {label!r}: {ck.size} stored c_n for the {ns.size} "
                              f"chromosomes {ns[0]}..{ns[-1]} its window realises")
    micro = tuple(int(n) for n in ns if n not in set(macro))
    return DatabaseEntry(label=label, source=source, genome=genome,
                         p_max=float(p_max), curve=ResponseCurve.from_dict(json.loads(curve_json)),
                         chromosome_curves=tuple(ResponseCurve.from_dict(c)
                                                 for c in json.loads(chrom_json)),
                         corr_k=ck, corr_a=np.asarray(json.loads(ca), dtype=float),
                         macro=macro, micro=micro,
                         gamma=float(gamma), hurst=float(hurst))


def load_entries(path, *, labels_=None, where=None, params=()) -> list:
    """Read genomes as :class:`DatabaseEntry` (all, selected ``labels_``, or a SQL ``where``).

    Raises InputError for a database without genomes.
    """
    con = connect(path)
    try:
        sql = ("SELECT label, source, gamma, hurst, genome_json, p_max, curve_json, "
               "chromosome_curves_json, corr_k_json, corr_a_json, macro_json FROM genomes")
        if labels_ is not None:
            labels_ = list(labels_)
            sql += f" WHERE label IN ({','.join('?' * len(labels_))})"
            params = tuple(labels_)
        elif where:
            sql += f" WHERE {where}"
        rows = con.execute(sql + " ORDER BY id", params).fetchall()
        settings = read_settings(con) if rows else None
    finally:
        con.close()
    if not rows:
        raise InputError(f"the genome database {path} holds no genomes"
                         + (f" matching {labels_ or where!r}" if (labels_ or where) else
                            "; add genomes with `roughfe db build DB` (a Sobol design) or "
                            "`roughfe db extend DB GENOME.json ...`"))
    return [_entry(r, settings) for r in rows]


def summary_table(path) -> list:
    """One dict per genome: label, source, gamma, H, n_c, p_max (Pa), macro indices."""
    con = connect(path)
    try:
        rows = con.execute("SELECT label, source, gamma, hurst, n_chromosomes, p_max, macro_json "
                           "FROM genomes ORDER BY id").fetchall()
    finally:
        con.close()
    return [{"label": r[0], "source": r[1], "gamma": r[2], "H": r[3], "n_c": r[4], "p_max": r[5],
             "macro": json.loads(r[6])} for r in rows]
