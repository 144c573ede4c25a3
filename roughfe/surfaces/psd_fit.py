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
import scipy.optimize

from .stats import PSD_ROUNDOFF, PowerSpectrum


def whittle_power_law(q, c, weight):
    """Slope s and prefactor A of ``C = A q**s`` by the weighted Whittle likelihood.

    Minimises ``sum_i weight_i [ln(A q_i^s) + c_i / (A q_i^s)]`` over A and s, with
    ``weight`` the number of Fourier modes behind each PSD value ``c_i`` times the
    weight given to each mode. A is then ``sum weight c q^-s / sum weight`` and the
    profile likelihood in s, ``ln(sum weight c q^-s) + s <ln q>``, is convex (a
    log-sum-exp plus a linear term): a bounded scalar minimisation finds it.

    Why not least squares on log C: a periodogram value of a Gaussian surface is an
    exponential variable, and the log of the mean of k of them is biased low by
    ln k - psi(k) (0.58 for k = 1). The few modes per logarithmic bin at the low-q end
    of a profile flatten a log-log fit: H = 0.8 fitted as 0.74 on average over 200
    seeds of 1024-point profiles. The Whittle score equations are unbiased for any
    weights (E[c_i] = A q_i^s), and working with C itself, not its logarithm, keeps the
    empty bins between the lines of a Weierstrass-Mandelbrot spectrum from dragging the
    fit (H = 0.3 and 0.5 fitted as 0.79 and 0.99 by the binned log-log fit).
    """
    lq = np.log(q)
    lw = np.log(weight * c)              # c > 0 by the caller's selection
    wbar = float(np.sum(weight * lq) / np.sum(weight))
    shift = float(lq.mean())

    def objective(s):
        z = lw - s * (lq - shift)
        zmax = float(z.max())
        return zmax + float(np.log(np.sum(np.exp(z - zmax)))) + s * (wbar - shift)

    best = scipy.optimize.minimize_scalar(objective, bounds=(-12.0, 4.0), method="bounded",
                                          options={"xatol": 1e-10})
    s = float(best.x)
    prefactor = float(np.sum(weight * c * np.exp(-s * lq)) / np.sum(weight))
    return s, prefactor


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


# -- is the fitted range one power law? ----------------------------------------------------
#: The two halves (in log q) of a fit range are not one power law when their Hurst
#: exponents differ by more than this many standard errors ...
SPLIT_SIGMAS = 4.0
#: ... and by more than this (a difference too small to matter is not reported).
SPLIT_MIN_GAP = 0.2
#: A high-q half whose H is below this is flatter than any self-affine PSD: a white
#: noise floor (``C`` independent of q: H = -1) mixed in, e.g. the instrument's.
FLAT_HURST = 0.0
#: Hann window: neighbouring modes are correlated, and the variance of a spectral
#: estimate grows by ``N sum w^4 / (sum w^2)^2 = 35/18`` per axis (the taper's variance
#: inflation; measured: 1.8 on profiles, 1.6^2 on surfaces, 30 seeds each).
HANN_VARIANCE = 35 / 18


@dataclass(frozen=True)
class SplitFit:
    """The power law of :func:`~roughfe.surfaces.stats.fit_hurst` refitted on the two
    halves (in log q) of its range, below and above ``q_split`` (rad/m).

    ``hurst_low``/``hurst_high`` (-) with their standard errors ``*_error`` (-) from the
    Whittle score's sandwich variance for a Gaussian surface (every independent Fourier
    mode an exponential variable); NaN when a half has too few values (then ``note`` is
    empty). ``note`` says in words what is wrong when the halves disagree (by more than
    :data:`SPLIT_SIGMAS` errors and :data:`SPLIT_MIN_GAP`), else it is "".
    """

    q_split: float
    hurst_low: float
    hurst_low_error: float
    hurst_high: float
    hurst_high_error: float
    note: str


def independent_modes(psd: PowerSpectrum, sel, size) -> np.ndarray:
    """Independent Fourier modes behind the PSD values ``psd[sel]`` of a surface of
    physical ``size`` (m): half the modes (those at q and -q are one)."""
    cell = float(np.prod([2 * np.pi / s for s in np.atleast_1d(size)]))
    return psd.weight[sel] / (2 * cell)


def hurst_error(psd: PowerSpectrum, q, weight, modes) -> float:
    """Standard error (-) of the Whittle H fitted to the PSD values at ``q`` (rad/m) with
    Whittle weights ``weight`` (:func:`fit_points`) and ``modes`` independent modes each
    (:func:`independent_modes`): the score's sandwich variance for a Gaussian surface
    (each mode's periodogram an exponential variable), times :data:`HANN_VARIANCE` per
    axis with the Hann window. It is the statistical error only; a spectrum that is not
    one power law adds a systematic one (:func:`split_fit`). Measured against the scatter
    of 40 seeds (H = 0.8): 0.036 predicted / 0.037 observed (4096-point periodic
    profiles), 0.083 / 0.075 (1024-point windowed crops), 0.029 / 0.031 (256^2 periodic),
    0.093 / 0.081 (128^2 windowed crops)."""
    x = np.log(q)
    dx = x - np.sum(weight * x) / np.sum(weight)
    # score sum w (c/mu - 1)(x - xbar): Var(c/mu) = 1/modes; derivative -sum w dx^2
    var = np.sum(weight ** 2 * dx ** 2 / modes) / np.sum(weight * dx ** 2) ** 2
    if psd.window == "hann":
        var *= HANN_VARIANCE ** psd.ndim
    return float(np.sqrt(var) / 2)          # dH = ds / 2 (1D and 2D)


def _half_fit(psd, q, c, weight, modes):
    """H and its standard error of the Whittle power law of these values."""
    slope, _ = whittle_power_law(q, c, weight)
    hurst = -slope / 2 - 1 if psd.ndim == 2 else (-slope - 1) / 2
    return float(hurst), hurst_error(psd, q, weight, modes)


def split_fit(psd: PowerSpectrum, q_range, size) -> SplitFit:
    """Refit the two halves of ``q_range`` (rad/m) of ``psd``, the spectrum of a surface
    of physical ``size`` (m), to see whether it is one power law there (:class:`SplitFit`).

    A self-affine spectrum gives the same H on both halves within their errors (Gaussian
    spectral profiles and surfaces at H = 0.3, 0.5, 0.8, periodic and windowed crops, 30
    seeds each: difference / error has sd 0.8-1.2, at most 3.5; none reported; tests).
    A curved spectrum does not, and its one fitted H is then an average that depends on
    the range: opd-1.opd (plane removed) gives H = 0.03 over the default range as the
    mean of -0.27 +- 0.13 below q = 1.3e6 rad/m and 0.29 +- 0.02 above; its white noise
    floor (q > 1.4e7 rad/m) lies beyond the range's end pi / (2 dx) = 8.0e6 rad/m.
    """
    sel, weight = fit_points(psd, q_range)
    q, c = psd.q[sel], psd.C[sel]
    modes = independent_modes(psd, sel, size)
    split = float(np.sqrt(q[0] * q[-1])) if q.size else float("nan")
    halves = []
    for part in (q < split, q >= split):
        if part.sum() < 3 or q[part][-1] <= q[part][0] * 10 ** 0.1:
            return SplitFit(split, np.nan, np.nan, np.nan, np.nan, "")
        halves.append(_half_fit(psd, q[part], c[part], weight[part], modes[part]))
    (low, elow), (high, ehigh) = halves
    gap = abs(high - low)
    note = ""
    if gap > SPLIT_MIN_GAP and gap > SPLIT_SIGMAS * np.hypot(elow, ehigh):
        note = (f"the PSD is not one power law over q_range: H = {low:.2f} +- {elow:.2f} "
                f"below q = {split:.3g} rad/m, {high:.2f} +- {ehigh:.2f} above")
        if high < min(low, FLAT_HURST):
            note += (" (flatter than self-affine at high q: a white noise floor, e.g. the "
                     "instrument's, has H = -1)")
        note += ("; the fitted H depends on the range: fit the range that is self-affine "
                 "(q_range=, roughfe info --hurst-q-range QMIN QMAX)")
    return SplitFit(split, low, elow, high, ehigh, note)


def range_note(message: str) -> str:
    """The note of :func:`split_fit` inside a fit's ``message`` (``HurstFit.message``,
    ``SurfaceStatistics.hurst_message``), or "" when the range was one power law: what
    ``roughfe info`` and the demo report print beside H."""
    return message.partition("; ")[2] if "not one power law" in message else ""
