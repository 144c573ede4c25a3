"""Research script (issue 16 section 1; not in the package, not in ``make bench``):
ADAPTIVE load-conserving window sweeps of the contact edges inside the Polonsky-Keer CG.

The sweeps are those of ``benchmarks/edge_sweeps_in_pk.py`` (4 x 4 windows holding a
contact edge, each solved at its own load by 2 local PK iterations with the exact 16 x 16
block of the periodic operator, the tiling shifted by 2 on alternate sweeps; one product
H dp per sweep, the exact step clipped to [0, 1], p back to the load, a CG restart).
Every sweep made counts as a pass (an iteration) of the solve, as there: the hook
``continue``-s the PK loop, so ``nit`` counts it. The hook goes into a copy of
``roughfe/bem/pk.py`` at run time (the package is not changed).

Measured per pass (``--modes probe --log``; E = sum p (u/2 - h), the energy at the load,
one full-grid pass): a sweep's energy decrease, predicted BEFORE its product from the
windows' own 16 x 16 blocks, is within ~10 % of the actual one. Against the decrease of
the CG step taken in its place, the prediction is 0.72-0.82 on H = 0.5 surfaces and
0.44-0.58 on H = 0.8 ones (1024^2, 2048^2, seeds 1-2, 4 loads; first pass), and it is
the start sweeps that pay (3 sweeps before the first CG iteration only: H = 0.5 seed 1
95/113 -> 93/104; H = 0.8 87/99 -> 92/107), not the periodic ones. A per-pass rule
(sweep when the prediction beats the last CG step) sweeps about once per solve: H = 0.5
93/108, H = 0.8 89/100.

THE RULE (``--modes coarse``): the coarse-start level one below the fine grid (n/2,
solved anyway to 1e-4) is probed: before its first CG iteration the window kernel
predicts a sweep's decrease D_s (CPU only, no product, no pass), and that iteration's
actual decrease D_cg is measured. If rho = D_s / D_cg >= THETA (0.65), the fine solve
makes START_SWEEPS (3) sweeps before its first CG iteration, and none after; otherwise
it is the production solve, pass for pass. Cost: one product and one kernel run at the
n/2 level, two energy passes there; no pass of any level.

Usage (from the repository root; numba: Debian's python3-numba)::

    .venv/bin/python benchmarks/adaptive_sweeps_in_pk.py --n 1024 2048 --hurst 0.5 \
        --seeds 1 2 --modes prod coarse
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(HERE))

import edge_sweeps_in_pk as edge  # noqa: E402  (the window kernel and its schedule)

#: the rule's knobs (see ``Adaptive``)
#: the coarse-probe rule: sweeps at the start of the fine solve when, one level down,
#: the predicted decrease of a sweep is at least THETA x that of the first CG step
THETA = 0.65
START_SWEEPS = 3
KAPPA = 1.0          # a sweep must be predicted to lower the energy KAPPA x the last CG step
SWEEP_UNTIL = edge.SWEEP_UNTIL
MIN_SIDE = edge.MIN_SIDE

_NB = {}


def _compiled():
    """(energy, local curvature) numba functions, compiled on first use."""
    if not _NB:
        import numba
        jit = numba.njit(cache=True, fastmath=False, boundscheck=False)
        _NB.update(energy=jit(_energy_py), curv=jit(_local_curv_py))
    return _NB


def _energy_py(p, u, us, b):  # pragma: no cover - compiled
    """sum p (us u / 2 - b) over p > 0: the energy of Eq. 2.5 at the load (the approach
    term is constant at a fixed load)."""
    acc = 0.0
    for i in range(p.size):
        if p[i] > 0:
            acc += p[i] * (0.5 * us * np.float64(u[i]) - b[i])
    return acc


def _local_curv_py(A, dp, n0, n1, off):  # pragma: no cover - compiled
    """sum over the 4 x 4 windows (tiling shifted by ``off``) of dp_w^T A dp_w: the
    curvature of the sweep's change without the windows' mutual far field."""
    b = 4
    v = np.empty(16)
    acc = 0.0
    for I in range(n0 // b):
        for J in range(n1 // b):
            nz = False
            for r in range(b):
                row = ((I * b + off + r) % n0) * n1
                for s in range(b):
                    x = row + (J * b + off + s) % n1
                    v[r * b + s] = dp[x]
                    if dp[x] != 0.0:
                        nz = True
            if not nz:
                continue
            for j in range(16):
                vj = v[j]
                if vj == 0.0:
                    continue
                for i in range(16):
                    acc += np.float64(A[j, i]) * vj * v[i]
    return acc


def _decrease(slope, curv):
    """Energy decrease of the exact step along a change with ``slope`` and ``curv``,
    the step clipped to [0, 1] (as the sweep's step is)."""
    if slope >= 0 or curv <= 0:
        return 0.0
    s = min(1.0, -slope / curv)
    return -(s * slope + 0.5 * s * s * curv)


class Adaptive:
    """The sweeps of one fine solve under the adaptive rule.

    Every pass of the PK loop (while the KKT residual is above ``SWEEP_UNTIL``) first
    measures the energy E = sum p (u/2 - h) of its iterate (one full-grid pass, no
    product), so the decrease each pass (CG iteration or sweep) achieved is known
    exactly, clips and load rescalings included. Then (``rule``):

    * ``"energy"``: the window kernel computes the sweep's change dp (CPU only) and its
      predicted decrease D_sweep (local curvature: each window's own 16 x 16 block). The
      sweep is made (one product H dp, a pass) only if D_sweep > KAPPA * D_ref, with
      D_ref the decrease of the last pass (a CG iteration or, just after a sweep, that
      sweep); the very first pass of a solve is a sweep (nothing to compare with; the
      coarse start leaves most of the pixel-scale edges to settle). After ``patience``
      consecutive refused sweeps the kernel is run only every ``patience``-th pass (the
      CPU of a kernel that keeps saying no).
    * ``"fixed"``: the schedule of ``edge_sweeps_in_pk.py`` (for the comparison and the
      logs).

    ``count``: sweeps made (passes); ``log``: per pass (k, res, kind, decrease, predicted
    sweep decrease or nan)."""

    def __init__(self, shape, kernel, rule="energy", kappa=KAPPA, restart=True,
                 patience=3, verbose=False):
        self.shape, self.kernel = tuple(int(n) for n in shape), kernel
        self.rule, self.kappa, self.restart = rule, kappa, restart
        self.patience = patience
        self.verbose = verbose
        self.block = None
        self.count = 0
        self.E_prev = None
        self.last = None          # kind of the last pass: "cg" or "sweep"
        self.last_dec = None
        self.refused = 0
        self.calls = 0
        self.kernel_runs = 0
        self.cpu_kernel = 0.0
        self.log = []
        self.pred = np.nan
        self.probe = False
        self._go = False
        self.n_start = START_SWEEPS
        self._fixed = edge.EdgeSweeps(shape, kernel) if rule == "fixed" else None

    # -- bookkeeping -------------------------------------------------------------------
    def observe(self, it, res, p, u, us, b):
        """The energy of this iterate; the decrease of the last pass."""
        E = float(_NB["energy"](p, u, float(us), b))
        if self.E_prev is not None:
            self.last_dec = self.E_prev - E
            self.log.append((it - 1, self.last, self.last_dec, self.pred, res))
        self.E_prev = E
        self.last = "cg"
        self.pred = np.nan

    def due(self, k, res):
        """Is the kernel to be run (a candidate sweep) before this pass?"""
        self.calls += 1
        if self.rule == "fixed":
            self._go = self._fixed.due(k, res)
            return self._go or self.probe
        if self.rule == "probe1":
            return self.calls == 1
        if self.rule == "start":
            return k == 0 and self.count < self.n_start
        if self.last_dec is None:
            return True
        if self.refused >= self.patience:
            return self.calls % self.patience == 0
        return True

    def set_block(self, response):
        n0, n1 = self.shape
        G = np.asarray(response, float).reshape(n0, n1)
        i, j = np.divmod(np.arange(16), 4)
        self.block = np.ascontiguousarray(
            G[(i[None, :] - i[:, None]) % n0, (j[None, :] - j[:, None]) % n1], np.float32)
        if self._fixed is not None:
            self._fixed.block = self.block

    def _offset(self):
        return (self.count * 2) % 4

    def changes(self, p, u, h, out):
        """dp into ``out`` and (slope, predicted decrease), or None (no edge window)."""
        c0 = time.process_time()
        out.fill(0.0)
        n0, n1 = self.shape
        off = self._offset()
        solved, slope = self.kernel(self.block, p, u, h, n0, n1, off, edge.INNER, out)
        self.kernel_runs += 1
        if not solved:
            self.cpu_kernel += time.process_time() - c0
            return None
        curv = float(_NB["curv"](self.block, out, n0, n1, off))
        self.cpu_kernel += time.process_time() - c0
        self.pred = _decrease(float(slope), curv)
        return float(slope), self.pred

    def pays(self, pred):
        """The rule: is the predicted sweep worth its product?"""
        if self.rule == "fixed":
            return self._go
        if self.rule in ("never", "probe1"):
            return False
        if self.rule == "start":
            return True
        if self.last_dec is None:
            return True
        ok = pred > self.kappa * self.last_dec
        self.refused = 0 if ok else self.refused + 1
        return ok

    def curvature(self, dp, hdp):
        return float(edge._COMPILED["dot"](dp, hdp))

    def made(self):
        self.count += 1
        self.last = "sweep"
        if self._fixed is not None:
            self._fixed.made()

    def missed(self):
        if self.rule == "start":
            self.n_start = self.count
        if self._fixed is not None:
            self._fixed.missed()




def hooked_pk():
    """``roughfe.bem.pk`` with this script's hook (``EDGE[0]`` the controller)."""
    return edge.hooked_pk(edge.HOOK, "pk_adaptive")


_PK = []


def run(n, hurst, seed, loads, mode, kappa=KAPPA, restart=True, patience=3, log=False,
        theta=THETA, n_start=START_SWEEPS):
    """Per load: (passes, sweeps, CPU s, A*, mean gap, pressure, controller) of cold solves.
    ``mode``: "prod" (the package's solver through the same hooked copy, no controller),
    "fixed" (edge_sweeps_in_pk's schedule) or "adaptive"."""
    import roughfe.bem.contact as contact
    from roughfe.bem import Material, solve_contact
    from roughfe.surfaces.spectral import spectral_surface
    if not _PK:
        _PK.append(hooked_pk())
    pk = _PK[0]
    kernel = edge._kernel()
    _compiled()
    made = []
    probe = {}

    def solver(apply, b, *args, **kw):
        fine = (b.size == n * n and n >= MIN_SIDE and kw.get("tol", 1.0) < SWEEP_UNTIL
                and kw.get("mean_pressure") is not None and kw.get("deflation") is not None)
        ctl = None
        if mode == "coarse" and b.size * 4 == n * n and kw.get("mean_pressure") is not None:
            # one level down: the first CG step's decrease against a sweep's prediction
            ctl = Adaptive(b.shape, kernel, rule="probe1")
            ctl.until = 0.0
            pk.EDGE[0] = ctl
            try:
                return pk.polonsky_keer(apply, b, *args, **kw)
            finally:
                pk.EDGE[0] = None
                k, kind, dec, pred, _ = ctl.log[0] if ctl.log else (0, "", 0.0, 0.0, 0)
                probe["rho"] = pred / dec if dec > 0 else 0.0
                probe["kcpu"] = ctl.cpu_kernel
        if mode == "coarse" and fine:
            rho = probe.pop("rho", 0.0)
            if rho >= theta:
                ctl = Adaptive(b.shape, kernel, rule="start")
                ctl.n_start = n_start
                ctl.until = SWEEP_UNTIL
                ctl.rho = rho
                ctl.cpu_kernel += probe.pop("kcpu", 0.0)
                made.append(ctl)
            else:
                probe["skipped"] = rho
        elif mode != "prod" and fine:
            ctl = Adaptive(b.shape, kernel, rule={"fixed": "fixed", "probe": "never"}.get(
                               mode, "energy"),
                           kappa=kappa, restart=restart, patience=patience)
            ctl.until = SWEEP_UNTIL
            ctl.probe = log
            made.append(ctl)
        pk.EDGE[0] = ctl
        try:
            return pk.polonsky_keer(apply, b, *args, **kw)
        finally:
            pk.EDGE[0] = None

    old = contact.polonsky_keer
    contact.polonsky_keer = solver
    try:
        s = spectral_surface(n, 1.0, hurst, rms_slope=1.0, rng=seed)
        out = []
        for pm in loads:
            made.clear()
            probe.clear()
            c0 = time.process_time()
            r = solve_contact(s, Material(1.0, 0.0), mean_pressure=pm, solver="pk",
                              tol=1e-10, compute_stiffness=False)
            cpu = time.process_time() - c0
            area = float(np.count_nonzero(r.pressure > 0)) / r.pressure.size
            out.append(dict(nit=int(r.nit), sweeps=sum(m.count for m in made), cpu=cpu,
                            area=area, gap=float(r.mean_gap) if hasattr(r, "mean_gap")
                            else float("nan"), pressure=r.pressure,
                            ctl=made[0] if made else None,
                            kcpu=sum(m.cpu_kernel for m in made),
                            kruns=sum(m.kernel_runs for m in made),
                            rho=made[0].rho if made and hasattr(made[0], "rho") else
                            probe.get("skipped", float("nan"))))
        return out
    finally:
        contact.polonsky_keer = old


def main(argv=None) -> int:
    ap = edge.case_parser(__doc__.splitlines()[0])
    ap.add_argument("--modes", nargs="+", default=["prod", "coarse"],
                    help="prod, coarse (the rule), adaptive (per-pass energy rule), "
                         "fixed (edge_sweeps_in_pk schedule), probe (prod + logs)")
    ap.add_argument("--kappa", type=float, default=KAPPA)
    ap.add_argument("--patience", type=int, default=3)
    ap.add_argument("--no-restart", action="store_true")
    ap.add_argument("--theta", type=float, default=THETA, help="mode coarse: threshold")
    ap.add_argument("--n-start", type=int, default=START_SWEEPS,
                    help="mode coarse: start sweeps when the probe says they pay")
    ap.add_argument("--log", action="store_true", help="print every pass's decrease")
    ap.add_argument("--start", type=int, default=edge.START_SWEEPS,
                    help="mode fixed: sweeps at the start")
    ap.add_argument("--every", type=int, default=edge.EVERY,
                    help="mode fixed: then one before every EVERY-th CG iteration")
    a = ap.parse_args(argv)
    edge.START_SWEEPS, edge.EVERY = a.start, a.every
    if edge._kernel() is None:
        print("numba is not importable: nothing to measure")
        return 0
    for n in a.n:
        for seed in a.seeds:
            res = {m: run(n, a.hurst, seed, a.loads, m, a.kappa, not a.no_restart,
                          a.patience, a.log, a.theta, a.n_start) for m in a.modes}
            ref = res[a.modes[0]]
            for i, pm in enumerate(a.loads):
                line = [f"n={n} H={a.hurst} seed={seed} p/E*={pm}:"]
                for m in a.modes:
                    o = res[m][i]
                    same = bool(np.array_equal(o["pressure"] > 0, ref[i]["pressure"] > 0))
                    dp = np.abs(o["pressure"] - ref[i]["pressure"]).max() / \
                        ref[i]["pressure"].max()
                    line.append(f"{m} {o['nit']} ({o['sweeps']} sw, {o['kruns']} k"
                                f"{', rho %.2f' % o['rho'] if m == 'coarse' else ''}) "
                                f"{o['cpu']:.2f}s [k {o['kcpu']:.2f}s] A*={o['area']:.6f} "
                                f"gap={o['gap']:.9g} set={'=' if same else 'DIFF'} "
                                f"dp={dp:.1e};")
                print(" ".join(line), flush=True)
                if a.log:
                    for m in a.modes:
                        c = res[m][i]["ctl"]
                        if c is None:
                            continue
                        for (k, kind, dec, pred, r) in c.log:
                            print(f"   {m} pass {k:3d} {kind:5s} dec {dec:10.3e} "
                                  f"pred {pred:10.3e} res {r:8.1e}")
            tot = " ".join(f"{m} {sum(o['nit'] for o in res[m])} passes "
                           f"({sum(o['sweeps'] for o in res[m])} sw) "
                           f"{sum(o['cpu'] for o in res[m]):.1f}s" for m in a.modes)
            print(f"TOTAL n={n} H={a.hurst} seed={seed}: {tot}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
