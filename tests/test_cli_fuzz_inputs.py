"""What fuzzing the command line found (round 2, session 33; the script is in the session's
notes): extreme or out-of-range option values that ended in a Python traceback, ran for
minutes, or were refused in the library's words. Each test fails on the code before its
fix: one line ``roughfe CMD: error: ...`` naming the value and what is allowed, exit 2."""
import shutil
from pathlib import Path

import pytest

from roughfe.cli import main

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "studies"


def _refused(capsys, argv, *phrases):
    """``roughfe ARGV`` exits 2 with one error line holding every phrase, no traceback."""
    capsys.readouterr()
    assert main(argv) == 2
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if ": error: " in line]
    assert len(lines) == 1, err
    for phrase in phrases:
        assert phrase in lines[0], (phrase, lines[0])
    return lines[0]


def test_workers_beyond_a_c_int_are_refused_by_the_runner(tmp_path, capsys):
    # was: OverflowError "Python int too large to convert to C int" from multiprocessing
    # (study run, leak-study, db build, db extend: all through the runner's one check)
    spec = tmp_path / "selftest.toml"
    shutil.copy(EXAMPLES / "selftest.toml", spec)
    _refused(capsys, ["study", "run", str(spec), "-o", str(tmp_path / "st"), "--workers",
                      "99999999999"], "workers must be an integer in 1..1024",
             "99999999999")
    assert not (tmp_path / "st").exists()


def test_rmd_levels_are_checked_before_the_grid_is_sized(tmp_path, capsys):
    # was: 2 ** m computed first (10^11 levels ran for minutes; 20000 levels: a ValueError
    # traceback converting the 6021-digit point count to text for the memory message)
    for m in ("20000", "99999999999"):
        _refused(capsys, ["generate", "rmd", "--m", m, "--no-figures",
                          "-o", str(tmp_path / "r.npz")], "1 <= m <= 13", m)
    _refused(capsys, ["generate", "rmd", "--profile", "--m", "25", "--no-figures",
                      "-o", str(tmp_path / "r.npz")], "1 <= m <= 24", "25")


def test_mwm_wavelength_far_beyond_the_window_is_refused(tmp_path, capsys):
    # was: OverflowError (cannot convert float infinity to integer) in the default range
    _refused(capsys, ["generate", "mwm", "--n", "32", "--wavelength", "1e308", "--no-figures",
                      "-o", str(tmp_path / "w.npz")], "wavelength lambda 1e+308 m",
             "1e+06 times the length")


def test_spectral_rms_slope_beyond_the_float_range_is_refused(tmp_path, capsys):
    # was: OverflowError (34, 'Numerical result out of range') computing C0
    _refused(capsys, ["generate", "spectral", "--n", "32", "--rms-slope", "1e308",
                      "--no-figures", "-o", str(tmp_path / "s.npz")], "rms_slope = 1e+308")


def test_adhesion_range_whose_traction_underflows_is_refused(surface32, tmp_path, capsys):
    # was: ZeroDivisionError in the process zone (pi/4) E* w / sigma0^2 (sigma0 = 1e-310)
    for cmd in (["contact", "--steps", "2"], ["leak", "--delta", "1e-7"]):
        _refused(capsys, [cmd[0], str(surface32), *cmd[1:], "--adhesion", "md",
                          "--work-of-adhesion", "0.01", "--range", "1e308", "--no-figures",
                          "-o", str(tmp_path / "a")], "range = 1e+308", "w / range")


def test_negative_approach_is_said_in_the_commands_flags(surface32, tmp_path, capsys):
    # leak said the library's words: "deltas[0] = ... (response(..., adhesion=law))"
    for cmd in ("contact", "leak"):
        line = _refused(capsys, [cmd, str(surface32), "--delta", "1e-7", "-2e-7",
                                 "--no-figures", "-o", str(tmp_path / "n")],
                        "--delta[1] = -2e-07 m", "--adhesion")
        assert "response(" not in line and "deltas[" not in line


def test_an_implausible_approach_is_named_with_its_sign(surface32, tmp_path, capsys):
    # said "approach 1 m" for --delta -1 (the magnitude that the check compares)
    _refused(capsys, ["contact", str(surface32), "--delta", "-1", "--no-figures",
                      "-o", str(tmp_path / "d")], "approach -1 m")


def test_sequencing_tolerance_is_a_fraction(tmp_path, capsys):
    # was: OverflowError squaring --tolerance 1e308; a relative rms error >= 1 lets any
    # profile pass as WM-like
    acq = []
    assert main(["genome", "example", "-o", str(tmp_path / "g.json")]) == 0
    for scale in ("10x", "20x"):
        acq.append(str(tmp_path / f"a{scale}.npz"))
        assert main(["genome", "realize", str(tmp_path / "g.json"), "--scale", scale,
                     "--nodes", "256", "-o", acq[-1]]) == 0
    for value in ("1e308", "1"):
        _refused(capsys, ["genome", "sequence", *acq, "--tolerance", value, "--no-figures",
                          "-o", str(tmp_path / "q")], "--tolerance", "(0, 1)", value)


def test_db_build_hurst_range_is_checked_against_the_genome_range(tmp_path, capsys):
    # was: for HI = 1e308 a failed task whose error line printed the whole task; and
    # LO == HI (one H), accepted by the check, a scipy ValueError traceback (qmc.scale)
    _refused(capsys, ["db", "build", str(tmp_path / "d.sqlite"), "--limit", "1", "--nodes",
                      "64", "--steps", "5", "--workers", "1", "--hurst-range", "1", "1e308"],
             "hurst_range high (the genome's H) must lie in (0, 3]", "1e+308")
    assert main(["db", "build", str(tmp_path / "h.sqlite"), "--limit", "2", "--nodes", "64",
                 "--steps", "5", "--workers", "1", "--hurst-range", "0.8", "0.8",
                 "--quiet"]) == 0
    from roughfe.genomics.database import load_entries
    entries = load_entries(tmp_path / "h.sqlite")
    assert len(entries) == 2 and all(e.hurst == 0.8 for e in entries)


def test_a_memory_error_without_text_is_still_said(monkeypatch, tmp_path, capsys):
    # Python's own MemoryError has no text: the line read "not enough memory ()"
    import roughfe.cli.surface_cmds as cmds

    def exhausted(args):
        raise MemoryError()
    monkeypatch.setattr(cmds, "_generate", exhausted)
    line = _refused(capsys, ["generate", "wm", "--no-figures", "-o", str(tmp_path / "m.npz")],
                    "not enough memory (an allocation failed)")
    assert "()" not in line


def test_fem_contact_refuses_grid_check_before_it_solves(tmp_path, capsys):
    # was refused after the whole FEM sweep had run (6-10 s; the refusal came from the
    # grid check that follows the sweep)
    path = tmp_path / "p.npz"
    assert main(["generate", "wm", "--n", "256", "--seed", "1", "--no-figures",
                 "-o", str(path)]) == 0
    _refused(capsys, ["contact", str(path), "--method", "fem", "--grid-check", "--steps", "2",
                      "--no-figures", "-o", str(tmp_path / "f")],
             "--method fem does not take --grid-check")
    assert not (tmp_path / "f").exists()


def test_dolfinx_import_leaves_warnings_to_warnings(tmp_path):
    # importing ffcx (with dolfinx) calls logging.captureWarnings(True): roughfe's warnings
    # of `contact --method fem` were printed as "WARNING:py.warnings:FILE:LINE: ..." and a
    # source line, past the command's one-line printer
    import subprocess
    import sys
    code = ("import warnings; from roughfe.fem.petsc_tools import ensure_jit_cache; "
            "ensure_jit_cache(); import dolfinx, dolfinx.fem.petsc; "
            "print(warnings.showwarning.__module__)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=tmp_path, check=True).stdout.split()
    assert out == ["warnings"]


def test_db_build_does_not_take_over_a_small_file_of_other_content(tmp_path, capsys):
    # SQLite took a 1-byte file for an empty database and wrote a genome database over it
    notes = tmp_path / "notes"
    notes.write_bytes(b"x")
    _refused(capsys, ["db", "build", str(notes), "--limit", "1", "--nodes", "64", "--steps",
                      "5", "--workers", "1"], "not an SQLite file", "give a new file name")
    assert notes.read_bytes() == b"x" and not (tmp_path / "notes.study").exists()


@pytest.mark.parametrize("size", ["1e-300", "1e300"])
def test_a_lateral_size_outside_any_topography_is_refused(surface32, capsys, size):
    # 1e-300 m: a ValueError traceback from np.bincount (the PSD); 1e300 m: rms slope
    # exactly 0 and Nayak alpha null (the squares underflow), exit 0
    _refused(capsys, ["info", str(surface32), "--size", size, "--json"],
             f"size[0] = {float(size):g} m", "1e-15 m to 1e+06 m")


@pytest.mark.parametrize("model", ["rmd", "wm", "mwm"])
def test_generate_checks_the_length_before_it_generates(tmp_path, capsys, model):
    # --length 1e308: "heights must be finite: ... = nan" (rmd: "size[0] ... got inf")
    _refused(capsys, ["generate", model, "--length", "1e308", "--no-figures",
                      "-o", str(tmp_path / "g.npz")], "--length 1e+308 m", "1e-15 m to 1e+06 m")


def test_leak_study_length_is_checked_before_the_tasks_run(tmp_path, capsys):
    # --length 1e308 failed every task on the workers: "no task of the study ... finished"
    _refused(capsys, ["leak-study", "--D", "2.3", "--m", "3", "--surfaces", "1", "--steps",
                      "2", "--workers", "1", "--length", "1e308", "--no-figures",
                      "-o", str(tmp_path / "ls")], "1e+308 m is no lateral size", "'L': 1e+308")


def test_a_study_task_refused_says_the_reason_first(tmp_path, capsys):
    # the line was "analysis 'leakage', task {...every parameter...}: D ... got 3.0"
    line = _refused(capsys, ["leak-study", "--D", "3", "--m", "3", "--surfaces", "1",
                             "--steps", "2", "--workers", "1", "--no-figures",
                             "-o", str(tmp_path / "ls")], "got 3.0")
    assert line.startswith("roughfe leak-study: error: D (fractal dimension) must lie")


@pytest.mark.parametrize("cmd", ["mechanics", "natural"])
def test_genome_curves_need_three_steps(tmp_path, capsys, cmd):
    # K(p) is differenced over the steps: 2 ended in "response curve stiffness has
    # non-finite values: [nan nan]", 1 in "... need the same length >= 2, got 1, 1, 1"
    _refused(capsys, ["genome", cmd, str(tmp_path / "any"), "--steps", "2",
                      "-o", str(tmp_path / "o")], "--steps", "an integer >= 3", "'2'")


def test_validity_with_a_million_ridges_is_refused_at_once(tmp_path):
    # ran for days (M = 2 .. 10^6, pair arrays of M^2 / 2 per M); in a subprocess with a
    # timeout, so that a regression fails instead of hanging
    import subprocess
    import sys
    proc = subprocess.run([sys.executable, "-m", "roughfe", "genome", "validity", "--trials",
                           "10", "--max-ridges", "1000000", "-o", str(tmp_path / "v.png")],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    # session 33: the memory check of the largest M; session 34: the option's bound first
    assert "argument --max-ridges: must be an integer in 2..500, got '1000000'" in proc.stderr


def test_ctrl_c_while_the_command_loads_is_one_line_and_exit_130(tmp_path):
    # a Ctrl-C in the first 0.1-0.5 s (numpy, scipy and the command's modules importing)
    # was a KeyboardInterrupt traceback and exit 1 or -2: the command line now imports no
    # numpy itself, and main() catches it while it builds the command's parser
    import subprocess
    import sys
    code = ("import sys, roughfe.cli as c; numpy = 'numpy' in sys.modules\n"
            "def boom(command=None): raise KeyboardInterrupt\n"
            "c.build_parser = boom; rc = c.main(['info', 'x.npz']); print(numpy, rc)")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=tmp_path, timeout=120)
    assert proc.stdout.split() == ["False", "130"]
    assert proc.stderr == "roughfe: interrupted\n"


def test_leak_study_with_no_finished_task_says_the_first_error(tmp_path, monkeypatch, capsys):
    # said only "no task of the study ... finished; see `roughfe study status ...`" (found
    # with --E 1e308, now refused by the option; the leak options that failed every task
    # are checked before submitting): here the spawned workers die importing the BEM (a
    # bad ROUGHFE_THREADS that this process, which imported it, never reads again)
    import roughfe.bem._parallel  # noqa: F401
    monkeypatch.setenv("ROUGHFE_THREADS", "none")
    line = _refused(capsys, ["leak-study", "--D", "2.3", "--m", "3", "--surfaces", "1",
                             "--steps", "2", "--workers", "1", "--no-figures",
                             "-o", str(tmp_path / "ls")], "no task of the study", "(task 0: ")
    assert "worker lost" in line


def test_leak_study_checks_the_span_of_its_rmd_surfaces(tmp_path, capsys):
    # --length 1e6 passed the size check of L, but the RMD surface spans (2^m + 1) / 2^m L:
    # every task failed on the workers ("size[0] = 1.125e+06 m is no lateral size")
    _refused(capsys, ["leak-study", "--D", "2.3", "--m", "3", "--surfaces", "1", "--steps",
                      "2", "--workers", "1", "--length", "1e6", "--no-figures",
                      "-o", str(tmp_path / "ls")], "L = 1e+06 m with m = 3",
             "spans (2^m + 1) / 2^m L = 1.125e+06 m")
    assert not (tmp_path / "ls").exists()


def test_generate_interrupted_while_drawing_leaves_no_old_figure(tmp_path, monkeypatch,
                                                                 capsys):
    # generate --overwrite stopped by Ctrl-C while it drew the figure left the replaced
    # surface's PNG beside the new .npz (whose metadata names that PNG as its figure)
    out = tmp_path / "w.npz"
    assert main(["generate", "wm", "--n", "256", "--seed", "1", "-o", str(out)]) == 0
    assert (tmp_path / "w.png").is_file()
    import roughfe.plotting.surfaces as plots

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt
    monkeypatch.setattr(plots, "plot_profile", interrupted)
    assert main(["generate", "wm", "--n", "256", "--seed", "2", "-o", str(out),
                 "--overwrite"]) == 130
    from roughfe.surfaces.io import load_surface
    assert load_surface(out).metadata["seed"] == 2         # the new surface, complete
    assert not (tmp_path / "w.png").exists()                # and no picture of the old one


def test_renders_hold_ctrl_c_until_the_picture_is_drawn(tmp_path):
    # Ctrl-C inside vtk (generate rmd --m 11 at 1.5-1.75 s) was an ImportError traceback,
    # a ValueError from an empty mesh (vtk swallows the KeyboardInterrupt of its Python
    # callback) or a segmentation fault: every pyvista render holds it until it returns
    import signal

    from roughfe.plotting import bands, common, contact, fem, leakage, surfaces
    for render in (surfaces.render_surface, contact.render_contact, leakage.network_map,
                   leakage.pressure_map, leakage.flux_map, bands.render_band_sums,
                   fem._render):
        assert render.__wrapped__, render           # decorated with holds_interrupts
    steps = []

    @common.holds_interrupts
    def drawing():
        signal.raise_signal(signal.SIGINT)           # Ctrl-C in the middle of the render
        steps.append("after the signal")
        return "picture"
    with pytest.raises(KeyboardInterrupt):
        drawing()
    assert steps == ["after the signal"]             # the render finished first
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


# -- round 2, session 34: the leftovers of the session 33 fuzzing ---------------------------
@pytest.mark.parametrize("cmd", [
    ["contact", "S", "--steps", "2", "--no-figures", "-o", "OUT"],
    ["leak", "S", "--delta", "1e-7", "--no-figures", "-o", "OUT"],
    ["genome", "mechanics", "G", "--steps", "3", "--no-figures", "-o", "OUT"],
    ["genome", "chromosomes", "S", "--steps", "3", "--no-figures", "-o", "OUT"],
    ["leak-study", "--m", "3", "--surfaces", "1", "--workers", "1", "--no-figures", "-o", "OUT"],
    ["db", "build", "OUT", "--limit", "1", "--nodes", "64", "--steps", "5", "--workers", "1"]])
@pytest.mark.parametrize("value", ["1e308", "1e-300", "-1e9"])
def test_youngs_modulus_outside_any_material_is_refused_by_the_option(surface32, tmp_path,
                                                                      capsys, cmd, value):
    # 1e308 / 1e-300 overflowed or underflowed the pressures: a solver non-convergence line
    # ("Polonsky-Keer CG ... did not converge") that did not name E, after the work began
    genome = tmp_path / "g.json"
    assert main(["genome", "example", "-o", str(genome)]) == 0
    out = tmp_path / "out"
    files = {"S": str(surface32), "G": str(genome), "OUT": str(out)}
    _refused(capsys, [files.get(a, a) for a in cmd] + ["--E", value],
             "argument --E", "from 0.001 Pa to 1e+15 Pa", repr(value))
    assert not out.exists()


@pytest.mark.parametrize("E", ["1e-3", "1e15"])
def test_the_youngs_modulus_range_is_solved_at_both_ends(surface32, tmp_path, capsys, E):
    # the solver solves p / E*: A* of an approach does not depend on E*, and p scales with
    # it, at both ends of the admitted range as at the default 210 MPa
    import json
    runs = {}
    for e in (E, "2.1e8"):
        out = tmp_path / f"c{e}"
        assert main(["contact", str(surface32), "--delta", "2e-7", "--E", e, "--no-figures",
                     "--quiet", "-o", str(out)]) == 0
        runs[e] = json.loads((out / "results.json").read_text())["steps"][0]
    assert runs[E]["area_fraction"] == pytest.approx(runs["2.1e8"]["area_fraction"],
                                                     rel=1e-9)
    assert runs[E]["mean_pressure"] / float(E) == pytest.approx(
        runs["2.1e8"]["mean_pressure"] / 2.1e8, rel=1e-6)


@pytest.mark.parametrize("model, option, value, phrase", [
    ("rmd", "--rms-height", "1e308", "--rms-height 1e+308 m: allowed are 1e-15 m to 1e+06 m"),
    ("wm", "--rms-height", "1e308", "--rms-height 1e+308 m: allowed are"),
    ("mwm", "--rms-height", "1e-300", "--rms-height 1e-300 m: allowed are"),
    ("spectral", "--rms-height", "1e200", "--rms-height 1e+200 m: allowed are"),
    ("wm", "--amplitude", "1e308", "--amplitude 1e+308 m: the heights overflow"),
    ("wm", "--amplitude", "1e200", "--amplitude 1e+200 m gives heights of rms inf m"),
    ("mwm", "--amplitude", "1e308", "--amplitude 1e+308 m^(1-H) gives heights of rms inf m"),
    ("mwm", "--amplitude", "1e-300", "--amplitude 1e-300 m^(1-H) gives heights of rms 0 m")])
def test_generate_names_the_height_option_that_leaves_the_range(tmp_path, capsys, model,
                                                                 option, value, phrase):
    # was "heights must be finite: ... = inf" (naming no option); mwm --amplitude 1e308,
    # wm --amplitude 1e200 and every 1e-300 wrote a file of rms height inf or 0, exit 0.
    # Seeded: which of the two refusals wm --amplitude 1e308 meets depends on the phases
    # (heights that overflow, or finite ones of rms inf: 1 run in ~10 unseeded)
    out = tmp_path / "g.npz"
    _refused(capsys, ["generate", model, "--n", "64", option, value, "--no-figures",
                      "--seed", "0", "-o", str(out)] if model != "rmd" else
             ["generate", model, "--m", "5", option, value, "--no-figures", "--seed", "0",
              "-o", str(out)], phrase)
    assert not out.exists()


def test_counts_that_build_a_list_first_are_bounded(tmp_path, capsys):
    # a list of 10^11 replicas (leak-study) or ridge counts (validity) was built before any
    # check: "not enough memory (an allocation failed)", naming no option
    _refused(capsys, ["leak-study", "--surfaces", "99999999999", "--workers", "1",
                      "-o", str(tmp_path / "ls")],
             "n_surfaces", "--surfaces", "1..10000", "99999999999")
    assert not (tmp_path / "ls").exists()
    _refused(capsys, ["genome", "validity", "--max-ridges", "99999999999",
                      "-o", str(tmp_path / "v.png")],
             "argument --max-ridges", "an integer in 2..500", "'99999999999'")
    from roughfe.errors import InputError
    from roughfe.genomics.chromosomes import validity_monte_carlo
    with pytest.raises(InputError, match="M = 99999999999 ridges x 10 trials needs"):
        validity_monte_carlo(range(2, 10 ** 11), 10, rng=0)   # the library: sized first


@pytest.fixture(scope="module")
def tiny_db(tmp_path_factory):
    path = tmp_path_factory.mktemp("db") / "db.sqlite"
    assert main(["db", "build", str(path), "--nodes", "64", "--steps", "5", "--limit", "2",
                 "--quiet", "--workers", "1"]) == 0
    return path


@pytest.mark.parametrize("option, bound", [("--iterations", "1..100"), ("--refine", "0..100"),
                                           ("--search", "0..100000"),
                                           ("--search-starts", "1..100")])
def test_design_stage_budgets_are_bounded(tmp_path, capsys, option, bound):
    # ran as asked: 99999999999 GCMMA iterations / rounds / sweeps / starts (no upper bound)
    extra = ["--search", "5"] if option == "--search-starts" else []
    _refused(capsys, ["design", "--db", str(tmp_path / "none.sqlite"), "--target", "y_t1",
                      "--method", "sog", *extra, option, "99999999999", "-o",
                      str(tmp_path / "d")], f"argument {option}", f"an integer in {bound}",
             "'99999999999'")


def test_design_target_pressure_far_beyond_e_star_is_refused(tiny_db, tmp_path, capsys):
    # 1e308: "dense bpp did not converge: relative KKT residual inf" after the stages ran;
    # 1e20: a design of rms slope 4.5e12 written, exit 0
    for value in ("1e308", "1e20"):
        _refused(capsys, ["design", "--db", str(tiny_db), "--target", "y_t1", "--method", "sog",
                          "--iterations", "1", "--target-p-top", value, "--no-figures",
                          "-o", str(tmp_path / "d")],
                 f"--target-p-top {float(value):g} Pa", "at most 1000 x E*", "2.1e+08 Pa")
    assert not (tmp_path / "d").exists()


@pytest.mark.parametrize("extra", [["--resolution", "full"], ["--size", "1e-4"],
                                   ["--detrend", "none"], ["--boundary", "window"],
                                   ["--non-periodic"], ["--channel", "1"],
                                   ["--scan-axis", "y"]])
def test_design_targets_options_of_a_surface_need_the_surface(tiny_db, tmp_path, capsys,
                                                              extra):
    # accepted silently: the thesis' targets were written and the option ignored
    flag = "--periodic/--non-periodic" if extra == ["--non-periodic"] else extra[0]
    _refused(capsys, ["design-targets", "--db", str(tiny_db), *extra, "-o",
                      str(tmp_path / "t")], f"{flag} needs --surface FILE", "means nothing")
    assert not (tmp_path / "t").exists()


def test_design_surface_file_options_need_match_spectrum(tmp_path, capsys):
    _refused(capsys, ["design", "--db", str(tmp_path / "none.sqlite"), "--target", "y_t1",
                      "--method", "sog", "--size", "1e-4", "-o", str(tmp_path / "d")],
             "--size needs --match-spectrum SURFACE", "means nothing")


def test_a_killed_writers_temporary_is_removed_by_the_next_write(tmp_path, capsys):
    # SIGKILL during a single-file write (generate) left its hidden .roughfe-*.tmp.npz
    # beside the output for ever; a live writer's temporary must stay
    import signal
    import subprocess
    import sys
    writer = ("import os, sys, time; from pathlib import Path; "
              "from roughfe.writers import atomic_path\n"
              "with atomic_path(Path(sys.argv[1])) as tmp:\n"
              "    tmp.write_bytes(b'half'); print(tmp.name, flush=True)\n"
              "    time.sleep(float(sys.argv[2])) if sys.argv[2] != 'kill' else "
              "os.kill(os.getpid(), 9)\n")
    live = subprocess.Popen([sys.executable, "-c", writer, str(tmp_path / "b.npz"), "60"],
                            stdout=subprocess.PIPE, text=True)
    try:        # each writer clears the folder once: the live one first, then the killed
        alive = tmp_path / live.stdout.readline().strip()
        killed = subprocess.run([sys.executable, "-c", writer, str(tmp_path / "a.npz"),
                                 "kill"], capture_output=True, text=True, timeout=120)
        assert killed.returncode == -signal.SIGKILL
        dead = tmp_path / killed.stdout.strip()
        old_form = tmp_path / ".roughfe-15jb_9h0.tmp.npz"     # no pid: not judged
        old_form.write_bytes(b"x")
        assert dead.is_file() and alive.is_file() and not (tmp_path / "a.npz").exists()
        assert main(["generate", "wm", "--n", "64", "--no-figures",
                     "-o", str(tmp_path / "c.npz")]) == 0
        assert not dead.exists()
        assert alive.is_file() and old_form.is_file()
    finally:
        live.kill()
        live.wait()


@pytest.mark.parametrize("model", ["wm", "mwm"])
def test_wm_amplitude_overflow_is_one_error_line_without_numpy_warnings(tmp_path, capsys,
                                                                        model):
    # wm --amplitude 1e308 printed three numpy warnings (overflow in reduce and matmul,
    # invalid value in subtract) before its error line (round 2, session 34)
    capsys.readouterr()
    out = tmp_path / "g.npz"
    assert main(["generate", model, "--n", "64", "--amplitude", "1e308", "--no-figures",
                 "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--amplitude 1e+308" in err, err
    assert "warning" not in err and not out.exists()


@pytest.mark.parametrize("option, bound", [("--global-eval", "2..1000000"),
                                           ("--global-popsize", "0..10000"),
                                           ("--global-candidates", "1..100"),
                                           ("--global-rounds", "1..100")])
def test_design_global_budgets_are_bounded(tmp_path, capsys, option, bound):
    # ran as asked: 99999999999 evaluations / population / candidates / rounds (no upper
    # bound; the stage budgets got theirs in 9a415d2)
    _refused(capsys, ["design", "--db", str(tmp_path / "none.sqlite"), "--target", "y_t1",
                      "--method", "mcco", "--global", "cmaes", option, "99999999999", "-o",
                      str(tmp_path / "d")], f"argument {option}", f"an integer in {bound}",
             "'99999999999'")


@pytest.mark.parametrize("option, bound", [("--spectrum-starts", "0..100"),
                                           ("--pool", "0..100")])
def test_design_spectrum_starts_and_pool_are_bounded(tmp_path, capsys, option, bound):
    # ran as asked: 99999999999 spectrum-matched starts / pool genomes (round 2, session 34)
    _refused(capsys, ["design", "--db", str(tmp_path / "none.sqlite"), "--target", "y_t1",
                      "--method", "mcco", option, "99999999999", "-o",
                      str(tmp_path / "d")], f"argument {option}", f"an integer in {bound}",
             "'99999999999'")
