"""A periodic elastic BEM contact solve distributed over MPI ranks (mpi4py): the way
beyond one machine's memory (docs/theory/02b_bem_performance.md, "Memory and the
largest surfaces").

Each rank holds a contiguous block of rows of the ``n0 x n1`` grid
(:func:`~roughfe.bem.slab_fft.slab_rows`) of the heights and of every field of the
solve; the FFT products are the slab-decomposed ones of :mod:`roughfe.bem.slab_fft`
(no rank holds a full-grid array), and the solver is the production Polonsky-Keer CG,
:func:`roughfe.bem.pk.polonsky_keer`, with its global reductions over the communicator
(:class:`roughfe.bem.reductions.CommReductions`): load control (Eq. 2.5-2.6 with the
mean pressure imposed), preconditioned by M = E* |q| / 2, from the uniform pressure
(plain PK: no coarse start), without the two-level correction or the single-precision
products of :func:`roughfe.bem.solve_contact`, so it takes more iterations than the
serial production solve (measured in docs/benchmarks). Elastic, periodic, 2D only.

Usage (every rank)::

    from mpi4py import MPI
    from roughfe.bem.distributed import read_slab, solve_contact_distributed
    h, shape, rows = read_slab("heights.npy", MPI.COMM_WORLD)   # m, mmap: no full load
    r = solve_contact_distributed(h, shape, (Lx, Ly), e_star, mean_pressure,
                                  MPI.COMM_WORLD)
    # r.pressure, r.gap: this rank's rows; r.area_fraction, r.mean_gap: global

    mpirun -n 2 python script.py
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError, check_finite_positive, check_int, check_real_array
from .pk import polonsky_keer
from .reductions import CommReductions
from .slab_fft import SlabOperator, check_grid, slab_rows


@dataclass(frozen=True, eq=False)
class DistributedContact:
    """One rank's share of a distributed contact solve.

    Attributes
    ----------
    pressure, gap : ndarray
        This rank's rows ``rows`` of the contact pressure (Pa, >= 0) and of the gap (m,
        >= 0, zero in contact) of the grid ``shape``.
    rows : tuple
        ``(start, stop)``: the rows of the grid this rank holds.
    shape : tuple
        The whole grid ``(n0, n1)``.
    area_fraction : float
        A* = contact points / all points (global).
    mean_gap : float
        Mean of the gap over the whole grid (m).
    mean_pressure : float
        Mean pressure of the solution over the whole grid (Pa): the imposed one.
    delta : float
        The approach Delta (m): max h - mean h - mean-plane separation, as
        :attr:`roughfe.model.ContactResult.delta` (zero mean displacement).
    nit, n_products : int
        CG iterations and FFT products (H and M; each a collective product).
    residual, tolerance : float
        The relative KKT residual reached and the one asked for.
    ranks : int
        The communicator's size.
    """

    pressure: np.ndarray
    gap: np.ndarray
    rows: tuple
    shape: tuple
    area_fraction: float
    mean_gap: float
    mean_pressure: float
    delta: float
    nit: int
    n_products: int
    residual: float
    tolerance: float
    ranks: int


def read_slab(path, comm):
    """This rank's rows of the 2D heights (m) in the ``.npy`` file ``path``, read through
    a memory map (``np.load(mmap_mode="r")``: no rank loads the whole file). Returns
    ``(heights, shape, rows)``: the float64 slab, the grid's shape and ``(start,
    stop)``. An InputError for a file that is not a 2D real array."""
    try:
        a = np.load(path, mmap_mode="r", allow_pickle=False)
    except (OSError, ValueError) as exc:
        raise InputError(f"cannot read heights from {str(path)!r} as a .npy array: "
                         f"{exc}") from None
    if a.ndim != 2 or a.dtype.kind not in "fiu":
        raise InputError(f"{str(path)!r} must hold a 2D real array of heights (m), got "
                         f"shape {a.shape} and dtype {a.dtype}")
    rows = slab_rows(a.shape, comm.Get_size(), comm.Get_rank())
    return np.array(a[rows[0]:rows[1]], dtype=np.float64), tuple(a.shape), rows


def solve_contact_distributed(heights, shape, size, e_star, mean_pressure, comm, *,
                              tol=1e-10, max_iter=20000) -> DistributedContact:
    """Frictionless periodic contact of a rigid rough surface on an elastic half-space
    under the mean pressure ``mean_pressure`` (Pa), the grid distributed over the ranks
    of ``comm`` (collective: every rank calls it with its own slab).

    Parameters
    ----------
    heights : array_like
        This rank's rows of the heights (m), ``slab_rows(shape, comm.size, comm.rank)``
        (e.g. from :func:`read_slab`).
    shape : tuple of int
        The whole grid ``(n0, n1)``; n0 and n1 // 2 + 1 at least the number of ranks.
    size : tuple of float
        The periodic box ``(Lx, Ly)`` (m).
    e_star : float
        Composite modulus E* (Pa).
    mean_pressure : float
        The imposed mean pressure (Pa, > 0).
    comm : mpi4py communicator
    tol : float
        Relative KKT residual (that of :func:`roughfe.bem.solve_contact`).
    max_iter : int
        Iteration cap; NoConvergenceError beyond it (with this rank's slab).

    Returns a :class:`DistributedContact`.
    """
    shape = check_grid(shape)
    pm = check_finite_positive("mean_pressure (Pa)", mean_pressure)
    tol = check_finite_positive("tol", tol)
    max_iter = check_int("max_iter", max_iter, 1)
    ranks, rank = comm.Get_size(), comm.Get_rank()
    rows = slab_rows(shape, ranks, rank)
    h = check_real_array("heights (this rank's slab)", heights, ndim=2)
    if h.shape != (rows[1] - rows[0], shape[1]):
        raise InputError(f"rank {rank} of {ranks} holds rows {rows[0]}..{rows[1] - 1} of "
                         f"the grid {shape}: its heights must have shape "
                         f"{(rows[1] - rows[0], shape[1])}, got {h.shape}")
    op = SlabOperator(comm, shape, size, e_star)
    reduce = CommReductions(comm)
    n = reduce.count(h.size)
    hmax, hmin = reduce.max(h), reduce.min(h)
    out = polonsky_keer(op.apply, h, hmax - hmin, mean_pressure=pm,
                        precond=op.precondition, tol=tol, max_iter=max_iter,
                        offset=-hmax, reduce=reduce)
    p, gap, d = out.pressure, out.displacement, out.delta
    contact = p > 0
    gap += hmax - d           # in place: the gap u + max h - h - Delta, 0 in contact
    gap -= h
    np.maximum(gap, 0.0, out=gap)
    gap[contact] = 0.0
    return DistributedContact(
        pressure=p, gap=gap, rows=rows, shape=shape,
        area_fraction=reduce.count(int(np.count_nonzero(contact))) / n,
        mean_gap=reduce.sum(gap) / n, mean_pressure=reduce.sum(p) / n, delta=float(d),
        nit=int(out.nit), n_products=int(out.n_products), residual=float(out.residual),
        tolerance=tol, ranks=ranks)
