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

from ..errors import InputError


def wm_series(coords, amplitudes, wavenumbers, phases, angles=None, chunk=1 << 20):
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
        Points evaluated per block (bounds memory to ``chunk * n_c`` doubles).

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
    offset = float(np.sum(amplitudes * np.cos(phases)))
    out = np.empty(x.size)
    for start in range(0, x.size, chunk):
        sl = slice(start, start + chunk)
        acc = np.zeros(x[sl].size)
        for m in range(amplitudes.shape[0]):          # M ridges (<= ~20): small loop
            s = x[sl] if not surface else x[sl] * np.cos(angles[m]) + y[sl] * np.sin(angles[m])
            acc += np.cos(np.multiply.outer(s, q) + phases[m]) @ amplitudes[m]
        out[sl] = offset - acc
    return out.reshape(out_shape)
