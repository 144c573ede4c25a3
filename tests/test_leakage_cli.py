"""``roughfe leak`` and ``roughfe leak-study`` end to end on tiny RMD surfaces."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest

from roughfe._runtime import headless_environment
from roughfe.surfaces.io import save_surface
from roughfe.surfaces.rmd import rmd_surface

STEP_KEYS = {"delta", "mean_pressure", "area_fraction", "leak_rate", "hydraulic_aperture",
             "percolates_x", "percolates_y", "free_volume_star", "percolating_volume_star",
             "trapped_volume_star"}


@pytest.mark.slow
def test_leak_command_writes_results_fields_and_figures(tmp_path):
    s = rmd_surface(4, 2.3, 1e-4, rng=5)
    path = save_surface(s, tmp_path / "s.npz")
    out = tmp_path / "out"
    deltas = [0.2 * np.ptp(s.heights), 0.6 * np.ptp(s.heights)]
    # a fresh process, as a user runs it (the CLI loads vtk before dolfinx: roughfe._runtime)
    env = headless_environment(dict(os.environ))
    proc = subprocess.run(
        [sys.executable, "-m", "roughfe.cli", "leak", str(path), "--delta", *map(str, deltas),
         "--direction", "x", "--mu", "1e-3", "-o", str(out)],
        capture_output=True, text=True, env=env, timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    res = json.loads((out / "results.json").read_text())
    assert res["inputs"]["delta"] == pytest.approx(deltas, rel=1e-6, abs=0)
    steps = res["steps"]
    assert len(steps) == 2 and STEP_KEYS <= set(steps[0])
    assert steps[0]["percolates_y"] is None            # not analysed
    assert set(res["units"]) == set(steps[0])          # every key has its unit
    # the persson block's meaning of a null K, not the bare "Pa/m" of the suffix rule
    assert res["units"]["persson_stiffness"] == res["persson"]["units"]["persson_stiffness"]
    assert "null: infinite" in res["units"]["persson_stiffness"]
    for st in steps:     # the sealed part of the trapped (non-percolating) volume
        assert 0 <= st["sealed_volume"] <= st["trapped_volume"]
    assert "stiffness" not in steps[0]                 # not computed: no null read as inf
    # the contact scalars under the names of contact's records (leak wrote "nit")
    from roughfe.model import RECORD_KEYS
    assert set(RECORD_KEYS) - {"stiffness", "stiffness_fd"} <= set(steps[0])
    assert "nit" not in steps[0] and steps[0]["iterations"] >= 1
    # more load: more contact, less free volume, smaller leak rate
    assert steps[1]["area_fraction"] > steps[0]["area_fraction"]
    assert steps[1]["free_volume_star"] < steps[0]["free_volume_star"]
    assert steps[1]["leak_rate"] < steps[0]["leak_rate"]
    # Persson's theory beside every step (A*, mean gap, critical-junction leak rate)
    for st in steps:
        assert 0 < st["persson_area_fraction"] <= 1 and st["persson_mean_gap"] > 0
        assert st["persson_leak_rate"] >= 0
    assert res["persson"]["percolation_threshold"] == 0.42
    with np.load(out / "fields" / "step_000.npz") as f:
        assert f["gap"].shape == s.shape and f["fluid_pressure_x"].shape == s.shape
        assert f["flux_x"].shape == s.shape + (2,) and "flux_y" not in f
        assert not (f["percolating"] & f["trapped"]).any()
        assert not (f["sealed"] & ~f["trapped"]).any()
        # the widest path runs inlet -> outlet through cells no narrower than u_c
        path = f["widest_path_x"]
        assert path[0, 0] == 0 and path[-1, 0] == s.shape[0] - 1
        assert f["gap"][path[:, 0], path[:, 1]].min() == pytest.approx(steps[0]["critical_gap"],
                                                                      rel=1e-6, abs=0)
        # readable without results.json: the grid and every array's unit
        np.testing.assert_allclose(f["size_m"], s.size)
        np.testing.assert_allclose(f["spacing_m"], s.spacing)
        units = json.loads(str(f["units"]))
        assert units["gap"] == "m" and units["flux_x"].startswith("m^2/s")
        assert set(units) == set(f.files) - {"units"}
    for name in ("step_000_network.png", "step_001_pressure_x.png", "step_000_flux_x.png",
                 "steps.png"):
        assert (out / "figures" / name).stat().st_size > 5000


@pytest.mark.slow
def test_leak_study_runs_resumes_and_summarises(tmp_path, capsys):
    from roughfe.cli import main
    out = tmp_path / "study"
    argv = ["leak-study", "--D", "2.3", "2.7", "--m", "3", "--surfaces", "2", "--no-reynolds",
            "--workers", "1", "--quiet", "-o", str(out)]
    assert main(argv) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["n_records"] == 2 * 2 * 6
    # the settings the curves belong to (Q at this pressure drop and viscosity)
    assert summary["settings"]["pressure_drop"] == 1.0 and summary["settings"]["mu"] == 1e-3
    assert {(f["D"], f["m"]) for f in summary["fits"]} == {(2.3, 3), (2.7, 3)}
    assert (out / "figures" / "fits_g_beta.png").stat().st_size > 5000
    assert capsys.readouterr().err == ""                          # --quiet is quiet
    # rerun: every task is already done, the summary is the same
    loud = [a for a in argv if a != "--quiet"]
    assert main(loud) == 0
    assert json.loads((out / "summary.json").read_text()) == summary
    assert "4 already done" in capsys.readouterr().err
    # a rerun without figures leaves none of the earlier run's beside its summary
    assert main(argv + ["--no-figures"]) == 0
    assert not (out / "figures").exists()


FSI_KEYS = {"fluid_load_fraction", "coupled_iterations", "critical_gap", "critical_position",
            "leak_rate_critical_junction", "pocket_pressures", "pocket_volume", "persson_leak_rate",
            "trapped_load_fraction", "leak_rate_one_way", "fsi_state", "external_pressure",
            "contact_load_fraction", "pocket_volumes", "pockets_new", "pockets_released",
            "pockets_merged", "pocket_passes", "pockets_settled", "trapped_fluid",
            "bulk_modulus"}


def test_leak_fsi_writes_coupled_steps(tmp_path, capsys):
    from roughfe.cli import main
    from roughfe.surfaces.spectral import spectral_surface
    s = spectral_surface(32, 1e-4, 0.8, rms_height=1e-6, rng=4)
    path = save_surface(s, tmp_path / "s.npz")
    out = tmp_path / "fsi"
    argv = ["leak", str(path), "--pressure", "1e6", "3e6", "--fsi", "--direction", "x",
            "--inlet-pressure", "1e6", "--outlet-pressure", "0", "--E", "2.1e8",
            "--no-figures", "--quiet", "-o", str(out)]
    assert main(argv) == 0
    doc = json.loads((out / "results.json").read_text())
    steps = doc["steps"]
    assert len(steps) == 2 and FSI_KEYS <= set(steps[0])
    # every key has its unit (there was none per key: a user's review, session 29)
    assert set(doc["units"]) == set(steps[0])
    assert doc["units"]["pocket_volume"] == "m^3" and doc["units"]["external_pressure"] == "Pa"
    for st in steps:
        assert st["fsi_state"] == "contact" and st["coupled_residual"] <= 1e-8
        # the fluid opens the contact: the coupled leak rate exceeds the one-way one
        assert st["leak_rate"] > st["leak_rate_one_way"] > 0
        assert 0 < st["fluid_load_fraction"] < 1
        # external load = solid (effective) + fluid share
        assert st["mean_pressure"] == pytest.approx(
            st["external_pressure"] * (1 - st["fluid_load_fraction"]), rel=1e-8)
        # the network's volumes partition the free volume (its trapped_volume was
        # overwritten by the pockets' fluid volume, now pocket_volume)
        assert st["percolating_volume"] + st["trapped_volume"] == pytest.approx(
            st["free_volume"], rel=1e-9, abs=0)
        assert 0 <= st["pocket_volume"] <= st["free_volume"]
    with np.load(out / "fields" / "step_000.npz") as f:
        assert f["fluid_pressure"].shape == s.shape and f["fluid_pressure"].max() <= 1e6 * (1 + 1e-9)
    # bad input: one line each, exit code 2
    bad = [["--delta", "1e-7"], ["--direction", "both"], ["--inlet-pressure", "1e6"],
           ["--pressure-drop", "1", "--inlet-pressure", "1", "--outlet-pressure", "0"],
           ["--trapped-fluid", "pressure", "--bulk-modulus", "2.2e9"],
           ["--bulk-modulus", "-1"]]
    base = ["leak", str(path), "--fsi", "--no-figures", "--quiet", "--overwrite", "-o", str(out)]
    for extra in bad:
        args = list(base) + extra
        if "--delta" not in extra:
            args += ["--pressure", "1e6"]
        if "--direction" not in extra:
            args += ["--direction", "x"]
        assert main(args) == 2, extra
    # without --fsi a reversed pressure pair is refused (with --fsi it is solved)
    assert main(["leak", str(path), "--pressure", "1e6", "--inlet-pressure", "0",
                 "--outlet-pressure", "1e6", "--no-figures", "--quiet", "--overwrite",
                 "-o", str(out)]) == 2
    assert "reversed flow" in capsys.readouterr().err
    assert main(["leak", str(path), "--pressure", "1e6", "--bulk-modulus", "2.2e9",
                 "--no-figures", "--quiet", "--overwrite", "-o", str(out)]) == 2
    assert "--bulk-modulus needs --fsi" in capsys.readouterr().err


def _table_head(text):
    return next(line for line in text.splitlines() if line.lstrip().startswith("step "))


def test_leak_fsi_and_one_way_write_the_same_network_fields_and_columns(tmp_path, capsys):
    """The coupled (--fsi) step files carry the one-way files' contact and network arrays,
    the `sealed` mask included (they lacked it, and percolating_x and parent_channel_x:
    a user's review), and both tables print the Vp*, Vnp*, sealed* and perc x/y columns
    (the --fsi table had none of them)."""
    from roughfe.cli import main
    from roughfe.surfaces.spectral import spectral_surface
    s = spectral_surface(32, 1e-4, 0.8, rms_height=1e-6, rng=4)
    path = save_surface(s, tmp_path / "s.npz")
    common = ["leak", str(path), "--pressure", "1e6", "3e6", "--direction", "x", "--E", "2.1e8",
              "--no-figures"]
    fsi_out, plain_out = tmp_path / "fsi", tmp_path / "plain"
    assert main(common + ["--fsi", "--inlet-pressure", "1e6", "--outlet-pressure", "0",
                          "-o", str(fsi_out)]) == 0
    fsi_text = capsys.readouterr().out
    assert main(common + ["-o", str(plain_out)]) == 0
    plain_text = capsys.readouterr().out
    for text in (fsi_text, plain_text):
        head = _table_head(text)
        for column in ("A*", "Vp*", "Vnp*", "sealed*", "perc x/y", "Q (m^3/s)"):
            assert f" {column}" in head, (column, head)
        assert "sealed*: the part of Vnp* with no open path" in text
    # the printed sealed* is the step's sealed_volume_star; x analysed, y not ("-", not "N")
    steps = json.loads((fsi_out / "results.json").read_text())["steps"]
    row = _table_head(fsi_text).split()
    last = fsi_text.splitlines()[fsi_text.splitlines().index(_table_head(fsi_text)) + 2].split()
    assert float(last[row.index("sealed*") - 1]) == pytest.approx(
        steps[1]["sealed_volume_star"], rel=1e-3, abs=0)
    assert "T/-" in last

    flow_only = {"fluid_pressure_x", "flux_x"}             # the one-way Reynolds solve's
    with np.load(plain_out / "fields" / "step_001.npz") as plain, \
            np.load(fsi_out / "fields" / "step_001.npz") as fsi:
        assert set(plain.files) - flow_only <= set(fsi.files)
        units = json.loads(str(fsi["units"]))
        assert units["sealed"] == "1" and set(units) == set(fsi.files) - {"units"}
        sealed, trapped, gap = fsi["sealed"], fsi["trapped"], fsi["gap"]
        assert sealed.dtype == bool and sealed.shape == s.shape
        assert sealed.any() and not (sealed & ~trapped).any()
        # the mask is the one of the step's sealed_volume (the gap over its cells)
        dx, dy = fsi["spacing_m"]
        assert gap[sealed].sum() * dx * dy == pytest.approx(steps[1]["sealed_volume"],
                                                            rel=1e-12, abs=0)


def test_leak_takes_the_contact_physics_options(tmp_path, capsys):
    # roughfe leak accepts --adhesion/--hardness/--unload of roughfe contact (one option
    # vocabulary): at the same approaches adhesion pulls the body onto the surface and a
    # pressure cap lets the peaks flow, so both close more of the gap than the elastic
    # contact: more contact, a smaller leak rate; unloading keeps the plastic set
    from roughfe.cli import main

    s = rmd_surface(4, 2.3, 1e-4, rng=5)
    path = save_surface(s, tmp_path / "s.npz")
    deltas = [str(f * np.ptp(s.heights)) for f in (0.3, 0.5)]
    base = ["leak", str(path), "--delta", *deltas, "--direction", "x", "--no-figures",
            "--quiet"]

    def run(name, *extra):
        assert main(base + ["-o", str(tmp_path / name), *extra]) == 0
        return json.loads((tmp_path / name / "results.json").read_text())

    el = run("elastic")
    # (a range of half the peak-to-valley height: the law's process zone, 25.8 um, spans
    # 4.2 grid spacings; roughfe.bem.interface_law.check_resolution: not enough for the
    # default ramp on summits that stand off this 17^2 grid by more than half of it,
    # round 2 session 31)
    rng = str(0.5 * np.ptp(s.heights))
    adh = run("adhesive", "--adhesion", "md", "--work-of-adhesion", "5", "--range", rng)
    hp = 0.3 * max(st["mean_pressure"] for st in el["steps"]) / el["steps"][-1]["area_fraction"]
    hard = run("hardness", "--hardness", str(hp), "--unload")
    assert adh["inputs"]["adhesion"]["law"] == "md" and hard["inputs"]["hardness"] == hp
    # the process zone against the grid, kept: (pi/4) E* w / sigma0^2, sigma0 = w / range
    res = adh["inputs"]["adhesion_resolution"]
    e_star = adh["inputs"]["E"] / (1 - adh["inputs"]["nu"] ** 2)
    zone = np.pi / 4 * e_star * 5.0 / (5.0 / float(rng)) ** 2
    assert res["process_zone"] == pytest.approx(zone, rel=1e-12, abs=0)
    assert res["grid_spacing"] == pytest.approx(max(s.spacing), rel=1e-12, abs=0)
    assert res["process_zone_cells"] == pytest.approx(zone / max(s.spacing), rel=1e-12,
                                                      abs=0)
    # the Maugis-Dugdale law on a surface needs 2.7 cell compliances (about 3 cells), and
    # (pi/4)/s of them where the summits stand off the grid by more than half the ramp
    # s h0 / 2 (the cell relief, recorded)
    assert res["cell_compliance"] == pytest.approx(1.11, abs=0.02)
    assert res["cell_relief"] > 0.5 * 0.05 * float(rng)
    assert res["threshold_cells"] == pytest.approx(np.pi / 4 / 0.05 * res["cell_compliance"],
                                                   rel=1e-12, abs=0)
    assert not res["resolved"]
    assert "adhesion_resolution" not in el["inputs"]
    # the (non-adhesive) Persson theory beside the elastic steps only, not the adhesive ones
    assert all(st["persson_leak_rate"] is not None for st in el["steps"])
    assert not any(k.startswith("persson_") for st in adh["steps"] for k in st)
    assert adh["persson"]["adhesion"] == "not in the theory"
    for other in (adh, hard):
        for e, o in zip(el["steps"], other["steps"]):
            assert o["delta"] == pytest.approx(e["delta"], rel=1e-6, abs=0)
            assert o["area_fraction"] >= e["area_fraction"]
            assert o["leak_rate"] <= e["leak_rate"]
            assert o["mean_pressure"] < e["mean_pressure"]
    assert any(st["adhesive_area_fraction"] > 0 for st in adh["steps"])
    assert max(st["plastic_area_fraction"] for st in hard["steps"]) > 0
    # nor beside the plastic steps and those after them (the elastic theory; session 25)
    flowed = [k for k, st in enumerate(hard["steps"]) if st["plastic_area_fraction"] > 0]
    assert hard["persson"]["plastic_steps"] == list(range(flowed[0], len(hard["steps"])))
    assert all(st["persson_leak_rate"] is None and st["persson_area_fraction"] is None
               for st in hard["steps"][flowed[0]:])
    # --unload: the loading steps in reverse; the plastic set keeps the gap smaller than
    # on loading at the same approach
    unl = [st for st in hard["steps"] if st["unloading"]]
    assert len(unl) == 1
    assert unl[0]["delta"] == pytest.approx(hard["steps"][0]["delta"], rel=1e-6, abs=0)
    assert unl[0]["mean_gap"] < hard["steps"][0]["mean_gap"]


@pytest.mark.parametrize("extra, message", [
    # in leak's own words (it said "give approaches (delta, deltas, n_steps), not mean
    # pressures", the library's keywords, until session 26)
    (["--adhesion", "md", "--work-of-adhesion", "1", "--range", "1e-7", "--pressure", "1e6"],
     "roughfe leak: error: --adhesion runs in displacement control (the load-approach curve "
     "has unstable parts): give --delta, not --pressure"),
    (["--hardness", "1e6", "--adhesion", "exp", "--work-of-adhesion", "1", "--range", "1e-7",
      "--delta", "1e-7"], "not supported"),
    (["--fsi", "--direction", "x", "--hardness", "1e6", "--pressure", "1e6"], "--fsi"),
])
def test_leak_contact_physics_bad_input(tmp_path, capsys, extra, message):
    from roughfe.cli import main

    path = save_surface(rmd_surface(3, 2.3, 1e-4, rng=5), tmp_path / "s.npz")
    out = tmp_path / "o"
    assert main(["leak", str(path), "--quiet", "-o", str(out), *extra]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1
    assert not out.exists()


def test_leak_of_a_profile_with_adhesion_says_leakage_needs_a_surface(tmp_path, capsys):
    # the law's resolution (written beside the inputs) is taken on the profile's own
    # operator, and the run then says what is wrong: leakage is 2D (it said the
    # resolution needed the cell's compliance, round 2, session 22)
    from roughfe.cli import main
    from roughfe.surfaces.spectral import spectral_profile

    path = save_surface(spectral_profile(256, 1e-4, 0.8, rms_height=1e-6, rng=1),
                        tmp_path / "p.npz")
    assert main(["leak", str(path), "--quiet", "-o", str(tmp_path / "o"), "--adhesion",
                 "md", "--work-of-adhesion", "0.01", "--range", "1e-7", "--delta",
                 "1e-7"]) == 2
    err = capsys.readouterr().err.strip()
    assert "leakage needs a 2D surface" in err and len(err.splitlines()) == 1


def test_leak_direction_y_is_direction_x_of_the_transpose(tmp_path):
    # Reynolds and Persson's theory together: `--direction y` on Z equals `--direction x`
    # on Z.T (a rectangular, non-periodic surface, so the geometry factor matters)
    from roughfe.cli import main
    from roughfe.surfaces import Surface
    from roughfe.surfaces.spectral import spectral_surface
    z = spectral_surface(32, 1e-4, 0.8, rms_height=1e-6, rng=2).heights[:, :16]
    steps = {}
    for name, heights, size, d in (("y", z, (1e-4, 5e-5), "y"),
                                   ("xT", z.T.copy(), (5e-5, 1e-4), "x")):
        path = save_surface(Surface(heights, size, periodic=False), tmp_path / f"{name}.npz")
        out = tmp_path / name
        assert main(["leak", str(path), "--pressure", "2e6", "--direction", d, "--E", "2.1e8",
                     "--pressure-drop", "1e5", "--no-figures", "--quiet", "-o", str(out)]) == 0
        steps[name] = json.loads((out / "results.json").read_text())["steps"][0]
    a, b = steps["y"], steps["xT"]
    assert a["leak_rate"] > 0 and a["persson_leak_rate"] > 0
    assert a["leak_rate"] == pytest.approx(b["leak_rate"], rel=1e-6, abs=0)
    assert a["leak_rate_y"] == pytest.approx(b["leak_rate_x"], rel=1e-6, abs=0)
    assert a["persson_leak_rate"] == pytest.approx(b["persson_leak_rate"], rel=1e-6, abs=0)
    assert a["persson_leak_rate_y"] == pytest.approx(b["persson_leak_rate_x"], rel=1e-6, abs=0)


def test_leak_draws_the_maps_of_the_end_steps_unless_asked_for_all():
    """The per-step maps took ~90 % of a leak sweep's run time (8 steps at 128^2: 47 s
    against 4.6 s without figures; a user's review): by default only the first and last
    steps get them, every step with --maps all, none with --no-figures."""
    from argparse import Namespace

    from roughfe.cli.leak_cmd import _maps_of
    drawn = {m: [k for k in range(5) if _maps_of(Namespace(no_figures=False, maps=m), k, 5)]
             for m in ("ends", "all")}
    assert drawn == {"ends": [0, 4], "all": [0, 1, 2, 3, 4]}
    assert _maps_of(Namespace(no_figures=False, maps="ends"), 0, 1)
    assert not any(_maps_of(Namespace(no_figures=True, maps="all"), k, 5) for k in range(5))


def test_leak_warns_that_persson_is_isotropic_on_a_surface_with_a_lay(tmp_path, capsys):
    """A seals review: on x3p-2 (a machined lay) Persson's leak rate fell 10^5-10^6 x
    below the Reynolds rate along the grooves without a word. Grooves along y (Str 0.09)
    now get the "anisotropic" note in results.json and on stderr, with the Str that
    results.json carries; an isotropic RMD surface (Str 0.73) gets its Str and no note."""
    from roughfe.cli import main
    from roughfe.surfaces.surface import Surface
    n, rng = 33, np.random.default_rng(2)
    h = (1e-6 * np.sin(2 * np.pi * 3 * np.arange(n) / n)[:, None]
         + 1e-7 * rng.standard_normal((n, n)))
    grooved = save_surface(Surface(h, (1e-4, 1e-4), periodic=False), tmp_path / "g.npz")
    iso = save_surface(rmd_surface(5, 2.3, 1e-4, rng=5), tmp_path / "iso.npz")
    runs = {}
    for name, path in (("grooved", grooved), ("iso", iso)):
        assert main(["leak", str(path), "--E", "1e9", "--nu", "0.3", "--pressure", "1e7",
                     "--no-figures", "-o", str(tmp_path / name)]) == 0
        runs[name] = (json.loads((tmp_path / name / "results.json").read_text())["persson"],
                      capsys.readouterr().err)
    info, err = runs["grooved"]
    assert info["texture_aspect_ratio"] == pytest.approx(0.0934, abs=1e-3)
    assert info["lay_angle"] == pytest.approx(90.0, abs=1.0)
    assert info["anisotropic"].split(":")[0] == "the surface has a lay"
    assert f"Str = {info['texture_aspect_ratio']:.3g}" in err
    assert "Persson's theory assumes an isotropic surface" in err
    info, err = runs["iso"]
    assert info["texture_aspect_ratio"] > 0.5 and "anisotropic" not in info
    assert "has a lay" not in err


def test_leak_at_the_theory_s_full_contact_prints_no_numpy_warning(tmp_path, capsys):
    """At 0.8 E* on a smooth 16^2 window Persson's u(p) is 0 to double precision and
    K = -dp/du infinite: numpy's "divide by zero encountered in divide" reached the user
    (a 16^2 crop of x3p-2 at 2e11 Pa). Now K is inf, null in results.json, whose unit
    says what null means, and stderr has no numpy warning."""
    from roughfe.cli import main
    from roughfe.surfaces.surface import Surface
    h = 1e-8 * np.random.default_rng(2).standard_normal((16, 16))
    path = save_surface(Surface(h, (1e-4, 1e-4), periodic=False), tmp_path / "s.npz")
    main(["leak", str(path), "--E", "1e9", "--nu", "0.3", "--pressure", "8e8",
          "--no-figures", "-o", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert "divide" not in err and "RuntimeWarning" not in err
    res = json.loads((tmp_path / "out" / "results.json").read_text())
    assert res["steps"][0]["persson_mean_gap"] == 0.0
    assert res["steps"][0]["persson_stiffness"] is None
    assert "null: infinite" in res["persson"]["units"]["persson_stiffness"]


def test_leak_says_which_junctions_lie_at_the_edge_of_a_window(tmp_path, capsys):
    # a non-periodic window: the printed line names exactly the steps and directions that
    # results.json flags critical_at_edge (the spectral seed-1 32^2 surface, read
    # non-periodic: the y junctions at the window's edge at both approaches); the same
    # surface periodic has no cut and flags none
    from roughfe.cli import main
    path = tmp_path / "s.npz"
    assert main(["generate", "spectral", "--n", "32", "--seed", "1", "--no-figures",
                 "-o", str(path)]) == 0
    flagged = {}
    for periodic in ("--non-periodic", "--periodic"):
        out = tmp_path / periodic
        capsys.readouterr()
        assert main(["leak", str(path), periodic, "--delta", "1e-7", "2e-7", "--no-figures",
                     "-o", str(out)]) == 0
        printed = [ln for ln in capsys.readouterr().out.splitlines()
                   if ln.startswith("junction at the window's edge")]
        res = json.loads((out / "results.json").read_text())
        assert res["units"]["critical_at_edge_x"].startswith("bool")
        flagged[periodic] = [
            f"{s['step']} ({', '.join(d for d in 'xy' if s[f'critical_at_edge_{d}'])})"
            for s in res["steps"] if s["critical_at_edge_x"] or s["critical_at_edge_y"]]
        assert bool(printed) == bool(flagged[periodic])
        if printed:
            assert f"steps {', '.join(flagged[periodic])}:" in printed[0]
    assert flagged == {"--non-periodic": ["0 (y)", "1 (y)"], "--periodic": []}
