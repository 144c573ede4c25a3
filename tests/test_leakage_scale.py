"""The Reynolds flow is linear in the pressure drop and in 1/mu (round 2, session 34):
``leak --pressure-drop 1e308`` wrote null leak rates and hydraulic apertures (the
dissipation dp^2 overflowed) with exit 0, ``--mu 1e308`` a null flow imbalance and a
hydraulic aperture of 0. The library now solves at a unit drop and viscosity and scales;
the command refuses drops and viscosities outside a physical range, in one line."""
import numpy as np
import pytest

from roughfe.cli import main
from roughfe.errors import InputError
from roughfe.leakage import reynolds_flow
from roughfe.leakage.reynolds import times_ratio

H, N, DX = 2.0e-6, 16, 1.0e-6          # a parallel-plate gap of 2 um on 16 x 12 cells


def _plates(dp, mu):
    gap = np.full((N, 12), H)
    return reynolds_flow(gap, (DX, DX), direction="x", mu=mu, pressure_drop=dp)


@pytest.mark.parametrize("dp, mu", [(1.0, 1e-3), (1e300, 1e-3), (1.0, 1e250), (1e-250, 1.0)])
def test_parallel_plates_at_any_drop_and_viscosity(dp, mu):
    # exact: Q = h^3 W dp / (12 mu L) (the FV scheme is exact on a uniform gap); h_eff = h
    # whatever dp and mu (was: Q inf at dp 1e300, h_eff 0 at mu 1e250)
    r = _plates(dp, mu)
    width, length = 12 * DX, N * DX
    exact = H**3 * width / (12.0 * length) * (dp / mu)     # dp / mu is finite in each case
    assert r.leak_rate == pytest.approx(exact, rel=1e-9, abs=0)
    assert r.hydraulic_aperture == pytest.approx(H, rel=1e-9, abs=0)
    assert r.flow_imbalance < 1e-9
    # the pressure falls linearly from dp to 0 (cell centres), in Pa
    x = (np.arange(N) + 0.5) / N
    assert np.allclose(r.pressure[:, 3], dp * (1 - x), rtol=1e-9, atol=0)


def test_leak_rate_beyond_the_floats_is_refused_with_the_range():
    with pytest.raises(InputError, match=r"underflows the float range; this gap allows "
                                         r"dp / mu from 4.45e-290 1/s"):
        _plates(1.0, 1e308)
    with pytest.raises(InputError, match=r"overflows the float range"):
        _plates(1e308, 1e-300)


def test_times_ratio_keeps_what_the_naive_product_loses():
    assert times_ratio(1e-20, 1e308, 1e-3) == pytest.approx(1e291, rel=1e-15, abs=0)
    assert times_ratio(3.0, 1e-300, 1e300) == 0.0           # beyond the floats: 0
    assert times_ratio(np.array([2.0, -4.0]), 3.0, 2.0).tolist() == [3.0, -6.0]


@pytest.mark.parametrize("flags, phrases", [
    (["--pressure-drop", "1e308"], ["--pressure-drop", "1e308", "1e-06 Pa to 1e+12 Pa"]),
    (["--pressure-drop", "1e-308"], ["--pressure-drop", "1e-308", "1e-06 Pa to 1e+12 Pa"]),
    (["--inlet-pressure", "1e308", "--outlet-pressure", "0"],
     ["--inlet-pressure", "1e308", "0 Pa to 1e+12 Pa"]),
    (["--mu", "1e308"], ["--mu", "1e308", "1e-09 Pa s to 1e+15 Pa s"]),
])
def test_leak_refuses_a_drop_or_viscosity_outside_the_range(surface32, tmp_path, capsys,
                                                             flags, phrases):
    # was: exit 0 with leak_rate / hydraulic_aperture (drop) or flow_imbalance (mu) null
    capsys.readouterr()
    out = tmp_path / "o"
    assert main(["leak", str(surface32), "--delta", "1e-7", *flags, "--no-figures",
                 "-o", str(out)]) == 2
    lines = [ln for ln in capsys.readouterr().err.splitlines() if ": error: " in ln]
    assert len(lines) == 1
    for phrase in phrases:
        assert phrase in lines[0], (phrase, lines[0])
    assert not out.exists()


def test_leak_rate_scales_with_the_drop_over_the_viscosity(surface32, tmp_path):
    # the same contact at the ends of the ranges: Q(dp, mu) = Q(1, 1) dp / mu on a rough
    # gap, h_eff and the flow imbalance unchanged
    import json
    rec = {}
    for dp, mu in ((1.0, 1.0), (1e12, 1e-9), (1e-6, 1e15)):
        out = tmp_path / f"o{dp:g}"
        assert main(["leak", str(surface32), "--delta", "1e-7", "--pressure-drop", str(dp),
                     "--mu", str(mu), "--direction", "x", "--no-figures",
                     "-o", str(out)]) == 0
        rec[dp, mu] = json.loads((out / "results.json").read_text())["steps"][0]
    base = rec[1.0, 1.0]
    for (dp, mu), s in rec.items():
        assert s["leak_rate"] == pytest.approx(base["leak_rate"] * dp / mu, rel=1e-12, abs=0)
        assert s["hydraulic_aperture"] == base["hydraulic_aperture"] > 0
        # |in - out| / Q ~ 1e-10 from the scaled boundary flows: their rounding, 1e-16 of Q
        assert s["flow_imbalance_x"] == pytest.approx(base["flow_imbalance_x"], rel=1e-4, abs=0)


def test_junction_leak_rate_is_scaled_as_the_reynolds_one():
    # (W/L) u_c^3 dp / (12 mu) at the float limits: was 0.0 in silence at mu 1e308
    from roughfe.leakage import critical_constriction
    g = np.full((N, 12), H)
    c = critical_constriction(g, (DX, DX), direction="x")
    kw = dict(length=N * DX, width=12 * DX)
    exact = 12 / N * H**3 / 12.0
    for dp, mu in ((1.0, 1.0), (1e300, 1e-3), (1.0, 1e250)):
        assert c.leak_rate_junction(mu=mu, pressure_drop=dp, **kw) == pytest.approx(
            exact * (dp / mu), rel=1e-12, abs=0)
    assert c.leak_rate_junction(mu=1.0, pressure_drop=0.0, **kw) == 0.0
    with pytest.raises(InputError, match="underflows"):
        c.leak_rate_junction(mu=1e308, pressure_drop=1.0, **kw)


# -- the same rule beyond reynolds_flow (round 2, session 34, helper "left") ------------------
def test_scaled_fv_solve_at_absolute_pressures_any_drop_and_viscosity():
    # the raw FV solve of the two-way coupling, at absolute pressures: parallel plates are
    # exact, the pressure linear from p_in to p_out; reversed flow and no flow allowed
    from roughfe.leakage.reynolds import scaled_reynolds_fv
    gap = np.full((N, 12), H)
    x = (np.arange(N) + 0.5) / N
    for p_in, p_out, mu in ((2e7, 0.0, 1e-3), (1e300, 0.0, 1e-3), (0.0, 3e300, 1e250),
                            (5.0, 1.0, 1e-300)):
        sol = scaled_reynolds_fv(gap, (DX, DX), mu=mu, p_in=p_in, p_out=p_out)
        exact = times_ratio(H**3 * 12 / (12.0 * N), p_in - p_out, mu)
        assert sol.leak_rate == pytest.approx(exact, rel=1e-9, abs=0)
        assert sol.inlet_flow == pytest.approx(exact, rel=1e-9, abs=0)
        assert np.allclose(sol.pressure[:, 5], p_in + (p_out - p_in) * x, rtol=1e-9, atol=0)
    still = scaled_reynolds_fv(gap, (DX, DX), mu=1e-300, p_in=7.0, p_out=7.0)
    assert still.leak_rate == 0.0 and np.all(still.pressure == 7.0) and not still.flux.any()


@pytest.fixture(scope="module")
def coupled_case():
    from roughfe.model import Material
    from roughfe.surfaces.spectral import spectral_surface
    return spectral_surface(16, 1e-4, 0.8, rms_height=1e-6, rng=4), Material(1e9, 0.3)


def test_coupled_leakage_at_any_viscosity(coupled_case):
    # the fluid pressure of the two-way coupling does not depend on mu, its leak rates are
    # 1/mu (was: mu 1e250 a leak rate of 0.0 and a fluid load fraction of 0.042 instead of
    # 0.468 from underflowed transmissibilities, in silence; mu 1e-300 a NaN Reynolds solve,
    # a NoConvergenceError); a leak rate beyond the floats is an InputError
    from roughfe.leakage.fsi import coupled_leakage
    surface, mat = coupled_case
    runs = {mu: coupled_leakage(surface, mat, 3e7, p_in=2e7, p_out=0.0, mu=mu)
            for mu in (1e-3, 1e250, 1e-300)}
    base = runs[1e-3]
    assert base.state == "contact" and base.leak_rate > 0
    for mu, r in runs.items():
        assert r.fluid_load_fraction == pytest.approx(base.fluid_load_fraction, rel=1e-12,
                                                      abs=0)
        np.testing.assert_allclose(r.fluid_pressure, base.fluid_pressure, rtol=1e-12, atol=0)
        assert r.leak_rate == pytest.approx(times_ratio(base.leak_rate, 1e-3, mu), rel=1e-12,
                                            abs=0)
    with pytest.raises(InputError, match=r"mu = 1e\+300 Pa s: the leak rate .* underflows"):
        coupled_leakage(surface, mat, 3e7, p_in=2e7, p_out=0.0, mu=1e300)


def test_persson_junction_leak_rate_at_any_drop_and_viscosity():
    # Eq. (5) Q = (Ly/Lx) u_c^3 / 12 dp / eta: dp 1e300 Pa with eta 1e-20 Pa s was inf (the
    # product dp / eta overflowed first), dp 1e-308 Pa 0.0 m^3/s (underflowed), in silence
    from roughfe.surfaces.spectral import spectral_surface
    from roughfe.theory import critical_junction
    s = spectral_surface(64, 1e-3, 0.8, rms_height=1e-6, rng=3)
    unit = critical_junction(s, 1e9, 1e6, 1.0, 1.0)
    assert not unit.sealed and unit.leak_rate == pytest.approx(unit.u_c**3 / 12, rel=1e-14,
                                                               abs=0)
    far = critical_junction(s, 1e9, 1e6, 1e300, 1e-20)
    assert far.u_c == unit.u_c
    assert far.leak_rate == pytest.approx(times_ratio(unit.leak_rate, 1e300, 1e-20),
                                          rel=1e-14, abs=0)
    assert np.isfinite(far.leak_rate) and far.leak_rate > 1e250
    with pytest.raises(InputError, match=r"underflows the float range; this gap allows "
                                         r"dp / mu from"):
        critical_junction(s, 1e9, 1e6, 1e-308, 1e-3)


def test_finite_volume_leak_rate_shortcut_is_scaled():
    # the public shortcut solved at the given mu: 0.0 at mu 1e250, inf at dp 1e300
    from roughfe.leakage import finite_volume_leak_rate
    gap = np.full((N, 12), H)
    for dp, mu in ((1.0, 1.0), (1e300, 1e-3), (1.0, 1e250)):
        assert finite_volume_leak_rate(gap, (DX, DX), mu=mu, pressure_drop=dp) == \
            pytest.approx(H**3 * 12 / (12.0 * N) * (dp / mu), rel=1e-9, abs=0)


def test_channel_flow_flux_at_any_viscosity():
    # exact on a uniform channel: q = g^3 dp / (12 mu L) (m^2/s); 12 mu R overflowed at mu
    # 1e300 on a 10 nm gap: a flux of 0.0 in silence (the true 8e-311 is below the floats)
    from roughfe.leakage.channel import channel_flow
    g, n, dx = 1e-8, 11, 1e-6
    for dp, mu in ((1.0, 1e-3), (1e300, 1e-3), (1e-20, 1e-300)):
        f = channel_flow(np.full(n, g), dx, p_in=dp, p_out=0.0, mu=mu)
        assert f.leak_rate == pytest.approx(times_ratio(g**3 / (12 * (n - 1) * dx), dp, mu),
                                            rel=1e-12, abs=0)
    with pytest.raises(InputError, match="underflows the float range"):
        channel_flow(np.full(n, g), dx, p_in=1.0, p_out=0.0, mu=1e300)
