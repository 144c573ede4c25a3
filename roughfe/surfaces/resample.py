"""The same surface on another grid: the band-limited (Fourier) interpolant.

One routine, :func:`_interpolate_axis`, evaluates the trigonometric interpolant of the
samples along one axis on another grid of the same period; :func:`resampled` (any shape,
:meth:`Surface.resampled`) and :func:`refined` (an integer factor, the grid check) are
both made of it. The interpolant is the one surface of wavenumbers up to the grid's
Nyquist wavenumber that passes through the samples: no new roughness is made (the PSD
below the coarser grid's Nyquist wavenumber is the original's, zero above). It is the tool
of the grid check (:mod:`roughfe.bem.grid_check`, ``roughfe contact --grid-check``): a
contact quantity that changes when the same surface is solved on a finer grid carries the
grid's discretisation error (docs/theory/02, "Discretisation error at a fixed surface").

The Nyquist mode. On ``n`` points (even) the wavenumber ``n/2`` has one real coefficient
``c``: the samples see it as ``c (-1)^j``, the value of the cosine ``c cos(pi x / dx)``
(the real interpolant; a sine there vanishes at every sample). On a grid of ``m`` points:

* ``m > n`` (refinement): ``c`` is split evenly between ``+-n/2`` (the cosine), so the new
  grid holds the old samples exactly where the nodes coincide, and resampling back to
  ``n`` points is the identity. The mean square height of the new samples is that of the
  continuous interpolant, the same at every ``m > n``: it counts the Nyquist cosine at
  ``c^2/2`` (its mean square between the nodes), where the old samples, all at its crests,
  counted ``c^2``. Dropping the mode (:meth:`Surface.resampled` until round 2, session
  34) lost all of ``c^2`` and changed every sample
  (docs/guide/03_changes_to_numbers.md).
* ``m < n``, ``m`` even (coarsening): the new Nyquist mode ``m/2`` receives the sum of the
  old ``+-m/2`` coefficients (``2 Re c_{m/2}``, the cosine part of that wave, which is what
  the new nodes see of it; its sine part vanishes there). Waves beyond ``m/2`` are
  removed, instead of being aliased as thinning the samples would. Refining and then
  coarsening back is the identity.
* ``m = n``: the identity.

This is the rule of ``scipy.signal.resample`` (split on up-, join on downsampling).

* periodic: each axis is interpolated in turn (the interpolant is separable).
* non-periodic (a measured window, :func:`refined` only): the window is evenly mirrored
  first (:meth:`Surface.mirrored`, period ``2 (n - 1) dx``; a plain periodic wrap would add
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

from ..errors import InputError, check_int, check_memory
from .surface import Surface

#: bytes per point of the largest grid an axis pass of :func:`_interpolate_axis` holds:
#: the spectrum of its input and the complex output (16 each), the inverse transform
#: (16) and its real part times m/n (8 + 8), rounded up to 64 for numpy's temporaries
RESAMPLE_BYTES_PER_POINT = 64


def _check_resample_memory(old, new) -> None:
    """Refuse (:class:`InputError`, before any allocation) a resampling from the grid
    ``old`` to ``new`` (points per axis) whose axis passes need more than the available
    memory. An axis pass holds the grid that has the new size along the axes already done
    and the larger of the two along the current one; the last is the largest, bounded by
    the larger of the two sizes per axis. ``design --match-spectrum`` onto a database of
    7.8 nm spacing took x3p-2's mirrored 166 x 409 um window towards 2.1e4 x 5.2e4 points
    and about 80 GB, and hung until stopped (round 2, session 37)."""
    points = float(np.prod([max(a, b) for a, b in zip(old, new)]))
    check_memory(f"resampling a {' x '.join(map(str, old))} grid onto "
                 f"{' x '.join(map(str, new))} points", points * RESAMPLE_BYTES_PER_POINT)


def _interpolate_axis(h, axis, m, shift=0.0):
    """The trigonometric interpolant of ``h`` (periodic along ``axis``, ``n`` samples)
    sampled at the ``m`` points ``j n / m + shift`` (``j = 0..m-1``, in units of the old
    spacing): the discrete spectrum kept for the wavenumbers both grids resolve, the
    Nyquist mode by the rule of the module docstring (split between ``+-n/2`` when
    ``m > n``, ``+-m/2`` joined when ``m < n``), zero beyond. Real in, real out."""
    n = h.shape[axis]
    if m == n and not shift:
        return h
    spec = np.fft.fft(h, axis=axis)
    out_shape = list(h.shape)
    out_shape[axis] = m
    out = np.zeros(out_shape, complex)
    low = min(n, m)
    half = (low - 1) // 2                    # the modes +-1..half: both grids carry them

    def put(dst, src, scale=1.0):
        out[(slice(None),) * axis + (dst,)] += scale * spec[(slice(None),) * axis + (src,)]

    put(slice(0, half + 1), slice(0, half + 1))
    if half:
        put(slice(m - half, m), slice(n - half, n))
    if low % 2 == 0:
        k = low // 2
        if m > n:                            # the old Nyquist cosine, split between +-n/2
            put(k, k, 0.5)
            put(m - k, k, 0.5)
        else:                                # +-m/2 of the old grid joined at the new m/2
            put(k, k)
            if m < n:
                put(k, n - k)
    if shift:
        q = np.fft.fftfreq(m, d=1.0 / m)     # integer wavenumbers of the new grid
        phase = np.exp(2j * np.pi * q * shift / n)
        out *= phase.reshape([-1 if a == axis else 1 for a in range(h.ndim)])
    return np.fft.ifft(out, axis=axis).real * (m / n)


def resampled(surface: Surface, shape) -> Surface:
    """The band-limited Fourier interpolant of a periodic ``surface`` on another grid of
    the same size, ``shape`` points per axis (integers >= 2; a profile takes one).

    Per axis, the wavenumbers both grids resolve are kept, those beyond the coarser
    grid's Nyquist wavenumber removed (coarsening low-passes instead of aliasing), and the
    Nyquist mode follows the rule of the module docstring: on refinement the old samples
    are kept where the nodes coincide (the rms height is that of the continuous
    interpolant, the same at every finer grid); the mean height is kept exactly in every
    case. Metadata ``resampled_from`` (the old shape)."""
    if not isinstance(surface, Surface):
        raise InputError(f"resampled() takes a roughfe Surface, got {type(surface).__name__}")
    if not surface.periodic:
        raise InputError("resampled() is the Fourier interpolant of a periodic surface; "
                         "mirror a non-periodic window first (Surface.mirrored)")
    given = (shape,) if np.ndim(shape) == 0 else tuple(shape)
    if len(given) != surface.ndim:
        raise InputError(f"resampled shape must have {surface.ndim} entries >= 2, "
                         f"got {shape}")
    shape = tuple(check_int(f"resampled shape[{k}] (points along axis {k})", m, 2)
                  for k, m in enumerate(given))
    _check_resample_memory(surface.shape, shape)
    h = surface.heights
    for axis, m in enumerate(shape):
        h = _interpolate_axis(h, axis, m)
    return Surface(h, surface.size, periodic=True,
                   metadata={**surface.metadata, "resampled_from": list(surface.shape)})


def refined(surface: Surface, factor: int) -> Surface:
    """The band-limited refinement of ``surface``, ``factor`` times finer per axis
    (module docstring): the same size, ``factor * n`` points per axis, spacing
    ``dx / factor``; periodic surfaces keep their samples at every ``factor``-th point
    (:func:`resampled` to ``factor * n``), non-periodic windows are refined through their
    even mirror image and keep their footprint. Metadata ``refined_from`` (the old shape)
    and ``refined_factor``.

    ``factor`` is an integer >= 1 (1 returns the surface unchanged)."""
    if not isinstance(surface, Surface):
        raise InputError(f"refined() takes a roughfe Surface, got {type(surface).__name__}")
    factor = check_int("refinement factor (an integer >= 1: points per old spacing)",
                       factor, 1)
    if factor == 1:
        return surface
    n_in = surface.shape
    spanned = n_in if surface.periodic else tuple(2 * (n - 1) for n in n_in)  # the mirror
    _check_resample_memory(spanned, tuple(n * factor for n in spanned))
    if surface.periodic:
        h = surface.heights
        for axis in range(h.ndim):
            h = _interpolate_axis(h, axis, n_in[axis] * factor)
    else:
        h = surface.mirrored().heights
        # sub-cell centres of the original cells: (j + 1/2)/f - 1/2 spacings from sample 0
        shift = -(factor - 1) / (2.0 * factor)
        for axis in range(h.ndim):
            h = _interpolate_axis(h, axis, h.shape[axis] * factor, shift)
        h = h[tuple(slice(0, n * factor) for n in n_in)]
    return Surface(h, surface.size, surface.periodic,
                   {**surface.metadata, "refined_from": list(n_in), "refined_factor": factor})
