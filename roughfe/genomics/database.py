"""The genome database of thesis Sec. 4.1.2: genes, realisation settings, p_max, K(p)/A(p)
curves and the macro/micro classification of every genome, in one SQLite file.

Layout (schema version :data:`SCHEMA_VERSION`, stdlib :mod:`sqlite3`)
--------------------------------------------------------------------
``meta(key, value)``
    ``schema_version``; ``settings`` (JSON of :class:`DatabaseSettings`: the one
    realisation length L, node count N, material and BEM steps shared by every row);
    ``sobol`` (JSON of the :class:`SobolDesign` that made the ``sobol`` rows).
``genomes``
    one row per genome: ``label`` (unique; ``"i-k"`` = Sobol pair i, phase vector k),
    ``source`` (``sobol`` or ``extend``), the scalar genes, ``genome_json`` (the
    versioned Genome JSON of :mod:`roughfe.genomics.genome`), ``p_max`` (Pa, at A as
    stored), ``curve_json`` (K(p), A(p) of the realisation), ``chromosome_curves_json``,
    ``corr_k_json`` / ``corr_a_json`` (c_n of Alg. 2, in the order n = n_s..n_f),
    ``macro_json`` (chromosome indices n with c_n > threshold) and ``created_utc``.

The genomes are computed by the study runner (``roughfe db build|extend`` call
:func:`roughfe.study.build_genome_db`: any executor, a study folder beside the file, so an
interrupted build resumes from its finished genomes). Workers only return JSON-safe records of
:func:`genome_entry_task`; :func:`insert_records` adds them in one transaction, keeping
the genomes already present, after checking their settings against the stored ones.
"""
from __future__ import annotations

import datetime as _dt
import json
import sqlite3
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from ..errors import FileFormatError, InputError
from .similarity import ResponseCurve

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


@dataclass(frozen=True)
class DatabaseSettings:
    """Realisation and contact settings shared by every genome of a database (Sec. 4.1.2).

    Parameters
    ----------
    length : float
        Observation length L (m); thesis 849.42 um (= lambda).
    n_nodes : int
        Nodes N of each realisation; thesis 512.
    youngs_modulus : float
        E (Pa) of the deformable body against a rigid profile; thesis 1 MPa.
    poisson : float
        nu; the thesis gives none, 0 makes E* = E.
    n_steps : int
        n_t far-field displacements up to the peak-valley amplitude; thesis 20.
    threshold : float
        c_n above which a chromosome is macro-scale (Alg. 2); thesis 0.95.
    kernel : str
        BEM influence kernel passed to :func:`roughfe.bem.contact_sweep`.
    stiffness : {"fd", "exact"}
        How K(p) is taken from the sweep (see :func:`roughfe.genomics.macro_micro.profile_response`).
    correlation : {"steps", "pressure"}
        How c_n pairs the curves (see :mod:`roughfe.genomics.macro_micro`).
    """

    length: float = 849.42e-6
    n_nodes: int = 512
    youngs_modulus: float = 1.0e6
    poisson: float = 0.0
    n_steps: int = 20
    threshold: float = 0.95
    kernel: str = "auto"
    stiffness: str = "fd"
    correlation: str = "steps"

    def __post_init__(self):
        for name in ("length", "youngs_modulus"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"{name} must be finite and > 0, got {v!r}")
        if int(self.n_nodes) < 16:
            raise InputError(f"n_nodes must be >= 16, got {self.n_nodes!r}")
        if int(self.n_steps) < 3:
            raise InputError(f"n_steps must be >= 3, got {self.n_steps!r}")
        if self.correlation not in ("steps", "pressure"):
            raise InputError(f"correlation must be 'steps' or 'pressure', got {self.correlation!r}")
        if self.stiffness not in ("fd", "exact"):
            raise InputError(f"stiffness must be 'fd' or 'exact', got {self.stiffness!r}")
        if not (0.0 < self.threshold < 1.0):
            raise InputError(f"threshold must lie in (0, 1), got {self.threshold!r}")
        object.__setattr__(self, "n_nodes", int(self.n_nodes))
        object.__setattr__(self, "n_steps", int(self.n_steps))

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, d) -> "DatabaseSettings":
        return cls(**d)


@dataclass(frozen=True)
class SobolDesign:
    """The Sobol design of the thesis database (Sec. 4.1.2, Fig. 53).

    ``n_pairs`` (gamma, H) pairs from a 2-D Sobol sequence scaled to ``gamma_range`` x
    ``hurst_range``; ``n_vectors`` phase vectors of ``n_phases`` values in [0, 2 pi),
    taken *sequentially* from a 1-D Sobol sequence (vector k = values k*n_phases ..
    (k+1)*n_phases - 1). Genomes with more chromosomes than ``n_phases`` (small gamma)
    take their extra phases sequentially from the same sequence after the first
    ``n_vectors * n_phases`` values (``n_extra`` per vector), as the thesis adds "a
    larger number of phases for smaller gamma". Both sequences use
    ``scipy.stats.qmc.Sobol(scramble=scramble, seed=seed)`` (pairs: ``seed``, phases:
    ``seed + 1``); the design is stored in the database.
    """

    n_pairs: int = 20
    n_vectors: int = 3
    n_phases: int = 30
    n_extra: int = 34
    gamma_range: tuple = (1.2, 2.0)
    hurst_range: tuple = (0.5, 1.5)
    seed: int = 20240
    scramble: bool = True

    def pairs(self) -> np.ndarray:
        """The (gamma, H) pairs, shape (n_pairs, 2)."""
        from scipy.stats import qmc
        m = int(np.ceil(np.log2(max(self.n_pairs, 2))))
        u = qmc.Sobol(d=2, scramble=self.scramble, seed=self.seed).random_base2(m)[: self.n_pairs]
        return qmc.scale(u, [self.gamma_range[0], self.hurst_range[0]],
                         [self.gamma_range[1], self.hurst_range[1]])

    def phase_vectors(self) -> np.ndarray:
        """Phase vectors (rad), shape (n_vectors, n_phases + n_extra)."""
        from scipy.stats import qmc
        base = self.n_vectors * self.n_phases
        total = base + self.n_vectors * self.n_extra
        m = int(np.ceil(np.log2(total)))
        seq = 2 * np.pi * qmc.Sobol(d=1, scramble=self.scramble,
                                    seed=self.seed + 1).random_base2(m)[:total, 0]
        out = np.empty((self.n_vectors, self.n_phases + self.n_extra))
        for k in range(self.n_vectors):
            out[k, : self.n_phases] = seq[k * self.n_phases:(k + 1) * self.n_phases]
            out[k, self.n_phases:] = seq[base + k * self.n_extra: base + (k + 1) * self.n_extra]
        return out

    def tasks(self):
        """``(label, gamma, H, phases)`` for every genome, labels ``"i-k"`` (1-based)."""
        pairs, phases = self.pairs(), self.phase_vectors()
        return [(f"{i + 1}-{k + 1}", float(g), float(h), phases[k])
                for i, (g, h) in enumerate(pairs) for k in range(self.n_vectors)]

    def to_dict(self) -> dict:
        d = asdict(self)
        d["gamma_range"], d["hurst_range"] = list(self.gamma_range), list(self.hurst_range)
        return d

    @classmethod
    def from_dict(cls, d) -> "SobolDesign":
        d = dict(d)
        d["gamma_range"], d["hurst_range"] = tuple(d["gamma_range"]), tuple(d["hurst_range"])
        return cls(**d)


@dataclass(frozen=True, eq=False)
class DatabaseEntry:
    """One genome of the database with its stored responses (read-only view of a row).

    ``curve`` is the realisation's K(p)/A(p) at the stored amplitude gene; ``macro`` and
    ``micro`` are 0-based chromosome column indices (Alg. 2); ``corr_k``/``corr_a`` the
    c_n of every chromosome.
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


# ---------------------------------------------------------------------------------------
# per-genome task (pure; runs in a worker process or in the study runner)
# ---------------------------------------------------------------------------------------
def genome_entry_task(gamma=None, hurst=None, phases=None, *, label, source="sobol",
                      amplitude=1.0, lambda1=None, length=849.42e-6, n_nodes=512,
                      youngs_modulus=1.0e6, poisson=0.0, n_steps=20, threshold=0.95,
                      kernel="auto", stiffness="fd", correlation="steps",
                      genome_json=None) -> dict:
    """Realise one genome, run Alg. 2 on it and return its database record (JSON-safe).

    Parameters
    ----------
    gamma, hurst : float, optional
        Genes gamma (-) and H (-) of Eq. (3.1).
    phases : int or array_like, optional
        A phase vector phi_{1,n} (rad; the first n_c entries are used, M = 1) or an
        int seed that draws uniform phases with ``numpy.random.default_rng(seed)``.
    label : str
        Unique name of the genome in the database.
    amplitude, lambda1 : float
        Genes A (-) and lambda (m); ``lambda1=None`` means lambda = L (thesis).
    length, n_nodes, youngs_modulus, poisson, n_steps, threshold, kernel, stiffness,
    correlation
        :class:`DatabaseSettings` fields (keywords so a study runner can pass them).
    genome_json : dict, optional
        A complete Genome JSON (e.g. a sequenced genome for ``db extend``); then
        gamma/hurst/phases are not needed.

    Returns
    -------
    dict
        ``label, source, genome, p_max, curve, chromosome_curves, corr_k, corr_a,
        macro, micro, settings`` (all JSON-safe).
    """
    from .macro_micro import macro_micro
    from .genome import Genome
    settings = DatabaseSettings(length, n_nodes, youngs_modulus, poisson, n_steps, threshold,
                                kernel, stiffness, correlation)
    if genome_json is not None:
        genome = Genome.from_dict(genome_json)
    elif gamma is None or hurst is None or phases is None:
        raise InputError("genome_entry_task needs gamma, hurst and phases, or genome_json")
    else:
        genome = make_genome(gamma, hurst, phases, settings, amplitude=amplitude,
                             lambda1=lambda1)
    mm = macro_micro(genome, settings)
    genome = _with_metadata(genome, label=str(label), source=str(source))
    return {"label": str(label), "source": str(source), "genome": genome.to_dict(),
            "p_max": mm.curve.p_max, "curve": mm.curve.to_dict(),
            "chromosome_curves": [c.to_dict() for c in mm.chromosome_curves],
            "corr_k": mm.corr_k.tolist(), "corr_a": mm.corr_a.tolist(),
            "macro": list(mm.macro), "micro": list(mm.micro), "settings": settings.to_dict()}


def _with_metadata(genome, **facts):
    from .genome import Genome
    d = genome.to_dict()
    d["metadata"] = {**d.get("metadata", {}), **facts}
    return Genome.from_dict(d)


def make_genome(gamma, hurst, phases, settings: DatabaseSettings, *, amplitude=1.0,
                lambda1=None):
    """A one-ridge (M = 1) genome with the chromosomes realised at ``settings`` (Eq. 3.5).

    ``phases`` is a vector (its first n_c entries are used) or an int seed.
    """
    from .genome import Genome, chromosome_range
    lam = settings.length if lambda1 is None else float(lambda1)
    n_s, n_f = chromosome_range(float(gamma), lam, settings.length, settings.n_nodes)
    n_c = n_f - n_s + 1
    if np.isscalar(phases) and float(phases) == int(phases):
        phi = np.random.default_rng(int(phases)).uniform(0, 2 * np.pi, n_c)
    else:
        phi = np.asarray(phases, dtype=float).ravel()
        if phi.size < n_c:
            raise InputError(f"gamma = {gamma:.4g} needs {n_c} phases at N = {settings.n_nodes}, "
                             f"got a phase vector of {phi.size}")
        phi = phi[:n_c]
    return Genome(A=float(amplitude), H=float(hurst), gamma=float(gamma), lambda1=lam,
                  phases=phi[None, :], n_first=n_s)


# ---------------------------------------------------------------------------------------
# SQLite storage
# ---------------------------------------------------------------------------------------
def _now():
    return _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")


def connect(path, *, create=False) -> sqlite3.Connection:
    """Open (or with ``create=True`` create) a genome database and check its schema version.

    Without ``create`` the file is opened read-only and must already hold roughfe's
    tables: a foreign or empty SQLite file is reported (FileFormatError), never written.
    """
    path = Path(path)
    if not create:
        if not path.is_file():
            raise InputError(f"genome database {path} does not exist"
                             + (" (it is a folder)" if path.is_dir() else
                                " (build it with 'roughfe db build')"))
        return _connect_read_only(path)
    path.parent.mkdir(parents=True, exist_ok=True)
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
           json.dumps(record["chromosome_curves"]), json.dumps(record["corr_k"]),
           json.dumps(record["corr_a"]), json.dumps(record["macro"]), _now())
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


def sobol_tasks(design: SobolDesign, limit=None) -> list:
    """:func:`genome_entry_task` arguments (label, source, gamma, hurst, phases) per genome.

    ``limit`` keeps the first genomes of the design (a reduced database); it must be >= 1.
    """
    tasks = [{"label": lab, "source": "sobol", "gamma": g, "hurst": h,
              "phases": [float(v) for v in phi]} for lab, g, h, phi in design.tasks()]
    if limit is not None:
        if int(limit) < 1:
            raise InputError(f"limit must be >= 1 genome, got {limit!r}")
        tasks = tasks[: int(limit)]
    return tasks


def extend_tasks(con, genomes, labels_=None) -> list:
    """:func:`genome_entry_task` arguments (label, source, genome_json) to add ``genomes``.

    ``genomes`` are Genome objects or Genome JSON dicts (e.g. sequenced ones); labels
    default to ``"x-<k>"``. The database must hold settings already (an empty database
    is an error: build it first); a label already present is an error.
    """
    read_settings(con)
    dicts = [g if isinstance(g, dict) else g.to_dict() for g in genomes]
    if not dicts:
        raise InputError("no genomes given to add to the database")
    have = set(labels(con))
    if labels_ is None:
        start = len(have) + 1
        labels_ = [f"x-{start + k}" for k in range(len(dicts))]
    if len(labels_) != len(dicts):
        raise InputError(f"{len(labels_)} label(s) for {len(dicts)} genome(s)")
    clash = sorted(set(labels_) & have)
    if clash:
        raise InputError(f"labels already in the database: {clash}")
    return [{"label": lab, "source": "extend", "genome_json": d}
            for lab, d in zip(labels_, dicts)]


def _entry(row) -> DatabaseEntry:
    (label, source, gamma, hurst, genome_json, p_max, curve_json, chrom_json, ck, ca,
     macro) = row
    genome = json.loads(genome_json)
    ck, macro = np.asarray(json.loads(ck)), tuple(json.loads(macro))
    n_s = int(genome.get("n_first", 1))
    micro = tuple(n for n in range(n_s, n_s + ck.size) if n not in set(macro))
    return DatabaseEntry(label=label, source=source, genome=genome,
                         p_max=float(p_max), curve=ResponseCurve.from_dict(json.loads(curve_json)),
                         chromosome_curves=tuple(ResponseCurve.from_dict(c)
                                                 for c in json.loads(chrom_json)),
                         corr_k=ck, corr_a=np.asarray(json.loads(ca)), macro=macro, micro=micro,
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
    finally:
        con.close()
    if not rows:
        raise InputError(f"the genome database {path} holds no genomes"
                         + (f" matching {labels_ or where!r}" if (labels_ or where) else ""))
    return [_entry(r) for r in rows]


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
