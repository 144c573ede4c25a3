"""Rms slope by the 7-point derivative of ISO 4287 / ISO 25178-2 (Rdq, Sdq).

ISO 4287 (Rdq) and ISO 25178-2 (Sdq) evaluate the local slope with the sixth-order
central difference

    h'_i = (h_{i+3} - 9 h_{i+2} + 45 h_{i+1} - 45 h_{i-1} + 9 h_{i-2} - h_{i-3}) / (60 dx)

(error ``(k dx)^6 / 140`` on a wave of wavenumber k, against ``(k dx)^2 / 24`` of the
forward difference), and the rms slope is ``Rdq = sqrt<h'^2>`` (profile) or
``Sdq = sqrt<(dh/dx)^2 + (dh/dy)^2>`` (surface). :func:`rms_slope_iso` gives it beside
:func:`roughfe.surfaces.stats.rms_slope` (spectral for periodic data, forward differences
otherwise), which it does not replace. Periodic data wrap around the edges; on
non-periodic data the derivative along an axis exists 3 points away from its ends, and
each axis' mean square is taken over the points where its derivative exists (as
``rms_slope`` does for its differences). On data with power up to the grid scale the
two estimates differ: on a wave the stencil gives ``g = (45 sin t - 9 sin 2t + sin 3t) /
30`` per ``dx`` (``t = k dx``), the forward difference ``2 sin(t / 2)``; ``g`` is nearer
the exact ``t`` up to ``t = 0.57 pi`` and falls to 0 at the Nyquist wavenumber, where
the forward difference gives 2. On the five measured files (plane removed) the ISO
slope is 0.88-1.00 times the forward-difference one (docs/theory/01).
"""
from __future__ import annotations

import numpy as np

from ..errors import check_instance
from .surface import Surface

#: ISO 4287's 7-point first-derivative weights at offsets -3 .. 3 (times 1 / dx)
ISO_WEIGHTS = np.array([-1.0, 9.0, -45.0, 0.0, 45.0, -9.0, 1.0]) / 60.0

#: points an axis of non-periodic data needs for one derivative value
ISO_MIN_POINTS = 7


def iso_derivative(heights, spacing: float, axis: int, periodic: bool) -> np.ndarray:
    """``dh/dx`` (-) along ``axis`` of ``heights`` (m) on a grid of ``spacing`` (m) by
    :data:`ISO_WEIGHTS`: the whole grid when ``periodic`` (wrapped), else the points 3
    or more away from both ends of the axis (empty below :data:`ISO_MIN_POINTS`)."""
    h = np.moveaxis(np.asarray(heights, float), axis, 0)
    n = h.shape[0]
    if periodic:
        d = sum(c * np.roll(h, -k, axis=0) for k, c in zip(range(-3, 4), ISO_WEIGHTS) if c)
    elif n < ISO_MIN_POINTS:
        d = h[:0]
    else:
        d = sum(c * h[3 + k: n - 3 + k] for k, c in zip(range(-3, 4), ISO_WEIGHTS) if c)
    return np.moveaxis(d / spacing, 0, axis)


def rms_slope_iso(surface: Surface) -> float:
    """Rdq (profile) or Sdq (surface), dimensionless, by the ISO 7-point derivative
    (module docstring); NaN when a non-periodic axis has fewer than 7 points."""
    check_instance("surface", surface, Surface, "a roughfe Surface (roughfe.surfaces.Surface)")
    total = 0.0
    for axis, dx in enumerate(surface.spacing):
        d = iso_derivative(surface.heights, dx, axis, surface.periodic)
        if d.size == 0:
            return float("nan")
        total += float(np.mean(d ** 2))
    return float(np.sqrt(total))
