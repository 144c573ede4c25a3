"""Research script (issue 16 section 1; not in the package, not in ``make bench``): a
semismooth-Newton (primal-dual active set, PDAS) outer loop for the periodic,
load-controlled frictionless BEM contact whose inner tolerance follows the
Eisenstat-Walker forcing rule, with a safeguard against cycling. Measured in round 2,
session 38 (docs/theory/02b_bem_performance.md, "A Newton outer loop with
Eisenstat-Walker forcing, measured"); sessions 14 and 17 measured the same loop with fixed
inner tolerances.

The problem (Eq. 2.5, load control; u = H p in m, heights h in m, p in Pa): p >= 0, the
gap w = u - h - Delta >= 0, p . w = 0, mean(p) = P. Outer step k fixes the set I and
solves the linear saddle-point problem

    (H p)_I - h_I = Delta 1,     p = 0 off I,     sum p = n P

(negative pressures allowed: no projection inside the solve) inexactly, then takes
I <- {i in I: p_i > 0} + {i not in I: w_i < 0} (Hintermueller, Ito & Kunisch 2002).
The linear solve is the production direction on the fixed I: the gradient g_I = (u -
h)_I minus its mean (the load's projection), the single-precision stiffness
preconditioner M = E*|q|/2 (``contact._cg_preconditioner``), the two-level A-DEF2
correction ``roughfe.bem.deflation.BlockDeflation(op, 8)`` (as ``solve_contact`` builds
it; ``settle`` = 1: on a fixed set the correction acts at every inner iteration, its
changed-block test is for PK's moving free set) behind the production descent guard
(``directions._descent_guard``), Polak-Ribiere+ conjugation (flexible CG, restarted at
each outer step) and the exact step. The inner solve starts from the previous outer
pressure with the points that left I set to 0 and p rescaled to the load; u = H p is
tracked through it (u <- u - tau H t; on a restart u <- a (u - H p_removed), one product
where points left I), so the set update needs no product of its own. The first outer
step starts from the production coarse start (``coarse_start._coarse_start``: the load
solved on the grids coarsened by 2, to 1e-4) and its set {p > 0} + {w < 0}.

Forcing (Eisenstat & Walker 1996, choice 2): the inner solve of outer step k stops when
||g_I|| <= eta_k ||g_I at its start|| (the Newton step's linear residual relative to the
nonlinear one), with

    eta_k = gamma (r_k / r_{k-1})^alpha,  eta_k <- max(eta_k, gamma eta_{k-1}^alpha)
    when gamma eta_{k-1}^alpha > 0.1,  eta_k <- min(eta_k, eta_max),
    eta_k <- max(eta_k, 0.5 tol / r_k)  (no oversolving of the last step),

eta_0 = ``--eta0``. r_k is the production KKT residual (``roughfe.bem.solvers``:
max(sum p |w| / (sum p h_pv), max(-w, 0) / h_pv)) of the tracked iterate, extended to
negative pressures by the dual term max(-p, 0) H_ii / h_pv (it is the production
residual when p >= 0), Delta the mean of u - h over I. The solve ends when r_k <= tol
(1e-10) and a freshly computed u = H p of max(p, 0) confirms the production residual
<= tol (one product). Below r = 1e-4 the residual is also read at every inner iteration
(full-grid passes, no product), and the inner solve ends as soon as it is below tol.

Globalization (``--globalize``): an outer step is "bad" when its number of changed points
did not fall (and is not 0) or the residual rose; after two bad steps in a row the next
inner tolerance is multiplied by ``--tighten`` (0.1), or (``--fallback-pk N``) N
iterations of the production PK (``contact._pk`` with its own BlockDeflation, from
max(p, 0)) replace the next Newton step and the set is taken from its result.

Forcing from the changed points (``--forcing changed`` or ``changed-ratio``, session 39;
opt-in, the default ``ew`` is the rule above): eta_k = clip(c x^a, eta_min, eta_max)
(``--c``, ``--power``, ``--eta-min``), x = changed_k / |I_{k+1}| (the share of the new set
whose status changed) or changed_k / changed_{k-1} (1 at the first step), x = 0 when no
point changed; then the no-oversolving floor and the globalization as above.

Counts: an inner iteration is one product with H (float64: H t, which also updates u),
one with M (float32) and the correction's one (float32 H_II M g; none at the very first
inner iteration, where BlockDeflation has no last set), comparable to one iteration of
the production PK. Every product is counted, with the start's u = H p, the restart
products and the final confirmation; the convolution-equivalents weight each by its
grid (coarse levels m^2 / n^2) as ``benchmarks/fas_pressure.py`` does, the coarse
start's and the production solve's through ``benchmarks/_pk_log.py`` (the products of
every ``polonsky_keer`` call). The production solve (``solve_contact``, cold) runs on the
same surface beside it: its fine iterations, conv-eq, CPU and A*; the PDAS A* must match
it to 1e-6 relative, else the row is void (``a_star_match`` false).

Surfaces: those of ``benchmarks/bench_bem_growth.py`` (``octaves_case``: a new
self-affine surface at every n, unit rms slope, L = 1 m), E* = 1, tol 1e-10, cold, the
loads of its ``LOADS``.

Measured in session 38 (the docs section has the tables): the cap eta_max decides, the
rest of the rule hardly acts. eta_max was chosen on H = 0.5 and 0.8, seed 1, 1024^2 and
2048^2 among 0.3, 0.2, 0.1, 0.05, 0.03 (inner totals of the 4 loads, H = 0.5 / 0.8:
0.1 86 -> 98 / 86 -> 104, 0.05 89 -> 101 / 87 -> 101, 0.03 92 -> 105 / 90 -> 102; 0.2
and 0.3 near-cycle at 2048^2: 127-135); the default 0.03 was then checked on seed 2
(H = 0.5 105 -> 105, H = 0.8 97 -> 98; production 97 -> 111, 84 -> 98) and on one load
p/E* = 0.05 at 4096^2 (2048^2 -> 4096^2: H = 0.5 27 -> 31, H = 0.8 31 -> 31; production
31 -> 37, 27 -> 31). With 0.03 the globalization never fires (--no-globalize: the same
counts). Variants: --alpha 2 (with 0.1: 88 -> 99 / 88 -> 108); --persist and
--min-fall (a trigger lowers eta_max for good) and --fallback-pk N (N PK iterations
instead of the tightened step): with eta_max 0.3 they shorten the near-cycling (H = 0.5
seed 1, 2048^2, p/E* = 0.05 + 0.1: 96 inner iterations with the one-step tightening, 83
persistent, 84 with 5 PK steps) but stay far above eta_max 0.1 (55) or 0.03 (61);
eta_max 0.2 with --persist --min-fall 0.5: 89 -> 112 / 87 -> 114.

On the rest of the growth suite, with these defaults unchanged (the same session): the
4-load means of seeds 1-4 meet <= 1.15x (H = 0.5 1.085x, H = 0.8 1.082x), but the one
load p/E* = 0.05 from 2048^2 to 4096^2 does not on seeds 2-4 (H = 0.5 1.185x, 1.067x,
1.143x; H = 0.8 1.231x, 1.423x, 1.111x; H = 0.8 4-seed mean 1.182x), nor from 4096^2 to
8192^2 (H = 0.8 seed 1: 31 -> 38, 1.226x, production's own count). Not adopted.

The changed-points forcing, session 39 (fitted on seed 1 only, --no-production, inner
totals 2048^2 -> 4096^2 one load p/E* = 0.05 and 1024^2 -> 2048^2 four loads, H = 0.5 /
0.8; EW 0.03: 27 -> 31, 31 -> 31; 92 -> 105, 90 -> 102): ``changed``, c 1, eta_max 0.3:
33 -> 48 / 33 -> 61 (loose early solves give worse sets: the changes rise, up to 14
outer steps); ``changed``, c 1, eta_max 0.03: 30 -> 33 / 32 -> 34, 95 -> 111 (1.168x) /
94 -> 106; ``changed-ratio``, c 0.1, eta_max 0.03: 28 -> 32 / 31 -> 34, 95 -> 106 / 89
-> 103 (1.157x); ``changed``, c 0.3, eta_max 0.1: 31 -> 32 / 33 -> 36, 95 -> 111
(1.168x) / 94 -> 115 (1.223x); ``changed``, c 0.1, a 0.5, eta_min 0.002, eta_max 0.03:
28 -> 32 / 32 -> 34, 94 -> 107 / 91 -> 106 (1.165x). No variant meets <= 1.15x on the
four seed-1 rows, so none was frozen and none run out of sample. With eta_max 0.03 every
rule sits at the cap for the first three solves, where the extra work of the bad rows
is, so those solves are EW's, and so are the failing rows (one load, H = 0.8,
changed-ratio, checked after the fit failed: seed 3 26 -> 37 as EW, seed 2 26 -> 33
against EW's 26 -> 32). Not adopted.

Session 40, the worst row diagnosed (``--trace``, ``_pdas_trace.py``; H = 0.8 seed 3,
one load, EW 26 -> 37): its extra iterations are in steps 2-5 (13 -> 21; the first solve
6 -> 6, the tail 7 -> 10), where the inexact iterate moves points the wrong way (in or
out of the converged set A: 8766 / 5787 at step 2 of 4096^2, 691 / 2543 on seed 1) and
the set error falls only 4.1-4.6x per step (6-10x on seed 1). The restart's rescaling of
p is the cause: ``--restart shift`` (``_pdas_restart.py``; default ``scale``) restores
the load by a uniform shift on the new set instead, cuts those moves 2-6x and gives 26
-> 32 (one outer step less). It has no constant. Seed-1 rows (one load H = 0.5 / 0.8;
4 loads 1024^2 -> 2048^2) 1.103x / 1.000x; 1.152x / 1.159x; seeds 5-6 out of sample
(one load, H = 0.5 / 0.8): 1.067x / 1.185x, 1.179x / 1.107x (EW 1.065x / 1.143x,
1.259x / 1.172x). NOT met on 5 of 9 rows; not adopted.

Usage (from the repository root; a line per load and a total per n)::

    nice -n 10 .venv/bin/python benchmarks/pdas_eisenstat_walker.py --n 1024 2048 \
        --hurst 0.5 --seed 1 --output /tmp/pdas_h05.json
    nice -n 10 .venv/bin/python benchmarks/pdas_eisenstat_walker.py --n 4096 \
        --hurst 0.8 --loads 0.05
    nice -n 10 .venv/bin/python benchmarks/pdas_eisenstat_walker.py --n 2048 \
        --hurst 0.5 --loads 0.05 0.1 --no-production --eta-max 0.3 --fallback-pk 5
    nice -n 10 .venv/bin/python benchmarks/pdas_eisenstat_walker.py --n 2048 \
        --hurst 0.8 --seed 3 --loads 0.05 --no-production --trace --restart shift
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

from roughfe.bem import Material  # noqa: E402
from roughfe.bem.coarse_start import _coarse_start  # noqa: E402
from roughfe.bem.contact import _cg_preconditioner, _operator, _pk  # noqa: E402
from roughfe.bem.deflation import BlockDeflation  # noqa: E402
from roughfe.bem.directions import _descent_guard  # noqa: E402
from roughfe.bem.solvers import kkt_residual, pr_beta  # noqa: E402
from roughfe.errors import NoConvergenceError  # noqa: E402
from roughfe.surfaces.spectral import spectral_surface  # noqa: E402
from roughfe.writers import write_json  # noqa: E402
from _pk_log import install  # noqa: E402  (benchmarks/_pk_log.py)
from _pdas_trace import Trace, lines, residual_terms  # noqa: E402
from _pdas_restart import restart  # noqa: E402
from bench_bem_growth import LOADS, TOL, _solve_loads  # noqa: E402

CALLS = install()     # (grid points, products, nit) of every polonsky_keer call
MAT = Material(1.0, 0.0)
#: the residual below which the inner solve reads the KKT residual at every iteration
KKT_EVERY_BELOW = 1e-4


def growth_surface(n, hurst, seed):
    """The surface of ``bench_bem_growth.octaves_case`` (which also solves it)."""
    return spectral_surface(n, 1.0, hurst, rms_slope=1.0, rng=seed)


class Fine:
    """The fine grid's operator, preconditioner and heights, every product counted."""

    def __init__(self, surface):
        self.shape = surface.shape
        self.op = _operator(surface.shape, surface.size, MAT.E_star, "spectral")
        self.h = np.ascontiguousarray(surface.heights, dtype=float).reshape(-1)
        self.hmax = float(self.h.max())
        self.scale = float(np.ptp(self.h))
        self.c = float(self.op.diagonal)
        self.M32 = _cg_preconditioner(self.op)
        self.products = 0

    def H(self, x, single=False):
        self.products += 1
        return self.op.apply_unchecked(x.reshape(self.shape), single).reshape(-1)

    def M(self, x):
        self.products += 1
        return self.M32(x.reshape(self.shape)).reshape(-1)


def extended_residual(fine, p, u, mask, target):
    """The production KKT residual of (p, u) with Delta the mean of u - h over ``mask``
    (I), extended to p < 0 by max(-p, 0) H_ii / h_pv (module docstring)."""
    g = u - fine.h
    d = float(g[mask].mean())
    g -= d
    comp = float(np.dot(np.abs(p), np.abs(g)))
    feas = max(0.0, -float(g.min()))       # the largest penetration, anywhere
    neg = max(0.0, -float(p.min())) * fine.c
    return max(comp / (target * fine.scale), feas / fine.scale, neg / fine.scale)


def production_residual(fine, p, u):
    """The residual of ``solve_contact``'s PK (Delta the mean gap over p > 0)."""
    g = u - fine.h
    d = float(g[p > 0].mean())
    return kkt_residual(p, g - d, fine.scale)


def inner_solve(fine, deflation, p, u, I, mask, eta, target, max_it, tol, kkt_every):
    """The flexible two-level CG on the fixed set I (flat indices; ``mask`` its grid
    mask) from (p, u = H p), both updated in place, to ||g_I|| <= eta ||g_I^0|| (or a
    residual <= ``tol`` when ``kkt_every``). Returns (iterations, the KKT residual when
    read at the end or None, whether max_it was reached)."""
    n = p.size
    hI = fine.h[I]
    gI = u[I] - hI
    gI -= gI.mean()
    stop = eta * float(np.linalg.norm(gI))
    t = np.zeros(n)
    gbuf = np.zeros(n, np.float32)
    y = np.zeros(n, np.float32)

    def H_free(xI):
        y[I] = xI
        return fine.H(y, single=True)[I]

    tI = g_old = None
    gz_old = 0.0
    res = None
    for it in range(max_it + 1):
        if kkt_every:
            res = extended_residual(fine, p, u, mask, target)
            if res <= tol:
                return it, res, False
        if float(np.linalg.norm(gI)) <= stop:
            return it, res, False
        if it == max_it:
            return it, res, True
        gbuf[I] = gI
        zI = fine.M(gbuf)[I].astype(float)
        zI -= zI.mean()
        z2 = deflation.correct(I, gI, zI, H_free, free_mask=mask)
        zI, gz = _descent_guard(gI, zI, z2)
        beta = 0.0 if tI is None else float(pr_beta(gz - float(np.dot(zI, g_old)), gz_old))
        tI = zI if tI is None else zI + beta * tI
        t[I] = tI
        r = fine.H(t)
        tau = float(np.dot(gI, tI)) / float(np.dot(tI, r[I]))
        p[I] -= tau * tI
        u -= tau * r
        g_old, gz_old = gI, gz
        gI = u[I] - hI
        gI -= gI.mean()


def forcing(r, r_prev, eta_prev, opt):
    """Eisenstat-Walker choice 2 with its safeguards (module docstring)."""
    gamma, alpha = opt["gamma"], opt["alpha"]
    eta = gamma * (r / r_prev) ** alpha
    guard = gamma * eta_prev ** alpha
    if guard > 0.1:
        eta = max(eta, guard)
    eta = min(eta, opt["eta_max"])
    return max(eta, 0.5 * TOL / r)


def coarse_start(surface, load, target):
    """The production coarse start (to 1e-4 on the grids coarsened by 2), flat and scaled
    to sum p = ``target`` (n P), and its conv-eq (coarse products weighted m^2 / n^2)."""
    n = surface.heights.size
    CALLS.clear()
    p = _coarse_start(surface, MAT, load, None, kernel="spectral").reshape(-1).copy()
    coarse_conv = sum(m / n * k for m, k, _ in CALLS)
    p *= target / float(p.sum())
    return p, coarse_conv


def pk_from(fine, q, load, maxiter):
    """At most ``maxiter`` production PK iterations (``contact._pk`` with its own
    BlockDeflation, tol 1e-10) from the pressure ``q`` (>= 0, rescaled to the load in
    place), its products added to ``fine``: (PK result, converged)."""
    q *= load * q.size / float(q.sum())
    try:
        out = _pk(fine.op, fine.h.reshape(fine.shape), fine.hmax, fine.scale, TOL, maxiter,
                  q.reshape(fine.shape), True, BlockDeflation(fine.op, 8),
                  mean_pressure=load)
        converged = True
    except NoConvergenceError as exc:
        out, converged = exc.result, False
    fine.products += int(out.n_products)
    return out, converged


def forcing_changed(changed, changed_prev, set_size, r, opt):
    """The inner tolerance from the set's changes (``--forcing changed``: x = changed_k
    / |I_{k+1}|; ``changed-ratio``: x = changed_k / changed_{k-1}, 1 at the first step;
    x = 0 when no point changed): eta_k = clip(c x^a, eta_min, eta_max), then no
    oversolving (module docstring)."""
    if changed == 0:
        x = 0.0
    elif opt["forcing"] == "changed-ratio":
        x = 1.0 if not changed_prev else changed / changed_prev
    else:
        x = changed / max(set_size, 1)
    eta = min(max(opt["c"] * x ** opt["power"], opt["eta_min"]), opt["eta_max"])
    return max(eta, 0.5 * TOL / r)


def pdas(surface, load, opt):
    """One cold PDAS solve of ``load`` (p/E*); a dict of its counts and result."""
    c0 = time.process_time()
    fine = Fine(surface)
    n = fine.h.size
    target = load * n
    p, coarse_conv = coarse_start(surface, load, target)
    u = fine.H(p)
    g = u - fine.h
    w = g - float(g[p > 0].mean())
    mask = (p > 0) | (w < 0)
    del g, w
    trace = Trace(fine.shape) if opt.get("trace") else None   # --trace
    deflation = BlockDeflation(fine.op, 8, settle=1.0)
    r_prev = extended_residual(fine, p, u, mask, target)
    eta, bad, tighten_next, tightened = opt["eta0"], 0, False, 0
    changed_prev = None
    steps = []
    inner_total = pk_total = 0
    converged = False
    for k in range(1, opt["max_outer"] + 1):
        I = np.flatnonzero(mask)
        fallback = tighten_next and opt["fallback_pk"]
        if fallback:             # N production PK iterations replace this Newton step
            out, _ = pk_from(fine, np.maximum(p, 0.0), load, opt["fallback_pk"])
            pk_total += int(out.nit)
            its, res_in, capped = int(out.nit), None, False
            p = np.ascontiguousarray(out.pressure, dtype=float).reshape(-1).copy()
            u = np.ascontiguousarray(out.displacement, dtype=float).reshape(-1).copy()
            g = u - fine.h
            w = g - float(g[p > 0].mean())
            mask = (p > 0) | (w < 0)
            del g, w
        else:
            eta_used = eta * (opt["tighten"] if tighten_next else 1.0)
            its, res_in, capped = inner_solve(fine, deflation, p, u, I, mask, eta_used,
                                              target, opt["max_inner"], TOL,
                                              r_prev < KKT_EVERY_BELOW)
            inner_total += its
        r = (res_in if res_in is not None
             else extended_residual(fine, p, u, mask, target))
        if r <= TOL:
            q = np.maximum(p, 0.0)
            q *= target / float(q.sum())
            uq = fine.H(q)
            rq = production_residual(fine, q, uq)
            p, u = q, uq         # not confirmed: go on from the fresh displacement
            if rq <= TOL:
                steps.append({"inner": its, "eta": None if fallback else eta_used,
                              "residual": rq, "changed": 0, "fallback": bool(fallback)})
                if trace:
                    trace.step(mask, steps[-1], residual_terms(fine, p, u, mask, target),
                               bad, False)
                converged = True
                break
            r = max(rq, 2 * TOL)
        # the new set, from the tracked u
        g = u - fine.h
        d = float(g[mask].mean())
        new = np.where(mask, p > 0, g - d < 0)
        del g
        changed = int(np.count_nonzero(new != mask))
        steps.append({"inner": its, "eta": None if fallback else eta_used, "residual": r,
                      "changed": changed, "capped": capped, "fallback": bool(fallback)})
        # globalization: two bad steps in a row tighten the next solve (or PK steps)
        if opt["globalize"]:
            worse = (changed_prev is not None and changed > 0
                     and changed >= opt["min_fall"] * changed_prev)
            is_bad = worse or r > r_prev
            bad = bad + 1 if is_bad else 0
            tighten_next = bad >= 2
            if tighten_next:
                bad = 0
                if opt["persist"]:       # eta_max itself tightened for good
                    opt = {**opt, "eta_max": opt["eta_max"] * opt["tighten"]}
                    tighten_next = False
                    tightened += 1
        if trace:
            trace.step(mask, steps[-1], residual_terms(fine, p, u, mask, target), bad,
                       tighten_next)
        if not fallback:
            eta = (forcing(r, r_prev, eta, opt) if opt["forcing"] == "ew" else
                   forcing_changed(changed, changed_prev, int(np.count_nonzero(new)), r, opt))
        r_prev, changed_prev = r, changed
        restart(fine, p, u, mask, new, target, opt.get("restart", "scale"))
        mask = new
    cpu = time.process_time() - c0
    out = {"converged": converged, "outer": len(steps), "inner": inner_total,
           "pk_fallback_iterations": pk_total, "products": fine.products,
           "conv_eq": fine.products + coarse_conv, "coarse_conv_eq": coarse_conv,
           "cpu_s": cpu, "eta_max_tightened": tightened,
           "A*": float(np.count_nonzero(p > 0)) / n,
           "residual": production_residual(fine, np.maximum(p, 0.0), u) if converged
           else r, "steps": steps}
    if trace and converged:
        out["trace"] = trace.finish(p > 0)
    return out


def production(surface, load):
    """``solve_contact`` (cold) through bench_bem_growth._solve_loads: its fine
    iterations, A*, conv-eq (every polonsky_keer call, coarse levels weighted) and CPU."""
    n = surface.heights.size
    CALLS.clear()
    c0 = time.process_time()
    nit, area = _solve_loads(surface, (load,))
    cpu = time.process_time() - c0
    return {"iterations": nit[0], "A*": area[0], "cpu_s": cpu,
            "conv_eq": sum(m / n * k for m, k, _ in CALLS),
            "fine_products": CALLS[-1][1]}


def beside_production(row, result, surface, load, totals):
    """Run :func:`production` on the same load, store it and the A* check (1e-6
    relative) in ``row``, add its counts to ``totals``; the text for the row's line."""
    pr = row["production"] = production(surface, load)
    row["a_star_match"] = bool(abs(result["A*"] - pr["A*"]) <= 1e-6 * pr["A*"])
    totals["pk"] += pr["iterations"]
    totals["pk_conv_eq"] += pr["conv_eq"]
    totals["pk_cpu_s"] += pr["cpu_s"]
    return (f" | PK {pr['iterations']} its, {pr['conv_eq']:.1f} conv-eq, "
            f"{pr['cpu_s']:.1f} s, A* {pr['A*']:.7f} match {row['a_star_match']}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, nargs="+", default=[1024])
    ap.add_argument("--hurst", type=float, default=0.5)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--loads", type=float, nargs="+", default=list(LOADS))
    ap.add_argument("--gamma", type=float, default=0.9)
    ap.add_argument("--alpha", type=float, default=(1 + 5 ** 0.5) / 2)
    ap.add_argument("--eta-max", type=float, default=0.03)
    ap.add_argument("--eta0", type=float, default=None, help="default: --eta-max")
    ap.add_argument("--no-globalize", action="store_true")
    ap.add_argument("--tighten", type=float, default=0.1)
    ap.add_argument("--persist", action="store_true",
                    help="a trigger multiplies eta_max by --tighten for the rest of the solve")
    ap.add_argument("--min-fall", type=float, default=1.0,
                    help="a step is bad when changed >= min_fall x the last step's")
    ap.add_argument("--fallback-pk", type=int, default=0,
                    help="N PK iterations instead of a tightened solve (0: tighten)")
    ap.add_argument("--forcing", choices=("ew", "changed", "changed-ratio"), default="ew",
                    help="the inner tolerance: Eisenstat-Walker or the changed points")
    ap.add_argument("--c", type=float, default=1.0, help="changed forcing: eta = c x^a")
    ap.add_argument("--power", type=float, default=1.0, help="changed forcing: a")
    ap.add_argument("--eta-min", type=float, default=0.0, help="changed forcing: floor")
    ap.add_argument("--max-inner", type=int, default=300)
    ap.add_argument("--max-outer", type=int, default=60)
    ap.add_argument("--restart", choices=("scale", "shift"), default="scale",
                    help="the load restored after points leave I (restart())")
    ap.add_argument("--no-production", action="store_true")
    ap.add_argument("--trace", action="store_true",
                    help="per outer step: the set against the converged one (_pdas_trace)")
    ap.add_argument("--output", type=Path, default=None)
    a = ap.parse_args(argv)
    opt = {"gamma": a.gamma, "alpha": a.alpha, "eta_max": a.eta_max,
           "eta0": a.eta_max if a.eta0 is None else a.eta0, "globalize": not a.no_globalize,
           "tighten": a.tighten, "persist": a.persist, "min_fall": a.min_fall,
           "fallback_pk": a.fallback_pk, "max_inner": a.max_inner,
           "max_outer": a.max_outer, "forcing": a.forcing}
    if a.forcing != "ew":
        opt.update(c=a.c, power=a.power, eta_min=a.eta_min)
    if a.trace:
        opt["trace"] = True
    if a.restart != "scale":
        opt["restart"] = a.restart
    print(f"H = {a.hurst} seed {a.seed}, {opt}", flush=True)
    rows = []
    for n in a.n:
        surface = growth_surface(n, a.hurst, a.seed)
        tot = {"inner": 0, "outer": 0, "conv_eq": 0.0, "cpu_s": 0.0, "pk": 0,
               "pk_conv_eq": 0.0, "pk_cpu_s": 0.0}
        for load in a.loads:
            row = {"n": n, "hurst": a.hurst, "seed": a.seed, "load": load, "opt": opt,
                   "pdas": pdas(surface, load, opt)}
            s = row["pdas"]
            line = (f"{n}^2 p/E*={load}: PDAS {'ok' if s['converged'] else 'NOT converged'}"
                    f" inner {s['inner']} (+{s['pk_fallback_iterations']} PK) outer "
                    f"{s['outer']}, {s['products']} fine products, {s['conv_eq']:.1f} "
                    f"conv-eq, {s['cpu_s']:.1f} s, A* {s['A*']:.7f}")
            if not a.no_production:
                line += beside_production(row, s, surface, load, tot)
            print(line, flush=True)
            print("    inner per outer step " + " ".join(
                f"{st['inner']}{'pk' if st['fallback'] else ''}" for st in s["steps"])
                + " | changed " + " ".join(str(st["changed"]) for st in s["steps"])
                + " | eta " + " ".join("-" if st["eta"] is None else f"{st['eta']:.2g}"
                                       for st in s["steps"]), flush=True)
            for text in lines(s["trace"]) if s.get("trace") else ():
                print(text, flush=True)
            tot["inner"] += s["inner"] + s["pk_fallback_iterations"]
            tot["outer"] += s["outer"]
            tot["conv_eq"] += s["conv_eq"]
            tot["cpu_s"] += s["cpu_s"]
            rows.append(row)
        print(f"{n}^2 total: PDAS {tot['inner']} inner ({tot['outer']} outer), "
              f"{tot['conv_eq']:.1f} conv-eq, {tot['cpu_s']:.1f} s | PK {tot['pk']} its, "
              f"{tot['pk_conv_eq']:.1f} conv-eq, {tot['pk_cpu_s']:.1f} s", flush=True)
    if a.output is not None:
        a.output.parent.mkdir(parents=True, exist_ok=True)
        write_json(a.output, {"benchmark": "pdas_eisenstat_walker", "rows": rows})  # atomic
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
