"""Weierstrass-Mandelbrot (WM) building block shared by the generators and genomics.

Every WM-type height field in roughfe -- the WM profile (thesis Eq. 2.1), the
multivariate WM surface (Eq. 2.2 / 3.17) and the truncated MWM profile that realises a
genome (Eq. 3.1) and its chromosomes (Eq. 3.2) -- is a finite double sum of the same
elementary wave

    a_{m,n} [cos(phi_{m,n}) - cos(q_n s_m + phi_{m,n})],

where ``s_m`` is the coordinate seen by ridge ``m`` (``x`` for a profile, the projection
``x cos(theta_m) + y sin(theta_m)`` for a surface). Each term vanishes at the origin,
so Z(0) = 0 exactly. :func:`wm_series` evaluates that sum, vectorised over points and
terms, and is the one implementation the rest of the package uses.
"""
from __future__ import annotations

import numpy as np

from ..errors import (InputError, check_finite_positive, check_in_interval, check_int,
                      check_real_array)
from .surface import Surface


def wm_series(coords, amplitudes, wavenumbers, phases, angles=None, chunk=1 << 22):
    """Evaluate ``sum_m sum_n a[m,n] (cos(phi[m,n]) - cos(q[n] s_m + phi[m,n]))``.

    Parameters
    ----------
    coords : ndarray or tuple of two ndarrays
        Profile: ``x`` (m), any shape. Surface: ``(x, y)`` (m), broadcastable.
    amplitudes : ndarray, shape (M, n_c)
        Amplitude ``a[m, n]`` of each wave (m).
    wavenumbers : ndarray, shape (n_c,)
        Angular wavenumbers ``q_n`` (rad/m).
    phases : ndarray, shape (M, n_c)
        Phases ``phi[m, n]`` (rad).
    angles : ndarray, shape (M,), optional
        In-plane ridge angles ``theta_m`` (rad) for a surface; required with ``(x, y)``.
    chunk : int
        Elements (points x terms) per block: ``max(1, chunk // n_c)`` points at a time, so
        a temporary holds at most ``max(chunk, n_c)`` doubles (32 MB by default; it was
        ``chunk`` points, ``chunk * n_c`` doubles, until round 2, session 33: 10 GB for a
        1024**2 MWM surface at gamma = 1.01).

    Returns
    -------
    ndarray
        Heights (m), with the broadcast shape of the coordinates.
    """
    amplitudes = np.atleast_2d(np.asarray(amplitudes, dtype=float))
    phases = np.atleast_2d(np.asarray(phases, dtype=float))
    q = np.asarray(wavenumbers, dtype=float).ravel()
    if amplitudes.shape != phases.shape or amplitudes.shape[1] != q.size:
        raise InputError(
            f"amplitudes {amplitudes.shape} and phases {phases.shape} must both have shape "
            f"(M, n_c) with n_c = len(wavenumbers) = {q.size}")
    surface = isinstance(coords, tuple)
    if surface:
        if angles is None:
            raise InputError("a surface (x, y) needs one in-plane angle per ridge")
        angles = np.asarray(angles, dtype=float).ravel()
        if angles.size != amplitudes.shape[0]:
            raise InputError(f"angles has {angles.size} entries, expected M = {amplitudes.shape[0]}")
        x, y = np.broadcast_arrays(*(np.asarray(c, dtype=float) for c in coords))
        out_shape = x.shape
        x, y = x.ravel(), y.ravel()
    else:
        x = np.asarray(coords, dtype=float)
        out_shape = x.shape
        x = x.ravel()
    out = np.empty(x.size)
    block = max(1, int(chunk) // max(q.size, 1))
    # amplitudes near the float range overflow the sums to inf / nan: no numpy warnings
    # (generate wm --amplitude 1e308 printed three before its error), the heights'
    # finiteness check (Surface: "heights must be finite") says it
    with np.errstate(over="ignore", invalid="ignore"):
        offset = float(np.sum(amplitudes * np.cos(phases)))
        for start in range(0, x.size, block):
            sl = slice(start, start + block)
            acc = np.zeros(x[sl].size)
            for m in range(amplitudes.shape[0]):          # M ridges (<= ~20): small loop
                s = (x[sl] if not surface else
                     x[sl] * np.cos(angles[m]) + y[sl] * np.sin(angles[m]))
                acc += np.cos(np.multiply.outer(s, q) + phases[m]) @ amplitudes[m]
            out[sl] = offset - acc
    return out.reshape(out_shape)


# -- random sources ------------------------------------------------------------------------
def resolve_rng(rng, name="rng"):
    """``(generator, seed)`` from a numpy Generator, an integer seed or None.

    An integer is used as the seed and returned for the metadata. ``None`` draws a fresh
    seed from the operating system's entropy (so the result is still reproducible from
    its metadata). A Generator is used as is; its seed is unknown (``None``). ``name``
    is the caller's name of the argument, for the error message.
    """
    if isinstance(rng, np.random.Generator):
        return rng, None
    if rng is None:
        seed = int(np.random.SeedSequence().entropy % (2 ** 63))
        return np.random.default_rng(seed), seed
    if isinstance(rng, bool) or not isinstance(rng, (int, np.integer)) or rng < 0:
        raise InputError(f"{name} must be a numpy Generator, a non-negative integer seed or None, "
                         f"got {rng!r}")
    return np.random.default_rng(int(rng)), int(rng)


# -- WM profile (Eq. 2.1) and MWM surface (Eq. 2.2 / 3.17) ---------------------------------
def _grid(n, length, ndim):
    length = check_finite_positive("length L (m)", length)
    n = check_int("n (grid points per side)", n, 2)
    x = np.arange(n) * length / n
    return (x,) if ndim == 1 else (x[:, None], x[None, :]), length


def _check_gamma_hurst(gamma, hurst):
    """``(gamma, H)`` as floats: ``gamma > 1`` (finite), ``0 < H < 1``; or InputError."""
    return (check_in_interval("gamma (frequency density)", gamma, 1, np.inf),
            check_in_interval("hurst H", hurst, 0, 1))


def _int_pair(name, value, lower="first", upper="second"):
    """``(a, b)`` as two integers with ``a <= b``, or an :class:`InputError`."""
    try:
        a, b = value
        pair = int(a), int(b)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be two integers ({lower}, {upper}), "
                         f"got {value!r}") from None
    if any(int(v) != float(v) for v in value):
        raise InputError(f"{name} must be two integers ({lower}, {upper}), got {value!r}")
    if pair[1] < pair[0]:
        raise InputError(f"{name} must satisfy {lower} <= {upper}, got {pair}")
    return pair


#: longest wave of a truncated WM sum, in profile lengths: a longer one is a constant
#: over the grid whose huge amplitude the subtraction cos(phi) - cos(...) loses in round-off
MAX_WAVE_LENGTHS = 1e6

#: most frequencies (terms per ridge) of a WM sum: gamma -> 1 packs ln(q_max/q_min)/ln(gamma)
#: of them into the band (4.8e9 for gamma = 1 + 1e-9 on 256 points: an allocation error)
MAX_FREQUENCIES = 100_000


#: relative distance below the Nyquist wavenumber under which a wave counts as at it
_NYQUIST_SLACK = 1e-9


def _nyquist_index(ratio, gamma):
    """Largest integer ``k`` with ``gamma**k < ratio (1 - slack)``: the last wave of a WM
    sum below the Nyquist wavenumber, ``ratio`` times the first, by the rule of
    :func:`_check_band` (``gamma**k == ratio`` up to round-off counts as reaching it)."""
    limit = ratio * (1 - _NYQUIST_SLACK)
    k = int(np.ceil(np.log(limit) / np.log(gamma))) - 1
    for _ in range(2):                  # round-off of the logarithms: at most one step
        if np.power(gamma, float(k)) >= limit:
            k -= 1
    return k


def _check_band(name, q_low, q_high, n, length, count=1):
    """The wavenumbers of a WM sum on a grid of ``n`` points over ``length``: none at or
    beyond the Nyquist wavenumber ``pi n / L`` (a wave at it is sampled as
    ``(-1)**i a cos(phi)``: its sine part is lost; beyond it, it is aliased onto a longer
    wave), none longer than :data:`MAX_WAVE_LENGTHS` profile lengths, at most
    :data:`MAX_FREQUENCIES` of them (``count``)."""
    nyquist = np.pi * n / length
    if not q_high < nyquist * (1 - _NYQUIST_SLACK):
        raise InputError(f"{name} reaches the wavenumber {q_high:.4g} rad/m, at or beyond the "
                         f"grid's Nyquist wavenumber pi n / L = {nyquist:.4g} rad/m (aliased "
                         f"on the nodes): shorten the range or refine the grid")
    if not q_low >= 2 * np.pi / (MAX_WAVE_LENGTHS * length):
        raise InputError(f"{name} starts at a wavelength {2 * np.pi / q_low:.4g} m, more "
                         f"than {MAX_WAVE_LENGTHS:.0e} times the length L = {length:.4g} m "
                         f"(a constant over the grid, lost in round-off)")
    _check_count(name, count)


def _check_count(name, count):
    """At most :data:`MAX_FREQUENCIES` frequencies in a WM sum, or an :class:`InputError`."""
    if count > MAX_FREQUENCIES:
        raise InputError(f"{name} holds {count} frequencies, more than {MAX_FREQUENCIES}: "
                         f"gamma this close to 1 approaches a continuous spectrum (use "
                         f"spectral_profile / spectral_surface) or shorten the range")


def wm_profile(n, length, hurst, gamma=1.5, amplitude=1e-6, q0=None, k_range=None, rng=None):
    """Weierstrass-Mandelbrot profile, thesis Eq. (2.1), truncated to ``k1 <= k <= k2``.

    ``W(x) = A sum_k gamma**(-H k) [cos(phi_k) - cos(q0 gamma**k x - phi_k)]``

    Eq. (2.1) writes the wavenumber as ``gamma**k`` (per unit length); ``q0`` (rad/m)
    carries that unit (default ``2 pi / L``, so ``k = 0`` is the wave spanning the
    profile). ``W(0) = 0`` exactly. The sign convention of the phase (``- phi_k`` here,
    ``+ phi`` in :func:`wm_series`) is immaterial for uniform random phases.

    Parameters
    ----------
    n : int
        Number of points; ``x = i L / n``.
    length : float
        Profile length ``L`` (m), ``Surface.size``.
    hurst : float
        Hurst exponent ``H`` in (0, 1), ``D = 2 - H``.
    gamma : float
        Frequency density ``gamma > 1`` (1.5 after Malcai et al.).
    amplitude : float
        ``A`` (m).
    q0 : float, optional
        Base angular wavenumber (rad/m); default ``2 pi / L``.
    k_range : (int, int), optional
        ``(k1, k2)``; default: all ``k`` with ``2 pi / L <= q0 gamma**k < pi n / L``
        (from the profile length to below the Nyquist wavenumber, Majumdar & Bhushan
        1991; until round 2, session 33 a wave exactly at the Nyquist wavenumber, as
        ``gamma = 2`` on ``2**p`` points gives, was kept and sampled as
        ``(-1)**i a cos(phi_k)``). A range reaching the Nyquist wavenumber (aliased),
        starting more than :data:`MAX_WAVE_LENGTHS` lengths long or holding more than
        :data:`MAX_FREQUENCIES` frequencies is refused.
    rng : Generator or int, optional
        Source of the phases ``phi_k ~ U[0, 2 pi)``; the seed is recorded.

    Returns
    -------
    Surface
        Non-periodic profile (m).
    """
    (x,), length = _grid(n, length, 1)
    gamma, hurst = _check_gamma_hurst(gamma, hurst)
    amplitude = check_finite_positive("amplitude A (m)", amplitude)
    q0 = 2 * np.pi / length if q0 is None else check_finite_positive("q0 (rad/m)", q0)
    if k_range is None:
        k1 = int(np.ceil(np.log(2 * np.pi / length / q0) / np.log(gamma) - 1e-9))
        k2 = _nyquist_index(np.pi * n / length / q0, gamma)
    else:
        k1, k2 = _int_pair("k_range", k_range, "k1", "k2")
    if k2 < k1:
        raise InputError(f"k_range must satisfy k1 <= k2, got ({k1}, {k2}): no wave lies "
                         f"between the profile length and the Nyquist wavenumber for this "
                         f"q0 = {q0:.4g} rad/m")
    with np.errstate(all="ignore"):                # gamma**k over/underflows: refused
        _check_band(f"k_range ({k1}, {k2})", q0 * np.power(gamma, float(k1)),
                    q0 * np.power(gamma, float(k2)), n, length, k2 - k1 + 1)
    gen, seed = resolve_rng(rng)
    k = np.arange(k1, k2 + 1)
    phases = gen.uniform(0, 2 * np.pi, k.size)
    amps = float(amplitude) * gamma ** (-hurst * k)
    h = wm_series(x, amps[None, :], q0 * gamma ** k, -phases[None, :])
    meta = {"generator": "wm", "equation": "thesis Eq. (2.1)", "hurst": hurst, "gamma": gamma,
            "amplitude_A": float(amplitude), "q0": q0, "k_range": [k1, k2], "seed": seed}
    return Surface(h, length, periodic=False, metadata=meta)


def mwm_coefficients(hurst, gamma, wavelength, n_range, ridges, amplitude=1.0, anisotropy=None):
    """Amplitudes ``(M, n_c)`` and wavenumbers ``(n_c,)`` of the MWM sum, Eq. (3.17).

    ``a[m, n] = A alpha_m sqrt(ln(gamma) / M) (2 pi / lambda)**(-H) gamma**((1-n) H)``,
    ``q_n = (2 pi / lambda) gamma**(n-1)`` for ``n_s <= n <= n_f``. Eq. (2.2) is the same
    sum with ``A_m = alpha_m A (2 pi / lambda)**(-H)`` and an infinite range of ``n``.

    ``ln`` is the natural logarithm, as in Ausloos & Berman (1985) and Yan & Komvopoulos
    (1998) and as in roughfe's genome (:mod:`roughfe.genomics.genome`). The thesis says
    below Eq. (2.2) that its "log" is base 10; that departs from the sources it cites and
    was followed here until round 2, session 33 (heights ``sqrt(log10 e) = 0.659`` times
    the present ones for the same A). The factor ``sqrt(ln gamma)`` is what makes the
    spectrum a density independent of ``gamma``: with ``alpha_m = 1`` the line of
    chromosome ``n`` holds the mean square ``M a_n**2 / 2 = (A**2 / 2) ln(gamma) q_n**(-2H)``,
    i.e. the angular mean PSD (normalisation of :mod:`.stats`) ``C(q) = A**2 q**-(2+2H) / (4 pi)``
    as ``gamma -> 1``. Yan & Komvopoulos' ``L (G/L)**(D-2)`` with ``n_YK = n - 1``,
    ``L = lambda``, ``D = 3 - H`` is ``A (2 pi / lambda)**(-H)``: ``A = (2 pi)**H G**(1-H)``.
    """
    gamma, hurst = _check_gamma_hurst(gamma, hurst)
    wavelength = check_finite_positive("wavelength lambda (m)", wavelength)
    if isinstance(ridges, bool) or not isinstance(ridges, (int, np.integer)) or ridges < 1:
        raise InputError(f"ridges M must be an integer >= 1, got {ridges!r}")
    n_s, n_f = _int_pair("n_range", n_range, "n_s", "n_f")
    _check_count(f"n_range ({n_s}, {n_f})", n_f - n_s + 1)
    amplitude = check_finite_positive("amplitude A (m^(1-H))", amplitude)
    alpha = np.ones(ridges) if anisotropy is None else check_real_array(
        "anisotropy (factors a_m)", anisotropy, unit="-").ravel()
    if alpha.size != ridges or np.any(alpha <= 0):
        raise InputError(f"anisotropy must hold M = {ridges} positive factors a_m, got {anisotropy!r}")
    nn = np.arange(n_s, n_f + 1)
    q_base = 2 * np.pi / wavelength
    scale = amplitude * np.sqrt(np.log(gamma) / ridges) * q_base ** (-hurst)
    amps = scale * alpha[:, None] * gamma ** ((1 - nn) * hurst)[None, :]
    return amps, q_base * gamma ** (nn - 1.0)


def mwm_surface(n, length, hurst, gamma=1.5, wavelength=None, n_range=None, ridges=10,
                amplitude=1e-6, anisotropy=None, angles=None, rng=None):
    """Multivariate Weierstrass-Mandelbrot surface, thesis Eq. (2.2) / (3.17).

    ``Z(x, y) = sum_n sum_m a[m, n] [cos(phi_mn) - cos(q_n (x cos th_m + y sin th_m) + phi_mn)]``
    with ``a`` and ``q_n`` of :func:`mwm_coefficients`. A ridge sees the projection
    ``n_m . x = x cos(theta_m) + y sin(theta_m)`` on its direction (the scalar product of
    Eq. 2.2, Ausloos & Berman 1985). Eq. (3.17) writes it in Yan & Komvopoulos' (1998)
    polar form ``sqrt(x^2 + y^2) cos(theta_m)`` with the angle defined below it as
    ``theta_m = atan(y / x) - theta0_m``, position dependent: the same projection, with
    ``angles`` the thesis' ``theta0_m``. Eq. (3.19) and the sequencing (``Theta`` in
    [0, pi], one angle per ridge) use ``theta_m`` as a constant; read so, the term is not
    a plane wave (and is not smooth at the origin). ``Z(0, 0) = 0``.

    Parameters
    ----------
    n : int
        Grid points per side; ``x = i L / n``.
    length : float
        Side ``L`` (m), ``Surface.size``.
    hurst, gamma : float
        ``H`` in (0, 1) (``D = 3 - H``), ``gamma > 1``.
    wavelength : float, optional
        ``lambda`` (m), the longest wave (``n = 1``); default ``L``.
    n_range : (int, int), optional
        ``(n_s, n_f)``; default from ``1`` to the last ``n`` with ``q_n < pi n / L``
        (strictly below Nyquist, as :func:`wm_profile`). A range reaching Nyquist
        (aliased) or holding more than :data:`MAX_FREQUENCIES` frequencies is refused.
    ridges : int
        Number of ridges ``M``.
    amplitude : float
        ``A`` of Eq. (3.17) (unit m^(1-H), so that ``a`` is in metres); with the natural
        logarithm (see :func:`mwm_coefficients`, which also gives ``A`` from Yan &
        Komvopoulos' ``G``).
    anisotropy : array of M floats, optional
        Factors ``alpha_m`` (0.85..1.15 for anisotropic surfaces); default ones.
    angles : array of M floats or "random", optional
        Ridge angles ``theta_m`` (rad). Default ``pi m / M`` (Ausloos & Berman);
        ``"random"`` draws them uniformly in [0, pi).
    rng : Generator or int, optional
        Source of the phases ``phi_mn ~ U[0, 2 pi)``; the seed is recorded.

    Returns
    -------
    Surface
        Non-periodic surface (m).
    """
    (x, y), length = _grid(n, length, 2)
    wavelength = length if wavelength is None else check_finite_positive(
        "wavelength lambda (m)", wavelength)
    gamma, hurst = _check_gamma_hurst(gamma, hurst)
    amplitude = check_finite_positive("amplitude A (m^(1-H))", amplitude)
    if n_range is None:
        if not wavelength <= MAX_WAVE_LENGTHS * length:   # (1e308 overflowed the index)
            raise InputError(f"wavelength lambda {wavelength:.4g} m is more than "
                             f"{MAX_WAVE_LENGTHS:.0e} times the length L = {length:.4g} m: "
                             "the default n_range starts at waves that are constants over "
                             "the grid (lost in round-off); shorten it or give n_range")
        n_f = 1 + _nyquist_index(np.pi * n / length * float(wavelength) / (2 * np.pi), gamma)
        n_range = (1, max(n_f, 1))
    amps, q = mwm_coefficients(hurst, gamma, wavelength, n_range, ridges, amplitude, anisotropy)
    _check_band(f"n_range {tuple(int(v) for v in n_range)} with wavelength "
                f"{wavelength:.4g} m", q[0], q[-1], n, length, q.size)
    gen, seed = resolve_rng(rng)
    if angles is None:
        theta = np.pi * np.arange(1, ridges + 1) / ridges
    elif isinstance(angles, str) and angles == "random":
        theta = gen.uniform(0, np.pi, ridges)
    else:
        theta = check_real_array("angles (ridge angles theta_m)", angles, unit="rad").ravel()
        if theta.size != ridges:
            raise InputError(f"angles must hold M = {ridges} ridge angles (rad), got "
                             f"{theta.size}")
    phases = gen.uniform(0, 2 * np.pi, amps.shape)
    h = wm_series((x, y), amps, q, phases, angles=theta)
    meta = {"generator": "mwm", "equation": "thesis Eq. (2.2)/(3.17)", "hurst": hurst,
            "gamma": gamma, "wavelength": float(wavelength), "n_range": list(n_range),
            "ridges": int(ridges), "amplitude_A": float(amplitude),
            "normalisation": "sqrt(ln(gamma)/M)",        # log10 until round 2, session 33
            "anisotropy": None if anisotropy is None else [float(a) for a in np.ravel(anisotropy)],
            "angles": [float(t) for t in theta], "seed": seed}
    return Surface(h, (length, length), periodic=False, metadata=meta)
