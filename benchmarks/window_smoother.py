"""Research script (issue 16 section 1; not in the package, not in ``make bench``): a
windowed, exact, load-conserving local projected solve of the contact edges, used as a
smoother of the production coarse-to-fine start before the production Polonsky-Keer
solve (``solve_contact(initial=...)``). Measured in round 2, session 29; the numbers and
the verdict (not adopted) are in docs/theory/02b_bem_performance.md.

The grid is cut into b x b windows (b = 8; the tiling shifted by b/2 on alternate sweeps).
Each window solves its own small contact problem with the exact b^2 x b^2 block of the
periodic operator and the field of the pressure outside it from the current global
displacement, keeping its own load (a zero-sum change: at most a dipole far field,
unlike the point relaxation of session 18); a few batched PK iterations (GEMMs) solve
all windows at once. After each sweep one FFT product and the exact global line search
(step clipped to [0, 1]) keep the energy falling.

Counts: every product with the operator is one convolution-equivalent (coarse-level
products weighted by their grid size); the local GEMMs are not FFTs, their CPU is
reported apart as the smoothing CPU.

Usage (from the repository root)::

    .venv/bin/python benchmarks/window_smoother.py --n 2048 --sweeps 0 4 --inner 5 \
        --loads 0.005 0.01 0.05 0.1 --quiet

``--sweeps 0`` is the production solve from the production start (the reference of
each load: A* and max |dp| / max p are printed against it).
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))     # the repository
from roughfe.bem import Material, solve_contact  # noqa: E402
from roughfe.bem.contact import _operator  # noqa: E402
from roughfe.bem.coarse_start import _coarse_start  # noqa: E402
from roughfe.surfaces.spectral import spectral_surface  # noqa: E402

MAT = Material(1.0, 0.0)
NPROD = [0]
DTYPE = [np.float64]
EDGE_ONLY = [False]
NWIN = []

from _pk_log import install  # noqa: E402  (benchmarks/_pk_log.py)

CALLS = install()   # (grid points, products, nit) of every polonsky_keer call


def conv_eq(calls, n_fine):
    """Products of the calls in fine-grid units (a product on a grid of m points = m / N)."""
    return sum(m / n_fine * k for m, k, _ in calls)


def Hprod(op, x):
    NPROD[0] += 1
    return op.apply(x)


def local_matrix(op, b):
    n0, n1 = op.shape
    e = np.zeros(op.shape)
    e[0, 0] = 1.0
    G = op.apply(e)
    i, j = np.divmod(np.arange(b * b), b)
    return G[(i[:, None] - i[None, :]) % n0, (j[:, None] - j[None, :]) % n1]


def to_windows(x, b, off):
    n0, n1 = x.shape
    y = np.roll(x, (-off, -off), axis=(0, 1))
    return y.reshape(n0 // b, b, n1 // b, b).transpose(0, 2, 1, 3).reshape(-1, b * b)


def from_windows(y, shape, b, off):
    n0, n1 = shape
    x = y.reshape(n0 // b, n1 // b, b, b).transpose(0, 2, 1, 3).reshape(n0, n1)
    return np.roll(x, (off, off), axis=(0, 1))


def local_pk(A, c, q, n_inner):
    """Batched PK on every window: min 1/2 q.A q - q.c, q >= 0, sum q fixed (rows)."""
    A = A.astype(DTYPE[0])
    c = c.astype(DTYPE[0])
    q = q.astype(DTYPE[0])
    P = q.sum(1)
    t = np.zeros_like(q)
    g_old = np.zeros_like(q)
    gz_old = np.zeros(q.shape[0])
    for _ in range(n_inner):
        w = q @ A - c
        pos = q > 0
        npos = pos.sum(1)
        d = np.where(npos > 0, (w * pos).sum(1) / np.maximum(npos, 1), w.min(1))
        F = pos | (w < d[:, None])
        nF = np.maximum(F.sum(1), 1)
        g = np.where(F, w - d[:, None], 0.0)
        g -= np.where(F, (g.sum(1) / nF)[:, None], 0.0)
        gz = (g * g).sum(1)
        num = (g * (g - g_old * F)).sum(1)
        beta = np.where(gz_old > 0, np.maximum(0.0, num / np.where(gz_old > 0, gz_old, 1)), 0.0)
        t = np.where(F, g + beta[:, None] * t, 0.0)
        At = t @ A
        tAt = (t * At).sum(1)
        gt = (g * t).sum(1)
        tau = np.where(tAt > 0, gt / np.where(tAt > 0, tAt, 1), 0.0)
        q = q - tau[:, None] * t
        np.maximum(q, 0.0, out=q)
        s = q.sum(1)
        q *= np.where(s > 0, P / np.where(s > 0, s, 1), 0.0)[:, None]
        g_old, gz_old = g, gz
    return q


def kkt(p, u, h, scale):
    w = u - h
    pos = p > 0
    d = w[pos].mean()
    w = w - d
    comp = float(np.dot(p[pos], np.abs(w[pos])))
    feas = max(0.0, -float(w.min()))
    return max(comp / (p.sum() * scale), feas / scale)


def smooth(op, A, p, u, h, b, sweeps, n_inner, log=None):
    scale = float(np.ptp(h))
    for k in range(sweeps):
        off = (k % 2) * (b // 2)
        pw = to_windows(p, b, off)
        active = pw.sum(1) > 0
        if EDGE_ONLY[0]:      # skip windows wholly in contact
            active &= (pw > 0).sum(1) < b * b
        NWIN.append(int(active.sum()))
        uw = to_windows(u, b, off)[active]
        hw = to_windows(h, b, off)[active]
        q0 = pw[active]
        c = hw - uw + q0 @ A          # heights minus the field of the pressure outside
        q = local_pk(A, c, q0, n_inner)
        dw = np.zeros_like(pw)
        dw[active] = q.astype(float) - q0
        dp = from_windows(dw, p.shape, b, off)
        Hd = Hprod(op, dp)
        gd = float(np.vdot(dp, u - h))
        dHd = float(np.vdot(dp, Hd))
        s = min(1.0, max(0.0, -gd / dHd)) if dHd > 0 else 0.0
        p = p + s * dp
        np.maximum(p, 0.0, out=p)
        u = u + s * Hd
        if log is not None:
            log.append((k, s, kkt(p, u, h, scale), float(np.mean(p > 0))))
    return p, u


def run(n, hurst, seed, pm, b, sweeps, n_inner, verbose=True):
    s = spectral_surface(n, 1.0, hurst, rms_slope=1.0, rng=seed)
    h = s.heights
    op = _operator(s.shape, s.size, 1.0, "spectral")
    CALLS.clear()
    c0 = time.process_time()
    p0 = _coarse_start(s, MAT, pm, None)
    p0 *= pm * p0.size / p0.sum()
    tstart = time.process_time() - c0
    out = {}
    if sweeps == 0:
        c0 = time.process_time()
        r = solve_contact(s, MAT, mean_pressure=pm, solver="pk", tol=1e-10,
                          compute_stiffness=False, initial=p0)
        out = dict(nit=r.nit, cpu=time.process_time() - c0 + tstart, smooth_cpu=0.0,
                   nprod_smooth=0, p=r.pressure, conv=conv_eq(CALLS, h.size),
                   fine_prod=CALLS[-1][1])
        return out
    A = local_matrix(op, b)
    NPROD[0] = 0
    c0 = time.process_time()
    u = Hprod(op, p0)
    log = []
    p, u = smooth(op, A, p0, u, h, b, sweeps, n_inner, log)
    ts = time.process_time() - c0
    if verbose:
        scale = float(np.ptp(h))
        print(f"   start kkt {kkt(p0, op.apply(p0), h, scale):.3e} A* {np.mean(p0 > 0):.4f}")
        for row in log:
            print(f"   sweep {row[0]}: s = {row[1]:.3f}, kkt {row[2]:.3e}, A* {row[3]:.4f}")
    c0 = time.process_time()
    r = solve_contact(s, MAT, mean_pressure=pm, solver="pk", tol=1e-10,
                      compute_stiffness=False, initial=p)
    return dict(nit=r.nit, cpu=time.process_time() - c0 + ts + tstart, smooth_cpu=ts,
                nprod_smooth=NPROD[0], p=r.pressure,
                conv=conv_eq(CALLS, h.size) + NPROD[0], fine_prod=CALLS[-1][1])


if __name__ == "__main__":
    import argparse
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=1024)
    ap.add_argument("--hurst", type=float, default=0.5)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--loads", type=float, nargs="+", default=[0.05])
    ap.add_argument("--b", type=int, default=8)
    ap.add_argument("--sweeps", type=int, nargs="+", default=[0, 1, 2, 4])
    ap.add_argument("--inner", type=int, default=10)
    ap.add_argument("--f32", action="store_true")
    ap.add_argument("--quiet", action="store_true")
    ap.add_argument("--edge-only", action="store_true")
    a = ap.parse_args()
    EDGE_ONLY[0] = a.edge_only
    if a.f32:
        DTYPE[0] = np.float32
    for pm in a.loads:
        ref = None
        for sw in a.sweeps:
            o = run(a.n, a.hurst, a.seed, pm, a.b, sw, a.inner, verbose=not a.quiet)
            if ref is None:
                ref = o["p"]
            dp = float(np.abs(o["p"] - ref).max() / ref.max())
            print(f"n={a.n} H={a.hurst} seed={a.seed} p={pm} b={a.b} sweeps={sw} inner={a.inner}: "
                  f"PK nit {o['nit']}, conv-eq {o['conv']:.1f} (fine PK {o['fine_prod']}), smooth products {o['nprod_smooth']}, smooth CPU "
                  f"{o['smooth_cpu']:.2f} s, CPU {o['cpu']:.2f} s, A* {np.mean(o['p'] > 0):.6f}, "
                  f"dp {dp:.1e}, windows/sweep {NWIN[-sw:] if sw else []} of {(a.n // a.b) ** 2}", flush=True)
