"""The periodic BEM products of :mod:`roughfe.bem.operators` on a grid distributed over
MPI ranks in row slabs (:mod:`roughfe.bem.distributed`).

Layout: the ``n0 x n1`` grid is split along axis 0; rank k holds the contiguous rows
``row_splits[k]`` of every real field (pressure, displacement, heights) and, in the
spectral domain, the contiguous columns ``column_splits[k]`` of the rfft half-spectrum
(``n1 // 2 + 1`` columns) with all ``n0`` rows. An uneven split is allowed: the first
``n % ranks`` ranks take one row (column) more; a grid with fewer rows, or
half-spectrum columns, than ranks is refused.

A product y = irfft2(S * rfft2(x)) (:meth:`SlabOperator.convolve`) is the serial one's
(:func:`roughfe.bem.fft._convolve`: r2c along the last axis, c2c along the first, and
back, normalised by 1/n per axis) with one global transpose each way:

1. rfft along axis 1 of the rank's rows (``m_k x (n1//2 + 1)``, complex);
2. Alltoallv: rank k sends rank j its rows' block of j's columns and receives j's rows
   of its own columns, stacked in row order: an ``n0 x c_k`` column slab;
3. fft along axis 0, times the rank's slab of the multiplier S, ifft along axis 0;
4. Alltoallv back (the slab's rows of rank j are contiguous), irfft along axis 1.

The multipliers are made for the rank's own columns only
(:func:`roughfe.bem.operators.periodic_spectrum` with ``columns``): no rank builds a
full-grid array. The operator u = H p has S = 2 / (E* |q|), the preconditioner M =
E* |q| / 2 (:func:`roughfe.bem.operators.reciprocal_or_zero`), both zero at q = 0 (zero
mean displacement), as the serial operator. Memory per rank: two complex half-slabs of
~8 n0 n1 / ranks bytes each (the send buffer, and one buffer for the rfft of the rows
and the column slab in turn); a product allocates nothing.
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError, check_finite_positive, check_int
from .fft import WORKERS, _pocketfft
from .operators import periodic_spectrum, reciprocal_or_zero


def even_splits(n: int, parts: int) -> list:
    """``parts`` contiguous ranges ``(start, stop)`` covering ``range(n)``, the first
    ``n % parts`` one longer (numpy's ``array_split``). InputError when ``n < parts``
    (a rank would hold nothing)."""
    n, parts = int(n), int(parts)
    if n < parts:
        raise InputError(f"{n} rows (or half-spectrum columns) cannot be split over {parts} "
                         f"MPI ranks: each rank needs at least one; use at most {n} ranks "
                         f"or a larger grid")
    base, extra = divmod(n, parts)
    edges = np.cumsum([0] + [base + (k < extra) for k in range(parts)])
    return [(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:])]


def check_grid(shape) -> tuple:
    """``shape`` as ``(n0, n1)`` (integers >= 2), or an InputError."""
    try:
        dims = tuple(shape)
    except TypeError:
        dims = ()
    if len(dims) != 2:
        raise InputError(f"the distributed solver takes a 2D grid shape (n0, n1), got "
                         f"{shape!r}")
    return tuple(check_int(f"grid shape[{a}]", n, 2) for a, n in enumerate(dims))


def slab_rows(shape, ranks: int, rank: int) -> tuple:
    """The rows ``(start, stop)`` that rank ``rank`` of ``ranks`` holds of a grid
    ``shape`` (:func:`even_splits` of axis 0; the half-spectrum's columns must split
    too)."""
    n0, n1 = check_grid(shape)
    even_splits(n1 // 2 + 1, ranks)
    return even_splits(n0, ranks)[rank]


def _counts(counts) -> tuple:
    """Alltoallv's ``(counts, displacements)`` (lists of int) of consecutive blocks."""
    counts = [int(k) for k in counts]
    return counts, [int(k) for k in np.concatenate([[0], np.cumsum(counts)[:-1]])]


def _mpi():
    from mpi4py import MPI   # imported when a product is built: it initialises MPI
    return MPI


class SlabOperator:
    """The periodic influence operator u = H p (m/Pa, 2 / (E* |q|)) and its
    preconditioner M (E* |q| / 2, Pa/m) on the row slabs of a grid ``shape`` of ``size``
    (m) distributed over the ranks of the mpi4py communicator ``comm`` (module
    docstring). ``apply`` and ``precondition`` are collective: every rank calls them
    in the same order."""

    def __init__(self, comm, shape, size, e_star):
        self.comm = comm
        self.shape = check_grid(shape)
        size = tuple(check_finite_positive(f"size[{a}] (m)", s) for a, s in enumerate(size))
        if len(size) != 2:
            raise InputError(f"size must be (Lx, Ly) in m, got {size!r}")
        e_star = check_finite_positive("E* (Pa)", e_star)
        ranks, rank = comm.Get_size(), comm.Get_rank()
        n0, n1 = self.shape
        self.half = n1 // 2 + 1
        self.row_splits = even_splits(n0, ranks)
        self.column_splits = even_splits(self.half, ranks)
        self.rows = self.row_splits[rank]
        self.columns = self.column_splits[rank]
        m = np.array([b - a for a, b in self.row_splits])
        c = np.array([b - a for a, b in self.column_splits])
        mine_m, mine_c = m[rank], c[rank]
        # forward: to rank j my rows x j's columns; from j its rows x my columns
        self._fwd_send = _counts(mine_m * c)
        self._fwd_recv = _counts(m * mine_c)
        self.spectrum = periodic_spectrum(self.shape, size, e_star,
                                          columns=slice(*self.columns))
        self.inverse = reciprocal_or_zero(self.spectrum)
        if _pocketfft is None:     # pragma: no cover - scipy without its pocketfft binding
            raise InputError("the distributed products need scipy's pocketfft binding "
                             "(scipy.fft._pocketfft.pypocketfft)")
        # the row slab's half-spectrum and the column slab share one buffer (the first is
        # packed before the second is received, and unpacked after it is sent)
        raw = np.empty(max(mine_m * self.half, n0 * mine_c), np.complex128)
        self._half = raw[:mine_m * self.half].reshape(mine_m, self.half)
        self._slab = raw[:n0 * mine_c].reshape(n0, mine_c)
        self._pack = np.empty(mine_m * self.half, np.complex128)

    @property
    def local_shape(self) -> tuple:
        """The shape of this rank's slab of a real field."""
        return (self.rows[1] - self.rows[0], self.shape[1])

    def _alltoallv(self, send, send_counts, recv, recv_counts):
        kind = _mpi().C_DOUBLE_COMPLEX
        self.comm.Alltoallv([send, send_counts, kind], [recv, recv_counts, kind])

    def convolve(self, x, multiplier, out=None):
        """irfft2(S rfft2(x)) of this rank's slab ``x`` (float64; other real dtypes are
        cast) with this rank's column slab ``multiplier`` (S) of the half-spectrum,
        into ``out`` (a C-contiguous float64 array of the slab's shape; allocated if
        None). Collective. The transforms run in place in the operator's kept buffers
        (scipy's pocketfft binding, as :func:`roughfe.bem.fft._forward`): a product
        allocates nothing."""
        x = np.asarray(x)
        if x.shape != self.local_shape:
            raise InputError(f"this rank's slab must have shape {self.local_shape} "
                             f"(rows {self.rows[0]}..{self.rows[1] - 1} of {self.shape}), "
                             f"got {x.shape}")
        if out is None:
            out = np.empty(self.local_shape)
        half, pack, slab = self._half, self._pack, self._slab
        if x.dtype != np.float64 or not x.flags.c_contiguous:   # e.g. a float32 gradient
            np.copyto(out, x, casting="same_kind")      # staged in out (as fft._copy)
            x = out
        _pocketfft.r2c(x, [1], True, 0, half, WORKERS)
        for (c0, c1), (n, k) in zip(self.column_splits, zip(*self._fwd_send)):
            pack[k:k + n].reshape(-1, c1 - c0)[...] = half[:, c0:c1]
        self._alltoallv(pack, self._fwd_send, slab, self._fwd_recv)
        _pocketfft.c2c(slab, [0], True, 0, slab, WORKERS)
        slab *= multiplier
        _pocketfft.c2c(slab, [0], False, 2, slab, WORKERS)       # normalised by 1/n0
        self._alltoallv(slab, self._fwd_recv, pack, self._fwd_send)
        for (c0, c1), (n, k) in zip(self.column_splits, zip(*self._fwd_send)):
            half[:, c0:c1] = pack[k:k + n].reshape(-1, c1 - c0)
        _pocketfft.c2r(half, [1], self.shape[1], False, 2, out, WORKERS)  # 1/n1
        return out

    def apply(self, p, out=None, work=None):
        """u = H p (m) of this rank's pressure slab ``p`` (Pa); ``work`` is ignored (the
        interface of :func:`~roughfe.bem.pk.polonsky_keer`'s products)."""
        return self.convolve(p, self.spectrum, out)

    def precondition(self, g, out=None, work=None):
        """M g (Pa) of this rank's slab ``g`` (m): the stiffness E* |q| / 2."""
        return self.convolve(g, self.inverse, out)
