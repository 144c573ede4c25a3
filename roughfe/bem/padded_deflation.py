"""The two-level correction of a non-periodic BEM solve (issue 16, ``docs/theory/02b``,
session 16): the block deflation of the periodic solver, on the operator's padded torus.

A non-periodic operator (Love's rectangles, the thesis kernel) is applied as a circulant
on a zero-padded grid (DC-FFT, :mod:`roughfe.bem.operators`): the surface's n0 x n1
points are one corner of a torus of P0 x P1 points, P >= 2n - 1 per axis, whose kernel
at the offset d is the half-space kernel at the periodic-image distance min(|d|, P - |d|).
Two surface points are at most n - 1 < P / 2 apart, so between them the torus kernel *is*
the half-space kernel. The non-periodic contact problem is therefore the periodic one on
the torus with every point off the surface held at p = 0: never in the free set F.
:class:`~roughfe.bem.deflation.BlockDeflation` works on F alone (its near field on the
blocks' parts of F, its far field weighted by the blocks' fill fractions), so it applies
unchanged on the torus: the blocks off the surface are empty and take no part.

The torus of the correction has P = 8 fast_length(ceil((2n - 1) / 8)) points per axis:
whole 8 x 8 blocks, and a coarse grid of P / 8 points whose FFTs are fast (the operator's
own padded grid, fast_length(2n - 1), need not be a multiple of 8; a coarse side of 257,
a prime, cost 3x in the coarse CG). Its kernel is the operator's padded kernel at the
periodic-image offsets, clamped to the offsets that grid holds (the few extra middle
offsets never couple two surface points).
"""
from __future__ import annotations

import functools

import numpy as np
import scipy.fft

from ..errors import InputError
from .deflation import BlockDeflation
from .operators import WORKERS, InfluenceOperator, fast_length


def torus_shape(shape, block: int = 8) -> tuple:
    """Points per axis of the correction's torus for a non-periodic grid ``shape``: the
    multiple of ``block`` >= 2n - 1 whose quotient is a fast FFT length."""
    return tuple(block * fast_length(-(-(2 * int(n) - 1) // block)) for n in shape)


@functools.lru_cache(maxsize=4)
def _torus_operator(op: InfluenceOperator, block: int) -> InfluenceOperator:
    """The periodic operator on the torus of ``op`` (non-periodic, 2D): its padded kernel
    laid out at the periodic-image offsets of :func:`torus_shape`."""
    torus = torus_shape(op.shape, block)
    kern = op.circulant_kernel(torus)
    spectrum = np.ascontiguousarray(scipy.fft.rfftn(kern, workers=WORKERS).real)  # even
    return InfluenceOperator(op.name, torus, op.spacing, True, op.e_star, spectrum)


class PaddedBlockDeflation:
    """:class:`~roughfe.bem.deflation.BlockDeflation` of a non-periodic operator, on its
    padded torus (module docstring): the interface of ``polonsky_keer(deflation=)``.

    Measured (``benchmarks/bench_bem_nonperiodic.py``, 6-load sweeps p/E* h'_rms =
    0.005-0.2, tol 1e-10, against the plain solver without the coarse start; 02b,
    session 16): RMD 513^2 281 -> 132 iterations, 1.15x less CPU; RMD 1025^2 381 -> 148,
    1.61x; RMD 2049^2 (one load) 98 -> 29, 1.96x; the measured files 1.1-1.5x; the same
    contact sets. RMD 257^2 is dearer with it (0.75 -> 0.95 s): the automatic range,
    ``roughfe.bem.contact.DEFLATION_SIDES``, starts at an FFT grid of 1024^2 points.
    """

    def __init__(self, op: InfluenceOperator, block: int = 8, **options):
        if op.periodic or len(op.shape) != 2:
            raise InputError(f"PaddedBlockDeflation is for a non-periodic 2D operator, got "
                             f"{'a periodic' if op.periodic else 'a profile'} one "
                             f"({op.name}, shape {op.shape}); use BlockDeflation")
        self.shape = op.shape
        self.torus = torus_shape(op.shape, block)
        self._inner = BlockDeflation(_torus_operator(op, int(block)), block, **options)

    @property
    def zero_mean(self) -> bool:
        """Load control (True) or displacement control (as BlockDeflation's)."""
        return self._inner.zero_mean

    @property
    def inner_iterations(self) -> list:
        """Coarse CG iterations of each correction (as BlockDeflation's)."""
        return self._inner.inner_iterations

    def _embed(self, mask):
        """A grid mask (bool, the surface's shape or flat) on the torus: False off it."""
        n0, n1 = self.shape
        out = np.zeros(self.torus, bool)
        out[:n0, :n1] = np.asarray(mask).reshape(n0, n1)
        return out.reshape(-1)

    def correct(self, F, gF, zF, apply_free, free_mask=None, pressure=None):
        """BlockDeflation's direction with F (flat indices of the surface's grid) mapped
        to the torus; the values on F keep their order (the map is increasing)."""
        n1 = self.shape[1]
        i, j = np.divmod(F, n1)
        i *= self.torus[1]
        i += j
        del j
        return self._inner.correct(
            i, gF, zF, apply_free,
            free_mask=None if free_mask is None else self._embed(free_mask),
            pressure=None if pressure is None else self._embed(np.greater(pressure, 0.0)))
