"""Smooth reference geometries on the BEM grid (the analytic cases of Hertz, JKR, Maugis).

:func:`sphere_cap` -- the parabolic approximation ``h = -r^2 / (2 R)`` of a sphere of
radius R (the geometry of Hertz's and Maugis' solutions), cell-centred on an ``n x n``
grid of side ``length`` with the apex between the four central cells, non-periodic.
"""
from __future__ import annotations

import numpy as np

from ..errors import check_finite_positive, check_int
from .surface import Surface


def sphere_cap(n, length, radius) -> Surface:
    """Parabolic sphere ``h = -(x^2 + y^2) / (2 R)`` (m) on an ``n x n`` grid of side
    ``length`` (m), centred, non-periodic; ``metadata`` records the radius."""
    n = check_int("n (grid points per side)", n, 2)
    length = check_finite_positive("length (m)", length)
    radius = check_finite_positive("radius (m)", radius)
    x = (np.arange(n) - n / 2 + 0.5) * length / n
    X, Y = np.meshgrid(x, x, indexing="ij")
    return Surface(-(X ** 2 + Y ** 2) / (2 * radius), length, periodic=False,
                   metadata={"generator": "sphere_cap", "radius": radius})
