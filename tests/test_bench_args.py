"""benchmarks/*: a script's command line is read by one function (_report.script_args):
``--help`` prints the script's usage and exits 0, a wrong argument exits 2 naming it
(``bench_bands.py --help`` was a ValueError traceback from ``int('--help')``)."""
import subprocess
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"
SCRIPTS = ["bench_adhesion.py", "bench_bands.py", "bench_fem.py", "bench_fsi.py",
           "bench_reynolds.py", "bench_sequencing.py", "bench_surface_design.py",
           "bench_design_global.py"]


def _args():
    sys.path.insert(0, str(BENCH))
    try:
        import _report
    finally:
        sys.path.remove(str(BENCH))
    return _report.script_args


def test_integers_and_flags_are_read_in_order():
    script_args = _args()
    assert script_args("doc", ["2048", "--no-coupled", "512"], flags=("--no-coupled",)) == \
        ([2048, 512], {"--no-coupled"})
    assert script_args("doc", []) == ([], set())
    assert script_args("doc", ["film", "volume"], words=("volume", "film")) == \
        (["film", "volume"], set())


@pytest.mark.parametrize("argv, said", [(["12x"], "'12x'"), (["--fast"], "'--fast'"),
                                         (["1", "2", "3"], "at most 2")])
def test_a_wrong_argument_exits_2_naming_it(argv, said, capsys):
    with pytest.raises(SystemExit) as e:
        _args()("doc", argv, max_ints=2)
    assert e.value.code == 2 and said in capsys.readouterr().err


def test_a_wrong_word_names_the_allowed_ones(capsys):
    with pytest.raises(SystemExit) as e:
        _args()("doc", ["gas"], words=("volume", "film"))
    err = capsys.readouterr().err
    assert e.value.code == 2 and "'gas'" in err and "volume, film" in err


@pytest.mark.parametrize("script", SCRIPTS)
def test_help_prints_the_usage_and_exits_0(script):
    run = subprocess.run([sys.executable, str(BENCH / script), "--help"], capture_output=True,
                         text=True, timeout=120)
    assert run.returncode == 0, run.stderr[-2000:]
    assert "Run:" in run.stdout and "Traceback" not in run.stderr


def test_a_non_integer_size_exits_2_without_a_traceback():
    run = subprocess.run([sys.executable, str(BENCH / "bench_bands.py"), "big"],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 2 and "Traceback" not in run.stderr
    assert "bench_bands.py: expected integer arguments, got 'big'" in run.stderr


def test_help_into_a_closed_pipe_exits_141_quietly():
    """`bench_bands.py --help | head -1`: the rest of the usage goes nowhere, no
    BrokenPipeError traceback (as the roughfe CLI). The pipe is closed before the
    script writes, so the case is deterministic."""
    import os
    r, w = os.pipe()
    os.close(r)
    try:
        run = subprocess.run([sys.executable, str(BENCH / "bench_bands.py"), "--help"],
                             stdout=w, stderr=subprocess.PIPE, text=True, timeout=120)
    finally:
        os.close(w)
    assert run.returncode == 141 and "Traceback" not in run.stderr, run.stderr[-500:]
