"""Two-level (deflation) coarse correction of the Polonsky-Keer CG on its free set
(issue 16 §1, ``docs/theory/02b_bem_performance.md``).

Both classes are passed to :func:`roughfe.bem.pk.polonsky_keer` as ``deflation=`` and
give the same A-DEF2 direction on b x b block aggregates of the free set.
:class:`ProbedBlockDeflation` is the measured reference: exact in what matters for the
iteration count (the Galerkin coarse matrix of the current free set, its near field
probed by fine products every iteration, its coarse system solved directly) and
therefore far too dear for production: ``(2 r + 1)^2`` or more extra fine products per
iteration and a dense coarse factorisation. :class:`BlockDeflation` is the production
form (coarse matrix from the free-set mask, coarse CG), used by ``solve_contact`` in
its measured range.
"""
from __future__ import annotations

import functools

import numpy as np
import scipy.fft
import scipy.linalg

from ..errors import InputError
from . import coarse_blocks
from .coarse_blocks import (_a_def2, _check_grid, _chunks, _full_block_galerkin,
                            _kernel_window)
from .operators import InfluenceOperator


class ProbedBlockDeflation:
    """A-DEF2 coarse correction on b x b block aggregates of the free set F.

    On its free set F the CG of :func:`roughfe.bem.pk.polonsky_keer` solves the
    restricted system H_FF p_F = rhs of Eq. 2.5 (with the zero-mean projection of the
    load in load control). Its preconditioner M = E*|q|/2 is the exact inverse of H on
    the whole grid but not of H_FF: the large eigenvalues of M_FF H_FF belong to the
    smooth modes of each contact patch. The coarse space Z (columns: the indicators of
    the b x b grid blocks intersected with F) removes them through the two-level
    "A-DEF2" preconditioner (Tang, Nabben, Vuik & Erlangga 2009, J. Sci. Comput.
    39:340-370; for contact: Vollebregt 2014, J. Comput. Phys. 257:333-351)

        z = M g + Z E^-1 Z^T (g - H_FF M g),    E = Z^T H_FF Z,

    one more fine product (in single precision: it only steers the search direction)
    plus the coarse matrix. E is built every iteration for the current F: the entries
    of blocks within Chebyshev distance ``radius`` of each other by probing (the sum
    of the block indicators of one colour of an s x s colouring of the blocks, s >=
    2 radius + 1 and dividing the coarse grid, multiplied by H and summed over each
    block: s^2 fine products), corrected for the farther blocks of the same colour by
    the far-field approximation N_i N_j K(i - j) (K: the Galerkin matrix of the full
    blocks, a coarse circulant; N: the blocks' fill fractions), which also gives all
    farther entries. Measured: with ``radius`` = 1 the outer iterations equal those of
    the exact E; the far-field approximation alone on the diagonal (``radius`` = 0)
    loses most of the gain (see the docs page). The coarse system is solved by a dense
    Cholesky factorisation (O(k^3) for k active blocks: small grids only).

    Parameters
    ----------
    op : InfluenceOperator
        The periodic operator H on a 2D grid whose sides are multiples of ``block``.
    block : int
        Aggregate edge b in grid points.
    radius : int
        Block distance up to which E is probed exactly.
    """

    def __init__(self, op: InfluenceOperator, block: int = 8, radius: int = 1):
        block, radius = int(block), int(radius)
        _check_grid(op, block)
        m0, m1 = op.shape[0] // block, op.shape[1] // block
        colours = [s for s in range(2 * radius + 1, min(m0, m1) + 1)
                   if m0 % s == 0 and m1 % s == 0]
        if radius < 0 or not colours:
            raise InputError(f"radius = {radius} needs a colouring of the {m0} x {m1} "
                             f"coarse grid by s >= {2 * radius + 1} dividing both sides")
        self.shape = op.shape
        self.block = block
        self.radius = radius
        self.colours = colours[0]
        self.coarse_shape = (m0, m1)
        self.full_block = _full_block_galerkin(op, block)

    def correct(self, F, gF, zF, apply_free, free_mask=None, pressure=None):
        """The A-DEF2 direction on F from the gradient ``gF`` and ``zF`` = (M g)_F.

        ``F``: the flat indices of the free set; ``apply_free(xF)`` returns (H x)_F for
        x supported on F (a fine product). The vectors live in the zero-mean subspace
        of F (load control: the only mode of :func:`~roughfe.bem.pk.polonsky_keer`
        with a deflation; displacement control of a periodic H is singular on F = the
        whole grid). ``free_mask`` and ``pressure`` (F's grid mask and the pressure,
        whose positive part is the contact set) are not used: this reference corrects at
        every iteration.
        """
        b = self.block
        m0, m1 = self.coarse_shape
        bi, bj = np.divmod(F, self.shape[1])      # a reference for small grids: F-sized
        bi //= b                                  # index arrays are affordable here
        bj //= b
        blk = bi * m1 + bj
        counts = np.bincount(blk, minlength=m0 * m1).astype(float)
        act = np.flatnonzero(counts)
        ai, aj = np.divmod(act, m1)
        di = (ai[:, None] - ai[None, :]) % m0
        dj = (aj[:, None] - aj[None, :]) % m1
        fill = counts[act] / (b * b)
        E = fill[:, None] * fill[None, :] * self.full_block[di, dj]   # far field
        sc = self.colours
        # a block has at most one block of each colour within (s - 1) // 2 (>= radius),
        # and exactly one in all when every block has its own colour (s = m0 = m1)
        reach = np.inf if sc == m0 == m1 else (sc - 1) // 2
        near = np.maximum(np.minimum(di, m0 - di), np.minimum(dj, m1 - dj)) <= reach
        del di, dj
        colour_point = (bi % sc) * sc + bj % sc
        colour_block = (ai % sc) * sc + aj % sc
        del bi, bj
        for c in range(sc * sc):
            cols = np.flatnonzero(colour_block == c)
            if not cols.size:
                continue
            probe = apply_free((colour_point == c).astype(float))
            sums = np.bincount(blk, weights=probe, minlength=m0 * m1)[act]
            # the probe sum over a block minus the far-field approximation of the
            # farther blocks of colour c: its entry with the near one
            sub_near = near[:, cols]
            far = (E[:, cols] * ~sub_near).sum(axis=1)
            rows, which = np.nonzero(sub_near)
            E[rows, cols[which]] = sums[rows] - far[rows]
        E = 0.5 * (E + E.T)
        # the coarse space of zero-mean vectors: Z T c with T c = c - (n.c / |F|) 1;
        # T^T E T is singular along 1 only, which Z T maps to zero
        t = -counts[act] / float(F.size)
        Et = E + np.outer(E.sum(axis=1), t)
        E = Et + np.outer(t, Et.sum(axis=0))
        E += float(np.mean(np.diag(E))) / act.size
        factor = scipy.linalg.cho_factor(E, check_finite=False)

        def solve(rc):
            full = np.zeros(m0 * m1)
            full[act] = scipy.linalg.cho_solve(factor, rc[act], check_finite=False)
            return full

        return _a_def2(F, gF, zF, apply_free, self.shape, b, solve)


#: the block offsets of the near field (Chebyshev distance 1) up to symmetry: E[I, I+d]
#: for these d and, as E[J, J-d] = E[J-d, J], for -d
_NEAR = ((0, 0), (0, 1), (1, -1), (1, 0), (1, 1))


#: blocks per matrix product of the near field (bounds its temporaries to ~20 MB)
_CHUNK = 16384

@functools.lru_cache(maxsize=8)
def _block_constants(op: InfluenceOperator, b: int):
    """What :class:`BlockDeflation` needs of the operator alone, kept per operator (the
    operators are cached by the solver; measured 0.12 s a solve at 1025^2 non-periodic,
    paid at every load of a sweep before): the near-field kernel blocks (float32, the
    five b^2 x b^2 blocks of the offsets ``_NEAR`` side by side), and of K, the Galerkin
    matrix of full blocks, its entry at 0, those at the near offsets, its spectrum and
    the inverse of it (zero at the mean mode)."""
    m0, m1 = op.shape[0] // b, op.shape[1] // b
    # the real-space kernel G at the offsets of the near field (rows -b < r0 < 2b,
    # columns |r1| < 2b) and K, both from the half spectrum without a full grid (the
    # operator keeps no real-space kernel)
    kern = _kernel_window(op, np.arange(1 - b, 2 * b), np.arange(1 - 2 * b, 2 * b))
    a0, a1 = np.divmod(np.arange(b * b), b)          # position in a block
    near = []
    for d0, d1 in _NEAR:
        r0 = d0 * b + a0[None, :] - a0[:, None] + b - 1
        r1 = d1 * b + a1[None, :] - a1[:, None] + 2 * b - 1
        near.append(kern[r0, r1])                    # [a, c] = G(d b + c - a)
    near = np.concatenate(near, axis=1).astype(np.float32)
    K = _full_block_galerkin(op, b)
    khat = scipy.fft.rfft2(K)
    with np.errstate(divide="ignore", invalid="ignore"):
        kinv = np.where(np.abs(khat) > 0, 1.0 / khat, 0.0)
    kinv.flat[0] = 0.0
    for a in (near, khat, kinv):
        a.setflags(write=False)
    return (near, float(K[0, 0]), tuple(float(K[d0 % m0, d1 % m1]) for d0, d1 in _NEAR),
            khat, kinv)


#: the number of set bits of each byte value
_POPCOUNT = np.array([bin(v).count("1") for v in range(256)], np.uint8)


class BlockDeflation:
    """A-DEF2 coarse correction on b x b block aggregates of the free set: production form.

    The same two-level direction as :class:`ProbedBlockDeflation`,

        z = M g + Z E^-1 Z^T (g - H_FF M g),    E = Z^T H_FF Z,

    with the coarse matrix built from the free-set mask instead of fine probes and the
    coarse system solved iteratively:

    * near field (blocks I, J at Chebyshev distance <= 1): exact, E[I, J] = sum over
      i in I & F, j in J & F of G(x_j - x_i) (G the periodic real-space kernel of H,
      m/Pa), as single-precision matrix products of the blocks' b^2 mask rows with
      the five b^2 x b^2 kernel blocks of the offsets (0,0), (0,1), (1,-1), (1,0),
      (1,1) (the other four by symmetry of G): 2 b^2 flops per grid point and offset,
      no FFT, kept between calls and recomputed only where a block's mask changed;
    * far field: N_I N_J K(I - J) (N the blocks' fill fractions, K the Galerkin matrix
      of full blocks, a circulant on the coarse grid), applied by coarse FFTs;
    * the coarse system on the zero-mean coarse space (n . c = 0, n the blocks' point
      counts: the load-control constraint of Eq. 2.5) by projected CG preconditioned by
      S^-1 K^-1 S^-1 (S = sqrt(diag E / K(0))), to the relative residual ``coarse_tol``;
    * while the contact set is searched (more than ``settle`` of the active blocks
      changed their part of the contact set, the points of F with p > 0, since the last
      iteration; session 10, before that their part of F) the correction is skipped (the
      default) or, with ``search`` above ``settle``, acts on the stable part of F: the
      coarse space holds only the blocks whose part did not change (session 8).

    Parameters
    ----------
    op : InfluenceOperator
        The periodic operator H on a 2D grid whose sides are multiples of ``block``,
        with at least 3 blocks per side.
    block : int
        Aggregate edge b in grid points, a multiple of 8.
    coarse_tol : float
        Relative residual of the coarse CG. 1e-4 (session 7; was 1e-6): at 1024^2 and
        2048^2 (4 loads, cold, tol 1e-10) the same outer iterations and contact sets,
        pressures within 1.3e-9 of max p, 31 % fewer coarse iterations (2048^2: 1008 ->
        695), the coarse CG's CPU 1.86 -> 1.35 s (-2 % of the solve); 4096^2 one load
        p/E* = 0.05 / 0.1: 42 / 46 outer iterations (1e-6: 42 / 49); 8192^2, p/E* =
        0.05: 54 (1e-6: 53), the same A*.
    coarse_max_iter : int
        Iteration limit of the coarse CG (its last iterate is used if reached).
    zero_mean : bool
        Load control (default): the correction lives in the zero-mean subspace of F.
        False: displacement control of a positive definite H (the non-periodic torus of
        :mod:`roughfe.bem.padded_deflation`): no projection, the coarse mean mode kept.
    settle : float
        Fraction of the active blocks (those holding points of F) whose part of F may
        change from one iteration to the next with every active block in the coarse
        space; above it the correction is skipped (or, up to ``search``, restricted to
        the unchanged blocks).
    search : float, optional
        Fraction of changed active blocks above which the correction is skipped (the
        plain direction M g); between ``settle`` and ``search`` it acts on the stable
        part of F. Default ``settle`` (the form of sessions 5-7: skipped in the whole
        search). Measured with 1.0 (never skipped after the first iteration; 4 loads
        p/E* = 0.005-0.1, cold, tol 1e-10, 2048^2, paired CPU against the default): the
        ``bench_bem`` surface 115 -> 97 outer iterations (1024^2 94 -> 91: growth 1.22x
        -> 1.07x per doubling) at even CPU, a second seed 109 -> 100 at +11 % CPU,
        H = 0.5 129 -> 123 at +22 % CPU; 0.75 did not converge within 6 min of CPU on
        H = 0.5 at p/E* = 0.1. Not the default for that reason
        (``docs/theory/02b_bem_performance.md``, session 8).

    Measured (real loop, cold, tol 1e-10, H = 0.8, 4 loads p/E* = 0.005-0.1, b = 8):
    the outer iterations of the probed reference (256^2 117 -> 62, 512^2 147 -> 72),
    10-17 coarse CG iterations each; see ``docs/theory/02b_bem_performance.md`` for
    its CPU time against the plain loop.
    """

    def __init__(self, op: InfluenceOperator, block: int = 8, coarse_tol: float = 1e-4,
                 coarse_max_iter: int = 500, settle: float = 0.3, search=None,
                 zero_mean: bool = True):
        block = int(block)
        if block < 8 or block % 8:
            raise InputError(f"block must be a multiple of 8 (a block's row is whole bytes "
                             f"of the packed free-set mask), got {block}")
        _check_grid(op, block, 3)
        if not 0.0 < coarse_tol < 1.0:
            raise InputError(f"coarse_tol must lie in (0, 1), got {coarse_tol}")
        search = settle if search is None else search
        if not (settle >= 0.0 and search >= 0.0):
            raise InputError(f"settle and search must be >= 0 (fractions of the active "
                             f"blocks), got {settle} and {search}")
        self.shape = op.shape
        self.block = b = block
        self.coarse_tol = float(coarse_tol)
        self.coarse_max_iter = int(coarse_max_iter)
        self.settle = float(settle)
        self.search = float(search)
        self.zero_mean = bool(zero_mean)
        self.coarse_shape = (m0, m1) = (op.shape[0] // b, op.shape[1] // b)
        self._near, self._k0, self._knear, self._khat, self._kinv = _block_constants(op, b)
        if not self.zero_mean:     # the coarse mean mode is a mode of the solve too
            self._kinv = self._kinv.copy()
            self._kinv.flat[0] = 1.0 / self._khat.flat[0] if self._khat.flat[0] else 0.0
        self.inner_iterations = []
        self._last = None                                 # the last contact set's block rows
        self._mask = None                                 # those of the kept near field
        self._exact = [np.zeros(m0 * m1) for _ in _NEAR]  # exact near-field entries
        self._valid = [np.zeros(m0 * m1, bool) for _ in _NEAR]   # ... still exact

    def _rows(self, grid, positive=False):
        """The blocks' b^2 mask rows of a grid mask (``grid`` bool, the grid's shape or
        flat; with ``positive`` the mask ``grid > 0`` of a real grid, built a few block
        rows at a time), bit-packed (ceil(b^2 / 8) bytes a block, n / 8 bytes in all),
        and their point counts. A byte of ``np.packbits`` along the grid's rows is 8
        columns of one row: for b a multiple of 8 a block's row is whole bytes, so the
        packed grid only has its n / 8 bytes reordered (measured at 2048^2: ~1 ms,
        against 8 ms for the two scatters and transpositions from the free set's
        indices that it replaced in session 11)."""
        b = self.block
        m0, m1 = self.coarse_shape
        n0, n1 = self.shape
        grid = grid.reshape(self.shape)
        packed = np.empty((n0, n1 // 8), np.uint8)
        rows = b * max(1, coarse_blocks._POINTS // (b * n1))
        for r in range(0, n0, rows):
            part = grid[r:r + rows]
            packed[r:r + rows] = np.packbits(part > 0.0 if positive else part, axis=1)
        X = np.ascontiguousarray(packed.reshape(m0, b, m1, b // 8).transpose(0, 2, 1, 3)
                                 ).reshape(m0 * m1, b * b // 8)
        return X, _POPCOUNT[X].sum(axis=1, dtype=np.int64)

    def _free_rows(self, F):
        """:meth:`_rows` of the free set given by its flat indices ``F``."""
        mask = np.zeros(self.shape[0] * self.shape[1], bool)
        mask[F] = True
        return self._rows(mask)

    def _unpack(self, rows):
        """Mask rows (packed by :meth:`_rows`) as float32 b^2-vectors."""
        return np.unpackbits(rows, axis=1, count=self.block ** 2).astype(np.float32)

    def coarse_operator(self, F):
        """The coarse matrix E of the free set ``F`` (flat indices) as a map of coarse
        vectors (``coarse_shape`` arrays, zero off the active blocks), the blocks' point
        counts and the diagonal of E."""
        return self._coarse(*self._free_rows(F))

    def _coarse(self, X, counts):
        """The coarse operator of :meth:`coarse_operator` from the mask rows ``X`` of F;
        ``counts`` (the blocks' points in F, or zero where a block is left out of the
        coarse space) sets the coarse space: its blocks with a nonzero count."""
        b = self.block
        m0, m1 = self.coarse_shape
        # the exact near field E[I, I + d], kept between calls: an entry is recomputed
        # only when it is needed (both blocks in the coarse space) and the mask of I or
        # I + d changed since it was computed (the free set settles: measured at 1024^2,
        # p/E* = 0.1, the changed blocks fall from ~7000 of 7500 active ones to none in
        # the second half of the iterations). Entries with a block outside the coarse
        # space never act: the coarse vectors are zero there.
        changed = (np.ones(m0 * m1, bool) if self._mask is None
                   else (X != self._mask).any(axis=1)).reshape(m0, m1)
        self._mask = X
        on = (counts > 0).reshape(m0, m1)
        for o, (d0, d1) in enumerate(_NEAR):
            valid = self._valid[o]
            valid &= ~(changed | np.roll(changed, (-d0, -d1), axis=(0, 1))).ravel()
            need = np.flatnonzero(on.ravel() & np.roll(on, (-d0, -d1), axis=(0, 1)).ravel()
                                  & ~valid)
            kern = self._near[:, o * b * b:(o + 1) * b * b]
            # in chunks of rows: the product takes 4 b^2 bytes per row of the chunk
            for start in range(0, need.size, _CHUNK):
                chunk = need[start:start + _CHUNK]
                ri, rj = np.divmod(chunk, m1)
                nb = ((ri + d0) % m0) * m1 + (rj + d1) % m1
                self._exact[o][chunk] = np.einsum(
                    "ij,ij->i", self._unpack(X[chunk]) @ kern, self._unpack(X[nb]))
            valid[need] = True
        N = (counts / float(b * b)).reshape(m0, m1)
        coef = []
        for o, (d0, d1) in enumerate(_NEAR):
            e = self._exact[o]
            c = e.reshape(m0, m1) - N * np.roll(N, (-d0, -d1), axis=(0, 1)) * self._knear[o]
            coef.append(c)
        diag = coef[0] + N * N * self._k0
        khat = self._khat

        def apply(c):
            y = N * scipy.fft.irfft2(khat * scipy.fft.rfft2(N * c), s=(m0, m1))
            y += coef[0] * c
            for o, (d0, d1) in enumerate(_NEAR[1:], 1):
                y += coef[o] * np.roll(c, (-d0, -d1), axis=(0, 1))
                y += np.roll(coef[o] * c, (d0, d1), axis=(0, 1))
            return y

        return apply, counts.reshape(m0, m1), diag

    def _coarse_solve(self, apply, counts, diag, rc):
        """Projected PCG for E c = rc on {counts . c = 0} (the zero-mean coarse space; on
        the active blocks only without ``zero_mean``)."""
        m0, m1 = self.coarse_shape
        active = counts > 0
        nn = counts.astype(float)
        nn /= np.sqrt(float(np.dot(nn.ravel(), nn.ravel())))

        def proj(v):
            v = np.where(active, v, 0.0)
            if self.zero_mean:
                v -= nn * float(np.vdot(nn, v))
            return v

        s = np.where(active, np.sqrt(np.maximum(diag, 0.0) / self._k0), 0.0)
        sinv = np.where(s > 0, 1.0 / np.where(s > 0, s, 1.0), 0.0)
        kinv = self._kinv

        def prec(r):
            return proj(sinv * scipy.fft.irfft2(kinv * scipy.fft.rfft2(sinv * r),
                                                s=(m0, m1)))

        c = np.zeros((m0, m1))
        r = proj(rc)
        z = prec(r)
        t = z.copy()
        rz = float(np.vdot(r, z))
        stop = self.coarse_tol ** 2 * rz
        for it in range(1, self.coarse_max_iter + 1):
            q = proj(apply(t))
            alpha = rz / float(np.vdot(t, q))
            c += alpha * t
            r -= alpha * q
            z = prec(r)
            rz, rz_old = float(np.vdot(r, z)), rz
            if rz <= stop:
                break
            t *= rz / rz_old
            t += z
        self.inner_iterations.append(it)
        return c

    def correct(self, F, gF, zF, apply_free, free_mask=None, pressure=None):
        """The A-DEF2 direction on F (the interface of :class:`ProbedBlockDeflation`);
        on the stable part of F (the blocks whose part of the contact set did not change
        since the last call) while more than ``settle`` (and at most ``search``) of the
        active blocks changed, ``zF`` itself at the first call and while more than
        ``search`` of them changed (the contact-set search).

        ``free_mask`` (bool, flat grid): F as a mask, built from ``F`` when not given.
        ``pressure`` (flat grid, Pa): the contact set is where it is positive (within F;
        :func:`~roughfe.bem.pk.polonsky_keer` passes both); F itself when not given.
        Points at p = 0 that enter F for one iteration (they interpenetrate) and leave
        it the next, without ever carrying a pressure, do not change the pressure field
        the coarse space acts on; counted as changes they kept blocks out of it
        (measured, session 10: the bench surface 1024^2 / 2048^2, 4 cold loads, 89 / 103
        -> 87 / 99 iterations; ``docs/theory/02b_bem_performance.md``)."""
        X, counts = self._free_rows(F) if free_mask is None else self._rows(free_mask)
        mark = X if pressure is None else self._rows(pressure, positive=True)[0]
        last, self._last = self._last, mark
        if last is None:
            return zF
        changed = (mark != last).any(axis=1)
        moved = np.count_nonzero(changed)
        active = np.count_nonzero(counts)
        if moved > self.search * active:
            return zF
        if moved > self.settle * active:          # the stable part of F only
            counts = np.where(changed, 0, counts)
            if np.count_nonzero(counts) < 2:
                return zF
        apply, counts, diag = self._coarse(X, counts)
        return _a_def2(F, gF, zF, apply_free, self.shape, self.block,
                       lambda rc: self._coarse_solve(apply, counts, diag,
                                                     rc.reshape(counts.shape)).ravel(),
                       self.zero_mean)
