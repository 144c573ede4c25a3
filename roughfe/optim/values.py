"""The one rule of roughfe's maximisers for objective values that are not numbers: a
NaN or an infinity (alone, in a tuple, or in an array of a generation) counts as -inf,
the worst, so that it is never kept as the best and never freezes a comparison."""
from __future__ import annotations

import numpy as np


def finite_or_worst(v):
    """``v`` with every non-finite number replaced by -inf: a float for a scalar, a tuple
    for a tuple (element by element), an ndarray for an array."""
    if isinstance(v, tuple):
        return tuple(finite_or_worst(x) for x in v)
    a = np.asarray(v, dtype=float)
    out = np.where(np.isfinite(a), a, -np.inf)
    return float(out) if out.ndim == 0 else out
