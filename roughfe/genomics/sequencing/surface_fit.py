"""Step 4 of 2D MWM sequencing: the nonlinear fit of the lattice and the ridge angles
(variable projection, :func:`fit_model`), its information criterion (:func:`fit_bic`),
and the band of chromosomes the data hold (:func:`present_band`, :func:`polish`).

See :mod:`roughfe.genomics.sequencing.surface` for the model, the conventions and the
driver that calls these.
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import least_squares

from .lattice import bic, label_q1, round_off_cost


def clip_ranges(ranges, band):
    """The chromosome ranges (n_s, n_f) of the acquisitions clipped to ``band`` (the first
    and last chromosome present in the data, :func:`present_band`; None: unclipped)."""
    if band is None:
        return ranges
    return [(max(ns, band[0]), min(nf, band[1])) for ns, nf in ranges]


def fit_model(model, p0, budget=60, continuation=True, band=None, exact=False):
    """Levenberg-Marquardt on (ln q1, ln gamma, theta), with continuation in the cap.

    ``continuation=False``: a direct fit of the whole model (enough when the peaks put
    every wave in the basin). ``continuation=True`` (the caller tried the direct fit and it
    did not reproduce the data to round-off): the fit from ``p0`` adds the chromosomes a
    few at a time (the basin in ln gamma shrinks like 1/n). ``band``: the chromosomes
    fitted are those of Eq. 3.5 within it (:func:`clip_ranges`). ``exact``: every linear solve
    is :meth:`~.surface_grid.GridModel.solve`'s exact one (the final polish).
    """
    nit = 0
    ranges = clip_ranges(model.ranges(p0[0], p0[1]), band)
    lo = min(r[0] for r in ranges)
    hi = max(r[1] for r in ranges)
    caps = list(range(min(lo + 3, hi), hi + 1)) if continuation else [hi]
    if len(caps) > 5:
        caps = sorted(set(np.linspace(caps[0], hi, 5).round().astype(int).tolist()))
    p = np.asarray(p0, float)
    for cap in caps:
        cache = {}

        def sol(x):
            key = x.tobytes()
            if key not in cache:
                cache.clear()
                cache[key] = model.solve(x, ranges, cap, exact=exact)
            return cache[key]

        res = least_squares(lambda x: sol(x)["resid"] / model.scale, p,
                            jac=lambda x: model.jacobian(x, sol(x)) / model.scale,
                            method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15,
                            max_nfev=budget if cap == caps[-1] else 10)
        nit += res.nfev
        p = res.x
        if p[1] <= 0:
            raise ValueError("gamma <= 1")
        p[0] = label_q1(p[0], p[1], model.acqs[0].length)    # n_s = 1 for L_1 (Eq. 3.5)
        new = clip_ranges(model.ranges(p[0], p[1]), band)
        if new != ranges:            # the lattice moved across an Eq. 3.5 boundary
            ranges = new
    return p, ranges, nit


def fit_bic(model, cost, sol, p):
    """Bayesian information criterion (:func:`~.lattice.bic`, lower is better) of a fit,
    unknowns = the wave and plane coefficients and the lattice. (Measured, 1 % noise,
    gamma = 1.6: by the lowest cost gamma^(1/3) won with the misfit at the noise level, H
    and A wrong.)"""
    unknowns = 2 * sol["nn"].size + 3 * len(model.acqs) + len(p)
    # two fits exact to round-off (the sequencers' one definition) tie: the lattice with
    # fewer unknowns wins (measured: a floor of 1e-32 z.z, below the ~1e-29 the solve
    # reaches, let round-off pick sqrt(gamma) for gamma in 3 of 136 noise-free genomes)
    return bic(cost, model.z.size, unknowns, round_off_cost(model.z @ model.z))


def present_band(model, p, ranges):
    """The chromosomes the data hold: the band (first, last) left when the empty
    chromosomes at either end of the fit's band are dropped, or None when none is.

    Eq. 3.5 takes each window's chromosomes down to wavelengths of one node spacing, as a
    genome realises them (:func:`~roughfe.genomics.genome.realize_surface`); data need not
    hold them all (``mwm_surface`` stops its band strictly below the Nyquist wavenumber:
    n = 1..9 of Eq. 3.5's 1..11 at 64^2; its ``n_range`` or ``wavelength`` may leave the
    longest ones empty). The fit leaves such a chromosome at round-off (1e-14 of the
    heights), or, when its waves are nearly collinear with the others (the longest
    waves of 10 ridges), with coefficients of 1e-6 that cancel; but a genome puts waves
    on its power law into every chromosome of its phase matrix: kept, they misfit the
    data by 6 % (H 0.74 for 0.7, A 1.6e-6 for 1e-6, 64^2). So the end chromosome is
    dropped while the fit without it has no higher Bayesian information criterion
    (:func:`fit_bic`, one linear solve each): exact data leave its cost at round-off, and
    noise leaves it within the noise its 2 M coefficients fitted. A chromosome the data
    hold raises the cost beyond that. (The profile sequencer keeps the whole Eq. 3.5
    band: a profile's chromosome is the phasor sum of its M waves, which its phases make
    zero.) An empty chromosome *inside* the band is kept: it is the mark of a sub-lattice
    fit (:func:`.surface._every_chromosome_present`)."""
    band = [min(r[0] for r in ranges), max(r[1] for r in ranges)]
    sol = model.solve(p, ranges, exact=True)      # the fit's cost, not its diagonal's
    score = fit_bic(model, float(sol["resid"] @ sol["resid"]), sol, p)
    trimmed = False
    for side, step in ((1, -1), (0, 1)):           # the short end first, then the long
        while band[0] < band[1]:
            trial = list(band)
            trial[side] += step
            clipped = clip_ranges(ranges, trial)
            if any(ns > nf for ns, nf in clipped):
                break                            # an acquisition would hold none
            try:
                out = model.solve(p, clipped, exact=True)
            except np.linalg.LinAlgError:
                break
            cost = fit_bic(model, float(out["resid"] @ out["resid"]), out, p)
            if not cost <= score:
                break
            band, score, trimmed = trial, cost, True
    return tuple(band) if trimmed else None


def polish(model, p, ranges, sol, nit, rounds=3):
    """A fit within the tolerance without the empty chromosomes at the ends of its band
    (:func:`present_band`), its lattice and angles refitted with exact solves
    (:meth:`~.surface_grid.GridModel.solve`): (p, ranges, sol, nit), ``sol`` an exact solve.

    The nonlinear fit's solves carry a small diagonal (:func:`~.surface_grid._factor`);
    an ill-conditioned fit reaches round-off only with exact ones (the 10 ridges of
    ``mwm_surface``, cond 3e13, 64^2: relative misfit 1.6e-7 and angles off by 4e-8 deg
    before, 6e-15 after). A refit is kept when it lowers the exact cost. The band is read
    again at the refitted lattice, up to ``rounds`` times: empty long chromosomes of 10
    ridges (``n_range`` from 3) leave the fit at 5e-10 off round-off until the lattice is
    exact, and only then are they told from the data's. No refit when the band is whole
    and the exact solve's cost is at round-off or within 1e-6 of the search's (``sol``):
    the diagonal then did not move the fit (resolvable genomes, noise-free or noisy:
    genes as before to 1.5e-9)."""
    searched = float(sol["resid"] @ sol["resid"])
    sol = model.solve(p, ranges, exact=True)
    cost = float(sol["resid"] @ sol["resid"])
    unmoved = cost <= round_off_cost(model.z @ model.z) or cost >= (1.0 - 1e-6) * searched
    for round_ in range(rounds):
        band = present_band(model, p, ranges)
        if band is not None:
            ranges = clip_ranges(ranges, band)
            sol = model.solve(p, ranges, exact=True)
        elif round_ or unmoved:
            break                # the band is whole, and the lattice needs no refit
        band = (min(r[0] for r in ranges), max(r[1] for r in ranges))
        try:
            new, r_new, k = fit_model(model, p, continuation=False, band=band, exact=True)
            s_new = model.solve(new, r_new, exact=True)
        except (np.linalg.LinAlgError, ValueError):
            break
        nit += k
        if not float(s_new["resid"] @ s_new["resid"]) <= float(sol["resid"] @ sol["resid"]):
            break
        p, ranges, sol = new, r_new, s_new
    return p, ranges, sol, nit
