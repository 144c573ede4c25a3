"""What fuzzing the command line found (round 2, session 33; the script is in the session's
notes): extreme or out-of-range option values that ended in a Python traceback, ran for
minutes, or were refused in the library's words. Each test fails on the code before its
fix: one line ``roughfe CMD: error: ...`` naming the value and what is allowed, exit 2."""
import shutil
from pathlib import Path

import pytest

from roughfe.cli import main

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "studies"


@pytest.fixture
def surface32(tmp_path):
    path = tmp_path / "s32.npz"
    assert main(["generate", "spectral", "--n", "32", "--seed", "1", "--no-figures",
                 "-o", str(path)]) == 0
    return path


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
             "hurst_range must be 0 < low <= high <= 3", "1e+308")
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
