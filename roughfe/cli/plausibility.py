"""Physical plausibility of a command's input, checked or warned of by the commands that
solve: heights and sizes in a wrong unit, an instrument tilt kept by ``--detrend mean``,
loads beyond the elastic half-space (refused before the solve), and large strains
(warned of after it). Split from :mod:`roughfe.cli.options` (round 2, session 28)."""
from __future__ import annotations

from .options import warn


#: share of the height variance about the mean carried by the least-squares plane above
#: which a non-periodic surface read with ``--detrend mean`` warns (:func:`roughfe.cli.options.surface_from_args`).
#: On a self-affine window the plane is the longest roughness wavelength: over 40 seeds
#: it carries up to 0.88-0.92 of the variance of RMD surfaces and profiles (0.59 for the
#: thesis' Fig. 7 surface, seed 0; 0.5 warned on 47-88 % of them); an instrument's tilt
#: carries more (plu-1: 0.99996)
TILT_SHARE_LIMIT = 0.95


#: rms slope above which the heights are said to be out of the half-space's range (and
#: probably in another unit than metres: heights in um read as m give ~1e6)
SLOPE_LIMIT = 1.0
#: factor between --size and the size an instrument file states beyond which both are said
SIZE_RATIO_LIMIT = 100.0


def warn_units(args, surface) -> None:
    """Warn (stderr) of the two unit mistakes a review found accepted without a word: an
    rms slope above :data:`SLOPE_LIMIT` (a plain matrix of heights in um read as m had
    rms slope 1.3e6 and ran to a mean gap of 3 m), and a ``--size`` that differs from the
    instrument file's own size by more than :data:`SIZE_RATIO_LIMIT` (``--size 500`` for
    500 nm on an AFM file: a 500 m scan)."""
    from ..surfaces.stats import rms_slope

    in_file = surface.metadata.get("size_in_file")
    if in_file:
        ratio = max(max(a / b, b / a) for a, b in zip(surface.size, in_file) if a > 0 and b > 0)
        if ratio > SIZE_RATIO_LIMIT:
            warn(args, f"--size {' x '.join(f'{v:.4g}' for v in surface.size)} m differs "
                       f"{ratio:.3g}x from the file's own size "
                       f"{' x '.join(f'{v:.4g}' for v in in_file)} m: --size is in metres")
    try:
        slope = rms_slope(surface)
    except Exception:       # noqa: BLE001 -- a flat or degenerate surface: no slope to judge
        return
    if slope > SLOPE_LIMIT:
        warn(args, f"rms slope {slope:.3g} > {SLOPE_LIMIT:g}: beyond the small slopes of the "
                   f"elastic half-space" + (" -- far beyond: are the heights in metres and "
                                            "the size (--size) in metres?" if slope > 100 else ""))


def warn_tilt(args, surface) -> None:
    """Warn (once, stderr) when the least-squares plane of a non-periodic ``surface``
    carries more than :data:`TILT_SHARE_LIMIT` of its height variance about the mean:
    ``--detrend mean`` (the default) then solves a tilted plane (plu-1: rms 2.834 um
    with the mean removed, 18.3 nm with the plane removed; contact A* 0.0069 instead of
    0.037 at 9.4 kPa)."""
    from ..surfaces.stats import rms_height

    rms_mean, rms_plane = rms_height(surface), rms_height(surface.detrended("plane"))
    share = 1.0 - (rms_plane / rms_mean) ** 2 if rms_mean > 0 else 0.0
    if share > TILT_SHARE_LIMIT:
        warn(args, f"--detrend mean keeps the tilt of this non-periodic surface: its "
                   f"least-squares plane carries {100 * share:.5g} % of the height variance "
                   f"(rms height {rms_mean:.4g} m with the mean removed, {rms_plane:.4g} m "
                   f"with the plane removed): if that plane is the instrument's tilt and not "
                   f"the longest wavelength of the roughness, use --detrend plane")


#: Largest approach Delta / lateral size L before :func:`check_small_strain` warns.
SMALL_STRAIN_LIMIT = 0.1


def check_load_magnitudes(surface, material, pressures=None, deltas=None) -> None:
    """Refuse, before any solve, loads that no elastic half-space can mean: a mean
    pressure above E* (strains ~ p / E* >= 1: mostly E given in GPa or MPa as if in Pa)
    and an approach larger than the surface's smallest lateral size (a strain above 1:
    mostly a length in the wrong unit). Such a run took 10 minutes to a
    NoConvergenceError (``--E 210`` at 100 MPa) or ran without end (``--delta 1`` on a
    0.5 um window; a user's review, round 2, session 28). The milder case, an approach
    above 10 % of the size, is warned of after the solve (:func:`check_small_strain`)."""
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
        d, length = max(abs(float(v)) for v in deltas), min(surface.size)
        if d > length:
            raise InputError(
                f"approach {d:.4g} m is {d / length:.3g} x the smallest lateral size "
                f"{length:.4g} m of the surface: a strain above 1, beyond the elastic "
                f"half-space; is --delta in metres?")


def check_small_strain(args, surface, deltas, material, pressures) -> None:
    """Warn when the largest approach exceeds 10 % of the smallest lateral size.

    The half-space solution is linear elasticity: it assumes strains ~ Delta / L << 1.
    A non-periodic patch of 100 um pressed to p = 1e12 Pa needs Delta ~ 8 cm, a strain
    of 800 -- a number the solver returns but no material follows.
    """
    deltas = [float(d) for d in deltas]
    if not deltas:
        return
    d_max, length = max(deltas), min(surface.size)
    if d_max > SMALL_STRAIN_LIMIT * length:
        p_max = max(float(p) for p in pressures)
        warn(args, f"approach Delta = {d_max:.3g} m is {d_max / length:.3g} x the lateral size "
                   f"{length:.3g} m (p = {p_max:.3g} Pa = {p_max / material.E_star:.3g} E*): "
                   "far beyond the small strains of the elastic half-space; the result is not "
                   "physical")
