"""Atomic file output shared by every module that writes results.

An interrupted run must never leave a half-written file: everything is written to a
temporary file in the destination folder and then renamed over the target
(``os.replace`` is atomic on POSIX within one file system).
"""
from __future__ import annotations

import contextlib
import json
import os
import tempfile
from pathlib import Path

import numpy as np


@contextlib.contextmanager
def atomic_path(path, suffix=None):
    """Yield a temporary path beside ``path``; rename it onto ``path`` on success.

    Use it for writers that want a file name (``np.savez``, ``h5py.File``, matplotlib
    ``savefig``, pyvista ``screenshot``). On an exception the temporary file is removed
    and ``path`` is left untouched.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    suffix = path.suffix if suffix is None else suffix
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=f".tmp{suffix}", dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def _json_default(obj):
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, Path):
        return str(obj)
    raise TypeError(f"object of type {type(obj).__name__} is not JSON serialisable")


def to_json_text(data) -> str:
    """JSON text of ``data``; numpy scalars and arrays become plain numbers and lists.

    Non-finite floats are written as ``null`` is *not* done silently: ``allow_nan`` is
    False so that a NaN in a result is caught here rather than written.
    """
    return json.dumps(data, indent=2, default=_json_default, allow_nan=False)


def write_json(path, data):
    """Write ``data`` as indented JSON, atomically. Returns the path."""
    text = to_json_text(data)
    with atomic_path(path) as tmp:
        tmp.write_text(text + "\n")
    return Path(path)


def write_text(path, text):
    """Write a text file atomically. Returns the path."""
    with atomic_path(path) as tmp:
        tmp.write_text(text)
    return Path(path)


def json_scalars(obj, keys) -> dict:
    """``{key: getattr(obj, key)}`` as JSON-safe numbers: ints stay ints, floats become
    Python floats and non-finite values become ``None`` (JSON has no NaN/inf)."""
    out = {}
    for key in keys:
        v = getattr(obj, key)
        if isinstance(v, (bool, np.bool_)):
            out[key] = bool(v)
        elif isinstance(v, (int, np.integer)):
            out[key] = int(v)
        else:
            v = float(v)
            out[key] = v if np.isfinite(v) else None
    return out
