"""The coarse space of the two-level BEM correction (issue 16 §1,
``docs/theory/02b_bem_performance.md``): b x b block aggregates Z of a periodic 2D grid,
their Galerkin matrix Z^T H Z for full blocks (m/Pa, a circulant on the coarse grid), the
periodic kernel G at a window of offsets, the restriction Z^T on a free set and the A-DEF2
direction. Pure functions on numpy arrays, used by :mod:`roughfe.bem.deflation`.
"""
from __future__ import annotations

import numpy as np
import scipy.fft

from ..errors import InputError
from .operators import InfluenceOperator


def _check_grid(op: InfluenceOperator, block: int, min_blocks: int = 1) -> None:
    """A periodic 2D grid whose sides are multiples of ``block`` (>= ``min_blocks``
    blocks per side), else a one-line InputError."""
    if (not op.periodic or len(op.shape) != 2 or block < 1
            or any(n % block for n in op.shape) or min(op.shape) < min_blocks * block):
        least = f" with at least {min_blocks} blocks per side" if min_blocks > 1 else ""
        raise InputError(f"block deflation needs a periodic 2D grid whose sides are "
                         f"multiples of block = {block}{least}, got shape {op.shape}")


def _fejer(n: int, block: int) -> np.ndarray:
    """|sum_{a < block} exp(2 pi i k a / n)|^2 for k = 0 .. n - 1: the squared Fourier
    transform of a block's indicator along one axis."""
    k = np.arange(n)
    with np.errstate(divide="ignore", invalid="ignore"):
        w = (np.sin(np.pi * block * k / n) / np.sin(np.pi * k / n)) ** 2
    w[0] = block * block
    return w


def _full_block_galerkin(op: InfluenceOperator, block: int) -> np.ndarray:
    """K, the Galerkin matrix of full b x b blocks (m/Pa summed over block pairs), a
    circulant on the coarse grid: H applied to the indicator of block 0, summed over
    every block; K[d] couples blocks d apart.

    Built from the half spectrum without a full grid: in Fourier space K is the fine
    spectrum times the blocks' squared transform |B(k)|^2, summed over the aliases k of
    each coarse wavevector (k = kappa mod the coarse grid) and divided by b^2; the
    columns k1 > n1 / 2 of the full spectrum are conj(spectrum[-k0, n1 - k1])."""
    n0, n1 = op.shape
    m0, m1 = n0 // block, n1 // block
    spec = op.spectrum
    half = spec.shape[1]
    w0 = _fejer(n0, block)
    s = np.zeros((m0, half), spec.dtype)
    for rows in range(0, n0, m0):                   # the aliases k0 = kappa0 + l m0
        s += w0[rows:rows + m0, None] * spec[rows:rows + m0]
    full = np.empty((m0, n1), s.dtype)
    full[:, :half] = s
    full[:, half:] = np.conj(s[(-np.arange(m0)) % m0][:, n1 - np.arange(half, n1)])
    full *= _fejer(n1, block)
    khat = full.reshape(m0, block, m1).sum(axis=1) / float(block * block)
    return np.fft.ifft2(khat).real


def _kernel_window(op: InfluenceOperator, rows, cols) -> np.ndarray:
    """The periodic real-space kernel G (m/Pa) at the offsets ``rows`` x ``cols`` (grid
    points, any sign), from the half spectrum without a full grid: the inverse DFT
    along axis 0 at ``rows`` only (real matrix products with the spectrum), then an
    inverse real FFT along axis 1."""
    n0, n1 = op.shape
    rows = np.asarray(rows) % n0
    phase = (2.0 * np.pi / n0) * ((rows[:, None] * np.arange(n0)[None, :]) % n0)
    spec = op.spectrum
    part = np.cos(phase) @ spec + 1j * (np.sin(phase) @ spec)
    return scipy.fft.irfft(part / n0, n=n1, axis=1)[:, np.asarray(cols) % n1]


#: grid points per pass over the free set in the coarse correction (whole block rows;
#: bounds the index temporaries to ~8 MB, so that no F-sized integer array is made)
_POINTS = 1 << 20


def _chunks(F, shape, block):
    """Passes over the flat free set ``F`` (sorted, as ``flatnonzero`` gives) by runs of
    whole block rows of about ``_POINTS`` grid points: (slice of F, first grid row, the
    run's first and end coarse-block index). Every block's points lie in one slice."""
    n0, n1 = shape
    m1 = n1 // block
    rows = block * max(1, _POINTS // (block * n1))
    starts = np.arange(0, n0, rows)
    ends = np.searchsorted(F, np.append(starts[1:], n0) * n1)
    begin = 0
    for r0, end in zip(starts.tolist(), ends.tolist()):
        yield slice(begin, end), r0, r0 // block * m1, min(r0 + rows, n0) // block * m1
        begin = end


def _block_index(Fc, r0, shape, block):
    """Flat coarse-block index of the flat grid indices ``Fc`` (one pass of
    :func:`_chunks` from grid row ``r0``), relative to the pass's first block."""
    i, j = np.divmod(Fc - r0 * shape[1], shape[1])
    i //= block
    i *= shape[1] // block
    j //= block
    i += j
    return i


def _restrict(F, s, shape, block):
    """Z^T s: the sums of ``s`` (values on F) over each b x b block (flat coarse)."""
    out = np.zeros((shape[0] // block) * (shape[1] // block))
    for sl, r0, lo, hi in _chunks(F, shape, block):
        out[lo:hi] = np.bincount(_block_index(F[sl], r0, shape, block), weights=s[sl],
                                 minlength=hi - lo)
    return out


def _a_def2(F, gF, zF, apply_free, shape, block, coarse_solve, zero_mean=True):
    """The A-DEF2 direction z_F + Z c, c = coarse_solve(Z^T (g - H_FF z)), in the
    zero-mean subspace of F (load control; ``zero_mean`` False: on all of F, displacement
    control) (``coarse_solve`` maps flat coarse right-hand sides to flat coarse
    solutions); written over the vector of the right-hand side."""
    s = gF - apply_free(zF)
    if zero_mean:
        s -= s.mean()
    c = coarse_solve(_restrict(F, s, shape, block))
    for sl, r0, lo, hi in _chunks(F, shape, block):
        np.add(zF[sl], c[lo:hi][_block_index(F[sl], r0, shape, block)], out=s[sl])
    if zero_mean:
        s -= s.mean()
    return s
