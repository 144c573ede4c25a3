"""Memo caches bounded by the bytes they keep, not by a number of entries.

``functools.lru_cache(maxsize=16)`` on a function returning arrays pins 16 results of
any size: 16 influence operators of a 2048^2 surface are GBs. :func:`bytes_bounded_cache`
keeps the most recently used results while their total size (numpy ``nbytes``, summed
through tuples, lists, mappings and dataclass fields) stays within ``max_bytes``; a
result larger than the budget is returned but not kept. Keep only immutable values here
(read-only arrays, frozen dataclasses): never PETSc/dolfinx objects that a solve mutates.
"""
from __future__ import annotations

import dataclasses
import functools
import threading
from collections import OrderedDict
from typing import Callable, NamedTuple, Optional

import numpy as np

MB = 1 << 20


def nbytes(value) -> int:
    """Bytes of the numpy arrays held by ``value`` (arrays, containers, dataclasses)."""
    if isinstance(value, np.ndarray):
        return int(value.nbytes)
    if isinstance(value, (tuple, list)):
        return sum(nbytes(v) for v in value)
    if isinstance(value, dict):
        return sum(nbytes(v) for v in value.values())
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return sum(nbytes(getattr(value, f.name)) for f in dataclasses.fields(value))
    return 0


class CacheInfo(NamedTuple):
    hits: int
    misses: int
    entries: int
    bytes: int
    max_bytes: int


class _BytesBoundedCache:
    """The wrapper built by :func:`bytes_bounded_cache` (thread-safe bookkeeping)."""

    def __init__(self, func: Callable, max_bytes: int, key: Optional[Callable]):
        self._func, self.max_bytes, self._key = func, int(max_bytes), key
        self._data: OrderedDict = OrderedDict()
        self._sizes: dict = {}
        self._bytes = self._hits = self._misses = 0
        self._lock = threading.Lock()
        functools.update_wrapper(self, func)

    def __call__(self, *args):
        key = self._key(*args) if self._key else args
        with self._lock:
            if key in self._data:
                self._data.move_to_end(key)
                self._hits += 1
                return self._data[key]
            self._misses += 1
        value = self._func(*args)           # computed outside the lock
        size = nbytes(value)
        if size > self.max_bytes:
            return value                    # too large to keep: the caller holds it
        with self._lock:
            if key not in self._data:
                self._data[key] = value
                self._sizes[key] = size
                self._bytes += size
            while self._bytes > self.max_bytes:
                old, _ = self._data.popitem(last=False)
                self._bytes -= self._sizes.pop(old)
        return value

    def cache_info(self) -> CacheInfo:
        with self._lock:
            return CacheInfo(self._hits, self._misses, len(self._data), self._bytes,
                             self.max_bytes)

    def cache_clear(self) -> None:
        with self._lock:
            self._data.clear()
            self._sizes.clear()
            self._bytes = self._hits = self._misses = 0


def bytes_bounded_cache(max_bytes: int, key: Optional[Callable] = None):
    """Decorator: memoise a function of hashable arguments within ``max_bytes``.

    Parameters
    ----------
    max_bytes : int
        Budget for the kept results (bytes of their numpy arrays, see :func:`nbytes`).
    key : callable, optional
        Maps the arguments to the cache key (default: the argument tuple). Use it to key
        on parameters rather than on an object's identity.

    The wrapper has ``cache_info()`` (hits, misses, entries, bytes, max_bytes) and
    ``cache_clear()``, like :func:`functools.lru_cache`.
    """
    def wrap(func):
        return _BytesBoundedCache(func, max_bytes, key)
    return wrap
