"""The stored layout of instrument files: which array axis is x (the fast-scan line), and
the correction of SurfaceTopography's Bruker/Veeco ``.di`` reader for non-square maps.

roughfe's convention is ``heights[i, j]`` at ``x = i dx, y = j dy`` (axis 0 is x,
:mod:`roughfe.surfaces.surface`). An instrument stores its map line by line: a line holds
the points along the fast axis (a scan line of an AFM or a stylus, a row of a camera),
the lines follow each other along the slow axis. Every format read here puts the stored
lines along x, as the instrument's software and Gwyddion show them. Checked in round 2,
session 35 against independent readers of the five files in
:func:`~roughfe.surfaces.io.topographies_folder` (their headers parsed and their raw
blocks read by hand, compared after removing the mean):

=====  ======================  ===================================================  ========
file   stored                  roughfe ``heights`` (from the raw block)             agree to
=====  ======================  ===================================================  ========
x3p-2  x fastest (ISO 5436-2)  ``raw.reshape(650, 650).T``, 82.98 x 204.48 um       exact
sur-2  563 points a line       ``raw.reshape(484, 563).T``, 1.961 x 1.686 mm        5e-11
opd-1  480 points a column     ``raw.reshape(640, 480)[:, ::-1]``, 125.9 x 94.4 um  2e-13
plu-1  768 points a line       ``raw.reshape(576, 768).T``, 1274.9 x 956.2 um       4e-12 m
di-1   512 samps/line          ``raw.reshape(512, 512).T[:, ::-1]``, 500 x 500 nm   1e-15
=====  ======================  ===================================================  ========

(relative to the rms height; plu-1's in metres, its float32 micrometres scaled in float32
by the hand reader; opd-1 and di-1 are
mirrored in y as Gwyddion shows them: the first stored line is the last ``j``, which
changes no statistic). The stored lines are continuous: neighbouring heights along
either axis differ by 0.0014-0.48 of the rms height, the other reshape of the same bytes
(lines of ``n_y`` points) by 0.98-1.50 along y on the three non-square grids.

SurfaceTopography's ``.di`` reader (``DIReader.topography``, its IO/DI.py, version in the
venv of round 2, session 35) reshapes the raw block as ``(samps/line, number of lines)``
where the file stores ``number of lines`` rows of ``samps/line`` points, and returns the
transposed grid with the sizes in the file's order. On a square map that is right; on a
non-square one (a 512 x 256 scan) the points of each scan line are scattered over
several rows, and the grid is ``(lines, samps/line)`` with the size along the line on the
axis of the lines: every statistic of such a file was wrong. :func:`fix_di_lines` undoes
it (the same bytes, reshaped as stored), only when the reader's grid is the transposed
one: a SurfaceTopography that reads such files right is left alone. The sizes are the
image list's ``Scan Size`` (along the line, across the lines), as SurfaceTopography and,
for an image of as many lines as the scan, Gwyddion take them.
"""
from __future__ import annotations

import numpy as np

#: ``metadata["reader_fix"]`` of a non-square .di map whose lines were put back in order
DI_FIX = ("non-square .di: scan lines reordered (SurfaceTopography's DIReader reshapes "
          "the stored (lines, samps/line) block as (samps/line, lines))")


def di_lines_from_reader(heights, nx: int, ny: int) -> np.ndarray:
    """The ``(nx, ny)`` map of a ``.di`` channel with ``nx`` samples per line and ``ny``
    lines from the ``(ny, nx)`` array SurfaceTopography's reader returns.

    Its reader computes ``fliplr(block.reshape(nx, ny).T)`` from the stored ``block`` (the
    raw values in file order, any scale); the right map is
    ``fliplr(block.reshape(ny, nx).T)`` (line ``k`` of the file at ``j = ny - 1 - k``, as
    the reader puts it on square maps). This inverts the first and applies the second.
    """
    heights = np.asarray(heights)
    block = np.fliplr(heights).T.reshape(-1)          # the values in file order
    return np.fliplr(block.reshape(ny, nx).T)


def fix_di_lines(reader, channel, topo):
    """``topo`` (a SurfaceTopography ``Topography`` of ``channel`` read by ``reader``)
    with the scan lines of a non-square ``.di`` map in order (module docstring), and
    whether it was changed. Other formats, square maps and a grid already ``(samps/line,
    lines)`` are returned as they are."""
    if reader.format() != "di" or topo.dim != 2:
        return topo, False
    nx, ny = (int(n) for n in channel.nb_grid_pts)
    if nx == ny or tuple(topo.nb_grid_pts) != (ny, nx):
        return topo, False
    from SurfaceTopography import Topography
    heights = topo.heights()
    data = di_lines_from_reader(np.ma.getdata(heights), nx, ny)
    if np.ma.is_masked(heights):
        data = np.ma.masked_array(data, di_lines_from_reader(np.ma.getmaskarray(heights),
                                                             nx, ny))
    fixed = Topography(data, physical_sizes=tuple(topo.physical_sizes), unit=topo.unit,
                       info=topo.info, periodic=topo.is_periodic)
    return fixed, True
