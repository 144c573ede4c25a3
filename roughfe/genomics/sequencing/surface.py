"""Genome sequencing of 2D MWM surfaces (issue 15 §1; model: thesis Sec. 3.3.2, Eq. 3.17).

Beyond the thesis: its sequencing (Sec. 3.3.1) is of profiles only; everything here (the
2D periodogram, ridge clustering, the grid fit, sub-lattice and empty-ridge handling) is
this package's.

Model (Eq. 3.17 in the projected plane-wave form of :func:`roughfe.surfaces.wm.wm_series`
and :func:`roughfe.genomics.genome.realize_surface`): ridge m is a plane wave along the
in-plane direction theta_m,

    Z(x, y) = sum_n sum_m G gamma^((1-n)H) alpha_m [cos(phi_mn) - cos(q_n (x cos theta_m
              + y sin theta_m) + phi_mn)],      q_n = (2 pi / lambda1) gamma^(n-1).

What a surface can tell (unlike a profile)
------------------------------------------
On a profile all M ridges of chromosome n share the wavenumber q_n and only their phasor
sum is seen (:mod:`roughfe.genomics.sequencing`). On a surface every ridge of every
chromosome is its own wavevector q_n (cos theta_m, sin theta_m), so M, the angles Theta,
the amplitude factors alpha and every phase phi_mn are identifiable, and so are A and H
(the amplitudes b_mn = G gamma^((1-n)H) alpha_m are then known one by one, and
ln b_mn is linear in (ln G, H, ln alpha_m)).

Conventions
-----------
* Angles are defined modulo pi: the ridge at theta + pi is the same wave with phase -phi
  (cos(-q x.e + phi) = cos(q x.e - phi)). Sequenced angles lie in [0, pi); a ridge found
  at theta >= pi is reported at theta - pi with its phases negated.
* A and alpha share one scale: the anisotropy factors are normalised to a geometric mean
  of 1 (prod alpha_m = 1), and A carries the scale.
* lambda1 is labelled as for profiles (Eq. 3.5): lambda1 in [L_1, gamma L_1) for the
  coarsest acquisition L_1, so that its first chromosome is n = 1. (Any lambda1 gamma^k
  with the indices shifted by k and A rescaled describes the same heights.)
* The genome is band-limited: its phase matrix spans exactly the chromosomes present in
  the data (n_first..n_last): those of Eq. 3.5 over all acquisitions, less the empty
  ones at either end of that band (:func:`~.surface_fit.present_band`; data need not
  reach Eq. 3.5's wavelength of one node spacing: ``mwm_surface`` stops below the
  Nyquist wavenumber). The sequencer never invents chromosomes outside the data's band;
  it does not extend it either: a wave longer than gamma L_1 (an ``n_range`` of
  ``mwm_surface`` from 0 or below) is outside Eq. 3.5 and not modelled.

Steps (:func:`sequence_surfaces`)
---------------------------------
1. Windowed (Blackman-Harris, ~92 dB side lobes), zero-padded 2D periodogram of each
   acquisition; peaks = local maxima above the noise floor, located to sub-bin precision.
   Only peaks below 0.9 Nyquist on both axes are used (Eq. 3.5 keeps chromosomes with
   wavelengths between one and two node spacings, which alias on the grid).
2. Angles: the peak directions (mod pi) clustered; clusters of >= 2 peaks are ridges.
3. Lattice (gamma, q1): the comb fit of the profile sequencer on ln |q| of the peaks.
4. Variable projection: the heights are linear in the cos/sin coefficients of every
   (m, n) wave plus a plane per acquisition (which absorbs a removed mean plane);
   (ln q1, ln gamma, theta_1..theta_M) are refined by Levenberg-Marquardt with the
   Kaufman Jacobian, in continuation over the highest chromosome fitted; every product
   is separable on the tensor grids of the acquisitions (:class:`.surface_grid.GridModel`);
   among the gamma candidates the lowest BIC wins (:func:`fit_bic`). The search stops at the
   first candidate that fits the data to round-off or down to its white-noise floor (the
   noise variance read from the periodogram's high-q plateau, :func:`_noise_floor`) with
   every chromosome above the noise: no other candidate, continuation or added ridge can
   fit better than the noise allows (measured, 512^2 pair, 1 % noise, seeds 0-4: 4.4-32.5 s
   CPU before, 0.9-2.6 s after, the same genes). A fit within the tolerance loses the
   empty chromosomes at the ends of its band and is refitted with exact linear solves
   (:func:`~.surface_fit.polish`; the search's solves carry a small diagonal that keeps
   its landscape smooth, :func:`~.surface_grid._factor`). A fit within the tolerance
   with an empty chromosome inside its band may be a sub-lattice gamma^(1/k) fit: it is
   also tried on the coarser lattices (:func:`~.lattice.coarser_lattices`), the lower
   BIC wins, and a coarser fit that wins and is not at its floor is tried in turn
   (:data:`SETTLE_ROUNDS`: the search path of a poor start is chaotic in round-off and
   may end near no sub-lattice of the data's).
5. Genes: b_mn, phi_mn from the coefficients; (ln G, H, ln alpha) by least squares on
   ln b_mn weighted by b_mn^2, refined to the least height misfit of the genome with the
   fitted phases; A from G (Eq. 3.1) (:mod:`.surface_result`, with the misfits and the
   result).
6. Checks: the misfit of the genome; the nodes held out of the fit (an overfit,
   :mod:`.holdout`); and, for a fit that passes them, the lattice and ridges of the two
   halves of the data fitted again from the whole's (:mod:`.surface_reproduce`).
Undefined points (NaN) of a measured acquisition are left out of every step. The misfit
reported (``rms_errors``, ``success``) is that of the returned genome realised on the
acquisitions, not of the fit (every wave its own amplitude, ``fit_rms_errors``).
"""
from __future__ import annotations

import math
import time

import numpy as np

from ... import progress
from ..genome import Genome
from .acquisitions import check_controls
from .lattice import coarser_lattices, comb_periods, lattice_from_period, round_off_cost
from .surface_data import (ANGLE_TOL, SurfaceAcquisition, cluster_angles, noise_variance,
                           surface_acquisitions, surface_peaks)
from .surface_fit import fit_bic, fit_model, polish
from .surface_grid import GridModel
from .holdout import overfit_reason
from .surface_reproduce import surface_reproducibility
from .surface_result import (SurfaceSequencingResult, failure, genes_from_fit,
                             genome_residual, held_out_misfits, plane_free_misfits)


#: nodes (over all acquisitions) used by the nonlinear fit; the final solve uses every node
FIT_ROWS = 16384
#: a fit whose residual sum of squares is within this factor of the white-noise floor
#: (the noise variance of :func:`~.surface_data.surface_peaks` times the rows) explains all
#: but the noise: the estimate is within 2 % at 512^2 and 3-17 % high at 128^2 (measured,
#: 1 % and 0.1 % noise, seeds 0-4), and a fit of the noise alone leaves (1 - unknowns /
#: rows) of it
NOISE_FLOOR_FACTOR = 1.25
#: a chromosome is present when its strongest wave exceeds this many standard errors of a
#: wave amplitude fitted to noise alone (Rayleigh: exceeded by noise with probability
#: exp(-SIGNIFICANCE^2 / 2) = 4e-6 per wave)
SIGNIFICANCE = 5.0
#: the least comb coherence (:func:`~.lattice.comb_periods`) of the ridge peaks for a
#: discrete WM spectrum: measured 0.71-1.0 on resolvable MWM pairs (N = 64-256, noise up
#: to 20 %, seeds 0-2) and 0.12-0.27 on periodic self-affine surfaces (Fourier filtering,
#: 256^2, H = 0.3 and 0.8, 4 seeds), whose 17-31 "ridges" of periodogram maxima made the
#: fit run for more than 12 minutes before it failed
MIN_COMB_COHERENCE = 0.5
#: rounds of :func:`sequence_surfaces`' settling on coarser lattices (each a lower BIC):
#: a fit near no sub-lattice of the data's lattice (gamma^(2/9)) settled on gamma^(1/2)
#: in the first and on gamma in the second (measured, one window of seed 1 at 48^2, the
#: search path of OpenBLAS); 1 until round 2, session 42
SETTLE_ROUNDS = 3
#: the final fit and its held-out fits are damped where the data cannot resolve them, as
#: the profile sequencer's are (:mod:`.regularise`, :meth:`~.surface_grid.GridModel.solve`);
#: False: least squares, as until round 2, session 35
REGULARISE = True
#: a fit that passes the other tests is fitted again on each half of its data and its
#: lattice and ridges compared (:mod:`.surface_reproduce`); False: not tested, as until
#: round 2, session 35
REPRODUCE = True


def _chromosome_presence(sol, ratio=1e-6, noise=0.0):
    """(n, present): the chromosomes of the fit and whether each carries a wave above
    ``ratio`` times the strongest and above ``SIGNIFICANCE`` times ``noise`` (m, the
    standard error of a wave amplitude fitted to white noise alone)."""
    w = sol["nn"].size
    b = np.hypot(sol["coef"][:w], sol["coef"][w:2 * w])
    n = np.unique(sol["nn"])
    per_n = np.zeros(n.size)
    np.maximum.at(per_n, sol["nn"] - n[0], b)
    return n, per_n > max(ratio * b.max(), SIGNIFICANCE * noise)


def _every_chromosome_present(sol, ratio=1e-6, noise=0.0):
    """True when every chromosome of the fit is present (:func:`_chromosome_presence`).
    A fit that reproduces the data to round-off, or down to its noise floor, with this
    property is the lattice: a sub-lattice gamma^(1/k) (as good a fit) leaves k - 1 of
    every k chromosomes empty, or holding noise only, so the remaining gamma candidates
    need not be tried."""
    return bool(_chromosome_presence(sol, ratio, noise)[1].all())


def _noise_floor(model, variances):
    """The white-noise floor of a fit on ``model``: ``(cost, amplitude)``, the residual sum
    of squares (m^2) the noise alone leaves (``variances``: sigma_k^2 per row of
    acquisition k, from the periodogram plateau of :func:`~.surface_data.surface_peaks`)
    and the standard error (m) of a wave amplitude fitted to it, sigma sqrt(2 / rows) with
    the largest sigma and the fewest rows of an acquisition (the strictest test of a
    chromosome's presence)."""
    var = np.asarray(variances, float)
    rows = np.bincount(model.block, minlength=var.size)
    return (float(var @ rows),
            float(np.sqrt(var.max() * 2.0 / max(int(rows[rows > 0].min()), 1))))


def _merge_duplicate_ridges(p, tol=ANGLE_TOL / 10):
    """Drop ridges whose angle (mod pi) lies within ``tol`` of an earlier ridge's."""
    theta = np.mod(p[2:], np.pi)
    keep = []
    for k, t in enumerate(theta):
        if all(abs(np.angle(np.exp(2j * (t - theta[j])))) / 2 > tol for j in keep):
            keep.append(k)
    return np.concatenate([p[:2], p[2:][keep]])


def _weak_ridges(sol, n_ridges, ratio=0.01):
    """Ridges whose waves are all below ``ratio`` times the strongest wave of the same
    chromosome (median over n): spurious directions (side lobes, aliases, noise)."""
    w = sol["nn"].size
    b = np.hypot(sol["coef"][:w], sol["coef"][w:2 * w])
    n = np.unique(sol["nn"])
    amp = np.zeros((n_ridges, n.size))
    amp[sol["mm"], sol["nn"] - n[0]] = b
    rel = amp / np.maximum(amp.max(axis=0, keepdims=True), 1e-300)
    return np.flatnonzero(np.median(rel, axis=1) < ratio)


def _residual_acquisitions(full, p, ranges):
    """The residual of the fit at ``p`` on every node of each acquisition (``full`` is the
    model of all nodes; NaN where undefined)."""
    resid = full.solve(p, ranges)["resid"]
    out = []
    for k, a in enumerate(full.acqs):
        z = np.full(a.z.shape, np.nan)
        z[a.valid] = resid[full.block == k]
        out.append(SurfaceAcquisition(a.x, a.y, z, a.length))
    return out


def _add_missing_ridges(model, full, p, ranges, sol, done, max_new=8):
    """Greedy completion: a direction that holds the strongest peaks of the residual's
    periodogram becomes a new ridge when the refit halves the residual (ridges with one
    detected peak, or close to a stronger one, are missed by the first clustering).
    Nothing is tried once ``done(cost, p, ranges, sol)`` (the residual sum of squares at
    round-off or the noise floor: no refit can halve it there)."""
    nit = 0
    cost = float(sol["resid"] @ sol["resid"])
    for _ in range(max_new):
        if done(cost, p, ranges, sol):
            break
        peaks = [surface_peaks(a) for a in _residual_acquisitions(full, p, ranges)]
        ang = np.concatenate([pk.angle for pk in peaks])
        pw = np.concatenate([pk.power for pk in peaks])
        if ang.size == 0:
            break
        centres, labels, _ = cluster_angles(ang, pw)
        strength = np.bincount(labels, weights=pw)
        new = centres[int(np.argmax(strength))]
        try:
            p_new, r_new, k = fit_model(model, np.append(p, new), continuation=False)
            s_new = model.solve(p_new, r_new)
        except (np.linalg.LinAlgError, ValueError):
            break
        nit += k
        c_new = float(s_new["resid"] @ s_new["resid"])
        if not c_new < 0.5 * cost:
            break
        p, ranges, sol, cost = p_new, r_new, s_new, c_new
    return p, ranges, sol, nit


def sequence_surfaces(surfaces, *, valid=None, rms_tolerance=0.05,
                      n_restarts=3) -> SurfaceSequencingResult:
    """Sequence the genome of a 2D MWM surface from one or more nested acquisitions.

    Parameters
    ----------
    surfaces : sequence of Surface
        N x N acquisitions with the genome node convention on both axes (node (N//2, N//2)
        at the origin, spacing L/(N-1); ``metadata["x0"]`` (and ``"y0"``) when given), at
        observation lengths L_1 > L_2 > ...; non-periodic windows.
    valid : sequence of bool ndarray, optional
        Per acquisition, True where the height is defined (undefined points are left out).
    rms_tolerance : float
        Relative rms misfit above which ``success`` is False (not WM-like, or noisy).
    n_restarts : int
        Number of comb periods (gamma candidates) tried; the least Bayesian information
        criterion wins (the residual alone prefers a lattice gamma^(1/j) on noisy data).
    """
    t0 = time.perf_counter()
    rms_tolerance, n_restarts = check_controls(rms_tolerance, n_restarts)
    acqs = surface_acquisitions(surfaces, valid)
    n_nodes = acqs[0].z.shape[0]
    peaks = [surface_peaks(a) for a in acqs]
    q = np.concatenate([pk.magnitude for pk in peaks])
    ang = np.concatenate([pk.angle for pk in peaks])
    if q.size < 4:
        return failure(f"only {q.size} spectral peaks: the spectrum is not a discrete WM "
                        f"spectrum", acqs, peaks, t0)
    centres, labels, sizes = cluster_angles(ang, q ** 2)
    ridges = np.flatnonzero(sizes >= 2)
    if ridges.size == 0:
        return failure("no direction holds two or more spectral peaks: no MWM ridges found",
                        acqs, peaks, t0)
    in_ridge = np.isin(labels, ridges)
    log_q = np.log(q[in_ridge])
    groups = np.concatenate([np.full(pk.qx.size, k) for k, pk in enumerate(peaks)])[in_ridge]
    groups = groups * 1000 + labels[in_ridge]           # one peak per (acquisition, ridge, n)
    periods, coherence, refs = comb_periods(log_q, n_best=n_restarts)
    if not coherence.size or coherence.max() < MIN_COMB_COHERENCE:
        return failure(
            f"the {log_q.size} spectral peaks in {ridges.size} directions lie on no geometric "
            f"lattice ln q_n = ln q_1 + (n-1) ln gamma (comb coherence "
            f"{coherence.max() if coherence.size else 0.0:.2f} < {MIN_COMB_COHERENCE}): the "
            f"spectrum is continuous (a self-affine or measured surface), not the discrete "
            f"spectrum of an MWM surface; a genome of a measured surface is sequenced from a "
            f"profile by `roughfe genome natural`", acqs, peaks, t0)
    # the nonlinear fit on a tensor sub-grid of about FIT_ROWS nodes, the final solve on all
    axis_nodes = math.ceil(math.sqrt(FIT_ROWS / len(acqs)))
    model = GridModel(acqs, n_nodes, axis_nodes=axis_nodes)
    full = GridModel(acqs, n_nodes)
    # fitted to round-off, or down to the white-noise floor of the data (measured data,
    # noise): no other gamma candidate, continuation or added ridge can do better
    noise_cost, noise_amplitude = _noise_floor(model, [pk.noise_variance for pk in peaks])
    exact = round_off_cost(model.z @ model.z)
    tiny = max(exact, NOISE_FLOOR_FACTOR * noise_cost)
    holes = not all(a.valid.all() for a in acqs)

    def at_floor(cost, p, ranges, sol):
        """True when a fit's cost is at round-off or the noise floor. With undefined
        nodes the periodogram's plateau holds the error of their harmonic fill too (white,
        like noise): it let a fit stop at a 3 % misfit of noise-free data. The floor is
        then read again with the undefined nodes filled by this fit's own heights, whose
        error there is the fit's misfit on a few per cent of the nodes: it cannot pass
        for noise."""
        if cost <= exact or (cost <= tiny and not holes):
            return True
        if cost > tiny:
            return False
        filled = [SurfaceAcquisition(a.x, a.y, np.where(a.valid, a.z, h), a.length)
                  for a, h in zip(acqs, full.heights(p, ranges, sol["coef"]))]
        floor = _noise_floor(model, [noise_variance(a) for a in filled])[0]
        return cost <= NOISE_FLOOR_FACTOR * floor
    good = max(tiny, rms_tolerance ** 2 * float(model.z @ model.z))   # within the tolerance

    def score(out):
        return fit_bic(model, out[0], out[3], out[1])

    def settle(out, rounds=SETTLE_ROUNDS):
        """A fit within the tolerance with an empty chromosome may stand for a coarser
        lattice (a sub-lattice fit): the best-scoring start of
        :func:`~.lattice.coarser_lattices` is fitted and the lower BIC of the two is
        kept. A coarser fit that wins is settled in turn (``rounds`` in all) when it
        has an empty chromosome or is above its floor (:func:`at_floor`): the first
        fit may lie on no sub-lattice of the data's but near one (gamma^(2/9), misfit
        2.4 %), whose coarser lattices hold only a sub-lattice (gamma^(1/2), misfit
        4e-4 with every chromosome present: the data's first chromosome lies below its
        Eq. 3.5 band); from there the data's lattice is offered. (Poor fits are left
        alone: among them the BIC is a lottery, measured 1 seed in 100 turned from
        right to wrong.)"""
        if not rounds or out[0] > good:
            return out
        if _every_chromosome_present(out[3], noise=noise_amplitude) and (
                rounds == SETTLE_ROUNDS or at_floor(*out[:4])):
            return out
        trial = []
        for start in coarser_lattices(out[1], int(out[3]["nn"].min()), acqs[0].length):
            try:
                sol = model.solve(start, model.ranges(start[0], start[1]))
            except np.linalg.LinAlgError:
                continue
            trial.append((float(sol["resid"] @ sol["resid"]), start, None, sol, 0))
        if not trial:
            return out
        try:
            alt = attempt(min(trial, key=score)[1], False, coarsen=False)
        except (np.linalg.LinAlgError, ValueError):
            return out
        nit = out[4] + len(trial) + alt[4]
        if not score(alt) < score(out):
            return out[:4] + (nit,)
        return settle(alt[:4] + (nit,), rounds - 1)

    def prune(p, ranges, sol, nit):
        """Drop merged ridges and ridges with no lattice waves (:func:`_weak_ridges`) and
        refit; a fit within the tolerance then loses the empty chromosomes at the ends of
        its band and is refitted with exact solves (:func:`polish`; poor fits are left
        alone, as in :func:`settle`): (cost, p, ranges, sol, nit)."""
        p = _merge_duplicate_ridges(p)
        weak = _weak_ridges(sol, p.size - 2) if p.size == sol["mm"].max() + 3 else []
        if len(weak) and len(weak) < p.size - 2 or p.size != sol["mm"].max() + 3:
            # a direction with no lattice waves, or two ridges fitted onto one
            p, ranges, k = fit_model(model, np.delete(p, 2 + np.asarray(weak, int)),
                                continuation=False)
            nit += k
            sol = model.solve(p, ranges)
        if float(sol["resid"] @ sol["resid"]) <= good:
            p, ranges, sol, nit = polish(model, p, ranges, sol, nit)
        return float(sol["resid"] @ sol["resid"]), p, ranges, sol, nit

    def attempt(p0, continuation, coarsen=True):
        """Fit from p0, :func:`prune`, then (``coarsen``) :func:`settle`:
        (cost, p, ranges, sol, nit)."""
        p, ranges, nit = fit_model(model, p0, continuation=continuation)
        out = prune(p, ranges, model.solve(p, ranges), nit)
        return settle(out) if coarsen else out

    def complete(out):
        """Add the ridges the first clustering missed (best lattice only), then
        :func:`prune` (an added ridge can take over the waves of a ridge found at a wrong
        angle, which then holds none: kept, it came out with alpha ~ 1e-9 and, as the
        alphas have a product of 1, the others x 1e4 and A x 1e-4) and :func:`settle`."""
        p, ranges, sol, k = _add_missing_ridges(model, full, out[1], out[2], out[3],
                                                at_floor)
        return settle(prune(p, ranges, sol, out[4] + k))

    starts = []
    for period, ref in zip(periods, refs):
        log_q1, log_gamma = lattice_from_period(log_q, period, ref, acqs[0].length,
                                                 weights=q[in_ridge], groups=groups)
        if log_gamma > 0:
            starts.append(np.concatenate([[log_q1, log_gamma], centres[ridges]]))
    best, nit = None, 0
    # direct fits from every gamma candidate; the best is completed with missed ridges;
    # only when that does not reproduce the data to round-off or to the noise floor is the
    # continuation tried from every candidate as well; the lowest BIC wins

    for continuation in (False, True):
        outs = []
        label = ("sequencing: lattice fits" if not continuation
                 else "sequencing: fits by continuation")
        for p0 in progress.iterate(starts, label):
            try:
                outs.append(attempt(p0, continuation))
            except (np.linalg.LinAlgError, ValueError):
                continue
            if (_every_chromosome_present(outs[-1][3], noise=noise_amplitude)
                    and at_floor(*outs[-1][:4])):
                break        # exact (or at the noise floor), and not a sub-lattice
        nit += sum(o[4] for o in outs)
        if not outs:
            continue
        first = min(outs, key=score)
        top = complete(first)
        nit += top[4] - first[4]
        if best is None or score(top) < score(best):
            best = top
        if at_floor(*best[:4]):
            break
    if best is None:
        return failure("no gamma candidate gave a lattice fit", acqs, peaks, t0)
    _, p, ranges, _, _ = best
    sol = full.solve(p, ranges, exact=True, regularise=REGULARISE)
    g = genes_from_fit(p, sol, ranges)
    if not 0.0 < g["H"] <= 3.0:        # a Genome would refuse it with a message about
        return failure(               # an H the user never gave: a failed sequencing
            f"the fitted wave amplitudes grow or decay with an exponent H = {g['H']:.3g}, "
            f"outside (0, 3] (gamma = {math.exp(p[1]):.4g}): not a WM surface", acqs,
            peaks, t0)
    genome = Genome(A=g["A"], H=g["H"], gamma=g["gamma"], lambda1=g["lambda1"],
                    phases=g["phases"], n_first=g["n_first"], angles=g["angles"],
                    anisotropy=g["anisotropy"],
                    metadata={"source": "sequence_surfaces", "n_nodes": n_nodes,
                              "lengths": [a.length for a in acqs]})
    # the misfit of the returned genome (its amplitudes on the power law of its lattice),
    # not of the fit (every wave its own amplitude): the two agree for a WM surface and
    # differ where the genes do not describe the fitted waves (a sub-lattice fit: 1e-11
    # against 94 %)
    fit_errs, signal = plane_free_misfits(full, sol["resid"])
    errs, _ = plane_free_misfits(full, genome_residual(genome, full))
    ok = bool(np.all(errs <= rms_tolerance))
    msg = (f"M = {genome.M} ridges, gamma = {genome.gamma:.6g}, chromosomes "
           f"{genome.n_first}..{genome.n_last}; relative rms misfit of the genome "
           f"{', '.join(f'{e:.3g}' for e in errs)} (of the fit, every wave its own "
           f"amplitude: {', '.join(f'{e:.3g}' for e in fit_errs)})")
    if not ok:
        msg += f" > {rms_tolerance:g}: not reproduced (the surface is not WM-like or noisy)"
    # a small misfit is no genome when the waves reproduce any heights: the nodes held
    # out of the fit (:mod:`.holdout`) are then missed by far more than the fitted ones
    held_out = held_out_misfits(model, p, ranges, regularise=REGULARISE)
    if ok and float(np.max(held_out)) > rms_tolerance:
        ok = False
        waves = [2 * int(np.sum((sol["nn"] >= ns) & (sol["nn"] <= nf))) for ns, nf in ranges]
        msg = ("not a genome: " + overfit_reason(held_out, fit_errs, waves,
                                                 np.bincount(model.block), "wave")
               + "; " + msg)
    # a genome is a property of the surface: the two halves of the data give its lattice
    # and ridges again (:mod:`.surface_reproduce`); run on a fit that passed the others
    repro = None
    if REPRODUCE and ok:
        repro = surface_reproducibility(acqs, n_nodes, p, ranges, axis_nodes)
        if repro.reproducible:
            msg += ("; the lattice and ridges of the two halves agree (gamma " + " / ".join(
                f"{h.gamma:.6g}" for h in repro.halves) + f", ridges within "
                f"{math.degrees(repro.angle_difference):.2g} deg)")
        else:
            ok = False
            msg = "not a genome: " + repro.reason + "; " + msg
    return SurfaceSequencingResult(
        genome=genome, success=ok, message=msg, nit=nit, ranges=[tuple(r) for r in ranges],
        lengths=np.array([a.length for a in acqs]), rms_errors=errs,
        amplitudes=g["amplitudes"], peaks=peaks, elapsed=time.perf_counter() - t0,
        signal_rms=signal, fit_rms_errors=fit_errs, held_out_errors=held_out,
        reproducibility=repro)
