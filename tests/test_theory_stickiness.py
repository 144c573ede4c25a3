"""Pastewka-Robbins stickiness criterion (roughfe.theory.stickiness): the Hertzian edge
constants, Eq. (2) in closed form, its scaling with w, the range and the roughness."""
import numpy as np
import pytest

from roughfe.errors import InputError
from roughfe.surfaces.spectral import spectral_surface
from roughfe.surfaces.surface import Surface
from roughfe.theory.stickiness import EDGE_COEFFICIENT, pastewka_robbins


def _surface(scale=1.0):
    s = spectral_surface(64, 1e-5, 0.8, rms_height=1e-8, q_roll=2 * 2 * np.pi / 1e-5,
                         q_short=16 * 2 * np.pi / 1e-5, rng=3)
    return Surface(s.heights * scale, s.size, periodic=True)


def test_edge_coefficients_are_the_hertzian_gap_expansions():
    # Eq. (1): g = c_d (p_m / E*) xi^(3/2) / sqrt(a) just outside a Hertzian contact of
    # mean pressure p_m. Sphere (E* = R = 1): p_m = 4 a / (3 pi), gap from Johnson
    # (1985) Eq. 3.42; cylinder: p_m = pi a / 8, gap' = sqrt(x^2 - a^2) / R integrated.
    a, xi = 0.3, 1e-6 * 0.3
    r = a + xi
    g_sphere = (r * r / 2 - a * a + ((2 * a * a - r * r) * np.arcsin(a / r)
                                    + a * np.sqrt(r * r - a * a)) / np.pi)
    s = np.sqrt(r * r - a * a)
    g_cyl = 0.5 * (r * s - a * a * np.arcsinh(s / a))
    for dim, g, pm in ((2, g_sphere, 4 * a / (3 * np.pi)), (1, g_cyl, np.pi * a / 8)):
        assert g / (pm * xi ** 1.5 / np.sqrt(a)) == pytest.approx(EDGE_COEFFICIENT[dim],
                                                                   rel=1e-5)


def test_closed_form_and_scaling():
    s = _surface()
    e_star, w, dr = 1.33e6, 1e-4, 5e-9
    r = pastewka_robbins(s, e_star, w, dr)
    h1, h2 = r.rms_slope, r.rms_curvature
    a = 2 * h1 / h2
    closed = 2 * (2 * w / e_star / (h1 * dr)) * (2 * dr / (2 * np.sqrt(2) * h1 * a)) ** (2 / 3)
    assert r.stickiness == pytest.approx(closed, rel=1e-12)
    assert r.kappa_ratio == pytest.approx(1 / (1 - r.stickiness), rel=1e-12)
    # linear in w; Delta_r^(-1/3); heights x lambda -> lambda^(-5/3) (h_rms itself does not
    # enter, only slopes and curvatures); w and E* only as l_a = w / E*
    assert pastewka_robbins(s, e_star, 3 * w, dr).stickiness == pytest.approx(
        3 * r.stickiness, rel=1e-12)
    assert pastewka_robbins(s, e_star, w, 8 * dr).stickiness == pytest.approx(
        r.stickiness / 2, rel=1e-12)
    assert pastewka_robbins(_surface(2.0), e_star, w, dr).stickiness == pytest.approx(
        r.stickiness * 2 ** (-5 / 3), rel=1e-9)
    assert pastewka_robbins(s, 2 * e_star, 2 * w, dr).stickiness == pytest.approx(
        r.stickiness, rel=1e-12)
    # the verdict flips at S = 1
    w1 = w / r.stickiness
    assert not pastewka_robbins(s, e_star, 0.99 * w1, dr).sticky
    assert pastewka_robbins(s, e_star, 1.01 * w1, dr).sticky
    assert r.describe()["references"]


def test_profile_uses_the_strip_edge():
    x = np.arange(256) / 256
    prof = Surface(1e-8 * (np.cos(2 * np.pi * 8 * x) + 0.3 * np.cos(2 * np.pi * 21 * x)), 1e-5,
                   periodic=True)
    r = pastewka_robbins(prof, 1e6, 1e-4, 5e-9)
    a = 2 * r.rms_slope / r.rms_curvature
    d = (5e-9 * np.sqrt(a) / (EDGE_COEFFICIENT[1] * r.rms_slope / 2)) ** (2 / 3)
    assert r.dimension == 1 and r.ring_width == pytest.approx(d, rel=1e-12)
    assert r.stickiness == pytest.approx((1e-4 / 5e-9) / r.repulsive_pressure * d / a, rel=1e-12)


@pytest.mark.parametrize("args, match", [((1e6, 0.0, 1e-9), "work of adhesion"),
                                         ((1e6, 1e-3, float("nan")), "range"),
                                         ((-1.0, 1e-3, 1e-9), "E"),
                                         ])
def test_bad_input(args, match):
    with pytest.raises(InputError, match=match):
        pastewka_robbins(_surface(), *args)


def test_flat_surface_is_refused():
    with pytest.raises(InputError, match="rough surface"):
        pastewka_robbins(Surface(np.zeros((8, 8)), 1e-5, periodic=True), 1e6, 1e-3, 1e-9)
