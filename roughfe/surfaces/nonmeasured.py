"""Points an instrument file marks as not measured but SurfaceTopography returns as heights.

A reader of SurfaceTopography masks a file's undefined points where it knows the format's
marker (the NaN of an ``.opd``); :func:`roughfe.surfaces.io.load_surface` fills masked
points by harmonic interpolation and counts them in ``metadata["filled_points"]``. Where a
reader does not know the marker, the marker comes back as a height, and every statistic
and contact of the surface sees a spurious spike. :data:`MARKERS` lists, per reader, how to
find those points; :func:`nonmeasured_mask` applies it.

Digital Surf ``.sur`` (SurfaceTopography 1.18 ``SURReader`` keeps them): with the
header's ``special_points`` flag set, a non-measured point is the integer ``zmin - 2``,
two counts below the lowest measured one (the MountainsMap format, as written and read by
RosettaSciIO's digitalsurf plugin). sur-2.sur has 117 of them, 1.25 um below a surface of
17 nm rms: read as heights they were "deep pits" (rms height 31.2 nm, skewness -30,
kurtosis 1165, a PSD fit of H = -0.48).
"""
from __future__ import annotations

import numpy as np


def _sur_nonmeasured(topography):
    raw = (topography.info or {}).get("raw_metadata")
    if not isinstance(raw, dict) or not raw.get("special_points"):
        return None
    scale, zmin = raw.get("height_scale_factor"), raw.get("zmin")
    if not scale or zmin is None:
        return None
    counts = np.ma.getdata(topography.heights()) / float(scale)
    marker = np.abs(counts - (int(zmin) - 2)) < 0.5
    # the reader's heights are counts times the scale: a marker is an integer count
    if marker.any() and not np.allclose(counts[marker], int(zmin) - 2, rtol=0, atol=1e-3):
        return None
    return marker


#: reader class name -> function(topography in the file's unit) -> boolean mask of the
#: points the file marks as not measured (None: the file marks none, or says nothing)
MARKERS = {"SURReader": _sur_nonmeasured}


def nonmeasured_mask(reader, topography):
    """Boolean mask of the points ``topography`` (read by ``reader``, in the file's unit)
    holds as heights although the file marks them as not measured, or None."""
    find = MARKERS.get(type(reader).__name__)
    if find is None:
        return None
    mask = find(topography)
    return mask if mask is not None and mask.any() else None


def masked(topography, mask):
    """``topography`` with ``mask`` added to its undefined points (a SurfaceTopography
    Topography of the same size, unit, periodicity and info)."""
    from SurfaceTopography import Topography

    heights = topography.heights()
    mask = np.ma.getmaskarray(heights) | mask
    return Topography(np.ma.masked_array(np.ma.getdata(heights), mask=mask),
                      topography.physical_sizes, periodic=topography.is_periodic,
                      unit=topography.unit, info=topography.info)
