"""Immutable values inside frozen dataclasses: read-only arrays, tuples, FrozenMapping.

A ``@dataclass(frozen=True)`` stops ``result.x = ...`` but not ``result.pressure[0] = 0``
or ``result.fields["points"] = None``. :func:`freeze` turns a value into an immutable one
(numpy arrays read-only in place, lists and tuples into tuples, mappings into
:class:`FrozenMapping`, recursively); :class:`Frozen` is a base class for frozen
dataclasses that freezes every field after ``__init__`` and again after unpickling
(pickle does not keep numpy's ``writeable`` flag), so results sent between processes
stay immutable.
"""
from __future__ import annotations

import dataclasses
from collections.abc import Mapping

import numpy as np


class FrozenMapping(Mapping):
    """A read-only, picklable mapping (``types.MappingProxyType`` can not be pickled)."""

    __slots__ = ("_data",)

    def __init__(self, data=()):
        object.__setattr__(self, "_data", dict(data))

    def __getitem__(self, key):
        return self._data[key]

    def __iter__(self):
        return iter(self._data)

    def __len__(self):
        return len(self._data)

    def __setattr__(self, name, value):
        raise AttributeError("FrozenMapping is read-only")

    def __reduce__(self):
        return FrozenMapping, (self._data,)

    def __repr__(self):
        return f"FrozenMapping({self._data!r})"


def freeze(value):
    """``value`` made immutable: arrays read-only (in place, not copied), lists/tuples
    tuples, mappings :class:`FrozenMapping`, recursively; other values unchanged."""
    if isinstance(value, np.ndarray):
        value.setflags(write=False)
        return value
    if isinstance(value, Mapping):
        return FrozenMapping({k: freeze(v) for k, v in value.items()})
    if isinstance(value, (list, tuple)):
        return tuple(freeze(v) for v in value)
    return value


def freeze_fields(obj) -> None:
    """Freeze every init field of the dataclass instance ``obj`` (bypassing frozen)."""
    for f in dataclasses.fields(obj):
        if f.init:
            object.__setattr__(obj, f.name, freeze(getattr(obj, f.name)))


class Frozen:
    """Base of frozen dataclasses whose fields must be deeply immutable.

    Subclasses that define ``__post_init__`` call :func:`freeze_fields` (or
    ``super().__post_init__()``) themselves.
    """

    def __post_init__(self):
        freeze_fields(self)

    def __setstate__(self, state):
        for key, value in state.items():
            object.__setattr__(self, key, value)
        freeze_fields(self)
