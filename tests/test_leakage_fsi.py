"""Two-way fluid-structure coupling (issue 12): exactness, fixed point, states, trapped fluid.

* No flow (p_in = p_out = p_f) on a periodic surface: the coupled contact is the dry
  contact at p_ext - p_f point by point (a uniform traction does not change the gap of a
  periodic half-space).
* With flow: the returned state is a fixed point, checked independently of the loop (one
  more contact solve of the shifted heights and one more Reynolds solve reproduce it); the
  fluid opens the contact, so the coupled leak rate exceeds the one-way one.
* Reversed flow (p_in < p_out) is the mirror image; lift-off is a state; non-convergence
  raises with the residual.
"""
import numpy as np
import pytest

from roughfe.bem import solve_contact
from roughfe.bem.contact import surface_displacement
from roughfe.errors import InputError, NoConvergenceError
from roughfe.leakage.finite_volume import solve_reynolds_fv
from roughfe.leakage.fsi import coupled_leakage, coupled_sweep
from roughfe.model import Material
from roughfe.surfaces import Surface
from roughfe.surfaces.spectral import spectral_surface

MAT = Material(1e9, 0.3)
P_EXT = 3e7


@pytest.fixture(scope="module")
def surface():
    return spectral_surface(32, 1e-4, 0.8, rms_height=1e-6, rng=4)


@pytest.fixture(scope="module")
def flowing(surface):
    return coupled_leakage(surface, MAT, P_EXT, p_in=2e7, p_out=0.0)


def test_uniform_fluid_pressure_is_the_dry_contact_at_reduced_load(surface):
    pf = 1e7
    r = coupled_leakage(surface, MAT, P_EXT, p_in=pf, p_out=pf)
    dry = solve_contact(surface, MAT, mean_pressure=P_EXT - pf, tol=1e-11,
                        compute_stiffness=False)
    assert r.state == "contact" and r.residual <= 1e-8
    assert np.array_equal(r.contact.contact, dry.contact)
    assert np.allclose(r.contact.gap, dry.gap, rtol=0, atol=1e-8 * dry.gap.max())
    # effective (solid) contact pressure on top of p_f = the dry contact pressure
    assert np.allclose(r.contact.pressure, dry.pressure, rtol=0, atol=1e-6 * dry.pressure.max())
    assert np.allclose(r.fluid_pressure, pf)
    assert r.fluid_load_fraction == pytest.approx(pf / P_EXT, rel=1e-9)   # CG rtol 1e-10
    assert abs(r.leak_rate) < 1e-20 and r.coupled_iterations <= 2   # p_in = p_out: round-off


def test_coupled_state_is_a_fixed_point_and_leaks_more(surface, flowing):
    r = flowing
    assert r.state == "contact" and r.residual <= 1e-8
    # independent check: contact of the shifted heights under p_ext - mean(p_f) ...
    pf = r.fluid_pressure
    shifted = Surface(surface.heights - surface_displacement(surface, MAT, pf),
                      surface.size, surface.periodic)
    c = solve_contact(shifted, MAT, mean_pressure=P_EXT - pf.mean(), tol=1e-11,
                      compute_stiffness=False)
    assert np.array_equal(c.contact, r.contact.contact)
    assert np.allclose(c.gap, r.contact.gap, rtol=0, atol=1e-6 * c.gap.max())
    # ... and Reynolds on that gap (film regularised in contact cells) give the same fluid
    # pressure outside the trapped pockets; the leak rate is the unregularised FV solve
    gap = np.where(c.contact, 0, c.gap)
    film = solve_reynolds_fv(np.maximum(gap, 1e-3 * surface.heights.std()), surface.spacing,
                             p_in=2e7, p_out=0.0, periodic=True)
    sol = solve_reynolds_fv(gap, surface.spacing, p_in=2e7, p_out=0.0, periodic=True)
    pocket = (gap > 0) & ~sol.connected
    assert np.allclose(film.pressure[~pocket], pf[~pocket], rtol=0, atol=1e-6 * 2e7)
    assert sol.leak_rate == pytest.approx(r.leak_rate, rel=1e-6)
    # maximum principle and load shares
    assert pf.min() >= -1e-6 * 2e7 and pf.max() <= 2e7 * (1 + 1e-9)
    assert 0 < r.fluid_load_fraction < 2e7 / P_EXT
    assert r.contact.mean_pressure == pytest.approx(P_EXT * (1 - r.fluid_load_fraction),
                                                    rel=1e-8)
    # the fluid pushes the body open: more leakage than the one-way (dry) estimate, which
    # here does not even percolate
    assert r.leak_rate > 0 and r.one_way_leak_rate == 0.0
    rec = r.record()
    assert rec["coupled_iterations"] == r.coupled_iterations and rec["fsi_state"] == "contact"


def test_reversed_flow_is_the_mirror_image(surface, flowing):
    # p_in < p_out: the flow runs from the outlet side to the inlet side (negative Q); it
    # is the forward flow through the mirrored surface (not minus the forward flow: the
    # high pressure now loads the other end of the contact)
    rev = coupled_leakage(surface, MAT, P_EXT, p_in=0.0, p_out=2e7)
    mirrored = Surface(surface.heights[::-1], surface.size, True)
    mir = coupled_leakage(mirrored, MAT, P_EXT, p_in=2e7, p_out=0.0)
    assert rev.leak_rate < 0 and mir.leak_rate == pytest.approx(-rev.leak_rate, rel=1e-5)
    assert np.allclose(rev.fluid_pressure[::-1], mir.fluid_pressure, rtol=0, atol=1e-5 * 2e7)


def test_lift_off_is_a_state_and_non_convergence_raises(surface):
    r = coupled_leakage(surface, MAT, P_EXT, p_in=4e7, p_out=3.5e7)
    assert r.state == "lift-off" and r.leak_rate is None and r.contact is None
    assert r.fluid_load_fraction == 1.0
    with pytest.raises(NoConvergenceError, match="residual"):
        coupled_leakage(surface, MAT, P_EXT, p_in=2e7, p_out=0.0, max_iter=2)


def test_bad_input_is_named(surface):
    with pytest.raises(InputError, match="external pressure"):
        coupled_leakage(surface, MAT, -1.0, p_in=1.0, p_out=0.0)
    with pytest.raises(InputError, match="inlet pressure"):
        coupled_leakage(surface, MAT, P_EXT, p_in=float("nan"), p_out=0.0)
    film = coupled_sweep(surface, MAT, [1e7, 2e7, 3e7, 6e7], p_in=5e6, p_out=0.0)
    assert all(r.residual <= 1e-8 for r in film)
    with pytest.raises(InputError, match="trapped"):
        coupled_leakage(surface, MAT, P_EXT, p_in=1.0, p_out=0.0, trapped="volume")




def test_sweep_trapped_pockets_keep_their_pressure_at_closure(surface):
    rs = coupled_sweep(surface, MAT, [1e7, 2e7, 3e7], p_in=5e6, p_out=0.0, trapped="pressure")
    assert [r.state for r in rs] == ["contact"] * 3
    for r in rs:
        assert r.residual <= 1e-8
        lo, hi = 0.0, 5e6
        assert all(lo - 1e-6 * hi <= p <= hi * (1 + 1e-9) for p in r.pocket_pressures)
        assert 0 <= r.trapped_load_fraction <= r.fluid_load_fraction
    # more load: less leakage; pockets appear and hold fluid
    q = [r.leak_rate for r in rs]
    assert q[0] > q[1] > q[2] >= 0
    assert rs[-1].trapped_volume > 0 and rs[-1].pocket_pressures
    # the trapped fluid carries load: its pressure times its area
    r = rs[-1]
    lab_p = np.array(r.pocket_pressures)
    assert r.trapped_load_fraction > 0 and lab_p.max() > 0
