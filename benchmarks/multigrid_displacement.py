"""A truncated monotone multigrid for the periodic BEM contact in the displacement, beside
the production Polonsky-Keer solver (issue 16 §1; docs/theory/02b_bem_performance.md, "A
monotone multigrid in the displacement, measured", round 2 session 20).

A research probe, not a solver of the package and not part of ``make bench``: it asks
whether a multigrid that works in the displacement throughout keeps its rate per cycle as
roughness octaves are added (the growth target of issue 16 §1), and what it is worth as a
start for PK. The problem is the periodic contact of a self-affine surface h (the growth
surfaces of ``bench_bem_growth.py``: L = 1 m, unit rms slope, roll-off at the box,
cut-off at the grid's Nyquist wavenumber; E* = 1) in the obstacle form

    min 1/2 u . A u   subject to   u >= psi = h - d,     p = A u,

with u the surface displacement into the body, A the exact inverse of the periodic
influence operator (symbol E*|q|/2, the preconditioner of PK) and a stiffness k = E*/L of
the mean mode (a layer of finite depth: any k > 0 gives the same zero-mean displacement
and pressure; k only ties the load to the approach d). The approach d is read off PK's
converged solution at the load, so the minimiser is PK's answer and every cycle is
compared with it directly (max |p - p*| / max p*).

The multigrid: levels down to 8^2; bilinear prolongation P and restriction P^T; Galerkin
coarse operators P^T A P, exact and still diagonal in Fourier space (the rfft of P^T A P
applied to one coarse delta); projected damped Jacobi smoothing (omega = 0.8 of the
symbol's mean); transfers truncated at the points on the obstacle; the obstacle of the
correction restricted as the maximum of psi - u over the 3 x 3 support of each coarse
node (every prolonged correction stays feasible); the coarse correction scaled by its
energy minimiser along it, clipped to [0, 1]; V(1, 1) cycles from u = max(psi, 0). A fine
cycle costs 4 products with A (the post-smoother's gradient is g + t A e).

Usage::

    .venv/bin/python benchmarks/multigrid_displacement.py [--sizes 512 1024 2048]
        [--hurst 0.5] [--seed 1] [--load 0.05] [--cycles 30] [--starts 4 6 8 10 12]

Prints per cycle the products (convolution-equivalents at the fine grid), the relative
energy error and max |p - p*| / max p*, and PK's iterations from the cycles' pressure at
``--starts``; writes ``benchmarks/output/multigrid_displacement.json``. ~1 min CPU at
the defaults, ~5 min with 4096.
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
import scipy.fft as sfft

HERE = Path(__file__).resolve().parent
OMEGA = 0.8            # damping of the projected Jacobi sweeps
COARSEST = 8           # points per side of the coarsest level
COARSE_SWEEPS = 200    # sweeps that solve the coarsest level


def stiffness_symbol(n, e_star=1.0, k=1.0, length=1.0):
    """rfft2 multiplier of A on n x n points: E*|q|/2, and ``k`` at q = 0 (Pa/m)."""
    q = 2 * np.pi * sfft.fftfreq(n, length / n)
    qr = 2 * np.pi * sfft.rfftfreq(n, length / n)
    a = e_star * np.sqrt(q[:, None] ** 2 + qr[None, :] ** 2) / 2
    a[0, 0] = k
    return a


def prolong(ec):
    """Bilinear interpolation, periodic, (m, m) -> (2m, 2m)."""
    m = ec.shape[0]
    e = np.empty((2 * m, 2 * m))
    e[::2, ::2] = ec
    e[1::2, ::2] = 0.5 * (ec + np.roll(ec, -1, 0))
    e[:, 1::2] = 0.5 * (e[:, ::2] + np.roll(e[:, ::2], -1, 1))
    return e


def restrict(r):
    """The transpose of :func:`prolong` (full weighting times 4)."""
    a = r[::2] + 0.5 * (r[1::2] + np.roll(r[1::2], 1, 0))
    return a[:, ::2] + 0.5 * (a[:, 1::2] + np.roll(a[:, 1::2], 1, 1))


def restrict_max(phi):
    """The maximum over the 3 x 3 fine support of each coarse node."""
    a = np.maximum(np.maximum(phi[::2], phi[1::2]), np.roll(phi[1::2], 1, 0))
    return np.maximum(np.maximum(a[:, ::2], a[:, 1::2]), np.roll(a[:, 1::2], 1, 1))


class Levels:
    """The symbols of A on every level (Galerkin), their diagonals and a product count
    in units of one fine convolution."""

    def __init__(self, n):
        self.n = n
        self.products = 0.0
        self.symbols = [stiffness_symbol(n)]
        m = n
        while m > COARSEST:
            unit = np.zeros((m // 2, m // 2))
            unit[0, 0] = 1.0
            kernel = restrict(self.apply(len(self.symbols) - 1, prolong(unit), count=False))
            self.symbols.append(sfft.rfft2(kernel).real)
            m //= 2
        self.diagonal = []
        for level, s in enumerate(self.symbols):
            m = n >> level     # interior rfft columns stand for two modes
            self.diagonal.append((s.sum() + s[:, 1:(m + 1) // 2].sum()) / m ** 2)

    def apply(self, level, u, count=True):
        if count:
            self.products += u.size / self.n ** 2
        return sfft.irfft2(self.symbols[level] * sfft.rfft2(u, workers=2), s=u.shape,
                           workers=2)

    def smooth(self, level, u, psi, f, sweeps):
        for _ in range(sweeps):
            g = self.apply(level, u) - f
            u = np.maximum(psi, u - OMEGA * g / self.diagonal[level])
        return u

    def vcycle(self, level, u, psi, f):
        """One V(1, 1) cycle on min 1/2 u.A u - f.u, u >= psi at ``level``."""
        if level == len(self.symbols) - 1:
            return self.smooth(level, u, psi, f, COARSE_SWEEPS)
        u = self.smooth(level, u, psi, f, 1)
        g = self.apply(level, u) - f
        active = u <= psi
        r = np.where(active, 0.0, -g)
        phi = np.where(active, -np.inf, psi - u)
        phic = restrict_max(phi)
        phic[~np.isfinite(phic)] = -1e300
        ec = self.vcycle(level + 1, np.zeros_like(phic), phic, restrict(r))
        e = prolong(ec)
        e[active] = 0.0
        ae = self.apply(level, e)
        eae = float(np.vdot(e, ae))
        t = min(1.0, max(0.0, float(np.vdot(r, e)) / eae)) if eae > 0 else 0.0
        u, g = u + t * e, g + t * ae
        return np.maximum(psi, u - OMEGA * g / self.diagonal[level])


def run(n, hurst, seed, load, cycles, starts):
    from roughfe.bem import Material, solve_contact
    from roughfe.surfaces.spectral import spectral_surface

    surface = spectral_surface(n, 1.0, hurst, rms_slope=1.0, rng=seed)
    h = surface.heights
    mat = Material(1.0, 0.0)
    c0 = time.process_time()
    ref = solve_contact(surface, mat, mean_pressure=load, solver="pk", tol=1e-10,
                        compute_stiffness=False)
    pk_cpu = time.process_time() - c0
    p_ref = ref.pressure
    lv = Levels(n)
    # PK's displacement with the mean mode's stiffness k = 1: u* = H p* + P / k
    compliance = np.where(lv.symbols[0] > 0, 1.0 / lv.symbols[0], 0.0)
    compliance[0, 0] = 0.0
    u_ref = sfft.irfft2(compliance * sfft.rfft2(p_ref), s=h.shape) + load
    touch = p_ref > 0
    d = float(np.mean((h - u_ref)[touch]))
    psi = h - d
    e_ref = 0.5 * float(np.vdot(u_ref, lv.apply(0, u_ref, count=False)))
    u = np.maximum(psi, 0.0)
    row = {"n": n, "hurst": hurst, "seed": seed, "load": load, "pk_iterations": int(ref.nit),
           "pk_cpu_s": pk_cpu, "area_fraction": float(touch.mean()), "cycles": [],
           "pk_from_cycles": []}
    print(f"{n}^2, H = {hurst}, seed {seed}, p/E* = {load}: PK {ref.nit} iterations, "
          f"{pk_cpu:.2f} s CPU, A* {touch.mean():.4f}")
    mg_cpu = 0.0
    for k in range(1, cycles + 1):
        c0 = time.process_time()
        u = lv.vcycle(0, u, psi, 0.0)
        mg_cpu += time.process_time() - c0
        p = lv.apply(0, u, count=False)
        p_mg = np.where(u > psi, 0.0, np.maximum(p, 0.0))
        err = float(np.max(np.abs(p_mg - p_ref)) / p_ref.max())
        energy = (0.5 * float(np.vdot(u, p)) - e_ref) / e_ref
        row["cycles"].append({"cycle": k, "products": lv.products, "cpu_s": mg_cpu,
                              "energy_error": energy, "pressure_error": err,
                              "area_fraction": float(np.mean(u <= psi))})
        print(f"  cycle {k:3d}: {lv.products:6.1f} products, energy error {energy:9.2e}, "
              f"max |dp| / max p {err:.2e}, A* {np.mean(u <= psi):.4f}")
        if k in starts:
            c0 = time.process_time()
            out = solve_contact(surface, mat, mean_pressure=load, solver="pk", tol=1e-10,
                                compute_stiffness=False, initial=p_mg)
            cpu = time.process_time() - c0
            dp = float(np.max(np.abs(out.pressure - p_ref)) / p_ref.max())
            row["pk_from_cycles"].append({"cycle": k, "iterations": int(out.nit),
                                          "cpu_s": cpu, "cycles_cpu_s": mg_cpu,
                                          "pressure_difference": dp})
            print(f"    PK from cycle {k}: {out.nit} iterations ({cpu:.2f} s CPU after "
                  f"{mg_cpu:.2f} s of cycles), max |dp| / max p {dp:.1e}")
    return row


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[512, 1024, 2048])
    ap.add_argument("--hurst", type=float, default=0.5)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--load", type=float, default=0.05, help="p / E*")
    ap.add_argument("--cycles", type=int, default=30)
    ap.add_argument("--starts", type=int, nargs="*", default=[4, 6, 8, 10, 12])
    ap.add_argument("--output", type=Path, default=HERE / "output" / "multigrid_displacement.json")
    args = ap.parse_args(argv)
    for n in args.sizes:
        if n < 2 * COARSEST or n & (n - 1):
            ap.error(f"--sizes: powers of 2 from {2 * COARSEST}, got {n}")
    rows = [run(n, args.hurst, args.seed, args.load, args.cycles, set(args.starts))
            for n in args.sizes]
    args.output.parent.mkdir(parents=True, exist_ok=True)
    tmp = args.output.with_name(args.output.name + ".tmp")
    tmp.write_text(json.dumps({"benchmark": "multigrid_displacement", "rows": rows}, indent=1))
    tmp.replace(args.output)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
