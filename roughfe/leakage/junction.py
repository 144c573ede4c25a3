"""The critical constriction of a gap field (thesis Ch. 5 "critical section size and length of
the parent channel"; Persson's critical junction measured on the simulated gap).

Definitions (flow along axis 0 for ``direction="x"``, inlet at index 0; cells are
face-connected, the connectivity of the default finite-volume Reynolds scheme):

* **Critical gap** ``u_c``: the largest ``u`` for which the cells with ``gap >= u``
  still join the inlet to the outlet (the bottleneck, or maximin, value over all
  inlet-outlet paths: the widest path). Found by bisection over the sorted gap values,
  one connected-component labelling (scipy, linear) per step, so ``O(N log N)``.
* **Junction**: the cell with ``gap = u_c`` on the widest path; every inlet-outlet path
  through ``{gap >= u_c}`` passes through it (removing it, ``{gap > u_c}`` does not
  percolate). ``position`` is its centre ``(i dx, j dy)`` (m), the coordinates of
  :meth:`roughfe.surfaces.Surface.coordinates` (cell centres from 0).
* **Widest path**: the shortest (fewest cells) inlet-outlet path inside ``{gap >= u_c}``
  (breadth-first search), which passes through the junction.
* **Width** ``w_c``: the length of the open cross-section (run of cells with gap > 0)
  through the junction, transverse to the path's local direction there (Alg. 1's
  cross-section), m.
* **Parent channel**: the maximal stretch of the widest path around the junction in which
  the gap stays below ``channel_factor * u_c`` (default 2: where the local conductance
  ``h^3`` is within a factor 8 of the junction's); ``parent_channel_length`` is its length
  along the path (m). The thesis names these two sizes as future work without a
  definition; these are ours, stated here and in docs/theory/04b_leakage_ii.md.
* **At the edge** (``at_edge``): on a non-periodic window (a measured crop), a junction
  whose cell lies within :data:`EDGE_CELLS` cell of any of the four window edges. The
  constriction there may be an artefact of the cut: beyond the edge the real surface can
  go round it (a wall of the window) or open into it (the inlet or outlet reservoir), so
  ``u_c``, the width and the junction leak rate are then the window's, not the
  surface's. A periodic window has no cut and never flags.
* ``leak_rate_junction`` = ``(W/L) u_c^3 dp / (12 mu)``: Lorenz & Persson's (2009)
  critical-junction formula (Eq. 5 there) with the *measured* ``u_c``, beside the
  Reynolds leak rate and beside the PSD-based estimate of
  :func:`roughfe.theory.junction.critical_junction`.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import breadth_first_order

from ..errors import (InputError, check_finite_nonnegative, check_finite_positive,
                      check_leak_scale, check_real_array, check_spacing)
from ..frozen import ReadOnlyArrays, read_only_arrays
from .components import components_reaching

#: a junction within this many cells of a non-periodic window edge is ``at_edge`` (0: the
#: edge row or column only; 1: also the next one, where a channel closing at the cut
#: still narrows; the x3p-2 128^2 crop's y junction was in the last row, round 2, s. 33)
EDGE_CELLS = 1


@dataclass(frozen=True, eq=False)
class CriticalConstriction(ReadOnlyArrays):
    """Bottleneck of the open network along one flow direction.

    Attributes
    ----------
    direction : {"x", "y"}
    percolates : bool
        Whether any open path exists (False: every other field is None/empty).
    critical_gap : float or None
        ``u_c`` (m).
    junction : tuple of int or None
        Grid index ``(i, j)`` of the junction cell.
    position : tuple of float or None
        Centre of the junction cell, ``(i dx, j dy)`` (m; :meth:`Surface.coordinates`).
    width : float or None
        Open cross-section through the junction, transverse to the path (m).
    parent_channel_length : float or None
        Length of the parent channel along the path (m).
    path : ndarray of int, shape (n, 2)
        Cells of the widest (shortest maximin) inlet-outlet path.
    channel : ndarray of int, shape (m, 2)
        Cells of the parent channel (a stretch of ``path``).
    channel_factor : float
        Parent-channel threshold (gap < factor u_c).
    at_edge : bool
        The junction lies within :data:`EDGE_CELLS` cell of a window edge of a
        non-periodic gap (module docstring): the constriction may be the cut's, not the
        surface's. False without a junction and on periodic gaps.
    """

    direction: str
    percolates: bool
    critical_gap: Optional[float]
    junction: Optional[tuple]
    position: Optional[tuple]
    width: Optional[float]
    parent_channel_length: Optional[float]
    path: np.ndarray
    channel: np.ndarray
    channel_factor: float
    at_edge: bool = False

    def __post_init__(self):       # a result never changes: its arrays read-only
        read_only_arrays(self)     # in place (copies: +0.45 GB at 4096^2 Reynolds)

    def leak_rate_junction(self, *, mu: float, pressure_drop: float, length: float,
                           width: float) -> Optional[float]:
        """``(W/L) u_c^3 dp / (12 mu)`` (m^3/s) with the measured ``u_c``; 0 if sealed.

        ``length`` and ``width`` are the domain's size along and across the flow (m). A
        rate beyond the normal float range is an InputError
        (:func:`roughfe.errors.check_leak_scale`).
        """
        mu = check_finite_positive("mu (Pa s)", mu)
        pressure_drop = check_finite_nonnegative("pressure_drop (Pa)", pressure_drop)
        length = check_finite_positive("length (m)", length)
        width = check_finite_positive("width (m)", width)
        if not self.percolates:
            return 0.0
        # linear in dp / mu: scaled as the Reynolds leak rate (a drop or viscosity near the
        # float limits gave 0 or inf in silence; InputError beyond the floats)
        return check_leak_scale(width / length * self.critical_gap ** 3 / 12.0,
                                pressure_drop, mu)

    def record(self) -> dict:
        """JSON-safe scalars: ``critical_gap``, ``critical_position``, ``critical_width``,
        ``parent_channel_length``, ``critical_at_edge`` (None without a junction)."""
        return {"critical_gap": self.critical_gap,
                "critical_position": None if self.position is None else list(self.position),
                "critical_width": self.width,
                "parent_channel_length": self.parent_channel_length,
                "critical_at_edge": None if self.junction is None else bool(self.at_edge)}


def _percolates(g_flow, u, periodic):
    _, t_in, t_out = components_reaching(g_flow >= u, periodic=periodic)
    return bool((t_in & t_out).any())


def _shortest_path(open_cells, periodic):
    """Fewest-cell inlet->outlet path through face-connected ``open_cells`` (axis 0)."""
    nl, nt = open_cells.shape
    n = nl * nt
    idx = np.arange(n).reshape(nl, nt)
    pairs = [(idx[:-1], idx[1:], open_cells[:-1] & open_cells[1:]),
             (idx[:, :-1], idx[:, 1:], open_cells[:, :-1] & open_cells[:, 1:])]
    if periodic and nt > 1:
        pairs.append((idx[:, -1], idx[:, 0], open_cells[:, -1] & open_cells[:, 0]))
    a = np.concatenate([p[0][p[2]] for p in pairs] + [np.full(int(open_cells[0].sum()), n)])
    b = np.concatenate([p[1][p[2]] for p in pairs] + [idx[0][open_cells[0]]])
    graph = sp.csr_matrix((np.ones(a.size), (a, b)), shape=(n + 1, n + 1))
    order, pred = breadth_first_order(graph, n, directed=False, return_predecessors=True)
    last_row = np.zeros(n + 1, bool)
    last_row[idx[-1][open_cells[-1]]] = True
    end = order[last_row[order]][0]          # first outlet cell reached: fewest steps
    path = [end]
    while pred[path[-1]] != n:
        path.append(pred[path[-1]])
    path = np.array(path[::-1])
    return np.column_stack(np.unravel_index(path, (nl, nt)))


def critical_constriction(gap, spacing, *, direction: str = "x", periodic: bool = False,
                          channel_factor: float = 2.0) -> CriticalConstriction:
    """Critical gap, junction, width and parent channel of a gap field (module docstring).

    Parameters
    ----------
    gap : ndarray, shape (nx, ny)
        Gap in m (0 in contact).
    spacing : (float, float)
        ``(dx, dy)`` in m.
    direction : {"x", "y"}
        Flow axis (inlet at coordinate 0).
    periodic : bool
        Periodic side walls.
    channel_factor : float
        The parent channel is where the gap along the path stays below
        ``channel_factor * u_c`` (> 1).

    Returns
    -------
    CriticalConstriction
        With ``at_edge`` when ``periodic`` is False and the junction lies within
        :data:`EDGE_CELLS` cell of an edge.
    """
    g = check_real_array("gap", gap, 2)
    if min(g.shape) < 1 or g.min() < 0:
        raise InputError(f"gap must be a finite 2D array (nx, ny) of metres >= 0, got shape "
                         f"{g.shape}")
    if direction not in ("x", "y"):
        raise InputError(f"direction must be 'x' or 'y', got {direction!r}")
    dx, dy = check_spacing(spacing)
    factor = float(channel_factor)
    if not (np.isfinite(factor) and factor > 1):
        raise InputError(f"channel_factor must be > 1, got {channel_factor!r}")
    gf, dl, dt = (g, dx, dy) if direction == "x" else (g.T, dy, dx)
    values = np.unique(gf[gf > 0])
    empty = np.empty((0, 2), dtype=np.int64)
    if values.size == 0 or not _percolates(gf, values[0], periodic):
        return CriticalConstriction(direction, False, None, None, None, None, None, empty,
                                    empty, factor)
    lo, hi = 0, values.size - 1                 # percolates at values[lo]; find the largest
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if _percolates(gf, values[mid], periodic):
            lo = mid
        else:
            hi = mid - 1
    u_c = float(values[lo])
    path = _shortest_path(gf >= u_c, periodic)
    on = np.flatnonzero(gf[path[:, 0], path[:, 1]] == u_c)
    k = int(on[0])
    i, j = (int(v) for v in path[k])
    # local direction: the step into (or out of) the junction cell
    nb = path[k - 1] if k > 0 else path[min(k + 1, len(path) - 1)]
    along_flow = nb[0] != i or len(path) == 1
    if along_flow:                               # cross-section along axis 1
        row, pos, step = gf[i] > 0, j, dt
    else:
        row, pos, step = gf[:, j] > 0, i, dl
    width = step * _run_length(row, pos, periodic and along_flow)   # only axis 1 wraps
    # parent channel: contiguous stretch of the path with gap < factor u_c
    narrow = gf[path[:, 0], path[:, 1]] < factor * u_c
    a = k
    while a > 0 and narrow[a - 1]:
        a -= 1
    b = k
    while b < len(path) - 1 and narrow[b + 1]:
        b += 1
    seg = path[a:b + 1]
    # each cell's extent along the path: the step that enters it (first cell: that leaves it)
    along = np.abs(np.diff(path[:, 0])) != 0
    along = np.concatenate([along[:1] if along.size else [True], along])
    length = float(np.where(along, dl, dt)[a:b + 1].sum())
    centre = (i * dl, j * dt)           # the cell centres of Surface.coordinates()
    # the distance to the nearest edge; a periodic window has none (its walls wrap, and
    # its inlet and outlet cut nothing: the surface beyond them is the window itself)
    at_edge = not periodic and min(i, j, gf.shape[0] - 1 - i, gf.shape[1] - 1 - j) <= EDGE_CELLS
    if direction == "y":
        path, seg = path[:, ::-1], seg[:, ::-1]
        i, j = j, i
        centre = centre[::-1]
    return CriticalConstriction(direction=direction, percolates=True, critical_gap=u_c,
                                junction=(i, j), position=tuple(float(c) for c in centre),
                                width=float(width), parent_channel_length=length,
                                path=np.ascontiguousarray(path),
                                channel=np.ascontiguousarray(seg), channel_factor=factor,
                                at_edge=bool(at_edge))


def _run_length(row: np.ndarray, pos: int, periodic: bool) -> int:
    """Number of consecutive True entries of ``row`` through index ``pos``."""
    n = row.size
    if row.all():
        return n
    left = pos
    count = 1
    while True:
        nxt = left - 1
        if nxt < 0:
            if not periodic:
                break
            nxt = n - 1
        if not row[nxt]:
            break
        left, count = nxt, count + 1
    right = pos
    while True:
        nxt = right + 1
        if nxt >= n:
            if not periodic:
                break
            nxt = 0
        if not row[nxt]:
            break
        right, count = nxt, count + 1
    return count
