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


def read_only_arrays(obj, copy: bool = False) -> None:
    """Make every numpy array field of the dataclass instance ``obj`` read-only, copying
    it first when ``copy`` (for arrays the producer or the caller may still write to);
    containers and other values are left as they are (unlike :func:`freeze_fields`)."""
    for f in dataclasses.fields(obj):
        value = getattr(obj, f.name)
        if isinstance(value, np.ndarray):
            if copy:
                value = value.copy()
                object.__setattr__(obj, f.name, value)
            value.setflags(write=False)


class ReadOnlyArrays:
    """Base of frozen dataclasses whose array fields stay read-only after unpickling
    (pickle does not keep numpy's ``writeable`` flag), their containers untouched."""

    def __setstate__(self, state):
        for key, value in state.items():
            object.__setattr__(self, key, value)
        read_only_arrays(self)


def compact_repr(self) -> str:
    """A one-line ``__repr__`` for a result dataclass (assign ``__repr__ = compact_repr``
    in the class): arrays as ``array(shape, dtype)``, 1D arrays of at most 10 values (the
    steps of a sweep) by their values, sequences of arrays or results by their length
    and type, mappings of arrays or results by their keys and value types, other fields
    as usual; optional fields left at None and fields with ``repr=False`` are left out.
    (The dataclass repr printed every array: 3-18 kB for one 128^2 contact or leakage
    result, 83 kB for a sequencing result.)"""
    parts = []
    for f in dataclasses.fields(self):
        if not f.repr:
            continue
        v = getattr(self, f.name)
        if v is None and f.default is None:        # an optional field not computed
            continue
        if isinstance(v, np.ndarray) and v.ndim == 1 and v.size <= 10:   # per-step values
            text = "array(" + np.array2string(v, precision=4, separator=", ",
                                              max_line_width=10 ** 6) + ")"
        elif isinstance(v, np.ndarray):
            text = f"array(shape={v.shape}, dtype={v.dtype})"
        elif isinstance(v, (tuple, list)) and v and (isinstance(v[0], np.ndarray)
                                                     or dataclasses.is_dataclass(v[0])):
            text = f"<{len(v)} x {type(v[0]).__name__}>"
        elif isinstance(v, Mapping) and any(isinstance(x, np.ndarray)
                                            or dataclasses.is_dataclass(x) for x in v.values()):
            text = "{" + ", ".join(f"{k!r}: <{type(x).__name__}>" for k, x in v.items()) + "}"
        else:
            text = repr(v)
        parts.append(f"{f.name}={text}")
    return f"{type(self).__name__}({', '.join(parts)})"

