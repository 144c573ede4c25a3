"""Research script (issue 16 section 1; not in the package, not in ``make bench``): a full
approximation scheme (FAS, nonlinear multigrid) in the PRESSURE for the periodic,
load-controlled frictionless BEM contact, with a few iterations of the production
Polonsky-Keer CG (``roughfe.bem.pk.polonsky_keer``) as the smoother on every level.
Measured in round 2, session 31 (docs/theory/02b_bem_performance.md, "A full
approximation scheme in the pressure, measured").

The problem on level l (grid m_l = n / 2^l, heights h_l: the fine heights Fourier-truncated
as in the production coarse start, ``roughfe.bem.coarse_start._coarse_surface``; H_l the
exact periodic operator of that grid; c_l = (H_l)_ii) is the nonlinear complementarity
equation, with the natural residual

    N_l(P, Delta) = min(c_l P, H_l P - h_l - Delta) = rhs_l,      mean(P) = load_l,

(Delta the load's multiplier, PK's mean gap on the contact), rhs_0 = 0. A right-hand side
rhs is a shifted contact problem, P >= rhs / c_l and H_l P - h_l - Delta >= rhs, with
complementarity; in P' = P - rhs / c_l >= 0 it is the production contact problem with the
heights b' = h_l + rhs - H_l (rhs / c_l) and the load load_l - mean(rhs / c_l), which
``polonsky_keer`` solves (and smooths) unchanged.

FAS V-cycle on level l from P: nu1 PK iterations (``polonsky_keer`` with ``max_iter`` =
nu1, plain preconditioned; its float32 products only while the level's KKT residual is
above PK's own switch, 1e-5: PK's first product of a call is float32, and that rounding
left a floor of ~1e-6 of max p); the fine residual rho = rhs_l - N_l(P);
the coarse start P_c0 = R P (full weighting, load-conserving); the coarse right-hand side
with the FAS tau correction

    rhs_{l+1} = N_{l+1}(P_c0, Delta) + R rho,      load_{l+1} = mean(P_c0),

so that the coarse problem is the nonlinear contact problem itself (its own contact set,
its own shifted obstacle) and P_c0 solves it when P solves the fine one (consistency);
the coarse problem is solved by one V-cycle (PK to ``--coarse-tol`` on the coarsest
grid); the correction P <- P + I (P_c - P_c0) (bilinear I), clipped at the level's
obstacle and rescaled to the load by PK; nu2 PK iterations. Two details make the cycle
consistent (P* stays P*; without them one cycle from production's solution moved it by
27 % of max p at 256^2): the coarse start is P_c0 except on the shifted obstacle where
N_{l+1}(P_c0) is its pressure branch (there P_c0 - rhs / c = -R rho / c is no contact
pressure, and a positive value puts a point with an open gap into PK's contact set,
whose mean gap is PK's Delta); and a point on its level's obstacle takes the prolonged
correction only where the gap predicted with the interpolated change of the coarse
displacement closes (the interpolant's small positive values did the same on the fine
grid). The cycles start from a nested iteration (FMG): the coarsest grid solved, then one
V-cycle on each finer grid from the bilinear interpolant of the coarser solution. The
fine grid's smoother is the plain preconditioned PK (no two-level correction: the coarse
levels are the coarse correction).

Counts: every product with an operator or the preconditioner (float32 or float64) is one
convolution-equivalent weighted by its grid size (a product on m^2 points = m^2 / n^2),
counted by wrapping the operators, PK's own products (its start u = H p and the final
u = H p it returns after ``max_iter``) included; so is the production solve's
(``solve_contact`` with its coarse start and two-level correction), through a wrapper of
``polonsky_keer`` (its ``n_products``). Each cycle's pressure is compared with the
production solution (max |p - p*| / max p*, contact set), and the production PK is run
from chosen cycles (``solve_contact(initial=...)``; its answer is then production's).

Variants (measured in session 31, all worse than the defaults or no better): --nu-coarse
(more PK iterations on the coarser grids), --c-factor (the scale c_l of the min),
--restrict-pressure inject, --damping, --truncate (no correction on the obstacle),
--no-correction (the smoothing alone), --start production (the production coarse start
instead of the nested iteration); --coarsest n/2 with a tight --coarse-tol is the two-grid
cycle with an exact coarse solve.

Usage (from the repository root)::

    .venv/bin/python benchmarks/fas_pressure.py --n 512 1024 2048 --hurst 0.8 --seed 1 \
        --load 0.05 --cycles 12 --starts 2 4 6
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
sys.path.insert(0, str(HERE))

from roughfe.bem import Material, solve_contact  # noqa: E402
from roughfe.bem.coarse_start import _coarse_start, _coarse_surface  # noqa: E402
from roughfe.bem.contact import _cg_preconditioner, _operator  # noqa: E402
from roughfe.bem.pk import SINGLE_PRECISION_RESIDUAL, polonsky_keer  # noqa: E402
from roughfe.errors import NoConvergenceError  # noqa: E402
from roughfe.surfaces.spectral import spectral_surface  # noqa: E402
from multigrid_displacement import prolong, restrict  # noqa: E402  (bilinear, periodic)

MAT = Material(1.0, 0.0)
TOL = 1e-10
#: relative size below which a shifted start pressure is the obstacle itself
ZERO = 1e-12
#: the errors max |p - p*| / max p* whose first cycle is reported
REACH = (1e-2, 1e-4, 1e-6, 1e-8)
#: the variants of the command line (module-wide: one run of the script, one variant):
#: c_factor   c_l = c_factor (H_l)_ii, the scale of N's min (--c-factor)
#: correct    False (--no-correction): the cycles without their coarse correction (the
#:            coarse levels still run and are counted: the smoothing alone)
#: start      "fmg" (nested iteration) or "production" (the coarse-to-fine start) (--start)
#: damping    the factor of the prolonged correction (--damping)
#: new_contact False (--truncate): points on the obstacle never take the correction (the
#:            contact set grows through the smoother only)
#: line_search the correction scaled by the minimiser of the level's Lagrangian along it
#:            (one more product per level and cycle) (--line-search)
#: restrict   the coarse start P_c0: "fw" (full weighting, load-conserving) or "inject"
#:            (the coarse grid's own points; the coarse load is mean(P_c0))
OPT = {"c_factor": 1.0, "correct": True, "start": "fmg", "damping": 1.0,
       "new_contact": True, "restrict": "fw", "line_search": False}


def restrict_mean(x):
    """Full weighting with weights summing to 1 (the transpose of bilinear prolongation
    divided by 4): conserves the mean."""
    return restrict(x) / 4.0


class Counter:
    """Convolution-equivalents of the products on every grid, in units of the fine one."""

    def __init__(self, n_fine):
        self.n2 = float(n_fine) ** 2
        self.conv = 0.0

    def wrap(self, fn):
        def counted(x, *args, **kw):
            self.conv += np.asarray(x).size / self.n2
            return fn(x, *args, **kw)
        return counted


class Level:
    """One grid of the hierarchy: its heights, operator (counted) and PK smoother."""

    def __init__(self, surface, counter, scale):
        self.surface = surface
        self.h = np.ascontiguousarray(surface.heights)
        self.m = self.h.shape[0]
        self.op = _operator(surface.shape, surface.size, MAT.E_star, "spectral")
        # the scale of N's min (m/Pa): H_ii times OPT["c_factor"]
        self.c = float(self.op.diagonal) * OPT["c_factor"]
        self.counter = counter
        self.scale = scale
        self.apply = counter.wrap(self.op.apply_unchecked)
        self.apply_single = counter.wrap(
            lambda x, out=None, work=None: self.op.apply_unchecked(x, True, out, work))
        self.precond = counter.wrap(_cg_preconditioner(self.op))
        self.rhs = np.zeros_like(self.h)
        self.load = None
        self.pk_iterations = 0
        self.residual = np.inf       # PK's KKT residual after the last smoothing
        self.steps = []              # the line search's steps (--line-search)

    def H(self, x):
        return self.apply(np.ascontiguousarray(x, dtype=float))

    def setup(self, rhs, load):
        """The level's right-hand side and load: the shifted problem's obstacle, heights
        and load (one product H (rhs / c) when rhs is not zero)."""
        self.load = float(load)
        self.rhs = np.zeros_like(self.h) if rhs is None else rhs
        if rhs is None or not np.any(rhs):
            self.lb, self.Hlb, self.b = 0.0, 0.0, self.h
        else:
            self.lb = rhs / self.c
            self.Hlb = self.H(self.lb)
            self.b = self.h + rhs - self.Hlb

    def smooth(self, P, iterations, tol=1e-14):
        """``iterations`` PK iterations (or to ``tol``) on the level's problem from P:
        (P, u = H P, Delta)."""
        start = np.maximum(P - self.lb, 0.0)
        # P - rhs / c is rounding (~1e-17 P) where the start is on the shifted obstacle:
        # such points must not count as contact (PK's Delta is the mean gap there)
        start[start <= ZERO * float(start.max())] = 0.0
        load = self.load - float(np.mean(self.lb))
        if load <= 0:
            raise RuntimeError(f"level {self.m}: shifted load {load:.3e} <= 0")
        # PK's first product of a call is float32 (its residual is not known yet): once
        # the level's residual is below PK's own switch, the smoother calls go without
        # the single-precision products (their rounding, ~1e-6 of max p, was a floor)
        single = self.apply_single if self.residual > SINGLE_PRECISION_RESIDUAL else None
        try:
            out = polonsky_keer(self.apply, self.b, self.scale, mean_pressure=load,
                                initial=start, diagonal=self.c, precond=self.precond,
                                tol=tol, max_iter=iterations, apply_single=single,
                                overwrite_initial=True)
        except NoConvergenceError as exc:
            out = exc.result
        self.pk_iterations += int(out.nit)
        self.residual = float(out.residual)
        return out.pressure + self.lb, out.displacement + self.Hlb, float(out.delta)

    def natural(self, P, u, delta):
        """N(P, Delta) = min(c P, H P - h - Delta) (m)."""
        return np.minimum(self.c * P, u - self.h - delta)


def vcycle(levels, k, P, nu1, nu2, coarse_tol, coarse_iter, state=None):
    """One FAS V-cycle on level ``k`` (its rhs and load set) from P; returns (P, H P,
    Delta). ``nu1``, ``nu2``: PK iterations before and after the coarse correction, an
    int or a pair (fine level, coarser levels); with no pre-smoothing the fine level
    needs ``state`` = (H P, Delta) of P (the last cycle's)."""
    lv = levels[k]
    if k == len(levels) - 1:
        return lv.smooth(P, coarse_iter, coarse_tol)
    pre = nu1 if np.isscalar(nu1) else nu1[min(k, 1)]
    post = nu2 if np.isscalar(nu2) else nu2[min(k, 1)]
    if pre == 0 and state is not None:
        u, delta = state
    else:
        P, u, delta = lv.smooth(P, max(pre, 1))
    rho = lv.rhs - lv.natural(P, u, delta)
    co = levels[k + 1]
    Pc0 = restrict_mean(P) if OPT["restrict"] == "fw" else P[::2, ::2].copy()
    uc0 = co.H(Pc0)
    gap_c = uc0 - co.h - delta
    co.setup(np.minimum(co.c * Pc0, gap_c) + restrict_mean(rho), float(np.mean(Pc0)))
    # the coarse start: P_c0, but on the shifted obstacle where N_c(P_c0) is its pressure
    # branch (there P_c0 - rhs / c = -R rho / c is no contact pressure: left positive, it
    # puts points with an open gap into PK's contact set and its Delta)
    start = np.where(co.c * Pc0 < gap_c, co.lb, Pc0)
    Pc, uc, delta_c = vcycle(levels, k + 1, start, nu1, nu2, coarse_tol, coarse_iter)
    e = prolong(Pc - Pc0) * OPT["damping"] if OPT["correct"] else np.zeros_like(P)
    # the correction where the level's pressure is above its obstacle; a point on the
    # obstacle takes it only where the coarse solution closes its gap (the fine gap
    # predicted with the interpolated change of the coarse displacement): elsewhere the
    # interpolant's small positive values would put open points into PK's contact set
    above = P - lv.lb
    gap = u + prolong(uc - uc0) - lv.h - lv.rhs - delta_c
    closing = np.where(gap < 0, e, 0.0) if OPT["new_contact"] else 0.0
    above = np.where(above > 0, above + e, closing)
    P_new = np.maximum(above, 0.0) + lv.lb
    if OPT["line_search"]:
        # the minimiser of the level's Lagrangian along the change d (a convex combination
        # of two feasible pressures for s in [0, 1]): one more product on the level
        d = P_new - P
        hd = lv.H(d)
        dhd = float(np.vdot(d, hd))
        slope = float(np.vdot(d, u - lv.h - lv.rhs - delta))
        step = min(1.0, max(0.0, -slope / dhd)) if dhd > 0 else 0.0
        lv.steps.append(step)
        P_new = P + step * d
    return lv.smooth(P_new, post)


def fmg_start(levels, nu1, nu2, coarse_tol, coarse_iter, load):
    """Nested iteration: the coarsest grid solved, then one V-cycle per finer grid from
    the bilinear interpolant of the coarser solution (every level its plain problem)."""
    for lv in levels:
        lv.setup(None, load)
    P = levels[-1].smooth(np.full(levels[-1].h.shape, load), coarse_iter, coarse_tol)[0]
    for k in range(len(levels) - 2, -1, -1):
        for lv in levels[k + 1:]:
            lv.setup(None, load)
        P = vcycle(levels, k, np.maximum(prolong(P), 0.0), nu1, nu2, coarse_tol,
                   coarse_iter)[0]
    return P


from _pk_log import install  # noqa: E402  (benchmarks/_pk_log.py)

CALLS = install()     # (grid points, products, nit) of every polonsky_keer call


def production(surface, load, initial=None):
    """The production solve (cold, or from ``initial``): result, conv-eq, fine iterations."""
    CALLS.clear()
    c0 = time.process_time()
    r = solve_contact(surface, MAT, mean_pressure=load, solver="pk", tol=TOL,
                      compute_stiffness=False, initial=initial)
    cpu = time.process_time() - c0
    n2 = surface.heights.size
    return r, sum(m / n2 * k for m, k, _ in CALLS), int(r.nit), cpu


def run(n, hurst, seed, load, cycles, starts, nu1, nu2, coarsest, coarse_tol, coarse_iter):
    surface = spectral_surface(n, 1.0, hurst, rms_slope=1.0, rng=seed)
    ref, ref_conv, ref_nit, ref_cpu = production(surface, load)
    p_ref = ref.pressure
    pmax = float(p_ref.max())
    touch = p_ref > 0
    print(f"{n}^2 H={hurst} seed={seed} p/E*={load}: production {ref_nit} iterations, "
          f"{ref_conv:.1f} conv-eq, {ref_cpu:.1f} s CPU, A* {touch.mean():.5f}", flush=True)
    counter = Counter(n)
    scale = float(np.ptp(surface.heights))
    levels, s = [], surface
    while True:
        levels.append(Level(s, counter, scale))
        if s.shape[0] // 2 < coarsest:
            break
        s = _coarse_surface(s)
    row = {"n": n, "hurst": hurst, "seed": seed, "load": load, "nu": [nu1, nu2],
           "levels": [lv.m for lv in levels], "production": {
               "iterations": ref_nit, "conv_eq": ref_conv, "cpu_s": ref_cpu,
               "area_fraction": float(touch.mean())}, "cycles": [], "pk_from": []}

    def report(k, P, cpu):
        err = float(np.max(np.abs(P - p_ref)) / pmax)
        wrong = int(np.count_nonzero((P > 0) != touch))
        row["cycles"].append({"cycle": k, "conv_eq": counter.conv, "error": err,
                              "wrong_contact_points": wrong, "cpu_s": cpu,
                              "fine_pk_iterations": levels[0].pk_iterations})
        steps = levels[0].steps[-1:] if OPT["line_search"] else ""
        print(f"  cycle {k:2d}: {counter.conv:7.1f} conv-eq, max|p-p*|/max p* {err:.2e}, "
              f"wrong contact points {wrong}, fine PK its {levels[0].pk_iterations}, "
              f"{cpu:.1f} s {steps}", flush=True)
        if k in starts:
            r, conv, nit, cpu2 = production(surface, load, initial=np.maximum(P, 0.0))
            same = bool(np.array_equal(r.pressure > 0, touch))
            dp = float(np.max(np.abs(r.pressure - p_ref)) / pmax)
            row["pk_from"].append({"cycle": k, "fas_conv_eq": counter.conv,
                                   "pk_iterations": nit, "pk_conv_eq": conv,
                                   "total_conv_eq": counter.conv + conv,
                                   "same_contact_set": same, "max_dp": dp, "pk_cpu_s": cpu2})
            print(f"    PK from cycle {k}: {nit} iterations, {conv:.1f} conv-eq "
                  f"(total {counter.conv + conv:.1f} vs {ref_conv:.1f}); same contact set "
                  f"{same}, max|dp|/max p {dp:.1e}", flush=True)

    c0 = time.process_time()
    if OPT["start"] == "fmg":
        P = fmg_start(levels, nu1, nu2, coarse_tol, coarse_iter, load)  # ends without a state
    else:            # production's coarse-to-fine start (its coarse solves counted)
        CALLS.clear()
        P = _coarse_start(surface, MAT, load, None, kernel="spectral")
        counter.conv += sum(m / n ** 2 * k for m, k, _ in CALLS)
    report(0, P, time.process_time() - c0)
    state = None
    for k in range(1, cycles + 1):
        for lv in levels[1:]:
            lv.setup(None, load)
        levels[0].setup(None, load)
        P, u, delta = vcycle(levels, 0, P, nu1, nu2, coarse_tol, coarse_iter, state)
        state = (u, delta)
        report(k, P, time.process_time() - c0)
        if row["cycles"][-1]["error"] <= REACH[-1] and k >= max(starts, default=0):
            break            # at production's accuracy (and every start asked for run)
    for level in REACH:
        hit = next((c for c in row["cycles"] if c["error"] <= level), None)
        row[f"reach_{level:g}"] = None if hit is None else [hit["cycle"], hit["conv_eq"]]
        print(f"  to {level:g}: " + ("not reached" if hit is None else
              f"cycle {hit['cycle']}, {hit['conv_eq']:.1f} conv-eq"), flush=True)
    return row


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, nargs="+", default=[512, 1024])
    ap.add_argument("--hurst", type=float, default=0.8)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--load", type=float, default=0.05)
    ap.add_argument("--cycles", type=int, default=10)
    ap.add_argument("--starts", type=int, nargs="*", default=[])
    ap.add_argument("--nu", type=int, nargs=2, default=[2, 2],
                    help="pre, post PK iterations on the fine grid")
    ap.add_argument("--nu-coarse", type=int, nargs=2, default=None,
                    help="pre, post PK iterations on the coarser grids (default: --nu)")
    ap.add_argument("--coarsest", type=int, default=64)
    ap.add_argument("--coarse-tol", type=float, default=1e-10)
    ap.add_argument("--coarse-iter", type=int, default=200)
    ap.add_argument("--c-factor", type=float, default=1.0,
                    help="the scale c_l of N = min(c_l P, gap) in units of (H_l)_ii")
    ap.add_argument("--no-correction", action="store_true",
                    help="drop the coarse correction of the cycles (the smoothing alone)")
    ap.add_argument("--start", choices=("fmg", "production"), default="fmg",
                    help="nested FAS iteration, or production's coarse-to-fine start")
    ap.add_argument("--damping", type=float, default=1.0,
                    help="factor of the prolonged coarse correction")
    ap.add_argument("--truncate", action="store_true",
                    help="no coarse correction at points on the obstacle (p = 0 there)")
    ap.add_argument("--restrict-pressure", choices=("fw", "inject"), default="fw",
                    help="the coarse start of the pressure: full weighting or injection")
    ap.add_argument("--line-search", action="store_true",
                    help="scale each correction by the energy minimiser along it")
    ap.add_argument("--output", type=Path, default=None)
    a = ap.parse_args(argv)
    OPT["c_factor"] = a.c_factor
    OPT["correct"] = not a.no_correction
    OPT["start"] = a.start
    OPT["damping"] = a.damping
    OPT["new_contact"] = not a.truncate
    OPT["restrict"] = a.restrict_pressure
    OPT["line_search"] = a.line_search
    nc = a.nu if a.nu_coarse is None else a.nu_coarse
    rows = [run(n, a.hurst, a.seed, a.load, a.cycles, set(a.starts), (a.nu[0], nc[0]),
                (a.nu[1], nc[1]),
                a.coarsest, a.coarse_tol, a.coarse_iter) for n in a.n]
    if a.output is not None:
        a.output.parent.mkdir(parents=True, exist_ok=True)
        a.output.write_text(json.dumps({"benchmark": "fas_pressure", "rows": rows}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
