"""Window sweeps of the contact edges inside the Polonsky-Keer CG (issue 16 section 1).

What grows with the grid in the periodic load-controlled solve is the search for the
contact set: every new octave of roughness adds about four times as many pixel-scale
contact edges, and each CG iteration settles about a third of the wrong ones
(docs/theory/02b_bem_performance.md, sessions 15-28). A local solve settles them, but a
point relaxation (session 18) moved tens of thousands of points the same way and their
cut-off far fields added up. Here the local solve is a **load-conserving window sweep**
(round 2, session 29):

* the grid is tiled by 4 x 4 windows (the tiling shifted by 2 points on alternate
  sweeps); every window that holds a contact edge (0 < contact points < 16) solves its
  own contact problem, min 1/2 q.A q + q.(u - h) over q >= 0 with its own load
  sum q fixed, where A is the exact 16 x 16 block of the periodic influence operator
  and u - h the current gap (the field of the pressure outside the window is in u);
  two PK iterations in float32 (the gap taken relative to the window's first point so
  that float32 keeps its digits), the result rescaled in float64 to the window's load;
* the windows' changes sum to zero in each window (at most a dipole far field), so
  they combine almost additively: one product dp -> H dp and the exact line search
  along dp (step clipped to [0, 1]) keep the energy falling and the load exact;
* the CG is restarted after a sweep (the contact set has moved).

Sweeps run three times before the first CG iteration, then before every fourth one
while the KKT residual is above :data:`SWEEP_UNTIL`: on the growth surfaces of
``bench_bem_growth.py`` (H = 0.5, 4 loads) 18-20 sweeps in all. Measured (02b, session
29): the same A* and pressures to 3.7e-9 of the peak, 20-24 % fewer iterations and CPU
within a few per cent of the solver without them, and the growth per doubling of n
1.167x -> 1.106x at 1024^2 -> 2048^2.

The local solve is a compiled kernel (numba, Debian's ``python3-numba``); without numba
the solver runs without sweeps (:func:`edge_sweeps_for` returns None), with the same
answer. The kernel is the one loop over windows; it writes the change dp into the
CG's full-grid buffer of the two-level correction, in float64 (that buffer is float32
in the single-precision phase, where u is float32 too, so the sweep's peak is the
double-precision phase's), and returns the slope dp . (u - h). A float32 dp cost 10
more iterations for 4 loads at 1024^2 (97 -> 107): its rounding leaves the points a
window takes out of contact at p ~ 1e-8 p instead of 0, and the CG must clear them.
"""
from __future__ import annotations

import numpy as np

#: side of the square windows (points); the kernel is written for 4 x 4 = 16 unknowns
WINDOW = 4
#: sweeps before the first CG iteration, then one before every EVERY-th iteration
START_SWEEPS, EVERY = 3, 4
#: KKT residual below which no sweep is made (the contact set is found by then; the
#: coarse-start levels, solved to this tolerance, get none)
SWEEP_UNTIL = 1e-4
#: local PK iterations per window
INNER = 2
#: grids from MIN_SIDE^2 points on get the sweeps (where they were measured to pay, as
#: the two-level correction they run beside: both are on together)
MIN_SIDE = 1024


def _kernel():
    """The compiled window kernel, or None without numba (imported on first use: the
    command line stays light)."""
    try:
        import numba
    except ImportError:
        return None
    if "sweep" not in _COMPILED:
        jit = numba.njit(cache=True, fastmath=True, boundscheck=False)
        _COMPILED.update(sweep=jit(_sweep_py), dot=jit(_dot_py))
    return _COMPILED["sweep"]


_COMPILED = {}


def _dot_py(x, y):  # pragma: no cover - compiled
    """x . y in float64 for any float dtypes, without a full-grid temporary."""
    acc = 0.0
    for i in range(x.size):
        acc += np.float64(x[i]) * np.float64(y[i])
    return acc


def _sweep_py(A, p, u, h, n0, n1, off, n_inner, out):  # pragma: no cover - compiled
    """One sweep over the 4 x 4 windows of the (n0, n1) periodic grid (flat arrays p, u,
    h; the tiling shifted by ``off``): each window's change into ``out`` (zero elsewhere:
    the caller zeroes it); returns (windows solved, dp . (u - h)) in float64."""
    N = 16
    b = 4
    q = np.empty(N, np.float32)
    w = np.empty(N, np.float32)
    g = np.empty(N, np.float32)
    gold = np.empty(N, np.float32)
    t = np.empty(N, np.float32)
    At = np.empty(N, np.float32)
    dq = np.empty(N, np.float32)
    ix = np.empty(N, np.int64)
    z = np.float32(0.0)
    one = np.float32(1.0)
    solved = 0
    slope = 0.0
    for I in range(n0 // b):
        for J in range(n1 // b):
            c = 0
            for r in range(b):
                row = ((I * b + off + r) % n0) * n1
                for s in range(b):
                    x = row + (J * b + off + s) % n1
                    ix[r * b + s] = x
                    if p[x] > 0:
                        c += 1
            if c == 0 or c == N:
                continue
            solved += 1
            load = z
            ref = np.float64(u[ix[0]]) - h[ix[0]]
            for i in range(N):
                x = ix[i]
                q[i] = p[x]
                w[i] = (np.float64(u[x]) - h[x]) - ref
                load += q[i]
                t[i] = z
                gold[i] = z
            gz_old = z
            for it in range(n_inner):
                # the window's PK: Delta as the mean gap on its contact, the free set,
                # the gradient projected on zero mean there, PR+ conjugation
                sd = z
                ns = z
                for i in range(N):
                    m = one if q[i] > z else z
                    sd += m * w[i]
                    ns += m
                if ns == z:           # no contact left in the window: stop here
                    break
                d = sd / ns
                sg = z
                nf = z
                for i in range(N):
                    m = one if (q[i] > z or w[i] < d) else z
                    g[i] = m * (w[i] - d)
                    sg += g[i]
                    nf += m
                mg = sg / nf
                gz = z
                num = z
                for i in range(N):
                    m = one if (q[i] > z or w[i] < d) else z
                    gi = m * (g[i] - mg)
                    g[i] = gi
                    gz += gi * gi
                    num += gi * (gi - gold[i])
                beta = max(z, num / gz_old) if gz_old > z else z
                gz_old = gz
                for i in range(N):
                    m = one if g[i] != z else z
                    t[i] = m * (g[i] + beta * t[i])
                    gold[i] = g[i]
                for i in range(N):
                    At[i] = z
                for j in range(N):
                    tj = t[j]
                    for i in range(N):
                        At[i] += A[j, i] * tj
                tAt = z
                gt = z
                for i in range(N):
                    tAt += t[i] * At[i]
                    gt += g[i] * t[i]
                tau = gt / tAt if tAt > z else z
                sq = z
                for i in range(N):
                    v = max(q[i] - tau * t[i], z)
                    dq[i] = v
                    sq += v
                if not sq > z:        # every point would leave: keep the last iterate
                    break
                a = load / sq
                for i in range(N):
                    v = dq[i] * a
                    dq[i] = v - q[i]
                    q[i] = v
                if it + 1 < n_inner:
                    for j in range(N):
                        dj = dq[j]
                        for i in range(N):
                            w[i] += A[j, i] * dj
            # back in float64, to the window's load exactly: a zero-sum change
            p64 = 0.0
            q64 = 0.0
            for i in range(N):
                p64 += p[ix[i]]
                q64 += np.float64(q[i])
            if not q64 > 0:
                continue
            sc = p64 / q64
            for i in range(N):
                x = ix[i]
                v = np.float64(q[i]) * sc - p[x]
                out[x] = v
                slope += v * ((np.float64(u[x]) - h[x]) - ref)
    return solved, slope


class EdgeSweeps:
    """The sweeps of one solve (:func:`polonsky_keer` ``edge_sweeps``): when to sweep
    (:meth:`due`), the local block of the operator (:meth:`set_block`, from the operator
    applied to a unit load at the origin) and the change (:meth:`changes`).
    ``count``: sweeps made (each counts as an iteration of the solve)."""

    def __init__(self, shape, kernel):
        self.shape, self.kernel = tuple(int(n) for n in shape), kernel
        self.block = None
        self.count = 0           # sweeps made
        self._tries = 0          # sweeps asked for (a sweep with no edge window is none)
        self._last = -1

    def due(self, k, res) -> bool:
        """A sweep before the CG iteration ``k`` (from 0) at the KKT residual ``res``."""
        if res <= SWEEP_UNTIL:
            return False
        if self._tries < START_SWEEPS:
            self._tries += 1
            self._last = k
            return True
        if k % EVERY or k == self._last:
            return False
        self._last = k
        self._tries += 1
        return True

    def missed(self):
        """The sweep asked for changed nothing (no edge window, or no descent): the CG
        iteration goes on in its place (and the start's sweeps are not asked again)."""
        if self._tries < START_SWEEPS:
            self._tries = START_SWEEPS

    def set_block(self, response):
        """The 16 x 16 block A[j, i] = G(x_i - x_j) of the window from ``response``, the
        operator applied to a unit load at the origin (flat)."""
        n0, n1 = self.shape
        G = np.asarray(response, float).reshape(n0, n1)
        i, j = np.divmod(np.arange(WINDOW * WINDOW), WINDOW)
        self.block = np.ascontiguousarray(
            G[(i[None, :] - i[:, None]) % n0, (j[None, :] - j[:, None]) % n1], np.float32)

    def _offset(self):
        return (self.count * (WINDOW // 2)) % WINDOW

    def changes(self, p, u, h, out):
        """The sweep's change dp into ``out`` (zeroed here; float32 in the solver's
        single-precision phase) and its slope dp . (u - h) (float64, from the unrounded
        change), or None when no window holds a contact edge."""
        out.fill(0.0)
        n0, n1 = self.shape
        solved, slope = self.kernel(self.block, p, u, h, n0, n1, self._offset(), INNER, out)
        return float(slope) if solved else None

    def curvature(self, dp, hdp):
        """dp . H dp (float64) of the change ``dp`` and its product ``hdp`` (the float32
        product of the single-precision phase too)."""
        return float(_COMPILED["dot"](dp, hdp))

    def made(self):
        """The sweep's step was taken (the next one uses the shifted tiling)."""
        self.count += 1


def edge_sweeps_for(op, deflation, *, load, hardness, tol):
    """The :class:`EdgeSweeps` of a Polonsky-Keer solve, or None: periodic 2D grids of
    at least :data:`MIN_SIDE` ^2 points with sides divisible by :data:`WINDOW`, load
    control without a hardness, a tolerance below :data:`SWEEP_UNTIL`, the two-level
    correction on (``deflation``: its full-grid buffer carries the sweep's change, so
    the sweeps add no field), and numba present."""
    shape = tuple(op.fft_shape)
    if (deflation is None or not op.periodic or len(shape) != 2 or not load
            or (hardness is not None and np.isfinite(hardness)) or not tol < SWEEP_UNTIL
            or min(shape) < MIN_SIDE or any(n % WINDOW for n in shape)):
        return None
    kernel = _kernel()
    return None if kernel is None else EdgeSweeps(shape, kernel)
