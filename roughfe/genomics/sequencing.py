"""Genome sequencing of rough profiles from nested acquisitions (thesis Sec. 3.3.1, Eq. 3.5-3.16).

Input: two or more acquisitions of the same profile at observation lengths
L_1 > L_2 > ... (e.g. 10x, 20x, 100x), each with the same number of nodes N, centred on
the same point x = 0 (node coordinates from ``metadata["x0"]`` or the genome node
convention of :mod:`roughfe.genomics.genome`).

What a profile can and cannot tell (the thesis is loose here)
-------------------------------------------------------------
By the reduced form (Eq. 3.7-3.8, :mod:`roughfe.genomics.chromosomes`) every chromosome
of a *profile* is exactly one cosine,

    C_n(x) = c_n [cos(theta_n) - cos(q_n x + theta_n)],
    c_n e^{i theta_n} = G gamma^{(1-n) H} sum_m e^{i phi_{m,n}},

so the heights depend on (A, M, Phi) only through the complex amplitudes c_n e^{i theta_n}.
Consequences, stated once:

* gamma and lambda1 (the wavenumber lattice) and every c_n, theta_n are identifiable,
  exactly for WM data. With the lattice known the fit is *linear*: Eq. (3.12)-(3.16) with
  the phasor sums as unknowns, (eta, xi) -> c_n (cos theta_n, sin theta_n), needs no
  constraint eta^2 + xi^2 = 1, no fmincon, no (eta, xi) vs angle choice, and uses all
  nodes of all acquisitions (the thesis's low-pass behaviour came from 128 fitting nodes).
  Only (ln q_1, ln gamma) are nonlinear: they are refined by variable projection
  (scipy ``least_squares`` on the residual of the linear solve).
* M and the individual phi_{m,n} are *not* identifiable from profiles: any M phasors
  with the same sum give the same heights (the thesis's P_m(alpha) is flat in M up to
  optimiser noise). A and H enter only through the mean trend of |c_n|: with random phases
  |sum_m e^{i phi}|^2 / M is ~ exponentially distributed with mean 1 (independent of M), so
  A and H are *statistical* estimates with an error set by the number of chromosomes
  (standard deviation ~4.4 % on H over 20 phase seeds of Table 1, 22 chromosomes),
  whatever the fitting method.
  They are estimated here by maximum likelihood (:func:`amplitude_genes`); M by
  maximum likelihood over 2..20 using the distribution of the resultant of M random unit
  phasors (weak: M = 8 and M = 12 are nearly indistinguishable); the phases are then
  *one* set of M phasors per chromosome with the fitted sum (drawn from a seeded rng),
  so the sequenced genome reproduces the acquisitions exactly and has the fitted genes.

Steps (:func:`sequence_profiles`)
---------------------------------
1. PSD of each acquisition (Hann window, ``roughfe.surfaces.stats.power_spectrum``) and
   its peaks: the vertices of the upper convex hull of the log-log PSD (quickhull,
   ``scipy.spatial.ConvexHull``, as the thesis) plus the prominent local maxima,
   located to sub-bin precision by a parabola in log PSD.
2. gamma (Eq. 3.6): the peaks of all acquisitions lie on one lattice
   ln q_n = ln q_1 + (n-1) ln gamma; ln gamma is the period of a comb fitted to the peak
   abscissae (largest period with near-maximal coherence), refined by regression.
3. lambda1 so that n_s = 1 for the coarsest acquisition (Eq. 3.5): lambda1 in [L_1, gamma L_1).
4. Variable projection with continuation in the highest chromosome index (the basin of
   ln gamma shrinks like 1/n), restarts from the best comb periods; the lattice label is
   finally chosen among the shifts compatible with step 3 by the residual.
5. Genes A, H (maximum likelihood on c_n, M-free), M, phases; Z_d = Z_1 - Z_2 at the
   common nodes; relative rms errors of the realisations of the sequenced genome; a
   quality report (success is False, with a message, when the relative rms error of any
   acquisition exceeds ``rms_tolerance``: the profile is not WM-like).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Optional

import numpy as np
from scipy.linalg import lstsq as scipy_lstsq
from scipy.optimize import least_squares, minimize_scalar
from scipy.signal import find_peaks
from scipy.spatial import ConvexHull, QhullError

from ..errors import InputError
from ..surfaces.stats import power_spectrum
from ..surfaces.surface import Surface
from ..writers import to_jsonable
from .genome import Genome, chromosome_range, observation_coordinates, profile_heights

MIN_NODES = 32


# -- data checks -------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class Acquisition:
    """One acquisition: node abscissae x (m), heights z (m), observation length L = (N-1) dx."""

    x: np.ndarray
    z: np.ndarray
    length: float


def acquisitions_from_surfaces(surfaces) -> list:
    """Check nested acquisitions and return them sorted from coarsest to finest.

    Raises InputError for: fewer than 2 profiles, 2D data, different N, fewer than
    ``MIN_NODES`` nodes, a flat profile, equal lengths, windows that are not nested around x = 0, or
    scales that do not overlap (the finer window shorter than two coarse spacings).
    """
    surfaces = list(surfaces)
    if len(surfaces) < 2:
        raise InputError(f"sequencing needs at least 2 nested acquisitions, got {len(surfaces)}")
    for k, s in enumerate(surfaces):
        if not isinstance(s, Surface):
            raise InputError(f"acquisition {k} must be a roughfe Surface, got {type(s).__name__}")
        if s.ndim != 1:
            raise InputError(f"acquisition {k} must be a profile (1D heights), got shape {s.shape}")
    sizes = {s.shape[0] for s in surfaces}
    if len(sizes) != 1:
        raise InputError(f"all acquisitions must have the same number of nodes N (Sec. 3.2: N = 512 "
                         f"at every scale), got N = {[s.shape[0] for s in surfaces]}")
    n = sizes.pop()
    if n < MIN_NODES:
        raise InputError(f"too few points: N = {n} nodes per acquisition, at least {MIN_NODES} are needed")
    acq = []
    for k, s in enumerate(surfaces):
        if np.ptp(s.heights) == 0:
            raise InputError(f"acquisition {k} is flat (all heights equal {float(s.heights[0])!r} m): "
                             f"there is no roughness to sequence")
        x = observation_coordinates(s)
        acq.append(Acquisition(x, np.asarray(s.heights, dtype=float), float((n - 1) * s.spacing[0])))
    acq.sort(key=lambda a: -a.length)
    for a, b in zip(acq, acq[1:]):
        if not b.length < a.length * (1 - 1e-9):
            raise InputError(f"acquisitions must have different observation lengths, got two of "
                             f"{a.length:.6g} m")
        tol = 1e-6 * a.length
        if b.x[0] < a.x[0] - tol or b.x[-1] > a.x[-1] + tol:
            raise InputError(f"acquisition of length {b.length:.6g} m ([{b.x[0]:.4g}, {b.x[-1]:.4g}] m) is "
                             f"not nested inside the one of length {a.length:.6g} m "
                             f"([{a.x[0]:.4g}, {a.x[-1]:.4g}] m)")
        dx = a.length / (n - 1)
        if b.length <= 2 * dx:
            raise InputError(f"non-overlapping scales: the finer window {b.length:.4g} m is not longer than "
                             f"two spacings {2 * dx:.4g} m of the coarser acquisition, so they share no "
                             f"wavelength")
    return acq


# -- step 1: PSD peaks ---------------------------------------------------------------------
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
    spec = power_spectrum(Surface(acq.z, n * acq.length / (n - 1)), window="hann")
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


# -- step 2-3: the lattice -----------------------------------------------------------------
def comb_periods(log_q, weights=None, gamma_range=(1.05, 4.0), n_grid=6000, n_best=3):
    """Candidate ln(gamma): periods T of a comb fitted to the peak abscissae ln q (Eq. 3.6).

    Coherence S(T) = |sum w e^{2 pi i ln q / T}| / sum w is 1 for a perfect lattice of
    period T and also for T/2, T/3, ... ; the candidates are the local maxima of S with
    S >= 0.75 max S and the local maxima near their multiples 2T, 3T with S >= 0.5 max S,
    largest periods first (the fundamental), at most ``n_best``.
    Returns (periods, coherences, reference ln q).
    """
    log_q = np.asarray(log_q, dtype=float)
    w = np.ones_like(log_q) if weights is None else np.asarray(weights, dtype=float)
    periods = np.linspace(math.log(gamma_range[0]), math.log(gamma_range[1]), n_grid)
    ph = np.exp(2j * np.pi * np.outer(1.0 / periods, log_q))
    s = np.abs(ph @ w) / w.sum()
    loc = np.flatnonzero((s[1:-1] >= s[:-2]) & (s[1:-1] >= s[2:])) + 1
    if loc.size == 0:
        loc = np.array([int(np.argmax(s))])
    keep = loc[s[loc] >= 0.75 * s[loc].max()]
    # a lattice of period T is also one of T/2, T/3 (which can collect stray peaks --
    # aliases, leakage -- and win on coherence): the multiples 2T, 3T of each candidate
    # are candidates too when their coherence is fair (>= 0.5 max)
    extra = []
    for k in keep:
        for mult in (2, 3):
            j = int(np.argmin(np.abs(periods - mult * periods[k])))
            if abs(periods[j] / (mult * periods[k]) - 1) > 0.01:
                continue
            near = loc[np.abs(periods[loc] / periods[j] - 1) < 0.03]
            if near.size:
                j = near[np.argmax(s[near])]
                if s[j] >= 0.5 * s[loc].max():
                    extra.append(j)
    keep = np.unique(np.concatenate([keep, np.array(extra, dtype=int)]))
    keep = keep[np.argsort(-periods[keep])][:n_best]
    refs = []
    for k in keep:
        phase = np.angle(ph[k] @ w)
        refs.append(phase / (2 * np.pi) * periods[k])
    return periods[keep], s[keep], np.array(refs)


def _lattice_from_period(log_q, period, ref, coarse_length, weights=None, groups=None):
    """Refine (ln q1, ln gamma) by weighted regression on the lattice indices; q1 so that n_s = 1.

    Each peak gets the nearest lattice index. Within one acquisition (``groups``) only the
    peak closest to the lattice is kept per index -- aliases of the sub-Nyquist
    chromosomes can land next to a true line, and be stronger. Peaks farther than 0.15 period from the lattice are
    dropped, then, iteratively, those farther than 4 robust standard deviations (MAD) of
    the regression residual. ``weights`` (the peak bin numbers: the relative precision of
    a peak grows with its bin) weight the regression.
    """
    w = np.ones_like(log_q) if weights is None else np.asarray(weights, dtype=float)
    grp = np.zeros(log_q.size, dtype=int) if groups is None else np.asarray(groups)
    tol = None
    for _ in range(8):
        k = np.round((log_q - ref) / period)
        dev = log_q - ref - k * period
        keep = np.abs(dev) < 0.15 * period
        if tol is not None:
            keep &= np.abs(dev) <= tol
        order = np.lexsort((np.abs(dev), k, grp))   # closest first within (group, index)
        seen = set()
        for idx in order:
            key = (int(grp[idx]), int(k[idx]))
            if keep[idx] and key in seen:
                keep[idx] = False
            elif keep[idx]:
                seen.add(key)
        if np.unique(k[keep]).size < 2:
            break
        slope, icpt = np.polyfit(k[keep], log_q[keep], 1, w=np.sqrt(w[keep]))
        if not (0.5 * period < slope < 2 * period):
            break
        period, ref = slope, icpt
        res = log_q[keep] - ref - np.round((log_q[keep] - ref) / period) * period
        mad = float(np.median(np.abs(res - np.median(res)))) * 1.4826
        new_tol = max(4 * mad, 1e-4 * period)
        if tol is not None and abs(new_tol - tol) <= 1e-3 * tol:
            break
        tol = new_tol
    return _label_q1(ref, period, coarse_length), period


def _label_q1(log_q_any, period, coarse_length):
    """The lattice point ln q1 with lambda1 = 2 pi / q1 in [L_1, gamma L_1) (n_s = 1, Eq. 3.5)."""
    top = math.log(2 * math.pi / coarse_length)          # q1 <= 2 pi / L1
    return log_q_any + math.floor((top - log_q_any) / period + 1e-9) * period


# -- step 4: variable projection -----------------------------------------------------------
def _ranges(log_q1, log_gamma, acqs, n_nodes):
    lam1 = 2 * math.pi / math.exp(log_q1)
    return [chromosome_range(math.exp(log_gamma), lam1, a.length, n_nodes) for a in acqs]


def _design(log_q1, log_gamma, acqs, ranges, weights, n_cap=None):
    lo = min(r[0] for r in ranges)
    hi = max(r[1] for r in ranges) if n_cap is None else min(n_cap, max(r[1] for r in ranges))
    n = np.arange(lo, hi + 1)
    q = np.exp(log_q1 + (n - 1) * log_gamma)
    blocks = []
    for a, (ns, nf), w in zip(acqs, ranges, weights):
        on = (n >= ns) & (n <= nf)
        arg = np.multiply.outer(a.x, q)
        m = np.zeros((a.x.size, 2 * n.size))
        m[:, 0::2] = np.where(on, 1.0 - np.cos(arg), 0.0)
        m[:, 1::2] = np.where(on, np.sin(arg), 0.0)
        blocks.append(m * w)
    return n, np.vstack(blocks)


def _solve_linear(mat, rhs):
    scale = np.linalg.norm(mat, axis=0)
    scale[scale == 0] = 1.0
    coef, *_ = scipy_lstsq(mat / scale, rhs, cond=1e-12, lapack_driver="gelsy",
                           check_finite=False)   # pivoted QR: ~3x faster than SVD here
    return coef / scale


def _vp_residual(params, acqs, ranges, weights, rhs, n_cap):
    n, mat = _design(params[0], params[1], acqs, ranges, weights, n_cap)
    coef = _solve_linear(mat, rhs)
    return rhs - mat @ coef


def _first_cap(log_q1, log_gamma, lo, hi, coarse_length, cycles=30.0):
    """First continuation index: the last chromosome with at most ``cycles`` periods in L_1."""
    cap = lo + 3
    for n in range(lo + 3, hi + 1):
        if math.exp(log_q1 + (n - 1) * log_gamma) * coarse_length <= 2 * math.pi * cycles:
            cap = n
    return min(cap, hi)


def _projected_cost(mat, rhs):
    """||rhs - P rhs||^2 by the normal equations (fast; accurate enough to rank a grid)."""
    scale = np.linalg.norm(mat, axis=0)
    scale[scale == 0] = 1.0
    a = mat / scale
    gram = a.T @ a
    b = a.T @ rhs
    gram[np.diag_indices_from(gram)] += 1e-10 * max(float(np.trace(gram)) / gram.shape[0], 1e-300)
    try:
        c = np.linalg.solve(gram, b)
    except np.linalg.LinAlgError:
        return float("inf")
    return float(rhs @ rhs - b @ c)


def _scan(p, cap, acqs, ranges, weights, rhs, span=(0.015, 0.03), shape=(31, 13)):
    """Grid search of (ln gamma, ln q_cap) around ``p`` at continuation index ``cap``.

    Scanning ln q_cap (the wavenumber of the highest fitted chromosome) rather than ln q1
    decouples the two parameters. The grid is fine enough to land in the basin of the
    local least-squares fit (phase steps below ~0.5 rad at ``cap`` over L_1).
    """
    lq_cap = p[0] + (cap - 1) * p[1]
    best = (math.inf, p)
    for lg in p[1] + np.linspace(-span[0], span[0], shape[0]):
        for lqc in lq_cap + np.linspace(-span[1], span[1], shape[1]):
            cand = np.array([lqc - (cap - 1) * lg, lg])
            if cand[1] <= 0:
                continue
            _, mat = _design(cand[0], cand[1], acqs, ranges, weights, cap)
            c = _projected_cost(mat, rhs)
            if c < best[0]:
                best = (c, cand)
    return best[1], shape[0] * shape[1]


def _continuation(p, first, hi, acqs, ranges, weights, rhs, budget):
    """Local least squares at caps first..hi, one chromosome added per step."""
    caps = list(range(first, hi + 1))
    if len(caps) > 16:                    # many chromosomes (gamma near 1): coarser continuation
        caps = sorted(set(np.linspace(caps[0], hi, 16).round().astype(int).tolist()))
    nit = 0
    for cap in caps:
        if nit >= budget:
            break
        res = least_squares(_vp_residual, p, args=(acqs, ranges, weights, rhs, cap),
                            x_scale=np.array([1e-3, 1e-3]), diff_step=1e-9,
                            max_nfev=30, xtol=1e-15, ftol=1e-15, gtol=1e-15)
        nit += res.nfev + 2 * (res.njev or 0)
        if res.x[1] > 0:
            p = res.x
    return p, nit


def _fit_lattice(log_q1, log_gamma, acqs, n_nodes, weights, rhs, budget=600):
    """Variable projection with continuation in the highest chromosome index.

    First a local fit of the full model from the PSD estimate (enough when the refined
    peaks place every chromosome within the basin). Otherwise the continuation starts at
    the last chromosome with <= 30 periods in the coarsest
    window (:func:`_first_cap`) -- starting lower lets the unresolved longest waves drag
    gamma away -- and adds one chromosome per step (each step shrinks the error enough
    for the next one). It is run from the PSD estimate and, unless that already fits
    to round-off, again from the best point of a grid search (:func:`_scan`) around it,
    which absorbs a larger PSD error but can also pick a spurious minimum (the
    unmodelled shorter waves still carry most of the misfit at the first cap); the
    lower final residual wins.
    """
    ranges = _ranges(log_q1, log_gamma, acqs, n_nodes)
    lo = min(r[0] for r in ranges)
    hi = max(r[1] for r in ranges)
    p0 = np.array([log_q1, log_gamma])
    first = _first_cap(log_q1, log_gamma, lo, hi, acqs[0].length)
    rr = float(rhs @ rhs)

    def final_cost(p):
        r = _vp_residual(p, acqs, ranges, weights, rhs, None)
        return float(r @ r) / rr

    res = least_squares(_vp_residual, p0, args=(acqs, ranges, weights, rhs, None),
                        x_scale=np.array([1e-4, 1e-4]), diff_step=1e-10, max_nfev=40,
                        xtol=1e-15, ftol=1e-15, gtol=1e-15)
    nit = res.nfev + 2 * (res.njev or 0)
    if res.x[1] > 0 and final_cost(res.x) < 1e-20:
        return res.x, nit                 # the refined PSD lattice is already in the basin
    p_a, k = _continuation(p0, first, hi, acqs, ranges, weights, rhs, budget)
    nit += k
    cost_a = final_cost(p_a)
    if cost_a < 1e-20:
        return p_a, nit
    p_s, k = _scan(p0, first, acqs, ranges, weights, rhs)
    p_b, k2 = _continuation(p_s, first, hi, acqs, ranges, weights, rhs, budget)
    nit += k + k2
    return (p_a if cost_a <= final_cost(p_b) else p_b), nit


# -- step 5: genes ---------------------------------------------------------------------------
def amplitude_genes(n, c, gamma, lambda1):
    """Maximum-likelihood A (m^(1-H)) and H from the chromosome amplitudes c_n (m).

    Model: c_n^2 = s_n u_n with s_n = A^2 ln(gamma) q_1^(-2H) gamma^(2(1-n)H) (the mean of
    c_n^2 over random phases, Eq. 3.1 / 3.13 -- independent of M) and u_n ~ Exp(1). The
    log-likelihood -sum(ln s_n + c_n^2 / s_n) is maximised in closed form over A^2 for
    each H and numerically over H in (0, 3].
    """
    n = np.asarray(n, dtype=float)
    c2 = np.asarray(c, dtype=float) ** 2
    keep = c2 > 0
    n, c2 = n[keep], c2[keep]
    if n.size < 2:
        raise InputError("at least two chromosomes with non-zero amplitude are needed for A and H")
    lg = math.log(gamma)
    q1 = 2 * math.pi / lambda1

    def s0(h):                       # closed-form ML value of A^2 ln(gamma) q1^(-2H)
        return np.mean(c2 * gamma ** (2 * (n - 1) * h))

    def nll(h):
        s = s0(h) * gamma ** (-2 * (n - 1) * h)
        return float(np.sum(np.log(s) + c2 / s))

    h = minimize_scalar(nll, bounds=(1e-3, 3.0), method="bounded", options={"xatol": 1e-10}).x
    a = math.sqrt(s0(h) / lg) * q1 ** h
    return a, float(h)


def _resultant_samples(m, n_samples, rng):
    phi = rng.uniform(0, 2 * np.pi, size=(n_samples, m))
    return np.hypot(np.cos(phi).sum(axis=1), np.sin(phi).sum(axis=1)) / math.sqrt(m)


def ridge_likelihood(u, M_values=tuple(range(2, 21)), *, rng, n_samples=10000):
    """Log-likelihood of M for normalised chromosome amplitudes u_n = |sum_m e^{i phi}| / sqrt(M).

    The density of the resultant of M random unit phasors is estimated by a histogram of
    ``n_samples`` seeded draws (Kluyver's distribution). Values of u above sqrt(M) are
    impossible for that M (log-likelihood -inf).
    """
    gen = np.random.default_rng(rng)
    u = np.asarray(u, dtype=float)
    edges = np.linspace(0, math.sqrt(max(M_values)) + 1e-9, 121)
    out = []
    for m in M_values:
        hist, _ = np.histogram(_resultant_samples(int(m), n_samples, gen), bins=edges, density=True)
        idx = np.clip(np.digitize(u, edges) - 1, 0, hist.size - 1)
        dens = hist[idx]
        bad = (u > math.sqrt(m) * (1 + 1e-9)) | (dens <= 0)
        out.append(-np.inf if bad.any() else float(np.sum(np.log(dens))))
    return np.array(out)


def phases_with_sums(target, M, *, rng, attempts=200):
    """M phases per column whose unit phasors sum to ``target`` (complex, |target| <= M).

    M - 2 phases are drawn uniformly from ``rng``; the last two close the sum (two unit
    vectors reach any w with |w| <= 2). A symmetric fan is the fallback when random draws
    fail (|target| close to M). Returns an (M, len(target)) matrix in [0, 2 pi).
    """
    target = np.asarray(target, dtype=complex).ravel()
    M = int(M)
    if np.any(np.abs(target) > M * (1 + 1e-12)):
        raise InputError(f"a sum of {M} unit phasors cannot exceed {M} in modulus "
                         f"(max |target| = {np.abs(target).max():.4g})")
    out = np.empty((M, target.size))
    for k, t in enumerate(target):
        done = False
        if M >= 2:
            for _ in range(attempts):
                phi = rng.uniform(0, 2 * np.pi, size=M - 2)
                w = t - np.exp(1j * phi).sum()
                r = abs(w)
                if r <= 2.0 and r > 1e-12:
                    half = math.acos(min(1.0, r / 2))
                    base = math.atan2(w.imag, w.real)
                    out[:, k] = np.concatenate([phi, [base + half, base - half]])
                    done = True
                    break
        if not done:                      # fan: phases theta +- beta (and theta for odd M)
            r, theta = abs(t), math.atan2(t.imag, t.real)
            if M == 1:
                out[:, k] = theta
                continue
            odd = M % 2
            cb = (r - odd) / (M - odd)
            beta = math.acos(min(1.0, max(-1.0, cb)))
            signs = np.array([1.0, -1.0] * (M // 2) + [0.0] * odd)
            out[:, k] = theta + signs * beta
    return np.mod(out, 2 * np.pi)


# -- result ---------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class SequencingResult:
    """Sequenced genome and its quality report (scipy OptimizeResult-like).

    Attributes
    ----------
    genome : Genome
        Sequenced genome (phases: one set consistent with the fitted chromosome sums).
    success : bool
        True when every acquisition is reproduced within ``rms_tolerance``.
    message : str
    nit : int
        Residual evaluations of the nonlinear (lattice) fit.
    n : ndarray of int
        Chromosome indices fitted (union over acquisitions).
    amplitudes, phases : ndarray
        c_n (m) and theta_n (rad) of the reduced chromosomes (Eq. 3.7-3.8).
    ranges : list of (int, int)
        (n_s, n_f) per acquisition, coarsest first (Eq. 3.5).
    lengths : ndarray
        Observation lengths (m), coarsest first.
    rms_errors : ndarray
        rms(Z_i - Z_i^seq) / rms(Z_i) per acquisition (relative, -).
    x, heights, fitted : list of ndarray
        Nodes (m), measured and sequenced heights (m) per acquisition.
    zd_x, zd, zd_fit : ndarray
        Z_d = Z_1 - Z_2 at the common nodes of the two coarsest acquisitions and its
        sequenced counterpart (m); empty when they share no node.
    spectra : list of SpectrumPeaks
    gamma_psd, H_psd : float
        gamma from the PSD peaks alone (comb, step 2) and H from the slope of the PSD
        peaks on the lattice (ln C ~ -2H ln q, Eq. 3.11): the thesis's estimates, for
        comparison with the fit and the maximum-likelihood H.
    M_loglik : ndarray
        Log-likelihood of M = 2..20 (flat-ish: M is weakly identifiable).
    A0 : float
        Amplitude from the height variance of the coarsest acquisition (Eq. 3.13), for
        comparison with the maximum-likelihood A.
    seed : int or None
    elapsed : float
        Wall time (s).
    """

    genome: Genome
    success: bool
    message: str
    nit: int
    n: np.ndarray
    amplitudes: np.ndarray
    phases: np.ndarray
    ranges: list
    lengths: np.ndarray
    rms_errors: np.ndarray
    x: list
    heights: list
    fitted: list
    zd_x: np.ndarray
    zd: np.ndarray
    zd_fit: np.ndarray
    spectra: list
    gamma_psd: float
    H_psd: float
    M_loglik: np.ndarray
    A0: float = float("nan")
    seed: Optional[int] = None
    elapsed: float = 0.0
    references: tuple = field(default=("thesis Sec. 3.3.1, Eq. 3.5-3.16",))

    def report(self) -> dict:
        """JSON-safe summary (genes, rms errors, ranges, diagnostics)."""
        g = self.genome
        return {"success": bool(self.success), "message": self.message, "nit": int(self.nit),
                "genes": {"A": g.A, "H": g.H, "gamma": g.gamma, "lambda1": g.lambda1, "M": g.M},
                "lengths": self.lengths.tolist(), "ranges": [list(r) for r in self.ranges],
                "rms_errors": self.rms_errors.tolist(),
                "zd_rms": float(np.sqrt(np.mean(self.zd ** 2))) if self.zd.size else None,
                "zd_rms_error": (float(np.sqrt(np.mean((self.zd - self.zd_fit) ** 2))
                                       / max(np.sqrt(np.mean(self.zd ** 2)), 1e-300))
                                 if self.zd.size else None),
                "gamma_psd": self.gamma_psd, "H_psd": self.H_psd, "A0_variance": self.A0,
                "M_loglik": to_jsonable(self.M_loglik),
                "seed": self.seed, "elapsed_s": self.elapsed}


def _rel_rms(z, fit):
    rz = math.sqrt(float(np.mean(z ** 2)))
    return math.sqrt(float(np.mean((z - fit) ** 2))) / rz if rz > 0 else math.inf


def _peak_slope_H(spectra, log_q1, log_gamma):
    """H from the PSD peaks on the fitted lattice: ln C_peak = c_i - 2H ln q (Eq. 3.11).

    The thesis's estimate (slope of the line through the retained peaks). A spectral line
    of amplitude c gives a periodogram peak C ~ c^2 L_i whatever its q, so the peaks
    fall as q_n^(-2H); one intercept per acquisition absorbs L_i. Peaks farther than 0.15
    lattice steps from the lattice (aliases, leakage) are ignored.
    """
    lq, lc, which = [], [], []
    for i, sp in enumerate(spectra):
        k = (np.log(sp.peak_q) - log_q1) / log_gamma
        on = np.abs(k - np.round(k)) < 0.15
        lq.append(np.log(sp.peak_q[on]))
        lc.append(np.log(sp.peak_C[on]))
        which.append(np.full(int(on.sum()), i))
    lq, lc, which = np.concatenate(lq), np.concatenate(lc), np.concatenate(which)
    if lq.size < len(spectra) + 2:
        return float("nan")
    design = np.column_stack([lq] + [(which == i).astype(float) for i in range(len(spectra))])
    coef, *_ = np.linalg.lstsq(design, lc, rcond=None)
    return float(-coef[0] / 2)


def sequence_profiles(surfaces, *, seed=0, M=None, rms_tolerance=0.05, n_restarts=3) -> SequencingResult:
    """Sequence the genome of a profile from nested acquisitions (Sec. 3.3.1).

    Parameters
    ----------
    surfaces : sequence of Surface
        Two or more profiles of the same N nodes at observation lengths L_1 > L_2 > ...,
        centred on x = 0 (see :func:`acquisitions_from_surfaces` for the checks).
    seed : int
        Seeds the M likelihood and the phase draws (the fit itself is deterministic).
    M : int, optional
        Number of ridges of the sequenced genome. Default: maximum likelihood over 2..20
        (weakly identifiable, see the module notes).
    rms_tolerance : float
        Relative rms error above which the result is flagged ``success = False``.
    n_restarts : int
        Number of comb periods (gamma candidates) tried; the lowest residual wins.

    Returns
    -------
    SequencingResult
    """
    t0 = time.perf_counter()
    acqs = acquisitions_from_surfaces(surfaces)
    n_nodes = acqs[0].z.size
    rng = np.random.default_rng(seed)
    weights = [1.0 / max(math.sqrt(float(np.mean(a.z ** 2))), 1e-300) for a in acqs]
    rhs = np.concatenate([a.z * w for a, w in zip(acqs, weights)])

    # 1-2. spectra, peaks and the comb
    spectra = [spectrum_peaks(a) for a in acqs]
    log_q = np.concatenate([np.log(s.peak_q) for s in spectra])
    messages = []
    if log_q.size < 3:
        messages.append(f"only {log_q.size} PSD peaks found: the spectrum is not a discrete WM spectrum")
        periods, refs = np.array([math.log(1.5)]), np.array([math.log(2 * math.pi / acqs[0].length)])
    else:
        periods, _, refs = comb_periods(log_q, n_best=max(1, int(n_restarts)))
    bins = np.concatenate([s.peak_q / (s.q[1] - s.q[0]) for s in spectra])
    groups = np.concatenate([np.full(s.peak_q.size, i) for i, s in enumerate(spectra)])
    gamma_psd = float(math.exp(periods[0]))

    # 3-4. lattice fit with restarts
    best = None
    nit = 0
    for period, ref in zip(periods, refs):
        if log_q.size >= 3:
            lq1, lg = _lattice_from_period(log_q, period, ref, acqs[0].length, bins, groups)
        else:
            lq1, lg = _label_q1(ref, period, acqs[0].length), period
        if not (math.log(1.0 + 1e-3) < lg < math.log(10.0)):
            continue
        p, k = _fit_lattice(lq1, lg, acqs, n_nodes, weights, rhs)
        nit += k
        # lattice label compatible with n_s = 1 for the coarsest acquisition
        if not (1.0 < math.exp(p[1]) <= 10.0):
            continue
        base = _label_q1(p[0], p[1], acqs[0].length)     # lambda1 in [L_1, gamma L_1)
        for shift in (0.0, -1.0, 1.0):
            cand = np.array([base + shift * p[1], p[1]])
            lam1 = 2 * math.pi / math.exp(cand[0])
            if shift and not (acqs[0].length * (1 - 1e-6) <= lam1
                              < math.exp(cand[1]) * acqs[0].length * (1 + 1e-6)):
                continue
            ranges = _ranges(cand[0], cand[1], acqs, n_nodes)
            if shift and ranges[0][0] != 1:
                continue
            r = _vp_residual(cand, acqs, ranges, weights, rhs, None)
            n_par = 2 * (max(rr[1] for rr in ranges) - 1 + 1) + 2
            # BIC; the misfit is floored at round-off (1e-24 of the data energy) so that two
            # exact fits tie and the lattice with fewer chromosomes wins (a lattice of ratio
            # sqrt(gamma) contains the gamma lattice and fits WM data exactly too)
            rss = max(float(r @ r), 1e-24 * float(rhs @ rhs))
            cost = r.size * math.log(rss / r.size) + n_par * math.log(r.size)
            if best is None or cost < best[0]:
                best = (cost, cand, ranges)
        if best is not None and best[0] < r.size * math.log(1e-20 * float(rhs @ rhs) / r.size) + 1e-9:
            break                              # exact fit (WM data): no restart needed
    if best is None:
        raise InputError("sequencing found no admissible wavenumber lattice (gamma in (1, 10]) in the PSD "
                         "peaks; the acquisitions are not WM-like")
    _, (lq1, lg), ranges = best
    # final polish of the full model with the final chromosome ranges
    r0 = _vp_residual(np.array([lq1, lg]), acqs, ranges, weights, rhs, None)
    pol = least_squares(_vp_residual, np.array([lq1, lg]), args=(acqs, ranges, weights, rhs, None),
                        x_scale=np.array([1e-5, 1e-5]), diff_step=1e-11, max_nfev=100,
                        xtol=1e-15, ftol=1e-15, gtol=1e-15)
    nit += pol.nfev + 2 * (pol.njev or 0)
    if 2 * pol.cost < float(r0 @ r0) and _ranges(pol.x[0], pol.x[1], acqs, n_nodes) == ranges:
        lq1, lg = pol.x
    gamma, lam1 = math.exp(lg), 2 * math.pi / math.exp(lq1)
    n, mat = _design(lq1, lg, acqs, ranges, weights)
    coef = _solve_linear(mat, rhs)
    cvec = coef[0::2] + 1j * coef[1::2]
    amps, thetas = np.abs(cvec), np.angle(cvec)

    # 5. genes
    A, H = amplitude_genes(n, amps, gamma, lam1)
    m_values = tuple(range(2, 21))
    g1 = Genome(A=A, H=H, gamma=gamma, lambda1=lam1, phases=np.zeros((1, n.size)), n_first=int(n[0]))
    unit = g1.prefactor * gamma ** ((1.0 - n) * H)       # G(M=1) gamma^((1-n)H)
    u = amps / unit                                     # = |sum_m e^{i phi}| / sqrt(M)
    loglik = ridge_likelihood(u, m_values, rng=rng)
    if M is None:
        M = m_values[int(np.argmax(loglik))] if np.isfinite(loglik).any() else \
            max(2, int(math.ceil(float(np.max(u)) ** 2)))
    M = int(M)
    if M < 1:
        raise InputError(f"M must be >= 1, got {M}")
    target = u * math.sqrt(M) * np.exp(1j * thetas)
    over = np.abs(target) > M
    if over.any():
        messages.append(f"{int(over.sum())} chromosome amplitude(s) exceed what M = {M} ridges can carry "
                        f"with A = {A:.4g}; they were clipped (the realisation is not exact)")
        target = np.where(over, target / np.abs(target) * M, target)
    phases = phases_with_sums(target, M, rng=rng)
    genome = Genome(A=A, H=H, gamma=gamma, lambda1=lam1, phases=phases, n_first=int(n[0]),
                    metadata={"generator": "sequence_profiles", "seed": int(seed),
                              "lengths": [a.length for a in acqs], "n_nodes": n_nodes})

    # quality
    fitted = [profile_heights(genome, a.x, np.arange(r[0], r[1] + 1)) for a, r in zip(acqs, ranges)]
    rms = np.array([_rel_rms(a.z, f) for a, f in zip(acqs, fitted)])
    d = acqs[1].x[1] - acqs[1].x[0]
    k0 = np.round(acqs[0].x / d)
    k1 = np.round(acqs[1].x / d)
    on0 = np.isin(k0, k1) & (np.abs(acqs[0].x / d - k0) < 1e-6)
    on1 = np.isin(k1, k0[on0])
    zd_x = acqs[0].x[on0]
    zd = acqs[0].z[on0] - acqs[1].z[on1]
    zd_fit = fitted[0][on0] - fitted[1][on1]
    ok = bool(np.all(rms <= rms_tolerance))
    if not ok:
        messages.insert(0, "not WM-like: relative rms error " +
                        ", ".join(f"{e:.3g}" for e in rms) + f" exceeds {rms_tolerance:g}")
    message = "; ".join(messages) if messages else \
        "sequenced: relative rms errors " + ", ".join(f"{e:.2e}" for e in rms)
    meta_report = {"rms_errors": rms.tolist(), "success": ok}
    genome = Genome(A=A, H=H, gamma=gamma, lambda1=lam1, phases=phases, n_first=int(n[0]),
                    metadata={**genome.metadata, "sequencing": meta_report})
    return SequencingResult(
        genome=genome, success=ok, message=message, nit=nit, n=n, amplitudes=amps, phases=thetas,
        ranges=ranges, lengths=np.array([a.length for a in acqs]), rms_errors=rms,
        x=[a.x for a in acqs], heights=[a.z for a in acqs], fitted=fitted, zd_x=zd_x, zd=zd,
        zd_fit=zd_fit, spectra=spectra, gamma_psd=gamma_psd, H_psd=_peak_slope_H(spectra, lq1, lg),
        M_loglik=loglik, A0=variance_amplitude(acqs[0].z, np.arange(ranges[0][0], ranges[0][1] + 1),
                                               gamma, lam1, H),
        seed=int(seed), elapsed=time.perf_counter() - t0)


# -- the thesis's Eq. 3.12-3.15 on Z_d, for the record -------------------------------------
@dataclass(frozen=True)
class ZdRidgeFit:
    """Eq. (3.15) solved for each M: cost f_m and the probability P_m = f_m / sum f_m.

    Attributes: M (ridges tried), cost (f_m, the mean squared misfit of Z_d normalised by
    its peak-valley dZ), P (P_m), alpha (fitted A / A0 per M), A0 (Eq. 3.13 estimate),
    chromosomes (indices in Z_d with their sign +1 / -1), nit (Jacobian evaluations).
    """

    M: np.ndarray
    cost: np.ndarray
    P: np.ndarray
    alpha: np.ndarray
    A0: float
    chromosomes: tuple
    nit: int


def variance_amplitude(z, n, gamma, lambda1, H) -> float:
    """A0 of Eq. (3.13) from the height variance m0 (random, uniform phases).

    E[var Z] = sum_n E[c_n^2] / 2 = A^2 ln(gamma) q1^(-2H) sum_n gamma^(-2H (n-1)) / 2, so
    A0 = sqrt(2 m0 q1^(2H) / (ln(gamma) S)), S = sum_n gamma^(-2H (n-1)) over the realised
    chromosomes (the thesis writes the square of a geometric sum with ratio gamma^-H; the
    variance needs the sum with ratio gamma^-2H).
    """
    n = np.asarray(n, dtype=float)
    m0 = float(np.var(z))
    q1 = 2 * math.pi / lambda1
    s = float(np.sum(gamma ** (-2 * H * (n - 1))))
    return math.sqrt(2 * m0 * q1 ** (2 * H) / (math.log(gamma) * s))


def thesis_zd_fit(result: SequencingResult, M_values=tuple(range(2, 21)), *, seed=0,
                  n_starts=3) -> ZdRidgeFit:
    """Fit Z_d = Z_1 - Z_2 with the ridge model of Eq. (3.12)-(3.15) for each M (angles directly).

    Z_r(x) = alpha A0 sum_{n in U} s_n sum_m G_n(M) gamma^((1-n)H) [cos phi_mn - cos(q_n x + phi_mn)]
    with U the chromosomes of the coarsest acquisition missing from the second (s_n = +1)
    and those of the second missing from the first (s_n = -1), gamma, lambda1, H from the
    sequencing and A0 from Eq. (3.13). The unknowns alpha and phi_mn are fitted by scipy
    ``least_squares`` with the analytic Jacobian (angles directly: the constraint
    eta^2 + xi^2 = 1 of Eq. 3.12 disappears), from ``n_starts`` seeded random starts. The
    cost f_m is the same for every M >= 2 up to the optimiser (any resultant of modulus
    <= M is reachable and alpha absorbs the scale): P_m does not identify M.
    """
    if result.zd.size < 4:
        raise InputError("Z_d needs at least 4 shared nodes of the two coarsest acquisitions")
    g = result.genome
    (s1, f1), (s2, f2) = result.ranges[0], result.ranges[1]
    only1 = [n for n in range(s1, f1 + 1) if not s2 <= n <= f2]
    only2 = [n for n in range(s2, f2 + 1) if not s1 <= n <= f1]
    idx = np.array(only1 + only2, dtype=int)
    sign = np.array([1.0] * len(only1) + [-1.0] * len(only2))
    if idx.size == 0:
        raise InputError("the two coarsest acquisitions have the same chromosomes: Z_d = 0")
    x, zd = result.zd_x, result.zd
    dz = float(np.ptp(zd)) or 1.0
    A0 = variance_amplitude(result.heights[0], np.arange(s1, f1 + 1), g.gamma, g.lambda1, g.H)
    q = g.wavenumber(idx)
    qx = np.multiply.outer(x, q)                                     # (P, k)
    rng = np.random.default_rng(seed)
    costs, alphas, nit = [], [], 0
    for M in M_values:
        base = sign * A0 * math.sqrt(math.log(g.gamma) / M) * (2 * math.pi / g.lambda1) ** (-g.H) \
            * g.gamma ** ((1.0 - idx) * g.H)                         # (k,)

        def resid(p):
            phi = p[1:].reshape(M, idx.size)
            wave = (np.cos(phi)[None] - np.cos(qx[:, None, :] + phi[None])).sum(1)  # (P, k)
            return (p[0] * wave @ base - zd) / dz

        def jac(p):
            phi = p[1:].reshape(M, idx.size)
            wave = (np.cos(phi)[None] - np.cos(qx[:, None, :] + phi[None]))          # (P, M, k)
            dphi = p[0] * base[None, None, :] * (-np.sin(phi)[None] + np.sin(qx[:, None, :] + phi[None]))
            return np.column_stack([wave.sum(1) @ base, dphi.reshape(x.size, -1)]) / dz

        best = math.inf
        best_alpha = float("nan")
        for _ in range(int(n_starts)):
            p0 = np.concatenate([[1.0], rng.uniform(0, 2 * np.pi, M * idx.size)])
            r = least_squares(resid, p0, jac=jac, method="lm", max_nfev=200 * (1 + M * idx.size))
            nit += int(r.njev or 0)
            c = float(np.mean(r.fun ** 2))
            if c < best:
                best, best_alpha = c, float(r.x[0])
        costs.append(best)
        alphas.append(best_alpha)
    costs = np.array(costs)
    total = costs.sum()
    return ZdRidgeFit(np.array(M_values), costs, costs / total if total > 0 else np.full(costs.size, np.nan),
                      np.array(alphas), A0, tuple(zip(idx.tolist(), sign.tolist())), nit)
