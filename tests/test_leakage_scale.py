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


@pytest.fixture
def surface32(tmp_path):
    path = tmp_path / "s32.npz"
    assert main(["generate", "spectral", "--n", "32", "--seed", "1", "--no-figures",
                 "-o", str(path)]) == 0
    return path


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
