"""The same surface on a finer grid: band-limited (Fourier) refinement.

:func:`refined` gives the trigonometric interpolant of the samples, the one surface of
wavenumbers up to the grid's Nyquist wavenumber that passes through them, sampled ``f``
times finer per axis: no new roughness is made (the PSD below the original Nyquist
wavenumber is the original's, zero above). It is the tool of the grid check
(:mod:`roughfe.bem.grid_check`, ``roughfe contact --grid-check``): a contact quantity that
changes when the same surface is solved on a finer grid carries the grid's
discretisation error (docs/theory/02, "Discretisation error at a fixed surface").

* periodic: each axis' discrete spectrum is kept, zero-padded, and its Nyquist
  coefficient (even ``n``) split evenly between ``+-n/2`` (a cosine, the real
  interpolant; :meth:`Surface.resampled` drops it, which changes the samples): the
  refined grid holds the original samples exactly at every ``f``-th point.
* non-periodic (a measured window): the window is evenly mirrored first
  (:meth:`Surface.mirrored`, period ``2 (n - 1) dx``; a plain periodic wrap would add
  the edge step as roughness) and the interpolant is sampled at the centres of the
  ``f`` sub-cells of every original cell, so the refined window covers the same
  footprint ``[-dx/2, (n - 1/2) dx)`` per axis (same size, same nominal area). Edge
  effect: the mirror image has a kink (the slope reverses) at the window's edges, which
  the band-limited interpolant rounds, with an error decaying like 1 / distance: on a
  tilted plane (the worst case, the kink is its whole slope) 0.34 slope dx in the edge
  sub-cells, 0.10 one cell in, 0.03 four cells in, 0.015 eight cells in
  (tests/test_grid_check.py); on a rough window only the slope of the roughness at
  the edge enters, and the contact changes it measured (docs/theory/02) are those of
  the interior as much as of the edges.
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError, check_int
from .surface import Surface


def _interpolate_axis(h, axis, factor, shift):
    """Trigonometric interpolant of ``h`` (periodic along ``axis``, ``n`` samples)
    sampled at ``j / factor + shift`` (in units of the spacing), ``j = 0..n factor - 1``."""
    n = h.shape[axis]
    spec = np.fft.fft(h, axis=axis)
    m = n * factor
    out_shape = list(h.shape)
    out_shape[axis] = m
    out = np.zeros(out_shape, complex)
    half = (n - 1) // 2                      # the modes +-1..half: both grids carry them

    def put(dst, src, scale=1.0):
        out[(slice(None),) * axis + (dst,)] += scale * spec[(slice(None),) * axis + (src,)]

    put(slice(0, half + 1), slice(0, half + 1))
    if half:
        put(slice(m - half, m), slice(n - half, n))
    if n % 2 == 0:                           # the Nyquist cosine, split between +-n/2
        put(n // 2, n // 2, 0.5)
        put(m - n // 2, n // 2, 0.5)
    if shift:
        k = np.fft.fftfreq(m, d=1.0 / m)       # integer wavenumbers of the new grid
        phase = np.exp(2j * np.pi * k * shift / n)
        out *= phase.reshape([-1 if a == axis else 1 for a in range(h.ndim)])
    return np.fft.ifft(out, axis=axis).real * factor


def refined(surface: Surface, factor: int) -> Surface:
    """The band-limited refinement of ``surface``, ``factor`` times finer per axis
    (module docstring): the same size, ``factor * n`` points per axis, spacing
    ``dx / factor``; periodic surfaces keep their samples at every ``factor``-th point,
    non-periodic windows are refined through their even mirror image and keep their
    footprint. Metadata ``refined_from`` (the old shape) and ``refined_factor``.

    ``factor`` is an integer >= 1 (1 returns the surface unchanged)."""
    if not isinstance(surface, Surface):
        raise InputError(f"refined() takes a roughfe Surface, got {type(surface).__name__}")
    factor = check_int("refinement factor (an integer >= 1: points per old spacing)",
                       factor, 1)
    if factor == 1:
        return surface
    n_in = surface.shape
    if surface.periodic:
        h = surface.heights
        for axis in range(h.ndim):
            h = _interpolate_axis(h, axis, factor, 0.0)
    else:
        h = surface.mirrored().heights
        # sub-cell centres of the original cells: (j + 1/2)/f - 1/2 spacings from sample 0
        shift = -(factor - 1) / (2.0 * factor)
        for axis in range(h.ndim):
            h = _interpolate_axis(h, axis, factor, shift)
        h = h[tuple(slice(0, n * factor) for n in n_in)]
    return Surface(h, surface.size, surface.periodic,
                   {**surface.metadata, "refined_from": list(n_in), "refined_factor": factor})
