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


def _rough_set(shape, fraction, seed):
    """A contact set of clustered patches (a smoothed random field above a level)."""
    rng = np.random.default_rng(seed)
    f = rng.standard_normal(shape)
    f = np.fft.irfftn(np.fft.rfftn(f) * np.exp(-0.02 * np.add.outer(
        np.fft.fftfreq(shape[0]) ** 2 * shape[0] ** 2,
        np.fft.rfftfreq(shape[1]) ** 2 * shape[1] ** 2)), s=shape)
    return f > np.quantile(f, 1.0 - fraction)


@pytest.mark.parametrize("kernel, shape", [("spectral", (64, 64)), ("love", (40, 33))])
@pytest.mark.parametrize("two_level", [False, True])
def test_unit_load_form_is_the_dense_solve(monkeypatch, deflations_made, kernel, shape,
                                          two_level):
    """x of the load-controlled form (H_cc y = mu 1, sum y = 1; x = y / mu) against the
    Cholesky solution of H_cc x = 1, with and without the two-level correction (its range
    widened to these small grids): the same x within 1e-7 of its maximum, K within 1e-11;
    at the stiffness' tolerance 1e-6, K still within 1e-9."""
    from roughfe.bem import contact
    from roughfe.bem.operators import influence_operator
    from roughfe.bem.stiffness import unit_load_rate
    monkeypatch.setattr(contact, "DEFLATION_SIDES", (1, 10 ** 4) if two_level else (0, 0))
    monkeypatch.setattr(contact, "CORRECTION_MIN_PARTS", 0)
    made = deflations_made
    op = influence_operator(shape, (1e-4, 1e-4 * shape[1] / shape[0]), 2e9, kernel)
    c = _rough_set(shape, 0.3, 1)
    idx = np.flatnonzero(c)
    ref = np.zeros(c.size)
    ref[idx] = np.linalg.solve(op.dense()[np.ix_(idx, idx)], np.ones(idx.size))
    x = unit_load_rate(op, c, tol=1e-10)
    assert made == ([shape] if two_level else [])
    assert np.abs(x.ravel() - ref).max() <= 1e-7 * ref.max()
    assert x.mean() == pytest.approx(ref.mean(), rel=1e-11)
    # the stiffness alone at its looser tolerance: K is the inverse energy of the unit
    # load, accurate to about the square of the solve's error
    from roughfe.bem.stiffness import STIFFNESS_TOL
    loose = unit_load_rate(op, c, tol=STIFFNESS_TOL)
    assert loose.mean() == pytest.approx(ref.mean(), rel=1e-9)
    x_error = np.abs(loose.ravel() - ref).max() / ref.max()
    assert x_error > 100 * abs(loose.mean() / ref.mean() - 1.0)    # K: quadratic


def test_restricted_cg_honours_its_tolerance_with_a_single_precision_preconditioner():
    """The fixed-set CG with the solver's float32 preconditioner: its true residual is at
    its tolerance (the float32 direction had made H d single precision and the recursive
    residual drift: a true residual of ~1e-7 where 1e-10 was asked)."""
    from roughfe.bem.contact import _cg_preconditioner
    from roughfe.bem.operators import influence_operator
    from roughfe.bem.solvers import restricted_cg
    op = influence_operator((96, 80), (1e-4, 1e-4), 2e9, "love")
    c = _rough_set(op.shape, 0.3, 2)
    rhs = np.random.default_rng(3).random(op.shape)
    x, _ = restricted_cg(op.apply, c, rhs, precond=_cg_preconditioner(op), tol=1e-10)
    res = (rhs - op.apply(x))[c]
    assert np.linalg.norm(res) <= 2e-10 * np.linalg.norm(rhs[c])
