"""All roughfe exceptions in one place.

Every exception is a subclass of a builtin so that callers that expect ``ValueError``
(bad input) or ``RuntimeError`` (a solver that did not converge) keep working.
"""


class RoughfeError(Exception):
    """Base class of every roughfe exception."""


class InputError(RoughfeError, ValueError):
    """Bad input: the message names the argument, the value given and what is allowed."""


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


def check_finite_positive(name, value):
    """Return ``float(value)`` or raise :class:`InputError` unless it is finite and > 0."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a positive number, got {value!r}") from None
    if not (v > 0.0 and v < float("inf")):
        raise InputError(f"{name} must be finite and > 0, got {value!r}")
    return v


def check_in_open_interval(name, value, low, high):
    """Return ``float(value)`` or raise :class:`InputError` unless low < value < high."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number in ({low}, {high}), got {value!r}") from None
    if not (low < v < high):
        raise InputError(f"{name} must lie in the open interval ({low}, {high}), got {value!r}")
    return v
