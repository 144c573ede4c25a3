"""What a user's review of the command line found (round 2, session 21): each test fails
on the code before its fix. Wrong numbers in a printed table, tracebacks for bad input,
messages in the library's words, files that did not match their command."""
import json
import time
import warnings

import numpy as np
import pytest

from roughfe.cli import main
from roughfe.writers import OWNER_FILE, OutputFolder, write_text


@pytest.fixture
def surface64(spectral_file):
    return spectral_file(64, 3)


def _error(capsys):
    err = capsys.readouterr().err
    assert "Traceback" not in err
    return err


def test_adhesive_contact_table_prints_no_stiffness_where_none_was_computed(
        surface64, tmp_path, capsys):
    # the adhesive solver computes no K: the table said "inf" on every row (full contact
    # is the only place where inf is the answer, and it still reads inf there)
    capsys.readouterr()
    assert main(["contact", str(surface64), "--E", "1e6", "--nu", "0.5", "--steps", "2",
                 "--adhesion", "md", "--work-of-adhesion", "0.05", "--range", "1e-7",
                 "--no-figures", "-o", str(tmp_path / "ad")]) == 0
    out = capsys.readouterr()
    lines = out.out.splitlines()
    head = next(i for i, line in enumerate(lines) if "delta (m)" in line)
    rows = [line.split() for line in lines[head + 1:head + 3]]
    # (the 7th column, Persson's A*, is "-" too: the theory is non-adhesive; the 8th, the
    # patch width of the g = 0 patches, the adhesive result carries since session 32)
    assert all(len(r) == 8 and r[3] == "-" and r[6] == "-" for r in rows), out.out
    assert all(float(r[7]) >= 1.0 for r in rows), out.out
    # the unresolved law is said once for the run, not once per solve
    assert out.err.count("warning: the md adhesion law") == 1
    steps = json.loads((tmp_path / "ad" / "results.json").read_text())["steps"]
    assert all(s["stiffness"] is None for s in steps)
    assert main(["contact", str(surface64), "--E", "1e9", "--nu", "0.3", "--steps", "3",
                 "--no-figures", "-o", str(tmp_path / "el")]) == 0
    lines = capsys.readouterr().out.splitlines()
    head = next(i for i, line in enumerate(lines) if "delta (m)" in line)
    last = lines[head + 3].split()
    assert float(last[2]) == 1.0 and last[3] == "inf"        # full periodic contact


@pytest.mark.parametrize("args, flag", [
    (["--pressure", "1e7", "--solver", "dense"], "use --solver pk above 8192 points"),
    (["--delta", "1e-7", "--coarse-correction", "on"], "--coarse-correction on"),
    (["--pressure", "1e7", "--non-periodic", "--kernel", "spectral"],
     "(without --non-periodic); use --kernel strip/love otherwise"),
])
def test_contact_solver_rules_are_said_in_the_command_flags(tmp_path, capsys, args, flag):
    path = tmp_path / "s.npz"
    n = "128" if "dense" in args else "64"
    main(["generate", "spectral", "--n", n, "--seed", "1", "--no-figures", "-o", str(path)])
    capsys.readouterr()
    assert main(["contact", str(path), "--E", "1e9", "--nu", "0.3", *args, "--no-figures",
                 "-o", str(tmp_path / "out")]) == 2
    err = _error(capsys)
    assert flag in err and "solver='" not in err and "coarse_correction=" not in err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("model, option", [("wm", "--amplitude"), ("mwm", "--amplitude"),
                                           ("mwm", "--wavelength")])
@pytest.mark.parametrize("value", ["0", "-1", "nan"])
def test_generator_lengths_must_be_positive(tmp_path, capsys, model, option, value):
    # --amplitude 0 with --rms-height divided by zero; --wavelength 0 overflowed
    out = tmp_path / "z.npz"
    assert main(["generate", model, "--n", "32", option, value, "--rms-height", "1e-6",
                 "--no-figures", "-o", str(out)]) == 2
    assert "must be a finite number > 0" in _error(capsys) and not out.exists()


def test_generate_keeps_its_figure_with_its_surface(tmp_path, capsys):
    # a PNG of another name's stem is not replaced without --overwrite ...
    mine = tmp_path / "other.png"
    mine.write_bytes(b"mine")
    assert main(["generate", "spectral", "--n", "32", "--seed", "2",
                 "-o", str(tmp_path / "other.npz")]) == 2
    assert "other.png exists" in _error(capsys) and mine.read_bytes() == b"mine"
    assert not (tmp_path / "other.npz").exists()
    # ... and a surface replaced without figures does not keep the old surface's picture
    out = tmp_path / "st.npz"
    assert main(["generate", "spectral", "--n", "32", "--seed", "1", "-o", str(out)]) == 0
    assert out.with_suffix(".png").is_file()
    assert main(["generate", "spectral", "--n", "32", "--seed", "2", "--overwrite",
                 "--no-figures", "-o", str(out)]) == 0
    assert not out.with_suffix(".png").exists()
    # ... but a picture roughfe did not draw for the replaced surface stays (scan.png
    # beside a scan.npz of other data was removed as "the figure of the surface")
    scan = tmp_path / "scan.npz"
    np.savez(scan, a=0)
    (tmp_path / "scan.png").write_bytes(b"photo")
    assert main(["generate", "spectral", "--n", "16", "--no-figures", "--overwrite",
                 "-o", str(scan)]) == 0
    assert (tmp_path / "scan.png").read_bytes() == b"photo"


def test_unreadable_npz_files_say_what_is_wrong(tmp_path, surface64, capsys):
    text = tmp_path / "bad.npz"
    text.write_text("hello\n")
    assert main(["info", str(text)]) == 2
    assert "not a zip archive" in _error(capsys)
    data = dict(np.load(surface64))
    data["metadata"] = np.array("[1, 2]")            # valid JSON, but not an object
    odd = tmp_path / "odd.npz"
    np.savez(odd, **data)
    assert main(["info", str(odd)]) == 2
    assert "metadata must be a JSON object, got list" in _error(capsys)


def test_info_of_a_tiny_grid_has_no_numpy_warnings(tmp_path, capsys):
    path = tmp_path / "m2.txt"
    path.write_text("1e-6 2e-6\n3e-6 5e-6\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert main(["info", str(path), "--size", "1e-3"]) == 0
    out = capsys.readouterr()
    # the one warning is roughfe's own: this 2 x 2 grid is 97 % tilt (--detrend plane)
    other = [line for line in out.err.splitlines() if "--detrend mean keeps the tilt" not in line]
    assert not any("warning" in line for line in other) and "rms curvature" in out.out


def test_a_channel_without_height_unit_is_refused_by_name(topographies_dir, capsys):
    # di-1.di: channels Height, Height, Phase, AmplitudeError; the last two have no height
    # unit (a ValueError 'Unknown unit' traceback from SurfaceTopography before)
    for channel in ("2", "Phase", "AmplitudeError"):
        assert main(["info", str(topographies_dir / "di-1.di"), "--channel", channel]) == 2
        err = _error(capsys)
        assert "has no height unit" in err and "0 'Height', 1 'Height'" in err


def test_genome_validity_needs_two_ridges(tmp_path, capsys):
    assert main(["genome", "validity", "--max-ridges", "1", "-o",
                 str(tmp_path / "v.png")]) == 2
    assert "--max-ridges: must be an integer in 2..500" in _error(capsys)


def test_trapped_fluid_without_fsi_is_refused(surface64, tmp_path, capsys):
    assert main(["leak", str(surface64), "--E", "1e9", "--nu", "0.3", "--pressure", "1e7",
                 "--trapped-fluid", "pressure", "--no-figures", "-o",
                 str(tmp_path / "lk")]) == 2
    assert "--trapped-fluid needs --fsi" in _error(capsys)
    assert not (tmp_path / "lk").exists()


def test_a_refused_leak_study_leaves_no_folder(tmp_path, capsys):
    out = tmp_path / "ls"
    assert main(["leak-study", "--D", "2.3", "--m", "3", "--surfaces", "1", "--steps", "3",
                 "--scheduler", "tcp://127.0.0.1:1", "--no-figures", "-o", str(out)]) == 2
    assert "--scheduler is for the dask executor" in _error(capsys)
    assert not out.exists()


def test_output_record_times_the_whole_run(tmp_path):
    # the folder is checked before the computation and taken for the writes after it:
    # elapsed_s is the whole run (it timed the writes alone)
    folder = OutputFolder(tmp_path / "run", "contact")
    time.sleep(0.3)                                     # "the solve"
    with folder as d:
        write_text(d / "results.json", "{}")
    record = json.loads((tmp_path / "run" / OWNER_FILE).read_text())
    assert record["status"] == "complete" and record["elapsed_s"] >= 0.3
    assert record["started"] <= record["writing"] <= record["finished"]


def test_a_target_surface_too_small_for_the_database_spacing_is_named(topographies_dir):
    # di-1.di (1 um, mirrored) on the spacing of a 2D database: 0 x 0 points; the error
    # said "the surface is flat"
    from roughfe.errors import InputError
    from roughfe.genomics.database import DatabaseSettings
    from roughfe.genomics.design.targets import target_surface
    from roughfe.surfaces import load_surface
    settings = DatabaseSettings(dim=2, n_nodes=16)
    surface = load_surface(topographies_dir / "di-1.di")
    with pytest.raises(InputError, match=r"database spacing L/N = .* has 0 x 0 points, "
                                         r"fewer than 8 per side: .*--resolution full"):
        target_surface(surface, settings)
    assert target_surface(surface, settings, resolution="full").shape == (1022, 1022)   # mirrored


def test_db_build_is_quiet_and_its_database_honours_the_umask(tmp_path, capsys):
    # --quiet printed three lines of progress and summary; SQLite made its file 0644
    # whatever the umask (every other output is 0666 & ~umask)
    import os
    import stat
    path = tmp_path / "db.sqlite"
    old = os.umask(0o002)
    try:
        assert main(["db", "build", str(path), "--nodes", "128", "--steps", "4", "--limit",
                     "1", "--workers", "1", "--quiet"]) == 0
    finally:
        os.umask(old)
    out = capsys.readouterr()
    assert out.out == "" and out.err == ""
    assert stat.S_IMODE(path.stat().st_mode) == 0o664


def test_extend_and_sequence_say_what_is_wrong(tmp_path, capsys):
    genome = tmp_path / "g.json"
    assert main(["genome", "example", "--seed", "0", "-o", str(genome)]) == 0
    assert main(["genome", "sequence", str(genome), "-o", str(tmp_path / "sq")]) == 2
    assert "is a JSON file (a genome?), not an acquisition" in _error(capsys)
    text = tmp_path / "p.txt"
    text.write_text("1e-6 2e-6 3e-6 1e-6\n")
    assert main(["genome", "sequence", str(text), "-o", str(tmp_path / "sq")]) == 2
    err = _error(capsys)
    assert "takes no --size: give files that carry their size" in err
    assert main(["genome", "realize", str(genome), "-o", str(tmp_path / "r.npz")]) == 2
    assert "give --length L (m) or --scale" in _error(capsys)


@pytest.mark.parametrize("extra, message", [
    ('tol = 5.0', "tol (relative KKT residual) must lie in the open interval (0.0, 1.0)"),
    ('kernel = "spectral"', "kernel 'spectral' is periodic and needs a periodic surface"),
    ('kernel = "strip"', "kernel 'strip' is for profiles"),
])
def test_a_study_refuses_values_its_tasks_would_refuse(tmp_path, capsys, extra, message):
    # these passed the study's up-front check and then failed on every worker (retried)
    spec = tmp_path / "s.toml"
    spec.write_text('[study]\nanalysis = "contact_sweep"\n[grid]\nm = [3]\n[fixed]\n'
                    f'fractal_dimension = 2.3\n{extra}\n')
    assert main(["study", "run", str(spec), "--workers", "1", "-o", str(tmp_path / "o")]) == 2
    assert message in _error(capsys) and not (tmp_path / "o").exists()


def test_numbers_given_as_text_are_refused():
    # "2.3" ran (float() takes it) and keyed its task apart from 2.3
    from roughfe.errors import InputError, check_finite_positive, check_in_open_interval
    with pytest.raises(InputError, match="must be a number in"):
        check_in_open_interval("D", "2.3", 2.0, 3.0)
    with pytest.raises(InputError, match="must be a positive number"):
        check_finite_positive("L", "1e-3")
    with pytest.raises(InputError):
        check_finite_positive("L", True)
    assert check_finite_positive("L", np.float32(2.0)) == 2.0


def test_nonnegative_numbers_given_as_text_are_refused():
    # check_finite_nonnegative took "0.5" (float() does): an adhesive law's smoothing
    # given as text ran as 0.5
    from roughfe.errors import InputError, check_finite_nonnegative
    for bad in ("0.5", b"0", True, -1.0, float("nan")):
        with pytest.raises(InputError, match="must be a finite number >= 0"):
            check_finite_nonnegative("smoothing", bad)
    assert check_finite_nonnegative("smoothing", np.float32(0.5)) == 0.5
    assert check_finite_nonnegative("smoothing", 0) == 0.0


def test_a_study_run_never_leaves_an_earlier_table_beside_new_results(tmp_path, capsys):
    # table.csv of a collect after a partial run stayed, stale, once the run completed
    from roughfe.study import collect
    spec = tmp_path / "s.toml"
    out = tmp_path / "st"
    spec.write_text('[study]\nanalysis = "selftest"\n[grid]\nx = [0.5, 1.5]\n')
    assert main(["study", "run", str(spec), "--workers", "1", "--quiet", "-o", str(out)]) == 0
    assert capsys.readouterr().out == ""                           # --quiet: no summary
    collect(out, parquet=False)
    assert (out / "table.csv").is_file()
    spec.write_text('[study]\nanalysis = "selftest"\n[grid]\nx = [0.5, 1.5, 2.5]\n')
    assert main(["study", "run", str(spec), "--workers", "1", "--quiet", "-o", str(out)]) == 0
    assert not (out / "table.csv").exists()
    # a spec that names no parameter the analysis needs says so
    spec.write_text('[study]\nanalysis = "selftest"\n')
    assert main(["study", "run", str(spec), "-o", str(tmp_path / "none")]) == 2
    assert "analysis 'selftest' needs ['x'] (in [grid] or [fixed])" in _error(capsys)


def test_collect_waits_for_no_run(tmp_path):
    # collect wrote a partial table while a run held the folder's lock
    from roughfe.errors import InputError
    from roughfe.study import collect
    from roughfe.writers import folder_lock
    spec = tmp_path / "s.toml"
    spec.write_text('[study]\nanalysis = "selftest"\n[grid]\nx = [0.5]\n')
    out = tmp_path / "st"
    assert main(["study", "run", str(spec), "--workers", "1", "--quiet", "-o", str(out)]) == 0
    with folder_lock(out, "a run"):
        with pytest.raises(InputError, match="is writing to"):
            collect(out, parquet=False)
    assert not (out / "table.csv").exists()


def test_demo_contact_results_carry_persson_like_roughfe_contact(tmp_path):
    import warnings

    from roughfe.cli.contact_cmd import section_contact
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        text = section_contact(tmp_path, {})
    doc = json.loads((tmp_path / "contact" / "results.json").read_text())
    assert {"shape", "size", "periodic"} <= set(doc["inputs"]) and "persson" in doc["derived"]
    steps = doc["steps"]
    assert all(0 < s["persson_area_fraction"] < 1 for s in steps if s["mean_pressure"] > 0)
    assert "A* Persson" in text
    # one gbar on the page, Persson's (derived.persson.rms_gradient, the PSD's), and the
    # page's numbers reproduce from it: the last row's "A* Persson" is erf(sqrt2 p/(E* gbar))
    # and kappa = A* E* gbar / p. Until round 2 session 24 the kappa sentence used the
    # finite-difference rms slope (0.109 against the column's 0.130)
    import re
    from scipy.special import erf
    gbar = doc["derived"]["persson"]["rms_gradient"]
    shown = [float(g) for g in re.findall(r"gbar = (\d\.\d+)", text)]
    assert len(shown) == 2 and all(g == pytest.approx(gbar, abs=5e-5) for g in shown)
    e_star = doc["inputs"]["E_star"]
    row = [c.strip() for c in text.split("| A* Persson |")[1].split("\n\n")[0]
           .strip().splitlines()[-1].strip("|").split("|")]
    p, a, a_persson = float(row[1]) * 1e6, float(row[2]), float(row[3])
    assert erf(np.sqrt(2) * p / (e_star * shown[0])) == pytest.approx(a_persson, abs=1e-4)
    kappa = float(re.search(r"A\* / \(p/\(E\* gbar\)\) = (\d+\.\d+)", text).group(1))
    assert kappa == pytest.approx(a * e_star * shown[1] / p, abs=0.01)
    # the page says what K of this non-periodic window is, with the numbers of its file
    # (the contact command warns; the demo page explains instead)
    kc = float(re.search(r"K C = (\d+\.\d+) at the largest load", text).group(1))
    assert kc == pytest.approx(doc["derived"]["stiffness_compliance"][-1], abs=0.01)
    assert kc > 0.5


def test_a_mistake_in_a_rerun_keeps_the_finished_output(tmp_path, capsys):
    """`roughfe leak` took the folder before its own checks: a rerun with --fsi (which
    refuses the default --direction both) left UNFINISHED and nothing else of the
    finished leak output. The earlier output is now restored, byte for byte."""
    from roughfe.surfaces import Surface
    from roughfe.surfaces.io import save_surface
    h = np.random.default_rng(1).normal(size=(16, 16)) * 1e-7
    path = save_surface(Surface(h, 1e-4, periodic=True), tmp_path / "s.npz")
    out = tmp_path / "L"
    assert main(["leak", str(path), "--delta", "1e-7", "--no-figures", "-o", str(out)]) == 0
    before = {p.relative_to(out): p.read_bytes() for p in out.rglob("*")
              if p.is_file() and p.name != ".lock"}
    assert main(["leak", str(path), "--fsi", "--pressure", "1e7", "--no-figures",
                 "-o", str(out)]) == 2
    after = {p.relative_to(out): p.read_bytes() for p in out.rglob("*")
             if p.is_file() and p.name != ".lock"}
    assert after == before and not (out / "UNFINISHED").exists()


def test_study_run_prints_its_summary_once(tmp_path, capsys):
    # run_study logs the summary (stderr) and the command printed it again (stdout)
    spec = tmp_path / "s.toml"
    spec.write_text('[study]\nanalysis = "selftest"\n[grid]\nx = [0.5]\n')
    assert main(["study", "run", str(spec), "--workers", "1", "-o", str(tmp_path / "o")]) == 0
    both = capsys.readouterr()
    assert (both.out + both.err).count("1 tasks: 0 already done, 1 computed") == 1


def test_contact_warns_where_its_solution_leaves_the_model(tmp_path, capsys):
    """A steep surface (rms slope 0.7: the AFM file di-1 has 0.77), a load whose local
    pressure exceeds E* and a step whose contact rests on a few grid points were solved
    without a word (a user's review, round 2, session 29). Each is now one warning line
    that names its number; a gentle surface at a moderate load gets none of them."""
    steep = tmp_path / "steep.npz"
    assert main(["generate", "spectral", "--n", "64", "--seed", "3", "--rms-slope", "0.7",
                 "--no-figures", "-o", str(steep)]) == 0
    capsys.readouterr()
    assert main(["contact", str(steep), "--E", "1e9", "--nu", "0.5", "--pressure", "1e5",
                 "1e8", "--no-figures", "-o", str(tmp_path / "a")]) == 0
    err = _error(capsys)
    assert "warning: rms slope 0.7 > 0.5: the linear half-space assumes small slopes" in err
    e_star = 1e9 / 0.75
    import h5py
    with h5py.File(tmp_path / "a" / "fields.h5", "r") as f:
        peaks = f["pressure"][...].reshape(2, -1).max(axis=1)
    ratio = max(peaks) / e_star
    assert ratio > 1 and f"reaches {max(peaks):.3g} Pa = {ratio:.3g} E* (step 1)" in err
    steps = json.loads((tmp_path / "a" / "results.json").read_text())["steps"]
    # the patch rule (roughfe.bem.patches): step 0's few points are narrow patches
    w0 = steps[0]["patch_width"]
    assert 0 < w0 < 4 <= steps[1]["patch_width"] and 0 < steps[0]["n_contact"] < 32
    assert f"warning: step 0: contact patches of width {w0:.3g} grid points" in err
    gentle = tmp_path / "gentle.npz"
    assert main(["generate", "spectral", "--n", "64", "--seed", "3", "--rms-slope", "0.1",
                 "--no-figures", "-o", str(gentle)]) == 0
    capsys.readouterr()
    assert main(["contact", str(gentle), "--E", "1e9", "--nu", "0.5", "--pressure", "1e6",
                 "--no-figures", "-o", str(tmp_path / "b")]) == 0
    assert "warning" not in _error(capsys)


def test_contact_table_names_its_theory_slope_plastic_share_and_every_file(
        surface64, tmp_path, capsys):
    """The screen says which slope "A* Persson" took (the PSD's rms gradient, which
    differs up to 2x from the finite-difference slope of `roughfe info`), shows the
    plastic share of A* with --hardness, and lists every file it wrote, figures included
    (the PNGs were left out; a user's review, round 2, session 29)."""
    from roughfe.surfaces import load_surface
    from roughfe.surfaces.stats import rms_slope
    out = tmp_path / "c"
    assert main(["contact", str(surface64), "--E", "1e9", "--nu", "0.3", "--pressure",
                 "1e6", "1e7", "--hardness", "3e7", "-o", str(out)]) == 0
    lines = capsys.readouterr().out.splitlines()
    doc = json.loads((out / "results.json").read_text())
    head = next(i for i, line in enumerate(lines) if line.split()[:1] == ["delta"])
    assert lines[head].split()[5] == "A*plastic"
    for line, step in zip(lines[head + 1:head + 3], doc["steps"]):
        assert float(line.split()[3]) == pytest.approx(step["plastic_area_fraction"],
                                                       rel=5e-3)
    assert doc["steps"][1]["plastic_area_fraction"] > 0
    gbar = doc["derived"]["persson"]["rms_gradient"]
    assert (f"Persson's theory beside the results (persson_* in results.json) takes gbar = "
            f"{gbar:.3g}, the rms gradient of the surface's PSD; its rms slope by finite "
            f"differences (roughfe info) is {rms_slope(load_surface(surface64)):.3g}") in lines
    wrote = [line for line in lines if line.startswith("wrote ")]
    assert wrote == ["wrote " + ", ".join(str(out / f) for f in (
        "results.json", "fields.h5", "contact_area_stiffness.png", "contact_render.png"))]


def test_design_targets_says_when_its_surface_is_of_another_scale(capsys):
    """A 79 um 2D window as the target of a 0.85 mm profile database gave s = 0.08 with no
    word of why (a user's review): the dimension and the size ratio are said; a profile
    of the database's length is not warned of."""
    from argparse import Namespace

    from roughfe.cli.plausibility import check_target_surface
    from roughfe.genomics.database import DatabaseSettings
    from roughfe.surfaces.spectral import spectral_profile, spectral_surface
    settings = DatabaseSettings(length=8.4942e-4, n_nodes=128)
    args = Namespace(command="design-targets")
    check_target_surface(args, spectral_surface(32, 7.9e-5, 0.8, rms_height=1e-7, rng=0),
                         settings)
    err = capsys.readouterr().err
    assert "a 2D surface gives targets to a profile database (dim 1)" in err
    assert f"{8.4942e-4 / 7.9e-5:.3g}x shorter than the database length" in err
    check_target_surface(args, spectral_profile(128, 8.4942e-4, 0.8, rms_height=1e-6, rng=0),
                         settings)
    assert capsys.readouterr().err == ""


def test_a_design_target_falling_with_load_is_warned_of(capsys):
    """A K(p) target whose rows (1e6, 1e5, 1e8 Pa) were sorted so that K fell between 1e5
    and 1e6 Pa was taken without a word (a user's review); a rising one is quiet."""
    from argparse import Namespace

    from roughfe.cli.plausibility import check_target_curve
    from roughfe.genomics.similarity import Target
    args = Namespace(command="design")
    check_target_curve(args, Target([1e6, 1e5, 1e8], [1e10, 2e10, 5e10], "K", "unsorted"))
    err = capsys.readouterr().err
    assert ("target unsorted: K falls with the load at 1 of its 2 intervals (first from "
            "2e+10 at p = 1e+05 Pa to 1e+10 at 1e+06 Pa") in err
    check_target_curve(args, Target([1e5, 1e6, 1e8], [1e10, 2e10, 5e10], "K", "sorted"))
    assert capsys.readouterr().err == ""


def test_leak_warns_of_percolation_through_a_molecular_gap(capsys):
    """A channel whose critical gap is 0.3 Angstrom was counted as open without a word (a
    user's review: x3p-2 at 1 GPa); it is said, with its step and direction; a closed
    direction and a nanometre-wide gap are not."""
    from argparse import Namespace

    from roughfe.cli.plausibility import check_critical_gaps
    steps = [{"step": 0, "percolates_x": True, "critical_gap_x": 5e-9,
              "percolates_y": True, "critical_gap_y": 2e-9},
             {"step": 1, "percolates_x": True, "critical_gap_x": 3e-11,
              "percolates_y": False, "critical_gap_y": None}]
    check_critical_gaps(Namespace(command="leak"), steps)
    err = capsys.readouterr().err
    assert "step 1 (x: 3e-11 m) percolates through a critical gap below 1e-09 m" in err
    assert err.count("warning") == 1


def test_adhesive_contact_of_a_strip_is_written_without_a_stickiness(tmp_path, capsys):
    """A 2 x N non-periodic strip has no rms curvature: the Pastewka-Robbins criterion
    raised after the adhesive solve, which was then lost (exit 2, nothing written; a
    user's review). Now the results are written and the criterion is said not evaluated."""
    h = np.random.default_rng(0).normal(size=(2, 64)) * 1e-8
    np.save(tmp_path / "strip.npy", h)
    assert main(["contact", str(tmp_path / "strip.npy"), "--size", "1e-6", "3.2e-5",
                 "--adhesion", "exp", "--work-of-adhesion", "0.01", "--range", "1e-8",
                 "--steps", "2", "--no-figures", "-o", str(tmp_path / "s")]) == 0
    assert "stickiness not evaluated" in capsys.readouterr().out
    doc = json.loads((tmp_path / "s" / "results.json").read_text())
    assert doc["derived"]["stickiness"]["evaluated"] is False
    assert "curvature" in doc["derived"]["stickiness"]["why"]
    assert all(s["mean_pressure"] is not None for s in doc["steps"])


def test_the_adhesive_unloading_can_be_traced_further(tmp_path, capsys):
    """An unloading branch that ends attached gave a pull-off "NOT detached: a bound"
    with no way on the command line to trace further (a user's review): the message
    names --max-unload-steps, which reaches the separation, and the flag is refused
    without --adhesion --unload."""
    from roughfe.surfaces.io import save_surface
    from roughfe.surfaces.spectral import spectral_surface
    s = spectral_surface(32, 1e-5, 0.8, rms_height=1e-8, q_roll=4 * np.pi / 1e-5,
                         q_short=16 * np.pi / 1e-5, rng=3)
    save_surface(s, tmp_path / "s.npz")
    args = ["contact", str(tmp_path / "s.npz"), "--E", "1e6", "--nu", "0.5", "--adhesion",
            "exp", "--work-of-adhesion", "0.01", "--range", "5e-8", "--steps", "2",
            "--unload", "--no-figures"]
    assert main(args + ["--max-unload-steps", "1", "-o", str(tmp_path / "a")]) == 0
    assert "NOT detached: a bound; trace further with --max-unload-steps" in \
        capsys.readouterr().out
    assert main(args + ["--max-unload-steps", "16", "-o", str(tmp_path / "b")]) == 0
    assert "(detached)" in capsys.readouterr().out
    assert main(["contact", str(tmp_path / "s.npz"), "--steps", "2", "--max-unload-steps",
                 "3", "-o", str(tmp_path / "c")]) == 2
    assert "needs --adhesion and --unload" in capsys.readouterr().err
