"""Down to which wavelength a scanned map is reliable: the coherence of trace and retrace.

An AFM records each fast-scan line twice, left to right (trace) and right to left
(retrace), with the same tip over the same area. What the two sweeps share is the
surface (and whatever else repeats within one line cycle); what differs between them is
noise. Their agreement per wavenumber along the fast axis is the magnitude-squared
coherence, averaged over the ``K`` lines ``j``::

    gamma^2(q) = |<X_j(q) Y_j(q)*>_j|^2 / (<|X_j(q)|^2>_j <|Y_j(q)|^2>_j),

with ``X_j``, ``Y_j`` the Fourier transforms along the fast axis of line ``j`` of the
two scans (after alignment, levelling and windowing, below); ``q = k 2 pi / (n dx)``
(rad/m) for the ``n`` points of the aligned lines at spacing ``dx`` (m).

Threshold (derivation). Let both scans be the surface ``S`` plus independent noise of
equal power: ``X = S + N_1``, ``Y = S + N_2``, ``<|S|^2> = P_S``, ``<|N_i|^2> = P_N``,
``<S N_i*> = <N_1 N_2*> = 0``. Then ``<X Y*> = P_S`` and ``<|X|^2> = <|Y|^2> = P_S + P_N``,
so::

    gamma^2 = P_S^2 / (P_S + P_N)^2 = 1 / (1 + P_N / P_S)^2,
    P_S / P_N = |gamma| / (1 - |gamma|).

The surface's power equals the noise's (``P_S = P_N``) at ``gamma^2 = 1/4`` (``|gamma| =
1/2``); ``gamma^2 = 1/2`` is ``P_S / P_N = 1 / (sqrt 2 - 1) = 2.41``. The cutoff
:data:`THRESHOLD` is ``gamma^2 = 1/4``: above ``q_c`` each scan holds more noise than
surface. With unequal noise (``P_N1 != P_N2``) ``gamma^2 = P_S^2 / ((P_S + P_N1)(P_S +
P_N2))``: ``1/4`` is then where ``P_S`` equals about the mean of the two noise powers.

Reliability cutoff ``q_c``: the smallest ``q`` above which the coherence stays below the
threshold, interpolated linearly in ``ln q`` between the last wavenumber at or above it
and the next one. None when the last (Nyquist) wavenumber is at or above it (reliable
to the pixel); the lowest ``q`` when no wavenumber reaches it (nothing is reproducible).

Steps, and why:

1. Alignment. The two sweeps are offset along the fast axis (piezo hysteresis, a delay
   of the feedback: di-1 by about 6 samples). The integer lag ``L`` that maximises the
   correlation coefficient of the levelled lines over their overlap, ``|L| <= max_lag``,
   aligns them (``second[i + L] = first[i]``; every lag at once by FFT:
   :func:`_best_lag`) and both are cropped to the overlap,
   ``n = n_x - |L|`` points. ``gamma^2`` does not depend on a delay common to all lines
   (it multiplies every ``X_j Y_j*`` by one phase ``exp(i q tau)``), so the integer lag
   is enough for the coherence; the sub-sample rest ``delta`` is reported from the slope
   of the cross-spectrum's phase, ``arg <X Y*> = q delta dx``, fitted over the
   wavenumbers below ``q_c`` with the weights ``gamma^2 / (1 - gamma^2)`` (the inverse of
   the phase's variance): :attr:`TraceRetraceCoherence.lag` is ``L + delta`` samples.
2. Levelling. Each aligned line's least-squares straight line (mean and tilt) is removed
   (:func:`roughfe.surfaces.scan_lines.level_lines`), before the lag search and again
   on the aligned lines: the line offsets and tilts of a scanned map (di-1's offsets
   are 6 % of Sq) are large, long and partly different in the two sweeps; with the
   means removed only, di-1's correlation peaks at a lag of 8 samples instead of 6
   (its ``q_c`` moves by 0.07 %). The same for a mean, a plane or lines removed
   beforehand: ``q_c`` does not depend on ``--detrend``.
3. Window. Each line is multiplied by the Hann window of
   :func:`~roughfe.surfaces.stats.power_spectrum`: the aligned lines are not periodic,
   and the jump between their ends would leak ``q^-2`` power, shared by both sweeps,
   into the short waves, where it counts as coherent and pushes ``q_c`` up (di-1
   without a window: coherent to the Nyquist wavenumber, no cutoff; with it 5.93e8
   rad/m). The window's normalisation cancels.

Estimator. With ``K`` independent lines the null coherence (no shared signal) has
``P(gamma^2 >= t) = (1 - t)^(K - 1)`` and mean ``1 / K``; its standard deviation about a
true ``gamma^2`` is about ``sqrt(2 gamma^2 (1 - gamma^2)^2 / K)`` (0.023 at ``gamma^2 =
1/4``, ``K = 512``; Carter, Knapp & Nuttall 1973). A map needs at least
:func:`minimum_lines` lines: enough that pure noise reaches the threshold at one of its
wavenumbers with probability below :data:`FALSE_ALARM` (37 lines for 512 points).

What it cannot see: anything the two sweeps share. The tip's shape (both sweeps use the
same tip), a disturbance lasting a line cycle, a piezo's non-linearity that is the same
in both directions: these are coherent and are not flagged. ``q_c`` is an upper bound of
the reliable wavenumbers; a tip-radius criterion (SurfaceTopography's short reliability
cutoff) is a separate one. Along the slow axis trace and retrace are the same line
steps and share their line-to-line noise, so only the fast axis is measured.

How much of a map lies beyond ``q_c``: :func:`slope_share_above`, the share of the mean
square slope along x (or y) carried by the wavenumbers above a cutoff, from the line PSD
of :mod:`roughfe.surfaces.line_psd`; ``contact`` and ``leak`` report it along both axes
with the cutoff (the slopes, not the heights: the finest scales set the contact patches).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
import scipy.fft

from ..errors import (InputError, check_finite_positive, check_in_open_interval,
                      check_instance, check_int)
from ..frozen import ReadOnlyArrays, read_only_arrays
from .line_psd import line_power_spectrum
from .scan_lines import column_fits_removed, scan_axis_of
from .stats import _window
from .surface import Surface

#: coherence ``gamma^2`` at which the surface's power equals the noise's in each scan
#: (module docstring: ``gamma^2 = 1 / (1 + P_N / P_S)^2``)
THRESHOLD = 0.25
#: probability that pure noise reaches the threshold at one wavenumber of a map, above
#: which a map has too few lines (:func:`minimum_lines`)
FALSE_ALARM = 0.01
#: points per aligned line at least (8 wavenumbers; a Hann window needs 3)
MIN_POINTS = 16
#: a side of the lag search whose variance over an overlap is below this share of its
#: sum of squares there is constant (the rounding of :func:`_best_lag`'s sums)
CONSTANT = 1e-10


def minimum_lines(points: int, threshold: float = THRESHOLD) -> int:
    """Lines ``K`` a map of ``points`` per line needs so that pure noise (independent
    scans) reaches ``gamma^2 >= threshold`` at one of its ``points // 2`` wavenumbers with
    probability at most :data:`FALSE_ALARM`: the smallest ``K`` with
    ``(points // 2) (1 - threshold)^(K - 1) <= FALSE_ALARM`` (the null distribution of the
    coherence of ``K`` averages; neighbouring wavenumbers of a Hann-windowed line are
    correlated, so this is conservative)."""
    bins = max(1, int(points) // 2)
    return 1 + int(np.ceil(np.log(FALSE_ALARM / bins) / np.log1p(-threshold)))


@dataclass(frozen=True, eq=False)
class TraceRetraceCoherence(ReadOnlyArrays):
    """Result of :func:`trace_retrace_coherence` (module docstring).

    Attributes
    ----------
    q : ndarray
        Angular wavenumbers along the fast axis, ``k 2 pi / (n dx)``, ``k = 1 .. n // 2``
        (rad/m).
    coherence : ndarray
        ``gamma^2(q)`` (-), in [0, 1].
    snr : ndarray
        ``P_S / P_N = |gamma| / (1 - |gamma|)`` under equal independent noise (-; inf
        where ``gamma^2 = 1``).
    threshold : float
        The ``gamma^2`` that defines ``q_cutoff`` (-).
    q_cutoff : float or None
        ``q_c`` (rad/m); None: at or above the threshold up to the Nyquist wavenumber.
    lag : float
        ``second[i + lag] = first[i]`` along the fast axis (samples): the integer lag
        plus the sub-sample rest from the cross-spectrum's phase.
    integer_lag : int
        The lag that maximises the correlation, used to align the scans (samples).
    correlation : float
        Correlation coefficient of the levelled lines at ``integer_lag`` (-).
    spacing : float
        Point spacing along the fast axis ``dx`` (m).
    lines : int
        ``K``, the lines averaged.
    points : int
        ``n``, the points of each aligned line.
    axis : str
        The fast axis, ``"x"`` (lines ``heights[:, j]``) or ``"y"``.
    """

    q: np.ndarray
    coherence: np.ndarray
    snr: np.ndarray
    threshold: float
    q_cutoff: Optional[float]
    lag: float
    integer_lag: int
    correlation: float
    spacing: float
    lines: int
    points: int
    axis: str = "x"

    def __post_init__(self):       # a result never changes: its arrays read-only
        read_only_arrays(self)

    @property
    def wavelength_cutoff(self) -> Optional[float]:
        """``2 pi / q_c`` (m): the shortest reliable wavelength; None without a cutoff."""
        return None if self.q_cutoff is None else float(2 * np.pi / self.q_cutoff)

    @property
    def lag_length(self) -> float:
        """``lag * dx`` (m)."""
        return float(self.lag * self.spacing)

    @property
    def reliable_anywhere(self) -> bool:
        """Whether any wavenumber reaches the threshold (False: pure noise)."""
        return bool(np.any(self.coherence >= self.threshold))

    def summary(self) -> dict:
        """The scalars, JSON-safe, in SI units (``info --json``'s ``reliability``)."""
        return {"q_cutoff": self.q_cutoff, "wavelength_cutoff": self.wavelength_cutoff,
                "threshold": self.threshold, "lag": self.lag,
                "integer_lag": self.integer_lag, "lag_length": self.lag_length,
                "correlation": self.correlation, "lines": self.lines,
                "points": self.points, "axis": self.axis,
                "reliable_anywhere": self.reliable_anywhere}


#: SI units of :meth:`TraceRetraceCoherence.summary`
SUMMARY_UNITS = {"q_cutoff": "rad/m (null: reliable to the Nyquist wavenumber)",
                 "wavelength_cutoff": "m", "threshold": "1 (coherence gamma^2)",
                 "lag": "samples", "integer_lag": "samples", "lag_length": "m",
                 "correlation": "1", "lines": "lines", "points": "points per line"}


def _lines_of(surface: Surface, axis: str) -> np.ndarray:
    """The map's heights with the fast-scan lines as columns (axis 0 along the line)."""
    return surface.heights if axis == "x" else surface.heights.T


def _best_lag(a: np.ndarray, b: np.ndarray, max_lag: int) -> tuple:
    """(lag, correlation): the integer ``L``, ``|L| <= max_lag``, that maximises the
    correlation coefficient of ``a[i, j]`` and ``b[i + L, j]`` over their overlap (all
    lines ``j`` together; the first of equal maxima; 0 where a side is constant over the
    overlap, its variance below :data:`CONSTANT` of its sum of squares).

    For every lag at once: with ``m = (n - |L|) K`` pairs over the overlap,
    ``S_ab(L) = sum_ij a[i, j] b[i + L, j]`` is the cross-correlation along axis 0 by
    FFT (zero-padded to at least ``n + max_lag`` points, no wrap-around; the products
    summed over the lines before the one inverse transform), and the overlap sums
    ``S_a, S_aa`` (``S_b, S_bb``) are differences of cumulative sums of the line sums
    and sums of squares of the rows, so::

        r(L) = (S_ab - S_a S_b / m) / sqrt((S_aa - S_a^2 / m) (S_bb - S_b^2 / m)).

    ``O(n log n K)`` instead of ``O(n max_lag K)`` for the loop over the lags it replaced
    (the same lag and ``r`` to 1e-12: tests/test_surfaces_reliability_lag.py). Process
    CPU with ``max_lag = n // 8``, loop -> FFT (synthetic n^2 maps; round 2, session 37):
    512^2 0.18 -> 0.01 s (di-1: 0.22 -> 0.01 s), 2048^2 32 -> 0.23-0.36 s, 4096^2 395 ->
    1.0-1.6 s. At 4096^2 :func:`trace_retrace_coherence` then takes 7.3 s: the four line
    levellings 2.3 s, the coherence's transforms along axis 0 2.0 s, this search 1.8 s.
    """
    n, lines = a.shape
    a = a - a.mean()           # r does not change; the sums' differences lose less
    b = b - b.mean()
    size = scipy.fft.next_fast_len(n + max_lag, real=True)
    cross = np.sum(scipy.fft.rfft(a, size, axis=0).conj()
                   * scipy.fft.rfft(b, size, axis=0), axis=1)
    lags = np.arange(-max_lag, max_lag + 1)
    s_ab = scipy.fft.irfft(cross, size)[lags % size]
    lo_a, hi_a = np.maximum(0, -lags), n - np.maximum(0, lags)     # a[lo_a:hi_a]
    lo_b, hi_b = np.maximum(0, lags), n - np.maximum(0, -lags)     # b[lo_b:hi_b]

    def overlap(rows, lo, hi):         # sum of rows[lo:hi] for each lag
        c = np.concatenate(([0.0], np.cumsum(rows)))
        return c[hi] - c[lo]
    m = (n - np.abs(lags)) * lines
    s_a, s_b = overlap(a.sum(axis=1), lo_a, hi_a), overlap(b.sum(axis=1), lo_b, hi_b)
    s_aa = overlap(np.einsum("ij,ij->i", a, a), lo_a, hi_a)
    s_bb = overlap(np.einsum("ij,ij->i", b, b), lo_b, hi_b)
    var_a, var_b = s_aa - s_a * s_a / m, s_bb - s_b * s_b / m
    # a side constant over the overlap: its variance is the sums' rounding (< 1e-10 of
    # its sum of squares), and r is 0 as where the loop's norm was 0
    live = (var_a > CONSTANT * s_aa) & (var_b > CONSTANT * s_bb)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(live, (s_ab - s_a * s_b / m) / np.sqrt(var_a * var_b), 0.0)
    best = int(np.argmax(r))
    return int(lags[best]), float(r[best])


def _cutoff(q, coherence, threshold) -> Optional[float]:
    """``q_c`` of the curve (module docstring)."""
    above = np.flatnonzero(coherence >= threshold)
    if above.size == 0:
        return float(q[0])
    k = int(above[-1])
    if k == q.size - 1:
        return None
    g0, g1 = coherence[k], coherence[k + 1]
    f = (g0 - threshold) / (g0 - g1)
    return float(np.exp(np.log(q[k]) + f * (np.log(q[k + 1]) - np.log(q[k]))))


def _phase_delay(k, cross, coherence, n, reliable) -> float:
    """Sub-sample delay ``delta`` (samples) from ``arg <X Y*> = 2 pi k delta / n`` over
    the wavenumbers ``reliable`` (weighted least squares through the origin)."""
    if not np.any(reliable):
        return 0.0
    phase = np.unwrap(np.angle(cross[reliable]))
    omega = 2 * np.pi * k[reliable] / n
    g = np.clip(coherence[reliable], 0.0, 1.0 - 1e-12)
    w = g / (1.0 - g)
    return float(np.sum(w * omega * phase) / np.sum(w * omega * omega))


def _check_pair(first, second, axis):
    check_instance("first", first, Surface, "a Surface (one sweep of the map)")
    check_instance("second", second, Surface, "a Surface (the other sweep)")
    for name, s in (("first", first), ("second", second)):
        if s.ndim != 2:
            raise InputError(f"{name} is a profile (shape {s.shape}); the coherence of two "
                             f"sweeps averages over the lines of a 2D map")
    if first.shape != second.shape:
        raise InputError(f"the two scans must have the same grid, got {first.shape} and "
                         f"{second.shape} points")
    if not np.allclose(first.size, second.size, rtol=1e-9, atol=0.0):
        raise InputError(f"the two scans must have the same physical size, got "
                         f"{first.size} and {second.size} m")
    name = scan_axis_of(first, axis)
    if axis is None and scan_axis_of(second) != name:
        raise InputError(f"the two scans have different scan axes ({name!r} and "
                         f"{scan_axis_of(second)!r}); give axis")
    return name


def trace_retrace_coherence(first: Surface, second: Surface, axis=None,
                            threshold: float = THRESHOLD,
                            max_lag=None) -> TraceRetraceCoherence:
    """Coherence of two scans of the same area along the fast axis and the reliability
    cutoff ``q_c`` (module docstring: the formula, the threshold's derivation, the steps).

    Parameters
    ----------
    first, second : Surface
        The two sweeps (trace and retrace), maps of the same grid and physical size (m).
    axis : {"x", "y"}, optional
        The fast axis (:func:`~roughfe.surfaces.scan_lines.scan_axis_of`: default the
        first's metadata ``scan_axis``, else ``"x"``, lines ``heights[:, j]``).
    threshold : float
        ``gamma^2`` that defines ``q_c``, in (0, 1) (default :data:`THRESHOLD` = 1/4,
        surface power = noise power).
    max_lag : int, optional
        Largest ``|lag|`` searched (samples; default an eighth of the points per line).

    Returns
    -------
    TraceRetraceCoherence

    Raises
    ------
    InputError
        Not two maps, different grids or sizes, a threshold outside (0, 1), a
        ``max_lag`` that leaves fewer than :data:`MIN_POINTS` points per line, or fewer
        lines than :func:`minimum_lines`.
    """
    name = _check_pair(first, second, axis)
    threshold = check_in_open_interval("threshold (coherence gamma^2)", threshold, 0.0, 1.0)
    a, b = _lines_of(first, name), _lines_of(second, name)
    n_x, lines = a.shape
    dx = first.spacing[0 if name == "x" else 1]
    max_lag = n_x // 8 if max_lag is None else check_int("max_lag (samples)", max_lag, 0)
    if n_x - max_lag < MIN_POINTS:
        raise InputError(f"lines of {n_x} points with max_lag {max_lag} leave "
                         f"{n_x - max_lag} points to compare; at least {MIN_POINTS} are "
                         f"needed (a smaller max_lag, or longer lines)")
    need = minimum_lines(n_x - max_lag, threshold)
    if lines < need:
        raise InputError(f"{lines} lines along {name} are too few: with fewer than {need} "
                         f"lines, two independent noise scans reach coherence {threshold:g} "
                         f"at one of their wavenumbers with probability above "
                         f"{FALSE_ALARM:g}")
    lag, correlation = _best_lag(column_fits_removed(a, tilt=True),
                                 column_fits_removed(b, tilt=True), max_lag)
    n = n_x - abs(lag)
    a = column_fits_removed(a[max(0, -lag): n_x - max(0, lag)], tilt=True)
    b = column_fits_removed(b[max(0, lag): n_x - max(0, -lag)], tilt=True)
    w = _window("hann", (n,))[:, None]
    fa, fb = np.fft.rfft(a * w, axis=0), np.fft.rfft(b * w, axis=0)
    cross = np.mean(fa * fb.conj(), axis=1)[1:]
    paa = np.mean(fa.real ** 2 + fa.imag ** 2, axis=1)[1:]
    pbb = np.mean(fb.real ** 2 + fb.imag ** 2, axis=1)[1:]
    with np.errstate(divide="ignore", invalid="ignore"):
        coherence = np.where(paa * pbb > 0, np.abs(cross) ** 2 / (paa * pbb), 0.0)
        coherence = np.clip(coherence, 0.0, 1.0)
        root = np.sqrt(coherence)
        snr = np.where(root < 1, root / (1 - root), np.inf)
    k = np.arange(1, n // 2 + 1)
    q = k * 2 * np.pi / (n * dx)
    q_c = _cutoff(q, coherence, threshold)
    reliable = q < (np.inf if q_c is None else q_c)
    reliable &= np.cumprod(coherence >= threshold).astype(bool)   # the band from q[0] on
    delta = _phase_delay(k, cross, coherence, n, reliable)
    return TraceRetraceCoherence(
        q=q, coherence=coherence, snr=snr, threshold=threshold, q_cutoff=q_c,
        lag=float(lag + delta), integer_lag=int(lag), correlation=float(correlation),
        spacing=float(dx), lines=int(lines), points=int(n), axis=name)


def slope_share_above(surface: Surface, q_cutoff: float, direction="x",
                      window="auto") -> float:
    """Share of the mean-square slope along ``direction`` carried by ``|q| > q_cutoff``.

    With ``C_x(q)`` the mean PSD of the lines along x
    (:func:`~roughfe.surfaces.line_psd.line_power_spectrum`, m^3; ``"y"``: the lines
    along y, across the fast-scan lines of a map scanned along x)::

        s_x(q_c) = int_{q > q_c} q^2 C_x(q) dq / int_0^inf q^2 C_x(q) dq     (-),

    the sums over the line PSD's wavenumbers with its ``weight``. The denominator is the
    mean over the lines of their spectral mean-square slope ``<(dh/dx)^2>`` (-, from
    ``q`` in rad/m and ``C`` in m^3); a wave ``a sin(q x)`` adds ``a^2 q^2 / 2`` to it.
    It is spectral, not a difference quotient (module :mod:`roughfe.surfaces.stats`);
    with the Hann window of a non-periodic map (``window="auto"``) it is that of the
    windowed lines (without it the jumps between the ends of di-1's lines put 82 % of
    the slope along x above its cutoff instead of 7.8 %).

    Parameters
    ----------
    surface : Surface
        A map, or a profile (``direction="x"`` only).
    q_cutoff : float
        ``q_c`` (rad/m), finite and > 0 (e.g. :attr:`TraceRetraceCoherence.q_cutoff`); a
        cutoff at or above the Nyquist wavenumber gives 0, one below the lowest gives 1.
    direction : {"x", "y"}
        The lines' direction, as :func:`~roughfe.surfaces.line_psd.line_power_spectrum`.
    window : {"auto", "hann", "none", None}
        As :func:`~roughfe.surfaces.line_psd.line_power_spectrum`.

    Returns
    -------
    float
        ``s`` in [0, 1]; NaN when the lines have no slope at all (flat along
        ``direction``).

    Raises
    ------
    InputError
        ``q_cutoff`` not a finite positive number, or a bad surface, direction or window.
    """
    q_cutoff = check_finite_positive("q_cutoff (rad/m)", q_cutoff)
    psd = line_power_spectrum(surface, direction, window)
    slope = psd.q ** 2 * psd.C * psd.weight
    total = float(np.sum(slope))
    if not total > 0:
        return float("nan")
    return float(np.sum(slope[psd.q > q_cutoff]) / total)
