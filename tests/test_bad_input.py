"""The bad-input table of issue 11 sec. 4: every case is one line on stderr, exit code 2,
no traceback and nothing written (the folder is byte-for-byte as before)."""
import hashlib
import json
import sqlite3

import numpy as np
import pytest

from roughfe.cli import main
from roughfe.errors import available_memory
from roughfe.genomics.genome import save_genome, table1_genome
from roughfe.surfaces import Surface
from roughfe.surfaces.io import save_surface


def _surface(tmp_path, periodic=True, n=16, length=1e-4):
    x = np.arange(n) * length / n
    h = 1e-6 * np.cos(2 * np.pi * x / length)[:, None] * np.cos(4 * np.pi * x / length)[None, :]
    return save_surface(Surface(h, length, periodic=periodic), tmp_path / "s.npz")


def _genome_with(tmp_path, **changes):
    path = save_genome(table1_genome(rng=0, n_max=6), tmp_path / "g.json")
    data = json.loads(path.read_text())
    data.update(changes)
    path.write_text(json.dumps(data))
    return path


def _truncated_npz(t):
    p = _surface(t)
    data = p.read_bytes()
    p.write_bytes(data[: len(data) // 2])
    return ["info", str(p)], "truncated or not a zip archive"


def _output_is_a_file(t):
    (t / "out.txt").write_text("mine")
    return ["contact", str(_surface(t)), "-o", str(t / "out.txt")], "is an existing file"


def _output_not_writable(t):
    return (["contact", str(_surface(t)), "-o", "/proc/roughfe-nowhere/out"],
            "cannot create or write output folder")


def _output_foreign_folder(t):
    (t / "o").mkdir()
    (t / "o" / "thesis.tex").write_text("precious")
    return ["contact", str(_surface(t)), "-o", str(t / "o")], "not a roughfe output folder"


def _generate_existing_file(t):
    (t / "x.npz").write_bytes(b"mine")
    return ["generate", "spectral", "--n", "8", "-o", str(t / "x.npz")], "pass --overwrite"


def _genome_example_existing_file(t):
    (t / "g.json").write_text("{}")
    return ["genome", "example", "-o", str(t / "g.json")], "pass --overwrite"


def _huge_grid(t):
    if available_memory() > 80 * 2 ** 30:
        pytest.skip("this machine has more than 74.5 GiB available")
    return ["generate", "spectral", "--n", "100000", "-o", str(t / "big.npz")], "needs 74.5 GiB"


def _genome_h_string(t):
    return (["genome", "realize", str(_genome_with(t, H="0.75")), "--scale", "10x",
             "-o", str(t / "r.npz")], "H must be a number")


def _genome_m_fraction(t):
    return (["genome", "realize", str(_genome_with(t, M=8.5)), "--scale", "10x",
             "-o", str(t / "r.npz")], "M must be an integer")


def _genome_h_bool(t):
    return (["genome", "realize", str(_genome_with(t, H=True)), "--scale", "10x",
             "-o", str(t / "r.npz")], "H must be a number")


def _npz_as_genome(t):
    return (["genome", "realize", str(_surface(t)), "--scale", "10x", "-o", str(t / "r.npz")],
            "not a genome JSON file")


def _steps_zero(t):
    return ["contact", str(_surface(t)), "--steps", "0", "-o", str(t / "o")], "integer >= 1"


def _periodic_and_non_periodic(t):
    return (["contact", str(_surface(t)), "--periodic", "--non-periodic", "-o", str(t / "o")],
            "not allowed with argument --periodic")


def _complex_heights(t):
    np.save(t / "c.npy", np.ones((8, 8)) * (1 + 1j) * 1e-6)
    return ["info", str(t / "c.npy"), "--size", "1e-4"], "complex"


def _db_list_foreign_sqlite(t):
    con = sqlite3.connect(t / "f.sqlite")
    con.execute("CREATE TABLE customers (name TEXT)")
    con.commit()
    con.close()
    return ["db", "list", str(t / "f.sqlite")], "not a roughfe genome database"


def _db_list_empty_sqlite(t):
    (t / "e.sqlite").write_bytes(b"")
    return ["db", "list", str(t / "e.sqlite")], "not a roughfe genome database"


def _channel_on_npz(t):
    return ["info", str(_surface(t)), "--channel", "1"], "--channel"


def _damaged_instrument_file(t):
    (t / "scan.x3p").write_text("garbage\n")            # content ST would read as a .hgt grid
    return ["info", str(t / "scan.x3p")], "is not a readable .x3p file"


def _study_into_a_foreign_folder(t):
    (t / "o").mkdir()
    (t / "o" / "results.json").write_text("{}")
    spec = t / "s.toml"
    spec.write_text('[study]\nanalysis = "selftest"\noutput = "o"\n[grid]\nx = [1.0]\n')
    return ["study", "run", str(spec), "-o", str(t / "o")], "not a study folder"


def _tol_zero(t):
    return ["contact", str(_surface(t)), "--tol", "0", "-o", str(t / "o")], "a number in (0, 1)"


def _empty_npy(t):
    (t / "e.npy").write_bytes(b"")
    return ["info", str(t / "e.npy"), "--size", "1e-4"], "empty"


def _directory_as_input(t):
    (t / "d.npz").mkdir()
    return ["info", str(t / "d.npz")], "is a folder"


def _db_build_workers_zero(t):
    return (["db", "build", str(t / "new.sqlite"), "--workers", "0", "--limit", "1"],
            "--workers: must be an integer >= 1")


def _negative_young_modulus(t):
    return (["contact", str(_surface(t)), "--E", "-1e9", "-o", str(t / "o")],
            "argument --E: must be a Young's modulus from 0.001 Pa to 1e+15 Pa, got '-1e9'")


def _negative_poisson_exponent(t):
    return (["contact", str(_surface(t)), "--nu", "-1.5e0", "-o", str(t / "o")], "nu")


def _leak_delta_and_pressure(t):
    return (["leak", str(_surface(t)), "--delta", "1e-7", "--pressure", "1e6", "-o",
             str(t / "o")], "not allowed with argument")


def _negative_seed(t):
    # the flag's own name and rule, where the library's message named its "rng" argument
    return (["generate", "spectral", "--n", "16", "--seed", "-1", "-o", str(t / "s.npz")],
            "--seed: must be an integer >= 0")


def _fractional_grid_size(t):
    return (["generate", "spectral", "--n", "3.5", "-o", str(t / "s.npz")],
            "--n: expected an integer >= 1")


def _two_point_grid(t):
    # a 2-point axis has only its Nyquist mode: "grid too small", not a wavenumber ordering
    return (["generate", "spectral", "--n", "2", "-o", str(t / "s.npz")],
            "grid too small: 2x2 points")


CASES = [_truncated_npz, _output_is_a_file, _output_not_writable, _output_foreign_folder,
         _generate_existing_file, _genome_example_existing_file, _huge_grid, _genome_h_string,
         _genome_m_fraction, _genome_h_bool, _npz_as_genome, _steps_zero,
         _periodic_and_non_periodic, _complex_heights, _db_list_foreign_sqlite,
         _db_list_empty_sqlite, _channel_on_npz, _damaged_instrument_file,
         _study_into_a_foreign_folder, _tol_zero,
         _empty_npy, _directory_as_input, _db_build_workers_zero, _negative_young_modulus,
         _negative_poisson_exponent, _leak_delta_and_pressure, _negative_seed,
         _fractional_grid_size, _two_point_grid]


def _snapshot(root):
    return {str(p.relative_to(root)): (p.is_dir() or hashlib.sha256(p.read_bytes()).hexdigest(),
                                       p.stat().st_mtime_ns)
            for p in root.rglob("*")}


@pytest.mark.parametrize("case", CASES, ids=[c.__name__.lstrip("_") for c in CASES])
def test_bad_input_is_one_clear_line_and_writes_nothing(case, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    argv, expected = case(tmp_path)
    before = _snapshot(tmp_path)
    capsys.readouterr()
    assert main(argv) == 2
    out, err = capsys.readouterr()
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "error:" in lines[0] and lines[0].startswith("roughfe"), err
    assert expected in lines[0], lines[0]
    assert "Traceback" not in err + out
    assert _snapshot(tmp_path) == before                       # nothing written or touched


def test_a_legal_249_character_output_name_works(tmp_path, capsys):
    out = tmp_path / ("a" * 245 + ".npz")                       # 249 bytes, + a PNG beside it
    assert main(["generate", "spectral", "--profile", "--n", "64", "--seed", "1",
                 "-o", str(out)]) == 0
    assert out.is_file() and out.with_suffix(".png").stat().st_size > 1000


def test_a_strain_far_beyond_the_half_space_is_warned(tmp_path, capsys):
    """Non-periodic 100 um patch at p = E*/2: Delta of tens of micrometres, a strain of
    ~0.4, a warning (the numbers are returned: the half-space model is solved as asked).
    A mean pressure above E* or an approach above the lateral size is refused before any
    solve (a user's E in GPa, --E 210, ran 10 minutes to a NoConvergenceError; a 1 m
    approach on a 0.5 um window ran without end)."""
    path = _surface(tmp_path, periodic=False, n=16)
    assert main(["contact", str(path), "--E", "1e9", "--pressure", "5e8", "--tol", "1e-8",
                 "-o", str(tmp_path / "o"), "--no-figures"]) == 0
    err = capsys.readouterr().err
    assert "warning" in err and "not physical" in err
    delta = json.loads((tmp_path / "o" / "results.json").read_text())["steps"][0]["delta"]
    assert 2e-5 < delta < 8e-5                                  # ~40 um on a 100 um patch
    for cmd, extra, words in (
            ("contact", ["--pressure", "1e12"], ["mean pressure 1e+12 Pa is 1e+03 x E* = 1e+09 Pa",
                                                 "is --E in Pa?"]),
            ("leak", ["--pressure", "1e6", "2e9"], ["mean pressure 2e+09 Pa is 2 x E*"]),
            ("contact", ["--delta", "1"], ["approach 1 m is 1e+04 x the smallest lateral size "
                                           "0.0001 m", "is --delta in metres?"])):
        assert main([cmd, str(path), "--E", "1e9", *extra, "-o", str(tmp_path / "x"),
                     "--no-figures"]) == 2
        err = capsys.readouterr().err
        assert all(w in err for w in words), err
        assert not (tmp_path / "x").exists()
