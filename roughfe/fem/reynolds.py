"""Reynolds thin-film flow on a gap field with dolfinx (thesis Sec. 2.3.2, Eq. 2.10-2.12).

The steady, incompressible Reynolds equation for the volume flux per unit width
``q = h U / 2 - h^3/(12 mu) grad p`` (Eq. 2.11 divided by the constant density) and
mass conservation ``div q = 0`` (Eq. 2.10) give (Eq. 2.12)::

    div( h^3/(12 mu) grad p ) = div( h U / 2 )      on  [0, Lx] x [0, Ly]

Weak form, for every test function ``v`` that vanishes on the inlet and outlet::

    int h^3/(12 mu) grad p . grad v dx  =  int (h/2) U . grad v dx

(the remaining boundary term is the normal flux ``q.n``, zero on the two side walls:
no-flux, or periodic when asked).

Discretisation
--------------
* A quadrilateral mesh with one cell per grid sample of the gap field (the BEM grid:
  sample ``gap[i, j]`` is the cell ``[i dx, (i+1) dx] x [j dy, (j+1) dy]``), the gap
  ``h`` constant per cell (DG0) and the pressure ``p`` in Q1 (one value per cell corner,
  ``(nx+1) x (ny+1)`` vertices).
* ``p = p_in`` on the inlet side, ``p = p_out`` on the outlet side (``x = 0`` and
  ``x = Lx`` for ``direction="x"``; ``y = 0`` and ``y = Ly`` for ``"y"``).
* Cells in contact have ``h = 0``: vertices that touch no open cell, and whole pockets
  of open cells that reach neither inlet nor outlet, make the matrix singular (one
  constant null vector per such component). Each such component is found by
  connected-component labelling of the vertex graph (open cells join their four
  corners) and one vertex of it is pinned; its pressure is then undetermined by the
  boundary data and is returned as NaN. No artificial minimum gap is used (``h_min``
  is an option: it biases the flux).
* Periodic side walls are imposed algebraically: the vertices of the last row are
  identified with the first one through a restriction matrix ``P`` (``K_r = P^T K P``),
  which also removes the Dirichlet and pinned unknowns. The reduced matrix is SPD; it
  is solved with CG + BoomerAMG (hypre) by default.
* The unknown is ``x = p - p_out`` (``K`` annihilates constants; the Dirichlet lift is
  ``p_in - p_out`` on the inlet, 0 on the outlet), ``p_out`` is added afterwards.
* Leak rate without wall motion: the viscous dissipation over the drop,
  ``Q = x^T K x / (p_in - p_out) = int h^3/(12 mu) |grad x|^2 dx / (p_in - p_out)``
  (m^3/s), summed cell by cell from nodal differences (:func:`q1_dissipation`). For the
  discrete solution it equals the consistent (weak-form) flux ``w . r`` (``r = K x - b``
  the full residual, ``w`` linear from 1 on the inlet to 0 on the outlet) and the inlet
  sum of ``r``, but no term cancels another: near the percolation threshold ``K x`` at an
  inlet vertex of a large open reservoir is a difference far below the round-off of the
  drop (a 64^2 wall closed but for one pinhole cell of gap 1e-11 m, dp = 1 Pa: ``w . r``
  gave -2.8e-28 m^3/s for 8.3e-32). Its error is second order in the solver's; where
  that is not enough the CG goes on to a tighter tolerance (:mod:`roughfe.fem.dissipation`,
  shared with the finite volumes). With wall motion ``Q = w . r`` (from ``x``); the inlet
  and outlet sums of ``r`` are returned too (near the percolation threshold the one by
  the large reservoir is round-off).

Cells should be (nearly) square, as BEM grids are: for an aspect ratio above sqrt(2)
the Q1 stiffness has positive off-diagonal entries, and the discrete pressure may then
overshoot [p_out, p_in] slightly on rough gaps (measured: -3e-4 dp at aspect 1.5).

Note: with Q1 pressure, two open cells that touch only at a corner share a pressure
unknown and exchange flux through that vertex. The network analysis of
:mod:`roughfe.leakage.network` uses the saddle-point rule instead (thesis Fig. 13);
the two may disagree on whether a gap field percolates.

The mesh, function spaces and compiled forms are cached per grid (shape and size), so
a sweep over loads on one surface builds them once. dolfinx runs here on
``MPI.COMM_SELF`` (one process per solve; parallelism is over tasks).
"""
from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Mapping, Optional

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from ..errors import (InputError, NoConvergenceError, check_finite_nonnegative,
                      check_finite_positive, check_real_array, check_spacing)
from .dissipation import solve_for_dissipation
from .petsc_tools import CG_AMG, KrylovSolver, ensure_jit_cache, petsc_aij

DEFAULT_PETSC_OPTIONS = CG_AMG


@dataclass(frozen=True, eq=False)
class ReynoldsFESolution:
    """Raw finite-element solution of the Reynolds equation on a grid.

    Attributes
    ----------
    pressure : ndarray, shape (nx+1, ny+1)
        Q1 nodal pressure in Pa at the cell corners (axis 0 = x). NaN where the pressure
        is not determined by the inlet/outlet data (inside contact and trapped pockets).
    pressure_pinned : ndarray, shape (nx+1, ny+1)
        The same with the pinned values kept (finite everywhere), for flux evaluation.
    connected : ndarray of bool, shape (nx+1, ny+1)
        Vertices connected to the inlet or the outlet through open cells.
    residual : ndarray, shape (nx+1, ny+1)
        Nodal flux residual ``K (p - p_out) - b`` in m^3/s (non-zero on inlet/outlet
        only, up to the solver tolerance).
    flow_rate : float
        Leak rate ``Q`` in m^3/s (positive from inlet to outlet): the viscous dissipation
        over the drop without wall motion, the consistent flux ``w . r`` with it (module
        docstring); exactly 0 when inlet and outlet are not connected and there is no
        wall velocity.
    inlet_flow, outlet_flow : float
        Flow in through the inlet and out through the outlet (m^3/s).
    percolates : bool
        Whether the inlet and outlet are connected through open cells with Q1 (corner)
        conduction.
    success, message, nit : bool, str, int
        Solver status (scipy OptimizeResult-like); ``nit`` is the number of Krylov
        iterations (0 when there was nothing to solve).
    """

    pressure: np.ndarray
    pressure_pinned: np.ndarray
    connected: np.ndarray
    residual: np.ndarray
    flow_rate: float
    inlet_flow: float
    outlet_flow: float
    percolates: bool
    success: bool
    message: str
    nit: int


def _serial_partitioner(comm, nparts, tdim, cells, ghost_mode):
    from dolfinx import cpp
    return cpp.graph.AdjacencyList_int32(np.zeros(cells.num_nodes, dtype=np.int32))


@dataclass(frozen=True, eq=False)
class _Grid:
    """The immutable part of one grid, cached: mesh, spaces and index maps."""

    mesh: object
    V: object                   # Q1 pressure space
    W: object                   # DG0 gap space
    dof_of_vertex: np.ndarray   # (nx+1)*(ny+1) structured vertex -> Q1 dof (read-only)
    dof_of_cell: np.ndarray     # nx*ny structured cell -> DG0 dof (read-only)


@dataclass(frozen=True, eq=False)
class _GridSpace:
    """One solve's dolfinx/PETSc objects on a cached :class:`_Grid` (built per call: the
    coefficients and the matrix are mutated by the solve, so they are never shared)."""

    grid: _Grid
    h: object          # DG0 Function: gap (m)
    mu: object         # Constant: viscosity (Pa s)
    velocity: object   # Constant vector: wall velocity (m/s)
    a: object          # compiled stiffness form
    L: object          # compiled Couette load form
    K: object          # PETSc matrix with the sparsity of ``a``; destroy after use

    @property
    def dof_of_vertex(self):
        return self.grid.dof_of_vertex

    @property
    def dof_of_cell(self):
        return self.grid.dof_of_cell


@functools.lru_cache(maxsize=2)
def _grid(nx: int, ny: int, lx: float, ly: float) -> _Grid:
    """Mesh, spaces and index maps of an nx x ny grid (no PETSc object, nothing a solve
    mutates; the index maps are O(nx ny) integers)."""
    ensure_jit_cache()      # before dolfinx: a writable JIT cache, warnings not in logging
    from mpi4py import MPI
    from dolfinx import fem, mesh

    msh = mesh.create_rectangle(
        MPI.COMM_SELF, [np.array([0.0, 0.0]), np.array([lx, ly])], [nx, ny],
        mesh.CellType.quadrilateral, mesh.GhostMode.none, _serial_partitioner)
    V = fem.FunctionSpace(msh, ("Lagrange", 1))
    W = fem.FunctionSpace(msh, ("DG", 0))
    dx, dy = lx / nx, ly / ny
    xv = V.tabulate_dof_coordinates()
    iv = np.rint(xv[:, 0] / dx).astype(np.int64)
    jv = np.rint(xv[:, 1] / dy).astype(np.int64)
    dof_of_vertex = np.empty((nx + 1) * (ny + 1), dtype=np.int32)
    dof_of_vertex[iv * (ny + 1) + jv] = np.arange(xv.shape[0], dtype=np.int32)
    xc = W.tabulate_dof_coordinates()
    ic = np.floor(xc[:, 0] / dx).astype(np.int64)
    jc = np.floor(xc[:, 1] / dy).astype(np.int64)
    dof_of_cell = np.empty(nx * ny, dtype=np.int32)
    dof_of_cell[ic * ny + jc] = np.arange(xc.shape[0], dtype=np.int32)
    for arr in (dof_of_vertex, dof_of_cell):
        arr.setflags(write=False)
    return _Grid(msh, V, W, dof_of_vertex, dof_of_cell)


def _grid_space(nx: int, ny: int, lx: float, ly: float) -> _GridSpace:
    """Coefficients, forms and matrix of one solve on the cached grid (the forms are
    compiled once, by the dolfinx JIT disk cache). Measured, CPU per solve on random
    gaps: 4.4 -> 6.6 ms on 32^2, 60 -> 65 ms on 128^2 against caching these objects
    too, which shared one mutable matrix and gap Function between all callers."""
    import ufl
    from dolfinx import fem
    import dolfinx.fem.petsc as fem_petsc
    from petsc4py import PETSc

    grid = _grid(nx, ny, lx, ly)
    h = fem.Function(grid.W, name="gap")
    mu = fem.Constant(grid.mesh, PETSc.ScalarType(1.0))
    velocity = fem.Constant(grid.mesh, np.zeros(2, dtype=PETSc.ScalarType))
    p, v = ufl.TrialFunction(grid.V), ufl.TestFunction(grid.V)
    conductance = h**3 / (12.0 * mu)                       # h^3/(12 mu), Eq. 2.11
    a = fem.form(conductance * ufl.inner(ufl.grad(p), ufl.grad(v)) * ufl.dx)
    L = fem.form(0.5 * h * ufl.inner(velocity, ufl.grad(v)) * ufl.dx)   # Couette, Eq. 2.12
    return _GridSpace(grid, h, mu, velocity, a, L, fem_petsc.create_matrix(a))


def vertex_components(open_cells: np.ndarray, *, periodic_axis: Optional[int] = None):
    """Connected components of the Q1 vertex graph of a grid of cells.

    Every open cell joins its four corners (Q1 conduction, including corner-only
    contacts between cells). ``periodic_axis`` identifies the last vertex row along that
    axis with the first.

    Parameters
    ----------
    open_cells : ndarray of bool, shape (nx, ny)
    periodic_axis : {None, 0, 1}

    Returns
    -------
    labels : ndarray of int, shape (nx+1, ny+1)
        Component label of each vertex.
    """
    nx, ny = open_cells.shape
    nv = (nx + 1) * (ny + 1)
    vid = np.arange(nv).reshape(nx + 1, ny + 1)
    o = open_cells
    rows = [vid[:-1, :-1][o], vid[1:, :-1][o], vid[:-1, :-1][o]]
    cols = [vid[1:, 1:][o], vid[:-1, 1:][o], vid[1:, :-1][o]]
    if periodic_axis == 0:
        rows.append(vid[-1, :])
        cols.append(vid[0, :])
    elif periodic_axis == 1:
        rows.append(vid[:, -1])
        cols.append(vid[:, 0])
    r = np.concatenate(rows)
    c = np.concatenate(cols)
    graph = sp.coo_matrix((np.ones(r.size, dtype=np.int8), (r, c)), shape=(nv, nv))
    _, labels = connected_components(graph, directed=False)
    return labels.reshape(nx + 1, ny + 1)


def q1_dissipation(x, conductance, spacing) -> float:
    """Viscous dissipation ``int k |grad x|^2 dA`` of a Q1 field on the grid (W for ``x``
    in Pa): ``x^T K x`` with ``K`` the stiffness of :func:`solve_reynolds_fe`, summed cell
    by cell from nodal differences only (no absolute value enters, so nothing cancels).

    On a ``dx x dy`` cell of conductance ``k``, with ``d0, d1`` the differences of ``x``
    along axis 0 on its two edges at ``y = 0, dy`` and ``e0, e1`` those along axis 1 at
    ``x = 0, dx``, the bilinear field gives exactly
    ``k [(dy/dx) (d0^2 + d0 d1 + d1^2) + (dx/dy) (e0^2 + e0 e1 + e1^2)] / 3``
    (each bracket >= (d0^2 + d1^2) / 2).

    Parameters
    ----------
    x : ndarray, shape (nx+1, ny+1)
        Nodal values (e.g. ``p - p_out``, Pa).
    conductance : ndarray, shape (nx, ny)
        ``k = h^3 / (12 mu)`` per cell (m^3/(Pa s)).
    spacing : (float, float)
        ``(dx, dy)`` in m.
    """
    dx, dy = spacing
    total = 0.0
    for ratio, d, k in ((dy / dx, np.diff(x, axis=0), conductance),
                        (dx / dy, np.diff(x, axis=1).T, conductance.T)):
        d0, d1 = d[:, :-1], d[:, 1:]           # the two opposite edges of each cell
        total += ratio * float(np.sum(k * (d0 * d0 + d0 * d1 + d1 * d1)))
    return total / 3.0


def check_reynolds_data(gap, spacing, mu, p_in, p_out, direction, wall_velocity):
    """The data of the Reynolds problem (Eq. 2.12) as both discretisations take them
    (this Q1 solver and :func:`roughfe.leakage.finite_volume.solve_reynolds_fv`),
    checked once with a clear :class:`~roughfe.errors.InputError` per bad value.

    Returns ``(gap, (dx, dy), mu, u)``: the gap as a float array (nx, ny) in m, finite
    and >= 0; the cell size in m; the viscosity in Pa s; the wall velocity as a float
    array of two components in m/s. ``p_in`` and ``p_out`` (Pa) must be finite and
    ``direction`` one of ``"x"``, ``"y"``.
    """
    gap = check_real_array("gap", gap, 2)     # refuses masked and complex gaps
    if min(gap.shape) < 1:
        raise InputError(f"gap must be a 2D array (nx, ny) of metres, got shape {gap.shape}")
    if gap.min() < 0:
        raise InputError(f"gap must be finite and >= 0 (m), got min {gap.min()!r}")
    if direction not in ("x", "y"):
        raise InputError(f"direction must be 'x' or 'y', got {direction!r}")
    mu = check_finite_positive("mu", mu)
    dx, dy = check_spacing(spacing)
    if not (np.isfinite(p_in) and np.isfinite(p_out)):
        raise InputError(f"p_in and p_out must be finite (Pa), got {p_in!r}, {p_out!r}")
    u = check_real_array("wall_velocity", wall_velocity, unit="m/s").reshape(-1)
    if u.size != 2:
        raise InputError(f"wall_velocity must be two finite numbers (m/s), got {wall_velocity!r}")
    return gap, (dx, dy), mu, u


def solve_reynolds_fe(gap, spacing, *, direction: str = "x", mu: float = 1e-3,
                      p_in: float = 1.0, p_out: float = 0.0, periodic: bool = False,
                      wall_velocity=(0.0, 0.0), h_min: float = 0.0,
                      petsc_options: Optional[Mapping] = None) -> ReynoldsFESolution:
    """Solve the Reynolds equation (Eq. 2.12) on a gap field with Q1 finite elements.

    Parameters
    ----------
    gap : ndarray, shape (nx, ny)
        Local film thickness ``h`` in m per grid cell (>= 0; 0 in contact).
    spacing : (float, float)
        Cell size ``(dx, dy)`` in m.
    direction : {"x", "y"}
        Pressure drop along axis 0 (``"x"``) or axis 1 (``"y"``).
    mu : float
        Dynamic viscosity in Pa s.
    p_in, p_out : float
        Pressures on the inlet (coordinate 0) and outlet (coordinate L) sides, Pa.
    periodic : bool
        Periodic side walls (the two sides parallel to the flow); no-flux otherwise.
    wall_velocity : (float, float)
        Sliding velocity ``U`` of one wall in m/s (Couette term of Eq. 2.11-2.12).
    h_min : float
        Optional minimum gap in m applied to every cell (0: none, the default; a
        positive value makes contact cells conduct and biases the flux).
    petsc_options : mapping, optional
        PETSc options overriding :data:`DEFAULT_PETSC_OPTIONS` (prefix-free keys).

    Returns
    -------
    ReynoldsFESolution
    """
    import dolfinx.fem.petsc as fem_petsc

    gap, (dx, dy), mu, u = check_reynolds_data(gap, spacing, mu, p_in, p_out, direction,
                                               wall_velocity)
    h_min = check_finite_nonnegative("h_min (m)", h_min)

    h = np.maximum(gap, h_min) if h_min > 0 else gap
    nx, ny = h.shape
    axis = 0 if direction == "x" else 1
    space = _grid_space(nx, ny, nx * dx, ny * dy)

    # -- assemble the full (Neumann) matrix and the Couette load -------------------------
    space.h.x.array[space.dof_of_cell] = h.ravel()
    space.mu.value = mu
    space.velocity.value = u
    K = space.K                       # cached sparsity; values re-assembled here
    K.zeroEntries()
    fem_petsc.assemble_matrix(K, space.a)
    K.assemble()
    nv = (nx + 1) * (ny + 1)
    b_dof = np.zeros(nv)
    moving = bool(np.any(u != 0.0))
    if moving:
        bvec = fem_petsc.assemble_vector(space.L)
        b_dof = bvec.array.copy()                            # dolfinx dof order
        bvec.destroy()

    # -- structured bookkeeping: Dirichlet, periodic images, floating components -------
    vshape = (nx + 1, ny + 1)
    coord = np.indices(vshape)[axis]
    n_flow = vshape[axis] - 1
    inlet = (coord == 0).ravel()
    outlet = (coord == n_flow).ravel()
    periodic_axis = 1 - axis if periodic else None
    labels = vertex_components(h > 0, periodic_axis=periodic_axis).ravel()
    live = np.zeros(labels.max() + 1, dtype=bool)
    live[labels[inlet | outlet]] = True
    connected = live[labels]
    percolates = bool(np.intersect1d(labels[inlet], labels[outlet]).size)

    # master vertex of each vertex (periodic images point to the first row)
    master = np.arange(nv).reshape(vshape)
    if periodic_axis == 0:
        master[-1, :] = master[0, :]
    elif periodic_axis == 1:
        master[:, -1] = master[:, 0]
    master = master.ravel()
    fixed = inlet | outlet
    # pin one (master) vertex of each floating component: one constant null vector each
    is_master = master == np.arange(nv)
    floating_masters = np.flatnonzero(~connected & is_master)
    one_per_component = np.full(live.size, -1, dtype=np.int64)
    one_per_component[labels[floating_masters]] = floating_masters
    pinned = np.zeros(nv, dtype=bool)
    pinned[one_per_component[one_per_component >= 0]] = True
    fixed_v = fixed | pinned[master]
    free_master = is_master & ~fixed_v
    n_red = int(free_master.sum())
    red = np.full(nv, -1, dtype=np.int64)
    red[free_master] = np.arange(n_red)
    red_of_vertex = np.where(fixed_v, -1, red[master])
    # restriction P: dof (dolfinx numbering) -> reduced unknown
    dofs = space.dof_of_vertex
    keep = red_of_vertex >= 0
    P = sp.csr_matrix((np.ones(int(keep.sum())), (dofs[keep], red_of_vertex[keep])),
                      shape=(nv, max(n_red, 1)))
    # unknown x = p - p_out (K annihilates constants): the Dirichlet lift is the drop on the
    # inlet, 0 on the outlet and on the pinned vertices (their level is arbitrary)
    drop = p_in - p_out
    lift = np.zeros(nv)
    lift[dofs[inlet]] = drop
    k = h**3 / (12.0 * mu)

    def dissipation(x_dof):
        return q1_dissipation(x_dof[dofs].reshape(vshape), k, (dx, dy)), x_dof

    Kl = K.createVecLeft()
    Kl.setArray(lift)
    Klift = K.createVecLeft()
    K.mult(Kl, Klift)
    rhs_full = b_dof - Klift.array

    nit, success, message = 0, True, "nothing to solve: every pressure unknown is fixed"
    power, x_dof = dissipation(lift)
    if n_red > 0:
        # a dissipation leak rate goes on to rtol sqrt(rtol / R) (roughfe.fem.dissipation)
        energy = percolates and not moving and drop != 0.0
        Pm = petsc_aij(P)
        Kr = K.PtAP(Pm)
        Pm.destroy()
        with KrylovSolver("reynolds", petsc_options) as solver:
            _, nit, success, message, power, x_dof = solve_for_dissipation(
                solver, Kr, P.T @ rhs_full, own=True, scale=power if energy else None,
                evaluate=lambda xr: dissipation(lift + P @ xr))
    # full residual r = K x - b (flux into the domain at inlet/outlet vertices)
    Kl.setArray(x_dof)
    K.mult(Kl, Klift)
    r_dof = Klift.array - b_dof
    for obj in (Kl, Klift, K):
        obj.destroy()

    x = x_dof[dofs]                      # structured vertex order
    r = r_dof[dofs]
    if not success:
        raise NoConvergenceError(f"Reynolds solve: {message}")
    if not percolates and not moving:
        # inlet and outlet lie in different components of the open network: no through
        # flow, exactly (the computed sum is round-off, ~1e-30 m^3/s)
        q = 0.0
    elif not moving:
        q = power / drop if drop != 0.0 else 0.0   # Q dp = x^T K x: no cancellation
    else:
        w = 1.0 - coord.ravel() / n_flow           # linear weight, 1 at inlet, 0 at outlet
        q = float(w @ r)
    q_in = float(r[inlet].sum())
    q_out = float(-r[outlet].sum())
    p = x + p_out
    p_out_field = np.where(connected, p, np.nan).reshape(vshape)
    return ReynoldsFESolution(
        pressure=p_out_field, pressure_pinned=p.reshape(vshape),
        connected=connected.reshape(vshape), residual=r.reshape(vshape),
        flow_rate=q, inlet_flow=q_in, outlet_flow=q_out, percolates=percolates,
        success=success, message=message, nit=nit)
