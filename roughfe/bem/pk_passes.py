"""The full-grid passes of the Polonsky-Keer iteration (:mod:`roughfe.bem.pk`): the
Euclidean projection on the load, the threaded axpy, the gap u - b tested, reduced and
gathered in cache-sized chunks without a full-grid temporary (measured in
``docs/theory/02b_bem_performance.md``, sessions 4 and 11), and the increment of a moving
load put onto the contact set (:func:`_load_increment`, session 17)."""
from __future__ import annotations

import numpy as np
from scipy.linalg.blas import daxpy, saxpy

from . import _parallel as par
from .solvers import _rescale_to_load


def _shift_to_load(x, target_sum, upper):
    """Euclidean projection of ``x`` (in place) on {0 <= x <= upper, sum(x) = target_sum}:
    x <- clip(x + lam, 0, upper) with the shift lam found by safeguarded Newton steps on
    the monotone, piecewise linear sum (bisection when a step leaves the bracket).
    Returns False (x unchanged) when even x = upper everywhere is below the target."""
    if x.size * upper < target_sum:
        return False
    lo, hi = -float(x.max()), upper - float(x.min())
    lam = 0.0
    y = np.empty_like(x)
    for _ in range(200):
        np.add(x, lam, out=y)
        np.clip(y, 0.0, upper, out=y)
        f = float(y.sum()) - target_sum
        if abs(f) <= 1e-15 * target_sum or hi - lo <= 1e-16 * max(abs(lo), abs(hi)):
            break
        if f < 0:
            lo = lam
        else:
            hi = lam
        slope = int(np.count_nonzero((y > 0.0) & (y < upper)))
        step = lam - f / slope if slope else np.nan
        lam = step if lo < step < hi else 0.5 * (lo + hi)
    x[...] = y
    return True


#: elements per chunk of :func:`_axpy`'s float32 -> float64 cast (128 kB: in cache)
_CHUNK = 1 << 14


def _axpy(u, a, r):
    """``u += a r`` over the threads without a full-grid temporary: one BLAS axpy per
    block when ``u`` and ``r`` have the same dtype; a float32 ``r`` onto a float64 ``u``
    (the single-precision increments of the double-precision phase) is cast in
    cache-sized chunks, each then added by ``daxpy`` (measured at 2048^2: 4.8 ms CPU
    against 4.7 ms for a float64 ``r``)."""
    if u.dtype == r.dtype:
        axpy = saxpy if u.dtype == np.float32 else daxpy
        par.blocks(u.size, lambda i, j: axpy(r[i:j], u[i:j], a=a))
        return

    def one(i, j):
        buf = np.empty(min(_CHUNK, j - i))
        for k in range(i, j, _CHUNK):
            e = min(j, k + _CHUNK)
            c = buf[:e - k]
            c[...] = r[k:e]
            daxpy(c, u[k:e], a=a)

    par.blocks(u.size, one)


#: elements per chunk of :func:`_gap_mask`'s gap (512 kB of float64: in cache)
_GAP_CHUNK = 1 << 16


def _gap_into(u, us, b, out):
    """``out = us u - b`` (float64 out of a float32 or float64 ``u``); returns ``out``."""
    if us != 1.0:
        np.multiply(u, us, out=out)
        out -= b
    else:
        np.subtract(u, b, out=out)
    return out


def _gap_mask(u, us, b, d, mask, i, j):
    """``mask = (us u - b < d)`` on the block ``[i, j)`` (the free-set test), the gap
    ``us u - b`` computed in cache-sized chunks and never stored; returns the block's
    minimum of it (the largest penetration). One pass over u and b, where a stored gap
    took two and a full-grid float64 array (session 11)."""
    buf = np.empty(min(_GAP_CHUNK, j - i))
    low = np.inf
    for k in range(i, j, _GAP_CHUNK):
        e = min(j, k + _GAP_CHUNK)
        c = _gap_into(u[k:e], us, b[k:e], buf[:e - k])
        low = min(low, float(c.min()))
        np.less(c, d, out=mask[k:e])
    return low


def _gap_take(u, us, b, index):
    """The gap ``us u - b`` (float64, the values :func:`_gap_mask` tests) at the flat
    ``index``, gathered in parallel in cache-sized chunks."""
    out = np.empty(index.size)

    def one(i, j):
        for c in range(i, j, _GAP_CHUNK):     # cache-sized gathers, no index-sized ones
            e = min(j, c + _GAP_CHUNK)
            k = index[c:e]
            _gap_into(u.take(k, mode="wrap"), us, b.take(k, mode="wrap"), out[c:e])

    par.blocks(index.size, one)
    return out


def _positive_at(p, index):
    """``p[index] > 0`` (bool) in parallel, gathered in cache-sized chunks (no
    index-sized float temporary)."""
    out = np.empty(index.size, bool)

    def one(i, j):
        for k in range(i, j, _GAP_CHUNK):
            e = min(j, k + _GAP_CHUNK)
            np.greater(p.take(index[k:e], mode="wrap"), 0.0, out=out[k:e])

    par.blocks(index.size, one)
    return out


def _load_increment(p, S, extra, precond, buf, target):
    """Add the load ``extra`` (Pa summed over the grid) to ``p`` (flat, in place) on the
    contact set ``S`` (flat indices) in the shape of ``precond`` (M) applied to S's
    indicator, clipped at 0 (M 1_S is the pressure of a uniform displacement of S where
    the rest of the grid were free: a cheap stand-in for the exact rate of
    :func:`roughfe.bem.stiffness.unit_load_rate`), then clip p at 0 and rescale it to
    ``target``. ``buf`` (float32, flat) is M's input and is left zero. Returns False
    (``p`` untouched) when M 1_S has no positive part on S."""
    buf.fill(0.0)
    par.put(buf, S, 1.0)
    y = np.maximum(par.take(precond(buf), S), 0.0).astype(float)
    buf.fill(0.0)
    total = float(y.sum())
    if not total > 0:
        return False
    y *= extra / total
    y += par.take(p, S)
    np.maximum(y, 0.0, out=y)
    par.put(p, S, y)
    _rescale_to_load(p, target, np.inf)
    return True
