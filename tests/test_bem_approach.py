"""An imposed approach on a periodic surface solved through load control
(roughfe.bem.approach): the same solution as the gap-variable CG, the round trip with load
control, the secant hook on a known Delta(P), and the fallbacks."""
import numpy as np
import pytest

from roughfe.bem import Material, contact, contact_sweep, solve_contact
from roughfe.bem.approach import LoadSecant, approach_start
from roughfe.bem.coarse_start import _coarse_surface
from roughfe.surfaces.spectral import spectral_surface
from roughfe.surfaces.surface import Surface

MAT = Material(1.0, 0.0)


@pytest.fixture(scope="module")
def rough():
    return spectral_surface(256, 1.0, 0.8, rms_slope=1.0, rng=3)


def _gap_variable(monkeypatch):
    """solve_contact with the approach path switched off (the gap-variable CG)."""
    monkeypatch.setattr(contact, "approach_start", lambda *a, **k: None)


@pytest.mark.parametrize("fraction", [0.15, 0.4, 0.8])
def test_by_load_equals_the_gap_variable_solution(rough, fraction, monkeypatch):
    """Two independent solvers of Eq. 2.5-2.6 at an imposed Delta: the same contact set,
    pressures within the KKT tolerance, and the load-path answer meets the tolerance in
    displacement control (gap >= 0 and p g = 0 at the imposed Delta itself)."""
    delta = fraction * (rough.heights.max() - rough.heights.mean())
    a = solve_contact(rough, MAT, delta=delta, compute_stiffness=False)
    assert a.tolerance == 1e-10 and a.residual <= 1e-10 and a.delta == delta
    h = rough.heights
    w = a.displacement + h.max() - h - delta            # the gap at the imposed Delta
    scale = np.ptp(h)
    assert w.min() >= -1e-10 * scale
    assert np.sum(a.pressure * np.abs(w)) <= 1e-10 * scale * a.pressure.sum()
    _gap_variable(monkeypatch)
    b = solve_contact(rough, MAT, delta=delta, compute_stiffness=False)
    assert np.array_equal(a.contact, b.contact)
    assert np.abs(a.pressure - b.pressure).max() <= 1e-7 * b.pressure.max()
    assert a.mean_pressure == pytest.approx(b.mean_pressure, rel=1e-8)


def test_round_trip_with_load_control(rough):
    """The approach of a load-controlled solution, imposed, gives back its load."""
    p = solve_contact(rough, MAT, mean_pressure=0.03, compute_stiffness=False)
    d = solve_contact(rough, MAT, delta=p.delta, compute_stiffness=False)
    assert d.mean_pressure == pytest.approx(0.03, rel=1e-8)
    assert np.array_equal(d.contact, p.contact)


def test_the_secant_reaches_a_known_law():
    """On Delta(P) = c log(P / P0) (the exponential law of rough contacts) the hook,
    fed exact estimates, reaches the target within its tolerance in a few moves; it
    never moves while the residual is above the offset, nor within the tolerance."""
    c, p0, target = 0.3, 1e-3, 1.0
    law = lambda P: c * np.log(P / p0)                  # noqa: E731
    hook = LoadSecant(target, 1e-2, 1e-2 / 0.5, 1e-12, 1.0, 1e-12)
    assert hook(1.0, law(1e-2)) is None                 # residual 1 > |offset| 0.31
    P = 1e-2
    for _ in range(20):
        new = hook(1e-14, law(P))
        if new is None:
            break
        P = new
    assert abs(law(P) - target) <= 1e-12 and hook.moves <= 10
    assert P == pytest.approx(p0 * np.exp(target / c), rel=1e-11, abs=0)


def test_the_start_and_its_fallbacks(rough):
    """A coarse estimate of the load from the same flat height on the coarsened grid;
    none below 256 points per axis, where the coarse surface does not touch, or where
    the start is in contact on more than half the grid (those take the gap-variable CG,
    and still solve)."""
    top = rough.heights.max() - rough.heights.mean()
    p, pm = approach_start(rough, MAT, 0.3 * top, None)
    assert p.shape == rough.shape and pm > 0 and p.mean() == pytest.approx(pm)
    low = spectral_surface(256, 1.0, 0.8, rms_slope=1.0, rng=1)
    below = low.heights.max() - _coarse_surface(low).heights.max()   # its coarse top
    assert below > 0 and approach_start(low, MAT, 0.5 * below, None) is None
    small = spectral_surface(64, 1.0, 0.8, rms_slope=1.0, rng=1)
    assert approach_start(small, MAT, 0.3, None) is None
    r = solve_contact(small, MAT, delta=0.3 * (small.heights.max() - small.heights.mean()))
    assert r.residual <= 10 * r.tolerance
    given = np.zeros(rough.shape)
    given[:64] = 2.0                                     # a quarter of the grid
    assert approach_start(rough, MAT, 0.3 * top, given)[1] == 0.5
    assert approach_start(rough, MAT, 0.3 * top, np.zeros(rough.shape)) is None
    # nearly full contact: the gap-variable CG (its unknowns are the few open points)
    assert approach_start(rough, MAT, 0.3 * top, np.ones(rough.shape)) is None
    assert approach_start(rough, MAT, 0.999 * top, None) is None


def test_approach_sweep_equals_the_load_sweep(rough):
    """The default sweep (equispaced approaches, each started from the secant of the
    last two) against load control at its own mean pressures: the same contact areas,
    and every step at its imposed Delta."""
    s = contact_sweep(rough, MAT, n_steps=8, compute_stiffness=False)
    loads = [r.mean_pressure for r in s.results[:-1]]
    q = contact_sweep(rough, MAT, pressures=loads, compute_stiffness=False)
    assert np.array_equal(s.n_contact[:-1], q.n_contact)
    top = rough.heights.max() - rough.heights.mean()
    assert np.allclose(s.delta, top * np.arange(1, 9) / 8, rtol=0, atol=1e-15)
    assert all(r.residual <= r.tolerance for r in s.results)


def test_profiles_keep_the_gap_variable_solver():
    """A periodic profile (1D) is solved as before (its solves are cheap)."""
    x = np.arange(1024) / 1024      # above DENSE_MAX_POINTS: the pk path
    prof = Surface(0.01 * np.cos(2 * np.pi * x), 1.0, periodic=True)
    r = solve_contact(prof, MAT, delta=0.005)
    assert r.tolerance == 1e-9 and 0 < r.area_fraction < 1


def test_load_increment_goes_onto_the_contact_set():
    """The move of the load inside the PK (pk_passes._load_increment): the new total is
    the target, p stays >= 0 and zero off the contact set, and the increment is M 1_S
    (positive inside a patch, largest at its edge)."""
    from roughfe.bem.contact import _cg_preconditioner, _operator
    from roughfe.bem.pk_passes import _load_increment
    op = _operator((64, 64), (1.0, 1.0), 1.0, "spectral")
    M = _cg_preconditioner(op)
    x = np.arange(64) - 31.5
    disc = (x[:, None] ** 2 + x[None, :] ** 2 < 15.0 ** 2).ravel()
    S = np.flatnonzero(disc)
    p = np.where(disc, 1.0, 0.0)
    buf = np.zeros(p.size, np.float32)
    before = p.copy()
    assert _load_increment(p, S, 100.0, lambda v: M(v.reshape(64, 64)).ravel(), buf,
                           before.sum() + 100.0)
    assert p.sum() == pytest.approx(before.sum() + 100.0, rel=1e-12)
    assert p.min() >= 0 and not p[~disc].any() and not buf.any()
    inc = (p - before).reshape(64, 64)
    assert inc[32, 32] >= 0 and inc[32, 17] > inc[32, 32]       # the edge takes more


def test_a_failed_load_path_says_so_and_falls_back(rough, monkeypatch):
    """When the load path does not converge (here: an iteration cap it cannot meet) the
    gap-variable CG solves, and a RuntimeWarning says why."""
    import roughfe.bem.approach as approach
    real = approach.approach_by_load

    def capped(solve, *args):
        return real(lambda pm, t, hook: solve(pm, t * 1e-12, hook), *args)

    monkeypatch.setattr(contact, "approach_by_load", capped)
    delta = 0.4 * (rough.heights.max() - rough.heights.mean())
    with pytest.warns(RuntimeWarning, match="gap variable instead"):
        r = solve_contact(rough, MAT, delta=delta, max_iter=300, compute_stiffness=False)
    assert r.tolerance == 1e-9 and r.residual <= 1e-9


def test_the_elastic_state_of_a_hardness_solve(rough, monkeypatch):
    """With a hardness, a cold periodic approach starts its bounded CG from the elastic
    state at that approach, now solved through load control: the same answer as from
    the gap-variable elastic state (plastic and contact sets, pressures to the
    tolerance)."""
    delta = 0.6 * (rough.heights.max() - rough.heights.mean())
    hp = 0.3 * MAT.E_star * 1.0          # below the elastic peak: points flow
    a = solve_contact(rough, MAT, delta=delta, hardness=hp, compute_stiffness=False)
    _gap_variable(monkeypatch)
    b = solve_contact(rough, MAT, delta=delta, hardness=hp, compute_stiffness=False)
    assert a.plastic_area_fraction > 0.01
    assert np.array_equal(a.contact, b.contact)
    assert np.array_equal(a.pressure >= hp, b.pressure >= hp)
    assert np.abs(a.pressure - b.pressure).max() <= 1e-7 * hp


def test_unloading_off_the_recessed_surface_is_no_contact(rough, monkeypatch):
    """Unloading after plastic flow: the recessed heights h - u_pl first touch the flat at
    Delta_0 = max h - max(h - u_pl) > 0. At or below it there is no contact and no load,
    exactly (as at Delta <= 0 without a recess), with no iteration; it went to load
    control, whose secant halved P for 20000 iterations and then fell back with a
    RuntimeWarning (35 s for a 4-step 256^2 unloading sweep; reviewer, session 25).
    Just above it the load path, started from the recessed heights, agrees with the
    gap-variable CG."""
    import warnings
    h = rough.heights
    hp = 0.3 * MAT.E_star
    top = solve_contact(rough, MAT, delta=0.6 * (h.max() - h.mean()), hardness=hp,
                        compute_stiffness=False)
    up = top.plastic_displacement
    first = float(h.max() - (h - up).max())
    assert top.plastic_area_fraction > 0.01 and first > 0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for d in (0.5 * first, first):
            r = solve_contact(rough, MAT, delta=d, hardness=hp, plastic_displacement=up)
            assert r.nit == 0 and r.n_contact == 0 and r.mean_pressure == 0.0
            assert r.gap.min() >= 0 and np.array_equal(r.plastic_displacement, up)
        assert r.gap.min() <= 1e-12 * float(np.ptp(h))     # at Delta_0 the top touches
        assert r.stiffness > 0                               # ... and responds
        d = first + 0.05 * float(h.std())
        a = solve_contact(rough, MAT, delta=d, hardness=hp, plastic_displacement=up,
                          compute_stiffness=False)
    _gap_variable(monkeypatch)
    b = solve_contact(rough, MAT, delta=d, hardness=hp, plastic_displacement=up,
                      compute_stiffness=False)
    assert 0 < a.area_fraction < 0.1 and a.plastic_area_fraction == 0.0
    assert np.array_equal(a.contact, b.contact)
    assert np.abs(a.pressure - b.pressure).max() <= 1e-7 * a.pressure.max()
