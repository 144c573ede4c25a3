"""Statistics of rough profiles and surfaces: PSD, spectral moments, Nayak, rms, Hurst.

Normalisation of the power spectral density (stated once, used everywhere)
--------------------------------------------------------------------------
With the discrete Fourier coefficients of the mean-free heights

    h~(q) = (1/N) sum_j h_j exp(-i q . x_j),      N = number of grid points,

and the angular wavevectors ``q = 2 pi k / L`` (rad/m) of the periodic box, Parseval's
identity is ``<h^2> = sum_{q != 0} |h~(q)|^2``. The PSD is the density of that sum per
unit (angular) wavevector:

* profile:  ``C(q) = |h~(q)|^2 / dq`` with ``dq = 2 pi / L`` (unit m^3), so that
  ``<h^2> = integral_{-inf}^{inf} C(q) dq``;
* surface:  ``C(q) = |h~(q)|^2 / (dqx dqy)`` with ``dqx dqy = 4 pi^2 / A`` (unit m^4), so
  that ``<h^2> = integral C(q) d^2q``; the radial average ``C(|q|)`` is the mean of
  ``C(q)`` over an annulus (``<h^2> ~ integral 2 pi q C(q) dq`` for isotropic surfaces).

:class:`PowerSpectrum` returns ``q > 0`` only, the values ``C`` (two-sided convention,
``C(q) = C(-q)``) and the q-space ``weight`` each value stands for (``2 dq``; ``dq`` for
the Nyquist wavenumber; ``N_bin dqx dqy`` for an annulus), so that
``sum(C * weight) == <h^2> - <h>^2`` holds exactly (tested) for periodic data
(``window="none"``). With the Hann window of non-periodic data it holds for the windowed
heights, and for the heights themselves only in expectation over stationary data (white
noise: 1.00); a window shorter than the data's long waves sees less: the mean square of
the PSD is 0.54 of the variance of 512-point windows of H = 0.8 profiles (0.91 after a
line is removed), 0.17-1.3 on the five measured files (docs/theory/01).

This is Persson's convention (Persson et al., J. Phys.: Condens. Matter 17, R1, 2005:
``<h^2> = integral C d^2q``), the one of :mod:`roughfe.theory.persson`. Jacobs, Junge &
Pastewka (Surf. Topogr. Metrol. Prop. 5, 013001, 2017), SurfaceTopography and
contact.engineering take the continuous transform ``int h(x) exp(-i q x) dx`` and
``C = |.|^2 / L`` (``/ A``), with ``<h^2> = (1/pi) int_0^inf C dq`` (profile) and
``(1/2 pi) int_0^inf q C dq`` (surface): the same units, values ``(2 pi)^d`` times ours
(6.28 for a profile, 39.5 for a surface; :attr:`PowerSpectrum.C_jacobs`). Until round 2,
session 34 this docstring called ours their convention.

Spectral moments follow Nayak (1971) for an isotropic surface, ``m_n`` being the moments
of a profile cut in any direction: profile ``m_n = sum q^n |h~|^2``; surface
``m0 = sum |h~|^2``, ``m2 = (1/2) sum |q|^2 |h~|^2``, ``m4 = (3/8) sum |q|^4 |h~|^2``
(the averages of cos^2 and cos^4 over the direction); see :func:`spectral_moments` for
how they are evaluated on non-periodic data. Nayak's bandwidth parameter is
``alpha = m0 m4 / m2^2`` (>= 1.5 for a surface; large for broad spectra).

The Hurst exponent is fitted on the PSD by the weighted Whittle likelihood of a power law
(every decade of q weighted alike; unbiased, unlike least squares on log C): a
self-affine profile has ``C ~ q^-(1+2H)``, a surface ``C ~ q^-2(1+H)``; the fractal
dimension is ``D = d + 1 - H`` with ``d`` the topological dimension (1 or 2),
as in the thesis text after Eq. (2.1).
"""
from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Optional

import numpy as np

from ..errors import InputError, check_finite_positive, check_instance
from ..frozen import ReadOnlyArrays, read_only_arrays
from .iso_slope import rms_slope_iso
from .surface import Surface


# -- wavevectors ---------------------------------------------------------------------------
def angular_wavevectors(shape, size):
    """Angular wavevector components of the periodic box, FFT ordering, rad/m.

    Returns one array per axis, broadcastable to ``shape`` (``q_x`` along axis 0).
    """
    shape, size = tuple(shape), tuple(size)
    out = []
    for axis, (n, length) in enumerate(zip(shape, size)):
        q = 2 * np.pi * np.fft.fftfreq(n, d=length / n)
        out.append(q.reshape([-1 if a == axis else 1 for a in range(len(shape))]))
    return tuple(out)


#: points per side a Hann window needs (it is zero on both ends of a side of 2)
HANN_MIN_POINTS = 3


def _window(name, shape):
    if name is None or name == "none":
        return None
    if name != "hann":
        raise InputError(f"window must be None, 'none' or 'hann', got {name!r}")
    if min(shape) < HANN_MIN_POINTS:
        raise InputError(f"a Hann window needs at least {HANN_MIN_POINTS} points per side "
                         f"(it is zero on 2), "
                         f"got shape {tuple(shape)}; use window='none'")
    w = np.ones(shape)
    for axis, n in enumerate(shape):
        w1 = np.hanning(n).reshape([-1 if a == axis else 1 for a in range(len(shape))])
        w = w * w1
    return w / np.sqrt(np.mean(w ** 2))     # keeps the mean-square height of white noise


def _fourier_power(surface: Surface, window):
    """``|h~(q)|^2`` of the mean-free (optionally windowed) heights, and the wavevectors."""
    h = surface.heights - surface.heights.mean()
    w = _window(window, h.shape)
    if w is not None:
        h = h * w
        h = h - h.mean()
    power = np.abs(np.fft.fftn(h) / h.size) ** 2
    return power, angular_wavevectors(h.shape, surface.size)


def rfft_full_sum(values, n_last: int) -> float:
    """Sum over all modes of a quantity given on the ``rfftn`` half-spectrum of a real
    grid whose last axis has ``n_last`` points: the interior columns stand for two modes
    (q and -q), column 0 and, for even ``n_last``, the Nyquist column for one."""
    total = 2.0 * float(values.sum()) - float(values[..., 0].sum())
    if n_last % 2 == 0:
        total -= float(values[..., -1].sum())
    return total


def periodic_moment(heights, size, order: int) -> float:
    """``sum |q|^(2 order) |h~(q)|^2`` over all q of periodic ``heights`` (m) of physical
    ``size`` (m) (order >= 1), from the real FFT (half the modes; the interior columns of
    the last axis stand for two), with in-place passes: one complex half-spectrum and
    one real half-grid in memory (a 8192^2 surface needs 1 GB here instead of ~4 GB
    through the full FFT)."""
    h = heights
    spec = np.fft.rfftn(h)
    power = np.abs(spec)
    del spec
    power *= power
    power /= float(h.size) ** 2
    qs = list(angular_wavevectors(h.shape, size))
    m = h.shape[-1]
    qs[-1] = qs[-1][..., : m // 2 + 1]
    q2 = np.zeros(power.shape)
    for q in qs:
        q2 += q ** 2
    if order > 1:
        q2 **= order
    power *= q2
    del q2
    return rfft_full_sum(power, m)


def _check_surface(surface):
    check_instance("surface", surface, Surface, "a roughfe Surface (roughfe.surfaces.Surface)")


def _default_window(surface, window):
    if window == "auto":
        return None if surface.periodic else "hann"
    return window


# -- PSD -----------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)      # arrays: == compared them and raised ValueError
class PowerSpectrum(ReadOnlyArrays):
    """One-sided view of a (radially averaged) PSD; see the module docstring.

    Attributes
    ----------
    q : ndarray
        Angular wavenumbers > 0 (rad/m); for surfaces the mean ``|q|`` of each annulus.
    C : ndarray
        PSD values: m^3 (profile) or m^4 (surface), Persson's normalisation
        (``(2 pi)^-ndim`` times SurfaceTopography's: :attr:`C_jacobs`).
    weight : ndarray
        q-space measure of each value (rad/m or rad^2/m^2): ``sum(C*weight) = <h^2>``.
    ndim : int
        1 (profile) or 2 (surface).
    window : str
        Window applied before the FFT (``"none"`` or ``"hann"``).
    q2 : ndarray or None
        Power-weighted mean ``|q|^2`` of the modes behind each value (rad^2/m^2), so that
        ``sum(q2 * C * weight) = <|grad h|^2>`` exactly; ``q**2`` when None (a profile,
        or a spectrum given by its values). An annulus' mean ``|q|`` squared is 1-2 %
        below it on 32^2-128^2 grids.
    """

    q: np.ndarray
    C: np.ndarray
    weight: np.ndarray
    ndim: int
    window: str
    q2: Optional[np.ndarray] = None

    def __post_init__(self):       # a result never changes: its arrays read-only
        read_only_arrays(self)     # in place (copies: +0.45 GB at 4096^2 Reynolds)

    @property
    def mean_square(self) -> float:
        """``sum(C * weight)``: the mean-square height (m^2) by Parseval; exact for
        periodic data, of the windowed heights with a window (module docstring)."""
        return float(np.sum(self.C * self.weight))

    @property
    def C_jacobs(self) -> np.ndarray:
        """``C`` in the convention of Jacobs, Junge & Pastewka (2017), SurfaceTopography
        and contact.engineering (m^3 or m^4): ``(2 pi)^ndim C`` (module docstring); the
        values to compare with their PSD at the same ``q``."""
        return (2 * np.pi) ** self.ndim * self.C

    @property
    def q_squared(self) -> np.ndarray:
        """``q2``, or ``q**2`` without it (rad^2/m^2)."""
        return self.q ** 2 if self.q2 is None else self.q2


def line_spectrum(power, n: int, length: float, label: str) -> PowerSpectrum:
    """Profile PSD from ``power`` = ``|h~(k)|^2`` at ``k = 0 .. n // 2`` of lines of ``n``
    points and ``length`` (m): ``C = power / dq`` at ``q = k dq > 0``, ``dq = 2 pi / L``,
    weight ``2 dq`` (``dq`` for an even grid's Nyquist coefficient: no mirror image)."""
    dq = 2 * np.pi / length
    k = np.arange(1, n // 2 + 1)
    weight = np.full(k.size, 2 * dq)
    if n % 2 == 0:
        weight[-1] = dq
    return PowerSpectrum(q=k * dq, C=power[k] / dq, weight=weight, ndim=1, window=label)


def power_spectrum(surface: Surface, window="auto", bin_width=None) -> PowerSpectrum:
    """PSD of a profile, or radially averaged PSD of a surface (normalisation above).

    Parameters
    ----------
    surface : Surface
    window : {"auto", "hann", None}
        ``"auto"``: none for periodic data, a Hann window (normalised to keep the
        mean-square height) for non-periodic data, which otherwise leak the edge jump
        as a spurious ``q^-2`` tail.
    bin_width : float, optional
        Surfaces: width ``w`` (rad/m) of the annuli ``[(k - 1/2) w, (k + 1/2) w)``,
        ``k >= 1``; default ``2 pi / max(Lx, Ly)``. Each annulus reports the mean ``|q|``
        of its Fourier modes.

    Returns
    -------
    PowerSpectrum
    """
    _check_surface(surface)
    window = _default_window(surface, window)
    power, qs = _fourier_power(surface, window)
    label = "none" if window is None else window
    if surface.ndim == 1:
        return line_spectrum(power[: power.size // 2 + 1], power.size, surface.size[0], label)
    cell = float(np.prod([2 * np.pi / s for s in surface.size]))
    qabs = np.sqrt(qs[0] ** 2 + qs[1] ** 2).ravel()
    p = power.ravel()
    width = 2 * np.pi / max(surface.size) if bin_width is None else bin_width
    width = check_finite_positive("bin_width (rad/m)", width)
    idx = np.floor(qabs / width + 0.5).astype(int)          # annulus k: [(k-1/2)w, (k+1/2)w)
    nbins = int(idx.max()) + 1
    keep = qabs > 0
    idx, qk, pk = idx[keep], qabs[keep], p[keep]
    count = np.bincount(idx, minlength=nbins).astype(float)
    qsum = np.bincount(idx, weights=qk, minlength=nbins)
    psum = np.bincount(idx, weights=pk, minlength=nbins)
    q2sum = np.bincount(idx, weights=qk * qk * pk, minlength=nbins)
    full = count > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        q2 = np.where(psum > 0, q2sum / psum, (qsum / np.maximum(count, 1)) ** 2)[full]
    return PowerSpectrum(q=qsum[full] / count[full], C=psum[full] / count[full] / cell,
                         weight=count[full] * cell, ndim=2, window=label, q2=q2)


# -- moments and rms values ------------------------------------------------------------
def spectral_moments(surface: Surface):
    """Nayak's spectral moments ``(m0, m2, m4)`` (m^2, dimensionless, m^-2).

    Profile: ``m_n = sum q^n |h~|^2``. Surface (isotropic average over the direction of
    a profile cut): ``m0 = sum |h~|^2``, ``m2 = 1/2 sum |q|^2 |h~|^2``,
    ``m4 = 3/8 sum |q|^4 |h~|^2``. By Parseval these are ``m0 = Rq^2`` and, for a
    profile, ``m2 = <h'^2>``, ``m4 = <h''^2>``; for a surface ``m2 = <|grad h|^2> / 2``
    and ``m4 = 3/8 <(lap h)^2> = 3/2 <(lap h / 2)^2>``. They are computed through those
    identities from :func:`rms_height`, :func:`rms_slope` and :func:`rms_curvature`,
    i.e. spectrally for periodic data and by finite differences for non-periodic data
    (whose spectral derivatives would be dominated by the jump at the edges).
    """
    _check_surface(surface)
    m0 = rms_height(surface) ** 2
    slope2, curv2 = rms_slope(surface) ** 2, rms_curvature(surface) ** 2
    if surface.ndim == 1:
        return m0, slope2, curv2
    return m0, 0.5 * slope2, 1.5 * curv2


def rms_height(surface: Surface) -> float:
    """Root-mean-square height about the mean, Rq/Sq (m)."""
    _check_surface(surface)
    return float(np.std(surface.heights))


def rms_slope(surface: Surface) -> float:
    """Rms slope: profile ``sqrt<h'^2>``; surface rms gradient ``sqrt<|grad h|^2>``.

    Periodic data: exact derivative of the Fourier interpolant (``sqrt(m2)`` for a
    profile, ``sqrt(2 m2)`` for a surface). Non-periodic data: forward differences (the
    spectral derivative would see the jump at the edge). ISO 4287's Rdq / Sdq (7-point
    derivative): :func:`~roughfe.surfaces.iso_slope.rms_slope_iso`.
    """
    _check_surface(surface)
    if surface.periodic:
        return float(np.sqrt(periodic_moment(surface.heights, surface.size, 1)))
    h = surface.heights
    return float(np.sqrt(sum(np.mean((np.diff(h, axis=a) / d) ** 2)
                             for a, d in enumerate(surface.spacing))))


def rms_curvature(surface: Surface) -> float:
    """Rms curvature (1/m): profile ``sqrt<h''^2>``; surface rms mean curvature
    ``sqrt<(lap h / 2)^2>``.

    Periodic: Fourier interpolant; non-periodic: second central differences inside (NaN
    when a side has fewer than 3 points: no inner point).
    """
    _check_surface(surface)
    factor = 1.0 if surface.ndim == 1 else 0.5
    if surface.periodic:
        return factor * float(np.sqrt(periodic_moment(surface.heights, surface.size, 2)))
    h = surface.heights
    if min(h.shape) < 3:
        return float("nan")
    inner = tuple(slice(1, -1) for _ in range(h.ndim))
    lap = np.zeros_like(h[inner])
    for a, d in enumerate(surface.spacing):
        sl = [slice(1, -1)] * h.ndim
        lo, hi = list(sl), list(sl)
        sl[a], lo[a], hi[a] = slice(1, -1), slice(0, -2), slice(2, None)
        lap += (h[tuple(hi)] - 2 * h[tuple(sl)] + h[tuple(lo)]) / d ** 2
    return factor * float(np.sqrt(np.mean(lap ** 2)))


def peak_to_valley(surface: Surface) -> float:
    """Peak-to-valley amplitude ``max h - min h`` (m), Rt/Sz-like."""
    _check_surface(surface)
    return float(np.ptp(surface.heights))


# -- Hurst exponent ----------------------------------------------------------------------
@dataclass(frozen=True)
class HurstFit:
    """Power-law fit ``C(q) = prefactor * q**slope`` of the PSD over ``q_range``.

    ``hurst`` from ``slope = -(1 + 2H)`` (profile) or ``-2(1 + H)`` (surface);
    ``fractal_dimension = d + 1 - H``. ``success`` is False when fewer than 3 PSD points
    fall in the range or H leaves (0, 1) (the surface is then not self-affine there);
    ``q_range`` is NaN when no range was fitted. ``message`` adds the note of
    :func:`~roughfe.surfaces.psd_fit.split_fit` when the range is not one power law.
    ``hurst_error`` is the standard error of ``hurst`` (-) for a Gaussian self-affine
    surface (:func:`~roughfe.surfaces.psd_fit.hurst_error`; NaN without a fit).
    """

    hurst: float
    fractal_dimension: float
    slope: float
    prefactor: float
    q_range: tuple
    npoints: int
    success: bool
    message: str
    hurst_error: float = float("nan")


#: PSD values below this fraction of the spectrum's largest are round-off of the heights
#: (1e-10 of them in amplitude; float64 transforms leave ~1e-30 of the power in modes a
#: band-limited surface does not hold) and are left out of :func:`fit_hurst`
PSD_ROUNDOFF = 1e-20


def fit_hurst(surface: Surface, q_range=None, window="auto") -> HurstFit:
    """Fit the Hurst exponent on the (radially averaged) PSD: a power law ``C = A q^s``
    by the weighted Whittle likelihood
    (:func:`~roughfe.surfaces.psd_fit.whittle_power_law`), each decade of q weighted
    alike; ``hurst_error`` is its statistical error
    (:func:`~roughfe.surfaces.psd_fit.hurst_error`).

    Parameters
    ----------
    surface : Surface
    q_range : (float, float), optional
        Angular wavenumbers (rad/m) bounding the fit. Default: from ``4 * 2 pi / L``
        (the few longest waves are too few to average) to half the Nyquist wavenumber
        (``pi / (2 dx)``, where grid-scale artefacts of generators and instruments live).
        Modes with round-off power (beyond a band-limited surface's cut-off:
        :data:`PSD_ROUNDOFF`) are left out.
    window : see :func:`power_spectrum`.

    Returns
    -------
    HurstFit
    """
    _check_surface(surface)
    if q_range is None:
        qlo, qhi = 4 * 2 * np.pi / max(surface.size), np.pi / (2 * max(surface.spacing))
        if qlo >= qhi:      # (it reported this empty range, low > high, as q_range)
            return HurstFit(np.nan, np.nan, np.nan, np.nan, (np.nan, np.nan), 0, False,
                            f"grid too small for the default q_range: 8 pi / L = {qlo:.3g} is not "
                            f"below pi / (2 dx) = {qhi:.3g} rad/m (needs > 16 points per side); give q_range")
        q_range = (qlo, qhi)
    try:
        qlo, qhi = (float(v) for v in q_range)
    except (TypeError, ValueError):
        raise InputError(f"q_range must be two wavenumbers (q_min, q_max) in rad/m, got "
                         f"{q_range!r}") from None
    if not (0 < qlo < qhi):
        raise InputError(f"q_range must satisfy 0 < q_min < q_max (rad/m), got {q_range!r}")
    psd = power_spectrum(surface, window=window)
    from .psd_fit import (fit_points, hurst_error, independent_modes, split_fit,
                          whittle_power_law)        # (they import this module)
    sel, weight = fit_points(psd, (qlo, qhi))
    n = int(sel.sum())
    if n < 3:      # a flat surface said "only 0 PSD points in q_range; widen it" (s. 37)
        return HurstFit(np.nan, np.nan, np.nan, np.nan, (qlo, qhi), n, False,
                        f"only {n} PSD points in q_range; widen it" if np.any(psd.C > 0)
                        else "the surface is flat (its PSD is zero): no power law to fit")
    q, c = psd.q[sel], psd.C[sel]
    if q[-1] <= q[0] * 10 ** 0.1:
        return HurstFit(np.nan, np.nan, np.nan, np.nan, (qlo, qhi), n, False,
                        "q_range spans less than 0.1 decade of PSD points; widen it")
    slope, prefactor = whittle_power_law(q, c, weight)
    d = surface.ndim
    hurst = -slope / 2 - 1 if d == 2 else (-slope - 1) / 2
    ok = 0 < hurst < 1
    note = split_fit(psd, (qlo, qhi), surface.size).note     # "" when one power law
    return HurstFit(float(hurst), float(d + 1 - hurst), float(slope), float(prefactor),
                    (qlo, qhi), n, bool(ok), ("fit converged" if ok else f"H = {hurst:.3f} "
                    "outside (0, 1): not self-affine") + (f"; {note}" if note else ""),
                    hurst_error(psd, q, weight, independent_modes(psd, sel, surface.size)))


# -- everything at once ------------------------------------------------------------------
@dataclass(frozen=True)
class SurfaceStatistics:
    """Summary statistics of a profile or surface (SI units; see each function).

    ``hurst``/``fractal_dimension`` come from :func:`fit_hurst`; ``hurst_success`` is
    False when the fitted H is outside (0, 1) (the data are not self-affine there).
    """

    ndim: int
    shape: tuple
    size: tuple
    periodic: bool
    mean: float
    rms_height: float
    rms_slope: float
    rms_curvature: float
    peak_to_valley: float
    skewness: float
    kurtosis: float
    m0: float
    m2: float
    m4: float
    nayak_alpha: float
    hurst: float
    fractal_dimension: float
    hurst_q_range: tuple
    hurst_success: bool
    hurst_message: str = ""       # HurstFit.message: why not, or a range not one power law
    hurst_error: float = float("nan")     # HurstFit.hurst_error: its standard error
    rms_slope_iso: float = float("nan")   # Rdq/Sdq, ISO 7-point derivative (iso_slope)

    def as_dict(self) -> dict:
        """JSON-safe dict (NaN becomes None: :func:`roughfe.writers.to_jsonable`)."""
        from ..writers import to_jsonable
        return to_jsonable(asdict(self))


def height_moments(surface: Surface) -> tuple:
    """Skewness and kurtosis of the heights about their mean (-; a Gaussian surface has
    0 and 3), NaN for a flat surface."""
    h = np.asarray(surface.heights, float)
    dev = h - h.mean()
    rq = float(np.sqrt(np.mean(dev ** 2)))
    if not rq > 0:
        return float("nan"), float("nan")
    return float(np.mean(dev ** 3)) / rq ** 3, float(np.mean(dev ** 4)) / rq ** 4


def surface_statistics(surface: Surface, q_range=None) -> SurfaceStatistics:
    """All statistics of this module for one surface (see the module docstring)."""
    _check_surface(surface)
    h = surface.heights
    rq = rms_height(surface)
    skewness, kurtosis = height_moments(surface)
    m0, m2, m4 = spectral_moments(surface)
    fit = fit_hurst(surface, q_range=q_range)
    return SurfaceStatistics(
        ndim=surface.ndim, shape=tuple(int(n) for n in surface.shape), size=surface.size,
        periodic=surface.periodic, mean=float(h.mean()), rms_height=rq,
        rms_slope=rms_slope(surface), rms_curvature=rms_curvature(surface),
        peak_to_valley=peak_to_valley(surface),
        skewness=skewness, kurtosis=kurtosis,
        m0=m0, m2=m2, m4=m4, nayak_alpha=m0 * m4 / m2 ** 2 if m2 > 0 else float("nan"),
        hurst=fit.hurst, fractal_dimension=fit.fractal_dimension, hurst_q_range=fit.q_range,
        hurst_success=fit.success, hurst_message=fit.message, hurst_error=fit.hurst_error,
        rms_slope_iso=rms_slope_iso(surface))
