"""Sequencing of a profile from nested acquisitions: the driver of steps 1-5
(thesis Sec. 3.3.1, see :mod:`roughfe.genomics.sequencing`)."""
from __future__ import annotations

import math
import time

import numpy as np
from scipy.optimize import least_squares

from ... import progress
from ...errors import InputError, check_int
from ...surfaces.wm import resolve_rng
from ..genome import Genome, profile_heights
from .acquisitions import Acquisition, acquisitions_from_surfaces, check_controls
from .genes import (H_SEARCH, M_VALUES, amplitude_gene_errors, amplitude_genes,
                    peak_slope_H, phases_with_sums, ridge_support,
                    ridge_likelihood, variance_amplitude)
from .lattice import (LINE_PER_AMPLITUDE, OVERFIT_FACTOR, bic, coarser_lattices, comb_periods,
                      design_matrix, fit_lattice, label_q1, lattice_from_period,
                      lattice_ranges, line_columns, round_off_cost, solve_model, tilt_bounds,
                      tilt_columns, vp_residual)
from .holdout import held_out_errors, overfit_reason
from .peaks import spectrum_peaks
from .result import SequencingResult


#: largest k of the coarser lattices gamma^k tried on a fit within the tolerance
#: (:func:`_settle`): 1.05^24 = 3.2, so every sub-lattice down to the comb's lowest
#: candidate (1.05) of a lattice up to 3.2 is covered, in at most 299 linear solves
#: (measured: Table 1 at 0.1 % and 1 % noise came out as 1.5^(1/7), seeds 1 and 5)
K_MAX = 24
#: the final fit and its held-out fits are damped where the data cannot resolve them
#: (:mod:`.regularise`); False: least squares, as until round 2, session 33
REGULARISE = True


def _rel_rms(residual, z):
    """rms(residual) / rms(z) (inf for z = 0)."""
    rz = math.sqrt(float(np.mean(z ** 2)))
    return math.sqrt(float(np.mean(residual ** 2))) / rz if rz > 0 else math.inf


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


def sequence_profiles(surfaces, *, seed=0, M=None, rms_tolerance=0.05, n_restarts=3,
                      windows=None) -> SequencingResult:
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
        Number of comb periods (gamma candidates) tried; the lowest BIC wins, and a fit
        within ``rms_tolerance`` is also tried on its coarser lattices (:func:`_settle`).
    windows : bool, optional
        True: the acquisitions are windows of one sampled profile (any N each; each holds
        the coarsest one's long chromosomes), as :func:`roughfe.genomics.natural.
        nested_acquisitions` makes them; None: read from their metadata
        (:func:`~.acquisitions.acquisitions_from_surfaces`).

    Returns
    -------
    SequencingResult

    Raises
    ------
    InputError
        Fewer than 3 PSD peaks over all acquisitions (too few to read a lattice from), or
        no admissible lattice (gamma in (1, 10]).
    """
    t0 = time.perf_counter()
    rms_tolerance, n_restarts = check_controls(rms_tolerance, n_restarts)
    if M is not None:
        M = check_int("M (number of ridges; None: maximum likelihood)", M, 1)
    rng = resolve_rng(seed, "seed")[0]
    acqs = acquisitions_from_surfaces(surfaces, windows)
    n_nodes = acqs[0].z.size
    weights = [1.0 / max(math.sqrt(float(np.mean(a.z ** 2))), 1e-300) for a in acqs]
    rhs = np.concatenate([a.z * w for a, w in zip(acqs, weights)])

    # 1-2. spectra, peaks and the comb
    spectra = [spectrum_peaks(a) for a in acqs]
    log_q = np.concatenate([np.log(s.peak_q) for s in spectra])
    messages = []
    if log_q.size < 3:
        raise InputError(
            f"only {log_q.size} PSD peaks found in the {len(acqs)} acquisitions; the lattice "
            f"ln q_n = ln q_1 + (n-1) ln gamma (Eq. 3.6) needs at least 3: the spectrum is "
            f"not a discrete WM spectrum, or its chromosomes are not resolved (give more "
            f"nodes than N = {n_nodes}, or more acquisitions)")
    periods, _, refs = comb_periods(log_q, n_best=n_restarts)
    bins = np.concatenate([s.peak_q / (s.q[1] - s.q[0]) for s in spectra])
    groups = np.concatenate([np.full(s.peak_q.size, i) for i, s in enumerate(spectra)])
    gamma_psd = float(math.exp(periods[0]))

    # 3-4. lattice fit with restarts, then the coarser lattices of the best
    best = None
    nit = 0
    exact = 1e-20 * float(rhs @ rhs)
    for period, ref in progress.iterate(list(zip(periods, refs)), "sequencing: lattice fits"):
        lq1, lg = lattice_from_period(log_q, period, ref, acqs[0].length, bins, groups)
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
    gamma, lam1 = math.exp(lg), 2 * math.pi / math.exp(lq1)
    n, mat = design_matrix(lq1, lg, acqs, ranges, weights)
    # damped where the data cannot resolve it (:mod:`.regularise`): least squares ranks
    # the lattices above, but its coefficients along the directions the data do not
    # resolve (the long chromosomes of fine lattices and the line, collinear) are not
    # the data's (measured rows: waves of 0.4-7 m that cancel)
    coef = solve_model(mat, rhs, acqs, regularise=REGULARISE)
    cvec = coef[0:2 * n.size:2] + 1j * coef[1:2 * n.size:2]
    # the acquisitions' height offsets (their heights at x = 0 off the genome's zero) and
    # tilts (the line a levelled profile lost)
    offsets = coef[2 * n.size:2 * n.size + len(acqs)]
    tilts = np.array([coef[2 * n.size + len(acqs) + c] if c >= 0 else 0.0
                      for c in tilt_columns(acqs)])
    given = acqs                         # the data as given: the yardstick of the quality
    acqs = [Acquisition(a.x, a.z - off - tilt * a.x, a.length, window=a.window)
            for a, off, tilt in zip(acqs, offsets, tilts)]
    amps, thetas = np.abs(cvec), np.angle(cvec)

    # 5. genes
    A, H = amplitude_genes(n, amps, gamma, lam1)
    errors = amplitude_gene_errors(n, amps, gamma, lam1)
    m_values = M_VALUES
    g1 = Genome(A=A, H=H, gamma=gamma, lambda1=lam1, phases=np.zeros((1, n.size)), n_first=int(n[0]))
    unit = g1.prefactor * gamma ** ((1.0 - n) * H)       # G(M=1) gamma^((1-n)H)
    u = amps / unit                                     # = |sum_m e^{i phi}| / sqrt(M)
    loglik = ridge_likelihood(u, m_values, rng=rng)
    if M is None:
        M = m_values[int(np.argmax(loglik))] if np.isfinite(loglik).any() else \
            max(2, int(math.ceil(float(np.max(u)) ** 2)))
    M = int(M)
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
    # relative to the data as given: the fitted offsets and tilts are unknowns of the
    # model, and the heights less them are no yardstick (plu-1's row: a shared tilt of
    # 0.18 m/m against chromosomes of 2e-4 m, heights less the tilt of 6.5e-5 m rms on a
    # row of 1.8e-8 m rms, read as a misfit of 1e-4 where the data's is 0.37)
    rms = np.array([_rel_rms(a.z - f, g.z) for a, g, f in zip(acqs, given, fitted)])
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
        # the clipping (an M too small for the amplitudes, e.g. imposed) is the cause of
        # the misfit it leaves, not the data: Table 1 with M = 1 read "not WM-like" (0.87)
        # first, while M = 8 reproduces it to 1e-14
        rms_text = ("relative rms error " + ", ".join(f"{e:.3g}" for e in rms)
                    + f" exceeds {rms_tolerance:g}")
        if over.any():
            messages.append(rms_text + " with the clipped amplitudes")
        else:
            messages.insert(0, "not WM-like: " + rms_text)
    # a small misfit does not make a genome: a fit with about as many unknowns as
    # distinct nodes reproduces any acquisitions (di-1.di: 145 chromosomes, H = 3, waves
    # of 2.9 m on a profile of 15 nm rms, off by 1e8 on windows it was not fitted to).
    # Its nodes held out of the fit (:mod:`.holdout`) are missed by far more than the
    # tolerance; a genome predicts them to about its misfit
    held_out = held_out_errors(lq1, lg, given, ranges, weights, rhs,
                               regularise=REGULARISE)
    z_scale = max(float(np.max(np.abs(a.z - a.z.mean()))) for a in given)
    at_bound = not (H_SEARCH[0] * (1 + 1e-6) < H < H_SEARCH[1] * (1 - 1e-6))
    reasons = []
    if at_bound:
        reasons.append(f"H = {H:.4g} is the end of its search interval {H_SEARCH} (the "
                       f"chromosome amplitudes follow no power law)")
    if float(np.max(amps)) > OVERFIT_FACTOR * z_scale:
        reasons.append(f"chromosome amplitudes up to {float(np.max(amps)):.3g} m on "
                       f"acquisitions of at most {z_scale:.3g} m (waves that cancel: an overfit)")
    bounds, rise = tilt_bounds(given), LINE_PER_AMPLITUDE * OVERFIT_FACTOR
    at = [i for i, c in enumerate(tilt_columns(given))
          if c >= 0 and abs(tilts[i]) >= (1 - 1e-9) * bounds[c]]
    if at and all(a.window for a in given):
        reasons.append(f"the line shared by the windows is at its bound, {tilts[0]:.3g} m/m "
                       f"(rising over half the row by {rise:.3g} "
                       f"times the largest height: the longest chromosomes trade with it)")
    elif at:
        reasons.append("the line of acquisition " + ", ".join(
            f"{i + 1} is at its bound, {tilts[i]:.3g} m/m" for i in at)
            + f" (rising over half its window by {rise:.3g} times the largest height: the "
            f"longest chromosomes trade with it)")
    if ok and float(np.max(held_out)) > rms_tolerance:
        reasons.append(overfit_reason(held_out, rms, [2 * (r[1] - r[0] + 1) for r in ranges],
                                      [g.z.size for g in given]))
    if reasons:
        ok = False
        messages.insert(0, "not a genome: " + "; ".join(reasons))
    message = "; ".join(messages) if messages else \
        "sequenced: relative rms errors " + ", ".join(f"{e:.2e}" for e in rms)
    meta_report = {"rms_errors": rms.tolist(), "success": ok}
    genome = Genome(A=A, H=H, gamma=gamma, lambda1=lam1, phases=phases, n_first=int(n[0]),
                    metadata={**genome.metadata, "sequencing": meta_report})
    return SequencingResult(
        genome=genome, success=ok, message=message, nit=nit, n=n, amplitudes=amps, phases=thetas,
        ranges=ranges, lengths=np.array([a.length for a in acqs]), rms_errors=rms,
        x=[a.x for a in acqs], heights=[a.z for a in acqs], fitted=fitted, zd_x=zd_x, zd=zd,
        zd_fit=zd_fit, spectra=spectra, gamma_psd=gamma_psd, H_psd=peak_slope_H(spectra, lq1, lg),
        M_loglik=loglik, M_support=ridge_support(loglik, m_values),
        lnA_stderr=errors[0], H_stderr=errors[1], offsets=offsets, tilts=tilts,
        held_out_errors=held_out,
        A0=variance_amplitude(given[0].z, np.arange(ranges[0][0], ranges[0][1] + 1), gamma, lam1, H),
        seed=int(seed), elapsed=time.perf_counter() - t0)
