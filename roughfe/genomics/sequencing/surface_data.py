"""Acquisitions, periodogram peaks and ridge directions of 2D MWM sequencing (steps 1-2).

See :mod:`roughfe.genomics.sequencing.surface` for the model and the conventions.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.fft
import scipy.sparse
import scipy.sparse.linalg
from scipy.ndimage import maximum_filter
from scipy.signal.windows import blackmanharris

from ...errors import InputError
from ...surfaces.surface import Surface
from .acquisitions import MIN_NODES, ROWS_PATH, check_kind

#: zero-padding factor of the periodogram
PAD = 4
#: peaks are used below this fraction of the Nyquist wavenumber on both axes
NYQUIST_FRACTION = 0.9
#: single-linkage tolerance of the angle clustering (rad)
ANGLE_TOL = math.radians(1.5)


@dataclass(frozen=True, eq=False)
class SurfaceAcquisition:
    """One 2D acquisition: node coordinates x, y (m), heights z (m; NaN = undefined)."""

    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    length: float

    @property
    def valid(self) -> np.ndarray:
        return np.isfinite(self.z)


def _node_coordinates(surface: Surface, axis: int) -> np.ndarray:
    n = surface.shape[axis]
    d = surface.spacing[axis]
    x0 = surface.metadata.get("y0" if axis == 1 else "x0")
    if axis == 1 and x0 is None:
        x0 = surface.metadata.get("x0")
    x0 = -(n // 2) * d if x0 is None else float(x0)
    return x0 + np.arange(n) * d


def surface_acquisitions(surfaces, valid=None) -> list:
    """Check nested 2D acquisitions; return them sorted coarsest first.

    ``valid`` (optional, one boolean N x N mask per surface, True = defined) marks the
    undefined points of measured acquisitions (a :class:`Surface` holds finite heights
    only: readers fill undefined points, ``metadata["filled_points"]``); they are left out.

    Raises InputError (one message naming the mismatch and what to do) for: a profile
    among them or a periodic surface (:func:`~.acquisitions.check_kind`), different N, non-square grids or unequal spacings, fewer than
    ``MIN_NODES`` nodes, a flat or all-undefined acquisition, equal lengths, or windows that
    are not nested around the origin.
    """
    surfaces = check_kind(surfaces, 2)
    if not surfaces:
        raise InputError("surface sequencing needs at least one acquisition (an N x N "
                         "window), got none")
    shapes = {s.shape for s in surfaces}
    if len(shapes) != 1:
        raise InputError(f"all acquisitions must have the same N x N nodes, got "
                         f"{[s.shape for s in surfaces]}")
    n, n2 = shapes.pop()
    if n != n2:
        raise InputError(f"acquisitions must be square (N x N nodes), got {n} x {n2}: the "
                         f"surface sequencer models N x N windows of Eq. 3.17. Crop a "
                         f"square window (Surface.cropped(index=((0, {min(n, n2)}), (0, "
                         f"{min(n, n2)})))), or {ROWS_PATH}")
    if n < MIN_NODES:
        raise InputError(f"too few points: {n} x {n} nodes, at least {MIN_NODES} per axis")
    if valid is None:
        valid = [None] * len(surfaces)
    valid = list(valid)
    if len(valid) != len(surfaces):
        raise InputError(f"valid must give one mask per acquisition: {len(valid)} masks for "
                         f"{len(surfaces)} acquisitions")
    acq = []
    for k, (s, mask) in enumerate(zip(surfaces, valid)):
        dx, dy = s.spacing
        if abs(dx / dy - 1) > 1e-9:
            raise InputError(f"acquisition {k} has spacings {dx:g} m and {dy:g} m: the node "
                             f"convention of the surface sequencer needs equal spacings on "
                             f"both axes; {ROWS_PATH}")
        z = np.array(s.heights, dtype=float)
        if mask is not None:
            mask = np.asarray(mask)
            if mask.shape != z.shape or mask.dtype != bool:
                raise InputError(f"valid mask {k} must be a boolean array of shape {z.shape}, "
                                 f"got {mask.dtype} {mask.shape}")
            z[~mask] = np.nan
        ok = np.isfinite(z)
        if ok.sum() < 0.5 * z.size:
            raise InputError(f"acquisition {k} has {z.size - ok.sum()} undefined points of "
                             f"{z.size}: at least half must be defined")
        if np.ptp(z[ok]) == 0:
            raise InputError(f"acquisition {k} is flat: there is no roughness to sequence")
        x, y = _node_coordinates(s, 0), _node_coordinates(s, 1)
        acq.append(SurfaceAcquisition(x, y, z, float((n - 1) * dx)))
    acq.sort(key=lambda a: -a.length)
    for a, b in zip(acq, acq[1:]):
        if not b.length < a.length * (1 - 1e-9):
            raise InputError(f"acquisitions must have different observation lengths, got two of "
                             f"{a.length:g} m")
    for k, a in enumerate(acq):
        for c in (a.x, a.y):
            if not (c[0] <= 1e-9 * a.length and c[-1] >= -1e-9 * a.length):
                raise InputError(f"acquisition {k} (L = {a.length:g} m) does not contain the "
                                 f"origin: windows must be nested around x = y = 0")
    return acq


# -- steps 1-3: peaks, ridges, lattice --------------------------------------------------------
@dataclass(frozen=True, eq=False)
class SurfacePeaks:
    """Periodogram peaks of one acquisition: wavevectors (rad/m) and power (m^2 arbitrary)."""

    qx: np.ndarray
    qy: np.ndarray
    power: np.ndarray
    #: white-noise variance of the heights (m^2) from the periodogram's high-q plateau
    noise_variance: float = 0.0

    @property
    def magnitude(self):
        return np.hypot(self.qx, self.qy)

    @property
    def angle(self):
        """Direction mod pi in [0, pi)."""
        return np.mod(np.arctan2(self.qy, self.qx), np.pi)


def _parabola_offset(lm, l0, lp):
    den = lm - 2 * l0 + lp
    return np.where(den < 0, 0.5 * (lm - lp) / np.where(den < 0, den, -1.0), 0.0)


def harmonic_fill(z):
    """``z`` (N x N, NaN = undefined) with every undefined node set to the mean of its
    grid neighbours (the discrete harmonic fill: a sparse Laplace solve with the defined
    nodes as boundary values; an isolated node gets the mean of its 4 neighbours). The
    interpolation the file readers use (SurfaceTopography's ``interpolate_undefined_data``),
    solved directly: 1000x faster at 512^2.

    For the periodogram only: undefined nodes set to zero act as impulsive noise of about
    sqrt(fraction) of the rms height (17 % at 3 % undefined), which raised the noise floor
    and dropped the peaks of a WM surface (measured, 3 % undefined, seeds 0-49: 14 of 50
    at N = 48 and 6 of 50 at N = 64 failed with "only k spectral peaks" or similar). The
    fit leaves the undefined nodes out (:class:`GridModel`)."""
    bad = ~np.isfinite(z)
    out = np.where(bad, 0.0, z)
    if not bad.any():
        return out
    idx = np.full(z.shape, -1)
    idx[bad] = np.arange(int(bad.sum()))
    rows, cols, vals = [], [], []
    diag = np.zeros(int(bad.sum()))
    rhs = np.zeros(int(bad.sum()))
    bi, bj = np.nonzero(bad)
    for di, dj in ((1, 0), (-1, 0), (0, 1), (0, -1)):
        ni, nj = bi + di, bj + dj
        inside = (ni >= 0) & (ni < z.shape[0]) & (nj >= 0) & (nj < z.shape[1])
        k, ni, nj = idx[bi[inside], bj[inside]], ni[inside], nj[inside]
        diag[k] += 1.0
        other = idx[ni, nj]
        unknown = other >= 0
        rows.append(k[unknown])
        cols.append(other[unknown])
        rhs[k[~unknown]] += out[ni[~unknown], nj[~unknown]]
    mat = scipy.sparse.coo_matrix(
        (np.r_[diag, -np.ones(sum(r.size for r in rows))],
         (np.r_[np.arange(diag.size), np.concatenate(rows)],
          np.r_[np.arange(diag.size), np.concatenate(cols)])), shape=(diag.size,) * 2)
    out[bad] = scipy.sparse.linalg.spsolve(mat.tocsc(), rhs)
    return out


def _periodogram(acq: SurfaceAcquisition):
    """(power, noise variance) of :func:`surface_peaks`: the windowed, zero-padded
    periodogram of the heights about their mean (undefined nodes filled) and the white-noise
    variance (m^2) read from its plateau."""
    n = acq.z.shape[0]
    ok = acq.valid
    z = harmonic_fill(acq.z - acq.z[ok].mean())
    w1 = blackmanharris(n)
    window = np.outer(w1, w1)
    power = np.abs(scipy.fft.rfft2(z * window, s=(PAD * n, PAD * n))) ** 2
    m_pad = PAD * n
    high_x = np.abs(np.fft.fftfreq(m_pad)) >= 0.25         # above half the Nyquist wavenumber
    high_y = np.arange(power.shape[1]) >= m_pad // 4
    return power, float(np.median(power[high_x[:, None] | high_y[None, :]])) / (
        math.log(2.0) * float(np.sum(window[ok] ** 2)))


def noise_variance(acq: SurfaceAcquisition) -> float:
    """The white-noise variance (m^2) of :func:`surface_peaks` alone (no peak search)."""
    return _periodogram(acq)[1]


def surface_peaks(acq: SurfaceAcquisition, dynamic_range=1e-9) -> SurfacePeaks:
    """Peaks of the Blackman-Harris windowed, zero-padded periodogram (half plane q_y >= 0).

    A peak is a local maximum over +-3 original bins whose power exceeds both
    ``dynamic_range`` times the largest peak and 30 times the median power (the noise
    floor); sub-bin positions by a parabola in log power along each axis. Undefined nodes
    are filled by :func:`harmonic_fill` first (set to zero they were impulsive noise that
    lifted the median and hid peaks).

    ``noise_variance``: the variance sigma^2 (m^2) of white noise on the heights, from the
    plateau of the periodogram above half the Nyquist wavenumber (|k_x| or |k_y|): there a
    discrete (WM) spectrum holds a few peaks and the window's side lobes (~92 dB down),
    so the median bin is noise. A bin of white noise is complex Gaussian with mean power
    sigma^2 sum(w^2) (the window over the defined nodes; the zero padding adds nothing),
    exponentially distributed: sigma^2 = median / (ln 2 sum(w^2)). On noise-free data it
    is the side-lobe and round-off level; with undefined nodes it includes the error of the
    fill there (white too: impulses at scattered nodes), which the caller must not take
    for noise.
    """
    n = acq.z.shape[0]
    d = acq.x[1] - acq.x[0]
    power, noise = _periodogram(acq)
    m_pad = PAD * n
    size = 2 * 3 * PAD + 1
    is_max = power == maximum_filter(power, size=size, mode="wrap")
    floor = 30.0 * float(np.median(power))
    top = float(power.max())
    cand = np.argwhere(is_max & (power > max(floor, dynamic_range * top)))
    kx = np.where(cand[:, 0] <= m_pad // 2, cand[:, 0], cand[:, 0] - m_pad).astype(float)
    ky = cand[:, 1].astype(float)
    # q and -q are one wave on the q_y = 0 row; the zero bin is the window-weighted mean
    # (the plane columns' share), no wave: told by its bin, not by |q| > 0 after the
    # sub-bin offset, which its mirror-symmetric neighbours leave at round-off (0 or not
    # by the last bits: a fit's residual gained its largest "peak", at angle 0, and the
    # 2D sequencer a ridge there, with OpenBLAS only)
    keep = ~((ky == 0) & (kx <= 0))
    cand, kx, ky = cand[keep], kx[keep], ky[keep]
    lp = np.log(power + 1e-300 * top)
    i, j = cand[:, 0], cand[:, 1]
    dx = _parabola_offset(lp[(i - 1) % m_pad, j], lp[i, j], lp[(i + 1) % m_pad, j])
    jm, jp = np.abs(j - 1), np.minimum(j + 1, lp.shape[1] - 1)
    dy = _parabola_offset(lp[i, jm], lp[i, j], lp[i, jp])
    dq = 2 * np.pi / (m_pad * d)
    qx, qy = (kx + dx) * dq, (ky + dy) * dq
    nyq = NYQUIST_FRACTION * np.pi / d
    inside = (np.abs(qx) < nyq) & (np.abs(qy) < nyq)
    return SurfacePeaks(qx[inside], qy[inside], power[i, j][inside], noise)


def cluster_angles(angles, weights, tol=ANGLE_TOL):
    """Single-linkage clusters of directions mod pi; returns (centres, labels, sizes).

    Centres are weighted circular means (period pi); clusters are ordered by centre.
    """
    a = np.mod(np.asarray(angles, float), np.pi)
    if a.size == 0:
        return np.array([]), np.array([], int), np.array([], int)
    order = np.argsort(a)
    s = a[order]
    gaps = np.diff(np.concatenate([s, [s[0] + np.pi]]))
    cuts = set(np.flatnonzero(gaps > tol).tolist())     # gap after sorted position i
    labels_sorted = np.zeros(a.size, int)
    if cuts:
        start = (min(cuts) + 1) % a.size                 # a cluster may wrap around pi
        lab = 0
        for k in range(a.size):
            idx = (start + k) % a.size
            labels_sorted[idx] = lab
            if idx in cuts:
                lab += 1
    labels = np.empty(a.size, int)
    labels[order] = labels_sorted
    w = np.asarray(weights, float)
    n_cl = labels.max() + 1
    centres = np.array([np.mod(np.angle(np.sum(w[labels == c] * np.exp(2j * a[labels == c])))
                               / 2, np.pi) for c in range(n_cl)])
    sizes = np.bincount(labels, minlength=n_cl)
    rank = np.argsort(centres)
    relabel = np.empty(n_cl, int)
    relabel[rank] = np.arange(n_cl)
    return centres[rank], relabel[labels], sizes[rank]


def resolvable_surface_genome(seed, *, length, n_nodes, n_ridges=3, gamma=1.8, hurst=0.8,
                              ratio=2.5):
    """A random 2D MWM genome the sequencer can resolve, and its two nested acquisitions.

    The genome is in the sequencer's gauge: lambda1 uniform in [L, gamma L) (so n_s = 1 at
    L), anisotropy factors log-normal (sigma 0.3) with geometric mean 1, ridge angles at
    least 0.4 pi / M apart (resolvable at N >= 48), phases uniform; A = 1e-3. The
    acquisitions are :func:`~roughfe.genomics.genome.realize_surface` at L and L / ratio
    with ``n_nodes`` nodes. Used by the sequencing tests and ``roughfe validate
    surface-genomics`` (recovery over seeds, noise table).

    Returns
    -------
    (Genome, [Surface, Surface], numpy.random.Generator)
        The generator continues the seeded stream (e.g. for noise).
    """
    from ..genome import random_genome, realize_surface

    rng = np.random.default_rng(seed)
    lam1 = length * rng.uniform(1.0, gamma)
    angles = np.sort((np.arange(n_ridges) + rng.uniform(0.2, 0.8, n_ridges)) * np.pi / n_ridges)
    aniso = np.exp(rng.normal(0.0, 0.3, n_ridges))
    aniso /= np.exp(np.mean(np.log(aniso)))
    g = random_genome(1e-3, hurst, gamma, lam1, n_ridges, 30, rng=rng, angles=angles,
                      anisotropy=aniso)
    return g, [realize_surface(g, length, n_nodes), realize_surface(g, length / ratio, n_nodes)], rng
