"""Steps 2-4 of sequencing: the wavenumber lattice ln q_n = ln q_1 + (n-1) ln gamma
(Eq. 3.5-3.6) from the PSD peaks, then variable projection of the linear chromosome fit
(Eq. 3.12-3.16 with the phasor sums as unknowns) with continuation in the highest index."""
from __future__ import annotations

import math

import numpy as np
from scipy.linalg import lstsq as scipy_lstsq
from scipy.optimize import least_squares, lsq_linear

from ..genome import chromosome_range
from .regularise import damped_system, resolution_damping

#: a chromosome amplitude this many times the largest height of the acquisitions is a fit
#: of waves that cancel (an overfit), not a genome (WM fits stay below 1); the
#: tilts (the line of the windows of one row, a levelled profile's) are bounded by the
#: same factor (:func:`tilt_bounds`)
OVERFIT_FACTOR = 10.0
#: the largest rise, over half a window of length L, of the least-squares line of one
#: wave c [cos(theta) - cos(q x + theta)] per unit amplitude c: 3 (sin a - a cos a) / a^2
#: at a = q L / 2 = 2.0816 (theta = pi / 2), 1.3085, rounded up
LINE_PER_AMPLITUDE = 1.31


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


def lattice_from_period(log_q, period, ref, coarse_length, weights=None, groups=None):
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
    return label_q1(ref, period, coarse_length), period


def label_q1(log_q_any, period, coarse_length):
    """The lattice point ln q1 with lambda1 = 2 pi / q1 in [L_1, gamma L_1) (n_s = 1, Eq. 3.5)."""
    top = math.log(2 * math.pi / coarse_length)          # q1 <= 2 pi / L1
    return log_q_any + math.floor((top - log_q_any) / period + 1e-9) * period


def coarser_lattices(p, n0, coarse_length, k_max=6, gamma_max=4.0):
    """Starts (ln q1, k ln gamma, *rest) of every lattice that holds the lattice
    ``p = (ln q1, ln gamma, *rest)`` as every k-th chromosome, k = 2..``k_max``
    (gamma^k <= ``gamma_max``, the top of the comb's search), through each of its first k
    chromosomes from ``n0`` (the first chromosome of the fit); q1 labelled by
    :func:`label_q1` (``rest``: the ridge angles of a surface fit, kept).

    A fit on a sub-lattice gamma^(1/k) of the data's lattice reproduces the data as well
    (to round-off, or down to the noise) with k - 1 of every k chromosomes empty, or
    holding noise only; a Genome forces its amplitudes onto the power law of its own
    lattice and puts waves back into them (measured, 2D: a fit to 1e-11 whose genome
    misfits its windows by 94 %). Which chromosomes are empty is not reliable near the
    window length (long waves of neighbouring chromosomes nearly collinear: all present
    in an exact gamma^(1/4) fit of one 48^2 window), so every (k, offset) is offered; the
    callers rank them by the cost of one linear solve.
    """
    starts = []
    for k in range(2, k_max + 1):
        if k * p[1] > math.log(gamma_max):
            break
        for r in range(k):
            log_q = p[0] + (n0 + r - 1) * p[1]
            starts.append(np.concatenate([[label_q1(log_q, k * p[1], coarse_length),
                                           k * p[1]], p[2:]]))
    return starts


#: relative round-off of a least-squares fit: a residual sum of squares at or below
#: ROUND_OFF times the energy of the data fitted (sum of z^2) is an exact fit, the
#: definition of "exact" of both sequencers (:func:`round_off_cost`). The linear solves
#: reach ~1e-29 relative (measured, 2D grid fit, N = 48): a floor below that (1e-32 was
#: used) let round-off choose between two exact fits, sqrt(gamma) for gamma (3 of 136
#: noise-free random surface genomes at N = 48)
ROUND_OFF = 1e-24


def round_off_cost(energy):
    """The residual sum of squares (units of ``energy``, e.g. m^2) of a fit exact to
    round-off, ``ROUND_OFF * energy`` (plus 1e-300, so that data of zero energy have a
    positive floor): the floor of :func:`bic`, and the test of an exact fit."""
    return 1e-300 + ROUND_OFF * float(energy)


def bic(cost, rows, unknowns, floor):
    """Bayesian information criterion of a least-squares fit (lower is better):
    rows ln(cost / rows) + unknowns ln(rows), ``cost`` the residual sum of squares floored
    at ``floor`` (round-off: two exact fits tie and the one with fewer unknowns wins).

    The lowest cost alone would not do: a lattice gamma^(1/k) holds the data's lattice as
    every k-th chromosome, so it fits exactly too, and with noise a little better (its
    extra waves fit noise); its extra coefficients lower the cost by about their share
    of the rows, the penalty ln(rows) per unknown keeps the data's lattice.
    """
    return rows * math.log(max(cost, floor) / rows) + unknowns * math.log(rows)


# -- step 4: variable projection -----------------------------------------------------------
def lattice_ranges(log_q1, log_gamma, acqs):
    """The chromosome range (n_s, n_f) of each acquisition, Eq. (3.5) with its own L and N.
    A window of the coarsest acquisition's profile (:attr:`.acquisitions.Acquisition.window`)
    starts at the coarsest one's n_s: it holds those long waves, while a realisation of
    its own window (Eq. 3.5) does not (a window of a Table 1 profile at L/5 without
    chromosomes 1-4 misfit by 0.5 % and its fit was an overfit). It also ends at the
    row's finest n_f: a window sampled at a stride above 1 holds the row's short
    chromosomes aliased on its nodes (Eq. 3.1 evaluated there), which its own Eq. 3.5
    range left as misfit (1-5.5 % on Table 1 rows at stride 2; 1e-13 now)."""
    lam1 = 2 * math.pi / math.exp(log_q1)
    out = [chromosome_range(math.exp(log_gamma), lam1, a.length, a.model_nodes) for a in acqs]
    top = max((r[1] for a, r in zip(acqs, out) if a.window), default=0)
    return [(out[0][0], top) if a.window else r for a, r in zip(acqs, out)]


def tilt_columns(acqs) -> list:
    """The tilt unknown of each acquisition (0, 1, ... after the offsets), or -1 for none:
    one for each levelled acquisition (:attr:`.acquisitions.Acquisition.levelled`), or
    one *shared* by windows of one row (:attr:`.acquisitions.Acquisition.window`: the
    row lost one line, its least-squares one, before it was cut into windows). The shared
    tilt is set by the full row, not by each short window (the free tilts of session 29),
    and bounded (:func:`tilt_bound`, :func:`solve_model`).

    Without it a realised Table 1 row (256 samples, seeds 0 and 1) came back as
    gamma^(1/3), exact (a finer lattice makes the line of its long chromosomes), and as
    gamma 1.22 with a misfit of 1.5e-8 (measured in round 2, session 33): removing the
    row's line once and fitting none is no exact model of a levelled row. Unbounded, it
    reached 3e3-5e5 m/m on measured rows (di-1, x3p-2, opd-1, ``--nodes 128``): a line
    lies nearly in the span of the long chromosomes of the fine lattices these fits end
    on (gamma 1.17-1.19: the design is singular to cond 1e16-1e17 with or without it),
    so the fit traded it against them. A model levelled as the data were (each
    chromosome column less its least-squares line over the row, no tilt unknown) is the
    same model, as ill-conditioned (cond 8.5e16 against 9.3e16, di-1)."""
    if acqs and all(a.window for a in acqs):
        return [0] * len(acqs)
    return list(np.cumsum([bool(a.levelled) for a in acqs]) * [bool(a.levelled) for a in acqs] - 1)


def line_columns(acqs) -> int:
    """The unknowns of the acquisitions' lines in :func:`design_matrix`: an offset for
    each, then the tilts of :func:`tilt_columns`."""
    return len(acqs) + max(tilt_columns(acqs), default=-1) + 1


def design_matrix(log_q1, log_gamma, acqs, ranges, weights, n_cap=None):
    """The linear model of the stacked acquisitions (Eq. 3.12-3.16): for each chromosome
    n the columns ``1 - cos(q_n x)`` and ``sin(q_n x)`` (the real and imaginary parts of
    its phasor sum), then a constant column per acquisition (its height offset), then a
    linear column per *levelled* acquisition (its tilt), or one shared by windows of one
    row (:func:`tilt_columns`).

    The genome's profile is zero at x = 0 (Eq. 3.1); a measured or mean-removed profile
    is not, and without the offsets the fit bends the chromosomes to absorb it
    (mean-removed Table 1 profiles: gamma 1.14 for 1.5). A levelled profile (its
    least-squares line removed, as profilometers do) lost a line: without a tilt the fit
    took gamma^(1/3) or gamma^(1/2) (a user's review, round 2, session 29). The tilt is
    fitted only where the data say a line was removed (its own least-squares line is zero
    to round-off): a free tilt on every acquisition is nearly collinear with the longest
    chromosome's sine over a window shorter than its wavelength, and on measured rows
    (``genome natural``) it traded them into waves of 1e4 x the heights. The tilt shared
    by the windows of one row and those of levelled profiles are solved within their
    bounds by :func:`solve_model`. Returns (n, matrix); the last :func:`line_columns`
    unknowns are the offsets, then the tilts."""
    lo = min(r[0] for r in ranges)
    hi = max(r[1] for r in ranges) if n_cap is None else min(n_cap, max(r[1] for r in ranges))
    n = np.arange(lo, hi + 1)
    q = np.exp(log_q1 + (n - 1) * log_gamma)
    tilt_col = tilt_columns(acqs)
    blocks = []
    for k, (a, (ns, nf), w) in enumerate(zip(acqs, ranges, weights)):
        on = (n >= ns) & (n <= nf)
        arg = np.multiply.outer(a.x, q)
        m = np.zeros((a.x.size, 2 * n.size + line_columns(acqs)))
        m[:, 0:2 * n.size:2] = np.where(on, 1.0 - np.cos(arg), 0.0)
        m[:, 1:2 * n.size:2] = np.where(on, np.sin(arg), 0.0)
        m[:, 2 * n.size + k] = 1.0
        if tilt_col[k] >= 0:
            m[:, 2 * n.size + len(acqs) + tilt_col[k]] = a.x
        blocks.append(m * w)
    return n, np.vstack(blocks)


def solve_linear(mat, rhs):
    scale = np.linalg.norm(mat, axis=0)
    scale[scale == 0] = 1.0
    coef, *_ = scipy_lstsq(mat / scale, rhs, cond=1e-12, lapack_driver="gelsy",
                           check_finite=False)   # pivoted QR: ~3x faster than SVD here
    return coef / (scale if coef.ndim == 1 else scale[:, None])


def tilt_bounds(acqs) -> np.ndarray:
    """Largest |tilt| (m/m) of each tilt unknown (:func:`tilt_columns`): the steepest line
    one chromosome of the largest amplitude the amplitude guard of
    :func:`~.profile.sequence_profiles` admits (:data:`OVERFIT_FACTOR` times the largest
    height of the acquisitions as given, about their means) can carry over the window of
    the acquisition (the coarsest of those sharing the unknown), whose rise over half of
    it is at most :data:`LINE_PER_AMPLITUDE` times that amplitude.

    A WM row's own line stays far inside it: at most 3.9 times the largest height (the
    bound: 13.1) on 2700 realised rows (Table 1 and random genomes, gamma 1.1-2.5, N
    128-512, three lengths; measured in round 2, session 33). Exact WM data are
    therefore fitted as without the bound; a fit that needs the line at it is trading
    it against waves that cancel (reported as not a genome). The tilt of a levelled
    acquisition (the line a profilometer removed, of its own window) is bounded the same
    way since round 2, session 34 (before: free)."""
    cols = tilt_columns(acqs)
    out = np.full(max(cols, default=-1) + 1, math.inf)
    if out.size:
        z_scale = max(float(np.max(np.abs(a.z - a.z.mean()))) for a in acqs)
        for a, c in zip(acqs, cols):
            if c >= 0:
                out[c] = min(out[c], LINE_PER_AMPLITUDE * OVERFIT_FACTOR * z_scale
                             / (0.5 * a.length))
    return out


def tilt_bound(acqs) -> float:
    """Largest |tilt| (m/m) of the line shared by the windows of one row
    (:func:`tilt_columns`, :func:`tilt_bounds`); inf for other acquisitions."""
    if not (acqs and all(a.window for a in acqs)):
        return math.inf
    return float(tilt_bounds(acqs)[0])


def _bounded_tilts(r1, r2, bounds):
    """The tilts t within +-``bounds`` of least |r1 - r2 t|^2 (``r1`` the residual of the
    heights and ``r2`` those of the tilt columns, the other unknowns projected out): for
    one tilt the free minimiser clipped (0 when its column lies in the span of the
    others), for several the exact bounded least squares (``scipy.optimize.lsq_linear``,
    BVLS, on the columns scaled to unit norm)."""
    if bounds.size == 1:
        d = float(r2[:, 0] @ r2[:, 0])
        t = float(r1 @ r2[:, 0]) / d if d > 0 else 0.0
        return np.array([min(max(t, -bounds[0]), bounds[0]) if math.isfinite(t) else t])
    scale = np.linalg.norm(r2, axis=0)
    scale[scale == 0] = 1.0
    free = np.linalg.lstsq(r2 / scale, r1, rcond=None)[0] / scale
    if np.all(np.abs(free) <= bounds):
        return free                                          # the bounds are not active
    top = np.maximum(bounds * scale, 1e-300)                 # a zero bound: t = 0
    fit = lsq_linear(r2 / scale, r1, bounds=(-top, top), method="bvls")
    return fit.x / scale


def solve_model(mat, rhs, acqs, solver=solve_linear, regularise=False):
    """The coefficients of :func:`design_matrix` (columns ``mat``, weighted heights
    ``rhs``) by least squares (``solver``), the tilts (its last columns) within
    :func:`tilt_bounds`; with ``regularise``, damped where the data cannot resolve them
    (:mod:`.regularise`: Tikhonov at the lambda of the least-squares fit's misfit, the
    same bounds on the tilts).

    The other columns R are solved for the heights and the tilt columns at once (one
    factorisation): R x1 = rhs and R X2 = tilt columns, so that the misfit at tilts t is
    |r1 - r2 t|^2 (r1, r2 their residuals), a convex quadratic; the tilts are its least
    within the bounds (:func:`_bounded_tilts`: exact bounded least squares), the rest
    x1 - X2 t. Regularised, the same on the stacked system [mat; lambda D] x = [rhs; 0]
    (:func:`~.regularise.damped_system`), which is least squares too."""
    bounds = tilt_bounds(acqs)
    if not bounds.size:
        coef = solver(mat, rhs)
    else:
        k = bounds.size
        rest, cols = mat[:, :-k], mat[:, -k:]
        x = solver(rest, np.column_stack([rhs, cols]))
        tilts = _bounded_tilts(rhs - rest @ x[:, 0], cols - rest @ x[:, 1:], bounds)
        coef = np.concatenate([x[:, 0] - x[:, 1:] @ tilts, tilts])
    damping = resolution_damping(mat, rhs, coef) if regularise else 0.0
    if damping > 0.0:
        return solve_model(*damped_system(mat, rhs, damping), acqs, solver)
    return coef


def vp_residual(params, acqs, ranges, weights, rhs, n_cap):
    n, mat = design_matrix(params[0], params[1], acqs, ranges, weights, n_cap)
    coef = solve_model(mat, rhs, acqs)
    return rhs - mat @ coef


def _first_cap(log_q1, log_gamma, lo, hi, coarse_length, cycles=30.0):
    """First continuation index: the last chromosome with at most ``cycles`` periods in L_1."""
    cap = lo + 3
    for n in range(lo + 3, hi + 1):
        if math.exp(log_q1 + (n - 1) * log_gamma) * coarse_length <= 2 * math.pi * cycles:
            cap = n
    return min(cap, hi)


def _normal_solve(mat, rhs):
    """Least squares by the normal equations (fast; accurate enough to rank a grid);
    NaN coefficients when the Gram matrix is singular."""
    scale = np.linalg.norm(mat, axis=0)
    scale[scale == 0] = 1.0
    a = mat / scale
    gram = a.T @ a
    gram[np.diag_indices_from(gram)] += 1e-10 * max(float(np.trace(gram)) / gram.shape[0], 1e-300)
    try:
        coef = np.linalg.solve(gram, a.T @ rhs)
    except np.linalg.LinAlgError:
        return np.full((mat.shape[1],) + rhs.shape[1:], np.nan)
    return coef / (scale if coef.ndim == 1 else scale[:, None])


def _projected_cost(mat, rhs, acqs):
    """||rhs - mat c||^2 of the normal-equation fit (:func:`solve_model`); inf when
    singular."""
    r = rhs - mat @ solve_model(mat, rhs, acqs, _normal_solve)
    cost = float(r @ r)
    return cost if math.isfinite(cost) else float("inf")


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
            _, mat = design_matrix(cand[0], cand[1], acqs, ranges, weights, cap)
            c = _projected_cost(mat, rhs, acqs)
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
        res = least_squares(vp_residual, p, args=(acqs, ranges, weights, rhs, cap),
                            x_scale=np.array([1e-3, 1e-3]), diff_step=1e-9,
                            max_nfev=30, xtol=1e-15, ftol=1e-15, gtol=1e-15)
        nit += res.nfev + 2 * (res.njev or 0)
        if res.x[1] > 0:
            p = res.x
    return p, nit


def fit_lattice(log_q1, log_gamma, acqs, weights, rhs, budget=600, continuation=True):
    """Variable projection with continuation in the highest chromosome index.

    First a local fit of the full model from the PSD estimate (enough when the refined
    peaks place every chromosome within the basin; all that is done with
    ``continuation=False``, for a start known to be in the basin). Otherwise the
    continuation starts at the last chromosome with <= 30 periods in the coarsest
    window (:func:`_first_cap`) -- starting lower lets the unresolved longest waves drag
    gamma away -- and adds one chromosome per step (each step shrinks the error enough
    for the next one). It is run from the PSD estimate and, unless that already fits
    to round-off, again from the best point of a grid search (:func:`_scan`) around it,
    which absorbs a larger PSD error but can also pick a spurious minimum (the
    unmodelled shorter waves still carry most of the misfit at the first cap); the
    lower final residual wins.
    """
    ranges = lattice_ranges(log_q1, log_gamma, acqs)
    lo = min(r[0] for r in ranges)
    hi = max(r[1] for r in ranges)
    p0 = np.array([log_q1, log_gamma])
    first = _first_cap(log_q1, log_gamma, lo, hi, acqs[0].length)
    rr = float(rhs @ rhs)

    def final_cost(p):
        r = vp_residual(p, acqs, ranges, weights, rhs, None)
        return float(r @ r) / rr

    res = least_squares(vp_residual, p0, args=(acqs, ranges, weights, rhs, None),
                        x_scale=np.array([1e-4, 1e-4]), diff_step=1e-10, max_nfev=40,
                        xtol=1e-15, ftol=1e-15, gtol=1e-15)
    nit = res.nfev + 2 * (res.njev or 0)
    if not continuation:
        return (res.x if res.x[1] > 0 else p0), nit
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
