"""The tidy table of a study: ``collect`` writes ``table.csv`` (and ``table.parquet``).

One row per record of every finished task, in task order: ``task`` (grid index),
``key``, the parameters, ``seed``, then the record's fields. The rows are read from the
result files (:mod:`roughfe.study.store`), under the study's lock.
"""
from __future__ import annotations

import csv
import io
from pathlib import Path

from ..writers import folder_lock, write_text
from .spec import canonical_json
from .store import read_result, read_study


def _cell(value):
    if value is None:
        return ""
    if isinstance(value, (list, dict)):
        return canonical_json(value)
    return value


def table_rows(outdir):
    """Tidy rows of all finished tasks, in task order.

    Each row has ``task`` (grid index), ``key``, the parameters, ``seed`` and then one
    record's fields. A record field named like a parameter is dropped when equal to it
    and kept as ``<name>_result`` otherwise. Returns (columns, rows, n_missing).
    """
    data = read_study(outdir)
    columns, rows, missing = {}, [], 0
    for t in data["tasks"]:
        result = read_result(outdir, t["key"])
        if result is None:
            missing += 1
            continue
        head = {"task": t["index"], "key": t["key"], **t["params"], "seed": t["seed"]}
        for record in result["records"]:
            row = dict(head)
            for name, value in record.items():
                if name in head:
                    if canonical_json(value) == canonical_json(head[name]):
                        continue
                    name = f"{name}_result"
                row[name] = value
            for name in row:
                columns.setdefault(name, None)
            rows.append(row)
    return list(columns), rows, missing


def collect(outdir, *, parquet=True):
    """Write ``table.csv`` (and ``table.parquet`` if pyarrow is importable).

    Returns (paths written, number of rows, number of tasks without a result, note),
    where ``note`` says why Parquet was not written (or is empty).
    """
    outdir = Path(outdir)
    read_study(outdir)                        # a study folder, or a one-line error
    with folder_lock(outdir, "`roughfe study collect`"):   # not under a run
        return _collect(outdir, parquet)


def _collect(outdir, parquet):
    columns, rows, missing = table_rows(outdir)
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(columns)
    for row in rows:
        writer.writerow([_cell(row.get(c)) for c in columns])
    paths = [write_text(outdir / "table.csv", buf.getvalue())]
    note = ""
    if parquet:
        note = _write_parquet(outdir / "table.parquet", columns, rows)
        if not note:
            paths.append(outdir / "table.parquet")
    return paths, len(rows), missing, note


def _parquet_column(values) -> list:
    """One column for Parquet: lists and tables as JSON text (as in the CSV); a column
    whose values are of several kinds (numbers, booleans, text) all as text, since an
    Arrow column has one type (numbers beside a list raised ArrowTypeError)."""
    def kind(v):
        return "bool" if isinstance(v, bool) else "number" if isinstance(v, (int, float)) \
            else "text"
    kinds = {kind(v) for v in values if v is not None}
    if len(kinds) > 1:
        return [None if v is None else v if isinstance(v, str) else canonical_json(v)
                for v in values]
    return [None if v is None else _cell(v) for v in values]


def _write_parquet(path, columns, rows) -> str:
    """Write the table as Parquet (atomically); return why it was not written, or ""."""
    try:
        import pyarrow
    except ModuleNotFoundError as exc:
        if exc.name != "pyarrow":   # pyarrow is there, one of its imports is not
            return f"Parquet not written: pyarrow cannot be imported here: {exc}"
        return "Parquet not written: pyarrow is not installed (pip install pyarrow)"
    except Exception as exc:        # found but broken, e.g. built for another numpy
        return (f"Parquet not written: pyarrow is installed but cannot be imported here "
                f"({type(exc).__name__}: {exc})")
    import pandas as pd

    from ..writers import atomic_path

    frame = pd.DataFrame({c: _parquet_column([r.get(c) for r in rows]) for c in columns},
                         columns=columns)
    try:
        with atomic_path(path) as tmp:
            frame.to_parquet(tmp, index=False, engine="pyarrow")
    except (pyarrow.ArrowException, TypeError, ValueError) as exc:
        return f"Parquet not written: {type(exc).__name__}: {exc}"
    return ""
