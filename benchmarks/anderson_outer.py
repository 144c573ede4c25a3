"""Research script (issue 16 section 1; not in the package, not in ``make bench``): an
Anderson-accelerated outer loop for the periodic, load-controlled frictionless BEM
contact, measured against the production solver (``solve_contact``, coarse start and
two-level PK) in round 2, session 38 (docs/theory/02b_bem_performance.md, "An
Anderson-accelerated outer loop, measured").

The fixed-point maps x = G(x) accelerated by the package's type-II Anderson
(``roughfe.optim.anderson.anderson_fixed_point``, memory m, mixing beta; its own stopping
test is switched off: the loop ends on PK's KKT residual, below):

richardson  the projected preconditioned Richardson step. The iterate x is first made
            admissible, p = max(x, 0) rescaled to the load (mean p = P: the safeguard of
            an extrapolated iterate), then u = H p, Delta = the mean gap over
            S = {p > 0} (PK's load multiplier) and

                G(x) = proj(p - omega M (H p - h - Delta)),  M = E*|q|/2 (production's),

            proj the same clip and rescale. ``--mask free`` (default) applies M to the
            gradient restricted to PK's free set F = S + {p = 0, gap < Delta} with zero
            mean on F and moves only F (PK's direction without conjugation); ``--mask
            none`` the literal step on the whole grid. ``--line-search``: omega is the
            exact minimiser of the energy along the direction (one more product).
            A G evaluation: 1 product with H and 1 with M (+1 with the line search).
natural     the same step in the unprojected variable y (p = max(y, 0) rescaled): G
            returns p - omega z unclipped on F and -kappa w / (H)_ii on the open points
            (w > 0, p = 0), so that the iterate keeps their gaps (a fixed point y* has
            max(y*, 0) = p* and y* = -kappa w* / H_ii off the contact) and the
            extrapolation sees points approach the contact; the clipped map's iterate is
            0 there whatever the gap.
pk          G(x) = k iterations of ``roughfe.bem.pk.polonsky_keer`` from ``initial`` = x
            (the production options: float32 products and M, ``--deflation`` the
            production two-level ``BlockDeflation`` with its split line search, a fresh
            one per call); PK clips and rescales x itself (the safeguard). A call costs
            its k iterations plus its start u = H p and the final u = H p it returns.
            The loop stops as soon as a call converges (PK's own test).

The KKT residual is PK's (``roughfe.bem.solvers.relative_residual``: max(sum p |w| /
(sum p scale), largest interpenetration / scale), scale = ptp h), evaluated on the
admissible p of every G evaluation (its H p is G's own product), tol 1e-10. A run counts
only if its contact fraction A* equals production's to 1e-6 relative (reported with
max |p - p*| / max p*).

``--restart x`` clears the memory (through ``RejectedIterate``: the plain step G(x_k) is
taken instead, at no product) when an extrapolated iterate's contact set differs from
that of the last plain step in more than a fraction x of its points.

Counts: convolution-equivalents, every product with H (float32 or float64, split line
search included) or M on the fine grid is 1; the production coarse start is counted from
its PK calls (``benchmarks/_pk_log.py``) and added to every variant (all start from it);
production's total likewise (``fas_pressure.production``). Not counted: Anderson's own
work on the grid (``anderson_fixed_point`` copies its history into arrays, about 5 m
full-grid passes an evaluation, and solves an n x m least squares, 2 n m^2 flops; at
2048^2, m = 20: 676 s CPU, half of it system time, and 4.4 GB against production's 13 s). Baselines printed with each run:
production (its fine PK iterations and, where the two-level correction runs, the points
off its final contact set at every fine iteration, read by wrapping
``BlockDeflation.correct``), the production solve with ``coarse_correction=False`` (plain
preconditioned PK), and with ``--plain-trace j`` the points off the final set after j, 2j,
... iterations of the plain PK from production's coarse start.

Measured (session 38; H = 0.5 seed 1, one load p/E* = 0.05, E* = 1, tol 1e-10, every
converged run's A* equal to production's, max |p - p*| / max p* <= 5e-9): the clipped
Richardson map needs omega ~ 0.2 and m ~ 10 (512^2: 75 evaluations, 162.8 conv-eq
against production's 48 iterations, 132.8), 2.34x production at 1024^2; the restart rule
and the literal whole-grid step did not converge; k PK iterations per G (k = 2-10) were
5-20x production and did not reach 1e-10 in 100-200 calls. The unprojected map with m =
20 (omega 0.2, kappa 0.3): 44 / 55 / 78 evaluations, 100.8 / 126.6 / 173.3 conv-eq at
512^2 / 1024^2 / 2048^2 (0.76x / 1.27x / 1.52x production; plain PK 48 / 62 / 86
iterations), growth 1.25x and 1.42x per doubling; its contact set is final after 27 /
38 / 54 evaluations (plain PK after about 25-28 / 33-36 / 61-66 iterations, production
22 / 23 of 26 / 31). 4 loads p/E* = 0.005, 0.01, 0.05, 0.1 at 1024^2 / 2048^2: 205 / 278
evaluations, 465.4 / 614.6 conv-eq against production's 95 / 113 iterations, 355.4 /
415.6 conv-eq (1.31x / 1.48x; plain PK 210 / 294 iterations, 584.4 / 863.1); growth
1.356x (production 1.189x, plain PK 1.400x).

Usage (from the repository root; the runs of session 38)::

    nice -n 10 .venv/bin/python benchmarks/anderson_outer.py --n 512 --map richardson \\
        --memory 10 --omega 0.2 --max-eval 400
    nice -n 10 .venv/bin/python benchmarks/anderson_outer.py --n 512 --map pk --k 3 \\
        --memory 5 --max-eval 200
    nice -n 10 .venv/bin/python benchmarks/anderson_outer.py --n 512 1024 2048 \\
        --map natural --memory 20 --omega 0.2 --kappa 0.3 --max-eval 300
    nice -n 10 .venv/bin/python benchmarks/anderson_outer.py --n 1024 --map natural \\
        --memory 20 --omega 0.2 --kappa 0.3 --load 0.005 0.01 0.05 0.1
    nice -n 10 .venv/bin/python benchmarks/anderson_outer.py --n 2048 --map natural \\
        --memory 20 --omega 0.2 --kappa 0.3 --load 0.1 0.005 0.01
    nice -n 10 .venv/bin/python benchmarks/anderson_outer.py --n 2048 --skip-aa \\
        --plain-trace 6
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
sys.path.insert(0, str(HERE))

from fas_pressure import CALLS, MAT, TOL, Counter, production  # noqa: E402
from roughfe.bem import solve_contact  # noqa: E402
from roughfe.bem.coarse_start import _coarse_start  # noqa: E402
from roughfe.bem.contact import _cg_preconditioner, _operator, _pk  # noqa: E402
from roughfe.bem.deflation import BlockDeflation  # noqa: E402
from roughfe.bem.pk import polonsky_keer  # noqa: E402
from roughfe.bem.solvers import relative_residual  # noqa: E402
from roughfe.errors import NoConvergenceError  # noqa: E402
from roughfe.optim.anderson import RejectedIterate, anderson_fixed_point  # noqa: E402
from roughfe.surfaces.spectral import spectral_surface  # noqa: E402
from roughfe.writers import write_json  # noqa: E402


class Converged(Exception):
    """Raised inside G when the admissible iterate meets the KKT tolerance."""

    def __init__(self, p):
        super().__init__()
        self.p = p


def admissible(x, load):
    """max(x, 0) rescaled to mean p = load (the safeguard of an extrapolated iterate)."""
    p = np.maximum(x, 0.0)
    s = float(p.mean())
    return p * (load / s) if s > 0 else np.full_like(p, load)


def kkt(p, u, h, scale):
    """PK's relative KKT residual of p with u = H p (load control, no hardness) and its
    Delta (the mean gap over S = {p > 0})."""
    g = u - h
    S = p > 0
    d = float(g[S].mean())
    comp = float(np.dot(p[S], np.abs(g[S] - d)))
    feas = max(0.0, d - float(g.min()))
    return float(relative_residual(comp, feas, float(p.sum()), scale)), d, g


class Problem:
    """One surface and load: counted operators and the trace of the loop."""

    def __init__(self, surface, load, touch):
        self.touch = touch       # production's contact set (the wrong points' reference)
        self.h = np.ascontiguousarray(surface.heights)
        self.n = self.h.shape[0]
        self.load = float(load)
        self.scale = float(np.ptp(self.h))
        self.op = _operator(surface.shape, surface.size, MAT.E_star, "spectral")
        self.counter = Counter(self.n)
        w = self.counter.wrap
        self.apply = w(self.op.apply_unchecked)
        self.apply_single = w(lambda x, out=None, work=None:
                              self.op.apply_unchecked(x, True, out, work))
        self.precond = w(_cg_preconditioner(self.op))
        self.split = w(self.op.split_product)
        self.evaluations = 0
        self.restarts = 0
        self.plain = None        # the contact set of the last G(x) (--restart)
        # (evaluation, conv-eq, residual, contact points, points off production's set)
        self.trace = []

    def log(self, res, p):
        self.evaluations += 1
        self.trace.append((self.evaluations, self.counter.conv, res,
                           int(np.count_nonzero(p)),
                           int(np.count_nonzero((p > 0) != self.touch))))

    def guard(self, p, restart):
        """--restart: refuse (RejectedIterate: the memory is cleared and the plain step
        G(x_k) taken) an extrapolated p whose contact set differs from that of the last
        plain step G(x_{k-1}) in more than ``restart`` of its points (no product spent)."""
        if restart is None or self.plain is None:
            return
        if np.count_nonzero((p > 0) != self.plain) > restart * np.count_nonzero(self.plain):
            self.restarts += 1
            raise RejectedIterate

    def richardson(self, omega, mask, line_search, restart, kappa=None):
        """G of the projected preconditioned Richardson step (module docstring); with
        ``kappa`` the unprojected form (--map natural)."""
        def G(x):
            p = admissible(x, self.load)
            self.guard(p, restart)
            u = self.apply(p)
            res, d, g = kkt(p, u, self.h, self.scale)
            self.log(res, p)
            if res <= TOL:
                raise Converged(p)
            g -= d
            F = (p > 0) | (g < 0)
            open_gap = None if kappa is None else g[~F] * (kappa / self.op.diagonal)
            if mask == "free":
                g[~F] = 0.0
                g[F] -= g[F].mean()
                z = np.asarray(self.precond(g.astype(np.float32)), dtype=float)
                z[~F] = 0.0
                z[F] -= z[F].mean()
            else:
                z = np.asarray(self.precond(g.astype(np.float32)), dtype=float)
            step = omega
            if line_search:
                step *= float(np.dot(g.ravel(), z.ravel())) / float(
                    np.dot(z.ravel(), self.apply(z).ravel()))
            if kappa is None:
                out = admissible(p - step * z, self.load)
            else:        # y: unclipped on F, -kappa w / H_ii on the open points
                out = p - step * z
                out[~F] = -open_gap
            self.plain = out > 0
            return out
        return G

    def pk(self, k, deflation, restart):
        """G of k production PK iterations from x (module docstring)."""
        def G(x):
            start = np.array(x, dtype=float)
            self.guard(admissible(start, self.load), restart)
            defl = BlockDeflation(self.op, 8) if deflation else None
            try:
                out = polonsky_keer(self.apply, self.h, self.scale, initial=start,
                                    diagonal=self.op.diagonal, tol=TOL,
                                    precond=self.precond, overwrite_initial=True,
                                    max_iter=k, offset=-float(self.h.max()),
                                    apply_single=self.apply_single,
                                    mean_pressure=self.load, deflation=defl,
                                    split=self.split if deflation else None)
                converged = True
            except NoConvergenceError as exc:
                out, converged = exc.result, False
            self.log(float(out.residual), out.pressure)
            if converged:
                raise Converged(out.pressure)
            self.plain = out.pressure > 0
            return np.asarray(out.pressure, dtype=float)
        return G


def production_settled(surface, load, touch):
    """The fine PK iteration from which production's contact set is its final one for
    good: production solved again with ``BlockDeflation.correct`` wrapped to read the
    pressure it is given at every fine iteration (None where the solve has no two-level
    correction, e.g. 512^2)."""
    seen = []
    original = BlockDeflation.correct

    def correct(self, F, gF, zF, apply_free, free_mask=None, pressure=None):
        if pressure.size == touch.size:       # the fine grid (not the coarse start's)
            seen.append(int(np.count_nonzero((pressure.reshape(touch.shape) > 0)
                                             != touch)))
        return original(self, F, gF, zF, apply_free, free_mask=free_mask,
                        pressure=pressure)

    BlockDeflation.correct = correct
    try:
        r = production(surface, load)[0]
    finally:
        BlockDeflation.correct = original
    if not seen:
        return None, []
    wrong = seen + [int(np.count_nonzero((r.pressure > 0) != touch))]
    k = len(wrong)
    while k > 0 and wrong[k - 1] == 0:
        k -= 1
    return k + 1, wrong


def plain_production(surface, load):
    """solve_contact without the two-level correction (``coarse_correction=False``; the
    coarse start kept): (iterations, conv-eq), the baseline of a loop without one."""
    CALLS.clear()
    r = solve_contact(surface, MAT, mean_pressure=load, solver="pk", tol=TOL,
                      compute_stiffness=False, coarse_correction=False)
    n2 = surface.heights.size
    return int(r.nit), sum(m / n2 * k for m, k, _ in CALLS)


def plain_settled(surface, load, touch, step):
    """Points off production's contact set after j = step, 2 step, ... iterations of the
    plain production PK (``roughfe.bem.contact._pk`` without the two-level correction,
    from the production coarse start, ``max_iter`` = j: PK is deterministic, so the
    pressure returned after j iterations is that of the j-th iteration of the full
    solve): [(j, wrong points)] up to convergence."""
    h = np.ascontiguousarray(surface.heights)
    op = _operator(surface.shape, surface.size, MAT.E_star, "spectral")
    p0 = _coarse_start(surface, MAT, load, None, kernel="spectral")
    rows, j = [], step
    while True:
        try:
            out = _pk(op, h, float(h.max()), float(np.ptp(h)), TOL, j, p0.copy(), True,
                      None, mean_pressure=load)
            done = True
        except NoConvergenceError as exc:
            out, done = exc.result, False
        rows.append((int(out.nit) if done else j,
                     int(np.count_nonzero((out.pressure > 0) != touch))))
        if done:
            return rows
        j += step


def settled(trace):
    """The first evaluation from which the contact set is production's for good."""
    k = len(trace)
    while k > 0 and trace[k - 1][4] == 0:
        k -= 1
    return None if k == len(trace) else k + 1


def run(n, hurst, seed, load, a):
    surface = spectral_surface(n, 1.0, hurst, rms_slope=1.0, rng=seed)
    ref, ref_conv, ref_nit, ref_cpu = production(surface, load)
    p_ref = ref.pressure
    a_ref = float(np.count_nonzero(p_ref)) / p_ref.size
    print(f"{n}^2 H={hurst} seed={seed} p/E*={load}: production {ref_nit} iterations, "
          f"{ref_conv:.1f} conv-eq, {ref_cpu:.1f} s CPU, A* {a_ref:.6f}", flush=True)
    ref_settled, ref_wrong = production_settled(surface, load, p_ref > 0)
    print(f"  production's contact set settled at iteration {ref_settled}; points off "
          f"it by iteration: {ref_wrong}", flush=True)
    plain_nit, plain_conv = plain_production(surface, load)
    print(f"  production without the two-level correction: {plain_nit} iterations, "
          f"{plain_conv:.1f} conv-eq", flush=True)
    plain_wrong = (plain_settled(surface, load, p_ref > 0, a.plain_trace)
                   if a.plain_trace else None)
    if plain_wrong:
        print(f"  plain PK (iteration, points off the final set): {plain_wrong}",
              flush=True)
    if a.skip_aa:
        return {"n": n, "hurst": hurst, "seed": seed, "load": load,
                "production": {"iterations": ref_nit, "conv_eq": ref_conv,
                               "settled_at": ref_settled, "wrong": ref_wrong},
                "plain_production": {"iterations": plain_nit, "conv_eq": plain_conv,
                                     "wrong": plain_wrong}}
    prob = Problem(surface, load, p_ref > 0)
    CALLS.clear()
    p0 = _coarse_start(surface, MAT, load, None, kernel="spectral")
    start_conv = sum(m / n ** 2 * k for m, k, _ in CALLS)
    prob.counter.conv += start_conv
    G = (prob.pk(a.k, a.deflation, a.restart) if a.map == "pk" else
         prob.richardson(a.omega, a.mask, a.line_search, a.restart,
                         a.kappa if a.map == "natural" else None))
    c0 = time.process_time()
    p, status = None, "max_iter"
    try:
        anderson_fixed_point(G, p0, tol=1e-300, max_iter=a.max_eval, memory=a.memory,
                             relaxation=a.beta, backoff=0)
        status = "rejected"      # only reached if G refused the plain step
    except Converged as c:
        p, status = c.p, "converged"
    cpu = time.process_time() - c0
    res = [t[2] for t in prob.trace]
    row = {"n": n, "hurst": hurst, "seed": seed, "load": load, "map": a.map,
           "memory": a.memory, "kappa": a.kappa if a.map == "natural" else None,
           "beta": a.beta, "omega": a.omega, "mask": a.mask,
           "line_search": a.line_search, "k": a.k, "deflation": a.deflation,
           "restart": a.restart, "restarts": prob.restarts,
           "production": {"iterations": ref_nit, "conv_eq": ref_conv, "cpu_s": ref_cpu,
                          "area_fraction": a_ref, "settled_at": ref_settled,
                          "wrong": ref_wrong},
           "plain_production": {"iterations": plain_nit, "conv_eq": plain_conv,
                                "wrong": plain_wrong},
           "start_conv_eq": start_conv, "status": status, "evaluations": prob.evaluations,
           "conv_eq": prob.counter.conv, "cpu_s": cpu, "best_residual": min(res),
           "settled_at": settled(prob.trace), "trace": prob.trace}
    if p is not None:
        area = float(np.count_nonzero(p)) / p.size
        row["area_fraction"] = area
        row["area_match"] = abs(area - a_ref) <= 1e-6 * a_ref
        row["max_dp"] = float(np.max(np.abs(p - p_ref)) / p_ref.max())
    ratio = prob.counter.conv / ref_conv
    print(f"  AA({a.map}) {status}: {prob.evaluations} G evaluations, "
          f"{prob.counter.conv:.1f} conv-eq ({ratio:.2f}x production; start "
          f"{start_conv:.1f}), best residual {min(res):.2e}, {cpu:.1f} s CPU, contact "
          f"set settled at evaluation {row['settled_at']}, {prob.restarts} restarts"
          + (f", A* {row['area_fraction']:.6f} match {row['area_match']}, "
             f"max|dp|/max p* {row['max_dp']:.1e}" if p is not None else ""), flush=True)
    for t in prob.trace[:: max(1, len(prob.trace) // a.show)]:
        print(f"    eval {t[0]:4d}: {t[1]:7.1f} conv-eq, residual {t[2]:.2e}, "
              f"contact points {t[3]}, wrong {t[4]}", flush=True)
    return row


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, nargs="+", default=[512, 1024])
    ap.add_argument("--hurst", type=float, default=0.5)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--load", type=float, nargs="+", default=[0.05])
    ap.add_argument("--map", choices=("richardson", "natural", "pk"), default="richardson")
    ap.add_argument("--kappa", type=float, default=1.0,
                    help="--map natural: y = -kappa w / H_ii on the open points")
    ap.add_argument("--memory", type=int, default=10, help="Anderson memory m")
    ap.add_argument("--beta", type=float, default=1.0, help="Anderson mixing")
    ap.add_argument("--omega", type=float, default=1.0, help="Richardson step")
    ap.add_argument("--mask", choices=("free", "none"), default="free")
    ap.add_argument("--line-search", action="store_true")
    ap.add_argument("--k", type=int, default=3, help="PK iterations per G (--map pk)")
    ap.add_argument("--deflation", action="store_true",
                    help="PK with the production two-level correction (--map pk)")
    ap.add_argument("--restart", type=float, default=None,
                    help="clear the memory when an extrapolated iterate's contact set "
                         "differs from the last plain step's in more than this fraction")
    ap.add_argument("--plain-trace", type=int, default=0,
                    help="trace the plain PK's contact set every this many iterations")
    ap.add_argument("--skip-aa", action="store_true",
                    help="the baselines only (production, plain PK and its trace)")
    ap.add_argument("--max-eval", type=int, default=400)
    ap.add_argument("--show", type=int, default=12, help="trace lines printed")
    ap.add_argument("--output", type=Path, default=None)
    a = ap.parse_args(argv)
    if min(a.n) < 256:      # the maps start from the production coarse start (2D grids)
        ap.error(f"--n {min(a.n)}: the maps start from the production coarse start, "
                 f"which needs at least 256 points per axis")
    rows = [run(n, a.hurst, a.seed, pm, a) for n in a.n for pm in a.load]
    if a.output is not None:
        write_json(a.output, rows)          # atomic (the house rule for results)
    return 0


if __name__ == "__main__":
    sys.exit(main())
