"""Study specifications: which analysis, over which parameter grid, written where.

A study is read from TOML (``tomllib``) or built from a mapping with the same layout::

    [study]
    name = "leakage-small"       # free text, recorded with the results
    analysis = "leakage"         # a key of roughfe.study.analyses.ANALYSES
    output = "studies/leakage"   # results folder (relative to the working directory)
    seed = 2026                  # base seed of the whole study (integer >= 0)
    seed_from = ["D", "replica"] # parameters that select the random surface (default: all)
    max_attempts = 2             # attempts per task and per run before it is left failed

    [grid]                       # cartesian product, in the order written here
    D = [2.1, 2.4]
    m = [5, 6]
    replica = [0, 1]

    [fixed]                      # the same value for every task
    n_steps = 6

Each task gets a seed derived by SHA-256 from the base seed, the analysis and the
values of the ``seed_from`` parameters (never Python's salted ``hash()``). Leaving a
parameter out of ``seed_from`` keeps the same random surface across its values, e.g.
the same realisation refined over resolutions ``m``. A parameter named ``seed`` in the
grid or fixed table is used as given instead. A grid parameter named ``replica``
(e.g. ``replica = [0, 1, ..., 19]`` for 20 surfaces per point) only selects the seed and
labels the rows: it is not passed to the analysis. So a grid of several replicas needs
``replica`` in ``seed_from`` (when ``seed_from`` is given) and no ``seed`` parameter; a
spec without them is refused (its replicas would all run the same surface).

Each task is stored under a content key: SHA-256 of the canonical JSON of the analysis,
its version, the roughfe version, the parameters as the task runs them (the spec's values
over the analysis' defaults) and the seed. Identical work always gets the same key, on
any machine and with any executor, and a changed default gives new keys. Up to key
format 1 only the spec's values were hashed (a changed default reused old results);
:data:`KEY_FORMAT` is recorded in ``study.json``.
"""
from __future__ import annotations

import hashlib
import inspect
import itertools
import json
import math
import os
import tomllib
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

from .. import __version__
from ..errors import InputError
from ..frozen import freeze_containers

#: The task-key scheme, recorded in ``study.json``: 2 hashes the resolved parameters
#: (defaults included); 1 (no record) hashed the spec's values only.
KEY_FORMAT = 2
SECTIONS = {"study", "grid", "fixed"}
RUNNER_ONLY = ("replica",)  # parameters that select seeds but are not passed to the analysis
STUDY_KEYS = {"name", "analysis", "output", "seed", "seed_from", "max_attempts"}


def canonical_json(obj) -> str:
    """Canonical JSON text: sorted keys, no spaces, ASCII, no NaN/inf.

    Two equal parameter sets always give the same text (and hence the same hash).
    """
    return json.dumps(obj, sort_keys=True, separators=(",", ":"), ensure_ascii=True,
                      allow_nan=False)


def sha256_hex(obj) -> str:
    """SHA-256 hex digest of :func:`canonical_json` of ``obj``."""
    return hashlib.sha256(canonical_json(obj).encode("ascii")).hexdigest()


def derive_seed(base_seed: int, analysis: str, values: Mapping[str, Any]) -> int:
    """Deterministic seed in ``[0, 2**53)`` from the study seed, the analysis and parameters.

    Stable across processes, machines and Python versions (SHA-256 of canonical JSON).
    53 bits keep the seed exact wherever it passes through a float (JSON readers,
    spreadsheets, ``float(seed) == int(seed)`` checks).
    """
    digest = sha256_hex({"base_seed": int(base_seed), "analysis": analysis,
                         "values": dict(values)})
    return int(digest[:14], 16) >> 3


def _check_value(where: str, value):
    """A parameter value must be a JSON scalar (or a list/table of them) without NaN."""
    if isinstance(value, bool) or isinstance(value, (int, str)):
        return value
    if isinstance(value, float):
        if not math.isfinite(value):
            raise InputError(f"{where} must be finite, got {value!r}")
        return value
    if isinstance(value, list):
        return [_check_value(f"{where}[{i}]", v) for i, v in enumerate(value)]
    if isinstance(value, dict):
        return {str(k): _check_value(f"{where}.{k}", v) for k, v in value.items()}
    raise InputError(f"{where} must be a number, string, boolean, list or table, "
                     f"got {type(value).__name__} {value!r}")


def _check_name(where: str, name: str):
    if not (isinstance(name, str) and name.isidentifier()):
        raise InputError(f"{where}: parameter name {name!r} must be a Python identifier "
                         "(letters, digits, underscores; not starting with a digit)")
    return name


def _check_replica(grid: Mapping, fixed: Mapping, seed_from) -> None:
    """Refuse a ``replica`` grid that cannot select the seed.

    ``replica`` is not passed to the analysis: it only selects the seed. With a ``seed``
    parameter (used as given) or a ``seed_from`` without ``replica``, its values would be
    distinct tasks of one surface (identical "replicas", spread 0).
    """
    if len(grid.get("replica", ())) < 2:
        return
    if "seed" in grid or "seed" in fixed:
        raise InputError("[grid] replica only selects the seed, but a parameter 'seed' gives "
                         "the seed as is: every replica would run the same surface. Drop "
                         "'seed' (the study's [study] seed and seed_from derive one per "
                         "replica) or drop 'replica'")
    if seed_from is not None and "replica" not in seed_from:
        raise InputError(f"[grid] replica only selects the seed, but [study] seed_from = "
                         f"{list(seed_from)} leaves it out: every replica would run the "
                         f"same surface. Add 'replica' to seed_from, or drop 'replica'")


@dataclass(frozen=True)
class Task:
    """One unit of work: an analysis called with ``params`` and ``seed``.

    Attributes
    ----------
    index : int
        Position in the grid's cartesian product (the row order of the table).
    params : dict
        Grid values followed by fixed values, by name.
    seed : int
        The task's seed (derived, or the ``seed`` parameter when one is given).
    key : str
        Content key (SHA-256 hex) under which the result is stored: the analysis, its
        version, the roughfe version, ``params`` over the analysis' defaults, the seed.
    """

    index: int
    params: Mapping[str, Any]
    seed: int
    key: str

    def __post_init__(self):
        freeze_containers(self)

    @property
    def kwargs(self) -> dict:
        """Keyword arguments of the analysis call (``params`` minus runner-only ones)."""
        return {k: v for k, v in self.params.items() if k not in RUNNER_ONLY}


@dataclass(frozen=True)
class StudySpec:
    """A validated study: analysis, parameter grid, fixed parameters and output folder.

    Build it with :func:`load_spec` (TOML file) or :func:`spec_from_mapping`; the
    constructor validates everything and raises :class:`~roughfe.errors.InputError`
    naming the offending entry.
    """

    name: str
    analysis: str
    output: Path
    grid: Mapping[str, tuple] = field(default_factory=dict)
    fixed: Mapping[str, Any] = field(default_factory=dict)
    seed: int = 0
    seed_from: tuple | None = None
    max_attempts: int = 2

    def __post_init__(self):
        from .analyses import ANALYSES  # the registry of names (no analysis is imported)

        if not isinstance(self.analysis, str):
            raise InputError(f"[study] analysis must be the name of an analysis (a string), "
                             f"got {type(self.analysis).__name__} {self.analysis!r}; "
                             f"choose from {sorted(ANALYSES)}")
        if self.analysis not in ANALYSES:
            raise InputError(f"[study] analysis {self.analysis!r} is unknown; "
                             f"choose from {sorted(ANALYSES)}")
        if not isinstance(self.name, str) or not self.name:
            raise InputError(f"[study] name must be a non-empty string, got {self.name!r}")
        if not isinstance(self.output, (str, os.PathLike)):
            raise InputError(f"[study] output must be a folder name (a string), got "
                             f"{type(self.output).__name__} {self.output!r}")
        if not str(self.output).strip():
            raise InputError(f"[study] output must name a folder, got {str(self.output)!r} "
                             "(the results would be written into the working directory)")
        object.__setattr__(self, "output", Path(self.output))
        if isinstance(self.seed, bool) or not isinstance(self.seed, int) or self.seed < 0:
            raise InputError(f"[study] seed must be an integer >= 0, got {self.seed!r}")
        if (isinstance(self.max_attempts, bool) or not isinstance(self.max_attempts, int)
                or not 1 <= self.max_attempts <= 100):
            raise InputError(f"[study] max_attempts must be an integer in 1..100, "
                             f"got {self.max_attempts!r}")
        grid = {}
        for name, values in dict(self.grid).items():
            _check_name("[grid]", name)
            if not isinstance(values, (list, tuple)) or len(values) == 0:
                raise InputError(f"[grid] {name} must be a non-empty list of values, "
                                 f"got {values!r}")
            vals = tuple(_check_value(f"[grid] {name}[{i}]", v) for i, v in enumerate(values))
            texts = [canonical_json(v) for v in vals]
            if len(set(texts)) != len(texts):
                dup = next(v for v, t in zip(vals, texts) if texts.count(t) > 1)
                raise InputError(f"[grid] {name} lists the value {dup!r} more than once")
            grid[name] = vals
        fixed = {}
        for name, value in dict(self.fixed).items():
            _check_name("[fixed]", name)
            if name in grid:
                raise InputError(f"parameter {name!r} is both in [grid] and [fixed]; "
                                 "give it in one of them")
            fixed[name] = _check_value(f"[fixed] {name}", value)
        object.__setattr__(self, "grid", grid)
        object.__setattr__(self, "fixed", fixed)
        names = [*grid, *fixed]
        if self.seed_from is not None:
            if isinstance(self.seed_from, str) or not isinstance(self.seed_from, (list, tuple)):
                raise InputError(f"[study] seed_from must be a list of parameter names, "
                                 f"got {self.seed_from!r}")
            unknown = [s for s in self.seed_from if s not in names]
            if unknown:
                raise InputError(f"[study] seed_from names {unknown} that are not parameters; "
                                 f"the parameters are {names}")
            object.__setattr__(self, "seed_from", tuple(self.seed_from))
        _check_replica(grid, fixed, self.seed_from)

    @property
    def n_tasks(self) -> int:
        """Number of tasks (product of the grid lengths; 1 for an empty grid)."""
        return math.prod(len(v) for v in self.grid.values())

    def to_dict(self) -> dict:
        """JSON-safe mapping in the TOML layout (the inverse of :func:`spec_from_mapping`)."""
        study = {"name": self.name, "analysis": self.analysis, "output": str(self.output),
                 "seed": self.seed, "max_attempts": self.max_attempts}
        if self.seed_from is not None:
            study["seed_from"] = list(self.seed_from)
        return {"study": study, "grid": {k: list(v) for k, v in self.grid.items()},
                "fixed": dict(self.fixed)}

    def tasks(self) -> list[Task]:
        """All tasks, in cartesian-product order of the grid (last parameter fastest)."""
        from .analyses import ANALYSES, parameter_defaults

        version = ANALYSES[self.analysis].version
        defaults = parameter_defaults(self.analysis)
        names = list(self.grid)
        out = []
        for index, combo in enumerate(itertools.product(*self.grid.values())):
            params = {**dict(zip(names, combo)), **self.fixed}
            if "seed" in params:
                seed = params.pop("seed")
                if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
                    raise InputError(f"parameter seed must be an integer >= 0, got {seed!r}")
            else:
                chosen = names + list(self.fixed) if self.seed_from is None else self.seed_from
                seed = derive_seed(self.seed, self.analysis, {k: params[k] for k in chosen})
            key = sha256_hex({"analysis": self.analysis, "analysis_version": version,
                              "code_version": __version__, "params": {**defaults, **params},
                              "seed": seed})
            out.append(Task(index=index, params=params, seed=seed, key=key))
        return out


#: Old parameter names of study specs -> the names of the CLI vocabulary (``--E``, ``--nu``).
RENAMED_PARAMETERS = {"youngs_modulus": "E", "poisson": "nu"}


def _current_names(analysis: str, section: str, table: Mapping) -> dict:
    """``table`` with old parameter names (:data:`RENAMED_PARAMETERS`) renamed, with a
    ``FutureWarning``, where the analysis takes the new name and not the old one."""
    table = dict(table)
    old = [k for k in table if k in RENAMED_PARAMETERS]
    if not old:
        return table
    from .analyses import ANALYSES, resolve

    if not isinstance(analysis, str) or analysis not in ANALYSES:
        return table  # StudySpec reports the unknown analysis
    accepted = inspect.signature(resolve(analysis)).parameters
    for key in old:
        new = RENAMED_PARAMETERS[key]
        if key in accepted or new not in accepted:
            continue
        if new in table:
            raise InputError(f"[{section}] gives both {key!r} and {new!r}; write {new!r} only")
        warnings.warn(f"study spec [{section}] {key} is deprecated: write {new} (the "
                      f"vocabulary of the command line)", FutureWarning, stacklevel=3)
        table[new] = table.pop(key)
    return table


def spec_from_mapping(data: Mapping[str, Any], *, output=None) -> StudySpec:
    """Build a :class:`StudySpec` from the TOML layout (``[study]``, ``[grid]``, ``[fixed]``).

    ``output`` overrides ``[study] output`` (e.g. from the command line).
    """
    if not isinstance(data, Mapping):
        raise InputError(f"a study spec must be a table, got {type(data).__name__}")
    extra = set(data) - SECTIONS
    if extra:
        raise InputError(f"unknown section(s) {sorted(extra)} in the study spec; "
                         f"allowed: {sorted(SECTIONS)}")
    study = data.get("study")
    if not isinstance(study, Mapping):
        raise InputError("the study spec needs a [study] table with at least "
                         "'analysis' and 'output'")
    extra = set(study) - STUDY_KEYS
    if extra:
        raise InputError(f"unknown key(s) {sorted(extra)} in [study]; "
                         f"allowed: {sorted(STUDY_KEYS)}")
    for needed in ("analysis",):
        if needed not in study:
            raise InputError(f"[study] needs '{needed}'")
    if output is None and "output" not in study:
        raise InputError("[study] needs 'output' (the results folder), or give --output")
    for section in ("grid", "fixed"):
        if section in data and not isinstance(data[section], Mapping):
            raise InputError(f"[{section}] must be a table, got {data[section]!r}")
    grid, fixed = (_current_names(study["analysis"], section, data.get(section, {}))
                   for section in ("grid", "fixed"))
    return StudySpec(
        name=study.get("name", study["analysis"]),
        analysis=study["analysis"],
        output=output if output is not None else study["output"],   # checked there
        grid=grid,
        fixed=fixed,
        seed=study.get("seed", 0),
        seed_from=study.get("seed_from"),
        max_attempts=study.get("max_attempts", 2),
    )


def load_spec(path, *, output=None) -> StudySpec:
    """Read and validate a study spec from a TOML file."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputError(f"study spec {path} does not exist") from None
    except UnicodeDecodeError as exc:
        raise InputError(f"study spec {path} is not UTF-8 text (TOML files are UTF-8): byte "
                         f"0x{exc.object[exc.start]:02x} at offset {exc.start}; save it as "
                         "UTF-8") from None
    except OSError as exc:
        raise InputError(f"cannot read study spec {path}: {exc.strerror}") from None
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"study spec {path} is not valid TOML: {exc}") from None
    return spec_from_mapping(data, output=output)
