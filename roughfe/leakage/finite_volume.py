"""Cell-centred finite volumes for the Reynolds equation (thesis Eq. 2.10-2.12): the default
leak-rate scheme.

One pressure per grid cell (the BEM grid: sample ``gap[i, j]`` is the centre of a
``dx x dy`` cell); mass balance per cell with two-point fluxes across the four faces:

* between two cells ``a, b`` sharing a face of length ``w`` at centre distance ``l``, the
  pressure-driven volume flow is ``T_ab (p_a - p_b)`` with the transmissibility
  ``T_ab = (w / l) * 2 k_a k_b / (k_a + k_b)``, ``k = h^3 / (12 mu)`` (harmonic mean of
  the conductances, exact for two half-cells in series); a closed cell (``h = 0``) makes
  every face it bounds impermeable, so **two open cells that touch only at a corner never
  exchange fluid** (no conduction through corner contacts, as in Dapp & Muser, EPL 2016,
  and the common Reynolds solvers of rough contacts);
* the inlet and outlet pressures act on the boundary faces, half a cell from the first
  and last centres (``T = w / (l/2) * k``); the sides parallel to the flow are walls
  (no flux) or periodic;
* the Couette term ``h U / 2`` of Eq. 2.11 crosses a face with the mean gap of the two
  cells when both are open (boundary faces: the gap of the boundary cell).

Cells are *connected* when they belong to a face-connected open component that reaches
the inlet or the outlet; the pressure of every other open cell (pockets ringed by
contact: trapped fluid) is not determined by the inlet/outlet data and is NaN; their
rows are identity rows in the (SPD) linear system, solved with CG + BoomerAMG (PETSc,
through :func:`roughfe.fem.petsc_tools.ksp_solve`). The system is assembled with array
operations (no loop over cells). ``percolates`` is True when one open component touches
both inlet and outlet: by construction the same verdict as the free-volume network with
``corner_rule="closed"`` (:func:`roughfe.leakage.network.free_volume_network`).

The leak rate is the mean of the inlet and outlet flows (equal to the solver
tolerance); it is exactly 0 when nothing percolates and no wall moves.
Consistency: the scheme is exact for parallel plates and for strips in series and in
parallel, and second-order convergent on smooth gap fields (tests; the Q1 finite
elements of :mod:`roughfe.fem.reynolds` converge to the same limit).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping, Optional

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from ..errors import InputError, NoConvergenceError, check_finite_positive
from ..fem.petsc_tools import ksp_solve


@dataclass(frozen=True, eq=False)
class FVSolution:
    """Raw cell-centred solution of Eq. 2.12 (grid orientation of the input gap).

    Attributes
    ----------
    pressure : ndarray, shape (nx, ny)
        Cell pressure in Pa; NaN in closed cells and in open cells not connected to the
        inlet or outlet.
    flux : ndarray, shape (nx, ny, 2)
        Flux per unit width at the cell centres (mean of the two opposite face flows
        divided by the face length), m^2/s.
    connected : ndarray of bool, shape (nx, ny)
        Open cells whose component reaches the inlet or the outlet.
    inlet_flow, outlet_flow : float
        Volume flow in through the inlet and out through the outlet (m^3/s).
    leak_rate : float
        Mean of the two (0 exactly without percolation and wall motion).
    percolates : bool
        An open face-connected component touches both inlet and outlet.
    success, message, nit
        Linear solver report.
    """

    pressure: np.ndarray
    flux: np.ndarray
    connected: np.ndarray
    inlet_flow: float
    outlet_flow: float
    leak_rate: float
    percolates: bool
    success: bool
    message: str
    nit: int


def _harmonic(a, b):
    s = a + b
    return np.divide(2.0 * a * b, s, out=np.zeros_like(s), where=s > 0)


def _open_components(open_cells: np.ndarray, periodic: bool):
    """Face-connected components of the open cells (labels per cell, -1 closed)."""
    nl, nt = open_cells.shape
    idx = np.arange(nl * nt).reshape(nl, nt)
    pairs = [(idx[:-1][open_cells[:-1] & open_cells[1:]], idx[1:][open_cells[:-1] & open_cells[1:]]),
             (idx[:, :-1][open_cells[:, :-1] & open_cells[:, 1:]],
              idx[:, 1:][open_cells[:, :-1] & open_cells[:, 1:]])]
    if periodic and nt > 1:
        w = open_cells[:, -1] & open_cells[:, 0]
        pairs.append((idx[:, -1][w], idx[:, 0][w]))
    a = np.concatenate([p[0] for p in pairs])
    b = np.concatenate([p[1] for p in pairs])
    n = nl * nt
    graph = sp.csr_matrix((np.ones(a.size, np.int8), (a, b)), shape=(n, n))
    _, lab = connected_components(graph, directed=False)
    return np.where(open_cells.ravel(), lab, -1).reshape(nl, nt)


def components_reaching(open_cells: np.ndarray, *, periodic: bool = False):
    """Open components, and which of them touch the inlet (row 0) and the outlet (last row).

    Flow along axis 0. Returns ``(labels, touches_in, touches_out)``: per-cell component
    label (-1 closed) and boolean arrays indexed by label.
    """
    lab = _open_components(np.asarray(open_cells, bool), periodic)
    nlab = int(lab.max()) + 1 if lab.size and lab.max() >= 0 else 0
    touches_in = np.zeros(nlab, bool)
    touches_out = np.zeros(nlab, bool)
    touches_in[lab[0][lab[0] >= 0]] = True
    touches_out[lab[-1][lab[-1] >= 0]] = True
    return lab, touches_in, touches_out


def solve_reynolds_fv(gap, spacing, *, direction: str = "x", mu: float = 1e-3,
                      p_in: float = 1.0, p_out: float = 0.0, periodic: bool = False,
                      wall_velocity=(0.0, 0.0),
                      petsc_options: Optional[Mapping] = None) -> FVSolution:
    """Solve Eq. 2.12 by cell-centred finite volumes (see the module docstring).

    Parameters
    ----------
    gap : ndarray, shape (nx, ny)
        Film thickness ``h`` per cell in m (>= 0; 0 in contact).
    spacing : (float, float)
        ``(dx, dy)`` in m.
    direction : {"x", "y"}
        Flow axis; the inlet is the side at coordinate 0.
    mu : float
        Viscosity in Pa s.
    p_in, p_out : float
        Inlet and outlet pressures in Pa (``p_in < p_out`` gives reversed flow: a
        negative leak rate).
    periodic : bool
        Periodic side walls.
    wall_velocity : (float, float)
        Sliding velocity of one wall (m/s).
    petsc_options : mapping, optional
        Overrides of :data:`roughfe.fem.petsc_tools.CG_AMG`.

    Returns
    -------
    FVSolution
    """
    g = np.asarray(gap, dtype=float)
    if g.ndim != 2 or min(g.shape) < 1:
        raise InputError(f"gap must be a 2D array (nx, ny) of metres, got shape {g.shape}")
    if not np.all(np.isfinite(g)) or g.min() < 0:
        raise InputError(f"gap must be finite and >= 0 (m), got min {np.nanmin(g)!r} "
                         f"and {int((~np.isfinite(g)).sum())} non-finite value(s)")
    if direction not in ("x", "y"):
        raise InputError(f"direction must be 'x' or 'y', got {direction!r}")
    mu = check_finite_positive("mu", mu)
    if len(spacing) != 2:
        raise InputError(f"spacing must be (dx, dy) in m, got {spacing!r}")
    dx, dy = (check_finite_positive("spacing", s) for s in spacing)
    if not (np.isfinite(p_in) and np.isfinite(p_out)):
        raise InputError(f"p_in and p_out must be finite (Pa), got {p_in!r}, {p_out!r}")
    u = np.asarray(wall_velocity, dtype=float).reshape(-1)
    if u.size != 2 or not np.all(np.isfinite(u)):
        raise InputError(f"wall_velocity must be two finite numbers (m/s), got {wall_velocity!r}")
    ul, ut = u
    if direction == "y":                       # work with the flow along axis 0
        g, dx, dy, ul, ut = g.T, dy, dx, ut, ul
    dl, dt = dx, dy
    nl, nt = g.shape
    n = nl * nt
    k = g**3 / (12.0 * mu)
    is_open = g > 0
    wrap = periodic and nt > 1

    lab, t_in_lab, t_out_lab = components_reaching(is_open, periodic=periodic)
    live = np.zeros(lab.size, bool).reshape(nl, nt)
    ok = lab >= 0
    live[ok] = (t_in_lab | t_out_lab)[lab[ok]]
    percolates = bool((t_in_lab & t_out_lab).any())

    # face transmissibilities (m^3/(Pa s)) and Couette face flows (m^3/s, along +axis)
    both_l = is_open[:-1] & is_open[1:]
    T_l = dt / dl * _harmonic(k[:-1], k[1:])
    C_l = np.where(both_l, 0.25 * (g[:-1] + g[1:]) * ul * dt, 0.0)
    gt_a, gt_b = (g, np.roll(g, -1, axis=1)) if wrap else (g[:, :-1], g[:, 1:])
    kt_a, kt_b = (k, np.roll(k, -1, axis=1)) if wrap else (k[:, :-1], k[:, 1:])
    T_t = dl / dt * _harmonic(kt_a, kt_b)
    C_t = np.where((gt_a > 0) & (gt_b > 0), 0.25 * (gt_a + gt_b) * ut * dl, 0.0)
    T_in = dt / (0.5 * dl) * k[0]
    T_out = dt / (0.5 * dl) * k[-1]
    C_in = 0.5 * g[0] * ul * dt
    C_out = 0.5 * g[-1] * ul * dt

    idx = np.arange(n).reshape(nl, nt)
    ia_c = np.concatenate([idx[:-1].ravel(), idx[:, :T_t.shape[1]].ravel()])
    ib_c = np.concatenate([idx[1:].ravel(),
                           (np.roll(idx, -1, axis=1) if wrap else idx[:, 1:]).ravel()])
    T = np.concatenate([T_l.ravel(), T_t.ravel()])
    C = np.concatenate([C_l.ravel(), C_t.ravel()])
    lv = live.ravel()
    C = np.where(lv[ia_c], C, 0.0)            # C != 0 only inside one open component
    keep = (T > 0) & lv[ia_c]                 # faces inside a live component
    ia, ib, T = ia_c[keep], ib_c[keep], T[keep]

    # (float: bincount of an empty weight array is integer)
    diag = np.bincount(ia, T, n) + np.bincount(ib, T, n) + 0.0
    diag[idx[0]] += T_in
    diag[idx[-1]] += T_out
    rhs = np.bincount(ib_c, C, n) - np.bincount(ia_c, C, n) + 0.0
    rhs[idx[0]] += T_in * p_in + C_in
    rhs[idx[-1]] += T_out * p_out - C_out
    dead = ~lv
    diag[dead] = 1.0
    rhs[dead] = 0.0

    p = np.zeros(n)
    nit, success, message = 0, True, "nothing to solve: no open cell reaches inlet or outlet"
    if lv.any():
        A = sp.csr_matrix((np.concatenate([diag, -T, -T]),
                           (np.concatenate([np.arange(n), ia, ib]),
                            np.concatenate([np.arange(n), ib, ia]))), shape=(n, n))
        p, nit, success, message = ksp_solve(A, rhs, name="reynolds_fv", options=petsc_options)
        del A
    p = np.where(lv, p, 0.0).reshape(nl, nt)
    if not success:
        raise NoConvergenceError(f"Reynolds finite-volume solve: {message}")

    # face flows (m^3/s, along +axis) and the inlet/outlet balance
    F_l = T_l * (p[:-1] - p[1:]) + C_l
    F_l = np.where(live[:-1] & live[1:], F_l, 0.0)
    pt_b = np.roll(p, -1, axis=1) if wrap else p[:, 1:]
    F_t = T_t * (p[:, :T_t.shape[1]] - pt_b) + C_t
    lt_b = np.roll(live, -1, axis=1) if wrap else live[:, 1:]
    F_t = np.where(live[:, :T_t.shape[1]] & lt_b, F_t, 0.0)
    F_in = np.where(live[0], T_in * (p_in - p[0]) + C_in, 0.0)
    F_out = np.where(live[-1], T_out * (p[-1] - p_out) + C_out, 0.0)
    q_in, q_out = float(F_in.sum()), float(F_out.sum())
    leak = 0.5 * (q_in + q_out)
    if not percolates and ul == 0.0:
        leak = 0.0                            # no open path: no through-flow, exactly

    # cell-centre flux per unit width: mean of the two opposite face flows
    fl = np.concatenate([F_in[None], F_l, F_out[None]], axis=0)
    q_l = 0.5 * (fl[:-1] + fl[1:]) / dt
    if wrap:
        ft = np.concatenate([np.roll(F_t, 1, axis=1)[:, :, None], F_t[:, :, None]], axis=2)
        q_t = 0.5 * ft.sum(axis=2) / dl
    else:
        z = np.zeros((nl, 1))
        ft = np.concatenate([z, F_t, z], axis=1)
        q_t = 0.5 * (ft[:, :-1] + ft[:, 1:]) / dl
    pressure = np.where(live, p, np.nan)
    flux = np.stack([q_l, q_t], axis=-1)
    if direction == "y":
        pressure, live = pressure.T, live.T
        flux = np.stack([q_t.T, q_l.T], axis=-1)
    return FVSolution(pressure=np.ascontiguousarray(pressure), flux=np.ascontiguousarray(flux),
                      connected=np.ascontiguousarray(live), inlet_flow=q_in,
                      outlet_flow=q_out, leak_rate=float(leak), percolates=percolates,
                      success=bool(success), message=message, nit=int(nit))


def finite_volume_leak_rate(gap, spacing, *, direction: str = "x", mu: float = 1e-3,
                            pressure_drop: float = 1.0, periodic: bool = False) -> float:
    """Leak rate ``Q`` (m^3/s) of Eq. 2.12 by cell-centred finite volumes (shortcut).

    ``pressure_drop = p_in - p_out`` in Pa (> 0); see :func:`solve_reynolds_fv`.
    """
    dp = check_finite_positive("pressure_drop", pressure_drop)
    return solve_reynolds_fv(gap, spacing, direction=direction, mu=mu, p_in=dp, p_out=0.0,
                             periodic=periodic).leak_rate
