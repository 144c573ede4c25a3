"""Self-affine periodic surfaces and profiles by Fourier filtering.

The standard input of Tamaas and contact.engineering (Persson et al. 2005; Jacobs,
Junge & Pastewka 2017). The target PSD (normalisation of :mod:`roughfe.surfaces.stats`)
is isotropic with a roll-off:

    C(q) = C0                                  q_l <= |q| <  q_r
    C(q) = C0 (|q| / q_r)**(-(d + 2H))         q_r <= |q| <= q_s
    C(q) = 0                                   otherwise (and at q = 0)

with ``d`` the topological dimension: ``q**-2(1+H)`` for a surface, ``q**-(1+2H)`` for a
profile (both self-affine with Hurst exponent ``H``).

The Fourier coefficients are ``h~(q) = sqrt(C(q) dqx dqy) xi(q)``, where ``xi`` is the
(normalised) DFT of real white noise: it is Hermitian (``xi(-q) = conj xi(q)``) by
construction, so the heights are real, and its phases are uniform on [0, 2 pi).
``amplitudes="gaussian"`` keeps the Gaussian modulus of ``xi`` (``E|xi|^2 = 1``);
``"fixed"`` keeps only its random phase (``|xi| = 1``: the PSD of one realisation is
exactly ``C0`` times the shape). Modes at the Nyquist wavenumber of an even grid are set
to zero (their slope is undefined). The result is periodic with period ``size``.

``C0`` is set from the target rms height (or rms gradient), both computed as in
:mod:`.stats` (spectrally for periodic data), in one of two ways (``match``):

* ``"realisation"`` (default): the realisation's own rms height (slope) equals the
  target exactly. With Gaussian amplitudes ``C0`` is then a random variable (the target
  over the realisation's own sum), and the *ensemble mean* PSD is not ``C0`` times the
  shape: the few long waves that dominate the rms height fluctuate, and dividing by
  them inflates the mean short-wave PSD. Measured (rms height target, no plateau), the
  mean PSD of the shorter-wave half of the modes over the target's: 1.05 / 1.10 / 1.17
  for 128**2 surfaces at H = 0.3 / 0.5 / 0.8, and 1.18 / 1.37 / 1.72 for 1024-point
  profiles (the mean square slope alike); 1.00 with a plateau of 8 Fourier modes.
* ``"expectation"``: ``C0 = target**2 / sum(shape dq**d)`` over the grid's modes, so the
  ensemble mean PSD is exactly ``C0`` times the shape (a Gaussian random field with the
  target spectrum, as SurfaceTopography's ``fourier_synthesis``, which integrates the
  continuous spectrum instead of summing the grid's modes) and the target is met by the
  ensemble mean of the mean square height (slope), not by each realisation.

With ``amplitudes="fixed"`` the two coincide. ``metadata["C0"]`` records the ``C0`` used
(m**4 surface, m**3 profile; the PSD normalisation of :mod:`.stats`, Persson's:
``(2 pi)**d C0`` is the prefactor in SurfaceTopography's and contact.engineering's).

``H = 1`` is allowed (``C ~ q**-(d+2)``, the smooth limit; Persson's theory and Tamaas
take H in (0, 1]); ``H <= 0`` or ``H > 1`` is refused.
"""
from __future__ import annotations

import numpy as np

from ..errors import (InputError, check_finite_nonnegative, check_finite_positive,
                      check_in_interval, check_int)
from .stats import angular_wavevectors, periodic_moment, rfft_full_sum
from .surface import Surface, _as_size
from .wm import resolve_rng


def self_affine_psd(q, hurst, q_roll, q_short, q_long=0.0, ndim=2):
    """Shape of the isotropic PSD above with ``C0 = 1`` (dimensionless), at ``|q|`` (rad/m).

    Exponent ``-(ndim + 2 H)``: ``ndim = 2`` surface, ``ndim = 1`` profile.
    """
    q = np.asarray(q, dtype=float)
    c = np.maximum(q, q_roll)          # in place from here: one array of q's size
    c /= q_roll                         # 1 below the roll-off
    c **= -(ndim + 2.0 * hurst)
    c[(q < q_long) | (q > q_short) | (q <= 0)] = 0.0
    return c


def _shape_and_size(n, size, ndim):
    """(shape, size) of the grid: ``n`` points per axis (one integer or one per axis) and
    ``size`` in m (one number or one per axis, as :class:`Surface` takes it)."""
    ns = (n,) * ndim if np.ndim(n) == 0 else tuple(n)
    if len(ns) != ndim:
        raise InputError(f"n must give {ndim} grid size(s) >= 2, got {n!r}")
    shape = tuple(check_int(f"n (grid points along axis {k})", v, 2) for k, v in enumerate(ns))
    return shape, _as_size(size, ndim)


def _synthesise(ndim, n, size, hurst, rms_height, rms_slope, q_long, q_roll, q_short,
                amplitudes, rng, match):
    shape, size = _shape_and_size(n, size, ndim)
    hurst = check_in_interval("hurst H", hurst, 0, 1, closed="right")
    if (rms_height is None) == (rms_slope is None):
        raise InputError("give exactly one of rms_height (m) and rms_slope (-), "
                         f"got rms_height={rms_height!r}, rms_slope={rms_slope!r}")
    target = check_finite_positive("rms_height (m)" if rms_slope is None else "rms_slope",
                                   rms_height if rms_slope is None else rms_slope)
    if amplitudes not in ("gaussian", "fixed"):
        raise InputError(f"amplitudes must be 'gaussian' or 'fixed', got {amplitudes!r}")
    if match not in ("realisation", "expectation"):
        raise InputError(f"match must be 'realisation' or 'expectation', got {match!r}")
    q_min = 2 * np.pi / max(size)
    q_nyq = min(np.pi * nn / s for nn, s in zip(shape, size))
    q_roll = q_min if q_roll is None else check_finite_positive("q_roll (rad/m)", q_roll)
    q_short = q_nyq if q_short is None else check_finite_positive("q_short (rad/m)", q_short)
    q_long = 0.0 if q_long is None else check_finite_nonnegative("q_long (rad/m)", q_long)
    if q_nyq <= q_min and q_short == q_nyq:
        raise InputError(f"grid too small: {'x'.join(map(str, shape))} points have no Fourier "
                         f"mode between the lowest wavenumber 2 pi/L = {q_min:.6g} rad/m and the "
                         f"Nyquist wavenumber {q_nyq:.6g} rad/m; use at least 3 points per axis "
                         "(or give q_short explicitly on a strip)")
    if not (0 <= q_long <= q_roll < q_short):
        raise InputError(f"wavenumbers must satisfy 0 <= q_long <= q_roll < q_short (rad/m), got "
                         f"q_long={q_long!r}, q_roll={q_roll!r}, q_short={q_short!r}")
    gen, seed = resolve_rng(rng)
    # memory: one complex half-spectrum and two real half-grids at most (in-place passes)
    noise = np.fft.rfftn(gen.standard_normal(shape))
    noise /= np.sqrt(np.prod(shape))                     # E|xi|^2 = 1
    if amplitudes == "fixed":
        noise = np.exp(1j * np.angle(noise))
    qs = list(angular_wavevectors(shape, size))
    qs[-1] = qs[-1][..., : shape[-1] // 2 + 1]          # rfft keeps q_last >= 0
    qs[-1] = np.abs(qs[-1])
    qabs = np.zeros(noise.shape)
    for q in qs:
        qabs += q ** 2
    np.sqrt(qabs, out=qabs)
    filt = self_affine_psd(qabs, hurst, q_roll, q_short, q_long, ndim)
    for axis, nn in enumerate(shape):                    # drop Nyquist modes of even axes
        if nn % 2 == 0:
            idx = [slice(None)] * ndim
            idx[axis] = nn // 2
            filt[tuple(idx)] = 0.0
    if not np.any(filt > 0):
        raise InputError(f"no Fourier mode lies in [q_long, q_short] = [{q_long}, {q_short}] rad/m "
                         f"on this grid")
    npts = float(np.prod(shape))
    if match == "expectation":     # E<h^2> = sum shape / N^2 (E|xi|^2 = 1), E<|grad h|^2> alike
        if rms_slope is not None:
            qabs **= 2
            qabs *= filt
        expected = rfft_full_sum(filt if rms_slope is None else qabs, shape[-1]) / npts ** 2
    del qabs
    np.sqrt(filt, out=filt)
    noise *= filt
    del filt
    h = np.fft.irfftn(noise, s=shape, axes=tuple(range(ndim)))
    del noise
    # the statistics of :mod:`.stats` on the raw array (no Surface copy of it)
    if match == "realisation":
        achieved = (float(np.std(h)) if rms_slope is None else
                    float(np.sqrt(periodic_moment(h, size, 1))))
    else:
        achieved = float(np.sqrt(expected))
    scale = target / achieved
    h *= scale
    # h~ = scale sqrt(shape) xi / N = sqrt(C0 shape dq^d) xi
    with np.errstate(over="ignore"):    # (a Python float overflowed: a traceback)
        c0 = float(np.float64(scale) ** 2 / npts ** 2 / np.prod([2 * np.pi / s for s in size]))
    if not np.isfinite(c0):
        raise InputError(f"{'rms_height (m)' if rms_slope is None else 'rms_slope'} = "
                         f"{target!r} scales the heights by {scale:.3g}: their power spectrum "
                         f"(C0) lies beyond the floating-point range")
    meta = {"generator": "spectral", "hurst": hurst, "q_long": q_long, "q_roll": q_roll,
            "q_short": q_short, "amplitudes": amplitudes, "match": match,
            "rms_height_target": rms_height, "rms_slope_target": rms_slope, "C0": c0,
            "seed": seed}
    return Surface(h, size, periodic=True, metadata=meta)


def spectral_surface(n, size, hurst, rms_height=None, rms_slope=None, q_long=None, q_roll=None,
                     q_short=None, amplitudes="gaussian", rng=None,
                     match="realisation") -> Surface:
    """Periodic self-affine surface by Fourier filtering (PSD in the module docstring).

    Parameters
    ----------
    n : int or (int, int)
        Grid points per axis.
    size : float or (float, float)
        Period ``L`` per axis (m).
    hurst : float
        Hurst exponent ``H`` in (0, 1]; ``C ~ q**(-2(1+H))``, ``D = 3 - H``.
    rms_height, rms_slope : float
        Exactly one target: rms height (m) or rms gradient (-).
    q_long, q_roll, q_short : float, optional
        Long-wavelength cut-off ``q_l`` (default 0), roll-off ``q_r`` (default
        ``2 pi / L``: no plateau) and short-wavelength cut-off ``q_s`` (default Nyquist
        ``pi n / L``), rad/m.
    amplitudes : {"gaussian", "fixed"}
        Gaussian random field, or random phases with the exact target PSD.
    rng : Generator or int, optional
        Random source or seed (recorded).
    match : {"realisation", "expectation"}
        Meet the target exactly on this realisation, or in the ensemble mean with the
        ensemble mean PSD exactly the target (module docstring: the first biases the
        mean short-wave PSD of Gaussian amplitudes upwards).

    Returns
    -------
    Surface
        Periodic surface, mean zero (m).
    """
    return _synthesise(2, n, size, hurst, rms_height, rms_slope, q_long, q_roll, q_short,
                       amplitudes, rng, match)


def spectral_profile(n, size, hurst, rms_height=None, rms_slope=None, q_long=None, q_roll=None,
                     q_short=None, amplitudes="gaussian", rng=None,
                     match="realisation") -> Surface:
    """Periodic self-affine profile, ``C ~ q**(-(1+2H))`` above ``q_r`` (``D = 2 - H``).

    Parameters as in :func:`spectral_surface`, one axis; ``rms_slope`` is ``sqrt<h'^2>``.
    """
    return _synthesise(1, n, size, hurst, rms_height, rms_slope, q_long, q_roll, q_short,
                       amplitudes, rng, match)
