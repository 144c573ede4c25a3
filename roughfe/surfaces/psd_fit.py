"""Which PSD values the power-law fit reads, and how its line sits on them.

:func:`roughfe.surfaces.stats.fit_hurst` fits ``C = A q^s`` by the weighted Whittle
likelihood: ``A = sum(w c q^-s) / sum(w)`` is a weighted *mean* of the data over the line.
On a self-affine spectrum the line runs through the data (median data/line 0.96-1.04 on
RMD and Gaussian spectral surfaces; ln 2 = 0.69 on profiles, whose values are single
exponential modes). A spectrum that is not one power law moves the mean away from the
bulk of the values: on x3p-2.x3p (plane removed; a machined surface whose grooves are
about 9.3 um apart) three annuli at the grooves' wavenumbers, 32x, 10x and 7x above the
line, carry 66 % of ``A``, and the line lies 3.5x above the median of the data (they
pull the fitted H too: 0.415, 0.23 without the values above 3x the line).
:func:`fit_level` measures both, so a figure can draw the fitted slope where the data
are and name the values that set the Whittle level.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .stats import PSD_ROUNDOFF, PowerSpectrum

#: A PSD value that carries at least this share of the Whittle level ``sum(w c q^-s)``
#: is reported as one that sets it (:attr:`FitLevel.peak_q`).
PEAK_SHARE = 0.1


def fit_points(psd: PowerSpectrum, q_range) -> tuple:
    """The PSD values :func:`~roughfe.surfaces.stats.fit_hurst` fits in ``q_range`` (a
    mask) and their Whittle weights ``weight / q^ndim`` (each decade alike). Modes with
    round-off power (a band-limited surface beyond its cut-off, below
    :data:`~roughfe.surfaces.stats.PSD_ROUNDOFF` of the largest value) are no power law:
    kept, they pulled H up (+0.075 on profiles, +0.1 on surfaces; round 2, session 22)."""
    floor = PSD_ROUNDOFF * float(psd.C.max()) if psd.C.size else 0.0
    sel = (psd.q >= q_range[0]) & (psd.q <= q_range[1]) & (psd.C > floor)
    return sel, psd.weight[sel] / psd.q[sel] ** psd.ndim


@dataclass(frozen=True)
class FitLevel:
    """Where a fitted power law sits on the PSD values it was fitted to.

    Attributes
    ----------
    median_ratio : float
        Median of ``C / (A q^s)`` over the fitted values (-): 1 when the line runs through
        the data; NaN when no value was fitted.
    peak_q : ndarray
        Wavenumbers (rad/m) of the values that each carry at least :data:`PEAK_SHARE` of
        the Whittle level ``A``.
    peak_C : ndarray
        Their PSD values (m^3 or m^4).
    peak_share : float
        The share of ``A`` they carry together (-).
    """

    median_ratio: float
    peak_q: np.ndarray
    peak_C: np.ndarray
    peak_share: float


def fit_level(psd: PowerSpectrum, fit) -> FitLevel:
    """How the line ``fit.prefactor * q**fit.slope`` of a successful
    :class:`~roughfe.surfaces.stats.HurstFit` sits on ``psd`` (the spectrum it was
    fitted to, same window) over ``fit.q_range``."""
    sel, weight = fit_points(psd, fit.q_range)
    q, c = psd.q[sel], psd.C[sel]
    if not q.size:
        return FitLevel(float("nan"), np.empty(0), np.empty(0), 0.0)
    ratio = c / (fit.prefactor * q ** fit.slope)
    share = weight * ratio / np.sum(weight * ratio)      # each value's part of A
    peak = share >= PEAK_SHARE
    return FitLevel(median_ratio=float(np.median(ratio)), peak_q=q[peak], peak_C=c[peak],
                    peak_share=float(share[peak].sum()))
