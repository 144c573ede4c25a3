"""Preconditioned projected nonlinear CG for the adhesive energy (gap variable).

In the spirit of Rey, Anciaux & Molinari (2017) (our own formulation): the unknowns are
the gap g >= 0 (and, for non-periodic operators, the displacement of the padding), the
gradient of Eq. (1) of :mod:`roughfe.bem.adhesion` is the traction residual
``r = K u + pbar + phi'(g)`` (Pa), and the search direction is preconditioned by the
compliance H = K^-1 (the exact inverse of the elastic Hessian; m/Pa), as the elastic
Polonsky-Keer CG is preconditioned by the stiffness:

* free set F: all points except those in contact (g = 0) pushed into it (r > 0);
* direction ``d = -P_F H P_F r + beta d_old`` (Polak-Ribiere+ beta on the preconditioned
  residual; d is reset to steepest descent when it is not a descent direction);
* line search along d: the elastic part is quadratic (``K(u + a d) = Ku + a Kd``, one
  FFT pair for Kd), the law is evaluated pointwise on the projected gap
  ``max(g + a d, 0)``, so f'(a) costs no FFT; the first
  local minimum along d (non-convex law) is bracketed from the elastic Newton step and
  refined by safeguarded secant steps to ``|f'(a)| <= 0.1 |f'(0)|``;
* projection: g <- max(g, 0); Ku is recomputed exactly (one FFT pair) when a point was
  clipped, and every 50 iterations.

Each iteration costs two FFT pairs (Kd, H r), like the elastic CG. The periodic mean gap
is held by the machine spring of :class:`roughfe.bem.adhesive_energy.AdhesiveEnergy`,
whose stiffness k0 is the preconditioner of the uniform mode.
"""
from __future__ import annotations

import numpy as np

from .directions import _StallWatch
from .solvers import pr_beta

#: The adhesive CG gives up (``_minimise`` hands over to L-BFGS-B) when its residual has
#: not halved in this many iterations: on the non-convex branch of a jump-in it crawled
#: for all 20000 (n = 1024, Johnson's sinusoid, exponential law; round 2, session 22),
#: where a warm step takes 30-60
ADHESIVE_STALL_WINDOW = 200


def _line_search(df, alpha0, slope0):
    """First zero of the directional derivative ``df(a)`` (increasing through it) for
    a > 0, from ``df(0) = slope0 < 0`` and the trial step ``alpha0``; returns the step."""
    lo, flo = 0.0, slope0
    hi, fhi = alpha0, df(alpha0)
    for _ in range(30):              # expand until the derivative turns non-negative
        if fhi >= 0.0:
            break
        lo, flo = hi, fhi
        hi *= 2.0
        fhi = df(hi)
    else:
        return hi
    a = hi
    for _ in range(30):              # Illinois (regula falsi) on the bracket [lo, hi]
        a = hi - fhi * (hi - lo) / (fhi - flo)
        fa = df(a)
        if abs(fa) <= 0.1 * abs(slope0):
            return a
        if fa > 0:
            hi, fhi = a, fa
            flo *= 0.5
        else:
            lo, flo = a, fa
            fhi *= 0.5
    return a


def adhesive_pcg(energy, x0, tol, max_iter):
    """Minimise ``energy`` (an ``adhesive_energy.AdhesiveEnergy``) from ``x0`` (scaled unknowns);
    returns ``(x, nit, residual, message)``. The residual is the largest projected
    traction over the traction scale (``energy.residual``)."""
    op, ell, scale = energy.op, energy.ell, energy.s0
    shape = energy.shape
    v = x0.reshape(shape) * ell                  # gap (and padding displacement), m
    periodic = op.periodic
    phys = slice(None) if periodic else energy.phys
    n = v[phys].size
    hspec = (op.spectrum.real if not periodic else op.spectrum.copy()).astype(np.float64)
    if periodic:
        hspec.flat[0] = 1.0 / energy.k0          # the spring's stiffness: uniform mode
    hspec = hspec.astype(np.float32)

    def K(f):
        return op.convolve_spectrum(f, energy.kspec)

    def displacement(vv):
        u = vv.copy()
        u[phys] -= energy.c
        return u

    ku = K(displacement(v))
    d = np.zeros(shape)
    z_old, gz_old = None, 0.0
    res, it, message = np.inf, 0, "max_iter reached"
    watch = _StallWatch(ADHESIVE_STALL_WINDOW)
    for it in range(1, int(max_iter) + 1):
        g = v[phys]
        _, phi1 = energy.law_at(g)
        r = ku.copy()
        pbar = 0.0
        if periodic:
            pbar = energy.k0 * (float(g.mean()) - energy.gbar)
            r += pbar
        r[phys] += phi1
        # free set: not in contact pushed into it
        pinned = np.zeros(shape, bool)
        pinned[phys] = (g <= 0.0) & (r[phys] > 0.0)
        rf = np.where(pinned, 0.0, r)
        res = float(np.max(np.abs(rf[phys]))) / scale
        if not periodic:
            res = max(res, float(np.max(np.abs(rf))) / scale)
        if res <= tol:
            message = "converged"
            break
        if watch.stalled(res):
            message = f"stalled (residual not halved in {ADHESIVE_STALL_WINDOW} iterations)"
            break
        z = op.convolve_spectrum(rf, hspec).astype(np.float64)
        z[pinned] = 0.0
        gz = float(np.vdot(rf, z))
        beta = 0.0 if z_old is None else float(pr_beta(float(np.vdot(rf, z - z_old)), gz_old))
        d *= beta
        d -= z
        d[pinned] = 0.0
        slope0 = float(np.vdot(r, d))
        if slope0 >= 0.0:                        # not a descent direction: restart
            d = -z
            slope0 = -gz
        z_old, gz_old = z, gz
        kd = K(d)
        dkd = float(np.vdot(d, kd))
        dphys = d[phys]
        gd = float(dphys.mean()) if periodic else 0.0
        curv = dkd + (energy.k0 * n * gd * gd if periodic else 0.0)
        dku = float(np.vdot(d, ku))
        gmean = float(g.mean()) if periodic else 0.0

        def df(a):
            # the law on the projected gap (the step is clipped at g = 0 afterwards; an
            # exponential law would overflow on a long step into g < 0)
            _, t = energy.law_at(np.maximum(g + a * dphys, 0.0))
            val = dku + a * dkd + float(np.vdot(dphys, t))
            if periodic:
                val += energy.k0 * n * (gmean + a * gd - energy.gbar) * gd
            return val

        alpha = _line_search(df, -slope0 / curv, slope0)
        if not (np.isfinite(alpha) and alpha > 0):
            message = f"line search failed (step {alpha!r})"
            break
        v += alpha * d
        gnew = v[phys]
        clipped = bool(np.any(gnew < 0.0))
        if clipped:
            np.maximum(gnew, 0.0, out=gnew)
        if clipped or it % 50 == 0:
            ku = K(displacement(v))
        else:
            ku += alpha * kd
    return (v / ell).ravel(), it, res, message
