"""The 1D PSD of a map along x or along y: the mean of the line PSDs of its profiles.

contact.engineering and SurfaceTopography (``power_spectrum_from_profile``) show, beside
the radially averaged 2D PSD, the PSD of the profiles along x (and, transposed, along y)
averaged over the lines of the map. On a surface with a lay (grooves, turning marks)
the two differ; on an isotropic one they agree within their scatter.

Each line (``heights[:, j]`` along x, ``heights[i, :]`` along y: axis 0 is x) is a
profile of ``n`` points and length ``L`` (the map's size along that axis). Its own mean
is removed, it is windowed by the 1D Hann window of :func:`roughfe.surfaces.stats.
power_spectrum` when asked (``"auto"``: none for periodic maps, Hann otherwise; the
window is along the line only), and its PSD is the profile PSD of the module
:mod:`roughfe.surfaces.stats` (Persson's normalisation, ``<h^2> = int C dq`` over both
signs of q; :attr:`~roughfe.surfaces.stats.PowerSpectrum.C_jacobs` = ``2 pi C`` is
SurfaceTopography's / contact.engineering's 1D PSD). The line PSDs are averaged at each q:

    C_x(q) = (1/N_y) sum_j C_j(q),

so ``sum(C_x * weight)`` is the mean over lines of each line's variance (Parseval per
line; of the windowed lines with a window): the map's variance less the variance of the
line means. Without a window it is also the 2D PSD summed over the other component,
``C_x(q_x) = sum_{q_y} C(q_x, q_y) dq_y`` (exact on the grid, tested).

Against SurfaceTopography's ``power_spectrum_from_profile`` of a 2D map (its transpose
for y; measured on x3p-2, plu-1, di-1): without a window the two are ``2 pi`` apart to
1e-10 at every q it reports (it drops the Nyquist wavenumber). Its default window of a
non-periodic map is the radial 2D one; with its ``window("hann", direction="x")`` the
values from ``q = 2 dq`` on are 0.95-1.04 times ours (medians 0.998-1.002): its Hann is
scipy's periodic one (``n`` points in the cosine's period, ours ``n - 1``), and it keeps
each line's mean, whose product with the window puts power at ``q = dq`` (0.9-1.7x ours
on centred lines, 2e3-6e6x on plu-1's tilted ones).
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError
from .stats import (PowerSpectrum, _check_surface, _default_window, _window,
                    line_spectrum, power_spectrum)
from .surface import Surface

#: direction name -> array axis of the heights (axis 0 is x)
DIRECTIONS = {"x": 0, "y": 1}


def line_power_spectrum(surface: Surface, direction="x", window="auto") -> PowerSpectrum:
    """Mean PSD of the profiles of ``surface`` along ``direction`` (module docstring).

    Parameters
    ----------
    surface : Surface
        A map, or a profile (then ``direction="x"`` is its :func:`power_spectrum`).
    direction : {"x", "y"}
        The lines' direction: ``"x"`` averages the columns ``heights[:, j]`` (along
        axis 0), ``"y"`` the rows ``heights[i, :]``.
    window : {"auto", "hann", "none", None}
        As :func:`~roughfe.surfaces.stats.power_spectrum`, applied along each line.

    Returns
    -------
    PowerSpectrum
        ``ndim = 1``: ``q`` (rad/m), ``C`` (m^3, Persson's normalisation), ``weight``.
    """
    _check_surface(surface)
    if direction not in DIRECTIONS:
        raise InputError(f"direction must be 'x' or 'y', got {direction!r}")
    axis = DIRECTIONS[direction]
    if surface.ndim == 1:
        if axis:
            raise InputError("direction 'y' needs a 2D surface; a profile runs along x")
        return power_spectrum(surface, window=window)
    window = _default_window(surface, window)
    h = np.moveaxis(np.asarray(surface.heights, float), axis, 0)
    n = h.shape[0]
    h = h - h.mean(axis=0)
    w = _window(window, (n,))
    if w is not None:
        h = h * w[:, None]
        h -= h.mean(axis=0)
    spec = np.fft.rfft(h, axis=0)
    power = np.mean(spec.real ** 2 + spec.imag ** 2, axis=1) / float(n) ** 2
    return line_spectrum(power, n, surface.size[axis], "none" if window is None else window)


def line_spectra(surface: Surface, window="auto") -> dict:
    """``{"along x": ..., "along y": ...}`` :func:`line_power_spectrum` of a map; empty
    for a profile (its PSD is the profile PSD)."""
    if surface.ndim == 1:
        return {}
    return {f"along {d}": line_power_spectrum(surface, d, window) for d in DIRECTIONS}
