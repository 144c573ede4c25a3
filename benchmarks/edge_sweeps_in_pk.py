"""Research script (issue 16 section 1; not in the package, not in ``make bench``):
load-conserving window sweeps of the contact edges INSIDE the Polonsky-Keer CG, measured
in round 2, session 29 and **not adopted** (docs/theory/02b_bem_performance.md, "Window
sweeps inside the CG, measured").

Every 4 x 4 window holding a contact edge (0 < contact points < 16; the tiling shifted
by 2 on alternate sweeps) solves its own contact problem at its own load with the exact
16 x 16 block of the periodic operator, by 2 PK iterations in a numba-compiled kernel
(float32, the gap relative to the window's first point, the result rescaled in float64
to the window's load). In the CG: 3 sweeps before the first iteration, then one before
every 4th while the KKT residual is above 1e-4; each sweep is one product H dp, the
exact step (clipped to [0, 1]), p rescaled to the load and a CG restart. The change dp
is kept in float64 (a float32 dp cost 10 more passes for 4 loads at 1024^2: it left the
points a window took out of contact at ~1e-8 p instead of 0).

The hook is put into a copy of ``roughfe/bem/pk.py`` at run time (the package is not
changed); the sweeps act on the fine solve only (not on the coarse-start levels).
Every sweep counts as a pass (an iteration) of the solve.

Usage (from the repository root; numba: Debian's python3-numba)::

    .venv/bin/python benchmarks/edge_sweeps_in_pk.py --n 1024 2048 --hurst 0.8 \
        --seeds 1 2 --loads 0.005 0.01 0.05 0.1
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


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

    #: the hook's controller interface (:data:`HOOK`, shared with
    #: adaptive_sweeps_in_pk.py): no residual floor of its own, every sweep worth its
    #: product, and a CG restart after each
    until = float("-inf")
    restart = True

    def __init__(self, shape, kernel):
        self.shape, self.kernel = tuple(int(n) for n in shape), kernel
        self.block = None
        self.count = 0           # sweeps made
        self._tries = 0          # sweeps asked for (a sweep with no edge window is none)
        self._last = -1

    def observe(self, *state):
        """Nothing to learn from the CG's iterations (the adaptive controller does)."""

    def pays(self, predicted) -> bool:
        """Every sweep with a descent is made."""
        return True

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
        single-precision phase) and ``(slope, None)``, its slope dp . (u - h) (float64,
        from the unrounded change) and no predicted decrease, or None when no window
        holds a contact edge."""
        out.fill(0.0)
        n0, n1 = self.shape
        solved, slope = self.kernel(self.block, p, u, h, n0, n1, self._offset(), INNER, out)
        return (float(slope), None) if solved else None

    def curvature(self, dp, hdp):
        """dp . H dp (float64) of the change ``dp`` and its product ``hdp`` (the float32
        product of the single-precision phase too)."""
        return float(_COMPILED["dot"](dp, hdp))

    def made(self):
        """The sweep's step was taken (the next one uses the shifted tiling)."""
        self.count += 1


#: the hook, put into the Polonsky-Keer loop before its stall watch; ``EDGE[0]`` is the
#: controller (:class:`EdgeSweeps`, or adaptive_sweeps_in_pk.py's): ``until`` (no sweep
#: at or below that residual), ``observe``, ``due``, ``changes`` -> (slope, predicted
#: decrease) or None, ``pays``, ``curvature``, ``made``, ``missed``, ``restart``
HOOK = """        if EDGE[0] is not None and res > EDGE[0].until:
            ctl = EDGE[0]
            ctl.observe(it, res, p, u, us, bf)
            if ctl.due(it - 1 - ctl.count, res):
                if us != 1.0:
                    u *= us
                    us = 1.0
                fn = apply_single if single else apply
                y = buffer("y", np.float64)
                if ctl.block is None:
                    y.fill(0.0)
                    y[0] = 1.0
                    ctl.set_block(product(fn, y, y))
                est = ctl.changes(p, u, bf, y)
                if est is not None and est[0] < 0 and ctl.pays(est[1]):
                    slope = est[0]
                    r = product(fn, y, buffer("r", np.float32 if single else np.float64))
                    curvature = ctl.curvature(y, r)
                    step = min(1.0, -slope / curvature) if curvature > 0 else 0.0
                    if step > 0:
                        _axpy(p, step, y)
                        np.maximum(p, 0.0, out=p)
                        _rescale_to_load(p, target, upper)
                        _axpy(u, step, r)
                        ctl.made()
                        exact = False
                        if ctl.restart:
                            gz_old = 0.0
                        S = par.flatnonzero(p)
                        continue
                ctl.missed()
"""


def hooked_pk(hook=None, name="pk_edge"):
    """``roughfe.bem.pk`` with ``hook`` (default: this script's :data:`HOOK`) put in
    before the stall test of its loop: a module of its own, ``EDGE[0]`` the sweeps (also
    used by ``adaptive_sweeps_in_pk.py`` with its own hook)."""
    import importlib.util
    src = (ROOT / "roughfe" / "bem" / "pk.py").read_text()
    anchor = "        if watch is not None and watch.stalled(res):\n"
    assert src.count(anchor) == 1, "pk.py changed: put the hook in again"
    src = src.replace(anchor, (HOOK if hook is None else hook) + anchor).replace(
        "def polonsky_keer(", "EDGE = [None]\n\n\ndef polonsky_keer(", 1)
    spec = importlib.util.spec_from_loader(f"roughfe.bem._{name}", loader=None)
    mod = importlib.util.module_from_spec(spec)
    mod.__package__ = "roughfe.bem"
    exec(compile(src, name, "exec"), mod.__dict__)
    return mod


def run(n, hurst, seed, loads, sweeps_on):
    """Passes (sweeps counted), sweeps, CPU and pressures of cold solves at ``loads``."""
    import roughfe.bem.contact as contact
    from roughfe.bem import Material, solve_contact
    from roughfe.surfaces.spectral import spectral_surface
    pk = hooked_pk()
    made = []

    def solver(apply, b, *args, **kw):
        fine = b.size == n * n and kw.get("tol", 1.0) < SWEEP_UNTIL and \
            kw.get("mean_pressure") is not None and kw.get("deflation") is not None
        pk.EDGE[0] = EdgeSweeps(b.shape, _kernel()) if sweeps_on and fine else None
        if pk.EDGE[0] is not None:
            made.append(pk.EDGE[0])
        try:
            return pk.polonsky_keer(apply, b, *args, **kw)
        finally:
            pk.EDGE[0] = None

    contact.polonsky_keer = solver
    s = spectral_surface(n, 1.0, hurst, rms_slope=1.0, rng=seed)
    out = []
    for pm in loads:
        made.clear()
        c0 = time.process_time()
        r = solve_contact(s, Material(1.0, 0.0), mean_pressure=pm, solver="pk", tol=1e-10,
                          compute_stiffness=False)
        out.append((r.nit, sum(m.count for m in made), time.process_time() - c0, r.pressure))
    return out


def case_parser(description) -> argparse.ArgumentParser:
    """The options of a measured case: --n, --hurst, --seeds, --loads (also used by
    adaptive_sweeps_in_pk.py)."""
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("--n", type=int, nargs="+", default=[1024])
    ap.add_argument("--hurst", type=float, default=0.5)
    ap.add_argument("--seeds", type=int, nargs="+", default=[1])
    ap.add_argument("--loads", type=float, nargs="+", default=[0.005, 0.01, 0.05, 0.1])
    return ap


def main(argv=None) -> int:
    a = case_parser(__doc__.splitlines()[0]).parse_args(argv)
    if _kernel() is None:       # a research script: nothing to measure is no failure
        print("numba is not importable: nothing to measure")
        return 0
    for n in a.n:
        for seed in a.seeds:
            base = run(n, a.hurst, seed, a.loads, False)
            swept = run(n, a.hurst, seed, a.loads, True)
            for pm, (n0, _, c0, p0), (n1, k1, c1, p1) in zip(a.loads, base, swept):
                print(f"n={n} H={a.hurst} seed={seed} p/E*={pm}: without {n0} passes "
                      f"{c0:.2f} s; with {n1} passes ({k1} sweeps) {c1:.2f} s; same contact "
                      f"set {bool(np.array_equal(p0 > 0, p1 > 0))}, max|dp|/max p "
                      f"{np.abs(p0 - p1).max() / p0.max():.1e}", flush=True)
            print(f"TOTAL n={n} H={a.hurst} seed={seed}: without {sum(b[0] for b in base)}, "
                  f"with {sum(s[0] for s in swept)} passes", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
