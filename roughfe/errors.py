"""All roughfe exceptions (and warnings) in one place.

Every exception is a subclass of a builtin so that callers that expect ``ValueError``
(bad input) or ``RuntimeError`` (a solver that did not converge) keep working.
"""
import operator
import sys


class RoughfeError(Exception):
    """Base class of every roughfe exception."""


class InputError(RoughfeError, ValueError):
    """Bad input: the message names the argument, the value given and what is allowed."""


class MemoryShortage(InputError):
    """An input that needs more memory than the machine that checks it has available
    (:func:`check_memory`): a fact about that machine as much as about the input. A
    study whose tasks run on other machines (a remote dask scheduler) reports it as a
    note and lets each worker check its own memory
    (:func:`roughfe.study.runner.run_study`)."""


class NoConvergenceError(RoughfeError, RuntimeError):
    """A solver stopped before meeting its tolerance.

    The message says what was reached (iterations, residual) and what was asked.
    ``result`` holds the last iterate when one is available.
    """

    def __init__(self, message, result=None):
        super().__init__(message)
        self.result = result


class FileFormatError(RoughfeError, ValueError):
    """A file could not be read or does not follow the documented format."""


class Terminated(KeyboardInterrupt):
    """The process was asked to stop by SIGTERM (``kill PID``, a batch system's time
    limit). The command line turns SIGTERM into this exception so that it stops as after
    Ctrl-C (KeyboardInterrupt, of which it is a subclass): clean-up code runs, a study's
    workers are stopped and its folder keeps ``UNFINISHED``, an output folder is left as
    after Ctrl-C (:class:`roughfe.writers.OutputFolder`), and the command exits with 143
    (128 + 15, what a shell reports for a process killed by SIGTERM) instead of 130."""


class ResolutionWarning(UserWarning):
    """The input is valid but the grid does not resolve a length the physics needs: the
    result depends on the discretisation (the message says which length, by how much,
    and what to change)."""


class TruncatedFileWarning(UserWarning):
    """An instrument file has fewer bytes than its header announces, though the heights
    were read (they lie before the cut): a truncated copy
    (:func:`roughfe.surfaces.probe.warn_if_shorter_than_announced`)."""


class WindowStiffnessWarning(RuntimeWarning):
    """The contact stiffness of a finite non-periodic window (a measured topography) is
    mostly the bulk stiffness of the loaded window (a flat-punch property of its size)
    in series with the rough interface, not a property of the roughness
    (:func:`roughfe.bem.window.window_report`)."""


class FlowImbalanceWarning(RuntimeWarning):
    """The inlet and outlet flows of a Reynolds solve differ by more than
    :data:`roughfe.leakage.reynolds.FLOW_IMBALANCE_TOL` of the leak rate. Two causes:
    the linear solver's tolerance (a relative residual leaves an imbalance of about that
    size: 2.8e-6 on a 10 x 9 random gap at the default, 4e-10 at 1e-14), and near the
    percolation threshold the drop across the boundary faces of a large open reservoir
    falling below the round-off of the pressure drop (the message names both and says
    what the leak rate rests on)."""


def _is_bool(value) -> bool:
    """True for a Python bool and for a numpy boolean (``np.True_``, a bool array), which
    ``isinstance(value, bool)`` misses and ``float()`` / ``operator.index()`` take as 1."""
    return isinstance(value, bool) or getattr(getattr(value, "dtype", None), "kind", "") == "b"


def _number(value):
    """``value``, or a TypeError for text and bools (numpy's too), which ``float()`` would
    take ("2.3" in a study spec ran, under a key of its own, beside 2.3)."""
    if isinstance(value, (str, bytes)) or _is_bool(value):
        raise TypeError(value)
    return value


def check_finite_positive(name, value):
    """Return ``float(value)`` or raise :class:`InputError` unless it is finite and > 0 (a
    number: not a string such as "2.3", not a bool)."""
    try:
        v = float(_number(value))
    except (TypeError, ValueError):
        # a Material where a modulus is asked for (persson(surface, material, p)): say how
        hint = "; pass its .E_star (Pa)" if hasattr(value, "E_star") else ""
        raise InputError(f"{name} must be a positive number, got {value!r}{hint}") from None
    if not (v > 0.0 and v < float("inf")):
        raise InputError(f"{name} must be finite and > 0, got {value!r}")
    return v


def check_finite_nonnegative(name, value):
    """Return ``float(value)`` or raise :class:`InputError` unless it is finite and >= 0 (a
    number: not a string such as "0.5", not a bool)."""
    try:
        v = float(_number(value))
    except (TypeError, ValueError):
        v = None
    if v is None or not (0.0 <= v < float("inf")):
        raise InputError(f"{name} must be a finite number >= 0, got {value!r}")
    return v


#: the ends of an interval that :func:`check_in_interval` includes, and how it is written
INTERVAL_ENDS = {"neither": "({}, {})", "left": "[{}, {})", "right": "({}, {}]",
                 "both": "[{}, {}]"}


def check_in_interval(name, value, low, high, closed="neither"):
    """Return ``float(value)`` or raise :class:`InputError` unless it lies between ``low``
    and ``high``, the ends included as ``closed`` says: ``"neither"`` (low, high),
    ``"left"`` [low, high), ``"right"`` (low, high], ``"both"`` [low, high] (a number:
    not a string, not a bool; NaN lies in no interval). The message names the value and
    the interval, the ends written as given (pass ``0, 1`` for "(0, 1]")."""
    if closed not in INTERVAL_ENDS:
        raise ValueError(f"closed must be one of {tuple(INTERVAL_ENDS)}, got {closed!r}")
    interval = INTERVAL_ENDS[closed].format(low, high)
    try:
        v = float(_number(value))
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number in {interval}, got {value!r}") from None
    above = v >= low if closed in ("left", "both") else v > low
    below = v <= high if closed in ("right", "both") else v < high
    if not (above and below):
        where = "the open interval " if closed == "neither" else ""
        raise InputError(f"{name} must lie in {where}{interval}, got {value!r}")
    return v


def check_in_open_interval(name, value, low, high):
    """Return ``float(value)`` or raise :class:`InputError` unless low < value < high (a
    number: not a string, not a bool): :func:`check_in_interval` with both ends out."""
    return check_in_interval(name, value, low, high, "neither")


# times_ratio and check_leak_scale are arithmetic, not errors: they live here because
# theory/ and leakage/ share them and theory/ may not import leakage/; the base layer
# has no numerics module to hold them (looked for in round 2, session 35: none), and one
# for two functions is not worth a module
def times_ratio(value, numerator: float, denominator: float):
    """``value * numerator / denominator`` without an intermediate overflow or underflow.

    The three are split into mantissa and binary exponent (``frexp``) and the product is
    rebuilt once (``ldexp``): finite whenever the result is, rounded as a product of three
    floats; ``inf`` or 0 only where the result itself is beyond the float range. ``value``
    may be an array.
    """
    import numpy as np          # here: importing the command line imports no numpy

    mv, ev = np.frexp(value)
    mn, en = np.frexp(float(numerator))
    md, ed = np.frexp(float(denominator))
    with np.errstate(over="ignore", under="ignore"):
        out = np.ldexp(mv * mn / md, ev + (en - ed))
    return out if np.ndim(out) else float(out)


def check_leak_scale(conductance: float, pressure_drop: float, mu: float) -> float:
    """The leak rate ``Q = C dp / mu`` (m^3/s) of a gap of conductance ``C`` (m^3, the leak
    rate at a unit drop and viscosity); :class:`InputError` when ``Q != 0`` is beyond the
    normal float range (it overflowed to a null, or underflowed to 0 or to a subnormal
    that keeps few digits), naming the range of ``dp / mu`` this gap allows. One rule for
    every leak rate linear in ``dp / mu``: the Reynolds solves
    (:mod:`roughfe.leakage.reynolds`, the coupled one of :mod:`roughfe.leakage.fsi`), the
    critical junction of a gap field and Lorenz & Persson's (:mod:`roughfe.theory.junction`).
    """
    q = times_ratio(conductance, pressure_drop, mu)
    tiny, top = sys.float_info.min, sys.float_info.max
    if conductance > 0 and pressure_drop != 0 and not (tiny <= abs(q) <= top):
        c = float(conductance)                                # Python floats: no warning
        low, high = tiny / c, top / c                         # high: inf for C < 1
        allowed = (f"from {low:.3g} to {high:.3g} 1/s" if high < float("inf")
                   else f"from {low:.3g} 1/s up")
        raise InputError(
            f"pressure_drop = {pressure_drop:g} Pa with mu = {mu:g} Pa s: the leak rate "
            f"Q = C dp / mu (C = {conductance:.4g} m^3, this gap's leak rate at a unit drop "
            f"and viscosity) {'overflows' if abs(q) > 1 else 'underflows'} the float range; "
            f"this gap allows dp / mu {allowed}")
    return q


def check_bool(name, value) -> bool:
    """Return ``value`` as a bool or raise :class:`InputError` unless it is one: a Python
    or numpy bool, or the integer 1 or 0 (one element of an array too). Text such as
    ``"no"`` and numbers such as 0.5 were read by their truthiness, ``"no"`` as True
    (round 2, session 37)."""
    import numpy as np          # here: importing the command line imports no numpy

    a = np.asarray(value) if not isinstance(value, (str, bytes)) else None
    if a is not None and a.size == 1 and (
            a.dtype == bool or (a.dtype.kind in "iu" and a.item() in (0, 1))):
        return bool(a.item())
    raise InputError(f"{name} must be a bool, True or False (or the integer 1 or 0), "
                     f"got {value!r}")


def check_int(name, value, minimum):
    """Return ``int(value)`` or raise :class:`InputError` unless it is an integer (a Python
    or numpy integer, not a bool, numpy's included, and not a float such as 3.5 or 4.0)
    >= ``minimum``."""
    try:
        v = None if _is_bool(value) else operator.index(value)
    except TypeError:
        v = None
    if v is None or v < minimum:
        raise InputError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return v


def check_spacing(spacing, ndim=2):
    """Return the cell size ``(dx, dy)`` (``ndim`` finite, positive floats, m) or raise
    :class:`InputError` naming what is wrong (a bare number, the wrong length, a string)."""
    try:
        values = tuple(spacing)
    except TypeError:
        values = None
    if values is None or len(values) != ndim:
        names = "(dx, dy)" if ndim == 2 else f"{ndim} numbers"
        raise InputError(f"spacing must be the cell size {names} in m, got {spacing!r}")
    return tuple(check_finite_positive(f"spacing[{k}] (m)", v) for k, v in enumerate(values))


def check_real_array(name, value, ndim=None, unit="m", allow_nan=False):
    """Return ``value`` as a float ndarray (not copied when it already is one) or raise
    :class:`InputError` naming what is wrong: complex or non-numeric entries, a number of
    axes not in ``ndim`` (an int or a tuple of ints; None: any), non-finite entries
    (their count and the first one's index; with ``allow_nan`` NaN is allowed, where the
    caller documents it as "no value", and only infinities are refused), masked entries
    (the values under a mask are not data)."""
    import numpy as np

    if np.ma.isMaskedArray(value) and np.ma.getmaskarray(value).any():
        # np.asarray would keep the values under the mask (a topography's undefined points)
        raise InputError(
            f"{name} is a masked array with {int(np.ma.getmaskarray(value).sum())} masked "
            f"(undefined) point(s), first at index "
            f"{tuple(int(i) for i in np.argwhere(np.ma.getmaskarray(value))[0])}; fill them "
            f"first (load_surface interpolates a file's undefined points)")
    if np.ma.isMaskedArray(value):
        value = np.ma.getdata(value)
    if np.iscomplexobj(value):     # np.asarray(..., float) would drop the imaginary part
        raise InputError(f"{name} must be real numbers ({unit}), got a complex array")
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a numeric array ({unit}), "
                         f"got {type(value).__name__}") from None
    allowed = (ndim,) if isinstance(ndim, int) else ndim
    if allowed is not None and a.ndim not in allowed:
        axes = " or ".join(f"{k}D" for k in allowed)
        raise InputError(f"{name} must be a {axes} array, got shape {a.shape}")
    bad = np.isinf(a) if allow_nan else ~np.isfinite(a)
    if bad.any():
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        raise InputError(f"{name} must be finite: {int(bad.sum())} non-finite value(s), "
                         f"first at index {idx} = {a[idx]!r}")
    return a


def available_memory() -> int:
    """Bytes of memory this process may still use: ``MemAvailable`` on Linux, else the
    physical memory."""
    import os

    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")


def check_memory(what: str, n_bytes: float) -> None:
    """Raise :class:`MemoryShortage` (an :class:`InputError`) when ``what`` needs more
    than the available memory.

    The message gives both in GiB, e.g. "a 100000 x 100000 grid needs 74.5 GiB of
    memory, 21.3 GiB are available".
    """
    free = available_memory()
    if n_bytes > free:
        gib = 2.0 ** 30
        raise MemoryShortage(f"{what} needs {n_bytes / gib:.1f} GiB of memory, "
                             f"{free / gib:.1f} GiB are available")


def check_instance(name, value, cls, what):
    """Return ``value`` or raise :class:`InputError` (``"NAME must be WHAT, got TYPE"``)
    unless it is an instance of ``cls``."""
    if not isinstance(value, cls):
        raise InputError(f"{name} must be {what}, got {type(value).__name__}")
    return value
