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
* the Couette term ``h U / 2`` of Eq. 2.11 crosses a face between two open cells with
  the gap of their two half-cells in series, ``(h_a^-2 + h_b^-2) / (h_a^-3 + h_b^-3)``
  (:func:`_series_gap`; exact for strips in series), a boundary face with the gap of its
  cell.

Cells are *connected* (live) when they belong to a face-connected open component that
reaches the inlet or the outlet (components labelled by ``scipy.ndimage.label``, merged
across the periodic seam); the pressure of every other open cell (pockets ringed by
contact: trapped fluid) is not determined by the inlet/outlet data and is NaN. Only the
live cells are unknowns: closed cells and pockets never enter the linear system (at high
A* most of the grid); without wall motion neither do the components reaching one side
only, which carry no flow: their pressure is p_in or p_out exactly. (Near the threshold
they hang reservoirs on a side through junctions ~1e17 times weaker, below the round-off
of a diagonal: BoomerAMG then broke down, DIVERGED_INDEFINITE_PC/MAT.) The unknown is ``p - p_out``, so the solver tolerance is relative to
the pressure drop (and the Couette flow), never to the absolute pressure level. The
symmetric positive definite system is assembled with array operations straight into CSR
(no loop over cells, no COO duplicates) and solved with CG + BoomerAMG (PETSc, through
:class:`roughfe.fem.petsc_tools.KrylovSolver`, options :data:`REYNOLDS_FV`; a sequence of
solves on one grid can keep the AMG hierarchy, :func:`reynolds_fv_solver`). ``percolates`` is
True when one open component touches both inlet and outlet: by construction the same
verdict as the free-volume network with ``corner_rule="closed"``
(:func:`roughfe.leakage.network.free_volume_network`).

Without wall motion the leak rate is the viscous dissipation over the drop,
``Q = sum_faces T (x_a - x_b)^2 / (p_in - p_out)`` (``x = p - p_out``, the boundary faces
included; summing the cell balances, it equals the inlet and the outlet flow of the
discrete solution): no term cancels another, and its error is second order in the
solver's, an upper bound ~ rtol^2 R with ``R = sum(T_in) (p_in - p_out) / Q``. Where
rtol R > 1 the solve goes on from its answer to rtol sqrt(rtol / R) (not below
:data:`~roughfe.fem.dissipation.RTOL_FLOOR`; :mod:`roughfe.fem.dissipation`, the
continuation of both schemes). The boundary flows are computed from ``x`` too, but
across each inlet face ``p_in - p`` is ~1/R of the drop, round-off once R nears 1e16:
near the percolation threshold, where the open reservoirs conduct ``(h / u_c)^3`` ~ 1e8-1e15 times
more than the junction (a 64^2 pinhole wall of gap 1e-11 m: inlet flow -3.6e-30, exact Q
8.3e-32 m^3/s; :attr:`roughfe.leakage.reynolds.ReynoldsResult.flow_imbalance`). With wall
motion the leak rate is the mean of the inlet and outlet flows, and that floor is its
own. Without percolation and wall motion along the flow it is exactly 0. The CG
tolerance stays rtol 1e-10: on 512^2 gaps (A* = 0.15-0.40) rtol 1e-8 saves 2 of 11-14
iterations, but near the percolation threshold it left an in/out imbalance of 2.3e-6 (the
leakage-study records of tests/test_leakage_study.py).
Consistency: the scheme is exact for parallel plates and for strips in series and in
parallel, and second-order convergent on smooth gap fields (tests; the Q1 finite
elements of :mod:`roughfe.fem.reynolds` converge to the same limit).
"""
from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Mapping, Optional

import numpy as np

from ..errors import (InputError, NoConvergenceError, check_finite_positive, check_memory,
                      check_real_array)
from ..fem.dissipation import solve_for_dissipation
from ..fem.petsc_tools import CG_AMG, KrylovSolver, petsc_aij_csr
from ..fem.reynolds import check_reynolds_data
from .components import components_reaching

#: lower bounds of the peak memory of a solve (bytes per cell of the gap and per
#: unknown: the CSR system and BoomerAMG's hierarchy): ru_maxrss at 2048^2 rose by 364
#: and 291 bytes per cell with 85 % and 60 % of the cells open, i.e. ~118 per cell +
#: ~288 per unknown (round 2, session 38); checked once the unknowns are known, so that
#: a gap beyond the machine is an InputError, not the OOM killer
REYNOLDS_BYTES_PER_CELL, REYNOLDS_BYTES_PER_UNKNOWN = 100, 250

#: PETSc options of the finite-volume Reynolds solve, over
#: :data:`roughfe.fem.petsc_tools.CG_AMG` (CG + BoomerAMG, rtol 1e-10 of the preconditioned
#: residual): one forward Gauss-Seidel sweep down and one backward sweep up (a symmetric
#: V-cycle, as CG needs) over all points instead of hypre's default symmetric sweeps with C/F
#: ordering. Measured at 1024^2 (A* = 0.15, back to back): set-up + solve 1.7-1.8 s CPU
#: instead of 2.5-2.6 s, 11 CG iterations instead of 10, the same leak rate to 1e-10.
REYNOLDS_FV = {"pc_hypre_boomeramg_relax_type_down": "SOR/Jacobi",
               "pc_hypre_boomeramg_relax_type_up": "backward-SOR/Jacobi",
               "pc_hypre_boomeramg_no_CF": None}


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
        Volume flow in through the inlet and out through the outlet (m^3/s), from
        ``p - p_out``; near the percolation threshold the larger-conductance side is
        round-off (module docstring).
    leak_rate : float
        Viscous dissipation over the drop without wall motion, else the mean of the two
        (0 exactly without percolation and wall motion along the flow).
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


def _harmonic(a, b, scale, live, out=None):
    """``scale * 2ab / (a + b)`` where ``live``, else 0 (0 also where ``a + b = 0``)."""
    t = np.multiply(a, b, out=out)
    t *= 2.0 * scale
    s = np.add(a, b)
    np.divide(t, s, out=t, where=s > 0)
    t *= live
    return t


def _series_gap(a, b, live):
    """The gap (m) that carries the Couette flow U/2 h across the face between two open
    cells of gaps ``a`` and ``b`` where ``live`` (else 0): the two half-cells in series,
    as the pressure term's harmonic transmissibility. Each half-cell passes
    q = (k / (dl/2)) dp_half + (U/2) h with k = h^3 / (12 mu); eliminating the face
    pressure gives q = T (p_a - p_b) + (U/2) (h_a/k_a + h_b/k_b) / (1/k_a + 1/k_b), i.e.
    the gap (a^-2 + b^-2) / (a^-3 + b^-3): a for a = b, and exact for strips in series
    (the arithmetic mean of the two gaps was first-order wrong on a gap that jumps)."""
    ok = (a > 0) & (b > 0) & live
    with np.errstate(divide="ignore", invalid="ignore"):
        ia, ib = 1.0 / a, 1.0 / b
        h = (ia * ia + ib * ib) / (ia * ia * ia + ib * ib * ib)
    return np.where(ok, h, 0.0)


def solve_reynolds_fv(gap, spacing, *, direction: str = "x", mu: float = 1e-3,
                      p_in: float = 1.0, p_out: float = 0.0, periodic: bool = False,
                      wall_velocity=(0.0, 0.0),
                      petsc_options: Optional[Mapping] = None,
                      initial=None, solver: Optional[KrylovSolver] = None) -> FVSolution:
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
    initial : ndarray, shape (nx, ny), optional
        A pressure field (Pa) to start the CG from, e.g. the previous solution of a
        fluid-structure coupling loop (:func:`roughfe.leakage.fsi.coupled_leakage`) on a
        slightly different gap; NaN (pockets, closed cells) and cells that were not live
        start at ``p_out``. The answer is the same to the solver tolerance (it is
        relative to the right-hand side, not to the start): only the iteration count
        changes.
    solver : KrylovSolver, optional
        A solver kept across calls (:func:`reynolds_fv_solver`; not with
        ``petsc_options``): it reuses its AMG hierarchy while the live system keeps its
        sparsity pattern, same tolerance. Default: a fresh CG + BoomerAMG solve.

    Returns
    -------
    FVSolution
    """
    g, (dx, dy), mu, (ul, ut) = check_reynolds_data(gap, spacing, mu, p_in, p_out,
                                                     direction, wall_velocity)
    if solver is not None and petsc_options:
        raise InputError("give petsc_options to reynolds_fv_solver, not beside a solver")
    if initial is not None:
        initial = check_real_array("initial pressure", initial, unit="Pa", allow_nan=True)
        if initial.shape != g.shape:
            raise InputError(f"initial pressure has shape {initial.shape}, the gap {g.shape}")
    if direction == "y":                       # work with the flow along axis 0
        g, dx, dy, ul, ut = g.T, dy, dx, ut, ul
        initial = None if initial is None else initial.T
    dl, dt = dx, dy
    nl, nt = g.shape
    k = np.multiply(g, g)
    k *= g
    k /= 12.0 * mu
    is_open = g > 0
    wrap = periodic and nt > 1

    lab, t_in_lab, t_out_lab = components_reaching(is_open, periodic=periodic)
    live = np.append(t_in_lab | t_out_lab, False)[lab]      # label -1 (closed): False
    percolates = bool((t_in_lab & t_out_lab).any())
    # without wall motion a component reaching one side only carries no flow: p = p_in
    # (inlet) or p_out exactly, no unknown (module docstring); `solve` masks the system
    inlet_only = None
    solve = live
    if ul == 0.0 and ut == 0.0:
        solve = np.append(t_in_lab & t_out_lab, False)[lab]
        inlet_only = np.append(t_in_lab & ~t_out_lab, False)[lab]
    del lab
    unknowns = int(np.count_nonzero(solve))
    check_memory(f"the Reynolds solve of a {nl} x {nt} gap ({unknowns} unknowns)",
                 REYNOLDS_BYTES_PER_CELL * float(g.size)
                 + REYNOLDS_BYTES_PER_UNKNOWN * float(unknowns))

    # face transmissibilities (m^3/(Pa s)); T_t[:, j] joins columns j and j + 1 (with wrap,
    # the last column is the seam face); faces outside the live components carry nothing
    T_l = _harmonic(k[:-1], k[1:], dt / dl, solve[:-1])
    T_t = np.empty((nl, nt if wrap else nt - 1))
    _harmonic(k[:, :-1], k[:, 1:], dl / dt, solve[:, :-1], out=T_t[:, :nt - 1])
    if wrap:
        _harmonic(k[:, -1:], k[:, :1], dl / dt, solve[:, -1:], out=T_t[:, -1:])
    # Couette face flows (m^3/s, along +axis; None without wall motion along that axis)
    C_l = C_t = None
    if ul:
        C_l = _series_gap(g[:-1], g[1:], live[:-1]) * (0.5 * ul * dt)
    if ut:
        gt_b = np.roll(g, -1, axis=1) if wrap else g[:, 1:]
        gt_a = g if wrap else g[:, :-1]
        C_t = _series_gap(gt_a, gt_b, live if wrap else live[:, :-1]) * (0.5 * ut * dl)
    if wrap and nt == 2:                       # the wrap face joins the same two cells
        T_t, wrap = T_t[:, :1] + T_t[:, 1:], False
        if C_t is not None:
            C_t = C_t[:, :1] - C_t[:, 1:]
    T_in = dt / (0.5 * dl) * k[0] * solve[0]
    T_out = dt / (0.5 * dl) * k[-1] * solve[-1]
    del k
    C_in = 0.5 * g[0] * ul * dt * live[0]
    C_out = 0.5 * g[-1] * ul * dt * live[-1]

    # right-hand side: boundary pressures and the net Couette inflow of each cell;
    # unknown: p - p_out (every row of the operator applied to a constant gives its boundary
    # transmissibility), so the solver tolerance is relative to the drop p_in - p_out and
    # the Couette flow, not to the absolute pressure level
    rhs = np.zeros((nl, nt))
    rhs[0] += T_in * (p_in - p_out) + C_in
    rhs[-1] -= C_out
    if C_l is not None:
        rhs[:-1] -= C_l
        rhs[1:] += C_l
    if C_t is not None:
        rhs[:, :C_t.shape[1]] -= C_t
        rhs[:, 1:] += C_t[:, :nt - 1]
        if wrap:
            rhs[:, 0] += C_t[:, -1]

    # unknowns on the `solve` cells only: closed cells and pockets do not enter the system;
    # a dissipation leak rate (energy) goes on to rtol sqrt(rtol / R) (module docstring)
    drop = p_in - p_out
    energy = percolates and ul == 0.0 and ut == 0.0 and drop != 0.0
    nit, success, message = 0, True, ("nothing to solve: no open component reaches both "
                                      "inlet and outlet")
    flows = functools.partial(_pressure_flows, live=solve, T_l=T_l, T_t=T_t, T_in=T_in,
                              T_out=T_out, drop=drop, wrap=wrap, out=rhs)
    if solve.any():
        M = _live_system(T_l, T_t, _diagonal(T_l, T_t, T_in, T_out, wrap), solve, wrap)
        x0 = None
        if initial is not None:                # unknown p - p_out; NaN (pockets) -> 0
            x0 = initial[solve] - p_out
            x0[~np.isfinite(x0)] = 0.0
        one_shot = solver is None
        if one_shot:
            solver = reynolds_fv_solver(petsc_options, reuse=False)
        try:
            _, nit, success, message, power, (x_grid, fl, ft) = solve_for_dissipation(
                solver, M, rhs[solve], x0, own=True, evaluate=flows,
                scale=drop * drop * float(T_in.sum()) if energy else None)
        finally:
            if one_shot:
                solver.close()
    else:
        power, (x_grid, fl, ft) = flows(np.zeros(0))
    if not success:
        raise NoConvergenceError(f"Reynolds finite-volume solve: {message}")
    # Couette face flows on top of the pressure-driven ones
    fl[0] += C_in
    fl[-1] += C_out
    if C_l is not None:
        fl[1:-1] += C_l
    if C_t is not None:
        ft[:, 1:C_t.shape[1] + 1] += C_t
    if wrap:
        ft[:, 0] = ft[:, -1]
    q_in, q_out = float(fl[0].sum()), float(fl[-1].sum())
    if not percolates and ul == 0.0:
        leak = 0.0                             # no open path: no through-flow, exactly
    elif energy:
        leak = power / drop                    # Q dp = sum T (x_a - x_b)^2: no cancellation
    else:
        leak = 0.5 * (q_in + q_out)            # wall motion: the mean of the boundary flows
    p = x_grid
    if inlet_only is not None:
        p[inlet_only] = drop
    p += p_out

    # cell-centre flux per unit width: mean of the two opposite face flows
    flux = np.empty((nl, nt, 2))
    np.add(fl[:-1], fl[1:], out=flux[..., 0])
    flux[..., 0] *= 0.5 / dt
    del fl
    np.add(ft[:, :-1], ft[:, 1:], out=flux[..., 1])
    flux[..., 1] *= 0.5 / dl
    del ft
    p[~live] = np.nan
    if direction == "y":
        p, live, flux = p.T, live.T, flux.transpose(1, 0, 2)[..., ::-1]
    return FVSolution(pressure=np.ascontiguousarray(p), flux=np.ascontiguousarray(flux),
                      connected=np.ascontiguousarray(live), inlet_flow=q_in,
                      outlet_flow=q_out, leak_rate=float(leak), percolates=percolates,
                      success=bool(success), message=message, nit=int(nit))


def reynolds_fv_solver(petsc_options: Optional[Mapping] = None, *,
                       reuse: bool = True) -> KrylovSolver:
    """The CG + BoomerAMG solver of :func:`solve_reynolds_fv` (:data:`REYNOLDS_FV` with
    ``petsc_options`` over it), to keep across a sequence of solves (``solver=``).

    With ``reuse`` the AMG hierarchy is built once and kept while the live system keeps
    its sparsity pattern (e.g. the regularised gaps of a coupling loop, every cell live):
    CG then runs on each new matrix to the same tolerance, preconditioned by the kept
    hierarchy, and builds a fresh one when a solve stalls
    (:class:`roughfe.fem.petsc_tools.KrylovSolver`). Close it after use (a context
    manager).
    """
    return KrylovSolver("reynolds_fv", petsc_options, reuse_preconditioner=reuse,
                        defaults={**CG_AMG, **REYNOLDS_FV})


def _pressure_flows(x, live, T_l, T_t, T_in, T_out, drop, wrap, *, out):
    """Pressure-driven face flows (m^3/s, along +axis) from the live unknowns
    ``x = p - p_out`` itself (p_out is added to the pressure only afterwards: near the
    percolation threshold the drop across an outlet face is far below the round-off of an
    absolute pressure). Returns ``(power, (x_grid, fl, ft))``: ``x`` on the grid ``out``
    (0 outside the live cells); ``fl[i]`` enters row i (``fl[0]`` inlet, ``fl[-1]``
    outlet), ``ft[:, j]`` column j (``ft[:, 0]``, ``ft[:, -1]``: the seam face, or a wall:
    0); ``power = sum T (x_a - x_b)^2`` over every face (W), the viscous dissipation."""
    nl, nt = live.shape
    out.fill(0.0)
    out[live] = x
    fl = np.empty((nl + 1, nt))
    ft = np.zeros((nl, nt + 1))
    power = sum(_face_flows(a, b, T, f) for a, b, T, f in (
        (out[:-1], out[1:], T_l, fl[1:-1]), (drop, out[0], T_in, fl[0]),
        (out[-1], 0.0, T_out, fl[-1]), (out[:, :-1], out[:, 1:], T_t[:, :nt - 1], ft[:, 1:-1]))
        + (((out[:, -1], out[:, 0], T_t[:, -1], ft[:, -1]),) if wrap else ()))
    return power, (out, fl, ft)


def _face_flows(x_a, x_b, T, out) -> float:
    """Flows ``T (x_a - x_b)`` (m^3/s) into ``out``; returns ``sum T (x_a - x_b)^2`` (W)."""
    np.subtract(x_a, x_b, out=out)
    ij = "ij"[:out.ndim]
    power = float(np.einsum(f"{ij},{ij},{ij}->", T, out, out))   # no temporary
    out *= T
    return power


def _diagonal(T_l, T_t, T_in, T_out, wrap):
    """Diagonal of the 5-point operator: the sum of the face transmissibilities of every
    cell (its mass balance), the inlet/outlet faces included (shapes as in
    :func:`_live_system`)."""
    nl = T_l.shape[0] + 1
    nt = T_t.shape[1] + (0 if wrap else 1)
    diag = np.zeros((nl, nt))
    diag[:-1] += T_l
    diag[1:] += T_l
    diag[:, :T_t.shape[1]] += T_t
    diag[:, 1:] += T_t[:, :nt - 1]
    if wrap:
        diag[:, 0] += T_t[:, -1]
    diag[0] += T_in
    diag[-1] += T_out
    return diag


def _live_system(T_l, T_t, diag, live, wrap):
    """The 5-point operator on the live cells as a PETSc AIJ matrix (row-major numbering;
    32-bit indices: up to 2^31 entries).

    ``T_l`` (nl-1, nt) and ``T_t`` (nl, nt-1; (nl, nt) with ``wrap``, the last column being
    the seam face) are the face transmissibilities, 0 on faces without flow; only faces with
    ``T > 0`` give an off-diagonal entry. The CSR arrays are filled slot by slot in column
    order (no COO intermediate, no (n, 5) temporaries: 4096^2 grids stay lean) and handed to
    PETSc without a copy.
    """
    nl, nt = live.shape
    itype = np.int32
    m = int(np.count_nonzero(live))
    num = np.full((nl, nt), -1, dtype=itype)
    num[live] = np.arange(m, dtype=itype)
    inner = T_t[:, :nt - 1]
    every, head, tail = slice(None), slice(None, -1), slice(1, None)
    # (cells, their neighbours, weight, sign) per slot, in the column order of every row:
    # the seam neighbours of the last and first column come where their numbers fall
    slots = [((tail, every), (head, every), T_l, -1.0),
             ((every, tail), (every, head), inner, -1.0),
             ((every, every), (every, every), diag, 1.0),
             ((every, head), (every, tail), inner, -1.0),
             ((head, every), (tail, every), T_l, -1.0)]
    if wrap:
        first, last = slice(0, 1), slice(nt - 1, None)
        seam = T_t[:, last]
        slots.insert(1, ((every, last), (every, first), seam, -1.0))
        slots.insert(5, ((every, first), (every, last), seam, -1.0))
    masks = [live if sign > 0 else w > 0 for _, _, w, sign in slots]
    # CSR row pointers from the entry count of every live cell, then each slot's entries
    # go to the next free position of their row (cursor: full grid, one pass per slot)
    cursor = np.zeros((nl, nt), dtype=itype)
    for (cells, _, _, _), mask in zip(slots, masks):
        cursor[cells] += mask
    indptr = np.zeros(m + 1, dtype=itype)
    np.cumsum(cursor[live], out=indptr[1:])
    cursor[live] = indptr[:-1]
    nnz = int(indptr[-1])
    indices = np.empty(nnz, dtype=itype)
    data = np.empty(nnz)
    for (cells, nbrs, w, sign), mask in zip(slots, masks):
        pos = cursor[cells][mask]
        indices[pos] = num[nbrs][mask]
        vals = w[mask]
        data[pos] = vals if sign > 0 else np.negative(vals, out=vals)
        cursor[cells] += mask
    return petsc_aij_csr((m, m), indptr, indices, data)


def finite_volume_leak_rate(gap, spacing, *, direction: str = "x", mu: float = 1e-3,
                            pressure_drop: float = 1.0, periodic: bool = False) -> float:
    """Leak rate ``Q`` (m^3/s) of Eq. 2.12 by cell-centred finite volumes (shortcut).

    ``pressure_drop = p_in - p_out`` in Pa (> 0); see :func:`solve_reynolds_fv`. Solved at
    a unit drop and viscosity and scaled (:func:`roughfe.leakage.reynolds.scaled_reynolds_fv`:
    mu = 1e308 Pa s gave 0.0, a drop of 1e300 Pa inf).
    """
    from .reynolds import scaled_reynolds_fv      # reynolds imports this module
    dp = check_finite_positive("pressure_drop", pressure_drop)
    return scaled_reynolds_fv(gap, spacing, direction=direction, mu=mu, p_in=dp, p_out=0.0,
                              periodic=periodic).leak_rate
