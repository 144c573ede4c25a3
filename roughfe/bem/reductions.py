"""The global reductions of the Polonsky-Keer CG (:func:`roughfe.bem.pk.polonsky_keer`):
its sums, dots, means, minima and maxima over the grid, its point count and the load
target come from one of these objects, so that the same loop runs on the whole grid
(:data:`SERIAL`, the default: numpy's own reductions, as the loop had them inline, so
its results and counts are bit for bit those of before) or on one process's slab of a
grid distributed over MPI ranks (:class:`CommReductions`: the local reduction, then an
Allreduce over the communicator; :mod:`roughfe.bem.distributed`).

Every rank must take the same branches of the loop (a product is a collective call), so
every quantity a branch depends on is a global reduction, the same value on every rank.
"""
from __future__ import annotations

import numpy as np


class SerialReductions:
    """Reductions over the whole field held by this process (the production solver)."""

    #: False: the field is the whole grid
    distributed = False

    def count(self, n: int) -> int:
        """The grid's points, given this process's ``n``."""
        return n

    def size(self, x) -> int:
        """The global length of the vector ``x`` (a free-set gather, a slab)."""
        return x.size

    def sum(self, x) -> float:
        return float(x.sum())

    def dot(self, a, b) -> float:
        return float(np.dot(a, b))

    def mean(self, x):
        """The mean of ``x`` (numpy's scalar of ``x``'s dtype, as ``x.mean()``)."""
        return x.mean()

    def min(self, x) -> float:
        return float(x.min())

    def max(self, x) -> float:
        return float(x.max())

    def min_of(self, value: float) -> float:
        """The global minimum of a scalar found by each process (e.g. over its blocks)."""
        return value

    def any(self, x) -> bool:
        return bool(x.any())


#: the default of :func:`~roughfe.bem.pk.polonsky_keer`
SERIAL = SerialReductions()


def _mpi_op(name):
    """``mpi4py.MPI.<name>``, imported at the first use (importing mpi4py initialises
    MPI: a process that only builds this object for a check must not)."""
    from mpi4py import MPI
    return getattr(MPI, name)


class CommReductions(SerialReductions):
    """Reductions over a grid distributed over the ranks of the mpi4py communicator
    ``comm`` (each rank holds a slab of every field): the local reduction in float64,
    then ``comm.allreduce``. An empty local part counts as 0 in sums and as +-inf in
    minima and maxima. Means are the global sum over the global length."""

    distributed = True

    def __init__(self, comm):
        self.comm = comm

    def count(self, n: int) -> int:
        return int(self.comm.allreduce(int(n)))

    def size(self, x) -> int:
        return int(self.comm.allreduce(int(x.size)))

    def sum(self, x) -> float:
        return float(self.comm.allreduce(float(x.sum(dtype=np.float64))))

    def dot(self, a, b) -> float:
        return float(self.comm.allreduce(float(np.dot(a, b))))

    def mean(self, x) -> float:
        total, n = self.comm.allreduce(np.array([float(x.sum(dtype=np.float64)), x.size]))
        return float(total / n) if n else float("nan")

    def min(self, x) -> float:
        return self.min_of(float(x.min()) if x.size else np.inf)

    def max(self, x) -> float:
        local = float(x.max()) if x.size else -np.inf
        return float(self.comm.allreduce(local, op=_mpi_op("MAX")))

    def min_of(self, value: float) -> float:
        return float(self.comm.allreduce(float(value), op=_mpi_op("MIN")))

    def any(self, x) -> bool:
        return bool(self.comm.allreduce(int(bool(x.any())), op=_mpi_op("MAX")))
