"""Adhesive BEM (roughfe.bem.adhesion): interface laws, the non-adhesive limit, sphere
pull-off against Maugis-Dugdale (DMT and JKR sides), hysteresis, failure reporting."""
import warnings

import numpy as np
import pytest

from roughfe.bem import solve_contact
from roughfe.bem.adhesion import AdhesionLaw, adhesive_sweep, solve_adhesive
from roughfe.errors import InputError, NoConvergenceError, ResolutionWarning
from roughfe.model import Material
from roughfe.reference import maugis_parameter, maugis_pull_off
from roughfe.surfaces.shapes import sphere_cap
from roughfe.surfaces.spectral import spectral_surface
from roughfe.surfaces.surface import Surface

# a sphere of radius R = 1 m on E* = 1 Pa with w = 2.83e-4 J/m^2: JKR pull-off contact
# radius (9 pi w R^2 / 8 E*)^(1/3) = 0.1 m; lengths scale out of every ratio tested
R, E_STAR, W = 1.0, 1.0, 2.83e-4
MAT = Material(E_STAR * 0.91, 0.3)
K = 4.0 / 3.0 * E_STAR
D_SCALE = (np.pi ** 2 * W ** 2 * R / K ** 2) ** (1 / 3)       # Maugis' approach unit (m)


def sphere(n, length):
    return sphere_cap(n, length, R)


def md_law(lam):
    """Maugis-Dugdale law with Maugis' parameter lambda for this sphere."""
    sigma0 = lam / (2 * (R / (np.pi * W * K ** 2)) ** (1 / 3))
    return AdhesionLaw("md", W, W / sigma0)


@pytest.fixture(scope="module")
def jkr_side():
    # lambda = 2 (Maugis: -1.535 pi w R, 2.3 % from the JKR limit). dx = 3.3e-3 m puts 4
    # cells in the Dugdale zone c - a = 1.3e-2 m at pull-off; the domain (0.21 m) holds the
    # contact (a <= 0.1 m) of every step. Loading starts out of range (the apex gap
    # 0.6 D_SCALE = 4.6e-3 m exceeds h0 = 2.4e-3 m) and jumps into contact by -0.4.
    law = md_law(2.0)
    return adhesive_sweep(sphere(64, 0.21), MAT, law, np.linspace(-0.6, 0.2, 5) * D_SCALE,
                          unload=True, max_unload_steps=8)


@pytest.mark.parametrize("kind", ["md", "exp"])
def test_laws_store_the_work_of_adhesion(kind):
    law = AdhesionLaw(kind, 0.05, 1e-9)
    g = np.linspace(0, 30e-9, 300001)
    t = law.traction(g)
    # phi(0) = -w, phi(inf) = 0, phi' = traction, int traction dg = w (the md ramp is
    # symmetric about h0, so w = sigma0 h0 holds exactly)
    assert law.potential(0.0) == pytest.approx(-0.05, rel=1e-12, abs=0)
    assert law.potential(30e-9) == pytest.approx(0.0, abs=1e-12 * 0.05)
    assert np.sum(0.5 * (t[1:] + t[:-1]) * np.diff(g)) == pytest.approx(0.05, rel=1e-6)
    dphi = np.gradient(law.potential(g), g)
    inner = slice(10, -10)
    np.testing.assert_allclose(dphi[inner], t[inner], atol=1e-3 * law.max_traction)
    assert law.max_traction == pytest.approx(0.05 / 1e-9)


def test_weak_adhesion_recovers_the_elastic_bem_periodic_and_not():
    # w -> 0: the adhesive equilibrium is the non-adhesive one (independent solver: PK).
    # Tolerance 2e-3: the traction residual 1e-5 sigma0 on a tiny sigma0, plus the
    # remaining adhesive traction w/rho ~ 1e-6 of the mean pressure.
    s = spectral_surface(32, 1e-4, 0.8, rms_height=1e-7, rng=4)
    mat = Material(1e9, 0.3)
    delta = 0.5 * float(s.heights.max() - s.heights.mean())
    law = AdhesionLaw("exp", 1e-12, 1e-9)
    adh = solve_adhesive(s, mat, law, delta=delta)
    ref = solve_contact(s, mat, delta=delta)
    assert adh.mean_pressure == pytest.approx(ref.mean_pressure, rel=2e-3)
    assert adh.delta == pytest.approx(delta, rel=1e-3)       # the machine spring holds Delta
    assert adh.n_contact == pytest.approx(ref.n_contact, rel=0.05)
    # non-periodic profile (strip kernel on the padded grid): a parabolic bump
    x = (np.arange(128) - 64) * 1e-6
    bump = Surface(-x ** 2 / 2e-3, 128e-6, periodic=False)
    d = 2e-8
    adh = solve_adhesive(bump, mat, law, delta=d)
    ref = solve_contact(bump, mat, delta=d)
    assert adh.kernel == "strip" and adh.mean_pressure == pytest.approx(ref.mean_pressure,
                                                                         rel=2e-3)


def test_dmt_limit_sphere_pull_off():
    # lambda = 0.1: Maugis -1.9506 pi w R, DMT -2. The attraction reaches r ~ sqrt(2 R h0)
    # = 0.31 m: the domain (0.8 m) holds it; the contact is a few cells, and in this
    # limit the pull-off is the integral of the Dugdale traction over the rigid sphere,
    # which the cells sample accurately. Measured -1.9485 (n = 48, cell-averaged law).
    law = md_law(0.1)
    assert maugis_parameter(R, MAT.E_star, W, law.max_traction) == pytest.approx(0.1)
    sw = adhesive_sweep(sphere(48, 0.8), MAT, law, np.array([-0.1, 0.2]) * D_SCALE,
                        unload=True, max_unload_steps=3)
    ratio = sw.pull_off_force / (np.pi * W * R)
    assert ratio == pytest.approx(maugis_pull_off(0.1), rel=1e-2)
    assert ratio == pytest.approx(-2.0, rel=3e-2)


@pytest.mark.slow
def test_jkr_side_sphere_pull_off(jkr_side):
    # lambda = 2: Maugis -1.535 pi w R. The continuation samples F(Delta) at steps of 0.2
    # Maugis units; the most tensile sample read -1.506 (-1.9 %, on the JKR side of the
    # minimum). Since round 2, session 30 the steps around it are bisected down to a
    # quarter of the law's range (refine_pull_off): measured -1.5374 (+0.15 %), the rest
    # the grid's (the cell-averaged law). Far from the DMT value 2, 2.3 % beyond the JKR
    # limit 1.5 as Maugis' curve (validation/adhesion_maugis.py).
    ratio = jkr_side.pull_off_force / (np.pi * W * R)
    assert jkr_side.detached
    assert ratio == pytest.approx(maugis_pull_off(2.0), rel=5e-3)
    assert ratio == pytest.approx(-1.5, rel=3e-2)


def test_loading_and_unloading_branches_differ(jkr_side):
    recs = jkr_side.records()
    assert [r["unloading"] for r in recs[:5]] == [False] * 5
    assert all(r["unloading"] for r in recs[5:])
    load = {round(r["delta"] / D_SCALE, 6): r for r in recs if not r["unloading"]}
    unload = {round(r["delta"] / D_SCALE, 6): r for r in recs if r["unloading"]}
    # hysteresis: at Delta = -0.6 the loading branch is out of range (no contact, no
    # force: the Dugdale attraction ends at h0), the unloading branch still adheres
    assert load[-0.6]["n_contact"] == 0 and abs(load[-0.6]["load"]) < 1e-12 * np.pi * W * R
    assert unload[-0.6]["n_contact"] > 0
    assert unload[-0.6]["load"] < -0.9 * np.pi * W * R
    # the sweep ends detached: no contact, load back near zero
    assert recs[-1]["n_contact"] == 0 and abs(recs[-1]["load"]) < 1e-2 * abs(
        jkr_side.pull_off_force)
    # the traction is tensile in the interaction zone of every contact state
    assert all(r.adhesive_area_fraction > 0 for r in jkr_side.sweep.results if r.n_contact)


def test_non_converged_adhesive_solve_raises_with_the_residual():
    # (2.5 zone cells on this grid, below the 3 a Maugis-Dugdale law needs: said once)
    with pytest.raises(NoConvergenceError, match="residual") as info, \
            pytest.warns(ResolutionWarning):
        solve_adhesive(sphere(32, 0.21), MAT, md_law(2.0), delta=0.1 * D_SCALE, max_iter=2)
    assert info.value.result.residual > 1e-5


@pytest.mark.parametrize("args, match", [
    (("md", 0.0, 1e-9), "work of adhesion"),
    (("exp", -1.0, 1e-9), "work of adhesion"),
    (("md", 0.05, float("nan")), "range"),
    (("md", 0.05, float("inf")), "range"),
    (("lj", 0.05, 1e-9), "adhesion law"),
])
def test_bad_adhesion_parameters(args, match):
    with pytest.raises(InputError, match=match):
        AdhesionLaw(*args)


@pytest.mark.parametrize("smoothing", ["x", None, float("nan"), -0.1, 1.0])
def test_bad_smoothing_is_an_input_error(smoothing):
    # "x" was a ValueError and None a TypeError from float()
    with pytest.raises(InputError, match="smoothing"):
        AdhesionLaw("md", 0.05, 1e-9, smoothing=smoothing)


def test_bad_initial_state_and_approaches_are_input_errors():
    # initial="abc" was an AttributeError, deltas=["a"] a ValueError from numpy
    s = spectral_surface(16, 1e-5, 0.8, rms_height=1e-8, rng=3)
    mat, law = Material(1e6, 0.5), AdhesionLaw("exp", 1e-3, 1e-7)
    with pytest.raises(InputError, match="initial must be a ContactResult"):
        solve_adhesive(s, mat, law, delta=1e-9, initial="abc")
    for deltas in (["a"], [[1e-9], [2e-9, 3e-9]]):
        with pytest.raises(InputError, match="deltas must be a non-empty sequence"):
            adhesive_sweep(s, mat, law, deltas)


def test_wrong_argument_types_are_input_errors_that_name_the_argument():
    # adhesive_sweep and response(..., adhesion=) gave an AttributeError ("'str' object
    # has no attribute 'process_zone'") for a law given by name, a missing material or a
    # heights array (found by a reviewer, session 26); they check the types first, with
    # solve_adhesive's check and in each function's own names
    from roughfe.model import Loading
    from roughfe.response import response
    s = spectral_surface(16, 1e-5, 0.8, rms_height=1e-8, rng=3)
    mat, law = Material(1e6, 0.5), AdhesionLaw("exp", 1e-3, 1e-7)
    for call, message in (
            (lambda: adhesive_sweep(s, mat, "md", [0.0, 1e-9]),
             "law must be an AdhesionLaw, got str"),
            (lambda: adhesive_sweep(s, None, law, [0.0, 1e-9]),
             "material must be a roughfe.model.Material, got NoneType"),
            (lambda: adhesive_sweep(s.heights, mat, law, [0.0, 1e-9]),
             "surface must be a roughfe Surface, got ndarray"),
            (lambda: adhesive_sweep(s.heights, mat, law, n_steps=2),
             "surface must be a roughfe Surface, got ndarray"),
            (lambda: response(s, mat, Loading(n_steps=2), adhesion="md"),
             "adhesion must be an AdhesionLaw, got str"),
            (lambda: response(s, mat, Loading(n_steps=2), adhesion={"kind": "md"}),
             "adhesion must be an AdhesionLaw, got dict")):
        with pytest.raises(InputError) as info:
            call()
        assert str(info.value) == message


def test_bad_approach():
    with pytest.raises(InputError, match="delta"):
        solve_adhesive(sphere(16, 0.2), MAT, md_law(1.0), delta=float("nan"))
    # the solver controls are named before any work (tol = 0 and max_iter = 0 ran into a
    # NoConvergenceError after the elastic start)
    for kwargs, match in (({"tol": 0.0}, "tol"), ({"tol": 1.5}, "tol"),
                          ({"max_iter": 0}, "max_iter"), ({"max_iter": 2.5}, "max_iter")):
        with pytest.raises(InputError, match=match):
            solve_adhesive(sphere(16, 0.2), MAT, md_law(1.0), delta=0.1 * D_SCALE, **kwargs)


def test_periodic_full_contact_approach_is_refused():
    # mean u = 0: Delta = max h - mean h closes every gap; the adhesive state is then not
    # set by the approach (the solver would return the machine spring's force)
    s = spectral_surface(16, 1e-4, 0.8, rms_height=1e-7, rng=1)
    top = float(s.heights.max() - s.heights.mean())
    with pytest.raises(InputError, match="full contact"):
        solve_adhesive(s, Material(1e9, 0.3), AdhesionLaw("exp", 0.01, 1e-6), delta=top)


@pytest.mark.parametrize("spring", [float("nan"), -1.0, 0.0, float("inf"), "1e9"])
def test_the_mean_gap_spring_must_be_finite_and_positive(spring):
    # nan returned a NaN residual with no NoConvergenceError, -1 a "converged" state at
    # another approach, 0 a ZeroDivisionError (until round 2 session 24)
    s = spectral_surface(16, 1e-4, 0.8, rms_height=1e-7, rng=1)
    with pytest.raises(InputError, match="spring .* must be"):
        solve_adhesive(s, Material(1e9, 0.3), AdhesionLaw("exp", 0.01, 1e-6), delta=0.0,
                       spring=spring)


def test_the_mean_gap_spring_is_refused_on_a_non_periodic_kernel():
    # the DC-FFT operator has no mean-gap spring: a spring given there was ignored
    with pytest.raises(InputError, match="periodic kernel 'spectral' only"):
        solve_adhesive(sphere(16, 0.2), MAT, md_law(1.0), delta=0.1 * D_SCALE, spring=1.0)


def test_a_residual_that_is_not_a_number_is_not_converged(monkeypatch):
    # the convergence tests read "not r <= tol": "r > tol" is False for NaN, and a NaN
    # residual came back as a result with no NoConvergenceError
    from roughfe.bem import adhesive_energy
    monkeypatch.setattr(adhesive_energy.AdhesiveEnergy, "residual",
                        lambda self, x: float("nan"))
    s = spectral_surface(16, 1e-4, 0.8, rms_height=1e-7, rng=1)
    with pytest.raises(NoConvergenceError, match="residual nan"):
        solve_adhesive(s, Material(1e9, 0.3), AdhesionLaw("exp", 0.01, 1e-6), delta=0.0,
                       max_iter=50)


def _johnson_difference(n, h0, delta):
    """(p - p_Johnson(a)) / p* for the adhesive sinusoid (Johnson 1995, JKR-type, plane
    strain): h = D cos(2 pi x / l), Johnson's alpha = 0.5, Maugis-Dugdale law with range
    h0 and a traction ramp over h0 -+ h0/4 (smoothing 0.5: the zone end resolved), and
    the Dugdale-zone width over a (cells where the tensile traction exceeds sigma0/2)."""
    l, amp = 1.0, 0.01
    e_star = MAT.E_star
    w = 0.25 * np.pi ** 2 * amp ** 2 / (2 * l)
    pstar = np.pi * e_star * amp / l
    s = Surface(amp * np.cos(2 * np.pi * np.arange(n) / n), l, periodic=True)
    law = AdhesionLaw("md", w, h0, smoothing=0.5)
    r = solve_adhesive(s, MAT, law, delta=delta)
    psi = np.pi * r.n_contact / (2 * n)
    johnson = pstar * np.sin(psi) ** 2 - np.sqrt(2 * w * e_star * np.tan(psi) / l)
    zone = np.count_nonzero((r.gap > 0) & (r.pressure < -0.5 * law.max_traction)) / 2
    return ((r.mean_pressure - johnson) / pstar, zone / (r.n_contact / 2),
            zone * l / n / law.process_zone(e_star))


def test_johnson_adhesive_sinusoid_in_the_jkr_limit():
    # Johnson's closed form p = p* sin^2(psi) - sqrt(2 w E* tan(psi) / l), psi = pi a / l,
    # is the JKR limit (Dugdale zone << a). The BEM with a Maugis-Dugdale law differs by
    # O(zone / a): measured +0.0046-0.0054 p* at zone/a = 2 % and +0.0012-0.0015 p* at
    # 0.5 % (grid-converged: 8192 -> 16384 cells change it by < 4e-4 p*). With the
    # nearly sharp default ramp (smoothing 0.05) the same case converges only slowly in
    # the grid (+0.026 / +0.013 / +0.008 p* at 2048 / 4096 / 8192 cells): the traction
    # step at h0 is then sampled by the cells (docs/theory/07_adhesion_persson.md)
    big, zone_big, measured_big = _johnson_difference(4096, 9.0e-4, 0.004)
    small, zone_small, measured_small = _johnson_difference(16384, 4.5e-4, 0.004)
    assert zone_big == pytest.approx(0.02, rel=0.3) and zone_small == pytest.approx(
        0.005, rel=0.5)
    # the measured Dugdale zone (traction beyond sigma0/2 outside contact) is
    # AdhesionLaw.process_zone, (pi/4) E* w / sigma0^2 (G = K^2 / 2E* at the edge of a
    # contact): measured 0.95 / 1.00 of it; the (pi/8) form read half the length
    assert measured_big == pytest.approx(1.0, abs=0.1)
    assert measured_small == pytest.approx(1.0, abs=0.1)
    assert 0.002 < big < 0.008
    assert abs(small) < 0.002 and abs(small) < big / 3


def test_cell_averaged_law_keeps_the_work_and_locates_the_zone_end():
    # the cell average of the Maugis-Dugdale law over g -+ delta: exact where the law is
    # linear, and int phi' dg = w for any spread (the ramp is symmetric about h0)
    law = AdhesionLaw("md", 0.05, 1e-9)
    g = np.linspace(0, 3e-9, 600001)
    for delta in (0.0, 0.1e-9, 0.4e-9, 2e-9):          # the last one capped at h0
        spread = np.full(g.shape, delta)
        phi, t = law.evaluate(g, spread)
        assert phi[0] == pytest.approx(-0.05, rel=1e-12, abs=0) and phi[-1] == 0.0
        assert np.sum(0.5 * (t[1:] + t[:-1]) * np.diff(g)) == pytest.approx(0.05, rel=1e-5)
        # brute-force average of the sharp-ish law over a uniform gap distribution
        if 0 < delta < 1e-9:
            k = np.searchsorted(g, [0.5e-9, 0.95e-9, 1.0e-9, 1.05e-9])
            sub = np.linspace(-delta, delta, 20001)
            for i in k:
                _, tb = law.evaluate(g[i] + sub)
                assert t[i] == pytest.approx(tb.mean(), abs=2e-2 * law.max_traction)


@pytest.mark.parametrize("kind", ["exp", "md"])
def test_preconditioned_cg_and_lbfgsb_reach_the_same_equilibrium(kind):
    # two independent minimisers of Eq. (1) (roughfe.bem.adhesive_cg and scipy's L-BFGS-B)
    # from the same elastic start: the same state to the traction tolerance (periodic
    # surface with the mean-gap spring, and the sphere on the padded Love grid)
    s = spectral_surface(64, 1e-4, 0.8, rms_height=1e-6, rng=1)
    mat = Material(1e9, 0.3)
    d = float(s.heights.max() - s.heights.mean() - 0.5e-6)
    law = AdhesionLaw(kind, 0.01, 20e-9)
    # tolerance 2e-6 of the traction scale: L-BFGS-B's line search stops on round-off
    # near 1e-6 (module docstring)
    a = solve_adhesive(s, mat, law, delta=d, solver="pcg", tol=2e-6)
    b = solve_adhesive(s, mat, law, delta=d, solver="lbfgsb", tol=2e-6)
    assert a.solver == f"adhesive-pcg-{kind}" and a.residual <= 2e-6
    scale = np.max(np.abs(b.pressure))
    assert np.max(np.abs(a.pressure - b.pressure)) <= 1e-4 * scale
    assert a.mean_pressure == pytest.approx(b.mean_pressure, rel=1e-5)
    assert np.count_nonzero(a.contact != b.contact) <= 2
    sph = sphere(32, 0.21)
    law = md_law(1.0) if kind == "md" else AdhesionLaw("exp", W, md_law(1.0).range)
    a = solve_adhesive(sph, MAT, law, delta=0.1 * D_SCALE, solver="pcg", tol=2e-6)
    b = solve_adhesive(sph, MAT, law, delta=0.1 * D_SCALE, solver="lbfgsb", tol=2e-6)
    assert a.load == pytest.approx(b.load, rel=1e-5, abs=1e-6 * np.pi * W * R)
    assert np.array_equal(a.contact, b.contact)


def test_unknown_adhesive_solver_is_refused():
    with pytest.raises(InputError, match="solver"):
        solve_adhesive(sphere(16, 0.2), MAT, md_law(1.0), delta=0.0, solver="newton")


#: exponential law on the 32^2 peel-off surface below: w = 0.01 J/m^2 over 100 nm, whose
#: process zone (pi/4) E* w / sigma0^2 = 1.05 um spans 3.4 grid spacings (resolved)
RESOLVED_EXP = AdhesionLaw("exp", 0.01, 1e-7)


def _peel_case():
    s = spectral_surface(32, 1e-5, 0.8, rms_height=1e-8, q_roll=2 * 2 * np.pi / 1e-5,
                         q_short=8 * 2 * np.pi / 1e-5, rng=3)
    return s, Material(1e6, 0.5)


def test_unloading_steps_grow_past_the_pull_off_until_separation():
    # Rough periodic contact, soft body, strong exponential adhesion (resolved): the last
    # patches peel off over a mean-gap opening ~ |p_pull| L / E* (~0.6 um), far beyond
    # the loading range (~0.02 um). With a fixed step 12 solves do not separate (the
    # pull-off is then a bound); with steps growing once the load recovers from its
    # minimum they do, and the pull-off (sampled at the fixed step while the states grow
    # more tensile) is the same.
    s, mat = _peel_case()
    law = RESOLVED_EXP
    deltas = np.linspace(0.1, 0.6, 3) * float(s.heights.max() - s.heights.mean())
    fixed = adhesive_sweep(s, mat, law, deltas, unload=True, max_unload_steps=12,
                           unload_growth=1.0)
    grown = adhesive_sweep(s, mat, law, deltas, unload=True, max_unload_steps=12)
    assert not fixed.detached and grown.detached
    assert grown.pull_off_pressure == pytest.approx(fixed.pull_off_pressure, rel=1e-12)
    # a tensile pull-off no larger than the peak traction of the law; separated at the end
    assert -law.max_traction < grown.pull_off_pressure < 0
    last = grown.sweep.results[-1]
    assert last.n_contact == 0 and abs(last.load) < 1e-3 * abs(grown.pull_off_force)
    with pytest.raises(InputError, match="unload_growth"):
        adhesive_sweep(s, mat, law, deltas, unload=True, unload_growth=0.5)


def test_pull_off_is_that_of_the_load_path_independent_of_the_step():
    """The quasi-static pull-off of a resolved law is that of the load path: independent
    of the step size, dependent on the maximum approach (the preload dependence of a
    displacement-controlled experiment)."""
    # Loaded to 0.6 of max h - mean h, the most tensile state of the unloading branch is
    # its start, the largest approach (-80.12 kPa), whatever the step: the pull-off is
    # the same at 3, 5 and 9 loading points to the solver's tolerance. Until round 2,
    # session 21 the branch's loads left that start out, and the pull-off read -77.57,
    # -78.94, -79.74 kPa, creeping towards it as the step shrank (taken then for
    # first-order convergence). Below the tensile strength sigma0 = w / rho. Loaded to
    # 0.2, 0.4 and 0.8 of it instead, the pull-off is -75.81, -77.73 and -83.14 kPa:
    # deeper loading, more tension (docs/theory/07_adhesion_persson.md; until round 2,
    # session 32, with each state pbar / k0 off its approach: -76.15, -78.12, -80.65,
    # -83.25 kPa).
    s, mat = _peel_case()
    top = float(s.heights.max() - s.heights.mean())
    runs = [adhesive_sweep(s, mat, RESOLVED_EXP, np.linspace(0.1, 0.6, k) * top,
                           unload=True, max_unload_steps=200) for k in (3, 5, 9)]
    pull = [r.pull_off_pressure for r in runs]
    assert max(pull) - min(pull) < 1e-5 * abs(pull[0])
    for r, k in zip(runs, (3, 5, 9)):
        branch = r.sweep.mean_pressure[k - 1:]          # from the largest approach on
        # (pull-off force / nominal area against the stored mean pressure: equal to the
        # rounding of that division, not bit for bit)
        assert r.pull_off_pressure == pytest.approx(branch.min(), rel=1e-12, abs=0.0)
        assert r.detached
    assert -RESOLVED_EXP.max_traction < pull[0] < 0

    def pull_off_to(depth):
        return adhesive_sweep(s, mat, RESOLVED_EXP, np.linspace(0.1, depth, 3) * top,
                              unload=True, max_unload_steps=200).pull_off_pressure

    by_depth = [pull_off_to(0.2), pull_off_to(0.4), pull[0], pull_off_to(0.8)]
    assert np.all(np.diff(by_depth) < -1e-2 * abs(pull[0]))   # far beyond the step's 1e-5
    # max_unload_steps = 0: no solve beyond the loading range (it meant the default)
    none = adhesive_sweep(s, mat, RESOLVED_EXP, np.linspace(0.1, 0.6, 3) * top,
                          unload=True, max_unload_steps=0)
    assert len(none.sweep.results) == 3 + 2


@pytest.mark.parametrize("kernel", ["spectral", "love"])
def test_the_continuation_start_is_the_elastic_gap_increment_of_a_fixed_contact_set(kernel):
    # The tangent predictor of adhesive_sweep (roughfe.bem.adhesive_start): from an
    # elastic state at Delta1, the gap g + dDelta (H x - 1), H_cc x_c = 1, is the elastic
    # gap at Delta2 when the contact set does not change (Eq. 2.5 is linear in Delta on a
    # fixed set); the shifted gap g - dDelta is not. Measured here: 9.8e-5 / 7.2e-5 of the
    # increment (periodic / Love), the rate's tolerance 1e-4; the shift 0.90 / 1.47.
    from roughfe.bem.adhesive_energy import AdhesiveEnergy
    from roughfe.bem.adhesive_start import continued_start
    from roughfe.bem.contact import _operator
    s = spectral_surface(64, 1e-4, 0.8, rms_height=1e-6, rng=4)
    if kernel == "love":
        s = Surface(s.heights, s.size, periodic=False)
    mat = Material(1e9, 0.3)
    top = float(s.heights.max() - (s.heights.mean() if kernel == "spectral" else
                                   s.heights.min()))
    d1 = 0.3 * top
    r1 = solve_contact(s, mat, delta=d1, kernel=kernel, tol=1e-12)
    # the largest step that keeps the contact set: a tenth of the smallest gap off it
    step = 0.1 * float(np.min(r1.gap[~r1.contact]))
    r2 = solve_contact(s, mat, delta=d1 + step, kernel=kernel, tol=1e-12)
    assert np.array_equal(r1.contact, r2.contact)
    op = _operator(s.shape, s.size, mat.E_star, kernel)
    c = float(s.heights.max()) - s.heights - (d1 + step)
    energy = AdhesiveEnergy(op, AdhesionLaw("exp", 1e-3, 1e-7), c, None, 1.0)
    x0 = continued_start(r1, d1 + step, op, energy)
    g = x0 if kernel == "spectral" else x0[energy.phys]
    change = np.abs(r2.gap - r1.gap).max()
    assert np.abs(g - r2.gap).max() <= 1e-3 * change
    assert np.abs((r1.gap - step) - r2.gap).max() > 0.1 * change     # the shift is not


def _pull_off_on_refined_grids(law, sizes):
    """Pull-off pressures (Pa) of one band-limited rough cell (resolved at 32^2: four
    points per shortest wavelength) on the grids ``sizes``, loaded to the same mean-plane
    separations and unloaded until separation."""
    length = 1e-5
    base = spectral_surface(32, length, 0.8, rms_height=1e-8, q_roll=4 * np.pi / length,
                            q_short=16 * np.pi / length, rng=3)
    sep = float(base.heights.max() - base.heights.mean()) * (1 - np.linspace(0.1, 0.6, 6))
    out = []
    for n in sizes:
        s = base if n == 32 else base.resampled((n, n))
        top = float(s.heights.max() - s.heights.mean())
        sw = adhesive_sweep(s, Material(1e6, 0.5), law, top - sep, unload=True,
                            max_unload_steps=80)
        assert sw.detached
        out.append(sw.pull_off_pressure)
    return np.array(out)


def test_rough_pull_off_converges_under_grid_refinement_only_when_the_zone_is_resolved():
    # One rough cell on 32^2, 64^2, 128^2 (the same band-limited surface). A law whose
    # process zone spans 3.4, 6.7, 13.4 spacings: first-order convergence (measured
    # -80123.9, -80117.0, -80113.7 Pa: differences 7.0, 3.3 Pa). The law of the old
    # peel-off test (zone 6.7e-4 of a spacing on 32^2): no convergence (-4.65, -4.62,
    # -3.05 MPa on the same grids, measured; -3.94, -4.43, -2.87 from the rest length at
    # the target, earlier in session 32). Until round 2, session
    # 32 the machine spring's compliance put each state pbar / k0 off its approach, k0
    # growing as 1 / dx: the resolved values read -79235, -79030, -78926 Pa (differences
    # 205, 104 Pa), the unresolved -6.70, -4.61, -3.07 MPa.
    p = _pull_off_on_refined_grids(RESOLVED_EXP, (32, 64, 128))
    d1, d2 = p[1] - p[0], p[2] - p[1]
    assert np.sign(d1) == np.sign(d2) and abs(d2) <= 0.6 * abs(d1)
    assert abs(d2) <= 2e-4 * abs(p[2])
    with pytest.warns(ResolutionWarning):
        q = _pull_off_on_refined_grids(AdhesionLaw("exp", 0.02, 2e-9), (32, 64, 128))
    # the spread over the three grids: 0.52 against 1.3e-4 (two grids can agree by
    # chance: -4.65 and -4.62 MPa on 32^2 and 64^2 since the state start of session 32)
    spread = lambda v: float(np.ptp(v) / np.max(np.abs(v)))
    assert spread(q) > 100 * spread(p)


def test_an_unresolved_process_zone_is_a_warning_that_names_the_lengths():
    # The peel-off surface with w = 0.02 J/m^2 over 2 nm: a process zone of 2.1e-10 m on a
    # 0.31 um grid. There the pull-off scatters by tens of percent with the step of the
    # continuation (docs/theory/07): the solve runs, and says so.
    s, mat = _peel_case()
    law = AdhesionLaw("exp", 0.02, 2e-9)
    assert law.process_zone(mat.E_star) == pytest.approx(
        np.pi / 4 * mat.E_star * 0.02 / 1e7 ** 2, rel=1e-14, abs=0)
    top = float(s.heights.max() - s.heights.mean())
    with pytest.warns(ResolutionWarning, match=r"process zone .* 2\.09e-10 m, 0\.00067 of "
                                               r"the grid spacing 3\.13e-07 m"):
        solve_adhesive(s, mat, law, delta=0.3 * top)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ResolutionWarning)
        solve_adhesive(s, mat, RESOLVED_EXP, delta=0.3 * top)     # resolved: silent
    # the sweep keeps the numbers (what roughfe contact writes to results.json)
    with pytest.warns(ResolutionWarning) as record:
        res = adhesive_sweep(s, mat, law, [0.3 * top, 0.4 * top], unload=True,
                             max_unload_steps=1).resolution
    # once for the sweep, not at each of its solves (the CLI printed it twice)
    assert sum(issubclass(w.category, ResolutionWarning) for w in record) == 1
    assert not res["resolved"] and res["grid_spacing"] == pytest.approx(1e-5 / 32, rel=1e-6, abs=0)
    assert res["process_zone_cells"] == pytest.approx(6.7e-4, rel=1e-2)
    assert adhesive_sweep(s, mat, RESOLVED_EXP, [0.3 * top]).resolution["resolved"]


def test_cell_averaged_law_in_2d_against_quadrature_on_a_paraboloid():
    # DMT limit: the rigid gap g = g0 + r^2 / 2R of a sphere; the total attraction is
    # exactly 2 pi R (-phi(g0)) (r dr = R dg). Against it, on 20 random sub-cell offsets
    # of the apex: the cell-averaged law (uniform spread with the variance of the linear
    # field, as in the solver), the exact average of the law over the linearised gap in
    # each cell (trapezoidal distribution, 24^2-point quadrature), and the law sampled at
    # the centres. Measured (g0 = 0 / 0.5 h0, max over offsets): 4 cells per zone radius
    # 1.2e-2 / 2.7e-2 (trapezoid 1.1e-2 / 2.1e-2, sampled 6.5e-2 / 8.5e-2); 8 cells
    # 4.9e-3 / 7.7e-3 (trapezoid 2.9e-3 / 5.8e-3, sampled 2.1e-2 / 1.2e-2). The remaining
    # error is the gap's curvature inside a cell (a mean bias, second order: x3.8 per
    # halving), which neither average removes; the uniform-for-trapezoid approximation
    # adds up to ~3.3e-3 at 8 cells (g0 = 0, over offsets).
    R, h0 = 1.0, 1e-4
    law = AdhesionLaw("md", 1e-3, h0)
    radius = np.sqrt(2 * R * h0)
    rng = np.random.default_rng(0)
    sub = (np.arange(24) + 0.5) / 24 - 0.5
    for g0, bounds in ((0.0, (1.5e-2, 6e-3)), (0.5 * h0, (3e-2, 1e-2))):
        exact = 2 * np.pi * R * (-law.potential(g0))
        bias = []
        for cells, bound in zip((4, 8), bounds):
            dx = radius / cells
            n = int(2 * np.ceil(1.3 * cells)) + 2
            err = []
            for _ in range(20):
                off = rng.uniform(-0.5, 0.5, 2) * dx
                x, y = np.meshgrid((np.arange(n) - n / 2 + 0.5) * dx + off[0],
                                   (np.arange(n) - n / 2 + 0.5) * dx + off[1], indexing="ij")
                g = g0 + (x * x + y * y) / (2 * R)
                averaged = law.evaluate(g, np.hypot(x, y) / R * dx / 2)[1].sum() * dx * dx
                sx, sy = np.meshgrid(sub * dx, sub * dx, indexing="ij")
                lin = g[..., None, None] + (x / R)[..., None, None] * sx \
                    + (y / R)[..., None, None] * sy
                trapezoid = law.traction(lin).mean(axis=(-1, -2)).sum() * dx * dx
                sampled = law.traction(g).sum() * dx * dx
                err.append((averaged / exact - 1, trapezoid / exact - 1, sampled / exact - 1))
            err = np.array(err)
            assert np.max(np.abs(err[:, 0])) <= bound
            assert np.max(np.abs(err[:, 0])) < np.max(np.abs(err[:, 2]))
            assert np.max(np.abs(err[:, 0] - err[:, 1])) <= 0.7 * bound
            bias.append(np.mean(err[:, 0]))
        assert bias[0] > 0 and bias[0] / bias[1] > 3           # second order


def test_adhesive_sweep_default_approaches():
    # n_steps: equispaced approaches short of full contact (periodic kernel: the
    # adhesive state is not defined by the approach there, and the solver refuses it)
    # or up to the peak-to-valley height (Love); both deltas and n_steps, or a bad
    # n_steps, is a clear error
    s = spectral_surface(32, 1e-5, 0.8, rms_height=1e-8, q_roll=2 * 2 * np.pi / 1e-5,
                         q_short=8 * 2 * np.pi / 1e-5, rng=3)
    mat, law = Material(1e6, 0.5), AdhesionLaw("exp", 1e-3, 1e-7)   # resolved, weak
    h = s.heights
    # (a reported Delta is the equilibrium's own, within pbar / k0 of the imposed one:
    # the sweeps are compared with those of the explicit approaches)
    sw = adhesive_sweep(s, mat, law, n_steps=3).sweep
    ref = adhesive_sweep(s, mat, law, (h.max() - h.mean()) * np.array([1, 2, 3]) / 4).sweep
    assert np.array_equal(sw.delta, ref.delta) and np.array_equal(sw.load, ref.load)
    assert np.all(np.diff(sw.load) > 0)                  # loading: more load
    love = adhesive_sweep(s, mat, law, n_steps=2, kernel="love").sweep
    ref = adhesive_sweep(s, mat, law, np.ptp(h) * np.array([0.5, 1.0]), kernel="love").sweep
    assert np.array_equal(love.delta, ref.delta)
    with pytest.raises(InputError, match="not both"):
        adhesive_sweep(s, mat, law, [1e-9], n_steps=3)
    with pytest.raises(InputError, match="n_steps must be an integer >= 1"):
        adhesive_sweep(s, mat, law, n_steps=0)


def test_every_sweep_argument_is_checked_before_the_first_solve(monkeypatch):
    # A periodic approach reaching max h - mean h was refused by the solve of that step,
    # unload_growth after the loading branch, max_unload_steps after the loading branch
    # and its retrace: `roughfe contact --delta ... 3.3e-8 --unload` solved every earlier
    # step before it failed (found by a reviewer, session 26). Now adhesive_sweep checks
    # them first: no solve runs.
    from roughfe.bem import adhesion

    def solved(*args, **kwargs):
        raise AssertionError("solve_adhesive ran before the arguments were checked")

    monkeypatch.setattr(adhesion, "solve_adhesive", solved)
    s = spectral_surface(16, 1e-5, 0.8, rms_height=1e-8, rng=3)
    mat, law = Material(1e6, 0.5), AdhesionLaw("exp", 1e-3, 1e-7)
    top = float(s.heights.max() - s.heights.mean())
    below = np.array([0.2, 0.5, 0.8]) * top
    for deltas, kwargs, match in (
            ([0.2 * top, 0.5 * top, top], {}, r"delta = .* reaches max h - mean h = .*full "
                                              r"contact"),
            ([0.2 * top, 1.5 * top], {"unload": True}, "full contact"),
            (below, {"unload": True, "unload_growth": 0.5}, "unload_growth must be a finite "
                                                            "factor >= 1, got 0.5"),
            (below, {"unload": True, "unload_growth": float("nan")}, "unload_growth"),
            (below, {"unload": True, "unload_growth": "x"}, "unload_growth"),
            (below, {"unload": True, "max_unload_steps": -1}, "max_unload_steps must be an "
                                                              "integer >= 0, got -1"),
            (below, {"unload": True, "max_unload_steps": 2.5}, "max_unload_steps")):
        with pytest.raises(InputError, match=match):
            adhesive_sweep(s, mat, law, deltas, **kwargs)
    # the full-contact rule is the periodic kernel's: on the Love kernel (peak-to-valley
    # approaches) the same approaches pass the check and reach the solver
    with pytest.raises(AssertionError, match="solve_adhesive ran"):
        adhesive_sweep(s, mat, law, [0.2 * top, top], kernel="love")


def test_adhesive_sweep_refuses_approaches_that_do_not_increase():
    # the continuation labels every given approach a loading step and retraces them in
    # reverse to unload: given decreasing, the separating steps were labelled loading and
    # the "unloading" branch went back up (until round 2 session 24)
    s = spectral_surface(16, 1e-5, 0.8, rms_height=1e-8, rng=3)
    mat, law = Material(1e6, 0.5), AdhesionLaw("exp", 1e-3, 1e-7)
    for deltas in ([3e-9, 2e-9, 1e-9], [1e-9, 1e-9], [1e-9, 3e-9, 2e-9]):
        with pytest.raises(InputError, match="must be strictly increasing") as info:
            adhesive_sweep(s, mat, law, deltas, unload=True)
        assert str(deltas[1]) in str(info.value)


def test_the_adhesive_rules_speak_each_front_end_s_words():
    """One function holds the rules; the library and the command line get the same
    message in their own vocabulary."""
    from roughfe.bem.adhesive_rules import check_adhesive_run
    from roughfe.cli.options import ADHESION_WORDS
    check_adhesive_run()                                   # the defaults keep every rule
    cases = [({"hardness": 1e9}, "hardness and adhesion", "--hardness and --adhesion"),
             ({"solver": "pk"}, "solver does not apply with adhesion",
              "--solver does not apply with --adhesion"),
             ({"coarse_correction": False}, "coarse_correction does not apply",
              "--coarse-correction does not apply"),
             ({"pressure_control": True}, "give approaches (delta, deltas, n_steps), not mean",
              "give --delta or --steps, not --pressure"),
             ({"deltas": [3e-8, 2e-8]}, "deltas (the approaches of the adhesion loading",
              "--delta (the approaches of the --adhesion loading")]
    for kwargs, library, cli in cases:
        with pytest.raises(InputError) as info:
            check_adhesive_run(**kwargs)
        assert library in str(info.value)
        with pytest.raises(InputError) as info:
            check_adhesive_run(**kwargs, words=ADHESION_WORDS)
        assert cli in str(info.value)



def test_the_adhesive_cg_hands_a_stalled_jump_in_to_lbfgsb():
    # Johnson's sinusoid (alpha = 0.5) with an exponential law at its jump-in: the warm
    # step from the last open state lands on the non-convex branch, where the CG crawled
    # for all 20000 iterations (traction residual 21) and the sweep raised, while
    # L-BFGS-B from the same start converges (found by a reviewer, round 2, session 22).
    # Now the CG stops when its residual has not halved in ADHESIVE_STALL_WINDOW
    # iterations and L-BFGS-B finishes: the jumped-in state, as L-BFGS-B alone finds it.
    mat, length, amp = Material(0.91, 0.3), 1.0, 0.01
    law = AdhesionLaw("exp", 0.25 * np.pi ** 2 * amp ** 2 / 2, 9e-4)
    n = 1024
    s = Surface(amp * np.cos(2 * np.pi * np.arange(n) / n), length, periodic=True)
    open_state = solve_adhesive(s, mat, law, delta=-0.375 * amp)
    assert open_state.n_contact == 0
    jumped = solve_adhesive(s, mat, law, delta=-0.35 * amp, initial=open_state)
    alone = solve_adhesive(s, mat, law, delta=-0.35 * amp, initial=open_state,
                           solver="lbfgsb")
    assert jumped.nit < 2000 and jumped.n_contact > 0.15 * n
    # both stop within the traction tolerance 1e-5 S (S = sigma0 here); the mean pressure
    # is 4 % of S, so 1e-4 of it (2.4e-6 S, held under the mean-gap spring until round
    # 2, session 32) asked for more than the solves give: measured 6.4e-6 S apart
    assert jumped.mean_pressure == pytest.approx(alone.mean_pressure, rel=0,
                                                 abs=1e-5 * law.max_traction)
    assert jumped.mean_pressure < -0.18 * np.pi * amp * mat.E_star   # tensile: attached


def test_the_resolution_a_law_needs_depends_on_the_law_and_the_grid():
    # Maugis' sphere (R = 1 m, w = 2.83e-4 J/m^2, lambda = 3) on the Love kernel, loaded
    # and unloaded to separation. The exponential law is resolved from about one zone
    # cell, the Maugis-Dugdale law needs about three (AdhesionLaw.resolution_cells;
    # measured in round 2, session 22): at 1.16 cells, which the law-blind threshold
    # of one cell called resolved, its pull-off is 4.9 % off Maugis' (and the branches
    # differ by 5 % of it where the state is unique); at 3.1 cells 1.0 %.
    from roughfe.bem.interface_law import SQUARE_CELL_COMPLIANCE, resolution
    from roughfe.reference import maugis_pull_off
    w, radius, lam = 2.83e-4, 1.0, 3.0
    mat = Material(0.91, 0.3)
    k = 4 / 3 * mat.E_star
    unit = (np.pi ** 2 * w ** 2 * radius / k ** 2) ** (1 / 3)
    sigma0 = lam / (2 * (radius / (np.pi * w * k ** 2)) ** (1 / 3))
    deltas = np.arange(-1.0, 0.425, 0.05) * unit

    def pull_off(kind, n):
        law = AdhesionLaw(kind, w, w / sigma0)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ResolutionWarning)
            sw = adhesive_sweep(sphere_cap(n, 0.3, radius), mat, law, deltas, unload=True)
        assert sw.detached
        return sw.pull_off_force / (np.pi * w * radius) / maugis_pull_off(lam) - 1, sw.resolution

    coarse, r = pull_off("md", 48)
    assert r["process_zone_cells"] == pytest.approx(1.16, abs=0.01)
    assert r["cell_compliance"] == pytest.approx(SQUARE_CELL_COMPLIANCE, abs=0.01)
    assert not r["resolved"] and r["threshold_cells"] == pytest.approx(3.03, abs=0.01)
    assert coarse > 0.03
    fine, r = pull_off("md", 128)
    assert r["resolved"] and abs(fine) < 0.015
    assert resolution(AdhesionLaw("exp", w, w / sigma0), mat.E_star, (0.3 / 48,) * 2)[
        "resolved"]
    # a profile: the cell is 3-7 times softer (its compliance grows as log n), and the
    # Maugis-Dugdale ramp's own stiffness counts (max(3.2, 0.6/s) c): Johnson's sinusoid
    # with s = 0.05 at 10.6 zone cells (n = 2048) shows 2.7e-2 p* of hysteresis
    n, amp = 2048, 0.01
    law = AdhesionLaw("md", 0.25 * np.pi ** 2 * amp ** 2 / 2, 9e-4, smoothing=0.05)
    s = Surface(amp * np.cos(2 * np.pi * np.arange(n) / n), 1.0, periodic=True)
    with pytest.warns(ResolutionWarning, match=r"needs at least 5\d"):
        solve_adhesive(s, mat, law, delta=0.0)
    with pytest.raises(InputError, match="compliance"):
        resolution(law, mat.E_star, (1.0 / n,))
    # below s = 0.05 the cell spread sets the ramp: s = 0 solves the same law and needs
    # the same grid (0.6 / s asked for 3e12 cells)
    sharp = AdhesionLaw("md", law.work, law.range, smoothing=0.0)
    assert sharp.resolution_cells(4.6, 1) == law.resolution_cells(4.6, 1) == pytest.approx(
        0.6 / 0.05 * 4.6)


def test_the_pull_off_does_not_depend_on_the_unloading_step():
    """A Maugis-Dugdale sphere (lambda = 2) traced at steps of 0.4 and 0.1 Maugis units:
    the most tensile sample of the coarse branch read short of the fine one (the true
    minimum lies between samples; a user's review measured 11 % on a coarser path). With
    the steps around it bisected (refine_pull_off) both give Maugis' pull-off, and the
    refined branch keeps its states in order of the approach."""
    from roughfe.bem.adhesive_pull_off import refine_pull_off
    law = md_law(2.0)
    runs = {}
    for name, count in (("coarse", 3), ("fine", 9)):
        runs[name] = adhesive_sweep(sphere(64, 0.21), MAT, law,
                                    np.linspace(-0.6, 0.2, count) * D_SCALE, unload=True,
                                    max_unload_steps=12)
    coarse, fine = (runs[k].pull_off_force / (np.pi * W * R) for k in ("coarse", "fine"))
    assert coarse == pytest.approx(fine, rel=5e-3)
    assert coarse == pytest.approx(maugis_pull_off(2.0), rel=1e-2)
    recs = [r for r in runs["coarse"].records() if r["unloading"]]
    assert all(a["delta"] > b["delta"] for a, b in zip(recs, recs[1:]))
    # the bisection itself on a parabola F = (d - 0.3)^2 - 1 sampled at d = 1, 0.5, 0, -0.5
    from types import SimpleNamespace
    calls = []

    def solve(d, initial):
        calls.append((d, initial.delta))
        return SimpleNamespace(delta=d, load=(d - 0.3) ** 2 - 1)
    branch = [(d, SimpleNamespace(delta=d, load=(d - 0.3) ** 2 - 1)) for d in (1, 0.5, 0, -0.5)]
    out = refine_pull_off(branch, solve, resolution=0.1)
    ds = [d for d, _ in out]
    assert ds == sorted(ds, reverse=True)
    # the samples' minimum -0.96 (at 0.5) becomes the parabola's to within (h / 2)^2
    assert -1.0 <= min(s.load for _, s in out) <= -1.0 + 0.05 ** 2
    assert all(init > d for d, init in calls)       # each continued from the larger approach
    assert len(calls) <= 2 * 4


def test_a_flat_surface_without_approaches_is_said_flat():
    """n_steps on a flat surface gave approaches 0, 0, 0 and the message "deltas must be
    strictly increasing" (a user's review): it now says the surface is flat."""
    flat = Surface(np.zeros((16, 16)), 1e-4, periodic=True)
    with pytest.raises(InputError, match="the surface is flat"):
        adhesive_sweep(flat, Material(1e6, 0.3), AdhesionLaw("exp", 0.01, 1e-8), n_steps=3)


def test_a_branch_without_tensile_state_has_no_pull_off():
    # a surface that is not sticky (Pastewka-Robbins C = 325) separates without tension:
    # the loads beyond separation are the exponential law's tail attraction, below what
    # a solve at tol 1e-5 resolves (-2.5e-11 N with the reference BLAS, -3.2e-9 N with
    # OpenBLAS: 2e-8 of the peak load). The branch ran on for 4 x the loading steps to a
    # gap of 750 x the range, read -1.3e-13 N of the FFT round-off as its pull-off and
    # bisected it (a docs audit, session 31); with OpenBLAS it read -8.7e-9 N (the floor
    # followed the FFT round-off, not the solve's tolerance; session 42)
    from roughfe.bem.adhesive_pull_off import tensile_floor
    surf = spectral_surface(32, 1e-4, 0.8, rms_height=1e-6, rng=4)
    sw = adhesive_sweep(surf, Material(1e9, 0.3), AdhesionLaw("exp", 0.05, 2e-8),
                        n_steps=4, unload=True)
    loads = sw.sweep.load
    assert tensile_floor(loads, 1e-5) == pytest.approx(1e-5 * np.abs(loads).max(), rel=1e-15, abs=0)
    assert tensile_floor(loads, 1e-12) == pytest.approx(1e-9 * np.abs(loads).max(), rel=1e-15, abs=0)
    assert sw.detached and sw.pull_off_force == 0.0 and sw.pull_off_pressure == 0.0
    assert loads.min() > -1e-5 * np.abs(loads).max()
    # it stops at the first separated state, not 16 steps later
    unloading = np.flatnonzero(sw.sweep.unloading)
    assert sw.sweep.results[unloading[-1]].n_contact == 0
    assert sw.sweep.results[unloading[-2]].n_contact > 0


@pytest.mark.slow
def test_a_narrow_ramp_on_summits_of_the_grid_scale_needs_the_cells_stiffness(
        topographies_dir):
    """Round 2, session 31. A 192^2 window of di-1.di (Love kernel, E* = 210 MPa,
    w = 0.05 J/m^2, h0 = 2 nm: 13.5 zone cells; its summits stand 0.27 nm rms off their
    neighbours), cold solves with the same flat at 0.317 of di-1's peak-to-valley height.
    On the measured grid one patch has jumped in with the ramps s = 0.2 and 0.5 and not
    with the default 0.05 (measured A* 0.124 against 0.187, its jump-in 0.32 nm of
    approach late; 0.21 / 0.15 nm at s = 0.2 / 0.5); on the 2x Fourier refinement (27
    zone cells) all three give A* = 0.1701 (and on the 4x one the jump-in approaches of
    the 2x grid). The rule asks the cell's stiffness E*/(c dx) to exceed the ramp's
    sigma0/(s h0) there: (pi/4)/s c = 17.6 cells at s = 0.05."""
    from roughfe.bem.interface_law import cell_relief, check_resolution, resolution
    from roughfe.surfaces.io import load_surface
    full = load_surface(topographies_dir / "di-1.di")
    h_full = full.heights
    plane = h_full.max() - 0.317 * (h_full.max() - h_full.min())
    mirror = full.mirrored()
    mat = Material(2.1e8, 0.0)
    laws = [AdhesionLaw("md", 0.05, 2e-9, smoothing=s) for s in (0.05, 0.2, 0.5)]
    area = {}
    for f in (1, 2):
        grid = mirror if f == 1 else mirror.resampled((mirror.shape[0] * f,) * 2)
        s = Surface(grid.heights[224 * f:416 * f, 288 * f:480 * f], 192 * full.spacing[0],
                    periodic=False)
        relief = cell_relief(s.heights)
        assert relief == pytest.approx(0.27e-9 / f ** 1.4, rel=0.1)
        r = resolution(laws[0], mat.E_star, s.spacing, 1.12, relief)
        assert r["process_zone_cells"] == pytest.approx(13.5 * f, abs=0.1 * f)
        assert r["threshold_cells"] == pytest.approx(np.pi / 4 / 0.05 * 1.12, abs=1e-9)
        with warnings.catch_warnings():
            warnings.simplefilter("error", ResolutionWarning)
            for law in laws[1:]:      # resolved on both grids
                assert check_resolution(law, mat.E_star, s.spacing, 1.12, relief)
            if f == 2:
                assert check_resolution(laws[0], mat.E_star, s.spacing, 1.12, relief)
        solved = {}       # the default ramp's warned solve is the first of the three
        if f == 1:
            with pytest.warns(ResolutionWarning, match=r"needs at least 18.*smoothing 0.5"):
                solved[0] = solve_adhesive(s, mat, laws[0], delta=s.heights.max() - plane)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ResolutionWarning)
            area[f] = [(solved.get(k) or solve_adhesive(s, mat, law,
                                                        delta=s.heights.max() - plane)
                        ).area_fraction for k, law in enumerate(laws)]
    assert area[1][0] < area[1][1] - 0.05
    assert area[1][1] == pytest.approx(area[1][2], abs=2e-3)
    assert max(area[2]) - min(area[2]) < 1e-3
    assert area[2][0] == pytest.approx(0.1701, abs=1e-3)


def test_response_carries_the_pull_off_of_the_adhesive_sweep():
    """Round 2, session 32: ``response(..., adhesion=law, unload=True)`` returned the
    sweep of the adhesive continuation without its pull-off force (the solver computed
    it; a user of the one entry point had to re-read it off the loads, unrefined). The
    sweep now carries the pull-off and whether the branch detached, the same as the
    direct adhesive_sweep, and None where no unloading branch was traced."""
    from roughfe.model import Loading
    from roughfe.response import response
    law = md_law(1.0)
    surface = sphere(32, 0.3)
    deltas = np.linspace(0.0, 0.3, 4) * D_SCALE     # (Loading takes no negative ones)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ResolutionWarning)
        direct = adhesive_sweep(surface, MAT, law, deltas, unload=True)
        swept = response(surface, MAT, Loading(deltas=deltas), adhesion=law, unload=True)
        loaded = response(surface, MAT, Loading(deltas=deltas), adhesion=law)
    assert direct.detached and swept.detached is True
    # the same continuation: the same most tensile load of the (refined) branch
    assert swept.pull_off_force == pytest.approx(direct.pull_off_force, rel=1e-9, abs=0)
    assert swept.pull_off_force == pytest.approx(min(swept.load), rel=1e-12, abs=0)
    assert swept.pull_off_force < 0
    assert swept.pull_off_pressure == pytest.approx(
        swept.pull_off_force / surface.nominal_area, rel=1e-12, abs=0)
    # the sphere's pull-off, within the coarse grid's error of Maugis' (lambda = 1)
    assert swept.pull_off_force / (np.pi * W * R) == pytest.approx(maugis_pull_off(1.0),
                                                                   rel=0.1, abs=0)
    assert loaded.pull_off_force is None and loaded.detached is None
    assert direct.sweep.pull_off_force == swept.pull_off_force
