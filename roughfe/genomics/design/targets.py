"""The thesis targets (Sec. 4.3-4.4) and independent re-scoring of saved designs."""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ...bem.batch import solve_batch
from ...bem.batch_exact import batch_sweep, solve_batch_exact
from ...bem.operators import influence_operator
from ...bem.window import window_compliance  # noqa: F401 (re-export: its home is bem)
from ...errors import InputError, NoConvergenceError
from ...model import Loading, Material, central_differences
from ...response import response
from ..database import DatabaseSettings, make_genome
from ..genome import Genome
from ..macro_micro import profile_response, top_approach
from ..similarity import ResponseCurve, Target, linear_then_flat_target, similarity
from .model import Design, DesignPart
from .objective import Evaluator, Objective


#: a target whose values differ from every database genome's (after Eq. 4.2) by more than
#: this factor at half its points or more is in other units, of another quantity, or of
#: another material than the database: no design can approach it (a K target of 0.05 Pa/m,
#: an area given as K, crashed GCMMA's subproblem with a singular matrix; session 32)
UNIT_FACTOR = 1e3


def check_strict_targets(targets) -> None:
    """A stiffness target needs at least 3 points with p > 0: the score solved at the
    target pressures (:func:`score_at_target_pressures`, the verdict of every design)
    takes K by central differences over them, and two points give one secant, the
    derivative at neither (a 2-point K target ran every design stage, then failed with
    "response curve stiffness has non-finite values: [nan nan]")."""
    for t in targets:
        if t.quantity == "K" and t.pressure.size < 3:
            raise InputError(f"the stiffness target {t.name} has {t.pressure.size} points "
                             f"with p > 0 (points at p = 0 are dropped); a design is scored "
                             f"with K by central differences over the target pressures, "
                             f"which needs at least 3: give 3 or more (pressure, K) points")


def check_target_units(entries, targets, settings: DatabaseSettings) -> None:
    """An InputError when every database genome's K or A (after Eq. 4.2, at the target's
    pressures) differs from a target by more than :data:`UNIT_FACTOR` at half its points
    or more: the target is in other units (pressure in Pa, K in Pa/m, A a fraction), of
    the other quantity, or of another material than the database (E* fixes K). The
    message gives the database's range there."""
    for t in targets:
        ratios, values = [], []
        for e in entries:
            y = e.curve.to_target_range(t.p_max).at(t.pressure, t.quantity)
            ok = y > 0
            if ok.any():
                ratios.append(np.median(np.abs(np.log10(y[ok] / t.values[ok]))))
                values.append(y[ok])
        if not ratios or min(ratios) <= np.log10(UNIT_FACTOR):
            continue
        lo, hi = (f(np.concatenate(values)) for f in (np.min, np.max))
        label, unit = {"K": ("stiffness K", "Pa/m"), "A": ("area fraction A", "-")}[t.quantity]
        raise InputError(
            f"target {t.name} ({label}, {t.values.min():.3g}..{t.values.max():.3g} {unit} at "
            f"{t.pressure[0]:.3g}..{t.pressure[-1]:.3g} Pa) is more than a factor "
            f"{UNIT_FACTOR:g} from every genome of the database at half its points or more "
            f"(theirs: {lo:.3g}..{hi:.3g} {unit} there, after Eq. 4.2, E* = "
            f"{settings.youngs_modulus / (1 - settings.poisson ** 2):.3g} Pa): check its units "
            f"(pressure in Pa, K in Pa/m, A a fraction 0 < A <= 1), its quantity (--quantity "
            f"K or A) and the material (a database of the target's E: `roughfe db build --E`)")


def check_design_inputs(entries, targets, settings: DatabaseSettings) -> tuple:
    """``(entries, entries by label)``: the database ``entries`` as a list and a dict,
    after the checks a design needs before any stage runs: a non-empty database,
    :func:`check_strict_targets` and :func:`check_target_units` on ``targets``. Every
    design method runs them first (:func:`~.algorithms.sog`, :func:`~.algorithms.gco`,
    :func:`~.algorithms.cco`, :func:`~.algorithms.mcco`, and so
    :func:`~.algorithms.run_design` and the CLI): until round 2, session 33 only
    ``run_design`` did, and a direct ``sog(entries, target, settings)`` with a 2-point K
    target ran every stage, then failed on NaN."""
    entries, targets = list(entries), list(targets)
    if not entries:
        raise InputError("the genome database is empty: build it first ('roughfe db build')")
    check_strict_targets(targets)
    check_target_units(entries, targets, settings)
    return entries, {e.label: e for e in entries}


def rescore(design: Design, targets, settings: DatabaseSettings, response=None) -> tuple:
    """Independent check: realise a saved design, run a fresh BEM sweep *without* any
    rescaling and return the similarity per target (must equal the reported scores)."""
    evaluate = Evaluator(settings, response)
    curve = evaluate(design)
    return tuple(similarity(t, curve, rescale=False) for t in targets)


def rescore_at_target_pressures(design: Design, targets, settings: DatabaseSettings) -> tuple:
    """Stricter independent check: Eq. (4.1) with the design solved *at the target's
    pressures* (load-controlled BEM steps), so nothing is interpolated; the design's
    heights go through :func:`score_at_target_pressures`.

    :func:`rescore` (and every optimiser) samples the design at its own n_t equal
    approaches and interpolates linearly at the target pressures. A(p) of a profile is
    a count of contact nodes (a staircase in p), so the interpolated value can be a
    fraction of a node that the design never has at that pressure. An independent BEM
    run of the target genome itself scores 1 to round-off.
    """
    return score_at_target_pressures(design.surface(), targets, settings)


def score_at_target_pressures(surface, targets, settings: DatabaseSettings) -> tuple:
    """Eq. (4.1) of a surface (e.g. a saved design's heights) solved at the targets' own
    pressures, with the database's material and approach rule.

    One displacement solve at the last approach of the database sweep (Delta =
    peak-valley for a profile; ``top_fraction`` of full contact for a periodic surface,
    :func:`~roughfe.genomics.macro_micro.top_approach`) gives p_max (Eq. 4.2 factor
    ``eta = p_max^t / p_max``); then the surface is solved at the pressures ``p_j / eta``
    of all targets; A is the exact node fraction there and K = dp/dDelta by the same
    central differences over those steps as the target's K over its own steps.
    """
    targets = list(targets)
    check_strict_targets(targets)
    mat = Material(settings.youngs_modulus, settings.poisson)
    delta = top_approach(surface, settings.kernel, settings.top_fraction)
    top = response(surface, mat, Loading(delta=delta), kernel=settings.kernel,
                   compute_stiffness=False)
    eta = targets[0].p_max / float(top.mean_pressure[-1])
    p = np.unique(np.concatenate([t.pressure for t in targets]))
    sw = response(surface, mat, Loading(pressures=tuple(p / eta)), kernel=settings.kernel,
                  compute_stiffness=False)
    k = central_differences(sw.delta, sw.mean_pressure)
    return _strict_scores(np.asarray(sw.mean_pressure) * eta, k, sw.area_fraction, targets)


def _strict_scores(pressure, stiffness, area_fraction, targets) -> tuple:
    """Eq. (4.1) of a curve solved at the target pressures (no rescaling)."""
    curve = ResponseCurve(pressure, stiffness, area_fraction)
    return tuple(similarity(t, curve, rescale=False) for t in targets)


def batch_scoring(settings: DatabaseSettings) -> bool:
    """True when :func:`score_batch_at_target_pressures` solves the designs together:
    profiles on the non-periodic strip kernel (the thesis database) by the batched exact
    BEM of :mod:`roughfe.bem.batch_exact`, periodic surfaces (a surface database, dim 2)
    by the batched Polonsky-Keer CG of :mod:`roughfe.bem.batch`; otherwise it scores them
    one by one."""
    if settings.dim == 2:
        return settings.kernel in ("auto", "spectral")
    return settings.kernel in ("auto", "strip") \
        and settings.top_fraction == 1.0 and int(settings.n_nodes) <= 4096


#: the scores :func:`score_batch` gives: "strict" (:func:`rescore_at_target_pressures`,
#: solved at the target pressures) and "interpolated" (Eq. 4.1 on the design's own n_t
#: equal approaches after Eq. 4.2, as the thesis stages and :func:`rescore` score)
SCORINGS = ("strict", "interpolated")


def score_batch(designs, targets, settings: DatabaseSettings, scoring=SCORINGS) -> dict:
    """Eq. (4.1) scores of many designs at once: ``{kind: array (B, targets)}`` for every
    kind in ``scoring`` (:data:`SCORINGS`), the same numbers as the single functions (to
    round-off: the same exact contact states) at a fraction of the cost.

    * ``"strict"``: :func:`rescore_at_target_pressures` of each design.
    * ``"interpolated"``: :meth:`Objective.scores` of each design's own BEM sweep, i.e.
      the n_t equal approaches ``Delta_j = j/n_t * top`` (Sec. 4.2.1;
      :func:`~roughfe.genomics.macro_micro.top_approach`), K by central differences,
      Eq. (4.2) rescaling to p_max^t, Eq. (4.1) interpolated at the target pressures:
      the score the thesis stages maximise and :func:`rescore` reproduces.

    With :func:`batch_scoring` the B designs are solved together and both kinds share
    the one displacement solve at the last approach (``top``, p_max and the Eq. 4.2
    factor eta per row; "interpolated" only with the database's K by differences,
    ``stiffness="fd"``): "strict" continues with
    :func:`roughfe.bem.batch_exact.batch_sweep` at the pressures ``p_j / eta`` (load
    control), "interpolated" with the same sweep at the approaches ``Delta_j``
    (displacement control). Profiles: exact pivoting
    (:func:`roughfe.bem.batch_exact.solve_batch_exact`, warm-started and, from the top
    state's contact sets, by Schur complements; the same contact states to round-off,
    ``docs/theory/06_design.md``); periodic surfaces: the batched CG to a relative KKT
    residual of 1e-10 (scores within ~1e-10 of the single solver,
    ``docs/theory/surface-design.md``). Otherwise (or when the CG cannot settle a row)
    the designs are scored one by one. A row whose curve is not a valid response (e.g. a
    flat design) scores -inf."""
    designs = list(designs)
    targets = list(targets)
    scoring = tuple(scoring)
    if not scoring or any(k not in SCORINGS for k in scoring):
        raise InputError(f"scoring must name some of {SCORINGS}, got {scoring!r}")
    if "strict" in scoring:         # a 2-point K target scored every design -inf, silently
        check_strict_targets(targets)
    if not designs:
        return {k: np.zeros((0, len(targets))) for k in scoring}
    out = {}
    together = tuple(k for k in scoring if batch_scoring(settings) and
                     (k == "strict" or settings.stiffness == "fd"))
    if together:
        try:
            out = _scores_together(designs, targets, settings, together)
        except NoConvergenceError:          # a row the CG cannot settle: one by one
            pass
    for k in scoring:
        if k not in out:
            out[k] = np.array([_score_one(k, d, targets, settings) for d in designs])
    return out


def _score_one(kind, design, targets, settings: DatabaseSettings) -> tuple:
    """One design's scores of kind ``kind`` (:data:`SCORINGS`) by the single solvers."""
    if kind == "strict":
        return rescore_at_target_pressures(design, targets, settings)
    return Objective(targets).scores(Evaluator(settings)(design))


def score_batch_at_target_pressures(designs, targets, settings: DatabaseSettings) -> np.ndarray:
    """:func:`rescore_at_target_pressures` of many designs at once, an array (B, targets):
    the ``"strict"`` kind of :func:`score_batch`."""
    return score_batch(designs, targets, settings, ("strict",))["strict"]


def score_batch_interpolated(designs, targets, settings: DatabaseSettings) -> np.ndarray:
    """Eq. (4.1) of many designs on their own n_t approaches (after Eq. 4.2), an array
    (B, targets): the ``"interpolated"`` kind of :func:`score_batch`, equal to
    :meth:`Objective.scores` of each design's BEM sweep (and to :func:`rescore` of a
    design rescaled to p_max^t)."""
    return score_batch(designs, targets, settings, ("interpolated",))["interpolated"]


def _scores_together(designs, targets, settings: DatabaseSettings, scoring) -> dict:
    """:func:`score_batch` with the designs solved together (:func:`batch_scoring`)."""
    surfs = [d.surface() for d in designs]
    h = np.array([sf.heights for sf in surfs])
    mat = Material(settings.youngs_modulus, settings.poisson)
    periodic = settings.dim == 2
    op = influence_operator(h.shape[1:], surfs[0].size, mat.E_star,
                            "spectral" if periodic else "strip")
    method = "pk" if periodic else "exact"
    delta = np.array([top_approach(sf, settings.kernel, settings.top_fraction) for sf in surfs])
    top = solve_batch(op, h, delta=delta) if periodic else solve_batch_exact(op, h, delta=delta)
    out = {}
    if "strict" in scoring:
        eta = targets[0].p_max / top.mean_pressure
        p = np.unique(np.concatenate([t.pressure for t in targets]))
        sw = batch_sweep(op, h, p[None, :] / eta[:, None], method=method, top=top)
        out["strict"] = _rows_scored(lambda b: _strict_scores(
            sw.mean_pressure[b] * eta[b], sw.stiffness[b], sw.area_fraction[b], targets),
            len(designs), len(targets))
    if "interpolated" in scoring:
        n = int(settings.n_steps)
        sw = batch_sweep(op, h, deltas=delta[:, None] * np.arange(1, n + 1) / n,
                         method=method, top=top)
        objective = Objective(targets)

        def interpolated(b):
            keep = sw.mean_pressure[b] > 0
            return objective.scores(ResponseCurve(sw.mean_pressure[b][keep],
                                                  sw.stiffness[b][keep],
                                                  sw.area_fraction[b][keep]))
        out["interpolated"] = _rows_scored(interpolated, len(designs), len(targets))
    return out


def _rows_scored(score_row, n_rows, n_targets) -> np.ndarray:
    """(n_rows, n_targets) of ``score_row(b)``; -inf in a row whose curve is refused."""
    out = np.full((n_rows, n_targets), -np.inf)
    for b in range(n_rows):
        try:
            out[b] = score_row(b)
        except InputError:
            pass
    return out


#: the genome behind target y_t1 (not in the Sobol database: gamma, H off the Sobol points,
#: phases from a different generator), fixed here and recorded in every report.
Y_T1_GENES = {"gamma": 1.55, "H": 0.8, "A": 1.0, "phase_seed": 20190}


#: surface databases (dim 2): y_t1 has M = 3 ridges at angles
#: ``default_rng(angle_seed).uniform(0, pi, 3)`` and unit anisotropy (beside Y_T1_GENES)
Y_T1_SURFACE_GENES = {"M": 3, "angle_seed": 20191}


def target_genome_t1(settings: DatabaseSettings) -> Genome:
    """Genome of y_t1: M = 1, lambda = L, phases ``default_rng(20190).uniform(0, 2 pi)``;
    for a surface database (dim 2) M = 3 ridges (:data:`Y_T1_SURFACE_GENES`) with the
    phases drawn as an (M, n_c) matrix from the same seed."""
    facts = dict(Y_T1_GENES)
    kw = {}
    if settings.dim == 2:
        m = Y_T1_SURFACE_GENES["M"]
        kw["angles"] = np.random.default_rng(Y_T1_SURFACE_GENES["angle_seed"]).uniform(
            0, np.pi, m)
        kw["anisotropy"] = np.ones(m)
        facts.update(Y_T1_SURFACE_GENES)
    g = make_genome(Y_T1_GENES["gamma"], Y_T1_GENES["H"], Y_T1_GENES["phase_seed"], settings,
                    amplitude=Y_T1_GENES["A"], **kw)
    return replace(g, metadata={"role": "target y_t1", **facts})


#: how :func:`surface_targets` loads a non-periodic (measured) window: "periodic" (the
#: evenly mirrored window with the periodic BEM, the interface the designs are; default) or
#: "window" (the window alone on the half-space, non-periodic kernel)
TARGET_BOUNDARIES = ("auto", "periodic", "window")
#: sampling of a periodic surface target: "design" (the database's spacing L/N) or "full"
TARGET_RESOLUTIONS = ("design", "full")


def surface_targets(surface, settings: DatabaseSettings, *, name="measured", detrend="plane",
                    boundary="auto", resolution="design"):
    """Targets K(p) and A(p) of a given (e.g. measured) surface: its own BEM sweep.

    The surface is detrended (``"plane"`` by default: instruments leave a tilt) and
    loaded exactly as the database loads its genomes (:func:`profile_response` with the
    database's E, nu, n_t, K kind and ``top_fraction``). The targets are that sweep's
    points: the design is then scored at these pressures (Eq. 4.1 after Eq. 4.2).

    ``boundary`` (a non-periodic window only; a periodic surface is always solved as it
    is): ``"auto"`` (default) is the designs' own setting, ``"periodic"`` on a surface
    database (``settings.dim == 2``) and ``"window"`` on a profile database, whose
    genomes are solved as non-periodic profiles on the strip kernel (a profile target
    mirrored and solved periodically scored a database genome's own profile s = 0.009
    against s = 1 in its own setting).

    * ``"periodic"``: the evenly mirrored window (:meth:`Surface.mirrored`,
      period twice the window, no height step at the edges) with the periodic BEM,
      approaches up to ``top_fraction`` of its full contact. This is the setting of the
      designs (periodic interfaces of a nominally infinite plane, K and p per nominal
      area), so target and design are compared like with like.
    * ``"window"``: the window alone pressed into a half-space (non-periodic Love/strip
      kernel), approaches up to ``top_fraction`` of its peak-valley height. Its K is
      *not* a property of the roughness: the mean approach includes the bulk compliance
      ``C`` of the finite window (:func:`window_compliance`, ~0.9 sqrt(A_n)/E*), in
      series with the interface, ``1/K_window ~ 1/K_periodic + C``
      (``tests/test_surface_design_targets.py``: within 7 % on x3p-2), so K_window
      saturates at 1/C (1.8e12 Pa/m for x3p-2 at E = 210 MPa), a number set by the
      window's lateral size and aspect ratio. A periodic design cannot and should not
      reproduce it; the thesis's profile targets (non-periodic strip) are kept as they are.

    ``resolution`` (periodic targets of a surface database only): ``"design"`` (default)
    resamples the periodic target onto the designs' grid spacing ``L/N``
    (:meth:`Surface.resampled`, the band-limited Fourier interpolant: wavelengths below
    ``2 L/N`` removed), so that target and designs carry the same band of wavelengths;
    ``"full"`` keeps the measured sampling. Why it matters: K is invariant under the
    Eq. (4.2) amplitude factor, and at a given p_max its level is set by the ratio of rms
    slope to rms height, i.e. by the shortest wavelengths; a design on a grid of spacing
    L/N cannot hold the measured sub-grid waves at any phase (x3p-2 at 163 x 163: every
    genome of a 32 x 32 database reaches at most 0.13 of the target's K(p_max)).

    Returns ``(t_K, t_A, curve)``.
    """
    boundary = _boundary(boundary, settings)
    surf = target_surface(surface, settings, detrend=detrend, boundary=boundary,
                          resolution=resolution)
    curve = profile_response(surf, **settings.response_options())
    meta = {"surface": dict(surface.metadata), "shape": list(surface.shape),
            "size_m": list(surface.size), "detrend": detrend, "boundary": boundary,
            "resolution": resolution,
            "solved_shape": list(surf.shape), "solved_size_m": list(surf.size),
            "settings": settings.to_dict()}
    return (Target(curve.pressure, curve.stiffness, "K", f"{name}_K", meta),
            Target(curve.pressure, curve.area_fraction, "A", f"{name}_A", meta), curve)


#: fewest points per side of a target surface resampled onto the database spacing
MIN_DESIGN_POINTS = 8

def _boundary(boundary, settings) -> str:
    """``boundary`` with ``"auto"`` resolved: the designs' setting of the database."""
    if boundary not in TARGET_BOUNDARIES:
        raise InputError(f"boundary must be one of {TARGET_BOUNDARIES}, got {boundary!r}")
    if boundary == "auto":
        return "periodic" if settings.dim == 2 else "window"
    return boundary


def target_surface(surface, settings: DatabaseSettings, *, detrend="plane",
                   boundary="auto", resolution="design"):
    """The surface :func:`surface_targets` solves: detrended, evenly mirrored when
    ``boundary="periodic"`` and the input is a non-periodic window, and resampled onto the
    database spacing L/N when ``resolution="design"`` (see :func:`surface_targets`)."""
    boundary = _boundary(boundary, settings)
    if resolution not in TARGET_RESOLUTIONS:
        raise InputError(f"resolution must be one of {TARGET_RESOLUTIONS}, got {resolution!r}")
    if settings.dim == 2 and surface.ndim != 2:
        # as spectrum_matched: a surface database designs periodic 2D surfaces, whose K(p)
        # and A(p) a profile's (a line contact per unit length) cannot be compared with
        raise InputError(f"the database is a surface database (dim 2, designs are periodic "
                         f"2D surfaces): its target must be a 2D surface, got a profile of "
                         f"{surface.shape[0]} points (targets of a profile need a profile "
                         f"database, dim 1)")
    surf = surface.detrended(detrend) if detrend != "none" else surface
    if boundary == "periodic" and not surf.periodic:
        surf = surf.mirrored()
    if resolution == "design" and surf.periodic and settings.dim == 2:
        spacing = settings.length / settings.n_nodes
        points = [int(round(s / spacing)) for s in surf.size]
        if min(points) < MIN_DESIGN_POINTS:
            raise InputError(
                f"the surface ({' x '.join(f'{s:.3g}' for s in surf.size)} m"
                f"{', evenly mirrored' if not surface.periodic else ''}) "
                f"resampled onto the database spacing L/N = {spacing:.3g} m has "
                f"{' x '.join(map(str, points))} points, fewer than {MIN_DESIGN_POINTS} per "
                f"side: solve it on its own grid (resolution='full', --resolution full) or "
                f"use a database of finer spacing")
        surf = surf.resampled(points)
    return surf


def thesis_targets(settings: DatabaseSettings, response=None, *, pbar2_fraction=0.53 / 1.6):
    """Targets of Sec. 4.3-4.4: y_t1 (K of :func:`target_genome_t1`), y_t3 (its A(p)) and
    y_t2 (K linear in p up to pbar, flat after, on the same pressure range).

    The thesis gives p in its own units and no p_max^t; reading p_max^t ~ 1.6e-4 off
    Figs. 57-59, ``pbar2_fraction = 0.53/1.6`` places pbar = 0.53e-4 at the same fraction
    of p_max^t. y_t2 starts at y_t1's first value (K at first contact is finite), rises
    linearly to y_t1's value at pbar and stays there. Returns ``(t1, t2, t3, curve)``.
    """

    evaluate = Evaluator(settings, response)
    g = target_genome_t1(settings)
    d = Design((DesignPart(g, tuple(range(g.n_first, g.n_last + 1)), 1.0, "y_t1"),), 1.0,
               settings.length, settings.n_nodes, "y_t1", settings.dim)
    curve = evaluate(d)
    meta = {"genome": g.to_dict(), "settings": settings.to_dict()}
    t1 = Target(curve.pressure, curve.stiffness, "K", "y_t1", meta)
    t3 = Target(curve.pressure, curve.area_fraction, "A", "y_t3", meta)
    pbar = pbar2_fraction * curve.p_max
    plateau = float(np.interp(pbar, curve.pressure, curve.stiffness))
    t2 = linear_then_flat_target(curve.p_max, pbar, plateau, n_points=settings.n_steps,
                                 name="y_t2", start=float(curve.stiffness[0]))
    return t1, t2, t3, curve

