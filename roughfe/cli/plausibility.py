"""Physical plausibility of a command's loads and results: loads beyond the elastic
half-space (refused before the solve), large strains and the other limits of the model a
solution reaches (warned of after it), design targets and designs beyond the half-space,
and the leak runs' thin channels and fluid loads. Split from :mod:`roughfe.cli.options`
(session 28); the warnings of a read surface (units, tilt, scan lines, a mirrored window,
a seam) are in :mod:`roughfe.cli.surface_warnings` (round 2, session 36)."""
from __future__ import annotations

import numpy as np

from .options import warn
from .surface_warnings import SLOPE_LIMIT, rms_slope_or_zero


#: Largest approach Delta / lateral size L before :func:`check_solution` warns.
SMALL_STRAIN_LIMIT = 0.1


def check_load_magnitudes(surface, material, pressures=None, deltas=None) -> None:
    """Refuse, before any solve, loads that no elastic half-space can mean: a mean
    pressure above E* (strains ~ p / E* >= 1: mostly E given in GPa or MPa as if in Pa)
    and an approach larger than the surface's smallest lateral size (a strain above 1:
    mostly a length in the wrong unit). Such a run took 10 minutes to a
    NoConvergenceError (``--E 210`` at 100 MPa) or ran without end (``--delta 1`` on a
    0.5 um window; a user's review, round 2, session 28). The milder case, an approach
    above 10 % of the size, is warned of after the solve (:func:`check_solution`)."""
    from ..errors import InputError

    e_star = material.E_star
    if pressures is not None and len(pressures):
        p = max(float(v) for v in pressures)
        if p > e_star:
            raise InputError(
                f"mean pressure {p:.4g} Pa is {p / e_star:.3g} x E* = {e_star:.4g} Pa (from "
                f"E = {material.E:.4g} Pa, nu = {material.nu:g}): the elastic half-space "
                f"needs p << E* (its strains are ~ p / E*); is --E in Pa?")
    if deltas is not None and len(deltas):
        d = max((float(v) for v in deltas), key=abs)     # signed, as given (adhesion: < 0)
        length = min(surface.size)
        if abs(d) > length:
            raise InputError(
                f"approach {d:.4g} m is {abs(d) / length:.3g} x the smallest lateral size "
                f"{length:.4g} m of the surface: a strain above 1, beyond the elastic "
                f"half-space; is --delta in metres?")


#: rms slope above which a solving command says the small-slope half-space is strained
#: (up to :data:`~roughfe.cli.surface_warnings.SLOPE_LIMIT`, above which the unit warning
#: speaks). The boundary-element half-space linearises the surface's geometry (the normal
#: is taken along z and the heights as small against the lateral scales); the AFM file
#: di-1 has 0.77.
STEEP_SLOPE = 0.5


def check_solution(args, surface, results, material) -> None:
    """Warn (stderr, after the solve) where the solution leaves the model it was solved
    in: an approach above :data:`SMALL_STRAIN_LIMIT` of the smallest lateral size (strains
    ~ Delta / L), an rms slope above :data:`STEEP_SLOPE` (the linear half-space), a local
    contact pressure above E* (local strains of order one: a hardness, ``--hardness``,
    is the usual remedy) and steps whose contact patches are narrower than
    :data:`roughfe.bem.patches.MIN_PATCH_POINTS` grid points (the results' ``patch_width``,
    load-weighted: not resolved; the rule of the BEM and the FEM results, which replaced
    a count of fewer than 32 contact points in round 2, session 32: it passed 32 single
    points and said nothing of a profile's contact on 1-3 nodes). ``results``: the steps'
    ContactResults; steps are numbered from 0, as in results.json, the ``leak`` table and
    the fields' frames. The last three from a user's review (round 2, session 29: di-1 at
    1 GPa reached 2.9 E* locally, and its 10 MPa step had 29 contact points). With a
    hardness also steps whose elastic rim around the plastic zone is narrower than
    :data:`roughfe.bem.patches.MIN_RIM_POINTS` grid points (``rim_width``: K depends on
    the grid; round 2, session 34)."""
    results = list(results)
    if not results:
        return
    e_star = material.E_star
    d_max, length = max(float(r.delta) for r in results), min(surface.size)
    if d_max > SMALL_STRAIN_LIMIT * length:
        p_max = max(float(r.mean_pressure) for r in results)
        warn(args, f"approach Delta = {d_max:.3g} m is {d_max / length:.3g} x the lateral size "
                   f"{length:.3g} m (p = {p_max:.3g} Pa = {p_max / e_star:.3g} E*): "
                   "far beyond the small strains of the elastic half-space; the result is not "
                   "physical")
    slope = rms_slope_or_zero(surface)
    if STEEP_SLOPE < slope <= SLOPE_LIMIT:      # above: surface_warnings.warn_units has spoken
        warn(args, f"rms slope {slope:.3g} > {STEEP_SLOPE:g}: the linear half-space assumes "
                   f"small slopes (its geometry is linearised); read A* and K as that model's")
    peaks = [float(np.max(r.pressure)) for r in results]
    k = int(np.argmax(peaks))
    peak = peaks[k]
    if peak > e_star:
        warn(args, f"the local contact pressure reaches {peak:.3g} Pa = {peak / e_star:.3g} E* "
                   f"(step {k}): local strains of order one, beyond linear elasticity; "
                   f"a real material yields first (--hardness)")
    from ..bem.patches import resolution_note, rim_note
    for note, key in ((resolution_note, "patch_width"), (rim_note, "rim_width")):
        few = [(i, getattr(r, key, None)) for i, r in enumerate(results)
               if note(getattr(r, key, None))]
        if few:
            more = ", ..." if len(few) > 6 else ""
            warn(args, f"step{'s' if len(few) > 1 else ''} "
                       f"{', '.join(str(i) for i, _ in few[:6])}{more}: {note(few[0][1])}"
                       + (f" (step {few[0][0]})" if len(few) > 1 else ""))


def persson_basis(args, surface, persson: dict) -> None:
    """Say (stdout) which slope Persson's theory beside the results took -- the rms
    gradient of the surface's PSD, which can differ from the finite-difference rms slope
    of ``roughfe info`` (2x on sur-2 as read then, a user's review, round 2, session 29;
    1.5x since the .sur reader fix, round 2, session 32) -- and warn
    when the heights are far from Gaussian, the theory's surface
    (:data:`roughfe.theory.beside.NON_GAUSSIAN`) or have a lay (texture aspect ratio
    below :data:`roughfe.theory.beside.ANISOTROPIC_STR`: the theory's surface is
    isotropic; x3p-2 at 3 GPa, steel: Persson's leak rate along the grooves 4.8e5 x below
    Reynolds', a seals review, round 2, session 31). ``persson``: the ``"persson"`` block of
    :func:`roughfe.theory.beside` (nothing is said without its ``rms_gradient``)."""
    if persson.get("rms_gradient") is None:
        return
    window = "" if surface.periodic else " (Hann-windowed)"
    print(f"Persson's theory beside the results (persson_* in results.json) takes gbar = "
          f"{persson['rms_gradient']:.3g}, the rms gradient of the surface's PSD{window}; "
          f"its rms slope by finite differences (roughfe info) is {rms_slope_or_zero(surface):.3g}")
    for note in ("non_gaussian", "anisotropic", "texture_bounded"):
        if persson.get(note):
            warn(args, persson[note])


def check_target_pressure(args, targets, settings, why) -> None:
    """Warn (stderr) when the largest pressure p_max^t of the design ``targets`` exceeds
    the database's E* (``why``: what the run's numbers are then)."""
    from ..model import Material
    e_star = Material(settings.youngs_modulus, settings.poisson).E_star
    p_top = max(float(t.p_max) for t in targets)
    if p_top > e_star:
        warn(args, f"the target's largest pressure p_max^t = {p_top:.4g} Pa is "
                   f"{p_top / e_star:.3g} x the database's E* = {e_star:.4g} Pa: beyond the "
                   f"small strains of the elastic half-space ({why})")


def check_design(args, surface, targets, settings) -> None:
    """Warn (stderr) when a roughness design leaves the elastic half-space it was designed
    in: a target whose largest pressure p_max^t exceeds the database's E*, and a designed
    surface whose rms slope exceeds :data:`STEEP_SLOPE` (Eq. 4.2 rescales the amplitude
    to reach p_max^t: the design tutorial's profile had rms slope 8.5 with the thesis'
    targets at 1.7 E*; a user's review, round 2, session 29). The design then matches
    the linear model's curves, which no material follows there."""
    check_target_pressure(args, targets, settings, "the model scales with E*: the design "
                                                   "matches p / E*, not a material's response")
    slope = rms_slope_or_zero(surface)
    if slope > STEEP_SLOPE:
        warn(args, f"the designed surface has rms slope {slope:.3g} (> {STEEP_SLOPE:g}; its "
                   f"amplitude is rescaled by Eq. 4.2 to reach p_max^t): beyond the small "
                   f"slopes of the elastic half-space; its K(p) and A(p) are the linear "
                   f"model's")


#: factor between a target surface's lateral size and the database length L beyond which
#: ``design-targets --surface`` says the curves are of another scale
TARGET_SIZE_RATIO = 2.0


def check_target_surface(args, surface, settings) -> None:
    """Warn (stderr) when ``design-targets --surface`` takes a surface that the database's
    designs cannot be compared with at face value: a 2D surface for a profile database
    (areal against line contact) and a lateral size more than :data:`TARGET_SIZE_RATIO`
    from the database length L (K(p) depends on the size: the long wavelengths, and for
    a non-periodic window its bulk compliance ~ 0.9 sqrt(A_n) / E*). A user's review
    (round 2, session 29) designed for a 79 um window with a 0.85 mm profile database and
    got s = 0.08 with no word of why."""
    if settings.dim == 1 and surface.ndim == 2:
        warn(args, "a 2D surface gives targets to a profile database (dim 1): its A(p) and "
                   "K(p) are those of an areal contact, the designs' of a line contact; "
                   "expect them to agree in shape at best (a surface database, dim 2, "
                   "designs 2D surfaces)")
    size = max(surface.size)
    ratio = max(size / settings.length, settings.length / size)
    if ratio > TARGET_SIZE_RATIO:
        warn(args, f"the surface is {size:.4g} m across, {ratio:.3g}x "
                   f"{'shorter' if size < settings.length else 'longer'} than the database "
                   f"length L = {settings.length:.4g} m: K(p) depends on the size (the longest "
                   f"wavelengths, and a window's bulk compliance ~ 0.9 sqrt(A_n) / E*), so the "
                   f"designs of length L may not reach its curves")


#: share of the ``--match-spectrum`` file's mean square at wavelengths longer than the
#: database length L above which :func:`check_long_waves` warns: where the curves move by
#: a design's tolerance (s > 0.95 of Eq. 4.1: 5 % at every target point). Measured (round
#: 2, session 37; 2L-periodic spectral surfaces, 128^2 on the spacing L/64 of the docs'
#: surface database, H 0.5 and 0.8, 4 seeds each, n_t = 20, top_fraction 0.8): with the
#: modes of wavelength > L removed, K(p) after Eq. 4.2 moves by a median (over the
#: target's steps 3-20) of 1.8-2.8 % at a share of 0.1 %, 4.3-6.6 % (mean 5.2) at 0.5 %,
#: 6.1-9.8 % at 1 %, 15-25 % at 5 %, A(p) by 3.3-4.8 % at 0.5 % (their mean square given
#: to the |q| = 2 pi / L modes instead, as the matching does: K 3.5-6.4 % at 0.5 %).
#: The strict score itself falls below 0.95 already at 0.1 % (0.57-0.90: its max over
#: the points, set by the first ones, a few contact nodes), too sensitive to set it by.
#: The measured files at their own size as L: plu-1 0.45 % moves K by 6 %, di-1 1.7 % by
#: 3.3 %, sur-2 9.1 % by 32 % (A 44 %), opd-1 0.04 % by 0.6 %
LONG_WAVE_SHARE_LIMIT = 0.005


def check_long_waves(args, surface, settings) -> None:
    """Warn (stderr) when the ``design --match-spectrum`` surface, as the design prepared
    it (detrended by ``--detrend``, evenly mirrored if a window, on the database grid:
    :func:`roughfe.genomics.design.target_surface`), carries more than
    :data:`LONG_WAVE_SHARE_LIMIT` of its mean square at wavelengths longer than the
    database length L (:func:`roughfe.genomics.design.long_wave_share`, from the Fourier
    modes that :func:`~roughfe.genomics.design.spectrum_matched` distributes). The designs
    are periodic of period L and hold none of those waves: the matching gives their mean
    square to the longest chromosome, at its own wavelength, and a target solved on the
    file (``design-targets --surface``, on the mirrored window) keeps them. The limit is
    the share whose removal moves K(p) by a design's tolerance, 5 % (median over the
    target's points, spectral surfaces; 1 %: 6-10 %). Until round 2, session 37 nothing
    was said (a mirrored window of side L: 0.5-22 % there; of 2 L:
    27-84 %; plu-1 and sur-2 on the L = 260 um of docs/theory/surface-design.md: 59 and
    62 %)."""
    from ..genomics.design import long_wave_share
    share = long_wave_share(surface, settings.length)
    if not share > LONG_WAVE_SHARE_LIMIT:
        return
    warn(args, f"--match-spectrum: {100 * share:.3g} % of the file's mean square (as the "
               f"design takes it: after --detrend, mirrored if a window, on the database "
               f"grid) lies at wavelengths longer than the database length L = "
               f"{settings.length:.4g} m (limit {100 * LONG_WAVE_SHARE_LIMIT:g} %): the "
               f"designs are periodic of period L and hold none of it, so the matching "
               f"gives it to the longest chromosome at its own wavelength, and waves of "
               f"that share move K(p) by about a design's 5 % tolerance (s > 0.95) or more "
               f"(median over the target's points; 1 %: 6-10 %, 5 %: 15-25 %). A database "
               f"of length {max(surface.size):.4g} m (db build --length; the longest "
               f"wavelength of the file as the design takes it) holds all of it; or match "
               f"the spectrum of a window of the file at most L/2 across")


def check_target_curve(args, target) -> None:
    """Warn (stderr) when a design target's K(p) or A(p) falls with the load: the contact
    stiffness and area of an elastic rough contact grow with it, so a falling curve is
    mostly a file whose rows or columns are mixed up (a user's review, round 2, session
    29: rows given as 1e6, 1e5, 1e8 Pa were sorted and K fell between 1e5 and 1e6)."""
    p = np.asarray(target.pressure, float)
    y = np.asarray(target.values, float)
    falls = np.flatnonzero(np.diff(y) < 0)
    if falls.size:
        k = int(falls[0])
        what = "K" if target.quantity == "K" else "A*"
        warn(args, f"target {target.name}: {what} falls with the load at "
                   f"{falls.size} of its {p.size - 1} intervals (first from {y[k]:.4g} at "
                   f"p = {p[k]:.4g} Pa to {y[k + 1]:.4g} at {p[k + 1]:.4g} Pa; the rows are "
                   f"read sorted by pressure): the {what} of an elastic rough contact grows "
                   f"with the load; are the file's rows or columns right?")


#: critical gap (m) below which a percolating channel is said to be of molecular size:
#: the continuum Reynolds film (and a measured topography's height resolution) stop there
MOLECULAR_GAP = 1e-9


def check_critical_gaps(args, steps) -> None:
    """Warn (stderr) of steps that percolate through a critical gap below
    :data:`MOLECULAR_GAP`: a channel of 0.3 Angstrom counted as open (x3p-2 at 1 GPa; a
    user's review, round 2, session 29) is closed for a seal, and the Reynolds equation
    does not describe a film of that thickness. ``steps``: the leak records."""
    thin = []
    for s in steps:
        for d in ("x", "y"):
            gap = s.get(f"critical_gap_{d}")
            if s.get(f"percolates_{d}") and gap is not None and 0 < gap < MOLECULAR_GAP:
                thin.append(f"{s['step']} ({d}: {gap:.2g} m)")
    if thin:
        warn(args, f"step{'s' if len(thin) > 1 else ''} {', '.join(thin[:6])}"
                   f"{', ...' if len(thin) > 6 else ''} percolate{'' if len(thin) > 1 else 's'} "
                   f"through a critical gap below {MOLECULAR_GAP:g} m: a channel of molecular "
                   f"size, beyond the continuum Reynolds film and most instruments' height "
                   f"resolution; read it as closed for a seal")


def check_curve(args, what, pressure, e_star, slope=None) -> None:
    """Warn (stderr) when a response curve computed without the per-step checks of
    :func:`check_solution` (``genome mechanics``: a genome's profile swept to full
    approach) runs beyond the elastic half-space: its largest mean pressure above E*, or
    the surface's rms ``slope`` above :data:`STEEP_SLOPE` (a user's review, round 2,
    session 29: a Table 1 profile at 10x, rms slope 27, swept to 49 E* in silence)."""
    p = np.asarray(pressure, float)
    p_max = float(np.nanmax(p)) if p.size else 0.0
    beyond = []
    if p_max > e_star:
        beyond.append(f"mean pressure up to {p_max:.3g} Pa = {p_max / e_star:.3g} E*")
    if slope is not None and slope > STEEP_SLOPE:
        beyond.append(f"rms slope {slope:.3g}")
    if beyond:
        warn(args, f"{what}: {' and '.join(beyond)}, beyond the small strains and slopes of "
                   f"the elastic half-space; the curves are the linear model's")


#: share of the mean contact pressure above which the mean fluid pressure of a one-way
#: leak run is said to matter (a 256^2 crop of opd-1, steel, at 30 MPa with a 20 MPa
#: inlet: fluid share 0.34 and a coupled leak rate 1.64x the one-way one, measured)
FLUID_LOAD_SHARE = 0.1


def check_fluid_load(args, steps, p_in, p_out) -> None:
    """Warn (stderr) of one-way leak steps whose fluid pressure is not small beside the
    mean contact pressure: the one-way model gives the whole load to the solid, while a
    fluid at a mean pressure about ``(p_in + p_out) / 2`` carries part of it, opens the
    contact and leaks more (``--fsi``); at or above the contact pressure it lifts the
    surfaces apart (a seals review: a 5e7 Pa drop through a contact at 1e7 Pa was solved
    without a word, while ``--fsi`` calls that state lift-off). ``steps``: leak records."""
    fluid = 0.5 * (p_in + p_out)
    share = [(s["step"], fluid / s["mean_pressure"]) for s in steps
             if s.get("mean_pressure") is not None and s["mean_pressure"] > 0]
    lift = [k for k, r in share if r >= 1.0]
    heavy = [k for k, r in share if FLUID_LOAD_SHARE < r < 1.0]
    if not (lift or heavy):
        return
    worst = max(r for _, r in share)
    said = []
    if lift:
        said.append(f"step{'s' if len(lift) > 1 else ''} {', '.join(map(str, lift[:6]))}"
                    f"{', ...' if len(lift) > 6 else ''}: the fluid would lift the surfaces "
                    f"apart (a real seal opens)")
    if heavy:
        said.append(f"step{'s' if len(heavy) > 1 else ''} "
                    f"{', '.join(map(str, heavy[:6]))}{', ...' if len(heavy) > 6 else ''}: "
                    f"the fluid carries part of the load and opens the contact, so the "
                    f"leak rate is underestimated")
    warn(args, f"the mean fluid pressure (p_in + p_out) / 2 = {fluid:.3g} Pa is up to "
               f"{worst:.3g} x the mean contact pressure, which the one-way solve gives "
               f"to the solid alone; {'; '.join(said)}: solve the coupling with --fsi "
               f"(--pressure is then the external pressure)")


def check_pocket_pressures(args, steps) -> None:
    """Warn (stderr) of ``--fsi`` steps whose sealed pockets hold their liquid at pressures
    above the external pressure: the contact around a pocket presses at GPa levels, and an
    incompressible liquid (the default ``--trapped-fluid volume``) or one of the given bulk
    modulus answers with that pressure (a seals review: a 64^2 crop of opd-1, steel,
    20 MPa inlet, 1.5 GPa external: pockets up to 6.5 GPa carrying 13 % of the load, the
    contact area held at A* 0.48). Real liquids compress and water solidifies near 1 GPa,
    so the trapped share is then an upper bound. ``steps``: the coupled records."""
    high = []
    for s in steps:
        pressures = s.get("pocket_pressures") or []
        above = [p for p in pressures if p > s["external_pressure"]]
        if above:
            high.append((s["step"], len(above), len(pressures), max(above),
                         max(above) / s["external_pressure"]))
    if not high:
        return
    k, n, total, p_max, ratio = max(high, key=lambda h: h[3])
    steps_said = ", ".join(str(h[0]) for h in high[:6]) + (", ..." if len(high) > 6 else "")
    liquid = ("an incompressible liquid (the default; water: --bulk-modulus 2.2e9)"
              if getattr(args, "bulk_modulus", None) is None
              else f"a liquid of bulk modulus {args.bulk_modulus:.3g} Pa")
    warn(args, f"step{'s' if len(high) > 1 else ''} {steps_said}: sealed pockets above the "
               f"external pressure (step {k}: {n} of {total}, up to {p_max:.3g} Pa = "
               f"{ratio:.3g} x p_ext), the contact pressure around them held by {liquid}; "
               f"a real liquid compresses and water solidifies near 1e9 Pa: read "
               f"trapped_load_fraction as an upper bound")
