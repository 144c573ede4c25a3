"""The fixed-contact-set solve H_cc x = 1 (roughfe.bem.contact_set_pressure_rate): the one
solve behind the exact stiffness K (Eq. 2.7) and the design sensitivities."""
import numpy as np
import pytest

from roughfe.bem import Material, contact_set_pressure_rate, solve_contact
from roughfe.errors import InputError
from roughfe.surfaces import Surface


def _profile(n=128):
    x = np.linspace(0.0, 1e-3, n)
    h = 1e-6 * (np.sin(2 * np.pi * x / 1e-3 * 3) + 0.3 * np.sin(2 * np.pi * x / 1e-3 * 17 + 1))
    return Surface(h, 1e-3)


@pytest.mark.parametrize("solver", ["dense", "pk"])
def test_mean_rate_is_the_exact_stiffness_and_the_pressure_derivative(solver):
    """mean(x) = K of the solution; (p(Delta + d) - p(Delta)) / d = x point by point while
    no point enters or leaves contact (d small), both solvers."""
    s, mat = _profile(), Material(1e6, 0.3)
    delta = 0.4 * float(np.ptp(s.heights))
    r = solve_contact(s, mat, delta=delta, solver=solver, tol=1e-12)
    x = contact_set_pressure_rate(r)
    assert x.shape == s.shape and np.all(x[~r.contact] == 0)
    assert np.all(x[r.contact] > 0)     # a positive approach loads every contact point
    assert float(x.mean()) == pytest.approx(r.stiffness, rel=1e-9)
    d = 1e-6 * delta
    r2 = solve_contact(s, mat, delta=delta + d, solver=solver, tol=1e-12)
    assert np.array_equal(r2.contact, r.contact)
    np.testing.assert_allclose((r2.pressure - r.pressure) / d, x, rtol=1e-4,
                               atol=1e-4 * np.abs(x).max())


def test_no_contact_or_full_periodic_contact_is_refused():
    h = np.sin(np.linspace(0, 2 * np.pi, 64, endpoint=False))
    s = Surface(1e-6 * h, 1e-3, periodic=True)
    r = solve_contact(s, Material(1e6, 0.0), delta=float(h.max() - h.mean()) * 1e-6)
    assert r.area_fraction == 1.0
    with pytest.raises(InputError, match="no finite pressure rate"):
        contact_set_pressure_rate(r)


def test_plastic_points_are_refused():
    """With a hardness the saturated points do not respond to the approach: the fixed-set
    rate of the elastic contact set does not apply."""
    s, mat = _profile(), Material(1e6, 0.3)
    r = solve_contact(s, mat, delta=0.5 * float(np.ptp(s.heights)), hardness=1e3)
    assert r.plastic_area_fraction > 0
    with pytest.raises(InputError, match="elastic contact"):
        contact_set_pressure_rate(r)
