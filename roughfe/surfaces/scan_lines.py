"""Scan-line levelling ("align rows") and a scan-line artefact check of a scanned map.

A scanning instrument (AFM, stylus or confocal line scanner) records a map line by
line: the *fast-scan* lines are each measured in one sweep, the *slow-scan* axis steps
from one line to the next. Drift, tip changes and feedback between sweeps shift each line
by its own height offset (and tilt), a step between neighbouring lines that is no
roughness: it puts power at ``q_x = 0`` along the slow axis, and so into the radial PSD,
the Hurst exponent, the rms slope and the contact.

Convention: the fast-scan lines are the profiles along x, ``heights[:, j]`` (axis 0 is
x; :mod:`roughfe.surfaces.surface`). SurfaceTopography's Bruker/Veeco ``.di`` reader,
which reads the AFM files, returns the file's lines (``samps/line`` points each) as
these columns (it transposes the stored array: ``heights = fliplr(raw.T)``; on a
non-square map roughfe puts its scrambled lines back, :mod:`roughfe.surfaces.layout`), so
a ``.di``'s scan lines are ``heights[:, j]``. Other formats store what the instrument
wrote; a map scanned along y (lines ``heights[i, :]``) is levelled and checked along y
with ``axis="y"`` (``Surface.detrended(mode, scan_axis="y")``, ``--scan-axis y``; the
surface's metadata ``scan_axis = "y"`` makes it the default): the same as the
transposed map along x (tested).

Levelling (:func:`level_lines`, ``Surface.detrended("lines")`` / ``("lines-tilt")``),
what Gwyddion's "align rows" and instrument software do (with the mean, not the median):

* ``"lines"``: each line's mean is subtracted, ``h'_ij = h_ij - (1/n_x) sum_i h_ij``.
  This removes *all* the power at ``q_x = 0`` (on a periodic map exactly the Fourier
  modes ``(0, q_y)``; otherwise each line's mean): the offsets, and also the real
  roughness whose wavevectors point along y, which no single line can tell from an
  offset. On an isotropic map that is one column of the 2D spectrum, ``1 / n_x`` of
  the modes, but it includes the longest waves along y (a tilt along y too); a map's
  tilt along x stays.
* ``"lines-tilt"``: each line's least-squares straight line (on ``x`` centred and
  divided by the length) is subtracted: also every line's own slope (the plane, and the
  real waves along x of wavelength about the length and longer). On a periodic map a
  line's slope is part of its periodic heights, so it removes the means only (metadata
  ``detrend = "lines-tilt (periodic: lines)"``), as ``"plane"`` does.

Both are for scan-line artefacts only, not the default: on a map without them they
remove real roughness. :func:`scan_line_check` says when a map has them.

Check (:func:`scan_line_check`): the line means ``m_j`` of a map with offsets ``o_j``
jump from line to line by the offsets' differences, while the mean over a line of the
real roughness changes little (an average of ``n_x`` heights). The criterion compares
second differences at the same lag (the line spacing ``dy``; ``k = round(dy / dx)``
points along x):

    R = rms_j(m_{j+1} - 2 m_j + m_{j-1}) / rms_ij(h_{i+k,j} - 2 h_ij + h_{i-k,j}),

the line-to-line curvature of the line means over the within-line curvature at the same
lag. Second differences make ``R`` the same with or without a mean or plane removed
and, for a self-affine map (PSD ~ ``q^-2(1+H)``, H < 1), dominated by the short waves,
so that without offsets ``R`` falls as ``1 / sqrt(n_x)``. Independent offsets of rms
``s`` give ``sqrt(6) s`` in the numerator. The check fires when

    R > max(0.25, 4 / sqrt(n_x))      (:data:`FLOOR`, :data:`SCALE`).

Measured (round 2, session 34; spectral surfaces of :mod:`roughfe.surfaces.spectral`, 20
seeds each, H = 0.3, 0.6, 0.9, 1.0, without and with a roll-off at 8 modes): the largest
R without offsets is 0.43 / 0.30 / 0.20 / 0.13 / 0.093 at n = 32 / 64 / 128 / 256 / 512
(~2.1 / sqrt(n)), below the threshold 0.71 / 0.50 / 0.35 / 0.25 / 0.25 by 1.6-2.7x: no
false alarm in 800 maps. With independent offsets of 6 % of the rms height per line
(di-1's size) it fires on 16 / 56 / 103 / 140 / 160 of the 160 maps (R 0.26-14 at 512:
the smaller, the larger the short waves, H = 0.3 with the roll-off, 0.26-0.29); offsets
that small are within the roughness of a small map. The measured files (plane removed):
di-1 (AFM) 11.2, fires; opd-1 0.064, plu-1 0.038, sur-2 0.065, x3p-2 0.11, do not.
A lay along x (grooves parallel to the fast-scan lines) a few
lines in wavelength can fire too: it is not distinguishable from offsets line by line.

Mirrored maps (:func:`is_mirrored`): the lines of a mirrored window
(:meth:`Surface.mirrored`, ``--mirror``) are not scan lines: along the lines half of each
is the mirror image of a measured line, and across them half of the lines are mirror
images of others. Levelling them is not the instrument's "align rows" (a mirrored map is
periodic, so ``"lines-tilt"`` removes the means only and keeps every line's tilt); level
the window, then mirror it. :func:`is_even_mirror` recognises such a map by its heights
alone (bit-for-bit even about its first row and column), when the metadata that says so
is lost (a ``.npy`` of a mirrored map).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from .surface import Surface

#: the array axis of the fast-scan lines' points (x): a line is ``heights[:, j]``
FAST_AXIS = 0
#: threshold of :func:`scan_line_check`: ``R > max(FLOOR, SCALE / sqrt(n_x))``
FLOOR, SCALE = 0.25, 4.0
#: levelling modes of :func:`level_lines` (``Surface.detrended`` names)
LINE_MODES = ("lines", "lines-tilt")
#: the axes the fast-scan lines can run along: x (``heights[:, j]``, the default) or y
#: (``heights[i, :]``)
SCAN_AXES = ("x", "y")


def scan_axis_of(surface: Surface, axis=None) -> str:
    """The axis the fast-scan lines of ``surface`` run along, ``"x"`` or ``"y"``:
    ``axis`` when given, else the surface's metadata ``scan_axis`` (a map read with
    ``--scan-axis y``), else ``"x"``; anything else is an InputError."""
    name = surface.metadata.get("scan_axis", "x") if axis is None else axis
    if not isinstance(name, str) or name not in SCAN_AXES:
        raise InputError(f"scan axis must be 'x' (lines heights[:, j]) or 'y' (lines "
                         f"heights[i, :]), got {name!r}")
    return name


def _along_x(surface: Surface, axis):
    """(heights with the scan lines as columns, the spacing along and across the lines,
    the axis name): the map itself for lines along x, its transpose for lines along y."""
    name = scan_axis_of(surface, axis)
    dx, dy = surface.spacing
    return (surface.heights, (dx, dy), name) if name == "x" else \
        (surface.heights.T, (dy, dx), name)


def is_even_mirror(heights) -> bool:
    """Whether a map is even about its first row and first column bit for bit,
    ``h[i] == h[-i]`` (indices modulo n) along both axes, n even and at least 4, and not
    flat: what :meth:`Surface.mirrored` builds (period ``2 (n - 1)``), also rebuilt into a
    new Surface without its metadata, saved and read back, or shifted by a constant. A
    measured or random map never is (no false alarm on 200 spectral maps or on the five
    measured files, tested); a mirrored map resampled or plane-levelled after mirroring is
    no longer exactly even, and is not recognised. Exact and O(n) in the points."""
    h = np.asarray(heights)
    if h.ndim != 2 or any(n < 4 or n % 2 for n in h.shape) or np.ptp(h) == 0:
        return False
    return all(np.array_equal(h, np.roll(np.flip(h, axis), 1, axis)) for axis in (0, 1))


def is_mirrored(surface: Surface) -> bool:
    """Whether ``surface`` is a mirrored window, whose lines are not scan lines (module
    docstring): its metadata ``mirrored`` (:meth:`Surface.mirrored`) or, without it,
    heights even about the first row and column (:func:`is_even_mirror`)."""
    return bool(surface.metadata.get("mirrored")) or is_even_mirror(surface.heights)


def column_fits_removed(h: np.ndarray, tilt: bool = False) -> np.ndarray:
    """A new array: each column of ``h`` (a line along axis 0) minus its mean, or with
    ``tilt`` minus its least-squares straight line. The arithmetic of
    :func:`level_lines` on a bare array (no Surface built: the coherence of
    :mod:`roughfe.surfaces.reliability` levels 4096 lines of two maps twice)."""
    out = h - h.mean(axis=FAST_AXIS, keepdims=True)
    if tilt:
        x = np.arange(h.shape[FAST_AXIS], dtype=float)
        x = (x - x.mean()) / h.shape[FAST_AXIS]  # centred, per length: O(1) at any scale
        slopes = (x @ out) / (x @ x)              # each line's least-squares slope
        out -= np.outer(x, slopes)
    return out


def level_lines(surface: Surface, tilt: bool = False, axis=None) -> Surface:
    """``surface`` with each fast-scan line's mean removed, or with ``tilt`` its
    least-squares straight line (module docstring: what that removes; on a periodic map
    the means only). The lines run along ``axis`` (:func:`scan_axis_of`: ``"x"``,
    ``heights[:, j]``, by default; ``"y"``, ``heights[i, :]``, levels the transpose and
    sets the metadata ``scan_axis = "y"``). A profile (1D) is one line: an InputError
    (use ``"mean"`` or ``"plane"``). Heights in m; metadata ``detrend`` says which."""
    if surface.ndim != 2:
        raise InputError(f"line levelling needs a 2D map of scan lines, got a profile "
                         f"(shape {surface.shape}); use detrend 'mean' or 'plane'")
    h, _, name = _along_x(surface, axis)
    fit = tilt and not surface.periodic
    out = column_fits_removed(h, tilt=fit)
    detrend = ("lines-tilt" if fit else "lines-tilt (periodic: lines)") if tilt else "lines"
    if name == "x":
        return surface.with_heights(out, detrend=detrend)
    return surface.with_heights(out.T, detrend=detrend, scan_axis="y")


@dataclass(frozen=True)
class ScanLineCheck:
    """Result of :func:`scan_line_check` (module docstring).

    ratio : float
        ``R``, the rms second difference of the line means over the rms second
        difference along the lines at the same lag (-).
    threshold : float
        ``max(FLOOR, SCALE / sqrt(n_x))`` (-).
    fires : bool
        ``ratio > threshold``: the map has scan-line offsets (or a lay along x a few
        lines in wavelength).
    line_jump : float
        rms jump of the line means between neighbouring lines, ``rms(m_{j+1} - m_j)`` (m).
    rms_height : float
        rms height about the mean (m), for scale.
    axis : str
        The axis the scan lines run along, ``"x"`` or ``"y"`` (:func:`scan_axis_of`).
    """

    ratio: float
    threshold: float
    fires: bool
    line_jump: float
    rms_height: float
    axis: str = "x"

    def note(self) -> str:
        """One line suggesting ``--detrend lines`` when the check fires, else ``""``."""
        if not self.fires:
            return ""
        line, other = ("heights[:, j]", "y") if self.axis == "x" else ("heights[i, :]", "x")
        return (f"the scan lines along {self.axis} ({line}) look offset from each other: their "
                f"means jump by {self.line_jump:.3g} m rms from line to line "
                f"({100 * self.line_jump / self.rms_height:.2g} % of the rms height; "
                f"line-to-line curvature of the means {self.ratio:.3g}x the within-line "
                f"one at the same lag, > {self.threshold:.3g}): if that is a scan-line "
                f"artefact (drift, tip changes), level each line with --detrend lines (or "
                f"lines-tilt); it also removes the real roughness along {other} at "
                f"q_{self.axis} = 0" + ("" if self.axis == "y" else
                                         " (a map scanned along y: --scan-axis y)"))


def scan_line_check(surface: Surface, axis=None):
    """The scan-line artefact check of a 2D map (module docstring), or ``None`` when it
    does not apply: a profile, fewer than 3 lines, or lines too short for a second
    difference at the line spacing (``n_x < 2 round(dy / dx) + 1``). The lines run along
    ``axis`` (:func:`scan_axis_of`; ``"y"``: the check of the transposed map)."""
    if surface.ndim != 2:
        return None
    h, (dx, dy), name = _along_x(surface, axis)
    k = max(1, int(round(dy / dx)))
    nx, ny = h.shape
    if ny < 3 or nx < 2 * k + 1:
        return None
    means = h.mean(axis=FAST_AXIS)
    across = float(np.sqrt(np.mean(np.diff(means, 2) ** 2)))
    along = float(np.sqrt(np.mean((h[2 * k:] - 2 * h[k:-k] + h[:-2 * k]) ** 2)))
    ratio = across / along if along > 0 else (np.inf if across > 0 else 0.0)
    threshold = max(FLOOR, SCALE / np.sqrt(nx))
    return ScanLineCheck(ratio=float(ratio), threshold=float(threshold),
                         fires=bool(ratio > threshold),
                         line_jump=float(np.sqrt(np.mean(np.diff(means) ** 2))),
                         rms_height=float(np.sqrt(np.mean((h - h.mean()) ** 2))),
                         axis=name)
