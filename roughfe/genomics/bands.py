"""Chromosomes of any surface: annuli of its Fourier transform (beyond thesis Sec. 3.3.2).

The thesis defines chromosome n of a Weierstrass-Mandelbrot (WM/MWM) genome as the sum of
the M ridge waves of wavenumber q_n = 2 pi gamma^(n-1) / lambda1 (Eq. 3.5-3.7). A measured
topography has a continuous spectrum, not a lattice of wavenumbers; the same idea carries
over as a *band* decomposition:

    C_n(x) = IFFT[ h~(q) * 1{ q_n <= |q| < gamma q_n } ],     q_n = q_1 gamma^(n-1),

chromosome n is the part of the 2D (or 1D) discrete Fourier transform of the detrended
heights whose wavevector magnitude lies in the annulus [q_n, gamma q_n). Because the
annuli partition the wavevectors (the mean, q = 0, is removed by the detrending):

* the chromosomes sum *exactly* to the detrended heights (linearity of the inverse FFT);
* they are mutually orthogonal, so their mean-square heights add up to <h^2> (Parseval):
  ``energy`` is the variance budget per band;
* the top-down (TD) and bottom-up (BU) partial sums of the thesis (Sec. 3.2.2) are
  cumulative sums over n.

Transform. A periodic surface is decomposed with the discrete Fourier transform (FFT), whose
bins are its exact periodic modes. A non-periodic window (every measured topography) is
decomposed with the type-II discrete cosine transform (DCT), i.e. the FFT of its even
(mirrored) extension, bins at |q| = pi sqrt((k_x/L_x)^2 + (k_y/L_y)^2): the mirrored
extension has no jump at the window's edges, so the leakage of a wave into distant bands
decays as 1/q^2 instead of the 1/q of the FFT's periodic extension (measured on MWM
realisations: FFT band misfits 0.5-3.7, DCT 0.14-0.6 in the bands away from the ends).
Both transforms are orthonormal, so the exact sum and the energy budget hold for both.

For an MWM realisation each band holds its WM chromosome up to the spectral leakage of the
window: exact when the WM wavevectors sit on the FFT grid of a periodic box, and otherwise
smeared over neighbouring bins (the window is not a whole number of periods).
:func:`band_leakage` measures it against the true chromosomes. Tapering (Hann) would cut the
leakage further but the chromosomes would then no longer sum to the surface; the
decomposition is therefore done on the un-tapered, detrended heights, and the leakage is
measured and documented (docs/theory/surface-genomics.md), not hidden.

Conventions. Wavenumbers are angular (rad/m). ``q1`` (the lower edge of band 1) defaults to
the smallest non-zero bin of the transform (2 pi / L_max for the FFT, pi / L_max for the
DCT: half a wave across the window), so band 1 holds the longest wave the window can show. To align the bands with a genome (gamma, lambda1) so that each WM wavenumber
q_n sits in the geometric middle of its band, pass ``q1 = 2 pi / lambda1 / sqrt(gamma)``
(:func:`genome_q1`). The last band is cut at the largest wavevector of the grid (the
corner of the Brillouin zone, sqrt(2) times the Nyquist wavenumber on a square grid).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.fft

from ..errors import (InputError, check_finite_positive, check_in_interval, check_instance,
                      check_memory)
from ..surfaces.scan_lines import is_mirrored
from ..surfaces.stats import angular_wavevectors
from ..surfaces.surface import Surface

#: default band ratio gamma of a measured surface (two bands per octave)
DEFAULT_GAMMA = float(np.sqrt(2.0))
DETREND_MODES = ("none", "mean", "plane", "lines", "lines-tilt")   # Surface.detrended
TRANSFORMS = ("auto", "fft", "dct")
#: relative slack when a wavevector lies on a band edge (it goes to the upper band)
_EDGE_SLACK = 1e-9

REFERENCES = (
    "thesis Sec. 3.2-3.3 (chromosomes, TD/BU partial sums), extended to continuous spectra",
)


def _readonly(a):
    a = np.asarray(a)
    a.setflags(write=False)
    return a


def genome_q1(gamma: float, lambda1: float) -> float:
    """Lower edge (rad/m) of band 1 that centres the WM wavenumber q_1 = 2 pi / lambda1
    geometrically in its band: q1 = q_1 / sqrt(gamma)."""
    gamma = _check_gamma(gamma)
    lambda1 = check_finite_positive("lambda1 (reference wavelength, m)", lambda1)
    return 2.0 * np.pi / lambda1 / np.sqrt(gamma)


def _check_gamma(gamma):
    return check_in_interval("gamma (band ratio)", gamma, 1, 10, "right")


def wavevector_magnitude(shape, size, transform: str = "fft") -> np.ndarray:
    """|q| (rad/m) of every bin of the FFT (``size`` = the periodic box) or of the type-II
    DCT (``size`` = the window, q_k = pi k / L per axis) of a grid of ``shape``."""
    if transform == "fft":
        qs = angular_wavevectors(shape, size)
    else:
        qs = [np.pi * np.arange(n) / length for n, length in zip(shape, size)]
        qs = [q.reshape([-1 if a == i else 1 for a in range(len(shape))])
              for i, q in enumerate(qs)]
    q2 = np.zeros(tuple(shape))
    for q in qs:
        q2 = q2 + q ** 2
    return np.sqrt(q2)


def _transform_pair(transform):
    """Forward and inverse orthonormal transforms (real output for the DCT)."""
    if transform == "fft":
        return scipy.fft.fftn, lambda c: scipy.fft.ifftn(c).real
    return (lambda h: scipy.fft.dctn(h, type=2, norm="ortho"),
            lambda c: scipy.fft.idctn(c, type=2, norm="ortho"))


@dataclass(frozen=True, eq=False)
class BandChromosomes:
    """Band (annulus) chromosomes of a surface (SI units; arrays read-only).

    Attributes
    ----------
    surface : Surface
        The decomposed surface: the input after detrending (heights in m).
    chromosomes : ndarray, shape (n_c, *surface.shape)
        C_n(x) (m), n = ``indices``; they sum exactly to ``surface.heights``.
    q_bounds : ndarray, shape (n_c + 1,)
        Band edges (rad/m): chromosome k holds ``q_bounds[k] <= |q| < q_bounds[k + 1]``.
    indices : ndarray of int
        Chromosome numbers n = 1..n_c (band 1 = the longest waves).
    gamma : float
        Band ratio q_{n+1} / q_n.
    energy : ndarray, shape (n_c,)
        Mean-square height of each chromosome (m^2); sums to the mean square of
        ``surface.heights`` (Parseval, the bands are orthogonal).
    n_bins : ndarray of int, shape (n_c,)
        Number of transform bins in each band (0: an empty band, flat chromosome).
    detrend : str
        Detrending applied before the decomposition ("none", "mean", "plane", "lines"
        or "lines-tilt"; ``roughfe genome chromosomes`` records its ``--detrend``, done on
        reading, before ``--mirror``).
    transform : str
        "fft" (periodic surfaces) or "dct" (non-periodic windows), see the module notes.
    """

    surface: Surface
    chromosomes: np.ndarray
    q_bounds: np.ndarray
    indices: np.ndarray
    gamma: float
    energy: np.ndarray
    n_bins: np.ndarray
    detrend: str
    transform: str
    references: tuple = REFERENCES

    @property
    def n_chromosomes(self) -> int:
        """Number of bands n_c."""
        return int(self.indices.size)

    def wavelengths(self) -> np.ndarray:
        """Band edges as wavelengths 2 pi / q (m), longest first, shape (n_c + 1,)."""
        return 2.0 * np.pi / self.q_bounds

    def partial_sums(self, order: str = "td") -> np.ndarray:
        """Partial sums of the chromosomes (m), shape (n_c, *shape).

        ``order="td"`` (top-down, Sec. 3.2.2): row k = C_1 + ... + C_{k+1}, from the
        waviness down to the finest scale. ``order="bu"`` (bottom-up): row k =
        C_{n_c} + ... + C_{n_c - k}. The last row of both is the complete surface.
        """
        if order == "td":
            return np.cumsum(self.chromosomes, axis=0)
        if order == "bu":
            return np.cumsum(self.chromosomes[::-1], axis=0)
        raise InputError(f"order must be 'td' or 'bu', got {order!r}")

    def as_surface(self, heights) -> Surface:
        """A :class:`Surface` with the grid, size and periodicity of the decomposed one."""
        return self.surface.with_heights(heights)


def _detrended(surface: Surface, detrend: str) -> Surface:
    if detrend not in DETREND_MODES:
        raise InputError(f"detrend must be one of {DETREND_MODES}, got {detrend!r}")
    if detrend == "none":
        return surface
    if detrend in ("lines", "lines-tilt") and is_mirrored(surface):
        raise InputError(f"detrend={detrend!r} levels the measured scan lines; this surface "
                         "is a mirrored window (metadata 'mirrored', or heights even about "
                         "the first row and column, as Surface.mirrored builds them), whose "
                         "lines are not those: level before mirroring "
                         "(surface.detrended('lines').mirrored()) and pass detrend='mean'")
    return surface.detrended(detrend)


def band_edges(q_min: float, q_max: float, gamma: float, q1=None) -> np.ndarray:
    """Geometric band edges q1 gamma^k (rad/m) covering [q_min, q_max].

    ``q1`` defaults to ``q_min``; a larger q1 is shifted down by whole powers of gamma
    (the band numbering still starts at the first band that holds q_min), a smaller one
    up, so band 1 always contains the longest wave of the grid.
    """
    gamma = _check_gamma(gamma)
    q_min = check_finite_positive("q_min (rad/m)", q_min)
    q_max = check_finite_positive("q_max (rad/m)", q_max)
    if q_max < q_min:
        raise InputError(f"q_max = {q_max:g} rad/m is below q_min = {q_min:g} rad/m")
    q1 = q_min if q1 is None else check_finite_positive("q1 (lower band edge, rad/m)", q1)
    k0 = int(np.floor(np.log(q_min / q1) / np.log(gamma) + _EDGE_SLACK))
    start = q1 * gamma ** k0
    n_bands = int(np.floor(np.log(q_max / start) / np.log(gamma) + _EDGE_SLACK)) + 1
    return start * gamma ** np.arange(n_bands + 1)


def band_chromosomes(surface: Surface, gamma: float = DEFAULT_GAMMA, *, q1=None,
                     detrend: str = "plane", transform: str = "auto") -> BandChromosomes:
    """Decompose a surface or profile into band chromosomes (see the module notes).

    Parameters
    ----------
    surface : Surface
        Any profile or surface (measured or synthetic, periodic or not), heights in m.
    gamma : float
        Band ratio (1, 10]; the genome's gamma when known, default sqrt(2).
    q1 : float, optional
        A band edge (rad/m); default the smallest non-zero bin of the transform. Use
        :func:`genome_q1` to centre a genome's WM wavenumbers in their bands.
    detrend : {"plane", "mean", "none", "lines", "lines-tilt"}
        Removed before the decomposition by :meth:`Surface.detrended` (the mean must go:
        q = 0 belongs to no band; with "none" a non-zero mean is an error). "lines" /
        "lines-tilt" level each scan line (along the metadata's ``scan_axis``, default
        x) of a measured map; a mirrored window is refused with them, as its lines are
        not the measured ones: level, mirror, then pass "mean" (as
        ``roughfe genome chromosomes --mirror`` does). A mirrored window is one with the
        metadata ``mirrored`` or, without it, heights even about the first row and
        column bit for bit (:meth:`Surface.mirrored`'s output rebuilt or read back;
        :func:`roughfe.surfaces.scan_lines.is_mirrored`, the CLI's check too); one
        resampled or plane-levelled after mirroring, without the metadata, is not
        recognised.
    transform : {"auto", "fft", "dct"}
        "auto": the FFT for a periodic surface, the DCT (mirrored window) otherwise.

    Returns
    -------
    BandChromosomes
    """
    check_instance("surface", surface, Surface, "a roughfe Surface")
    gamma = _check_gamma(gamma)
    if transform not in TRANSFORMS:
        raise InputError(f"transform must be one of {TRANSFORMS}, got {transform!r}")
    if transform == "auto":
        transform = "fft" if surface.periodic else "dct"
    surf = _detrended(surface, detrend)
    h = surf.heights
    scale = float(np.max(np.abs(h))) if h.size else 0.0
    if scale <= 1e-12 * float(np.max(np.abs(surface.heights))) or scale == 0.0:
        raise InputError("the surface is flat after detrending: it has no chromosomes")
    if detrend == "none" and abs(float(h.mean())) > 1e-9 * scale:
        raise InputError(f"the heights have a mean of {h.mean():.3g} m: the q = 0 mode belongs "
                         "to no band; use detrend='mean' or 'plane' (CLI: --detrend mean or plane)")
    if detrend != "none":     # round-off of the detrending, so that the bands sum exactly
        surf = surf.with_heights(h - h.mean())
        h = surf.heights
    box = tuple(n * d for n, d in zip(surf.shape, surf.spacing))    # n * spacing per axis
    qmag = wavevector_magnitude(surf.shape, box, transform)
    nonzero = qmag > 0
    edges = band_edges(float(qmag[nonzero].min()), float(qmag.max()), gamma, q1)
    band = np.full(qmag.shape, -1, dtype=np.int64)
    band[nonzero] = np.floor(np.log(qmag[nonzero] / edges[0]) / np.log(gamma)
                             + _EDGE_SLACK).astype(np.int64)
    n_c = edges.size - 1
    np.clip(band, -1, n_c - 1, out=band)
    # before the n_c x grid array is made: gamma = 1.0001 made 37808 bands of a 32^2 grid
    # (430 not empty), 1.001 asked 13.6 GiB for a 563 x 484 file
    shells = np.unique(qmag[nonzero]).size
    if n_c > shells:
        raise InputError(f"gamma = {gamma:g} makes {n_c} bands, more than the {shells} "
                         f"distinct wavenumbers of this {' x '.join(map(str, h.shape))} grid "
                         f"(most bands would be empty): choose a larger gamma")
    check_memory(f"{n_c} band chromosomes of a {' x '.join(map(str, h.shape))} grid",
                 2.0 * 8.0 * n_c * h.size)
    forward, inverse = _transform_pair(transform)
    spectrum = forward(h)
    chrom = np.empty((n_c,) + h.shape)
    for k in range(n_c):   # one masked inverse transform per band (n_c ~ 2 log2 N)
        chrom[k] = inverse(np.where(band == k, spectrum, 0.0))
    counts = np.bincount(band[nonzero], minlength=n_c)
    energy = np.mean(chrom.reshape(n_c, -1) ** 2, axis=1)
    return BandChromosomes(
        surface=surf, chromosomes=_readonly(chrom), q_bounds=_readonly(edges),
        indices=_readonly(np.arange(1, n_c + 1)), gamma=gamma, energy=_readonly(energy),
        n_bins=_readonly(counts), detrend=detrend, transform=transform)


def band_leakage(bands: BandChromosomes, reference) -> np.ndarray:
    """Relative rms misfit of each band chromosome against a known decomposition.

    ``reference`` (shape like ``bands.chromosomes``) holds the true chromosomes on the
    same grid (e.g. the WM chromosomes of an MWM realisation, band-aligned with
    :func:`genome_q1`). Returns ``||C_n - R_n|| / ||R_n||`` per band (NaN where R_n = 0):
    the spectral leakage of the window into and out of band n.
    """
    ref = np.asarray(reference, dtype=float)
    if ref.shape != bands.chromosomes.shape:
        raise InputError(f"reference chromosomes have shape {ref.shape}, expected "
                         f"{bands.chromosomes.shape}")
    n = ref.shape[0]
    diff = np.sqrt(np.mean((bands.chromosomes - ref).reshape(n, -1) ** 2, axis=1))
    norm = np.sqrt(np.mean(ref.reshape(n, -1) ** 2, axis=1))
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(norm > 0, diff / norm, np.nan)
