"""Random Midpoint Displacement (RMD) surfaces and profiles (thesis Sec. 2.1.1).

Recipe implemented (Peitgen & Saupe 1988, "The Science of Fractal Images", algorithms
MidPointFM1D and MidPointFM2D, without the optional "addition" of later stages):

Surface, grid ``(2**m + 1)**2``, Hurst exponent ``H = 3 - D``:

1. the four corners get independent N(0, delta^2) heights with ``delta = sigma0``;
2. for each level ``k = 1..m`` (cell width ``step = 2**(m-k+1)`` nodes):

   * ``delta *= 2**(-H/2)``; *diamond step*: the centre of every square cell gets the
     mean of its four corners plus ``delta * N(0, 1)``;
   * ``delta *= 2**(-H/2)``; *square step*: the midpoint of every cell edge gets the
     mean of its (four, or three on the boundary) neighbours at distance ``step/2``
     plus ``delta * N(0, 1)``.

   The variance of the displacements therefore drops by ``2**(-2H)`` per level (the
   lateral scale halves), which is what makes the surface self-affine with
   ``C(q) ~ q**(-2(1+H))``. Each level is one vectorised numpy operation.

The thesis text states the variance as ``sigma_1^2 = sigma_0^2 / 2**((3-D)/2)`` with
``sigma_0^2 = 1/sqrt(0.09)``: that is Peitgen-Saupe's factor of one half-step on the
*standard deviation* (``2**(-H/2)``) written as a factor on the variance. Taken
literally the variance would fall by ``2**(-H)`` per level instead of ``2**(-2H)``, a
surface of Hurst exponent ``H/2`` (``D`` too large by ``H/2``); roughfe follows Peitgen &
Saupe. The dimensionless ``sigma_0`` fixes no physical height. Here ``sigma0`` is a
length in metres, and ``rms_height`` optionally rescales the result to an exact rms
height (about the mean) -- the physically meaningful input.

Size convention: the thesis' ``L`` spans the ``2**m + 1`` nodes end to end (spacing
``delta = L / 2**m``). :class:`~roughfe.surfaces.surface.Surface` stores
``size = n * spacing``, so the returned ``size = (2**m + 1) * L / 2**m``. RMD surfaces
are not periodic.

Profile (``rmd_profile``, ``2**m + 1`` points, ``H = 2 - D``): ``X(0) = 0`` and
``X(L) ~ N(0, sigma0^2)``; at level ``k`` every midpoint gets the mean of its two
neighbours plus N(0, delta_k^2), ``delta_k^2 = sigma0^2 (1 - 2**(2H-2)) / 2**(2Hk)``
(MidPointFM1D). That displacement variance is what makes the increments between
neighbours of every level exactly fractional-Brownian,
``Var(X(t + L/2**k) - X(t)) = sigma0^2 2**(-2Hk)``:
``Var((X_b - X_a)/2 + D_k) = sigma0^2 2**(-2Hk) [2**(2H)/4 + 1 - 2**(2H-2)]``. It needs
the end-to-end increment to have variance ``sigma0^2``; until round 2, session 33 both
ends were drawn independently (``2 sigma0^2``), which added ``sigma0^2 4**(-k)`` at level
``k``: the increment variance over ``2**(-2Hk)`` was 1.96 / 1.70 / 1.53 / 1.39 / 1.27
for k = 0..4 at H = 0.8 (2000 profiles), a coarse-scale excess that bent the structure
function (1.00 at every level now).

Known artefacts (why Peitgen & Saupe offer "random successive additions"; measured on
200-400 surfaces of 129**2, docs/theory/01_surfaces.md): the surface is not stationary.
The statistics of a node depend on the level that made it: x-increments along the odd
columns (every node of which the last level made) have 0.86 times the variance of those
along the even columns at H = 0.8 (0.96 at H = 0.5). Near the boundary, where the square
step averages three neighbours, they differ too: x-increments along the edge y = 0 are
1.22 times the median, those from the first row to the second 0.82 (H = 0.8). The
diamond-square increments are fractional-Brownian only approximately: the structure
function's local exponent runs 0.59-0.71 for H = 0.8 and 0.43-0.46 for H = 0.5, and the
PSD fit of 257**2 surfaces gives 0.76 and 0.46 (means of 20). For an exactly self-affine,
stationary surface use :func:`~roughfe.surfaces.spectral.spectral_surface`.
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError, check_finite_positive, check_in_open_interval
from .surface import Surface
from .wm import resolve_rng


def _check_m(m, mmax=13, grid="2**m + 1"):
    """``int(m)``, or an InputError unless m is an integer in ``1..mmax``: the resolution
    level of a grid of ``grid`` points per side (13: 8193**2 float64 heights, 0.5 GB)."""
    if isinstance(m, bool) or not isinstance(m, (int, np.integer)):
        raise InputError(f"m (refinement levels, grid {grid}) must be an integer, got {m!r}")
    if not 1 <= m <= mmax:
        raise InputError(f"m must satisfy 1 <= m <= {mmax} (grid {grid} points per side), "
                         f"got {m}")
    return int(m)


def _rescale(h, rms_height):
    h = h - h.mean()
    if rms_height is None:
        return h
    target = check_finite_positive("rms_height (m)", rms_height)
    rms = np.sqrt(np.mean(h ** 2))
    return h * (target / rms)


def _neighbour_mean(z, known, rows, cols, half):
    """Mean of the known values at distance ``half`` (up/down/left/right) of the nodes
    ``z[rows, cols]`` (slices); missing neighbours outside the grid are skipped."""
    n = z.shape[0]
    zp = np.pad(z, half)
    kp = np.pad(known, half)
    total = np.zeros_like(z[rows, cols])
    count = np.zeros_like(total)
    for di, dj in ((-half, 0), (half, 0), (0, -half), (0, half)):
        r = slice(rows.start + half + di, n + half + di, rows.step)
        c = slice(cols.start + half + dj, n + half + dj, cols.step)
        total += zp[r, c] * kp[r, c]
        count += kp[r, c]
    return total / count


def rmd_surface(m, fractal_dimension, length, rng=None, rms_height=None, sigma0=1e-6):
    """RMD (diamond-square) rough surface, thesis Sec. 2.1.1 (recipe in the module doc).

    Parameters
    ----------
    m : int
        Refinement levels, ``1 <= m <= 13``; the grid has ``2**m + 1`` points per side.
    fractal_dimension : float
        Fractal dimension ``D`` in (2, 3); ``H = 3 - D``.
    length : float
        Thesis lateral size ``L`` (m) spanning the nodes end to end; spacing ``L / 2**m``.
    rng : numpy.random.Generator or int, optional
        Random source or seed (recorded in the metadata); None draws a fresh seed.
    rms_height : float, optional
        If given, the heights are rescaled to this rms about the mean (m).
    sigma0 : float
        Standard deviation (m) of the corner heights, the start of the variance cascade.

    Returns
    -------
    Surface
        Heights (m), mean zero, ``size = (2**m + 1) * L / 2**m`` per axis, not periodic.
    """
    m = _check_m(m)
    d = check_in_open_interval("fractal_dimension D of a surface", fractal_dimension, 2.0, 3.0)
    length = check_finite_positive("length L (m)", length)
    sigma0 = check_finite_positive("sigma0 (m)", sigma0)
    gen, seed = resolve_rng(rng)
    hurst = 3.0 - d
    n = 2 ** m + 1
    z = np.zeros((n, n))
    known = np.zeros((n, n))
    delta = sigma0
    corners = (slice(0, n, n - 1), slice(0, n, n - 1))
    z[corners] = delta * gen.standard_normal((2, 2))
    known[corners] = 1.0
    step = n - 1
    while step > 1:
        half = step // 2
        # diamond step: centres of the cells
        delta *= 2.0 ** (-hurst / 2)
        c = slice(half, n, step)
        e = slice(0, n, step)
        centre = (z[0:n - 1:step, 0:n - 1:step] + z[step::step, 0:n - 1:step]
                  + z[0:n - 1:step, step::step] + z[step::step, step::step]) / 4
        z[c, c] = centre + delta * gen.standard_normal(centre.shape)
        known[c, c] = 1.0
        # square step: midpoints of the cell edges (two families of nodes)
        delta *= 2.0 ** (-hurst / 2)
        for rows, cols in ((e, c), (c, e)):
            mean = _neighbour_mean(z, known, rows, cols, half)
            z[rows, cols] = mean + delta * gen.standard_normal(mean.shape)
            known[rows, cols] = 1.0
        step = half
    h = _rescale(z, rms_height)
    size = n * length / (n - 1)
    meta = {"generator": "rmd", "equation": "thesis Sec. 2.1.1 (Peitgen-Saupe diamond-square)",
            "m": m, "fractal_dimension": d, "hurst": hurst, "length_L": length,
            "sigma0": sigma0, "rms_height_target": rms_height, "seed": seed}
    return Surface(h, (size, size), periodic=False, metadata=meta)


def rmd_profile(m, fractal_dimension, length, rng=None, rms_height=None, sigma0=1e-6):
    """RMD rough profile (1D midpoint displacement), ``2**m + 1`` points.

    Parameters
    ----------
    m : int
        Refinement levels, ``1 <= m <= 24``.
    fractal_dimension : float
        Fractal dimension ``D`` of the profile in (1, 2); ``H = 2 - D``.
    length, rng, rms_height, sigma0
        As in :func:`rmd_surface`; ``size = (2**m + 1) * L / 2**m``.

    Returns
    -------
    Surface
        A non-periodic profile (m).
    """
    m = _check_m(m, mmax=24)
    d = check_in_open_interval("fractal_dimension D of a profile", fractal_dimension, 1.0, 2.0)
    length = check_finite_positive("length L (m)", length)
    sigma0 = check_finite_positive("sigma0 (m)", sigma0)
    gen, seed = resolve_rng(rng)
    hurst = 2.0 - d
    n = 2 ** m + 1
    z = np.zeros(n)
    z[-1] = sigma0 * gen.standard_normal()      # X(0) = 0: Var(X(L) - X(0)) = sigma0^2
    delta = sigma0 * np.sqrt(1.0 - 2.0 ** (2 * hurst - 2))
    step = n - 1
    while step > 1:
        half = step // 2
        delta *= 2.0 ** (-hurst)
        mid = (z[0:n - 1:step] + z[step::step]) / 2
        z[half::step] = mid + delta * gen.standard_normal(mid.size)
        step = half
    h = _rescale(z, rms_height)
    meta = {"generator": "rmd_profile", "equation": "thesis Sec. 2.1.1 (Peitgen-Saupe 1D)",
            "m": m, "fractal_dimension": d, "hurst": hurst, "length_L": length,
            "sigma0": sigma0, "rms_height_target": rms_height, "seed": seed}
    return Surface(h, n * length / (n - 1), periodic=False, metadata=meta)
