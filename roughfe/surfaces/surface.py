"""The one data type for rough profiles (1D) and surfaces (2D).

Conventions (fixed here, once, for the whole package):

* ``heights`` are in metres. A profile has shape ``(nx,)``; a surface has shape
  ``(nx, ny)`` with axis 0 along x and axis 1 along y (``heights[i, j]`` is the height
  at ``x = i*dx, y = j*dy``).
* ``size`` is the physical extent of the grid in metres, one entry per axis, and
  ``spacing = size / n``: every sample is the centre of a cell of width ``dx`` (the
  boundary-element view: the nominal area is ``n*dx`` (profile, per unit depth) or
  ``nx*ny*dx*dy``). This is SurfaceTopography's convention too. Generators that are
  defined on ``n`` nodes spanning a length ``L`` end to end (RMD: ``2**m + 1`` nodes
  over ``L``) therefore produce ``size = n * L / (n - 1)``; they say so.
* ``periodic`` says whether the heights repeat with period ``size`` (required by the
  periodic FFT contact operators, honoured by the statistics).
* ``metadata`` holds JSON-safe facts only (generator name, parameters, seed, source
  file); units are never stored there: they are SI by definition of the fields.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping

import numpy as np

from ..errors import InputError, check_bool, check_int, check_real_array
from ..frozen import FrozenMapping, ReadOnlyArrays


#: The lateral sizes a topography may have (m): 1 fm (far below an atom) to 1000 km. Outside,
#: the wavenumbers' and slopes' squares and fourth powers (PSD, spectral moments, the BEM
#: kernels) under- or overflow: --size 1e-300 was a traceback from np.bincount, 1e300 an
#: rms slope of exactly 0 and a null Nayak alpha, and the BEM did not converge.
SIZE_RANGE = (1e-15, 1e6)


def _as_size(size, ndim):
    """``size`` (m: one number, or one per axis) as a tuple of ``ndim`` finite, positive
    floats within :data:`SIZE_RANGE`, or an InputError naming what is wrong."""
    try:
        sizes = np.atleast_1d(np.asarray(size, dtype=float)).ravel()
    except (TypeError, ValueError):
        raise InputError(f"size must be a number of metres or one per axis ({ndim}), "
                         f"got {size!r}") from None
    if sizes.size == 1 and ndim == 2:
        sizes = np.repeat(sizes, 2)
    if sizes.size != ndim:
        raise InputError(
            f"size must have one entry per axis of the heights ({ndim}), got {size!r}")
    for k, s in enumerate(sizes):
        if not (np.isfinite(s) and s > 0):
            raise InputError(f"size[{k}] must be finite and > 0 (metres), got {s!r}")
        if not SIZE_RANGE[0] <= s <= SIZE_RANGE[1]:
            raise InputError(f"size[{k}] = {s:g} m is no lateral size of a topography: "
                             f"allowed are {SIZE_RANGE[0]:g} m to {SIZE_RANGE[1]:g} m (a "
                             f"length in another unit?)")
    return tuple(float(s) for s in sizes)


def _per_axis(name, value, ndim, what):
    """``value`` as one ``(start, stop)`` or None per axis (a profile may give one pair
    bare), or an InputError saying the expected form."""
    form = "(start, stop)" if ndim == 1 else "((x_start, x_stop), (y_start, y_stop))"
    if value is None:
        return (None,) * ndim
    try:
        items = list(value)
        if ndim == 1 and len(items) == 2 and all(v is None or np.ndim(v) == 0 for v in items):
            items = [items]
        pairs = tuple(None if v is None else tuple(v) for v in items)
    except TypeError:
        pairs = None
    if pairs is None or len(pairs) != ndim or any(p is not None and len(p) != 2 for p in pairs):
        raise InputError(f"{name} must be {form} ({what}; None for a whole axis), got {value!r}")
    return pairs


@dataclass(frozen=True, eq=False)
class Surface(ReadOnlyArrays):
    """A rough profile or surface: heights in metres on a regular grid.

    Parameters
    ----------
    heights : array_like, shape (nx,) or (nx, ny)
        Heights in metres. Must be finite; at least 2 points along each axis.
    size : float or sequence of float
        Physical size in metres of each axis (``nx*dx`` and ``ny*dy``). A single
        number for a surface means a square.
    periodic : bool
        Whether the heights are periodic with period ``size``.
    metadata : mapping, optional
        JSON-safe information (generator, parameters, seed, source file, ...); kept as
        a read-only mapping.

    The heights are copied into a read-only array: a ``Surface`` never changes.
    """

    heights: np.ndarray
    size: tuple
    periodic: bool = False
    metadata: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self):
        h = check_real_array("heights", self.heights, (1, 2)).copy()
        if min(h.shape) < 2:
            raise InputError(f"heights need at least 2 points along each axis, got shape {h.shape}")
        h.setflags(write=False)
        object.__setattr__(self, "heights", h)
        object.__setattr__(self, "size", _as_size(self.size, h.ndim))
        object.__setattr__(self, "periodic", check_bool("periodic", self.periodic))
        # read-only (FrozenMapping, picklable): a Surface never changes, nor do its facts
        object.__setattr__(self, "metadata", FrozenMapping(self.metadata or {}))

    # -- geometry -------------------------------------------------------------------
    @property
    def ndim(self) -> int:
        """1 for a profile, 2 for a surface."""
        return self.heights.ndim

    @property
    def shape(self) -> tuple:
        return self.heights.shape

    @property
    def spacing(self) -> tuple:
        """Grid spacing per axis in metres, ``size / n``."""
        return tuple(s / n for s, n in zip(self.size, self.shape))

    @property
    def cell_area(self) -> float:
        """Area of one grid cell: ``dx`` (m, per unit depth) for a profile, ``dx*dy`` (m^2)."""
        return float(np.prod(self.spacing))

    @property
    def nominal_area(self) -> float:
        """Nominal (apparent) contact area ``A_n``: ``Lx`` (m, per unit depth) or ``Lx*Ly`` (m^2)."""
        return float(np.prod(self.size))

    def coordinates(self):
        """Cell-centre coordinates, one 1D array per axis, starting at 0 (metres)."""
        return tuple(np.arange(n) * d for n, d in zip(self.shape, self.spacing))

    # -- derived surfaces -----------------------------------------------------------
    def with_heights(self, heights, **metadata) -> "Surface":
        """A new surface on the same grid with other heights (metadata updated); masked or
        complex heights are an InputError, as in :class:`Surface`."""
        heights = check_real_array("heights", heights)
        if heights.shape != self.shape:
            raise InputError(f"new heights have shape {heights.shape}, expected {self.shape}")
        return Surface(heights, self.size, self.periodic, {**self.metadata, **metadata})

    def scaled(self, factor: float) -> "Surface":
        """Heights multiplied by ``factor`` (same grid)."""
        return self.with_heights(self.heights * float(factor))

    def detrended(self, mode: str = "mean", scan_axis=None) -> "Surface":
        """Remove the mean (``"mean"``) or the least-squares plane/line (``"plane"``; fitted
        on coordinates centred and divided by the size, so the same at any unit of length).

        On a periodic surface ``"plane"`` removes the mean only (metadata ``detrend =
        "plane (periodic: mean)"``): the mean slope of a periodic surface is zero exactly
        (the integral of a derivative over a period), and the least-squares plane of its
        samples is a spurious tilt whose removal breaks the periodicity (a step at the
        edges, +47 % rms slope by spectral derivatives on a 128^2 H = 0.8 surface).

        ``"lines"`` / ``"lines-tilt"`` level each scan line along x (``heights[:, j]``) by
        its mean / least-squares line, for scan-line artefacts of AFM maps only (they
        remove real roughness too): :func:`roughfe.surfaces.scan_lines.level_lines`;
        ``scan_axis="y"`` (or the metadata ``scan_axis = "y"``) levels the lines along y
        (``heights[i, :]``); the other modes ignore ``scan_axis``.
        """
        h = self.heights
        if mode == "mean" or (mode == "plane" and self.periodic):
            return self.with_heights(h - h.mean(), detrend=(
                "mean" if mode == "mean" else "plane (periodic: mean)"))
        if mode == "plane":
            # centred and in units of the size: the columns of the fit are O(1) at any
            # scale (on raw coordinates lstsq's rcond cut the tilt columns of a window
            # below ~1e-11 m, ~1e-9 m at 1024^2, and kept the tilt)
            coords = np.meshgrid(*((c - c.mean()) / length for c, length
                                   in zip(self.coordinates(), self.size)), indexing="ij")
            a = np.column_stack([np.ones(h.size)] + [c.ravel() for c in coords])
            coef, *_ = np.linalg.lstsq(a, h.ravel(), rcond=None)
            return self.with_heights(h - (a @ coef).reshape(h.shape), detrend="plane")
        if mode in ("lines", "lines-tilt"):
            from .scan_lines import level_lines
            return level_lines(self, tilt=mode == "lines-tilt", axis=scan_axis)
        raise InputError(f"detrend mode must be 'mean', 'plane', 'lines' or 'lines-tilt', "
                         f"got {mode!r}")

    def mirrored(self) -> "Surface":
        """The evenly mirrored window: a periodic surface (or profile) of period
        ``2 (n - 1) d`` per axis.

        Along each axis the samples ``h_0, ..., h_{n-1}, h_{n-2}, ..., h_1`` (``2 (n-1)``
        values, spacing ``d`` kept): the periodic extension of a non-periodic window
        without the height step a plain periodic wrap puts at its edges (which would be
        an artificial ridge). Its edges are symmetry planes, so interior samples appear
        twice per axis and edge samples once. Metadata ``mirrored = True``.
        """
        h = self.heights
        for axis in range(h.ndim):
            back = np.flip(np.take(h, np.arange(1, h.shape[axis] - 1), axis=axis), axis=axis)
            h = np.concatenate([h, back], axis=axis)
        size = tuple(m * d for m, d in zip(h.shape, self.spacing))
        return Surface(h, size, periodic=True, metadata={**self.metadata, "mirrored": True})

    def resampled(self, shape) -> "Surface":
        """The band-limited Fourier interpolant of a periodic surface on another grid of
        the same size (``shape`` points per axis, integers >= 2).

        Waves both grids resolve are kept, waves beyond the coarser grid's Nyquist
        wavenumber removed (coarsening low-passes instead of aliasing as thinning would);
        the Nyquist mode of an even grid is the cosine the samples see, split between
        ``+-n/2`` on refinement (the old samples are kept where the nodes coincide) and
        joined from ``+-m/2`` on coarsening; the mean height is kept exactly
        (:func:`roughfe.surfaces.resample.resampled`, which says why). Metadata
        ``resampled_from`` (old shape).
        """
        from .resample import resampled
        return resampled(self, shape)

    def refined(self, factor: int) -> "Surface":
        """The same surface ``factor`` times finer per axis (integer >= 1): the
        band-limited (Fourier) interpolant of the samples, no new roughness; a
        non-periodic window through its even mirror image, keeping its footprint
        (:func:`roughfe.surfaces.resample.refined`, which says how)."""
        from .resample import refined
        return refined(self, factor)

    def cropped(self, index=None, extent=None) -> "Surface":
        """A rectangular window of the grid, by index ranges or by physical extents.

        Parameters
        ----------
        index : (start, stop) per axis, optional
            Half-open index ranges ``start <= i < stop`` (``0 <= start < stop <= n``, at
            least 2 points), as Python slices without steps or negative indices. A
            profile takes one pair; a surface ``((i0, i1), (j0, j1))``, None for a whole
            axis.
        extent : (start, stop) per axis, optional
            Physical ranges in metres on :meth:`coordinates` (``0 <= start < stop <=
            size``): the window holds the points whose cell centres lie in
            ``[start, stop)``, so a range of ``m`` spacings holds ``m`` points.

        Returns
        -------
        Surface
            The heights of the window, ``size = points * spacing`` per axis (the spacing
            is kept), **non-periodic** (a window of a periodic surface does not repeat
            with its own size). Metadata ``window``: ``[start, stop]`` per axis in the
            grid of the surface first cropped (a crop of a crop records one window),
            ``window_of_shape``: that grid's shape.

        Raises
        ------
        InputError
            Neither or both of ``index``/``extent``; a range outside the axis, reversed,
            or of fewer than 2 points (the message names the axis and what is allowed).
        """
        if (index is None) == (extent is None):
            raise InputError("cropped() takes index=... (points) or extent=... (metres), "
                             "one of them")
        ranges = []
        if index is not None:
            for axis, (pair, n) in enumerate(zip(_per_axis("index", index, self.ndim,
                                                           "point indices"), self.shape)):
                if pair is None:
                    ranges.append((0, n))
                    continue
                start, stop = (check_int(f"index[{axis}] {w} (axis {axis} has {n} points, "
                                         f"0..{n})", v, 0) for w, v in zip(("start", "stop"), pair))
                if not (stop <= n and stop - start >= 2):
                    raise InputError(
                        f"index[{axis}] = ({start}, {stop}) is not a window of axis {axis}: "
                        f"allowed 0 <= start < stop <= {n} (its points) with stop - start "
                        f">= 2 (a surface needs 2 points per axis)")
                ranges.append((start, stop))
        else:
            pairs = _per_axis("extent", extent, self.ndim, "metres")
            for axis, (pair, n, d, length) in enumerate(zip(pairs, self.shape, self.spacing,
                                                            self.size)):
                if pair is None:
                    ranges.append((0, n))
                    continue
                lo, hi = (float(np.asarray(v, dtype=float)) if np.ndim(v) == 0 else np.nan
                          for v in pair)
                if not (np.isfinite(lo) and np.isfinite(hi) and 0 <= lo < hi
                        and hi <= length * (1 + 1e-12)):
                    raise InputError(f"extent[{axis}] must satisfy 0 <= start < stop <= "
                                     f"{length:.6g} m (the size of axis {axis}), got {pair!r}")
                # points whose centres i*d lie in [lo, hi); 1e-9 of a cell absorbs the
                # round-off of a bound given as a multiple of the spacing
                start, stop = (min(int(np.ceil(v / d - 1e-9)), n) for v in (lo, hi))
                if stop - start < 2:
                    raise InputError(
                        f"extent[{axis}] = {pair!r} m holds {stop - start} point(s) of axis "
                        f"{axis} (spacing {d:.6g} m); a window needs at least 2 (any extent "
                        f"of 2 spacings, {2 * d:.6g} m, holds 2)")
                ranges.append((start, stop))
        h = self.heights[tuple(slice(a, b) for a, b in ranges)]
        size = tuple((b - a) * d for (a, b), d in zip(ranges, self.spacing))
        outer = self.metadata.get("window")
        first = self.metadata.get("window_of_shape")
        if (outer is not None and first is not None
                and [b - a for a, b in outer] == list(self.shape)):
            # a crop of a crop (on the same grid): one window in the first grid
            ranges = [(a + o[0], b + o[0]) for (a, b), o in zip(ranges, outer)]
        else:
            first = self.shape
        metadata = {**self.metadata, "window": [list(r) for r in ranges],
                    "window_of_shape": list(first)}
        return Surface(h, size, periodic=False, metadata=metadata)

    def __repr__(self):
        kind = "profile" if self.ndim == 1 else "surface"
        size = "(" + ", ".join(f"{v:.6g}" for v in self.size) + ("," if self.ndim == 1 else "")
        return (f"Surface({kind}, shape={self.shape}, size={size}) m, "
                f"periodic={self.periodic})")
