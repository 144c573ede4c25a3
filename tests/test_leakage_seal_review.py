"""A seals engineer's review of ``roughfe leak`` (round 2): what a leak run must say.

* The two-way coupled steps carry a hydraulic aperture (it was None): the gap of the
  parallel plates that leak as much, ``Q = h^3 W dp / (12 mu L)``, checked by solving
  those plates again, along x and along y of a non-square window.
* A one-way run whose fluid pressure is not small beside the contact pressure says that
  it ignores the fluid load (a 5e7 Pa drop through a contact at 1e7 Pa was solved in
  silence, where ``--fsi`` reports lift-off).
* A lift-off step of ``--fsi`` is explained below the table (its row was only dashes).
* One ``--size`` value on a non-square grid makes non-square cells: said.
"""
from argparse import Namespace

import numpy as np
import pytest

from roughfe.cli import main
from roughfe.leakage import reynolds_flow
from roughfe.leakage.fsi_sweep import coupled_leakage_sweep
from roughfe.model import Material
from roughfe.surfaces import Surface
from roughfe.surfaces.io import save_surface
from roughfe.surfaces.spectral import spectral_surface

MAT = Material(1e9, 0.3)
MU = 1e-3


@pytest.fixture(scope="module")
def surface():
    return spectral_surface(32, 1e-4, 0.8, rms_height=1e-6, rng=4)


@pytest.mark.parametrize("direction", ["x", "y"])
def test_coupled_hydraulic_aperture_is_the_gap_of_plates_that_leak_as_much(surface, direction):
    # a non-square window (cells 1 x 2): W / L differs between x and y
    rect = Surface(surface.heights, (1e-4, 2e-4), True)
    p_in, p_out = 2e7, 5e6
    sweep = coupled_leakage_sweep(rect, MAT, [2e7], direction=direction, p_in=p_in,
                                  p_out=p_out, mu=MU)
    rec = sweep.records()[0]
    assert rec["fsi_state"] == "contact" and rec["leak_rate"] > 0
    h = rec["hydraulic_aperture"]
    assert h is not None and rec[f"hydraulic_aperture_{direction}"] == h
    assert 0 < h < rec["mean_gap"] * 10
    # the parallel plates of that gap, solved on the same grid, leak as much
    plates = reynolds_flow(np.full(rect.shape, h), rect.spacing, direction=direction, mu=MU,
                           pressure_drop=p_in - p_out, periodic=True)
    assert plates.leak_rate == pytest.approx(rec["leak_rate"], rel=1e-9, abs=0)
    # and the closed form Q = h^3 W dp / (12 mu L)
    length, width = rect.size if direction == "x" else rect.size[::-1]
    assert h ** 3 * width * (p_in - p_out) / (12 * MU * length) == pytest.approx(
        rec["leak_rate"], rel=1e-12, abs=0)


def test_reversed_coupled_flow_has_the_aperture_of_its_magnitude(surface):
    rec = coupled_leakage_sweep(surface, MAT, [3e7], p_in=0.0, p_out=2e7, mu=MU).records()[0]
    assert rec["leak_rate"] < 0
    expected = np.cbrt(-rec["leak_rate"] * 12 * MU / 2e7)      # square window: L = W
    assert rec["hydraulic_aperture"] == pytest.approx(expected, rel=1e-12, abs=0)


def test_one_way_leak_says_when_the_fluid_carries_the_load(capsys):
    from roughfe.cli.plausibility import check_fluid_load
    args = Namespace(command="leak")
    steps = [{"step": 0, "mean_pressure": 1e7}, {"step": 1, "mean_pressure": 1e8},
             {"step": 2, "mean_pressure": 1e9}]
    check_fluid_load(args, steps, 5e7, 0.0)         # mean fluid pressure 2.5e7 Pa
    err = capsys.readouterr().err
    assert err.count("warning") == 1 and "up to 2.5 x the mean contact pressure" in err
    assert "step 0: the fluid would lift the surfaces apart" in err
    assert "step 1: the fluid carries part of the load" in err and "--fsi" in err
    check_fluid_load(args, steps, 1e5, 0.0)          # 5e4 Pa beside 1e7: quiet
    assert capsys.readouterr().err == ""


def test_leak_command_warns_of_a_drop_above_the_contact_pressure(tmp_path, capsys, surface):
    path = save_surface(surface, tmp_path / "s.npz")
    base = ["leak", str(path), "--pressure", "1e6", "--E", "1e9", "--nu", "0.3",
            "--direction", "x", "--no-figures", "--quiet", "--overwrite",
            "-o", str(tmp_path / "out")]
    assert main(base + ["--pressure-drop", "5e6"]) == 0
    assert "the fluid would lift the surfaces apart" in capsys.readouterr().err
    assert main(base + ["--pressure-drop", "1e3"]) == 0
    assert "fluid" not in capsys.readouterr().err


def test_fsi_lift_off_is_explained_below_the_table(tmp_path, capsys, surface):
    path = save_surface(surface, tmp_path / "s.npz")
    assert main(["leak", str(path), "--fsi", "--direction", "x", "--pressure", "1e7", "3e7",
                 "--inlet-pressure", "4e7", "--outlet-pressure", "0", "--E", "1e9",
                 "--nu", "0.3", "--no-figures", "-o", str(tmp_path / "fsi")]) == 0
    out = capsys.readouterr().out
    assert "lift-off at p_ext = 1e+07 Pa: the fluid pressure alone carries" in out
    assert "3e+07 Pa:" not in out.split("lift-off at", 1)[1].splitlines()[0]


def test_one_size_value_on_a_non_square_grid_is_said(tmp_path, capsys):
    h = np.random.default_rng(0).normal(size=(32, 16)) * 1e-8
    np.save(tmp_path / "h.npy", h)
    assert main(["info", str(tmp_path / "h.npy"), "--size", "1e-5"]) == 0
    err = capsys.readouterr().err
    assert "one --size value on a 32 x 16 grid" in err and "aspect 2" in err
    assert main(["info", str(tmp_path / "h.npy"), "--size", "1e-5", "5e-6"]) == 0
    assert "--size" not in capsys.readouterr().err
    np.save(tmp_path / "sq.npy", h[:16])
    assert main(["info", str(tmp_path / "sq.npy"), "--size", "1e-5"]) == 0
    assert "--size" not in capsys.readouterr().err


def test_leak_rate_scales_as_drop_over_viscosity_as_the_table_says(tmp_path, capsys, surface):
    """The table's note said 'Q is linear in both' (drop and viscosity): Q ~ dp / mu."""
    import json
    path = save_surface(surface, tmp_path / "s.npz")
    q = {}
    for mu, dp in ((1e-3, 1e3), (2e-3, 1e3), (1e-3, 3e3)):
        out = tmp_path / f"o_{mu:g}_{dp:g}"
        assert main(["leak", str(path), "--pressure", "1e6", "--E", "1e9", "--nu", "0.3",
                     "--mu", str(mu), "--pressure-drop", str(dp), "--no-figures",
                     "-o", str(out)]) == 0
        q[mu, dp] = json.loads((out / "results.json").read_text())["steps"][0]["leak_rate_x"]
    assert "Q is proportional to the drop and to 1/mu" in capsys.readouterr().out
    assert q[2e-3, 1e3] == pytest.approx(q[1e-3, 1e3] / 2, rel=1e-8, abs=0)
    assert q[1e-3, 3e3] == pytest.approx(q[1e-3, 1e3] * 3, rel=1e-8, abs=0)


def test_pockets_above_the_external_pressure_are_said(capsys):
    """Incompressible pockets held by the contact reached 6.5 GPa at 1.5 GPa external
    pressure (a 64^2 crop of opd-1) without a word; pockets below p_ext are quiet."""
    from roughfe.cli.plausibility import check_pocket_pressures
    steps = [{"step": 0, "external_pressure": 3e8, "pocket_pressures": [2e7, 1e7]},
             {"step": 1, "external_pressure": 1.5e9,
              "pocket_pressures": [6.5e9, 2e7, 3e9]},
             {"step": 2, "external_pressure": 1e7, "pocket_pressures": []}]
    check_pocket_pressures(Namespace(command="leak", bulk_modulus=None), steps)
    err = capsys.readouterr().err
    assert err.count("warning") == 1 and "step 1: sealed pockets above the external" in err
    assert "(step 1: 2 of 3, up to 6.5e+09 Pa = 4.33 x p_ext)" in err
    assert "--bulk-modulus 2.2e9" in err
    check_pocket_pressures(Namespace(command="leak", bulk_modulus=2.2e9), steps)
    assert "a liquid of bulk modulus 2.2e+09 Pa" in capsys.readouterr().err
    check_pocket_pressures(Namespace(command="leak", bulk_modulus=None), steps[::2])
    assert capsys.readouterr().err == ""
