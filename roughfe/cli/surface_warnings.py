"""Warnings of a read surface, given by every command that reads one (info, contact, leak,
natural, genome chromosomes, design-targets, design ``--match-spectrum``) through
:func:`plausible_surface`: heights and sizes in a wrong unit, an instrument tilt kept by
``--detrend mean`` (or ``lines``), offset scan lines, a mirrored window's lines levelled,
and a seam under ``--periodic``. Split from :mod:`roughfe.cli.plausibility` (round 2,
session 36), which keeps the checks of loads, solutions and design targets."""
from __future__ import annotations

import numpy as np

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
    """Warn (stderr) of the size mistakes a review found accepted without a word: a
    ``--size`` that differs from the instrument file's own size by more than
    :data:`SIZE_RATIO_LIMIT` (``--size 500`` for 500 nm on an AFM file: a 500 m scan), and
    one ``--size`` value on a non-square grid (cells that are not square). The slope (a
    matrix of heights in um read as m) is :func:`warn_slope`'s, judged after the
    detrending."""
    in_file = surface.metadata.get("size_in_file")
    if in_file:
        ratio = max(max(a / b, b / a) for a, b in zip(surface.size, in_file) if a > 0 and b > 0)
        if ratio > SIZE_RATIO_LIMIT:
            warn(args, f"--size {' x '.join(f'{v:.4g}' for v in surface.size)} m differs "
                       f"{ratio:.3g}x from the file's own size "
                       f"{' x '.join(f'{v:.4g}' for v in in_file)} m: --size is in metres")
    size = getattr(args, "size", None)
    if size is not None and len(size) == 1 and surface.ndim == 2 \
            and surface.shape[0] != surface.shape[1]:
        dx, dy = surface.spacing
        warn(args, f"one --size value on a {surface.shape[0]} x {surface.shape[1]} grid makes "
                   f"a square of {size[0]:.4g} m with cells of {dx:.4g} m x {dy:.4g} m "
                   f"(aspect {max(dx, dy) / min(dx, dy):.3g}); for square cells give "
                   f"--size LX LY")


def warn_slope(args, surface) -> None:
    """Warn (stderr) when the rms slope of ``surface``, the heights as the command uses
    them (after ``--detrend``), is above :data:`SLOPE_LIMIT`; far above it (100) the
    likely unit mistake is named. On a non-periodic surface whose least-squares plane
    brings the slope below the limit the warning says so: the slope is the tilt's. Until
    round 2, session 36 the slope was judged on the heights as read, before the
    detrending, so ``--detrend plane`` on a tilted scan still warned of a slope its
    analysis did not have (di-1's retrace channel: 1.06 as read, 0.72 levelled). The
    review that asked for it: a plain matrix of heights in um read as m had rms slope
    1.3e6 and ran to a mean gap of 3 m."""
    slope = rms_slope_or_zero(surface)
    if slope <= SLOPE_LIMIT:
        return
    tilt = ""
    if not surface.periodic:
        flat = rms_slope_or_zero(surface.detrended("plane"))
        if flat <= SLOPE_LIMIT:
            tilt = (f"; {flat:.3g} with its least-squares plane removed: the slope is the "
                    f"tilt's (--detrend plane if the tilt is the instrument's)")
    warn(args, f"rms slope {slope:.3g} > {SLOPE_LIMIT:g}: beyond the small slopes of the "
               f"elastic half-space" + tilt + (" -- far beyond: are the heights in metres "
                                               "and the size (--size) in metres?"
                                               if slope > 100 else ""))


def warn_tilt(args, surface, detrend: str = "mean") -> None:
    """Warn (once, stderr) when the least-squares plane of a non-periodic ``surface``
    carries more than :data:`TILT_SHARE_LIMIT` of its height variance about the mean:
    ``--detrend mean`` (the default) then solves a tilted plane (plu-1: rms 2.834 um
    with the mean removed, 18.3 nm with the plane removed; contact A* 0.0069 instead of
    0.037 at 9.4 kPa). With ``detrend="lines"`` the same share of the line-levelled map
    (each scan line's mean removed, which takes out the tilt across the lines but keeps
    the one along them, x unless the metadata's ``scan_axis`` is y): plu-1 0.99996, as
    with the mean; 240 RMD and spectral windows without a tilt at most 0.91 (round 2,
    session 34)."""
    from ..surfaces.stats import rms_height

    kept = surface.detrended("lines") if detrend == "lines" else surface
    rms_kept, rms_plane = rms_height(kept), rms_height(kept.detrended("plane"))
    share = 1.0 - (rms_plane / rms_kept) ** 2 if rms_kept > 0 else 0.0
    if share <= TILT_SHARE_LIMIT:
        return
    if detrend == "lines":
        from ..surfaces.scan_lines import scan_axis_of
        warn(args, f"--detrend lines keeps the tilt along {scan_axis_of(surface)} of this "
                   f"non-periodic surface "
                   f"(it levels each scan line's mean, not its slope): the least-squares "
                   f"plane of the levelled map carries {100 * share:.5g} % of its height "
                   f"variance (rms height {rms_kept:.4g} m with the lines levelled, "
                   f"{rms_plane:.4g} m with the plane removed too): if that plane is the "
                   f"instrument's tilt and not the longest wavelength of the roughness, use "
                   f"--detrend lines-tilt (each line's least-squares straight line)")
        return
    warn(args, f"--detrend mean keeps the tilt of this non-periodic surface: its "
               f"least-squares plane carries {100 * share:.5g} % of the height variance "
               f"(rms height {rms_kept:.4g} m with the mean removed, {rms_plane:.4g} m "
               f"with the plane removed): if that plane is the instrument's tilt and not "
               f"the longest wavelength of the roughness, use --detrend plane")


#: Largest rms height jump across a period's edge, in units of the rms step between
#: neighbouring points along that axis, before :func:`warn_seam` warns. Periodic
#: surfaces give 0.8-1.2 (spectral, 128^2, H = 0.3 and 0.8); windows cut from them 3.9-41;
#: the measured files with their plane removed 1.4-72 (opd-1 4.2, sur-2 2.8, x3p-2 15;
#: sur-2 re-measured after the .sur reader fix, round 2, session 32: 9.0 with its
#: non-measured points read as heights; now below the limit, so --periodic on sur-2 is
#: not warned of)
SEAM_LIMIT = 3.0


def warn_seam(args, surface) -> None:
    """Warn (once, stderr) when ``--periodic`` is given to heights that do not join up
    across the period: along an axis whose edge rows differ by more than
    :data:`SEAM_LIMIT` times the rms step between neighbouring rows, the periodic
    operator sees a step (a ridge or a trench) at the seam, which carries contact and
    blocks or opens a leak channel that the real surface does not have."""
    h = surface.heights
    jumps = []
    for axis in range(h.ndim):
        step = float(np.sqrt(np.mean(np.diff(h, axis=axis) ** 2)))
        seam = np.take(h, 0, axis=axis) - np.take(h, -1, axis=axis)
        ratio = float(np.sqrt(np.mean(seam ** 2))) / step if step > 0 else 0.0
        if ratio > SEAM_LIMIT:
            jumps.append(f"{ratio:.3g}x along axis {axis}")
    if jumps:
        warn(args, f"--periodic: the heights jump across the period's edges by "
                   f"{' and '.join(jumps)} the rms step between neighbouring points (a "
                   f"periodic surface: about 1); the seam acts as a ridge or a trench. A "
                   f"measured window is not periodic: use --non-periodic, or --mirror where "
                   f"the command has it")


def warn_scan_lines(args, surface) -> None:
    """Warn (once, stderr) when the scan lines of a map look offset from each other
    (:func:`roughfe.surfaces.scan_lines.scan_line_check`: the line means' second
    differences over the within-line ones at the same lag, above
    ``max(0.25, 4 / sqrt(n))`` with n the points per line; none of 800 spectral
    surfaces, H 0.3-1, n 32-512, fired) and suggest ``--detrend lines``. The lines run along x, or along y
    when the surface's metadata ``scan_axis`` is y (``--scan-axis y``); the warning
    names the axis. Of the five measured files only di-1 (an AFM scan) fires: 11.2
    (the others 0.04-0.11)."""
    from ..surfaces.scan_lines import is_mirrored, scan_line_check

    check = scan_line_check(surface)
    if check is not None and check.fires:
        warn(args, check.note() + (f"; but {_mirror_words(surface)}: level the measured "
                                   f"window before mirroring" if is_mirrored(surface) else ""))


def _mirror_words(surface) -> str:      # what says that it is a mirrored window
    if surface.metadata.get("mirrored"):
        return "this map is a mirrored window (its metadata says so)"
    n = [k // 2 + 1 for k in surface.shape]             # the window's points per axis
    return (f"this map is a mirrored window: its heights are even about the first row and "
            f"column bit for bit (h[i] = h[-i] along both axes), as Surface.mirrored and "
            f"--mirror build them: a window of {n[0]} x {n[1]} points "
            f"({' x '.join(f'{k * d:.4g}' for k, d in zip(n, surface.spacing))} m) and "
            f"its mirror images")


def warn_mirrored_lines(args, surface, detrend: str) -> None:
    """Warn (once, stderr) when ``--detrend lines | lines-tilt`` levels the lines of a
    mirrored window (:func:`roughfe.surfaces.scan_lines.is_mirrored`: its metadata, or
    heights even about the first row and column, e.g. a ``.npy`` of a mirrored map): they
    are measured lines joined to their mirror images. Against levelling before mirroring
    (96 x 64 map, line offsets and tilts): ``lines`` 1.2 % of Sq off, ``lines-tilt`` 3.5 Sq
    (the tilts kept), periodic or not. ``band_chromosomes`` refuses it (session 35); the
    commands said nothing until round 2, session 36."""
    from ..surfaces.scan_lines import is_mirrored, scan_axis_of

    if detrend not in ("lines", "lines-tilt") or not is_mirrored(surface):
        return
    warn(args, f"--detrend {detrend} levels each scan line along {scan_axis_of(surface)}, "
               f"but {_mirror_words(surface)}. Its lines are measured lines joined to their "
               f"mirror images, not the instrument's scan lines, and levelling them is not "
               f"the levelling of the measured ones"
               + (" (it keeps every line's tilt: a line joined to its mirror image has "
                  "none)" if detrend == "lines-tilt" else "")
               + f". Level the measured window before mirroring: its own file with "
                 f"--detrend {detrend} (and --mirror where the command has it: contact, "
                 f"genome chromosomes); or read these heights with --detrend mean")


def plausible_surface(args, surface, detrend: str = "none"):
    """``surface`` as its file gave it, detrended by ``detrend`` (a ``--detrend`` mode),
    after the warnings of a read surface: a size mistake (:func:`warn_units`), an
    instrument tilt kept by ``mean`` or ``lines`` on a non-periodic surface
    (:func:`warn_tilt`), scan-line offsets left by ``none``, ``mean`` or ``plane``
    (:func:`warn_scan_lines`), the lines of a mirrored window levelled by ``lines`` or
    ``lines-tilt`` (:func:`warn_mirrored_lines`), then on the detrended heights an rms
    slope beyond the half-space's (:func:`warn_slope`) and, with ``--periodic``, a seam
    (:func:`warn_seam`). The one path of these warnings: the commands that read
    :func:`roughfe.cli.options.surface_from_args` (info, contact, leak, natural, genome
    chromosomes), ``design-targets --surface``, which detrends in the library
    (:func:`roughfe.genomics.design.targets.target_surface`) and took none of them
    until round 2, session 35, and ``design --match-spectrum`` (round 2, session 36)."""
    warn_units(args, surface)
    if detrend in ("mean", "lines") and not surface.periodic:
        warn_tilt(args, surface, detrend)
    if detrend in ("none", "mean", "plane"):
        warn_scan_lines(args, surface)
    warn_mirrored_lines(args, surface, detrend)
    surface = surface if detrend == "none" else surface.detrended(detrend)
    warn_slope(args, surface)
    if getattr(args, "periodic", None) is True:
        warn_seam(args, surface)
    return surface


def rms_slope_or_zero(surface) -> float:
    """The rms slope of ``surface`` (finite differences, as ``roughfe info``), 0 for a
    flat or degenerate one (no slope to judge)."""
    from ..surfaces.stats import rms_slope
    try:
        return float(rms_slope(surface))
    except Exception:       # noqa: BLE001
        return 0.0
