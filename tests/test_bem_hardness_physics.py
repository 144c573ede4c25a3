"""The perfectly plastic interface (0 <= p <= H_p) against physics it must obey: a capped
Hertz contact against an independent axisymmetric reference, the energy balance of a
plastic loading, the elastic unloading of the recessed surface, reloading, the residual
deformation, path independence of a monotone loading and the agreement of load and
displacement control (round 2, session 33 review)."""
import numpy as np
import pytest
import scipy.optimize
from scipy.special import ellipe, ellipk

from roughfe.bem import Material, contact_sweep, solve_contact
from roughfe.bem.contact import YIELD_RTOL
from roughfe.reference import hertz_sphere
from roughfe.surfaces import Surface
from roughfe.surfaces.spectral import spectral_surface

MAT = Material(1e9, 0.3)
UNIT = Material(1.0, 0.0)


def rough(n=64, seed=1, periodic=True):
    """Self-affine surface, unit rms gradient, L = 1 m (E* = 1 Pa: p in units of E* gbar)."""
    s = spectral_surface(n, 1.0, 0.8, rms_slope=1.0, rng=seed)
    return s if periodic else Surface(s.heights, s.size, periodic=False)


# -- an independent reference: axisymmetric rings --------------------------------------------
def _disc_displacement(r, b, e_star):
    """Surface displacement (m) at radius r under a unit pressure on a disc of radius b
    (Johnson, Contact Mechanics, Eq. 3.39): 4 b E(r^2/b^2) / (pi E*) inside, 4 r [E(m) -
    (1 - m) K(m)] / (pi E*) with m = b^2/r^2 outside (E, K of parameter m)."""
    r, b = np.broadcast_arrays(np.asarray(r, float), np.asarray(b, float))
    out = np.zeros(r.shape)
    inside = r < b
    out[inside] = 4 * b[inside] / (np.pi * e_star) * ellipe((r[inside] / b[inside]) ** 2)
    outside = ~inside & (b > 0)
    m = (b[outside] / r[outside]) ** 2
    out[outside] = 4 * r[outside] / (np.pi * e_star) * (ellipe(m) - (1 - m) * ellipk(m))
    return out


def capped_hertz_rings(radius, e_star, load, hardness, n=200):
    """A paraboloid z = r^2 / 2R pressed on a perfectly plastic interface with ``load``
    (N): piecewise-constant pressure on ``n`` rings, exact ring influences (differences of
    the disc displacement) collocated at the ring middles, the three-set active set
    (off / elastic / at H_p) in displacement control and Brent's method on the approach.
    Returns (ring middles, pressure, approach, plastic displacement at the middles, outer
    edges)."""
    a_h = (3 * load * radius / (4 * e_star)) ** (1 / 3)
    r_max = 1.5 * max(a_h, np.sqrt(load / (np.pi * hardness)))
    edges = np.linspace(0.0, r_max, n + 1)
    mid = 0.5 * (edges[1:] + edges[:-1])
    D = _disc_displacement(mid[:, None], edges[None, :], e_star)
    A = D[:, 1:] - D[:, :-1]
    area = np.pi * np.diff(edges ** 2)
    z = mid ** 2 / (2 * radius)
    keep = {}

    def load_at(delta):
        state = keep.get("state", (z < delta).astype(int))   # 0 off, 1 elastic, 2 at H_p
        for _ in range(4 * n):
            C, S = state == 1, state == 2
            p = np.where(S, hardness, 0.0)
            if C.any():
                p[C] = np.linalg.solve(A[np.ix_(C, C)], delta - z[C] - A[np.ix_(C, S)] @ p[S])
            w = A @ p + z - delta
            tol = 1e-14 * delta
            new = state.copy()
            new[C & (p < 0)], new[C & (p > hardness)] = 0, 2
            new[(state == 0) & (w < -tol)], new[S & (w > tol)] = 1, 1
            if np.array_equal(new, state):
                break
            state = new
        keep.update(state=state, p=p, w=w)
        return float(p @ area) - load

    delta = scipy.optimize.brentq(load_at, 1e-3 * a_h ** 2 / radius, 20 * a_h ** 2 / radius,
                                  xtol=1e-18, rtol=1e-13)
    load_at(delta)
    plastic = np.where(keep["state"] == 2, -keep["w"], 0.0)
    return mid, keep["p"], delta, plastic, edges[1:]


def _sphere(n, width, radius, periodic=False):
    x = (np.arange(n) - n // 2) * width / n
    X, Y = np.meshgrid(x, x, indexing="ij")
    return Surface(-(X ** 2 + Y ** 2) / (2 * radius), width, periodic=periodic), np.hypot(X, Y)


def test_the_ring_reference_is_hertz_without_a_cap():
    R, P = 1e-2, 0.1
    ref = hertz_sphere(R, MAT.E_star, load=P)
    mid, p, delta, plastic, outer = capped_hertz_rings(R, MAT.E_star, P, 1e6 * ref.peak_pressure)
    assert not plastic.any()
    assert delta == pytest.approx(ref.approach, rel=1e-4, abs=0)            # measured 7e-6
    assert p[0] == pytest.approx(ref.peak_pressure, rel=1e-4, abs=0)        # measured 1.4e-6
    assert outer[p > 0].max() == pytest.approx(ref.contact_radius, abs=outer[0])


@pytest.mark.parametrize("fraction", [0.8, 0.5])
def test_capped_hertz_against_the_axisymmetric_reference(fraction):
    # Hertz capped at H_p: a plastic disc at p = H_p, an elastic annulus, a contact wider
    # than Hertz's carrying the same load. Measured (64^2 love kernel / 200 rings):
    # approach 1e-4 / 7e-4, contact area 2.5 / 2.3 %, plastic area 0.4 / 1.4 %, central
    # plastic displacement 0.03 / 0.2 %, loading stiffness 0.6 / 1.1 % (ring reference's
    # dP/dDelta by central differences)
    R, P = 1e-2, 0.1
    ref = hertz_sphere(R, MAT.E_star, load=P)
    hp = fraction * ref.peak_pressure
    mid, pr, delta, plastic, outer = capped_hertz_rings(R, MAT.E_star, P, hp)
    a_ref, c_ref = outer[pr > 0].max(), outer[pr >= hp].max()
    assert a_ref > 1.01 * ref.contact_radius and 0 < c_ref < a_ref
    n = 64
    L = 4 * max(ref.contact_radius, np.sqrt(P / (np.pi * hp)))
    surf, r = _sphere(n, L, R)
    b = solve_contact(surf, MAT, mean_pressure=P / L ** 2, hardness=hp)
    assert b.solver == "pk" and b.pressure.max() == hp
    assert b.delta == pytest.approx(delta, rel=2e-3, abs=0)
    assert b.contact_area == pytest.approx(np.pi * a_ref ** 2, rel=0.04, abs=0)
    # wider than the elastic contact on the same grid, which carries the load on less
    el = solve_contact(surf, MAT, mean_pressure=P / L ** 2)
    assert b.contact_area > 1.02 * el.contact_area and el.pressure.max() > hp
    assert b.plastic_area_fraction * L ** 2 == pytest.approx(np.pi * c_ref ** 2, rel=0.03, abs=0)
    assert b.plastic_displacement.max() == pytest.approx(plastic[0], rel=5e-3, abs=0)
    # inside the plastic disc the pressure is the cap, exactly
    assert np.all(b.pressure[r < 0.9 * c_ref] == hp)
    eps = 1e-3
    d_lo = capped_hertz_rings(R, MAT.E_star, P * (1 - eps), hp)[2]
    d_hi = capped_hertz_rings(R, MAT.E_star, P * (1 + eps), hp)[2]
    assert b.stiffness * L ** 2 == pytest.approx(2 * eps * P / (d_hi - d_lo), rel=0.02, abs=0)
    # the elastic loading stiffness 2 E* a is stiffer: the plastic disc does not respond
    assert b.stiffness * L ** 2 < 0.98 * ref.stiffness


# -- bounds, energy, path ------------------------------------------------------------------
def _check_bounds(r, hp, prior=None):
    """p <= H_p exactly; new plastic displacement (over ``prior``) only at the points at
    yield, and none lost."""
    assert r.pressure.max() <= hp and r.pressure.min() >= 0
    yielded = r.contact & (r.pressure >= hp * (1 - YIELD_RTOL))
    new = r.plastic_displacement - (0.0 if prior is None else prior)
    assert new.min() >= 0 and not new[~yielded].any()


def test_energy_balance_of_a_plastic_loading():
    # The work of the imposed approach is the stored elastic energy plus the plastic
    # dissipation: int P dDelta A = 1/2 sum p u dA + H_p sum u_pl dA (the interface flows
    # at p = H_p). Trapezoidal work over 20 / 40 steps: measured 3.1e-3 / 7.1e-4 off
    # (second order), dissipation 78 % of the work
    surf, hp = rough(64), 0.1
    top = 0.6 * float(surf.heights.max() - surf.heights.mean())
    errors, states = [], []
    for m in (20, 40):
        deltas = np.linspace(0.0, top, m + 1)
        loads, plastic = [0.0], None
        for d in deltas[1:]:
            r = solve_contact(surf, UNIT, delta=d, hardness=hp, compute_stiffness=False,
                              plastic_displacement=plastic)
            _check_bounds(r, hp, plastic)
            plastic = r.plastic_displacement
            loads.append(r.mean_pressure)
        work = np.trapz(loads, deltas) * surf.nominal_area
        stored = 0.5 * float(np.sum(r.pressure * r.displacement)) * surf.cell_area
        dissipated = hp * float(plastic.sum()) * surf.cell_area
        assert 0 < stored < work and dissipated > 0.5 * work
        errors.append((work - stored - dissipated) / work)
        states.append((stored, dissipated))
    assert 0 < errors[1] < errors[0] / 3 and errors[1] < 1.5e-3
    # the end state does not depend on the steps taken to it (no local unloading here)
    assert states[0] == pytest.approx(states[1], rel=1e-8, abs=0)


def test_monotone_loading_is_the_single_solve_at_its_end():
    # On a monotone load path no point that flowed unloads here, so the incremental
    # (sweep) answer is the one-shot solve at the last load: measured 2.7e-8 H_p in
    # pressure, 8e-11 of the largest plastic displacement (128^2, 20 steps)
    surf, hp = rough(64), 0.1
    sw = contact_sweep(surf, UNIT, pressures=np.linspace(0.004, 0.04, 10), hardness=hp,
                       compute_stiffness=False)
    flowed = np.zeros(surf.shape, bool)
    for r in sw.results:
        at_cap = r.pressure >= hp * (1 - YIELD_RTOL)
        assert not (flowed & ~at_cap).any()
        flowed |= at_cap
    one = solve_contact(surf, UNIT, mean_pressure=0.04, hardness=hp)
    last = sw.results[-1]
    assert np.max(np.abs(last.pressure - one.pressure)) <= 1e-6 * hp
    assert np.max(np.abs(last.plastic_displacement - one.plastic_displacement)) <= \
        1e-8 * one.plastic_displacement.max()
    assert last.plastic_area_fraction == one.plastic_area_fraction


# -- unloading, reloading, residual deformation --------------------------------------------
@pytest.mark.parametrize("periodic", [True, False])
def test_unloading_is_the_elastic_contact_of_the_recessed_surface(periodic):
    surf, hp = rough(64, 2, periodic), 0.1
    h = surf.heights
    top = solve_contact(surf, UNIT, mean_pressure=0.03, hardness=hp)
    up = top.plastic_displacement
    recessed = Surface(h - up, surf.size, periodic=periodic)
    for load in (0.015, 0.03 * (1 - 1e-4)):
        down = solve_contact(surf, UNIT, mean_pressure=load, hardness=hp,
                             plastic_displacement=up)
        _check_bounds(down, hp, up)
        el = solve_contact(recessed, UNIT, mean_pressure=load, solver="pk")
        assert down.plastic_area_fraction == 0.0 and np.array_equal(down.contact, el.contact)
        assert np.max(np.abs(down.pressure - el.pressure)) <= 1e-6 * hp
        assert down.stiffness == pytest.approx(el.stiffness, rel=1e-6, abs=0)
        # the approach is counted from the first contact of the original surface
        assert down.delta == pytest.approx(el.delta + h.max() - (h - up).max(), rel=1e-7, abs=0)
    # just below the peak the yielded points unload elastically: stiffer than the
    # loading tangent at the peak, where they flow and do not respond
    assert down.stiffness > 1.1 * top.stiffness
    assert np.array_equal(down.contact, top.contact)


def test_reloading_to_the_peak_approach_retraces_the_unloading():
    # periodic displacement control (the bounded CG): unload, reload to the peak approach:
    # the peak state again and no new plastic displacement
    surf, hp = rough(64, 3), 0.1
    top_delta = 0.5 * float(surf.heights.max() - surf.heights.mean())
    top = solve_contact(surf, UNIT, delta=top_delta, hardness=hp)
    up = top.plastic_displacement
    assert top.plastic_area_fraction > 0
    down = solve_contact(surf, UNIT, delta=0.5 * top_delta, hardness=hp,
                         plastic_displacement=up)
    assert down.plastic_area_fraction == 0 and down.mean_pressure < top.mean_pressure
    again = solve_contact(surf, UNIT, delta=top_delta, hardness=hp, plastic_displacement=up)
    _check_bounds(again, hp, up)
    assert again.mean_pressure == pytest.approx(top.mean_pressure, rel=1e-7, abs=0)
    assert np.max(np.abs(again.pressure - top.pressure)) <= 1e-6 * hp
    assert np.max(again.plastic_displacement - up) <= 1e-7 * up.max()


def test_residual_deformation_after_full_unloading_is_the_plastic_displacement():
    # Sphere (love kernel): below the recessed surface's first contact nothing presses,
    # the elastic displacement is 0 and the gap is the rigid one plus u_pl: the permanent
    # dent. Just beyond that approach the unloading curve has contact again.
    R, P = 1e-2, 0.1
    ref = hertz_sphere(R, MAT.E_star, load=P)
    hp = 0.5 * ref.peak_pressure
    L = 4 * np.sqrt(P / (np.pi * hp))
    surf, _ = _sphere(48, L, R)
    h = surf.heights
    top = solve_contact(surf, MAT, mean_pressure=P / L ** 2, hardness=hp)
    up = top.plastic_displacement
    first = float(h.max() - (h - up).max())          # the residual approach
    assert 0 < first < top.delta
    off = solve_contact(surf, MAT, delta=0.5 * first, hardness=hp, plastic_displacement=up)
    assert off.n_contact == 0 and not off.displacement.any() and off.stiffness == 0.0
    np.testing.assert_allclose(off.gap, up + h.max() - h - 0.5 * first, rtol=0,
                               atol=1e-15 * float(np.ptp(h)))
    on = solve_contact(surf, MAT, delta=first + 1e-3 * (top.delta - first), hardness=hp,
                       plastic_displacement=up)
    assert on.n_contact > 0 and 0 < on.mean_pressure < 1e-2 * top.mean_pressure
    assert on.plastic_area_fraction == 0.0 and np.array_equal(on.plastic_displacement, up)


# -- load and displacement control ---------------------------------------------------------
@pytest.mark.parametrize("periodic, frac, hp", [(False, 0.4, 0.3), (False, 0.4, 0.1),
                                                 (True, 0.3, 0.1), (True, 1.2, 0.1)])
def test_displacement_and_load_control_agree(periodic, frac, hp):
    # the same state reached both ways reads the same: the plastic area and the stiffness
    # (the loading tangent of the points below the cap) included. Measured: Delta 8e-12,
    # pressures 7e-9 H_p, identical plastic area and K (non-periodic; the approach as a
    # fraction of max h - min h); periodic (a fraction of max h - mean h, 1.2: beyond the
    # elastic full contact, A* 0.76 of which 0.756 plastic) identical plastic area and K
    surf = rough(64, 2 if not periodic else 1, periodic=periodic)
    h = surf.heights
    d = frac * float(np.ptp(h) if not periodic else h.max() - h.mean())
    a = solve_contact(surf, UNIT, delta=d, hardness=hp)
    b = solve_contact(surf, UNIT, mean_pressure=a.mean_pressure, hardness=hp)
    _check_bounds(a, hp)
    _check_bounds(b, hp)
    assert b.delta == pytest.approx(d, rel=1e-7, abs=0)
    assert np.max(np.abs(a.pressure - b.pressure)) <= 1e-6 * hp
    assert a.plastic_area_fraction == b.plastic_area_fraction > 0
    assert a.stiffness == pytest.approx(b.stiffness, rel=1e-6, abs=0)


def test_periodic_and_non_periodic_kernels_see_the_same_flow():
    # an isolated capped sphere (a = L/8): the same contact and plastic area on both
    # kernels (measured 128^2: areas equal, plastic within 0.8 %); the periodic K is
    # larger by the images' compliance, as without a cap (1.44 elastic, 1.36-1.40 capped)
    R, P = 1e-2, 0.1
    ref = hertz_sphere(R, MAT.E_star, load=P)
    L = 8 * ref.contact_radius
    ks = []
    for hp in (None, 0.5 * ref.peak_pressure):
        per, npr = (solve_contact(_sphere(64, L, R, periodic)[0], MAT, mean_pressure=P / L ** 2,
                                  hardness=hp) for periodic in (True, False))
        assert per.kernel == "spectral" and npr.kernel == "love"
        assert per.n_contact == npr.n_contact
        if hp is not None:
            assert per.plastic_area_fraction == pytest.approx(npr.plastic_area_fraction,
                                                              rel=0.02, abs=0)
        ks.append(per.stiffness / npr.stiffness)
    assert 1.2 < ks[1] < ks[0] < 1.6


def test_the_fem_has_no_hardness():
    # the FEM is the elastic cross-check: a hardness there is refused by name
    from roughfe.model import Loading
    from roughfe.response import response
    from roughfe.surfaces.spectral import spectral_profile
    prof = spectral_profile(64, 1e-4, 0.8, rms_height=1e-6, rng=1)
    with pytest.raises(ValueError, match="hardness"):
        response(prof, MAT, Loading(pressures=[1e6]), method="fem", hardness=1e7)


def test_contact_cli_refuses_a_hardness_with_the_fem(tmp_path, capsys):
    from roughfe.cli import main
    from roughfe.surfaces.io import save_surface
    from roughfe.surfaces.spectral import spectral_profile
    path = save_surface(spectral_profile(64, 1e-4, 0.8, rms_height=1e-6, rng=1),
                        tmp_path / "p.npz")
    assert main(["contact", str(path), "--method", "fem", "--pressure", "1e6",
                 "--hardness", "1e7", "-o", str(tmp_path / "o")]) == 2
    assert "--hardness" in capsys.readouterr().err
