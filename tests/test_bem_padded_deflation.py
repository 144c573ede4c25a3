"""The two-level correction of non-periodic solves (round 2, session 16): the periodic
block deflation on the operator's padded torus (:mod:`roughfe.bem.padded_deflation`).

Its premise is checked directly (between two surface points the torus kernel is the
half-space kernel, so the torus operator on a field that vanishes off the surface is the
non-periodic H), then its use: the same solution of Eq. 2.5-2.6 as the plain solve, in
fewer iterations, on by default where the FFT grid has ``DEFLATION_SIDES``^2 points."""
import numpy as np
import pytest

from roughfe.bem import Material, solve_contact
from roughfe.bem.operators import fast_length, influence_operator
from roughfe.bem.padded_deflation import (PaddedBlockDeflation, _torus_operator,
                                          torus_shape)
from roughfe.errors import InputError
from roughfe.surfaces import rmd_surface

KW = dict(solver="pk", tol=1e-10, compute_stiffness=False)


@pytest.mark.parametrize("shape", [(12, 12), (37, 50), (129, 100)])
def test_the_torus_operator_is_the_half_space_operator_on_the_surface(shape):
    op = influence_operator(shape, (1e-4, 1e-4 * shape[1] / shape[0]), 2e9, "love")
    torus = torus_shape(shape)
    for n, p in zip(shape, torus):
        assert p % 8 == 0 and p >= 2 * n - 1 and fast_length(p // 8) == p // 8
    top = _torus_operator(op, 8)
    assert top.periodic and top.shape == torus
    rng = np.random.default_rng(2)
    p = rng.random(shape)
    big = np.zeros(torus)
    big[:shape[0], :shape[1]] = p
    u = top.apply(big)
    np.testing.assert_allclose(u[:shape[0], :shape[1]], op.apply(p), rtol=1e-12,
                               atol=1e-12 * np.abs(op.apply(p)).max())
    # a positive definite circulant: the coarse correction's preconditioner inverts it
    assert top.spectrum.real.min() > 0


def test_needs_a_non_periodic_surface_operator():
    with pytest.raises(InputError, match="non-periodic 2D"):
        PaddedBlockDeflation(influence_operator((64, 64), (1.0, 1.0), 1.0, "spectral"))
    with pytest.raises(InputError, match="non-periodic 2D"):
        PaddedBlockDeflation(influence_operator((64,), (1.0,), 1.0, "strip"))


def test_same_solution_in_fewer_iterations_and_on_by_default(deflations_made):
    # a non-periodic RMD surface 513^2 (FFT grid 1080^2, in the automatic range):
    # the default uses the correction; it reaches the plain solve's contact set and
    # pressures (KKT tolerance 1e-10) in fewer iterations (measured 45 -> 21)
    s = rmd_surface(9, 2.3, 1e-4, rng=1)
    m = Material(1e9, 0.3)
    slope = float(np.sqrt(np.mean(np.gradient(s.heights, s.spacing[0], axis=0) ** 2)))
    load = 0.05 * m.E_star * slope
    made = deflations_made
    auto = solve_contact(s, m, mean_pressure=load, **KW)
    assert made and made[-1] == (513, 513)
    made.clear()
    off = solve_contact(s, m, mean_pressure=load, coarse_correction=False, **KW)
    assert not made
    assert auto.nit < 0.7 * off.nit
    assert np.array_equal(auto.contact, off.contact)
    assert np.abs(auto.pressure - off.pressure).max() <= 1e-7 * off.pressure.max()
    assert auto.mean_pressure == pytest.approx(load, rel=1e-12)
    # forced on below the automatic range (257^2): the same solution again
    small = rmd_surface(8, 2.3, 1e-4, rng=3)
    on = solve_contact(small, m, mean_pressure=load, coarse_correction=True, **KW)
    plain = solve_contact(small, m, mean_pressure=load, **KW)
    assert made == [(257, 257)]
    assert np.array_equal(on.contact, plain.contact)
    assert np.abs(on.pressure - plain.pressure).max() <= 1e-7 * plain.pressure.max()


def test_displacement_control_takes_it_in_the_full_space(deflations_made):
    # the torus operator is positive definite: in displacement control the correction
    # acts without the zero-mean projection; the same solution as the plain solve in
    # fewer iterations (513^2 at 40 % of the peak-to-valley: measured 65 -> 31), on by
    # default from the rigid interpenetration's contact parts
    s = rmd_surface(9, 2.3, 1e-4, rng=1)
    m = Material(1e9, 0.3)
    delta = 0.4 * float(np.ptp(s.heights))
    auto = solve_contact(s, m, delta=delta, **KW)
    assert deflations_made == [(513, 513)]
    off = solve_contact(s, m, delta=delta, coarse_correction=False, **KW)
    assert len(deflations_made) == 1
    assert auto.nit < 0.7 * off.nit
    assert np.array_equal(auto.contact, off.contact)
    assert np.abs(auto.pressure - off.pressure).max() <= 1e-7 * off.pressure.max()
    assert auto.mean_pressure == pytest.approx(off.mean_pressure, rel=1e-8)


def test_a_deflation_must_match_the_control():
    from roughfe.bem.pk import polonsky_keer
    op = influence_operator((64, 64), (1e-4, 1e-4), 1e9, "love")
    h = np.random.default_rng(0).random((64, 64)) * 1e-6
    for zero_mean, kw in ((True, dict(delta=5e-7)), (False, dict(mean_pressure=1e6))):
        with pytest.raises(InputError, match="must match the control"):
            polonsky_keer(op.apply, h, 1e-6, deflation=PaddedBlockDeflation(
                op, zero_mean=zero_mean), **kw)
