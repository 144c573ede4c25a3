"""Analytic reference solutions checked by identities and by quadrature."""
import numpy as np
import pytest
from scipy import integrate

from roughfe.reference import (hertz_cylinder, hertz_sphere, uniform_rectangle_displacement,
                               uniform_strip_displacement, westergaard)

E_STAR = 2.0e9


def test_westergaard_pressure_integrates_to_mean_pressure():
    lam, g = 1e-3, 1e-6
    for s in (0.05, 0.5, 0.95, 1.5):
        sol = westergaard(g, lam, E_STAR, s * np.pi * E_STAR * g / lam)
        # quadrature of the square-root pressure: integrable edge singularity of slope
        total, _ = integrate.quad(sol.pressure, -lam / 2, lam / 2, points=[-sol.half_width,
                                  sol.half_width], limit=200)
        assert total / lam == pytest.approx(sol.mean_pressure, rel=1e-6)


def test_westergaard_limits():
    lam, g = 2e-3, 3e-6
    p_star = np.pi * E_STAR * g / lam
    assert westergaard(g, lam, E_STAR, 0.0).mean_gap == pytest.approx(g)   # no load: gap = g
    full = westergaard(g, lam, E_STAR, p_star)
    assert full.half_width == pytest.approx(lam / 2)
    assert full.mean_gap == pytest.approx(0.0, abs=1e-20)
    assert full.full_contact_pressure == pytest.approx(p_star)
    # half-width law p = p* sin^2(pi a / lambda)
    sol = westergaard(g, lam, E_STAR, 0.3 * p_star)
    assert p_star * np.sin(np.pi * sol.half_width / lam) ** 2 == pytest.approx(0.3 * p_star)


def test_hertz_sphere_load_approach_inverse_and_stiffness():
    R = 5e-3
    a = hertz_sphere(R, E_STAR, load=2.0)
    b = hertz_sphere(R, E_STAR, approach=a.approach)
    assert b.load == pytest.approx(2.0, rel=1e-12)
    # delta = (9 P^2 / (16 R E*^2))^(1/3)
    assert a.approach == pytest.approx((9 * 4.0 / (16 * R * E_STAR ** 2)) ** (1 / 3), rel=1e-12,
                                       abs=0)
    # K = dP/d delta by finite differences
    h = 1e-4 * a.approach
    k_fd = (hertz_sphere(R, E_STAR, approach=a.approach + h).load
            - hertz_sphere(R, E_STAR, approach=a.approach - h).load) / (2 * h)
    assert a.stiffness == pytest.approx(k_fd, rel=1e-6)
    # the pressure integrates to the load
    tot, _ = integrate.quad(lambda r: 2 * np.pi * r * a.pressure(r), 0, a.contact_radius)
    assert tot == pytest.approx(2.0, rel=1e-8)


def test_hertz_cylinder_pressure_integrates_to_load():
    c = hertz_cylinder(1e-2, E_STAR, 100.0)
    tot, _ = integrate.quad(c.pressure, -c.contact_radius, c.contact_radius)
    assert tot == pytest.approx(100.0, rel=1e-8)
    assert c.contact_radius == pytest.approx(np.sqrt(4 * 100.0 * 1e-2 / (np.pi * E_STAR)))


def test_love_rectangle_against_quadrature_and_centre_value():
    a, b = 0.5, 0.3
    for x, y in [(0.2, 0.1), (1.3, -0.7), (-2.0, 0.0), (0.5, 0.3)]:
        q, _ = integrate.dblquad(lambda t, s: 1 / np.hypot(x - s, y - t), -a, a, -b, b,
                                 epsabs=1e-12)
        assert uniform_rectangle_displacement(x, y, a, b, 1.0) == pytest.approx(q / np.pi,
                                                                                 rel=1e-9)
    # centre of a square of side 2a: 8 ln(1 + sqrt 2) p a / (pi E*) = 2.24 p a / E*
    assert uniform_rectangle_displacement(0, 0, 1, 1, 1) == pytest.approx(
        8 * np.log(1 + np.sqrt(2)) / np.pi, rel=1e-14, abs=0)


def test_love_cell_lattice_matches_the_four_corner_form_and_the_point_load():
    """The one-evaluation-per-corner kernel of a grid cell equals Love's four-corner sum
    (the same formula, near field to rounding, far field within its cancellation), and far
    away it is the Boussinesq point load of the cell's force, p d0 d1 / (pi E* r)."""
    from roughfe.reference import uniform_cell_displacement_grid
    d0, d1, e = 2e-6, 3e-6, 2e9
    g = uniform_cell_displacement_grid(400, 300, d0, d1, e)
    assert g.shape == (400, 300)
    k0, k1 = np.meshgrid(np.arange(400), np.arange(300), indexing="ij")
    four = uniform_rectangle_displacement(k0 * d0, k1 * d1, d0 / 2, d1 / 2, e)
    np.testing.assert_allclose(g[:20, :20], four[:20, :20], rtol=1e-11)
    np.testing.assert_allclose(g, four, rtol=1e-7)
    assert g[0, 0] == pytest.approx(four[0, 0], rel=1e-14, abs=0)
    r = np.hypot(k0 * d0, k1 * d1)
    far = r > 100 * max(d0, d1)
    np.testing.assert_allclose(g[far], d0 * d1 / (np.pi * e * r[far]), rtol=1e-4)


def test_strip_against_quadrature_and_reference_point():
    for x in (0.0, 0.3, 2.0):
        pts = [x] if abs(x) < 0.5 else None
        q, _ = integrate.quad(lambda s: np.log(3.0 / abs(x - s)), -0.5, 0.5, points=pts)
        assert uniform_strip_displacement(x, 0.5, 1.0, 1.0, 3.0) == pytest.approx(
            2 / np.pi * q, rel=1e-9)


@pytest.mark.parametrize("call", [
    lambda: westergaard(-1.0, 1.0, 1.0, 0.1),
    lambda: westergaard(1.0, 1.0, 1.0, -0.1),
    lambda: westergaard(1.0, 1.0, 0.0, 0.1),
    lambda: hertz_sphere(1.0, 1.0),
    lambda: hertz_sphere(1.0, 1.0, load=1.0, approach=1.0),
    lambda: hertz_sphere(1.0, 1.0, load=float("nan")),
    lambda: hertz_cylinder(0.0, 1.0, 1.0),
])
def test_bad_input_raises_value_error(call):
    with pytest.raises(ValueError):
        call()
