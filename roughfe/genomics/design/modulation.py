"""Short-wave roughness modulated by the long-wave height (issue 15, beyond the thesis and
beyond the MWM model): a surface design whose short waves are weaker on its long-wave
crests.

A periodic surface design is a sum of lattice plane waves with fixed amplitudes, so its
short-wave roughness is the same on the crests of its long waves as in their valleys. A
measured surface need not be: on x3p-2 (the mirrored window, 41 x 100 on the database
spacing) the short-wave part (|q| > q_N / 2) has 0.79 of its rms on the nodes where the
long-wave part is in its highest 10 % (:func:`crest_roughness`), the study's 0.8607
M-CCO design 0.99; random phases with the target's spectrum scatter over 0.78-1.11 (6
seeds), so the target sits at the low end of that scatter (session 9,
``docs/theory/surface-design.md``). Made uniform, the target loses 14 % of its contact
area at the top approach (A* 0.428 -> 0.368) and its highest node rises from 2.71 to
3.07 rms: the level of A(p) that the x3p-2 M-CCO designs lacked.

The modulation of depth epsilon (-), split at ``cut`` (a fraction of the Nyquist
wavenumber of each axis, q_N = pi / spacing):

    Z_lo = F^-1[ 1(|q| <= cut q_N) F[Z - mean Z] ],      Z_hi = Z - mean Z - Z_lo,
    g = exp(-epsilon Z_lo / rms Z_lo),
    Z' = Z_lo + Z_hi g rms(Z_hi) / rms(Z_hi g),

with |q| / q_N = sqrt((2 f_0)^2 + (2 f_1)^2), f_i the FFT frequency in cycles per node
along axis i. The long-wave part and the rms of the short-wave part are kept; epsilon > 0
moves short-wave roughness from the crests to the valleys (the product with g puts
sidebands q +- q_lo beside every short wave, so Z' is no longer a sum of the design's own
lattice waves). epsilon = 0 returns Z - mean Z.
"""
from __future__ import annotations

import numpy as np

from ...errors import InputError, check_real_array

#: the split between long and short waves, a fraction of each axis' Nyquist wavenumber
MODULATION_CUT = 0.5


def wave_split(heights, cut: float = MODULATION_CUT):
    """``(Z_lo, Z_hi)`` of periodic ``heights`` (m): the modes at ``|q| <= cut q_N`` and the
    rest, mean removed (module notes; ``Z_lo + Z_hi = Z - mean Z``)."""
    h = check_real_array("heights", heights, 2)
    if not 0 < cut < np.sqrt(2):
        raise InputError(f"0 < cut < sqrt 2 needed, got cut {cut!r}")
    h = h - h.mean()
    n0, n1 = h.shape
    r = np.hypot(np.fft.fftfreq(n0)[:, None] * 2, np.fft.fftfreq(n1)[None, :] * 2)
    lo = np.real(np.fft.ifft2(np.where(r <= cut, np.fft.fft2(h), 0)))
    return lo, h - lo


def modulated_heights(heights, depth: float, cut: float = MODULATION_CUT) -> np.ndarray:
    """Z' of the module notes (m): the short-wave part of ``heights`` times
    ``exp(-depth Z_lo / rms Z_lo)``, rescaled to its own rms, plus the long-wave part."""
    lo, hi = wave_split(heights, cut)
    if not np.isfinite(depth):
        raise InputError(f"modulation depth must be finite, got {depth!r}")
    if depth == 0:
        return lo + hi
    if not (lo.std() > 0 and hi.std() > 0):
        raise InputError("a modulation needs long and short waves (both parts have rms 0 "
                         "or one of them has)")
    hm = hi * np.exp(-depth * lo / lo.std())
    return lo + hm * (hi.std() / hm.std())


def crest_roughness(heights, cut: float = MODULATION_CUT, top: float = 0.1) -> float:
    """rms of Z_hi on the nodes where Z_lo is in its highest fraction ``top``, over the rms
    of Z_hi on all nodes (-): about 1 for a sum of plane waves of fixed amplitudes, < 1
    where the short waves are weaker on the long-wave crests."""
    if not 0 < top < 1:
        raise InputError(f"0 < top < 1 needed, got {top!r}")
    lo, hi = wave_split(heights, cut)
    crest = lo >= np.quantile(lo, 1 - top)
    return float(np.sqrt(np.mean(hi[crest] ** 2)) / hi.std())
