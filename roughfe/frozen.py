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


def _read_only(self, *args, **kwargs):
    raise TypeError(f"a {type(self).__name__} is read-only (copy it to change it)")


class FrozenMapping(dict):
    """A read-only dict: picklable and JSON-serialisable as a dict (which
    ``types.MappingProxyType`` is not); every mutating method raises ``TypeError``.
    ``dict(m)`` or ``{**m, ...}`` give a mutable copy."""

    __slots__ = ()
    __setitem__ = __delitem__ = __ior__ = _read_only
    clear = pop = popitem = setdefault = update = _read_only

    def __reduce__(self):
        return FrozenMapping, (dict(self),)

    def __repr__(self):
        return f"FrozenMapping({dict.__repr__(self)})"


class FrozenList(list):
    """A read-only list: equal to the list it holds, picklable and JSON-serialisable as
    a list; every mutating method raises ``TypeError``. ``list(x)`` gives a mutable copy."""

    __slots__ = ()
    __setitem__ = __delitem__ = __iadd__ = __imul__ = _read_only
    append = extend = insert = pop = remove = clear = sort = reverse = _read_only

    def __reduce__(self):
        return FrozenList, (list(self),)

    def __repr__(self):
        return f"FrozenList({list.__repr__(self)})"


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


def freeze_containers(obj) -> None:
    """Make the dict and list fields of the dataclass instance ``obj`` immutable (one
    level: a dict becomes a :class:`FrozenMapping`, a list a :class:`FrozenList`, both
    still equal to what they were); arrays are left as they are. For frozen results
    whose arrays their producer shares."""
    for f in dataclasses.fields(obj):
        value = getattr(obj, f.name)
        if isinstance(value, dict) and not isinstance(value, FrozenMapping):
            object.__setattr__(obj, f.name, FrozenMapping(value))
        elif isinstance(value, list) and not isinstance(value, FrozenList):
            object.__setattr__(obj, f.name, FrozenList(value))


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
