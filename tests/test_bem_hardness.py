"""Hardness-limited (perfectly plastic interface) BEM contact, 0 <= p <= H_p: the elastic
limit, the fully plastic limit, Westergaard and Hertz below the onset of flow, agreement
of the matrix-free and the bounded least-squares solvers, a load-unload cycle."""
import warnings

import numpy as np
import pytest

from roughfe.bem import Material, solve_contact
from roughfe.reference import hertz_sphere, westergaard
from roughfe.surfaces import Surface
from roughfe.surfaces.spectral import spectral_surface

MAT = Material(1.0e9, 0.3)
UNIT = Material(1.0, 0.0)


def rough(n=64, seed=1):
    """Periodic self-affine surface, unit rms slope, L = 1 m; with E* = 1 Pa the mean
    pressure is p / (E* gbar)."""
    return spectral_surface(n, 1.0, 0.8, rms_slope=1.0, rng=seed)


def test_infinite_hardness_is_the_elastic_solution():
    surf = rough(128)
    a = solve_contact(surf, UNIT, mean_pressure=0.05, solver="pk")
    # a cap far above every pressure never binds: the same iterates up to round-off
    b = solve_contact(surf, UNIT, mean_pressure=0.05, solver="pk",
                      hardness=1e6 * a.pressure.max())
    assert a.plastic_area_fraction is None and b.plastic_area_fraction == 0.0
    assert np.array_equal(a.contact, b.contact)
    assert np.max(np.abs(a.pressure - b.pressure)) <= 1e-12 * a.pressure.max()
    assert b.mean_gap == pytest.approx(a.mean_gap, rel=1e-12, abs=0)
    assert b.stiffness == pytest.approx(a.stiffness, rel=1e-9)
    assert not b.plastic_displacement.any()


def test_fully_plastic_limit_area_is_load_over_hardness():
    # H_p far below the elastic pressures E* gbar: the contact points flow and
    # A* -> p / H_p (rigid-plastic junctions), approached as H_p / (E* gbar) -> 0
    surf, pm = rough(64), 0.01
    excess = []
    for hp in (0.1, 0.05, 0.02):
        r = solve_contact(surf, UNIT, mean_pressure=pm, hardness=hp)
        assert r.pressure.max() == hp and r.mean_pressure == pytest.approx(pm, rel=1e-12, abs=0)
        assert r.residual <= 1e-10
        excess.append(r.area_fraction * hp / pm - 1)
        plastic = r.pressure >= hp
        assert r.plastic_area_fraction == pytest.approx(plastic.mean(), abs=0)
        # the plastic displacement is the interpenetration at the flowing points only
        assert np.all(r.plastic_displacement[~plastic] == 0)
        assert np.all(r.plastic_displacement[plastic] >= 0)
    # measured 6.0 %, 1.4 %, 0.34 %: the elastic rims shrink with H_p
    assert excess[0] > excess[1] > excess[2] > 0 and excess[2] < 5e-3
    assert r.plastic_area_fraction > 0.99 * r.area_fraction


def test_westergaard_sinusoid_below_and_beyond_the_onset_of_flow():
    n, lam, g = 1024, 1e-3, 1e-6
    x = np.arange(n) * lam / n
    surf = Surface(g * np.cos(2 * np.pi * x / lam), lam, periodic=True)
    pm = 0.2 * np.pi * MAT.E_star * g / lam            # 0.2 p*: partial contact
    ref = westergaard(g, lam, MAT.E_star, pm)
    peak = float(ref.pressure(0.0))                      # 2 p / sin(pi a / lambda)
    # just above the analytic peak nothing flows: the elastic (Westergaard) state. Both
    # to tol 1e-12: at the default 1e-10 two converged pressures may differ by ~1e-7 peak
    # (a gap error of 1e-10 h_pv at the Nyquist wavenumber), depending on where each
    # iteration happens to cross the tolerance
    el = solve_contact(surf, MAT, mean_pressure=pm, tol=1e-12)
    a = solve_contact(surf, MAT, mean_pressure=pm, hardness=1.02 * peak, tol=1e-12)
    assert a.plastic_area_fraction == 0.0
    assert np.max(np.abs(a.pressure - el.pressure)) <= 1e-9 * peak
    assert a.area_fraction == pytest.approx(ref.area_fraction, abs=2.0 / n)
    # below it the crest flows: a plateau at H_p, a wider contact carrying the same load
    b = solve_contact(surf, MAT, mean_pressure=pm, hardness=0.7 * peak)
    assert b.pressure.max() == 0.7 * peak and b.plastic_area_fraction > 0
    assert b.area_fraction > a.area_fraction
    assert np.all(np.diff(b.pressure[: n // 4]) <= 1e-9 * peak)   # still decreasing
    # fully plastic limit: H_p << p*: A* -> p / H_p
    c = solve_contact(surf, MAT, mean_pressure=pm, hardness=1.25 * pm)
    assert c.area_fraction == pytest.approx(pm / (1.25 * pm), abs=0.01)


def test_hertz_sphere_below_and_beyond_the_onset_of_flow():
    n, L, R = 96, 1e-3, 1e-2
    x = (np.arange(n) - n // 2) * L / n
    X, Y = np.meshgrid(x, x, indexing="ij")
    surf = Surface(-(X ** 2 + Y ** 2) / (2 * R), L, periodic=False)
    pm = 1e5
    ref = hertz_sphere(R, MAT.E_star, load=pm * L * L)
    # both to tol 1e-12, as for the sinusoid above
    el = solve_contact(surf, MAT, mean_pressure=pm, solver="pk", tol=1e-12)
    assert el.pressure.max() == pytest.approx(ref.peak_pressure, rel=2e-2)
    a = solve_contact(surf, MAT, mean_pressure=pm, solver="pk", tol=1e-12,
                      hardness=1.01 * el.pressure.max())
    assert a.plastic_area_fraction == 0.0 and np.array_equal(a.contact, el.contact)
    assert np.max(np.abs(a.pressure - el.pressure)) <= 1e-8 * ref.peak_pressure
    # H_p = p0 / 2: a central plastic disc, the contact widens, the load is kept
    b = solve_contact(surf, MAT, mean_pressure=pm, solver="pk", hardness=0.5 * ref.peak_pressure)
    assert b.plastic_area_fraction > 0 and b.contact_area > a.contact_area
    assert b.load == pytest.approx(ref.load, rel=1e-10)
    centre = b.plastic_displacement[n // 2, n // 2]
    assert centre == b.plastic_displacement.max() > 0       # deepest at the apex
    # rigid-plastic limit H_p << p0: contact area -> P / H_p
    c = solve_contact(surf, MAT, mean_pressure=pm, solver="pk", hardness=0.05 * ref.peak_pressure)
    assert c.contact_area == pytest.approx(ref.load / (0.05 * ref.peak_pressure), rel=0.03)


@pytest.mark.parametrize("control", ["delta", "mean_pressure"])
def test_bounded_least_squares_and_matrix_free_agree(control):
    rng = np.random.default_rng(5)
    h = np.cumsum(rng.standard_normal(200)) * 1e-8
    surf = Surface(h - h.mean(), 1e-4, periodic=False)
    el = solve_contact(surf, MAT, delta=0.5 * np.ptp(h), solver="pk")
    hp = 0.3 * el.pressure.max()
    kw = {"delta": 0.5 * np.ptp(h)} if control == "delta" else {"mean_pressure":
                                                                el.mean_pressure / 3}
    a = solve_contact(surf, MAT, solver="nnls", hardness=hp, tol=1e-12, **kw)
    b = solve_contact(surf, MAT, solver="pk", hardness=hp, tol=1e-12, **kw)
    assert a.solver == "nnls" and b.solver == "pk"
    assert 0 < a.plastic_area_fraction < a.area_fraction
    assert np.array_equal(a.pressure >= hp, b.pressure >= hp)
    assert np.max(np.abs(a.pressure - b.pressure)) <= 1e-7 * hp
    assert np.max(np.abs(a.plastic_displacement - b.plastic_displacement)) <= \
        1e-6 * a.plastic_displacement.max()
    assert b.stiffness == pytest.approx(a.stiffness, rel=1e-6)


def test_load_unload_cycle_keeps_the_plastic_displacement():
    surf, hp = rough(64), 0.1
    top = solve_contact(surf, UNIT, mean_pressure=0.03, hardness=hp)
    up = top.plastic_displacement
    assert top.plastic_area_fraction > 0
    # unloading: nothing flows any more, the permanent displacement stays as it was
    low = solve_contact(surf, UNIT, mean_pressure=0.01, hardness=hp, plastic_displacement=up)
    assert low.plastic_area_fraction == 0.0
    assert np.array_equal(low.plastic_displacement, up)
    # hysteresis: the flattened asperities carry the lower load on a larger area and a
    # smaller mean gap than on the loading branch
    virgin = solve_contact(surf, UNIT, mean_pressure=0.01, hardness=hp)
    assert low.area_fraction > virgin.area_fraction and low.mean_gap < virgin.mean_gap
    # reloading to the same peak load is elastic (shakedown): the same pressure as at the
    # end of the first loading, and no further plastic displacement
    again = solve_contact(surf, UNIT, mean_pressure=0.03, hardness=hp, plastic_displacement=up)
    assert np.max(np.abs(again.pressure - top.pressure)) <= 1e-6 * hp
    assert np.max(np.abs(again.plastic_displacement - up)) <= 1e-8 * up.max()
    # the same state reads the same: the points that reach the hardness through the
    # elastic equations (p just below H_p, not clipped to it) are at yield, so the plastic
    # area and the stiffness of the reload are those of the first loading (an exact
    # p >= H_p test read 0.17 against 0.40, and 2.3x the stiffness, on a 32^2 surface)
    assert again.plastic_area_fraction == top.plastic_area_fraction
    assert again.stiffness == pytest.approx(top.stiffness, rel=1e-6)


@pytest.mark.parametrize("hardness", [0.0, -1.0, np.inf, np.nan, "soft", True])
def test_bad_hardness_is_an_input_error(hardness):
    with pytest.raises(ValueError, match="hardness"):
        solve_contact(rough(16), UNIT, mean_pressure=0.01, hardness=hardness)


def test_hardness_inconsistent_requests_are_input_errors():
    surf = rough(16)
    with pytest.raises(ValueError, match="below the hardness"):
        solve_contact(surf, UNIT, mean_pressure=0.2, hardness=0.1)
    with pytest.raises(ValueError, match="'dense'"):
        solve_contact(surf, UNIT, mean_pressure=0.01, hardness=0.1, solver="dense")
    with pytest.raises(ValueError, match="needs a hardness"):
        solve_contact(surf, UNIT, mean_pressure=0.01, plastic_displacement=np.zeros((16, 16)))
    with pytest.raises(ValueError, match="shape"):
        solve_contact(surf, UNIT, mean_pressure=0.01, hardness=0.1,
                      plastic_displacement=np.zeros(3))


def test_sweep_with_hardness_carries_the_plastic_displacement_and_unloads():
    from roughfe.bem import contact_sweep
    surf = rough(32)
    sw = contact_sweep(surf, UNIT, pressures=[0.01, 0.02, 0.03], hardness=0.1, unload=True)
    assert list(sw.mean_pressure) == pytest.approx([0.01, 0.02, 0.03, 0.02, 0.01], rel=1e-12,
                                                   abs=0)
    assert list(sw.unloading) == [0, 0, 0, 1, 1]
    recs = sw.to_records()
    assert recs[3]["unloading"] is True and recs[0]["plastic_area_fraction"] >= 0
    ups = [r.plastic_displacement for r in sw.results]
    # permanent: never decreases along the path, unchanged on unloading
    for a, b in zip(ups, ups[1:]):
        assert np.all(b >= a - 1e-15 * ups[2].max())
    assert np.array_equal(ups[-1], ups[2]) and sw.plastic_area_fraction[-1] == 0.0
    # hysteresis: more contact on the way down than on the way up at the same load
    assert sw.area_fraction[3] > sw.area_fraction[1]
    assert sw.area_fraction[4] > sw.area_fraction[0]


def test_periodic_displacement_control_with_a_hardness():
    # the box 0 <= p <= H_p makes the periodic displacement-controlled problem well posed
    # (bounded PK on the pressure): its state at Delta is the load-controlled state at the
    # mean pressure it returns (an independent path: load control imposes the mean)
    surf = rough(64)
    h = surf.heights
    top = float(h.max() - h.mean())
    for frac, hp in ((0.3, 0.1), (0.6, 0.3), (0.8, 10.0)):     # the last one elastic
        d = frac * top
        r = solve_contact(surf, UNIT, delta=d, hardness=hp)
        assert r.delta == pytest.approx(d, rel=1e-12, abs=0) and r.residual <= 1e-10
        ref = solve_contact(surf, UNIT, mean_pressure=r.mean_pressure, hardness=hp)
        assert ref.delta == pytest.approx(d, rel=1e-7)
        assert np.max(np.abs(r.pressure - ref.pressure)) <= 1e-6 * hp
        assert r.plastic_area_fraction == ref.plastic_area_fraction
        np.testing.assert_allclose(r.plastic_displacement, ref.plastic_displacement,
                                   atol=1e-6 * top)
    assert r.plastic_area_fraction == 0.0
    # beyond max h - mean h (elastic full contact) the peaks flow: the mean gap minus the
    # mean plastic displacement is max h - mean h - Delta < 0 (mean u = 0: volume balance)
    for d in (1.2 * top, 1.5 * top):
        r = solve_contact(surf, UNIT, delta=d, hardness=0.1)
        assert 0 < r.mean_pressure < 0.1 and r.plastic_area_fraction > 0.5
        assert r.mean_gap - r.plastic_displacement.mean() == pytest.approx(top - d, rel=1e-8)
    # Delta >= max h - min h: every point flows, p = H_p
    r = solve_contact(surf, UNIT, delta=1.01 * float(np.ptp(h)), hardness=0.1)
    assert r.area_fraction == 1.0 and np.all(r.pressure == 0.1)


def test_periodic_displacement_sweep_with_hardness_unloads():
    from roughfe.bem import contact_sweep
    surf = rough(32)
    top = float(surf.heights.max() - surf.heights.mean())
    sw = contact_sweep(surf, UNIT, deltas=[0.3 * top, 0.6 * top], hardness=0.1, unload=True)
    assert list(sw.unloading) == [0, 0, 1]
    # back at 0.3 top the flattened peaks carry less load, and the volume they lost opens
    # the gap: mean gap = max h - mean h - Delta + mean plastic displacement (mean u = 0;
    # nothing flows on unloading)
    back = sw.results[2]
    assert sw.mean_pressure[2] < sw.mean_pressure[0] and back.plastic_area_fraction == 0
    assert back.mean_gap == pytest.approx(top - 0.3 * top + back.plastic_displacement.mean(),
                                          rel=1e-8)


def test_a_loose_tolerance_does_not_make_every_point_yield():
    # The yield band grows with the tolerance (an elastic reload to the previous peak
    # comes out just below H_p), but at tol 1e-3 on a periodic surface under an imposed
    # approach (tolerance 10 tol) it reached all of 0..H_p: every point, in contact or
    # not, counted as yielded and K was 0 (found by a reviewer, round 2, session 22).
    # Capped at 1 % of H_p and counted on the contact set, it is the tight answer within
    # a cell or two
    s = spectral_surface(64, 1e-4, 0.8, rms_height=1e-6, rng=3)
    mat, hp = Material(1e9, 0.3), 2e8
    d = 0.4 * (s.heights.max() - s.heights.mean())
    tight = solve_contact(s, mat, delta=d, hardness=hp, tol=1e-10)
    assert 0 < tight.plastic_area_fraction < tight.area_fraction
    for tol in (1e-4, 1e-3):
        loose = solve_contact(s, mat, delta=d, hardness=hp, tol=tol)
        assert loose.plastic_area_fraction <= loose.area_fraction
        assert abs(loose.plastic_area_fraction - tight.plastic_area_fraction) * s.heights.size <= 2
        assert loose.stiffness == pytest.approx(tight.stiffness, rel=0.01)


def test_a_separated_unloading_step_has_zero_stiffness_with_every_solver():
    # Unloading after plastic flow ends with the recessed surface off the flat: no point
    # touches, so no point responds and K = 0. The dense path (nnls, until session 33 the
    # automatic choice of a non-periodic profile with a hardness) solved H_cc x = 1 on an
    # empty set and crashed in LAPACK (0 x 0 matrix; found by a reviewer, session 25); pk
    # returned 0
    prof = Surface(1e-6 * np.cos(2 * np.pi * np.linspace(0, 1, 64, endpoint=False)),
                   1e-4, periodic=False)
    top = solve_contact(prof, MAT, delta=1e-6, hardness=1e7, solver="nnls")
    assert top.solver == "nnls" and top.plastic_area_fraction > 0
    # the peak was flattened by more than the approach is backed off: separated
    assert top.plastic_displacement.max() > 0.5e-6
    for solver in ("auto", "nnls", "pk"):
        r = solve_contact(prof, MAT, delta=0.5e-6, hardness=1e7, solver=solver,
                          plastic_displacement=top.plastic_displacement)
        assert r.n_contact == 0 and r.mean_pressure == 0.0 and r.gap.min() > 0
        assert r.stiffness == 0.0
        assert np.array_equal(r.plastic_displacement, top.plastic_displacement)


@pytest.mark.parametrize("seed, load, hp", [(5, 2e6, 2e7), (6, 1e6, 5e6), (2, 1e6, 5e6)])
def test_bounded_load_control_keeps_u_equal_to_h_p(seed, load, hp):
    # In load control the rescale to the load scales the free set only, while the
    # saturated points stay at H_p; the displacement recursion scaled all of u, so u
    # drifted from H p by (alpha - 1) H p_fixed until its recompute every 50 iterations:
    # 2-cycles of the residual, a direction growing to float32 overflow ('invalid value
    # encountered in multiply') and 122 / 161 / 55 iterations on these profiles, where
    # the others of their kind take 10-30 (reviewer, session 25). As warnings are errors
    from roughfe.surfaces.spectral import spectral_profile
    prof = spectral_profile(128, 1e-4, 0.8, rms_height=1e-6, rng=seed)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = solve_contact(prof, MAT, mean_pressure=load, hardness=hp)
    assert r.solver == "pk" and r.plastic_area_fraction > 0
    assert r.nit <= 40
    assert r.mean_pressure == pytest.approx(load, rel=1e-12) and r.pressure.max() <= hp
    assert r.residual <= 1e-10


@pytest.mark.parametrize("seed", [1, 2])
def test_imposed_approach_between_full_contact_and_full_flow(seed):
    # H_p = 5 E* gbar: the peaks yield only near the elastic full contact. Between
    # Delta = max h - mean h and max h - min h every point touches and the mean pressure
    # is fixed by the few plastic points alone; the primal CG diverged there (NaN
    # pressures returned as converged) or crawled to 20000 iterations at the first
    # approaches of both seeds (round 2, session 31). Each state must be the
    # load-controlled one at the mean pressure it returns (an independent path), and the
    # load must rise with the approach.
    surf, hp = rough(64, seed), 5.0
    h = surf.heights
    top, ptp = float(h.max() - h.mean()), float(np.ptp(h))
    loads = []
    for t in (0.125, 0.25, 0.5, 0.875):
        d = top + t * (ptp - top)
        r = solve_contact(surf, UNIT, delta=d, hardness=hp)
        assert np.all(np.isfinite(r.pressure)) and r.success and r.residual <= 1e-9
        assert r.area_fraction == 1.0 and 0 < r.plastic_area_fraction < 1
        ref = solve_contact(surf, UNIT, mean_pressure=r.mean_pressure, hardness=hp)
        assert ref.delta == pytest.approx(d, rel=1e-8, abs=0)
        assert np.max(np.abs(r.pressure - ref.pressure)) <= 1e-7 * hp
        loads.append(r.mean_pressure)
    assert np.all(np.diff(loads) > 0) and loads[-1] < hp
    # at max h - mean h exactly every P in [p_full, H_p - max p'] holds the approach:
    # the least one, in full contact with no point at the cap
    r = solve_contact(surf, UNIT, delta=top, hardness=hp)
    assert r.area_fraction == 1.0 and r.plastic_area_fraction == 0.0
    assert r.pressure.min() == pytest.approx(0.0, abs=1e-12 * hp) and r.pressure.max() < hp


def test_a_diverged_iteration_is_never_a_converged_residual():
    # NaN pressures had a residual of 0 (the zero-total rule of the complementarity
    # term): a diverged solve was returned as converged
    from roughfe.bem.solvers import kkt_residual
    p, w = np.array([1.0, np.nan]), np.array([0.0, 1.0])
    assert kkt_residual(p, w, 1.0) == np.inf
    assert kkt_residual(p, w, 1.0, upper=2.0) == np.inf
    with np.errstate(invalid="ignore"):                 # 0 * inf: the NaN it is about
        assert kkt_residual(np.array([1.0, 0.0]), np.array([0.0, np.inf]), 1.0) == np.inf
    rows = kkt_residual(np.array([[1.0, 0.0], [1.0, np.nan]]), np.zeros((2, 2)), 1.0,
                        axis=1)
    assert rows[0] == 0.0 and rows[1] == np.inf


def test_auto_takes_the_matrix_free_solver_with_a_hardness():
    # BVLS (solver "nnls") was the automatic choice of non-periodic grids up to 512
    # points: a 10-load cycle of a 512-point profile took 16.6 s against pk's 0.07 s (a
    # 22^2 patch 11.3 s against 0.15 s), for the same states (pressures within 1e-8 H_p;
    # round 2, session 33)
    from roughfe.surfaces.spectral import spectral_profile
    prof = spectral_profile(512, 1e-4, 0.8, rms_height=1e-6, rng=5)
    prof = Surface(prof.heights, prof.size, periodic=False)
    for surf in (prof, Surface(rough(22).heights, 1.0, periodic=False)):
        mat = MAT if surf.ndim == 1 else UNIT
        el = solve_contact(surf, mat, mean_pressure=2e6 if surf.ndim == 1 else 0.02)
        hp = 0.5 * el.pressure.max()
        r = solve_contact(surf, mat, mean_pressure=el.mean_pressure, hardness=hp)
        assert r.solver == "pk" and r.plastic_area_fraction > 0
        ref = solve_contact(surf, mat, mean_pressure=el.mean_pressure, hardness=hp,
                            solver="nnls", tol=1e-12)
        assert np.max(np.abs(r.pressure - ref.pressure)) <= 1e-7 * hp
