"""What a fresh-eyes audit of bad command-line input found (round 2, session 37): options
whose second value silently replaced the first, an error that named the wrong option, a
step count that started weeks of work, and options that were ignored. Each test fails on
the code before its fix: one line ``roughfe CMD: error: ...`` naming the option, exit 2,
nothing written."""
import numpy as np
import pytest

from roughfe.cli import build_parser, main
from roughfe.errors import InputError


def _refused(capsys, argv, *phrases):
    """``roughfe ARGV`` exits 2 with one error line holding every phrase, no traceback."""
    capsys.readouterr()
    assert main(argv) == 2
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if ": error: " in line]
    assert len(lines) == 1 and "Traceback" not in err, err
    for phrase in phrases:
        assert phrase in lines[0], (phrase, lines[0])
    return lines[0]


def test_an_option_given_twice_with_other_values_is_refused(surface32, tmp_path, capsys):
    # argparse kept the last value in silence: --pressure 1e6 --pressure 2e6 solved 2e6
    # only, --size 1e-4 --size 2e-4 read the second size, --n 16 ... --n 32 made 32^2
    out = tmp_path / "c"
    _refused(capsys, ["contact", str(surface32), "--pressure", "1e6", "--pressure", "2e6",
                      "--no-figures", "-o", str(out)],
             "--pressure 1e+06 and --pressure 2e+06", "given twice")
    assert not out.exists()
    _refused(capsys, ["info", str(surface32), "--size", "1e-4", "--size", "2e-4"],
             "--size 0.0001 and --size 0.0002")
    _refused(capsys, ["generate", "spectral", "--n", "16", "--n", "32", "--no-figures",
                      "-o", str(tmp_path / "g.npz")], "--n 16 and --n 32")
    # the old spelling of --E stores into the same option
    _refused(capsys, ["contact", str(surface32), "--steps", "2", "--E", "1e9",
                      "--youngs-modulus", "2e9", "--no-figures", "-o", str(out)],
             "--E 1e+09 and --youngs-modulus 2e+09")
    assert not out.exists()


def test_the_same_value_twice_passes_and_leaves_no_trace(surface32, capsys):
    assert main(["info", str(surface32), "--size", "1e-4", "--size", "1e-4", "--json"]) == 0
    assert '"size"' in capsys.readouterr().out
    args, extra = build_parser("contact").parse_known_args(
        ["contact", "s.npz", "--pressure", "1e6", "-o", "x"])
    assert not extra and args.pressure == [1e6]
    assert not any(k.startswith("_roughfe") for k in vars(args))


def test_info_psd_errors_name_psd(surface32, tmp_path, capsys):
    # said "-o/--output must name a .csv or .png file": info has no -o
    line = _refused(capsys, ["info", str(surface32), "--psd", str(tmp_path / "p.txt")],
                    "--psd must name a .csv or .png file")
    assert "--output" not in line
    (tmp_path / "q.csv").mkdir()
    line = _refused(capsys, ["info", str(surface32), "--psd", str(tmp_path / "q.csv")],
                    "is a folder; --psd takes a file name here")
    assert "-o takes" not in line


def test_steps_whose_fields_cannot_fit_are_refused_before_the_sweep(surface32, tmp_path,
                                                                    capsys):
    # --steps 100000000 on a 32^2 grid started: ~2 weeks (2000 steps: 24 s) towards
    # 3.4 TB of fields and a MemoryError
    out = tmp_path / "c"
    _refused(capsys, ["contact", str(surface32), "--steps", "10000000000", "--no-figures",
                      "-o", str(out)], "keeping the fields of 10000000000 load steps of a "
             "32 x 32 grid and solving them needs", "GiB are available")
    assert not out.exists()
    _refused(capsys, ["contact", str(surface32), "--steps", "10000000000", "--adhesion", "md",
                      "--work-of-adhesion", "0.01", "--range", "1e-8", "--no-figures",
                      "-o", str(out)], "load steps of a 32 x 32 grid and solving them")
    assert not out.exists()


def test_the_library_sweeps_check_the_memory_of_their_steps():
    from roughfe.bem import Material, contact_sweep
    from roughfe.bem.adhesion import AdhesionLaw, adhesive_sweep
    from roughfe.surfaces import Surface
    x = np.arange(16) / 16
    s = Surface(1e-6 * np.cos(2 * np.pi * x)[:, None] * np.cos(2 * np.pi * x)[None, :],
                1e-4, periodic=True)
    steel = Material(E=210e9, nu=0.3)
    with pytest.raises(InputError, match="fields of 10000000000 load steps of a 16 x 16"):
        contact_sweep(s, steel, n_steps=10 ** 10)
    with pytest.raises(InputError, match="fields of 10000000000 load steps"):
        adhesive_sweep(s, steel, AdhesionLaw("md", 0.01, 1e-8), n_steps=10 ** 10)
    assert len(contact_sweep(s, steel, n_steps=2).results) == 2


def test_kernels_listed_twice_are_refused(tmp_path, capsys):
    # genome mechanics --kernels strip strip ran the strip sweeps twice (same files)
    assert main(["genome", "example", "-o", str(tmp_path / "g.json")]) == 0
    _refused(capsys, ["genome", "mechanics", str(tmp_path / "g.json"), "--scale", "10x",
                      "--kernels", "strip", "strip", "-o", str(tmp_path / "m")],
             "--kernels: lists 'strip' more than once")
    _refused(capsys, ["genome", "natural", str(tmp_path / "any.npz"), "--kernels", "thesis",
                      "strip", "thesis", "-o", str(tmp_path / "n")],
             "--kernels: lists 'thesis' more than once")
    assert not (tmp_path / "m").exists() and not (tmp_path / "n").exists()


def test_options_that_meant_nothing_are_refused(surface32, tmp_path, capsys):
    # leak --maps all --no-figures drew nothing; db build --ridges 5 of a profile
    # database built the usual profiles: both ignored in silence
    _refused(capsys, ["leak", str(surface32), "--pressure", "1e6", "--maps", "all",
                      "--no-figures", "-o", str(tmp_path / "l")], "--maps all",
             "--no-figures draws none")
    assert not (tmp_path / "l").exists()
    _refused(capsys, ["db", "build", str(tmp_path / "d.sqlite"), "--limit", "1", "--nodes",
                      "64", "--steps", "5", "--workers", "1", "--ridges", "5"],
             "--ridges 5", "--dim 2")
    assert not (tmp_path / "d.sqlite").exists()


def test_a_broken_link_as_output_is_refused_before_the_work(surface32, tmp_path, capsys,
                                                            monkeypatch):
    # passed the check (its nearest existing parent was writable), the sweep ran, and
    # mkdir failed afterwards: "cannot create output folder ...: File exists"
    import roughfe.cli.contact_cmd as contact_cmd

    def no_solve(*args, **kwargs):
        raise AssertionError("solved before the output folder was checked")
    monkeypatch.setattr(contact_cmd, "response", no_solve)
    (tmp_path / "link").symlink_to(tmp_path / "gone")
    for out in (tmp_path / "link", tmp_path / "link" / "sub"):
        _refused(capsys, ["contact", str(surface32), "--steps", "2", "--no-figures",
                          "-o", str(out)], f"{tmp_path / 'link'} is a broken symbolic link",
                 str(tmp_path / "gone"))
    assert not (tmp_path / "gone").exists()


def test_a_folder_as_target_file_is_said_to_be_a_folder(tmp_path):
    # `design --target DIR` said "target file DIR does not exist"
    from roughfe.genomics.target_csv import read_target_csv
    with pytest.raises(InputError, match="is a folder, not a 'pressure,value' CSV file"):
        read_target_csv(tmp_path)
    with pytest.raises(InputError, match="does not exist"):
        read_target_csv(tmp_path / "none.csv")


def test_leak_at_a_pressure_below_persson_u_p_keeps_its_reynolds_rates(surface32, tmp_path,
                                                                       capsys):
    # `leak --pressure 1e-200` (u(p) of Persson's theory overflows below ~1e-160 Pa on this
    # surface) failed: "pressure_drop = 1 Pa with mu = 0.001 Pa s: ... (C = inf m^3 ...)
    # overflows the float range; this gap allows dp / mu from 0 to 0 1/s"
    import json

    from roughfe.surfaces.io import load_surface
    from roughfe.theory.junction import critical_junction
    out = tmp_path / "l"
    assert main(["leak", str(surface32), "--pressure", "1e-200", "--no-figures",
                 "-o", str(out)]) == 0
    step = json.loads((out / "results.json").read_text())["steps"][0]
    assert step["leak_rate"] > 0
    # since the same session Persson's u(p) is finite there (-ln p: its E1(y^2) no longer
    # underflows), so its junction and leak rates are written beside the Reynolds rates
    u = step["persson_mean_gap"]
    assert u is not None and np.isfinite(u) and step["persson_leak_rate"] > 0
    junction = critical_junction(load_surface(surface32), 2.1e8, 1e-200, 1.0, 1e-3)
    assert np.isfinite(junction.u_c) and junction.leak_rate > 0


def test_an_empty_output_name_is_refused(surface32, tmp_path, capsys, monkeypatch):
    # `-o "$OUT"` with OUT unset: contact wrote results.json and fields.h5 into the working
    # directory when it was empty (study run already refused it)
    monkeypatch.chdir(tmp_path)
    (tmp_path / "empty").mkdir()
    monkeypatch.chdir(tmp_path / "empty")
    _refused(capsys, ["contact", str(surface32), "--steps", "2", "--no-figures", "-o", ""],
             "output must name a folder, got ''", "working directory")
    assert not any((tmp_path / "empty").iterdir())


def test_natural_says_which_fraction_is_too_short(surface32, tmp_path, capsys):
    # said the sequencer's "too few points: N = 7 nodes per acquisition, at least 32 are
    # needed" to `--nodes 64` (the 0.2 window of a 32-sample row has 7), and "acquisitions
    # must have different observation lengths" to `--fractions 1 1`
    out = tmp_path / "n"
    _refused(capsys, ["genome", "natural", str(surface32), "--nodes", "64", "--quiet",
                      "--no-figures", "-o", str(out)],
             "fraction 0.2 has 7 nodes", "row's 32 samples", "larger fractions or a row")
    _refused(capsys, ["genome", "natural", str(surface32), "--fractions", "1", "1", "--quiet",
                      "--no-figures", "-o", str(out)], "fractions must differ", "[1.0, 1.0]")
    assert not out.exists()


def test_info_of_a_flat_surface_says_it_is_flat(tmp_path, capsys):
    # the Hurst row said "n/a (only 0 PSD points in q_range; give --hurst-q-range)": no
    # range helps a PSD that is zero everywhere
    np.save(tmp_path / "flat.npy", np.zeros((32, 32)))
    assert main(["info", str(tmp_path / "flat.npy"), "--size", "1e-4"]) == 0
    row = [line for line in capsys.readouterr().out.splitlines()
           if line.startswith("Hurst exponent")][0]
    assert "the surface is flat (its PSD is zero)" in row and "--hurst-q-range" not in row


def test_a_database_without_permission_is_refused_before_the_work(tmp_path, capsys,
                                                                  monkeypatch):
    # a read-only database: db extend / db build computed every genome, then a traceback
    # "sqlite3.OperationalError: attempt to write a readonly database"; an unreadable one:
    # db list / db map / design-targets a traceback "unable to open database file"
    import os
    from pathlib import Path

    import roughfe.study.genome_db as genome_db
    db = tmp_path / "d.sqlite"
    assert main(["db", "build", str(db), "--limit", "1", "--nodes", "64", "--steps", "5",
                 "--workers", "1", "--quiet"]) == 0
    assert main(["genome", "example", "-o", str(tmp_path / "g.json")]) == 0
    real, denied = os.access, {"mode": os.W_OK}

    def access(path, mode, *args, **kwargs):   # as for a user without the permission:
        if Path(path) == db and mode & denied["mode"]:     # root ignores the mode bits
            return False
        return real(path, mode, *args, **kwargs)

    def no_work(*args, **kwargs):
        raise AssertionError("the genomes were computed before the database was checked")
    monkeypatch.setattr(os, "access", access)
    monkeypatch.setattr(genome_db, "run_study", no_work)
    db.chmod(0o444)
    try:
        _refused(capsys, ["db", "extend", str(db), str(tmp_path / "g.json"), "--workers", "1"],
                 f"cannot write genome database {db}: permission denied")
        _refused(capsys, ["db", "build", str(db), "--limit", "2", "--nodes", "64", "--steps",
                          "5", "--workers", "1"], "cannot write genome database")
        denied["mode"] = os.R_OK
        db.chmod(0o000)
        for argv in (["db", "list", str(db)], ["db", "map", str(db), "-o", str(tmp_path / "m")],
                     ["design-targets", "--db", str(db), "-o", str(tmp_path / "t")]):
            _refused(capsys, argv, f"cannot read genome database {db}: permission denied")
    finally:
        db.chmod(0o644)
    assert not (tmp_path / "m").exists() and not (tmp_path / "t").exists()


def test_info_psd_of_a_map_too_small_for_its_window_says_so(tmp_path, capsys):
    # said the library's "a Hann window needs at least 3 points per side ...; use
    # window='none'" (a keyword of power_spectrum, no option of info)
    np.save(tmp_path / "thin.npy", np.random.default_rng(1).normal(size=(2, 32)) * 1e-6)
    line = _refused(capsys, ["info", str(tmp_path / "thin.npy"), "--size", "1e-4", "5e-5",
                             "--psd", str(tmp_path / "p.csv")],
                    "--psd: a non-periodic 2 x 32 map is too small", "--periodic")
    assert "window=" not in line and not (tmp_path / "p.csv").exists()


def test_second_quantity_without_second_target_is_refused(tmp_path, capsys, monkeypatch):
    # `design --second-quantity A` without --second-target was ignored: the design ran
    # (exit 0). Refused before the database is read
    import roughfe.genomics.database as database

    def not_read(*args, **kwargs):
        raise AssertionError("the database was read before the options were checked")
    monkeypatch.setattr(database, "read_settings", not_read)
    for method in ("sog", "mcco"):
        _refused(capsys, ["design", "--db", str(tmp_path / "d.sqlite"), "--target", "y_t1",
                          "--method", method, "--second-quantity", "A", "--no-figures",
                          "-o", str(tmp_path / "o")],
                 "--second-quantity needs --second-target", "where it means nothing")
    assert not (tmp_path / "o").exists()


def test_a_mistyped_thesis_target_lists_the_thesis_targets(tmp_path, capsys, monkeypatch):
    # `design --target y_t9` said "target file y_t9 does not exist", after the database
    # was read
    import roughfe.genomics.database as database

    def not_read(*args, **kwargs):
        raise AssertionError("the database was read before the targets were checked")
    monkeypatch.setattr(database, "read_settings", not_read)
    monkeypatch.chdir(tmp_path)
    common = ["design", "--db", "d.sqlite", "--no-figures", "-o", "o"]
    for option, spec, method in (("--target", "y_t9", "sog"), ("--target", "Y_T1", "gco"),
                                 ("--second-target", "y_t4", "mcco")):
        argv = common + ["--method", method, "--target", "y_t1"] if option != "--target" \
            else common + ["--method", method]
        _refused(capsys, argv + [option, spec],
                 f"{option} {spec}: no thesis target of that name, and no such file",
                 "the thesis targets are y_t1", "y_t2", "y_t3",
                 "a 'pressure,value' CSV file is also accepted")
    assert not (tmp_path / "o").exists()


def test_boundary_window_on_a_periodic_surface_is_refused(tmp_path, capsys, monkeypatch):
    # `design-targets --surface PERIODIC --boundary window` solved the periodic surface as
    # it is (--boundary applies to a non-periodic window only) and said nothing
    import roughfe.genomics.design as design
    from roughfe.surfaces import Surface, save_surface
    db = tmp_path / "d.sqlite"
    assert main(["db", "build", str(db), "--limit", "1", "--nodes", "64", "--steps", "5",
                 "--workers", "1", "--quiet"]) == 0
    x = np.arange(256) / 256
    path = save_surface(Surface(1e-6 * np.sin(2 * np.pi * 8 * x), 1e-3, periodic=True),
                        tmp_path / "p.npz")
    real = design.surface_targets

    def not_solved(*args, **kwargs):
        raise AssertionError("the surface was solved before --boundary was checked")
    monkeypatch.setattr(design, "surface_targets", not_solved)
    _refused(capsys, ["design-targets", "--db", str(db), "--surface", str(path),
                      "--boundary", "window", "-o", str(tmp_path / "t")],
             "--boundary window", f"{path} is read as periodic", "--non-periodic")
    assert not (tmp_path / "t").exists()
    monkeypatch.setattr(design, "surface_targets", real)     # the ways out still run
    for extra in (["--boundary", "window", "--non-periodic"], ["--boundary", "periodic"]):
        assert main(["design-targets", "--db", str(db), "--surface", str(path), "--quiet",
                     "--overwrite", "-o", str(tmp_path / "t")] + extra) == 0


def test_another_users_output_folder_says_what_could_not_be_done(surface32, tmp_path, capsys,
                                                                 monkeypatch):
    # as user nobody (runuser; root ignores the mode bits) `contact -o OUT` on root's
    # earlier output, with or without --overwrite, said "Permission denied: OUT/.lock"
    import builtins
    import errno

    import roughfe.writers as writers
    out = tmp_path / "c"
    out.mkdir()
    (out / ".lock").write_text("`roughfe contact` (pid 1)\n")
    real = builtins.open

    def open_(path, *args, **kwargs):    # the lock file as another user's, 0644
        if str(path).endswith(".lock"):
            raise PermissionError(errno.EACCES, "Permission denied", str(path))
        return real(path, *args, **kwargs)
    monkeypatch.setattr(writers, "open", open_, raising=False)
    for extra in ([], ["--overwrite"]):
        _refused(capsys, ["contact", str(surface32), "--steps", "2", "--no-figures", "-o",
                          str(out), *extra],
                 f"cannot write in output folder {out}: its lock file {out / '.lock'} cannot "
                 "be opened for writing (permission denied; another user's output folder?); "
                 "choose another output folder")
    assert sorted(p.name for p in out.iterdir()) == [".lock"]
