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
* projection: g <- max(g, 0); Ku follows the step by increments, ``Ku += a Kd`` and,
  when a point was clipped, ``+= K(g+ - g)`` (one FFT pair of the cut).

Each iteration costs two FFT pairs (Kd, H r), like the elastic CG, and a third after a
clip. All three are float32 transforms (half the FFT work) into float64 fields: H r only
steers the direction, and Kd and K of the cut are increments, whose rounding (~1e-7 of
the increment) shrinks with the steps, as in the mixed-precision phase of
:func:`roughfe.bem.pk.polonsky_keer`. Ku is recomputed in double precision every
``EXACT_EVERY`` iterations and whenever the residual reaches the tolerance: a state is
reported converged only on that Ku, so the reported residual is the state's. Until round
2, session 31 Kd was a float64 product, and Ku was recomputed in double precision after
every clip; the CG vectors and masks lived on full-grid temporaries. Measured on the
measured AFM surface di-1.di (512^2, Love kernel, padded torus 1024^2, single thread):
the same iterations (+-4 %), pressures within 6e-7 of the traction scale, 1.2-1.4x less CPU
(docs/theory/07_adhesion_persson.md, "Speed"). The periodic mean gap is held by the
machine spring of :class:`roughfe.bem.adhesive_energy.AdhesiveEnergy`, whose stiffness
k0 is the preconditioner of the uniform mode (and whose rest length
:mod:`roughfe.bem.adhesive_minimise` moves between solves to meet the imposed mean gap).
"""
from __future__ import annotations

import numpy as np

from .directions import _StallWatch
from .fft import FFTWorkspace
from .pk_passes import _axpy
from .solvers import pr_beta

#: The adhesive CG gives up (``_minimise`` hands over to L-BFGS-B) when its residual has
#: not halved in this many iterations: on the non-convex branch of a jump-in it crawled
#: for all 20000 (n = 1024, Johnson's sinusoid, exponential law; round 2, session 22),
#: where a warm step takes 30-60
ADHESIVE_STALL_WINDOW = 200
#: Ku is recomputed in double precision at least this often (iterations)
EXACT_EVERY = 50
#: points per block of the law's evaluations (residual, line search): their temporaries
#: stay small and in cache. On the whole grid each evaluation allocated several fresh
#: grids (mmap'd pages: a page fault per 4 kB), and the law took 2.4x the CPU of the
#: blocked one (periodic di-1.di, 512^2, exponential law: 0.67 against 0.14 s a solve)
LAW_BLOCK = 1 << 13


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
    traction over the traction scale (``energy.residual``), from a double-precision Ku
    whenever it is reported converged."""
    op, ell, scale = energy.op, energy.ell, energy.s0
    shape = energy.shape
    v = x0.reshape(shape) * ell                  # gap (and padding displacement), m
    periodic = op.periodic
    phys = slice(None) if periodic else energy.phys
    g = v[phys]                                  # a view: moves with v
    n = g.size
    blocks = _blocks(g.shape)
    hspec = (op.spectrum.real if not periodic else op.spectrum.copy()).astype(np.float64)
    if periodic:
        hspec.flat[0] = 1.0 / energy.k0          # the spring's stiffness: uniform mode
    products = _Products(op, energy.kspec, hspec, shape)
    ku, fresh = products.exact(_displacement(v, phys, energy.c)), True
    rf, d, z, z_old = (np.zeros(shape) for _ in range(4))
    kd, clip = np.zeros(shape), np.zeros(shape)   # clip: zero off the grid, always
    gz_old, restart = 0.0, True
    res, it, message = np.inf, 0, "max_iter reached"
    watch = _StallWatch(ADHESIVE_STALL_WINDOW)
    for it in range(1, int(max_iter) + 1):
        pinned, res = _free_residual(energy, g, ku, rf, phys, scale, blocks)
        if res <= tol and not fresh:             # confirmed on a double-precision Ku
            ku, fresh = products.exact(_displacement(v, phys, energy.c)), True
            pinned, res = _free_residual(energy, g, ku, rf, phys, scale, blocks)
        if res <= tol:
            message = "converged"
            break
        if watch.stalled(res):
            message = f"stalled (residual not halved in {ADHESIVE_STALL_WINDOW} iterations)"
            break
        z, z_old = z_old, z
        products.single(rf, products.hspec, z)
        z[phys][pinned] = 0.0
        gz = float(np.vdot(rf, z))
        beta = 0.0 if restart else float(pr_beta(gz - float(np.vdot(rf, z_old)), gz_old))
        d *= beta
        d -= z
        d[phys][pinned] = 0.0
        slope0 = float(np.vdot(rf, d))           # = r.d: d vanishes where rf != r
        if slope0 >= 0.0:                        # not a descent direction: restart
            np.negative(z, out=d)
            slope0 = -gz
        gz_old, restart = gz, False
        products.single(d, products.kspec, kd)
        dkd = float(np.vdot(d, kd))
        dphys = d[phys]
        gd = float(dphys.mean()) if periodic else 0.0
        curv = dkd + (energy.k0 * n * gd * gd if periodic else 0.0)
        dku = float(np.vdot(d, ku))
        gmean = float(g.mean()) if periodic else 0.0

        def df(a):
            # the law on the projected gap (the step is clipped at g = 0 afterwards; an
            # exponential law would overflow on a long step into g < 0)
            val = dku + a * dkd
            for rows in blocks:
                step = dphys[rows]
                gap = np.multiply(step, a)
                gap += g[rows]
                np.maximum(gap, 0.0, out=gap)
                val += float(np.vdot(step, energy.law_at(gap, rows)[1]))
            if periodic:
                val += energy.k0 * n * (gmean + a * gd - energy.gbar) * gd
            return val

        alpha = _line_search(df, -slope0 / curv, slope0)
        if not (np.isfinite(alpha) and alpha > 0):
            message = f"line search failed (step {alpha!r})"
            break
        _axpy(v.reshape(-1), alpha, d.reshape(-1))        # v += alpha d, ku += alpha Kd
        _axpy(ku.reshape(-1), alpha, kd.reshape(-1))
        fresh = False
        cut = clip[phys]
        np.negative(g, out=cut)                  # how far the step went below g = 0
        if float(cut.max()) > 0.0:
            np.maximum(cut, 0.0, out=cut)
            g += cut                             # the projection g <- max(g, 0) ...
            products.single(clip, products.kspec, kd)
            _axpy(ku.reshape(-1), 1.0, kd.reshape(-1))  # ... and its traction K (g+ - g)
        if it % EXACT_EVERY == 0:
            ku, fresh = products.exact(_displacement(v, phys, energy.c)), True
    return (v / ell).ravel(), it, res, message


def _displacement(v, phys, c):
    """The displacement u = g - c on the grid (the padding's as it is), m."""
    u = v.copy()
    u[phys] -= c
    return u


def _blocks(shape):
    """Slices of the grid's first axis, each of about ``LAW_BLOCK`` points."""
    step = max(1, LAW_BLOCK // int(np.prod(shape[1:], dtype=np.int64)))
    return [slice(i, min(i + step, shape[0])) for i in range(0, shape[0], step)]


def _free_residual(energy, g, ku, rf, phys, scale, blocks):
    """The projected traction residual into ``rf`` (Pa; ``r = K u + pbar + phi'(g)``,
    zero where the point is in contact and pushed into it), and ``(pinned, res)``: those
    points (bool, on the grid) and max |rf| / S."""
    np.copyto(rf, ku)
    if energy.op.periodic:
        rf += energy.k0 * (float(g.mean()) - energy.gbar)
    rp = rf[phys]
    for rows in blocks:
        rp[rows] += energy.law_at(g[rows], rows)[1]
    pinned = (g <= 0.0) & (rp > 0.0)
    rp[pinned] = 0.0
    return pinned, max(float(rf.max()), -float(rf.min())) / scale


class _Products:
    """The FFT products of one adhesive solve on the unknowns' grid (periodic, or the
    padded torus), in one workspace and without full-grid temporaries: ``exact`` (Ku,
    float64) and ``single`` (float32 transforms of a float64 field, result cast into a
    float64 ``out``: the preconditioner H r, K d and K of the projection's cut)."""

    def __init__(self, op, kspec, hspec, shape):
        self.op, self.kspec64 = op, kspec
        self.kspec, self.hspec = kspec.astype(np.float32), hspec.astype(np.float32)
        self.work = FFTWorkspace()
        self.a32, self.b32 = np.empty(shape, np.float32), np.empty(shape, np.float32)

    def exact(self, u):
        return self.op.convolve_spectrum(u, self.kspec64, out=u, work=self.work)

    def single(self, x, spectrum, out):
        np.copyto(self.a32, x)
        np.copyto(out, self.op.convolve_spectrum(self.a32, spectrum, out=self.b32,
                                                 work=self.work))
        return out
