"""Steps 1-4 of profile sequencing and its final linear fit: the lattice of nested
acquisitions (comb, variable projection, coarser lattices, labels) and the chromosome
coefficients on it (:func:`fit_profile_model`), shared by the driver
(:func:`~.profile.sequence_profiles`) and the reproducibility test (:mod:`.reproduce`),
which sequences the two halves of the data the same way."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from ... import progress
from ...errors import InputError
from .lattice import (bic, coarser_lattices, comb_periods, design_matrix, fit_lattice,
                      label_q1, lattice_from_period, lattice_ranges, line_columns,
                      round_off_cost, solve_model, tilt_columns, vp_residual)
from .peaks import spectrum_peaks


#: largest k of the coarser lattices gamma^k tried on a fit within the tolerance
#: (:func:`_settle`): 1.05^24 = 3.2, so every sub-lattice down to the comb's lowest
#: candidate (1.05) of a lattice up to 3.2 is covered, in at most 299 linear solves
#: (measured: Table 1 at 0.1 % and 1 % noise came out as 1.5^(1/7), seeds 1 and 5)
K_MAX = 24
#: the final fit and its held-out fits are damped where the data cannot resolve them
#: (:mod:`.regularise`); False: least squares, as until round 2, session 33
REGULARISE = True


def _labelled(p, acqs, weights, rhs):
    """(bic, (ln q1, ln gamma), ranges, rss) of the fitted lattice ``p`` under the label of
    least BIC (:func:`~.lattice.bic`) among those compatible with n_s = 1 for the coarsest
    acquisition (Eq. 3.5: lambda1 in [L_1, gamma L_1), or one lattice step off it at the
    ends of that interval, up to round-off); None when gamma is not in (1, 10]."""
    if not (1.0 < math.exp(p[1]) <= 10.0):
        return None
    base = label_q1(p[0], p[1], acqs[0].length)     # lambda1 in [L_1, gamma L_1)
    # the misfit is floored at round-off (:func:`~.lattice.round_off_cost`) so that two
    # exact fits tie and the lattice with fewer chromosomes wins (a lattice of ratio
    # sqrt(gamma) contains the gamma lattice and fits WM data exactly too)
    floor = round_off_cost(rhs @ rhs)
    best = None
    for shift in (0.0, -1.0, 1.0):
        cand = np.array([base + shift * p[1], p[1]])
        lam1 = 2 * math.pi / math.exp(cand[0])
        if shift and not (acqs[0].length * (1 - 1e-6) <= lam1
                          < math.exp(cand[1]) * acqs[0].length * (1 + 1e-6)):
            continue
        ranges = lattice_ranges(cand[0], cand[1], acqs)
        if shift and ranges[0][0] != 1:
            continue
        r = vp_residual(cand, acqs, ranges, weights, rhs, None)
        lo, hi = min(rr[0] for rr in ranges), max(rr[1] for rr in ranges)
        rss = float(r @ r)
        cost = bic(rss, r.size, 2 * (hi - lo + 1) + line_columns(acqs) + 2, floor)
        if best is None or cost < best[0]:
            best = (cost, cand, ranges, rss)
    return best


def _settle(best, acqs, weights, rhs, good):
    """A fit within the tolerance (``rss <= good``) may stand for a coarser lattice: a
    lattice gamma^(1/k) holds the data's lattice gamma as every k-th chromosome and fits
    as well, the others empty (WM data: their amplitudes at round-off; measured, random
    genomes of gamma 1.6-1.9, N = 64: 3 of 40 sequenced as sqrt(gamma) or gamma^(1/3)) or
    holding noise only (Table 1 at 0.1 % noise: gamma^(1/3), H 2.3). Every coarser lattice
    of :func:`~.lattice.coarser_lattices` through the fit's chromosomes is solved
    (linear), the one of least BIC refitted locally (it starts in the basin) and the
    lower BIC of the two kept, as the 2D sequencer does. A coarser lattice whose
    chromosomes do not hold the fit's waves misfits the data and loses on the BIC.
    Poor fits are left alone (the BIC among them is no evidence of a lattice), and so
    is an exact fit (WM data) whose best coarser start is not exact (a sub-lattice fit
    is, to round-off: no local refit can make up for chromosomes the coarser lattice
    misses). Returns (best, residual evaluations)."""
    if best[3] > good:
        return best, 0
    _, (lq1, lg), ranges, _ = best
    trial = []
    for start in coarser_lattices(np.array([lq1, lg]), min(r[0] for r in ranges),
                                  acqs[0].length, k_max=K_MAX, gamma_max=10.0):
        out = _labelled(start, acqs, weights, rhs)
        if out is not None:
            trial.append(out)
    if not trial:
        return best, 0
    _, start, _, start_rss = min(trial, key=lambda t: t[0])
    exact = 1e-20 * float(rhs @ rhs)
    if best[3] < exact <= start_rss:
        return best, len(trial)      # an exact fit whose coarser lattices miss waves
    p, k = fit_lattice(start[0], start[1], acqs, weights, rhs, continuation=False)
    alt = _labelled(p, acqs, weights, rhs)
    nit = k + len(trial)
    return (alt if alt is not None and alt[0] < best[0] else best), nit


@dataclass(frozen=True, eq=False)
class ProfileModel:
    """The sequenced lattice and the linear fit on it (steps 1-4).

    ``log_q1``, ``log_gamma``: the lattice (ln of 1/m, -); ``ranges``: (n_s, n_f) per
    acquisition; ``weights``: 1 / rms(Z_i) (1/m); ``rhs``: the weighted stacked heights
    (-); ``n``: chromosome indices; ``cvec``: c_n e^{i theta_n} (m); ``offsets`` (m),
    ``tilts`` (m/m) per acquisition; ``spectra``: the SpectrumPeaks; ``gamma_psd``: the
    comb's gamma; ``nit``: residual evaluations; ``residual``: the fit's weighted
    residual on the stacked nodes (-, heights over their acquisition's rms)."""

    log_q1: float
    log_gamma: float
    ranges: list
    weights: list
    rhs: np.ndarray
    n: np.ndarray
    cvec: np.ndarray
    offsets: np.ndarray
    tilts: np.ndarray
    spectra: list
    gamma_psd: float
    nit: int
    residual: np.ndarray


def fit_profile_model(acqs, rms_tolerance, n_restarts, regularise=REGULARISE,
                      starts=()) -> ProfileModel:
    """Steps 1-4 of :func:`~.profile.sequence_profiles` on checked acquisitions
    (:class:`~.acquisitions.Acquisition`, coarsest first) and the final linear fit on the
    lattice found (damped with ``regularise``, :mod:`.regularise`); ``starts``: lattices
    (ln q_1, ln gamma) fitted before the comb's ``n_restarts`` (the lowest BIC wins; 0:
    the starts only, no comb, ``gamma_psd`` NaN). InputError: fewer than 3 PSD peaks
    (with ``n_restarts``), or no admissible lattice."""
    n_nodes = acqs[0].z.size
    weights = [1.0 / max(math.sqrt(float(np.mean(a.z ** 2))), 1e-300) for a in acqs]
    rhs = np.concatenate([a.z * w for a, w in zip(acqs, weights)])

    # 1-2. spectra, peaks and the comb (none with n_restarts = 0: the starts only)
    spectra = [spectrum_peaks(a) for a in acqs]
    log_q = np.concatenate([np.log(s.peak_q) for s in spectra])
    first = [tuple(map(float, p)) for p in starts]
    gamma_psd = math.nan
    if n_restarts:
        if log_q.size < 3:
            raise InputError(
                f"only {log_q.size} PSD peaks found in the {len(acqs)} acquisitions; the "
                f"lattice ln q_n = ln q_1 + (n-1) ln gamma (Eq. 3.6) needs at least 3: the "
                f"spectrum is not a discrete WM spectrum, or its chromosomes are not "
                f"resolved (give more nodes than N = {n_nodes}, or more acquisitions)")
        periods, _, refs = comb_periods(log_q, n_best=n_restarts)
        bins = np.concatenate([s.peak_q / (s.q[1] - s.q[0]) for s in spectra])
        groups = np.concatenate([np.full(s.peak_q.size, i) for i, s in enumerate(spectra)])
        gamma_psd = float(math.exp(periods[0]))
        first += [lattice_from_period(log_q, period, ref, acqs[0].length, bins, groups)
                  for period, ref in zip(periods, refs)]

    # 3-4. lattice fit with restarts, then the coarser lattices of the best
    best = None
    nit = 0
    exact = 1e-20 * float(rhs @ rhs)
    for lq1, lg in progress.iterate(first, "sequencing: lattice fits"):
        if not (math.log(1.0 + 1e-3) < lg < math.log(10.0)):
            continue
        p, k = fit_lattice(lq1, lg, acqs, weights, rhs)
        nit += k
        out = _labelled(p, acqs, weights, rhs)
        if out is not None and (best is None or out[0] < best[0]):
            best = out
        if best is not None and best[3] < exact:
            break                              # exact fit (WM data): no restart needed
    if best is None:
        raise InputError("sequencing found no admissible wavenumber lattice (gamma in (1, 10]) in the PSD "
                         "peaks; the acquisitions are not WM-like")
    best, k = _settle(best, acqs, weights, rhs, rms_tolerance ** 2 * float(rhs @ rhs))
    nit += k
    _, (lq1, lg), ranges, _ = best
    # final polish of the full model with the final chromosome ranges
    r0 = vp_residual(np.array([lq1, lg]), acqs, ranges, weights, rhs, None)
    pol = least_squares(vp_residual, np.array([lq1, lg]), args=(acqs, ranges, weights, rhs, None),
                        x_scale=np.array([1e-5, 1e-5]), diff_step=1e-11, max_nfev=100,
                        xtol=1e-15, ftol=1e-15, gtol=1e-15)
    nit += pol.nfev + 2 * (pol.njev or 0)
    if 2 * pol.cost < float(r0 @ r0) and lattice_ranges(pol.x[0], pol.x[1], acqs) == ranges:
        lq1, lg = pol.x
    n, mat = design_matrix(lq1, lg, acqs, ranges, weights)
    # damped where the data cannot resolve it (:mod:`.regularise`): least squares ranks
    # the lattices above, but its coefficients along the directions the data do not
    # resolve (the long chromosomes of fine lattices and the line, collinear) are not
    # the data's (measured rows: waves of 0.4-7 m that cancel)
    coef = solve_model(mat, rhs, acqs, regularise=regularise)
    cvec = coef[0:2 * n.size:2] + 1j * coef[1:2 * n.size:2]
    # the acquisitions' height offsets (their heights at x = 0 off the genome's zero) and
    # tilts (the line a levelled profile lost)
    offsets = coef[2 * n.size:2 * n.size + len(acqs)]
    tilts = np.array([coef[2 * n.size + len(acqs) + c] if c >= 0 else 0.0
                      for c in tilt_columns(acqs)])
    return ProfileModel(float(lq1), float(lg), ranges, weights, rhs, n, cvec, offsets, tilts,
                        spectra, gamma_psd, nit, mat @ coef - rhs)
