"""The switch of the two-level correction, ``solve_contact(coarse_correction=)`` (round 2,
sessions 12-13): None chooses it where it was measured to pay (``DEFLATION_SIDES``, and a
start whose contact set has many parts), False gives the plain solve, True puts it on
wherever it applies; the answer is the same solution of Eq. 2.5-2.6 either way, and a
request it cannot honour is a clear error."""
import numpy as np
import pytest

from roughfe.bem import Material, contact, contact_sweep, solve_contact
from roughfe.bem.coarse_start import CORRECTION_MIN_PARTS, _contact_parts
from roughfe.errors import InputError
from roughfe.surfaces.shapes import sphere_cap
from roughfe.surfaces.spectral import spectral_surface
from roughfe.surfaces.surface import Surface

KW = dict(solver="pk", tol=1e-10, compute_stiffness=False)


def test_off_is_the_plain_solve_and_on_is_the_same_solution(monkeypatch, deflations_made):
    # 1024^2 (the correction on by default): False is bit for bit the solve with the
    # correction's range emptied; the default reaches the same contact set with fewer
    # iterations (a rough surface: 23 against 49 at p/E* = 0.05)
    s = spectral_surface(1024, 1.0, 0.8, rms_slope=1.0, rng=1)
    m = Material(1.0, 0.0)
    made = deflations_made
    auto = solve_contact(s, m, mean_pressure=0.05, **KW)
    assert made and made[-1] == (1024, 1024)
    made.clear()
    off = solve_contact(s, m, mean_pressure=0.05, coarse_correction=False, **KW)
    assert not made                   # no level of the coarse start used it either
    monkeypatch.setattr(contact, "DEFLATION_SIDES", (10 ** 9, 10 ** 9))
    plain = solve_contact(s, m, mean_pressure=0.05, **KW)
    assert np.array_equal(off.pressure, plain.pressure) and off.nit == plain.nit
    assert auto.nit < off.nit
    assert np.array_equal(auto.contact, off.contact)
    assert np.abs(auto.pressure - off.pressure).max() <= 2e-8 * off.pressure.max()


def test_on_below_the_automatic_range(monkeypatch, deflations_made):
    # a sphere on 256^2 (automatic: plain), forced on: the same solution, Hertz-like
    s = sphere_cap(256, 1.0, 1.0)
    s = Surface(s.heights, s.size, periodic=True)
    m = Material(1.0, 0.0)
    made = deflations_made
    plain = solve_contact(s, m, mean_pressure=1e-3, **KW)
    assert not made
    on = solve_contact(s, m, mean_pressure=1e-3, coarse_correction=True, **KW)
    assert made == [(256, 256)]       # the fine grid only: the coarse levels choose
    assert np.array_equal(on.contact, plain.contact)
    assert np.abs(on.pressure - plain.pressure).max() <= 1e-6 * plain.pressure.max()
    sweep = contact_sweep(s, m, pressures=[1e-3], coarse_correction=False,
                          compute_stiffness=False)
    assert np.array_equal(sweep.results[0].contact, plain.contact)


def test_on_for_an_imposed_approach_through_load_control(deflations_made):
    # a rough 256^2 periodic surface at an imposed approach (solved through load control,
    # where the automatic choice leaves the correction off at this size): forced on, the
    # fine solve takes it and reaches the same contact set and load as the plain solve
    s = spectral_surface(256, 1.0, 0.8, rms_slope=1.0, rng=3)
    m = Material(1.0, 0.0)
    delta = 0.3 * float(np.ptp(s.heights))
    made = deflations_made
    plain = solve_contact(s, m, delta=delta, **KW)
    assert not made
    on = solve_contact(s, m, delta=delta, coarse_correction=True, **KW)
    assert made == [(256, 256)]
    assert np.array_equal(on.contact, plain.contact)
    assert on.mean_pressure == pytest.approx(plain.mean_pressure, rel=1e-8)
    assert on.delta == pytest.approx(delta, rel=1e-9)


def test_on_for_an_approach_without_a_load_start_warns():
    # an approach near full contact (the coarse start touches more than half of the
    # grid): no start in load control, so the gap-variable CG solves it, without the
    # correction, and says so
    s = spectral_surface(256, 1.0, 0.8, rms_slope=1.0, rng=3)
    m = Material(1.0, 0.0)
    delta = 0.99 * float(s.heights.max() - s.heights.mean())
    with pytest.warns(RuntimeWarning, match="without the two-level correction"):
        on = solve_contact(s, m, delta=delta, coarse_correction=True, **KW)
    plain = solve_contact(s, m, delta=delta, **KW)
    assert np.array_equal(on.pressure, plain.pressure)


def test_contact_parts_counts_patches_and_islands():
    # k disjoint square patches on a 64^2 grid: k patches + the one non-contact region;
    # a hole punched in a patch adds an island; contact everywhere is one part, no
    # contact at all says nothing (None)
    p = np.zeros((64, 64))
    for k in range(5):
        p[4 + 12 * k: 10 + 12 * k, 8:20] = 1.0
    assert _contact_parts(p) == 5 + 1
    p[4:10, 8:20] = 1.0
    p[6:8, 12:16] = 0.0              # an island inside the first patch
    assert _contact_parts(p) == 5 + 2
    assert _contact_parts(np.zeros((64, 64))) is None
    assert _contact_parts(np.ones((64, 64))) == 1


def test_automatic_choice_reads_the_contact_structure(monkeypatch, deflations_made):
    # in the automatic range (1024^2) a sphere's start has 2 parts (one patch, one
    # non-contact region): the correction is left off and the solve is bit for bit the
    # plain one, in a single solve and in a warm-started sweep; a rough surface's start
    # has hundreds of parts at a light and at a heavy load (A* = 0.97): it stays on
    m = Material(1.0, 0.0)
    sphere = sphere_cap(1024, 1.0, 1.0)
    sphere = Surface(sphere.heights, sphere.size, periodic=True)
    made = deflations_made
    auto = solve_contact(sphere, m, mean_pressure=1e-2, **KW)
    assert not made
    off = solve_contact(sphere, m, mean_pressure=1e-2, coarse_correction=False, **KW)
    assert np.array_equal(auto.pressure, off.pressure) and auto.nit == off.nit
    contact_sweep(sphere, m, pressures=[1e-3, 1e-2], compute_stiffness=False)
    assert not made
    rough = spectral_surface(1024, 1.0, 0.8, rms_slope=1.0, rng=1)
    for load in (0.005, 1.0):
        from roughfe.bem.coarse_start import _coarse_start
        assert _contact_parts(_coarse_start(rough, m, load, None)) >= 10 * CORRECTION_MIN_PARTS
    solve_contact(rough, m, mean_pressure=1.0, **KW)
    assert made and made[-1] == (1024, 1024)


@pytest.mark.parametrize("kw, why", [
    (dict(delta=1e-3), "load control"),   # an approach below 256^2: the gap variable
    (dict(mean_pressure=1e-3, hardness=0.5), "elastic interface"),
    (dict(mean_pressure=1e-3, solver="dense"), "solver 'pk'"),
])
def test_on_where_it_cannot_apply_says_why(kw, why):
    s = spectral_surface(32, 1.0, 0.8, rms_slope=1.0, rng=1)
    with pytest.raises(InputError, match=why):
        solve_contact(s, Material(1.0, 0.0), coarse_correction=True,
                      compute_stiffness=False, **kw)


def test_bad_values_and_grids():
    m = Material(1.0, 0.0)
    s = spectral_surface(32, 1.0, 0.8, rms_slope=1.0, rng=1)
    with pytest.raises(InputError, match="None .automatic., True or False"):
        solve_contact(s, m, mean_pressure=1e-3, coarse_correction="yes")
    odd = spectral_surface(36, 1.0, 0.8, rms_slope=1.0, rng=1)
    with pytest.raises(InputError, match="multiples of 8"):
        solve_contact(odd, m, mean_pressure=1e-3, coarse_correction=True)
    tiny = Surface(np.random.default_rng(1).random((10, 10)), 1.0, periodic=False)
    with pytest.raises(InputError, match="grid sides >= 12"):
        solve_contact(tiny, m, mean_pressure=1e-3, solver="pk", coarse_correction=True)
    profile = spectral_surface(1024, 1.0, 0.8, rms_slope=1.0, rng=1).heights[0]
    with pytest.raises(InputError, match="2D surface"):
        solve_contact(Surface(profile, 1.0, periodic=True), m, mean_pressure=1e-3,
                      coarse_correction=True)


def test_response_passes_the_switch_and_refuses_it_with_adhesion():
    from roughfe.bem.adhesion import AdhesionLaw
    from roughfe.model import Loading
    from roughfe.response import response
    s = spectral_surface(32, 1.0, 0.8, rms_slope=1.0, rng=1)
    m = Material(1.0, 0.0)
    with pytest.raises(InputError, match="load control"):
        response(s, m, Loading(deltas=[1e-3]), coarse_correction=True)
    with pytest.raises(InputError, match="coarse_correction does not apply with adhesion"):
        response(s, m, Loading(deltas=[1e-3]), coarse_correction=False,
                 adhesion=AdhesionLaw("exp", 0.01, 0.01))
