"""Texture direction of a surface: the texture aspect ratio Str of ISO 25178-2.

The normalised autocorrelation of the mean-free heights,

    f(tau) = sum_x h(x) h(x + tau) / sum_x h(x)^2,

is the inverse Fourier transform of the power |h~(q)|^2 (Wiener-Khinchin; the PSD of
:mod:`roughfe.surfaces.stats` without its window). Along each direction theta it falls
from 1 at tau = 0; the distance r(theta) at which it first reaches s = 0.2 is the
autocorrelation length in that direction, and

    Str = min_theta r(theta) / max_theta r(theta)      (ISO 25178-2, texture aspect ratio)

is near 1 for an isotropic surface and small for a lay (grooves: the heights stay
correlated along them). Persson's theory takes an isotropic PSD (the radial average of
:func:`~roughfe.surfaces.stats.power_spectrum`); :func:`roughfe.theory.beside` reads Str
to say when a surface is not (docs/theory/04_leakage.md).

A non-periodic window's autocorrelation is taken on the zero-padded heights (the biased
estimate, which falls to 0 at the window's size, so every direction has an r); a
periodic surface's is the circular one up to half its period. A direction whose
correlation stays above s up to that end has r at the end, and Str is then an upper
bound (``bounded`` True).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.ndimage

from ..errors import InputError, check_instance
from .surface import Surface

#: the autocorrelation level of ISO 25178-2's Str and Sal
ACF_LEVEL = 0.2
#: most points a side of the autocorrelation's grid (:func:`_autocorrelation`)
MAX_POINTS = 1024
#: ``persistence`` at or above which a direction is called correlated across the whole reach
#: (a lay longer than the cell): one wave across a 32^2 cell with 30 % noise keeps 0.83,
#: 60 isotropic self-affine periodic cells (64^2-256^2, H 0.3 / 0.8, no roll-off) at most
#: 0.68 (round 2, session 33)
LAY_PERSISTENCE = 0.75


@dataclass(frozen=True)
class TextureAspect:
    """Str and the autocorrelation lengths behind it (SI).

    Attributes
    ----------
    ratio : float
        Str = ``shortest / longest`` (-), in (0, 1].
    shortest, longest : float
        Autocorrelation lengths r(theta) in m of the fastest and slowest decay to
        :data:`ACF_LEVEL` (``shortest`` is ISO's Sal).
    lay_angle : float
        Direction of the slowest decay (the lay, along the grooves), degrees from the x
        axis in [0, 180).
    bounded : bool
        The slowest direction reached the end of the autocorrelation (the window or half
        the period) before falling to :data:`ACF_LEVEL`: Str is an upper bound.
    persistence : float
        The largest, over directions, of the smallest autocorrelation along the direction
        up to the end of the reach: 1 for one wave across a periodic cell (its crests never
        decorrelate), near :data:`ACF_LEVEL` for a bounded isotropic cell whose slowest
        direction just failed to fall below it. At or above :data:`LAY_PERSISTENCE` with
        ``bounded``, the cell holds a lay longer than itself that Str cannot measure.
    """

    ratio: float
    shortest: float
    longest: float
    lay_angle: float
    bounded: bool
    persistence: float


def _autocorrelation(surface):
    """Normalised autocorrelation (shifted: zero lag at ``centre``), its centre index, the
    largest lag (m) along each axis that it covers and the spacing (m) of its lags. Grids
    above :data:`MAX_POINTS` a side are block-averaged to at most that first (the padded
    transform of 4096^2 points would take 0.5 GB; the lengths of Str are many cells)."""
    h = np.asarray(surface.heights, float)
    blocks = [-(-n // MAX_POINTS) for n in h.shape]
    if max(blocks) > 1:
        nx, ny = (n // b for n, b in zip(h.shape, blocks))
        h = h[:nx * blocks[0], :ny * blocks[1]].reshape(nx, blocks[0], ny, blocks[1]).mean(
            axis=(1, 3))
    spacing = tuple(d * b for d, b in zip(surface.spacing, blocks))
    extent = [n * d for n, d in zip(h.shape, spacing)]
    h = h - h.mean()
    if surface.periodic:
        shape, reach = h.shape, [e / 2 for e in extent]
    else:
        shape, reach = tuple(2 * n for n in h.shape), extent
    f = np.fft.rfft2(h, s=shape)
    acf = np.fft.fftshift(np.fft.irfft2(np.abs(f) ** 2, s=shape))
    centre = tuple(n // 2 for n in shape)
    return acf / acf[centre], np.array(centre, float), reach, spacing


def texture_aspect_ratio(surface: Surface, n_angles: int = 180) -> TextureAspect:
    """ISO 25178-2 texture aspect ratio Str of a 2D surface (module docstring).

    Parameters
    ----------
    surface : Surface
        A 2D surface (heights in m; cells may be rectangular).
    n_angles : int
        Directions theta sampled in [0, 180) degrees.

    Returns
    -------
    TextureAspect
    """
    check_instance("surface", surface, Surface, "a roughfe Surface")
    if surface.ndim != 2 or min(surface.shape) < 2:
        raise InputError(f"Str needs a 2D surface of at least 2 x 2 points, got shape "
                         f"{surface.shape}")
    if not np.ptp(surface.heights) > 0:
        raise InputError("Str of a flat surface is undefined (no height variance)")
    acf, centre, reach, (dx, dy) = _autocorrelation(surface)
    step = 0.5 * min(dx, dy)
    theta = np.pi * np.arange(n_angles) / n_angles
    c, s = np.cos(theta), np.sin(theta)
    # each ray ends where it leaves the rectangle of lags the autocorrelation covers
    with np.errstate(divide="ignore"):
        end = np.minimum(np.where(np.abs(c) > 1e-12, reach[0] / np.abs(c), np.inf),
                         np.where(np.abs(s) > 1e-12, reach[1] / np.abs(s), np.inf))
    r = np.arange(int(np.ceil(end.max() / step)) + 1) * step
    ix = centre[0] + np.outer(c, r) / dx
    iy = centre[1] + np.outer(s, r) / dy
    values = scipy.ndimage.map_coordinates(acf, [ix, iy], order=1, mode="nearest")
    inside = r[None, :] <= end[:, None]
    below = (values <= ACF_LEVEL) & inside
    first = np.where(below.any(axis=1), below.argmax(axis=1), -1)
    length = np.where(first >= 0, r[np.maximum(first, 0)], end)
    # the crossing between the last sample above the level and the first below it
    k = np.maximum(first, 1)
    rows = np.arange(n_angles)
    v0, v1 = values[rows, k - 1], values[rows, k]
    frac = np.clip((v0 - ACF_LEVEL) / np.where(v0 > v1, v0 - v1, 1.0), 0.0, 1.0)
    length = np.where(first >= 1, r[k - 1] + frac * step, length)
    slow = int(np.argmax(length))
    persistence = float(np.where(inside, values, np.inf).min(axis=1).max())
    return TextureAspect(ratio=float(length.min() / length.max()),
                         shortest=float(length.min()), longest=float(length[slow]),
                         lay_angle=float(np.degrees(theta[slow])), bounded=bool(first[slow] < 0),
                         persistence=persistence)
