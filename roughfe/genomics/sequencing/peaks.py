"""Step 1 of sequencing: PSD peaks of an acquisition (thesis Sec. 3.3.1, Eq. 3.6)."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.signal import find_peaks
from scipy.spatial import ConvexHull, QhullError

from ...surfaces.stats import power_spectrum
from ...surfaces.surface import Surface
from .acquisitions import Acquisition


@dataclass(frozen=True)
class SpectrumPeaks:
    """PSD of one acquisition and its peaks.

    Attributes: q (rad/m), C (m^3, ``roughfe.surfaces.stats`` convention), hull (indices
    of the upper-convex-hull vertices), peak_q (refined peak wavenumbers, rad/m),
    peak_C (PSD at the peaks, m^3).
    """

    q: np.ndarray
    C: np.ndarray
    hull: np.ndarray
    peak_q: np.ndarray
    peak_C: np.ndarray


def upper_hull(q, C) -> np.ndarray:
    """Indices of the vertices of the upper convex hull of (log q, log C) (quickhull)."""
    pts = np.column_stack([np.log(q), np.log(np.maximum(C, np.finfo(float).tiny))])
    try:
        hull = ConvexHull(pts)
    except (QhullError, ValueError):
        return np.arange(q.size)
    upper = set()
    for simplex, eq in zip(hull.simplices, hull.equations):
        if eq[1] > 0:                                      # outward normal points up
            upper.update(int(i) for i in simplex)
    return np.array(sorted(upper), dtype=int)


def spectrum_peaks(acq: Acquisition, min_bin=4, prominence=2.0) -> SpectrumPeaks:
    """PSD (Hann window) of an acquisition, its upper hull and its refined peaks.

    A peak is an upper-hull vertex or a local maximum of ln C with a prominence of at
    least ``prominence`` (natural-log units), at FFT bin >= ``min_bin`` (lower bins are not
    resolved by the window) and below 0.8 times the Nyquist wavenumber (aliases of the
    sub-Nyquist chromosomes of Eq. 3.5 crowd there). Its wavenumber is refined by a parabola through ln C at the
    three bins around it.
    """
    n = acq.z.size
    spec = power_spectrum(Surface(acq.z, n * acq.span / (n - 1)), window="hann")
    q, C = spec.q, np.maximum(spec.C, np.finfo(float).tiny)
    logc = np.log(C)
    hull = upper_hull(q, C)
    found, _ = find_peaks(logc, prominence=prominence)
    cand = np.union1d(found, hull[(hull > 0) & (hull < q.size - 1)])
    # lower bins are unresolved; lines near Nyquist are often aliases of shorter waves
    cand = cand[(cand >= min_bin - 1) & (cand < int(0.8 * q.size))]
    cand = cand[(logc[cand] >= logc[cand - 1]) & (logc[cand] >= logc[cand + 1])]
    dq = q[1] - q[0]
    ym, y0, yp = logc[cand - 1], logc[cand], logc[cand + 1]
    den = ym - 2 * y0 + yp
    shift = np.where(den < 0, 0.5 * (ym - yp) / np.where(den < 0, den, -1.0), 0.0)
    q0 = q[cand] + np.clip(shift, -0.5, 0.5) * dq
    return SpectrumPeaks(q, C, hull, refine_peaks(acq, q0, dq), C[cand])


def refine_peaks(acq: Acquisition, q0, dq, n_iter=40):
    """Wavenumbers maximising the Hann-windowed DTFT power |sum w z e^{-i q x}|^2 near q0.

    A golden-section search within +-0.75 bin of each parabolic estimate: a line's
    windowed spectrum peaks at its own wavenumber, up to the leakage of the other lines
    (Hann sidelobes fall as 1/k^3, the neighbouring chromosomes are many bins away), so
    the estimate is far finer than a bin. All peaks are refined at once (vectorised).
    """
    q0 = np.asarray(q0, dtype=float)
    if q0.size == 0:
        return q0
    w = np.hanning(acq.z.size)
    zw = (acq.z - acq.z.mean()) * w

    def power(qs):
        return np.abs(np.exp(-1j * np.multiply.outer(qs, acq.x)) @ zw) ** 2

    a, b = q0 - 0.75 * dq, q0 + 0.75 * dq
    r = (math.sqrt(5) - 1) / 2
    c, d = b - r * (b - a), a + r * (b - a)
    fc, fd = power(c), power(d)
    for _ in range(n_iter):
        left = fc > fd                         # maximum in [a, d]
        b = np.where(left, d, b)
        a = np.where(left, a, c)
        c_new = b - r * (b - a)
        d_new = a + r * (b - a)
        c, d = c_new, d_new
        fc, fd = power(c), power(d)
    return 0.5 * (a + b)
