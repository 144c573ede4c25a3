"""`roughfe contact`: the files it writes and what they contain."""
import json

import numpy as np
import pytest

from roughfe.cli import main
from roughfe.surfaces import Surface
from roughfe.surfaces.io import save_surface


def _bump(n=24, periodic=False):
    x = (np.arange(n) - n // 2) * 1e-6
    X, Y = np.meshgrid(x, x, indexing="ij")
    return Surface(-(X ** 2 + Y ** 2) / 2e-3 + 1e-8 * np.cos(X / 3e-6), n * 1e-6,
                   periodic=periodic, metadata={"generator": "test bump"})


@pytest.mark.slow
def test_contact_cli_writes_results_fields_and_figures(tmp_path):
    path = save_surface(_bump(), tmp_path / "bump.npz")
    out = tmp_path / "out"
    assert main(["contact", str(path), "--E", "1e9", "--nu", "0.3", "--steps", "4",
                 "-o", str(out)]) == 0
    doc = json.loads((out / "results.json").read_text())
    assert doc["inputs"]["kernel"] == "love" and doc["inputs"]["E_star"] == pytest.approx(
        1e9 / 0.91)
    steps = doc["steps"]
    assert len(steps) == 4
    assert set(steps[0]) == {"delta", "load", "mean_pressure", "area_fraction", "contact_area",
                             "n_contact",
                             "stiffness", "stiffness_fd", "mean_gap", "mean_plane_separation",
                             "free_volume", "free_volume_star", "iterations", "residual",
                             "patch_width", "persson_area_fraction", "persson_mean_gap", "persson_stiffness"}
    # every dimensional record key has its unit (contact_area had none: read as a fraction)
    units = doc["derived"]["units"]
    assert units["contact_area"].startswith("m^2") and units["mean_gap"] == "m"
    # the last approach is the peak-to-valley height, loads increase
    assert steps[-1]["delta"] == pytest.approx(np.ptp(_bump().heights), rel=1e-6, abs=0)
    assert all(a["load"] < b["load"] for a, b in zip(steps, steps[1:]))
    h5py = pytest.importorskip("h5py")
    with h5py.File(out / "fields.h5", "r") as f:
        assert f["pressure"].shape == (4, 24, 24) and f["gap"].shape == (4, 24, 24)
        assert json.loads(f.attrs["dimensions"]) == ["frame", "x", "y"]
        # the stored pressure integrates to the recorded load
        assert f["pressure"][2].mean() * 24e-6 ** 2 == pytest.approx(steps[2]["load"], rel=1e-12,
                                                                     abs=0)
        assert np.all(f["gap"][...] >= 0)
        # self-contained: each frame's response and the material beside the fields
        np.testing.assert_array_equal(f["area_fraction"][...],
                                      [s["area_fraction"] for s in steps])
        np.testing.assert_array_equal(f["area_fraction"][...],
                                      f["contact"][...].mean(axis=(1, 2)))
        np.testing.assert_array_equal(f["mean_gap"][...], [s["mean_gap"] for s in steps])
        assert f["stiffness"].attrs["unit"] == "Pa/m" and f.attrs["e_star_Pa"] > 0
    assert (out / "contact_area_stiffness.png").stat().st_size > 0
    assert (out / "contact_render.png").stat().st_size > 0


@pytest.mark.slow
def test_contact_cli_draws_persson_beside_the_bem(tmp_path):
    # a self-affine periodic surface: BEM and Persson's theory side by side in results.json
    from roughfe.surfaces.spectral import spectral_surface
    from roughfe.surfaces.stats import rms_slope
    # 128^2, roll-off at 2 dq, cut-off at 16 dq (8 points per shortest wavelength: the
    # contact patches are resolved; at the Nyquist cut-off the BEM area doubles)
    dq = 2 * np.pi / 1e-4
    s = spectral_surface(128, 1e-4, 0.8, rms_height=1e-7, q_roll=2 * dq, q_short=16 * dq, rng=2)
    path = save_surface(s, tmp_path / "sa.npz")
    out = tmp_path / "sa"
    e_star = 1e9 / 0.91
    p = np.array([0.05, 0.1, 0.3]) * e_star * rms_slope(s)
    assert main(["contact", str(path), "--E", "1e9", "--nu", "0.3", "--pressure",
                 *map(str, p), "-o", str(out)]) == 0
    doc = json.loads((out / "results.json").read_text())
    steps = doc["steps"]
    assert doc["derived"]["persson"]["gamma"] == 0.45
    for st in steps:
        # measured 1.17-1.32: the BEM kappa ~ 2 against Persson's sqrt(8/pi) = 1.6 (known:
        # Hyun et al. 2004, Prodanov et al. 2014), closing towards full contact
        assert 1.05 < st["area_fraction"] / st["persson_area_fraction"] < 1.4
        # mean gap: measured 0.90-1.03 (docs/theory/07_adhesion_persson.md)
        assert 0.8 < st["mean_gap"] / st["persson_mean_gap"] < 1.2
    assert (out / "contact_area_stiffness.png").stat().st_size > 0


def test_contact_cli_pressure_control_profile(tmp_path):
    x = np.arange(256) * 1e-6
    prof = Surface(1e-6 * np.cos(2 * np.pi * x / 256e-6), 256e-6, periodic=True)
    path = save_surface(prof, tmp_path / "sine.npz")
    out = tmp_path / "o"
    assert main(["contact", str(path), "--E", "1e9", "--nu", "0", "--pressure", "1e6", "2e6",
                 "-o", str(out), "--no-figures"]) == 0
    steps = json.loads((out / "results.json").read_text())["steps"]
    assert [s["mean_pressure"] for s in steps] == pytest.approx([1e6, 2e6], rel=1e-12)


def test_contact_cli_bad_input_is_reported(tmp_path, capsys):
    path = save_surface(_bump(), tmp_path / "bump.npz")
    assert main(["contact", str(path), "--E", "-1", "--nu", "0.3", "-o",
                 str(tmp_path / "x")]) == 2
    assert "--E: must be a Young's modulus from 0.001 Pa to 1e+15 Pa" in capsys.readouterr().err
    # a relative tolerance of 1 or more asks nothing of the solver: refused
    for tol in ("2", "1", "0"):
        assert main(["contact", str(path), "--E", "1e9", "--nu", "0.3", "--tol", tol,
                     "-o", str(tmp_path / "x")]) == 2
        assert f"--tol: must be a number in (0, 1), got '{tol}'" in capsys.readouterr().err


def _sphere_file(tmp_path, n=40, length=0.8):
    from roughfe.surfaces.shapes import sphere_cap
    return save_surface(sphere_cap(n, length, 1.0), tmp_path / "sphere.npz")


@pytest.mark.slow
def test_contact_cli_adhesion_unload_pull_off(tmp_path):
    # R = 1 m sphere on E* = 1 Pa, Maugis-Dugdale w = 2.83e-4 J/m^2, h0 = 0.0486 m
    # (lambda = 0.1: Maugis' pull-off -1.95 pi w R, 2.5 % from DMT's -2 pi w R)
    path = _sphere_file(tmp_path)
    out = tmp_path / "adh"
    w = 2.83e-4
    assert main(["contact", str(path), "--E", "0.91", "--nu", "0.3", "--adhesion", "md",
                 "--work-of-adhesion", str(w), "--range", "0.0486", "--smoothing", "0.2",
                 "--delta", "-0.002", "0.004", "--unload", "-o", str(out)]) == 0
    doc = json.loads((out / "results.json").read_text())
    assert doc["inputs"]["adhesion"]["law"] == "md"
    assert doc["inputs"]["adhesion"]["smoothing"] == 0.2
    assert doc["inputs"]["tol"] == 1e-5
    steps = doc["steps"]
    assert [s["unloading"] for s in steps[:2]] == [False, False]
    assert all(s["unloading"] for s in steps[2:])
    pull = doc["derived"]["pull_off_force"]
    assert pull == min(s["load"] for s in steps if s["unloading"])
    # a coarse 40^2 grid with 0.006 m steps: within 5 % of Maugis / DMT
    assert pull / (np.pi * w) == pytest.approx(-1.95, rel=5e-2)
    assert doc["derived"]["detached"] is True
    assert all("adhesive_area_fraction" in s for s in steps)
    assert (out / "adhesion_load_approach.png").stat().st_size > 0
    # a sphere is one smooth asperity (roughfe.theory.asperity): the random-roughness
    # criterion of Pastewka-Robbins is not evaluated (it was, until round 2, session 32),
    # Maugis' sphere is given instead, and the BEM's pull-off is beside it
    st = doc["derived"]["stickiness"]
    assert st["evaluated"] is False and "asperity" in st["why"]
    maugis = doc["derived"]["maugis_sphere"]
    assert maugis["lambda"] == pytest.approx(0.1, rel=0.01, abs=0)
    assert pull == pytest.approx(maugis["pull_off_force"], rel=5e-2, abs=0)
    assert doc["derived"]["persson"]["single_asperity"]["shape"] == "sphere"


def test_contact_cli_gives_no_window_note_on_one_smooth_asperity(tmp_path, capsys):
    """Round 2, session 32: the note that K of a non-periodic window is mostly its
    flat-punch bulk stiffness, "not a property of the roughness", was printed for a
    sphere too, whose half-space deflection is Hertz's own: the BEM's K there is Hertz's
    2 E* a / A_n (within 2 %). A rough window keeps it (test_bem_window)."""
    path = _sphere_file(tmp_path, n=32, length=0.21)
    out = tmp_path / "sph"
    assert main(["contact", str(path), "--E", "1", "--nu", "0", "--delta", "1e-3", "4e-3",
                 "--no-figures", "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert "bulk stiffness of the measured window" not in err and "flat punch" not in err
    doc = json.loads((out / "results.json").read_text())
    assert doc["derived"]["stiffness_compliance"][-1] > 0.5     # the note's threshold
    last = doc["steps"][-1]
    assert last["stiffness"] == pytest.approx(last["hertz_stiffness"], rel=0.03, abs=0)


def test_contact_cli_takes_approaches_apart_with_adhesion_only(tmp_path, capsys):
    # Loading takes negative approaches since round 2, session 32 (response(...,
    # adhesion=law) can start apart); without adhesion they are refused in the flags' words
    path = _sphere_file(tmp_path, n=8)
    assert main(["contact", str(path), "--E", "1", "--delta", "-1e-3", "1e-3",
                 "-o", str(tmp_path / "x")]) == 2
    assert ("--delta[0] = -0.001 m is a negative approach (the surfaces apart): meaningful "
            "with adhesion only (--adhesion)") in capsys.readouterr().err


@pytest.mark.parametrize("extra, message", [
    (["--adhesion", "md"], "needs --work-of-adhesion"),
    (["--work-of-adhesion", "0.1"], "need --adhesion"),
    (["--adhesion", "exp", "--work-of-adhesion", "0.1", "--range", "1e-9", "--pressure",
      "1e3"], "displacement control"),
    (["--adhesion", "exp", "--work-of-adhesion", "0.1", "--range", "1e-9",
      "--coarse-correction", "off"], "--coarse-correction does not apply with --adhesion"),
    (["--adhesion", "exp", "--work-of-adhesion", "0.1", "--range", "1e-9", "--smoothing",
      "0.5"], "--smoothing is the ramp of the Maugis-Dugdale law"),
    (["--adhesion", "md", "--work-of-adhesion", "0.1", "--range", "1e-9", "--smoothing",
      "1.5"], "--smoothing must lie in [0, 1), got 1.5"),
    (["--smoothing", "0.5"], "need --adhesion"),
    (["--adhesion", "md", "--work-of-adhesion", "0.1", "--range", "1e-9", "--delta", "3e-8",
      "2e-8", "--unload"], "--delta (the approaches of the --adhesion loading branch, m) "
                           "must be strictly increasing"),
])
def test_contact_cli_adhesion_bad_input(tmp_path, capsys, extra, message):
    path = _sphere_file(tmp_path, n=8)
    assert main(["contact", str(path), "--E", "1e9", "--nu", "0.3", *extra,
                 "-o", str(tmp_path / "x")]) == 2
    assert message in capsys.readouterr().err


@pytest.mark.parametrize("value", ["0", "-1", "nan", "inf"])
def test_contact_cli_adhesion_parameters_must_be_positive_and_finite(tmp_path, capsys, value):
    path = _sphere_file(tmp_path, n=8)
    assert main(["contact", str(path), "--adhesion", "md", "--work-of-adhesion", value,
                 "--range", "1e-9", "-o", str(tmp_path / "x")]) == 2
    assert "--work-of-adhesion" in capsys.readouterr().err
def test_contact_cli_hardness_load_unload_cycle(tmp_path, capsys):
    # a Westergaard sinusoid whose crest flows: p* = pi E* g / lambda = 12.3 MPa, the
    # elastic peak at 3 MPa mean is ~10.8 MPa > H_p = 8 MPa
    x = np.arange(256) * 1e-6
    prof = Surface(1e-6 * np.cos(2 * np.pi * x / 256e-6), 256e-6, periodic=True)
    path = save_surface(prof, tmp_path / "sine.npz")
    out = tmp_path / "o"
    assert main(["contact", str(path), "--E", "1e9", "--nu", "0", "--pressure", "1e6", "3e6",
                 "--hardness", "8e6", "--unload", "-o", str(out), "--no-figures"]) == 0
    doc = json.loads((out / "results.json").read_text())
    steps = doc["steps"]
    assert doc["inputs"]["hardness"] == 8e6 and doc["inputs"]["unload"] is True
    assert [s["unloading"] for s in steps] == [False, False, True]
    assert steps[0]["plastic_area_fraction"] == 0.0 < steps[1]["plastic_area_fraction"]
    # back at 1 MPa the flattened crest carries the load on a wider contact
    assert steps[2]["area_fraction"] > steps[0]["area_fraction"]
    # Persson's elastic theory beside the elastic step only, not beside the plastic one
    # nor the unloading step on the flattened crest; derived.persson says why
    assert steps[0]["persson_area_fraction"] > 0
    assert steps[1]["persson_area_fraction"] is None is steps[2]["persson_area_fraction"]
    assert steps[2]["persson_mean_gap"] is None
    assert doc["derived"]["persson"]["plastic_steps"] == [1, 2]
    h5py = pytest.importorskip("h5py")
    with h5py.File(out / "fields.h5", "r") as f:
        up = f["plastic_displacement"][:]
        assert f["plastic_displacement"].attrs["unit"] == "m"
        assert not up[0].any() and up[1].max() > 0 and np.array_equal(up[1], up[2])
    # a hardness below the load, and a non-positive one, are one-line input errors
    assert main(["contact", str(path), "--E", "1e9", "--nu", "0", "--pressure", "1e6",
                 "--hardness", "5e5", "-o", str(tmp_path / "x")]) == 2
    assert "below the hardness" in capsys.readouterr().err
    assert main(["contact", str(path), "--E", "1e9", "--nu", "0", "--pressure", "1e6",
                 "--hardness", "0", "-o", str(tmp_path / "y")]) == 2
    capsys.readouterr()
    assert main(["contact", str(path), "--E", "1e9", "--nu", "0", "--hardness", "1e7",
                 "--adhesion", "md", "--work-of-adhesion", "0.1", "--range", "1e-7",
                 "-o", str(tmp_path / "z")]) == 2
    assert "not supported" in capsys.readouterr().err


def test_contact_cli_coarse_correction_switch(tmp_path, capsys):
    # --coarse-correction on/off reaches solve_contact (recorded in the inputs); on in
    # displacement control is refused with the reason
    from roughfe.surfaces.spectral import spectral_surface
    path = save_surface(spectral_surface(64, 1e-4, 0.8, rms_slope=0.1, rng=1),
                        tmp_path / "rough.npz")
    answers = {}
    for mode in ("on", "off"):
        out = tmp_path / mode
        assert main(["contact", str(path), "--E", "1e9", "--nu", "0.3", "--pressure", "1e7",
                     "--coarse-correction", mode, "-o", str(out), "--no-figures"]) == 0
        doc = json.loads((out / "results.json").read_text())
        assert doc["inputs"]["coarse_correction"] == mode
        answers[mode] = doc["steps"][0]["area_fraction"]
    assert answers["on"] == pytest.approx(answers["off"], abs=1e-12)
    assert main(["contact", str(path), "--E", "1e9", "--nu", "0.3", "--delta", "1e-7",
                 "--coarse-correction", "on", "-o", str(tmp_path / "x"), "--no-figures"]) == 2
    assert "needs load control" in capsys.readouterr().err


def test_cli_prints_the_library_s_warnings_as_one_line(tmp_path, capsys):
    # a law whose process zone (2.1e-10 m) the grid (0.31 um) does not resolve: the
    # library's ResolutionWarning reaches the user as "roughfe contact: warning: ...",
    # not as a Python file:line with a source line
    from roughfe.surfaces.io import save_surface
    path = save_surface(_narrow_band_cell(), tmp_path / "periodic.npz")
    assert main(["contact", str(path), "--E", "1e6", "--nu", "0.5", "--adhesion", "exp",
                 "--work-of-adhesion", "0.02", "--range", "2e-9", "--steps", "1",
                 "--no-figures", "-o", str(tmp_path / "adh")]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("roughfe contact: warning: the exp adhesion law")
    assert "process zone" in err[0] and ".py:" not in err[0]
    # ... and results.json keeps the numbers of the warning: (pi/4) E* w / sigma0^2 with
    # sigma0 = w / range (the exponential law) against the 10 um / 32 spacing
    res = json.loads((tmp_path / "adh" / "results.json").read_text())["derived"]["resolution"]
    e_star = 1e6 / (1 - 0.5 ** 2)
    zone = np.pi / 4 * e_star * 0.02 / (0.02 / 2e-9) ** 2
    assert res["process_zone"] == pytest.approx(zone, rel=1e-12, abs=0)
    assert res["grid_spacing"] == pytest.approx(1e-5 / 32, rel=1e-12, abs=0)
    assert not res["resolved"] and res["process_zone_cells"] == pytest.approx(zone * 32 / 1e-5)


def _narrow_band_cell():
    """A narrow-band periodic cell: 32^2, L = 10 um, H = 0.8, 10 nm rms, q_s / q_r = 4."""
    from roughfe.surfaces.spectral import spectral_surface
    return spectral_surface(32, 1e-5, 0.8, rms_height=1e-8, q_roll=4 * np.pi / 1e-5,
                            q_short=16 * np.pi / 1e-5, rng=3)


def test_contact_cli_adhesion_default_steps_on_a_periodic_surface(tmp_path, capsys):
    # the default approaches of --adhesion on a periodic surface stop short of full
    # contact (max h - mean h), where the adhesive state is not defined by the approach
    # and the solver refuses it: until round 2 session 13 the last default step did
    # (a weak law whose process zone, 10 um, spans 34 grid spacings: resolved)
    from roughfe.surfaces.io import save_surface
    path = save_surface(_narrow_band_cell(), tmp_path / "periodic.npz")
    out = tmp_path / "adh"
    assert main(["contact", str(path), "--E", "1e6", "--nu", "0.5", "--adhesion", "exp",
                 "--work-of-adhesion", "1e-3", "--range", "1e-7", "--steps", "3",
                 "-o", str(out)]) == 0
    doc = json.loads((out / "results.json").read_text())
    steps = doc["steps"]
    assert len(steps) == 3 and all(not st["unloading"] for st in steps)
    # without --unload there is no pull-off: null in the file, "not traced" on the screen
    assert doc["derived"]["pull_off_force"] is None
    assert "pull-off force not traced (--unload traces it)" in capsys.readouterr().out
    # (the reported Delta is the equilibrium's own: adhesion may close the last step
    # fully, at Delta = max h - mean h, below the imposed approach's 3/4 of it)
    assert np.all(np.diff([st["load"] for st in steps]) > 0)


def test_contact_help_says_where_the_default_approaches_stop(capsys, monkeypatch):
    # --steps said "up to full contact for periodic surfaces", also with --adhesion, whose
    # approaches stop at N/(N+1) of max h - mean h (adhesive_sweep; found by a reviewer,
    # session 26)
    monkeypatch.setenv("COLUMNS", "2000")              # one line per option, no wrapping
    assert main(["contact", "--help"]) == 0
    text = capsys.readouterr().out
    assert ("N equispaced approaches k/N (k = 1..N) of the peak-to-valley height, on a "
            "periodic surface of max h - mean h (full contact); with --adhesion on a "
            "periodic surface k/(N+1) of max h - mean h (full contact left out") in text


def _narrow_band_adhesive_run(tmp_path, capsys):
    """A narrow-band periodic cell (32^2, H = 0.8, 10 nm rms, q_s / q_r = 4) under a
    resolved Maugis-Dugdale law (w = 4.52e-5 J/m^2, range 10 nm: process zone 7.4 cells)
    loaded in 4 steps: the results.json and the screen."""
    path = save_surface(_narrow_band_cell(), tmp_path / "narrow.npz")
    out = tmp_path / "adh"
    assert main(["contact", str(path), "--E", "1e6", "--nu", "0.5", "--adhesion", "md",
                 "--work-of-adhesion", "4.52e-5", "--range", "1e-8", "--steps", "4",
                 "--no-figures", "-o", str(out)]) == 0
    return json.loads((out / "results.json").read_text()), capsys.readouterr().out


def test_contact_cli_adhesive_steps_get_no_non_adhesive_persson_theory(tmp_path, capsys):
    # Persson's theory is non-adhesive: at the net (repulsive minus attractive) load of an
    # adhesive state it predicts nothing (here the last step, p = 1.2 kPa > 0, has
    # A* = 0.42 where the non-adhesive theory gave 0.073). Until round 2 session 24 every
    # step with p > 0 got persson_area_fraction / persson_mean_gap unlabelled.
    doc, _ = _narrow_band_adhesive_run(tmp_path, capsys)
    steps = doc["steps"]
    assert any(st["mean_pressure"] > 0 for st in steps)
    assert not any(k.startswith("persson_") for st in steps for k in st)
    assert doc["derived"]["persson"]["adhesion"] == "not in the theory"


def test_contact_cli_says_when_pastewka_robbins_is_outside_its_domain(tmp_path, capsys):
    # Delta_r / g0 = 0.14 here, above the criterion's 0.1: its verdict ("not sticky",
    # while the loading branch holds contact at tensile loads) was printed as Eq. 10's
    # prediction with no caveat until round 2 session 24
    doc, out = _narrow_band_adhesive_run(tmp_path, capsys)
    st = doc["derived"]["stickiness"]
    assert st["range_over_edge_gap"] > 0.1 and st["in_domain"] is False
    assert (f"outside its domain: Delta_r/g0 = {st['range_over_edge_gap']:.2g} > 0.1"
            in out)


def test_contact_cli_completes_on_a_two_row_window(tmp_path):
    # Persson's theory has no PSD of a non-periodic 2 x N window (Hann): the run writes
    # its results without it (it failed after the whole solve, rc 2, nothing written)
    path = tmp_path / "two.npy"
    np.save(path, 1e-6 * np.random.default_rng(1).standard_normal((2, 64)))
    assert main(["contact", str(path), "--size", "1e-4", "--steps", "3", "-o",
                 str(tmp_path / "out"), "--no-figures", "--quiet"]) == 0
    doc = json.loads((tmp_path / "out" / "results.json").read_text())
    assert len(doc["steps"]) == 3 and all(st["area_fraction"] > 0 for st in doc["steps"])
    assert doc["derived"]["persson"]["theory"] == "not evaluated on this grid"
