"""Step 5 of sequencing: genes A, H, M and the phases from the chromosome amplitudes
(Eq. 3.1, 3.11, 3.13), statistical estimates since profiles identify only c_n e^{i theta_n}."""
from __future__ import annotations

import math

import numpy as np
from scipy.optimize import minimize_scalar

from ...errors import InputError


#: the search interval of the scaling exponent H: a fit at either end is not a power law
H_SEARCH = (1e-3, 3.0)


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

    h = minimize_scalar(nll, bounds=H_SEARCH, method="bounded", options={"xatol": 1e-10}).x
    a = math.sqrt(s0(h) / lg) * q1 ** h
    return a, float(h)


def amplitude_gene_errors(n, c, gamma, lambda1):
    """Standard errors (1 sigma) of ln A and of H of :func:`amplitude_genes` (-, -).

    The model of :func:`amplitude_genes`, c_n^2 = S gamma^(-2(n-1)H) u_n with u_n ~ Exp(1)
    and S = A^2 ln(gamma) q_1^(-2H), is an exponential family in (ln S, H) whose expected
    Fisher information is, with x_n = 2 (n - 1) ln(gamma),

        I = [[N, -sum x_n], [-sum x_n, sum x_n^2]]

    (each u_n carries unit information on the log of its scale). The covariance of
    (ln S, H) is I^-1, and ln A = ln S / 2 + H ln q_1 - ln ln(gamma) / 2 gives
    var(ln A) = g' I^-1 g, g = (1/2, ln q_1). Asymptotic (Cramer-Rao) errors: with N
    chromosomes they shrink as 1/sqrt(N); gamma and lambda1 are held at their fitted
    values (their own errors, from the lattice fit, are far smaller). For M ridges the
    u_n follow Kluyver's distribution, of variance 1 - 1/M below Exp(1)'s 1: the errors
    are then slightly conservative (measured over 400 phase sets, M = 8, 29
    chromosomes: spread / error 0.8-1.1, tests/test_genomics_sequencing.py). ``c``: the
    chromosome amplitudes (m), zeros ignored as in the fit."""
    n = np.asarray(n, dtype=float)
    keep = np.asarray(c, dtype=float) > 0
    x = 2.0 * (n[keep] - 1.0) * math.log(gamma)
    if x.size < 2:
        raise InputError("at least two chromosomes with non-zero amplitude are needed for "
                         "the errors of A and H")
    info = np.array([[x.size, -x.sum()], [-x.sum(), np.dot(x, x)]])
    cov = np.linalg.inv(info)
    g = np.array([0.5, math.log(2 * math.pi / lambda1)])
    return float(math.sqrt(g @ cov @ g)), float(math.sqrt(cov[1, 1]))


def _resultant_samples(m, n_samples, rng):
    phi = rng.uniform(0, 2 * np.pi, size=(n_samples, m))
    return np.hypot(np.cos(phi).sum(axis=1), np.sin(phi).sum(axis=1)) / math.sqrt(m)


#: the numbers of ridges M whose likelihood is computed (:func:`ridge_likelihood`; the
#: thesis's range, Sec. 3.3.1)
M_VALUES = tuple(range(2, 21))


def ridge_likelihood(u, M_values=M_VALUES, *, rng, n_samples=10000):
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


#: the drop of the log-likelihood of M that bounds its likelihood interval: chi^2_1(95 %)
#: / 2 (Wilks' theorem, read for a discrete parameter as a support range)
M_SUPPORT_DROP = 1.92


def ridge_support(loglik, M_values=M_VALUES):
    """(smallest, largest) M whose log-likelihood is within ``M_SUPPORT_DROP`` of the
    maximum (the M of :func:`ridge_likelihood` the data cannot tell apart at about 95 %),
    or None when no M has a finite likelihood."""
    loglik = np.asarray(loglik, dtype=float)
    if not np.isfinite(loglik).any():
        return None
    ok = np.flatnonzero(loglik >= np.max(loglik[np.isfinite(loglik)]) - M_SUPPORT_DROP)
    return int(M_values[ok[0]]), int(M_values[ok[-1]])


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


def peak_slope_H(spectra, log_q1, log_gamma):
    """H from the PSD peaks on the fitted lattice: ln C_peak = c_i - 2H ln q (Eq. 3.11).

    The thesis's estimate (slope of the line through the retained peaks). A spectral line
    of amplitude c gives a periodogram peak C ~ c^2 L_i whatever its q, so the peaks
    fall as q_n^(-2H); one intercept per acquisition absorbs L_i. Peaks farther than 0.15
    lattice steps from the lattice (aliases, leakage) are ignored.

    Two slips of the thesis around Eq. 3.11 are not followed: it writes
    q_n = (2 pi / lambda) gamma^(1-n), the wrong sign of the exponent (q_n = 2 pi /
    lambda_n = (2 pi / lambda1) gamma^(n-1) rad/m, Eq. 3.1-3.2, as used here), and it calls
    the PSD "the square root of the FFT", while the PSD C (m^3 for a profile,
    :func:`~roughfe.surfaces.stats.power_spectrum`) is the squared modulus |FFT|^2,
    normalised (of the modulus, the peaks would fall as q^-H and this estimate would
    read H/2).
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
