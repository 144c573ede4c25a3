"""Genome database: Sobol design, Alg. 2 records, resumable SQLite build, extend, errors."""
import json
import math
import re
import sqlite3
from pathlib import Path

import numpy as np
import pytest

from roughfe.errors import FileFormatError, InputError
from roughfe.genomics import database as db
from roughfe.genomics.genome import Genome, realize
from roughfe.genomics.macro_micro import classify, correlation, profile_response
from roughfe.genomics.similarity import ResponseCurve

SMALL = db.DatabaseSettings(n_nodes=256)


def test_sobol_design_is_the_thesis_design_and_reproducible():
    d = db.SobolDesign()
    pairs = d.pairs()
    assert pairs.shape == (20, 2)
    assert np.all((pairs[:, 0] >= 1.2) & (pairs[:, 0] <= 2.0))
    assert np.all((pairs[:, 1] >= 0.5) & (pairs[:, 1] <= 1.5))
    phases = d.phase_vectors()
    assert phases.shape == (3, 64) and np.all((phases >= 0) & (phases < 2 * np.pi))
    tasks = d.tasks()
    assert len(tasks) == 60 and len({t[0] for t in tasks}) == 60
    np.testing.assert_array_equal(db.SobolDesign().pairs(), pairs)        # recorded seed
    assert not np.allclose(db.SobolDesign(seed=1).pairs(), pairs)
    # "3 vectors of 30 phases taken sequentially": vector 2 continues vector 1
    assert not np.allclose(phases[0, :30], phases[1, :30])


def test_alg2_classification_maths():
    p = np.linspace(1.0, 2.0, 20)
    full = ResponseCurve(p, p ** 0.7, p / 4)
    same_shape = full.rescaled(5.0)                   # a chromosome that is the profile, scaled
    opposite = ResponseCurve(p, p[::-1], p / 4)       # K falling where the profile's rises
    assert correlation(full, same_shape) == pytest.approx(1.0)
    r = classify(full, [same_shape, opposite], [1, 2], threshold=0.95)
    assert r.macro == (1,) and r.micro == (2,)
    assert r.corr_k[1] == pytest.approx(-1.0, abs=0.05)


def test_a_constant_curve_has_an_undefined_correlation_and_is_micro():
    """Pearson's c_n of a constant curve is 0/0: NaN, not the 0.0 ("uncorrelated") it
    was; classify makes that chromosome micro, as any c_n not above the threshold."""
    p = np.linspace(1.0, 2.0, 20)
    full = ResponseCurve(p, p ** 0.7, p / 4)
    flat_k = ResponseCurve(p, np.full(p.size, 3.0e9), p / 4)     # K constant, A rising
    assert np.isnan(correlation(full, flat_k, "K"))
    assert np.isnan(correlation(flat_k, full, "K"))              # a constant reference
    assert correlation(full, flat_k, "A") == pytest.approx(1.0)   # A is defined
    assert np.isnan(correlation(full, flat_k, "K", axis="pressure"))
    r = classify(full, [full.rescaled(2.0), flat_k], [1, 2], threshold=0.95)
    assert r.macro == (1,) and r.micro == (2,)
    assert np.isnan(r.corr_k[1]) and r.corr_a[1] == pytest.approx(1.0)


def test_eq_4_2_scaling_law_with_the_bem():
    """Heights x eta under displacement control: p x eta, K and A unchanged (linear elasticity)."""
    g = db.make_genome(1.6, 0.8, 7, SMALL)
    surf = realize(g, SMALL.length, SMALL.n_nodes)
    kw = dict(youngs_modulus=SMALL.youngs_modulus, n_steps=10)
    for kind in ("fd", "exact"):
        c1 = profile_response(surf, stiffness=kind, **kw)
        c3 = profile_response(surf.scaled(3.0), stiffness=kind, **kw)
        np.testing.assert_allclose(c3.pressure, 3.0 * c1.pressure, rtol=1e-7)
        np.testing.assert_allclose(c3.stiffness, c1.stiffness, rtol=1e-6)
        np.testing.assert_array_equal(c3.area_fraction, c1.area_fraction)
        np.testing.assert_allclose(c1.rescaled(3.0).pressure, c3.pressure, rtol=1e-7)


@pytest.mark.slow
def test_build_through_the_runner_equals_the_task_and_resumes(tmp_path):
    """db build = genome_entry_task run by the study runner, then imported into SQLite."""
    from roughfe.study import build_genome_db, extend_genome_db

    tiny = db.DatabaseSettings(n_nodes=128, n_steps=8)
    path = tmp_path / "g.sqlite"
    run = build_genome_db(path, tiny, limit=2, workers=1, progress=False)
    assert (run.summary.n_done, run.n_inserted, run.n_genomes) == (2, 2, 2)
    assert run.study_dir == tmp_path / "g.sqlite.study"
    # the stored entry is exactly what a direct genome_entry_task call gives
    e = db.load_entries(path, labels_=["1-2"])[0]
    direct = db.genome_entry_task(**db.sobol_tasks(db.SobolDesign(), 2)[1], **tiny.to_dict())
    assert e.genome == direct["genome"] and e.curve.to_dict() == direct["curve"]
    assert [c.to_dict() for c in e.chromosome_curves] == direct["chromosome_curves"]
    assert list(e.corr_k) == direct["corr_k"] and list(e.macro) == direct["macro"]
    # interrupted after the tasks, before the import (here: the SQLite file is lost):
    # the finished genomes come from the study folder, only the new one is computed
    path.unlink()
    run = build_genome_db(path, tiny, limit=3, workers=1, progress=False)
    assert (run.summary.n_cached, run.summary.n_done, run.n_inserted) == (2, 1, 3)
    assert [x.label for x in db.load_entries(path)] == ["1-1", "1-2", "1-3"]
    assert db.load_entries(path, labels_=["1-2"])[0].curve.to_dict() == direct["curve"]
    # genomes already in the file are kept and not run again
    assert build_genome_db(path, tiny, limit=3, progress=False).summary.n_tasks == 0
    with pytest.raises(InputError, match="settings"):
        build_genome_db(path, db.DatabaseSettings(n_nodes=256), limit=1, progress=False)
    with pytest.raises(InputError, match="Sobol design"):
        build_genome_db(path, tiny, db.SobolDesign(seed=3), limit=1, progress=False)
    with pytest.raises(InputError, match="limit"):
        build_genome_db(path, tiny, limit=0, progress=False)
    new = db.make_genome(1.7, 0.9, 11, tiny)
    run = extend_genome_db(path, [new], labels=["seq-1"], workers=1, progress=False)
    assert run.n_inserted == 1 and run.n_genomes == 4
    assert db.load_entries(path, labels_=["seq-1"])[0].source == "extend"
    with pytest.raises(InputError, match="already"):
        extend_genome_db(path, [new], labels=["seq-1"], progress=False)
    # a label given twice is named as such (the study runner's "[grid] entry lists the
    # value {...the genome JSON...} more than once" before); the default labels count
    # on past the labels a user chose (x-<n + 1> clashed with a user's x-6)
    with pytest.raises(InputError, match=r"given more than once: \['twin'\]"):
        extend_genome_db(path, [new, new], labels=["twin", "twin"], progress=False)
    extend_genome_db(path, [new], labels=["x-6"], workers=1, progress=False)
    extend_genome_db(path, [new], workers=1, progress=False)
    assert {"x-6", "x-7"} <= {e.label for e in db.load_entries(path)}
    empty = tmp_path / "empty.sqlite"
    db.connect(empty, create=True).close()
    with pytest.raises(InputError, match="empty"):
        extend_genome_db(empty, [new], progress=False)
    con = sqlite3.connect(path)
    assert json.loads(con.execute("SELECT value FROM meta WHERE key='schema_version'")
                      .fetchone()[0]) == db.SCHEMA_VERSION
    con.close()


def test_built_entry_matches_its_bem_curve_and_record_checks(tmp_path):
    """A built genome stores the realisation's BEM curve and a consistent macro/micro split;
    insert_records refuses a record with other settings and inserts nothing."""
    from roughfe.study import build_genome_db
    path = tmp_path / "g.sqlite"
    assert build_genome_db(path, SMALL, limit=1, workers=1, progress=False).n_inserted == 1
    assert build_genome_db(path, SMALL, limit=1, workers=1, progress=False).n_inserted == 0
    e = db.load_entries(path)[0]
    g = Genome.from_dict(e.genome)
    n_s, n_f = g.chromosome_range(SMALL.length, SMALL.n_nodes)
    assert len(e.chromosome_curves) == len(e.corr_k) == n_f - n_s + 1
    assert set(e.macro) | set(e.micro) == set(range(n_s, n_f + 1))
    assert not set(e.macro) & set(e.micro)
    assert np.all(np.asarray(e.corr_k)[[n - n_s for n in e.macro]] > SMALL.threshold)
    assert e.p_max == pytest.approx(e.curve.p_max)
    again = profile_response(realize(g, SMALL.length, SMALL.n_nodes),
                             youngs_modulus=SMALL.youngs_modulus, n_steps=SMALL.n_steps)
    np.testing.assert_allclose(again.stiffness, e.curve.stiffness, rtol=1e-9)
    record = {"label": "other", "settings": db.DatabaseSettings(n_nodes=128).to_dict()}
    con = db.connect(path)
    try:
        with pytest.raises(InputError, match="settings"):
            db.insert_records(con, [record])
        assert db.labels(con) == ["1-1"]
    finally:
        con.close()
    con = db.connect(path, create=True)
    try:  # an undefined c_n (NaN: a constant curve) is stored as JSON null, read back NaN
        undefined = [float("nan")] + list(e.corr_k[1:])
        assert db.insert_records(con, [{
            "label": "nan-1", "source": e.source, "genome": e.genome, "p_max": e.p_max,
            "curve": e.curve.to_dict(),
            "chromosome_curves": [c.to_dict() for c in e.chromosome_curves],
            "corr_k": undefined, "corr_a": list(e.corr_a), "macro": list(e.macro),
            "settings": SMALL.to_dict()}]) == 1
        text = con.execute("SELECT corr_k_json FROM genomes WHERE label='nan-1'").fetchone()[0]
        assert text.startswith("[null,") and "NaN" not in text
    finally:
        con.close()
    back = db.load_entries(path, labels_=["nan-1"])[0]
    assert back.corr_k.dtype == float and np.isnan(back.corr_k[0])
    np.testing.assert_array_equal(back.corr_k[1:], e.corr_k[1:])


def test_empty_missing_and_foreign_databases(tmp_path):
    empty = tmp_path / "empty.sqlite"
    db.connect(empty, create=True).close()
    with pytest.raises(InputError, match="no genomes"):
        db.load_entries(empty)
    with pytest.raises(InputError, match="does not exist"):
        db.load_entries(tmp_path / "nope.sqlite")
    junk = tmp_path / "junk.sqlite"
    junk.write_text("not a database at all" * 100)
    with pytest.raises(FileFormatError):
        db.connect(junk)


#: relative tolerance of a database row's numbers against the recorded row. Measured on
#: the row of the test below: the reference BLAS (the recording) and OpenBLAS differ by
#: up to 3.7e-15 (corr_k; the BEM stiffnesses 1.6e-15), the nnls solver instead of the
#: dense one by 1.0e-14 (the same solution); the pk solver (CG) moves the numbers by
#: 5.6e-10 at its tol 1e-10 and 3.1e-8 at 1e-8, E x (1 + 1e-9) by 1e-9, and one step
#: more changes the lists' lengths
ROW_RTOL = 1e-12


def record_differences(got, ref, rtol: float = ROW_RTOL, where: str = "record") -> list:
    """Where the JSON-safe record ``got`` differs from the recorded ``ref``: the same
    dict keys in the same order, list lengths, strings, ints and bools exactly, floats to
    ``rtol`` relative (NaN only where the record has NaN). Returns one line per
    difference."""
    if type(got) is not type(ref):
        return [f"{where}: {type(got).__name__} {got!r}, recorded {type(ref).__name__} {ref!r}"]
    if isinstance(ref, dict):
        if list(got) != list(ref):
            return [f"{where}: keys {list(got)}, recorded {list(ref)}"]
        return [d for k in ref for d in record_differences(got[k], ref[k], rtol, f"{where}.{k}")]
    if isinstance(ref, list):
        if len(got) != len(ref):
            return [f"{where}: {len(got)} items, recorded {len(ref)}"]
        return [d for i, (g, r) in enumerate(zip(got, ref))
                for d in record_differences(g, r, rtol, f"{where}[{i}]")]
    if isinstance(ref, float) and (math.isclose(got, ref, rel_tol=rtol, abs_tol=0.0)
                                   or math.isnan(got) and math.isnan(ref)):
        return []
    return [] if got == ref else [f"{where}: {got!r}, recorded {ref!r}"]


def test_record_differences_sees_a_step_more_and_a_last_digit_not():
    """The comparison of the test below: a float moved by 1e-14 relative (round-off of
    another BLAS) passes, by 1e-11 (a solver's tolerance) fails, and so do one more item,
    another key, an int for a float and another label."""
    ref = {"label": "r", "curve": {"pressure": [1.0e5, 2.0e5], "stiffness": [1.0e9, 1.1e9]},
           "macro": [1, 2], "corr": [0.99, float("nan")]}
    same = json.loads(json.dumps(ref))
    same["curve"]["stiffness"][1] *= 1 + 1e-14
    assert record_differences(same, ref) == []
    for change in (lambda r: r["curve"]["stiffness"].__setitem__(1, 1.1e9 * (1 + 1e-11)),
                   lambda r: r["curve"]["pressure"].append(3.0e5),
                   lambda r: r["curve"].update(area=[0.1, 0.2]),
                   lambda r: r["macro"].__setitem__(0, 1.0),
                   lambda r: r["corr"].__setitem__(1, 0.5),
                   lambda r: r.update(label="s")):
        changed = json.loads(json.dumps(ref))
        change(changed)
        assert len(record_differences(changed, ref)) == 1


def test_genome_entry_task_rows_equal_the_recorded_ones(tmp_path):
    """The database task (Alg. 2 on one genome, BEM sweeps of 64-node profiles) gives
    the record of the code before the split of issue 11: the same keys, lengths, strings
    and integers, every number to :data:`ROW_RTOL` (the recording was made with the
    reference BLAS; with OpenBLAS the JSON differs in the last digits, so its bytes are
    no test), and the SQLite row stores exactly the JSON the task returned. A
    deliberate change of the rows (a new solver or physics option) must regenerate
    tests/data/genomics_refactor_reference.json and say so: databases built before and
    after would otherwise mix."""
    raw = json.loads((Path(__file__).parent / "data" / "genomics_refactor_reference.json")
                     .read_text())["genome_entry_task_json"]
    rec = db.genome_entry_task(1.7, 0.9, 11, label="r-1", n_nodes=64, n_steps=6)
    assert record_differences(json.loads(json.dumps(rec)), json.loads(raw)) == []
    ref = json.loads(json.dumps(rec))
    con = db.connect(tmp_path / "g.sqlite", create=True)
    db.write_settings(con, db.DatabaseSettings.from_dict(rec["settings"]))
    assert db.insert_records(con, [rec]) == 1
    row = con.execute("SELECT genome_json, curve_json, chromosome_curves_json, corr_k_json, "
                      "corr_a_json, macro_json, p_max FROM genomes").fetchone()
    con.close()
    assert row[:6] == tuple(json.dumps(ref[k]) for k in
                            ("genome", "curve", "chromosome_curves", "corr_k", "corr_a", "macro"))
    assert row[6] == ref["p_max"]
    with pytest.raises(InputError, match="unknown database setting"):
        db.genome_entry_task(1.7, 0.9, 11, label="r-2", n_node=64)


def test_micro_chromosomes_are_those_the_window_realises(tmp_path):
    """An extended genome whose phases start below the database's window (lambda1 = 10 L:
    the window shows n = 6..16 of its 1..44): macro and micro are the realised ones, so
    the design model built from the entry is the stored realisation (micro was numbered
    from the genome's first phase column, 1..6, none of them realised)."""
    from roughfe.genomics.design.model import entry_design
    from roughfe.genomics.genome import random_genome
    from roughfe.genomics.periodic import realization
    from roughfe.study import build_genome_db, extend_genome_db

    tiny = db.DatabaseSettings(n_nodes=64, n_steps=6)
    path = tmp_path / "g.sqlite"
    build_genome_db(path, tiny, limit=1, workers=1, progress=False)
    g = random_genome(1.0, 0.8, 1.5, 10 * tiny.length, 1, 44, rng=1)
    assert g.held_range(tiny.length, tiny.n_nodes) == (6, 16)
    extend_genome_db(path, [g], labels=["long"], workers=1, progress=False)
    e = db.load_entries(path, labels_=["long"])[0]
    assert sorted(e.macro + e.micro) == list(range(6, 17)) and len(e.corr_k) == 11
    design = entry_design(e, tiny)
    stored = realization(g, tiny.length, tiny.n_nodes)
    np.testing.assert_allclose(design.surface().heights, stored.heights,
                               atol=1e-12 * np.abs(stored.heights).max())


@pytest.mark.parametrize("nu", [float("nan"), 0.7, -1.0])
def test_db_build_refuses_a_bad_poisson_ratio_before_creating_the_file(tmp_path, nu):
    """A bad --nu was stored in a new database's settings before any task ran: every
    later build with it failed, every other nu clashed with the stored NaN."""
    from roughfe.cli import main

    with pytest.raises(InputError, match=r"Poisson's ratio\) must lie in \(-1, 0.5\]"):
        db.DatabaseSettings(poisson=nu)
    path = tmp_path / "y.sqlite"
    assert main(["db", "build", str(path), "--nu", str(nu), "--limit", "1", "--nodes", "32",
                 "--workers", "1"]) == 2
    assert not path.exists()


def test_extend_checks_labels_and_genomes_before_running(tmp_path):
    """A label of the Sobol form i-k took the place of the design's genome i-k (a later
    build skipped it as present); a genome the window cannot realise only showed as a
    failed task ("rerun the same command to retry"). Both are InputErrors now, before
    any task runs, and nothing is added."""
    from roughfe.genomics.genome import random_genome
    from roughfe.study import build_genome_db, extend_genome_db

    tiny = db.DatabaseSettings(n_nodes=64, n_steps=6)
    path = tmp_path / "g.sqlite"
    build_genome_db(path, tiny, limit=1, workers=1, progress=False)
    good = db.make_genome(1.7, 0.9, 11, tiny)
    with pytest.raises(InputError, match=r"\['2-1'\] have the form i-k of the Sobol"):
        extend_genome_db(path, [good], labels=["2-1"], progress=False)
    beyond = random_genome(1.0, 0.8, 1.5, tiny.length, 1, 61, rng=1, n_first=40)
    with pytest.raises(InputError, match=r"genome 1 of 1 cannot join .* holds only 40\.\.61"):
        extend_genome_db(path, [beyond], progress=False)
    surface = db.DatabaseSettings(n_nodes=32, n_steps=4, dim=2, top_fraction=0.8)
    spath = tmp_path / "s.sqlite"
    con = db.connect(spath, create=True)
    db.write_settings(con, surface)
    con.close()
    with pytest.raises(InputError, match="no ridge angles"):
        extend_genome_db(spath, [good], progress=False)
    assert [e.label for e in db.load_entries(path)] == ["1-1"]


def test_extend_leaves_the_memory_to_the_runner(tmp_path, monkeypatch):
    """extend_tasks checks what a genome is (window, angles, labels); whether its sweep
    fits in memory is the runner's to judge, which knows where the tasks run (a remote
    scheduler's workers: a warning; here: refused up front, naming the task, nothing
    added). A shortage in extend_tasks was "genome 1 of 1 cannot join this database"."""
    from roughfe import errors
    from roughfe.study import build_genome_db, extend_genome_db

    tiny = db.DatabaseSettings(n_nodes=64, n_steps=6)
    path = tmp_path / "g.sqlite"
    build_genome_db(path, tiny, limit=1, workers=1, progress=False)
    good = db.make_genome(1.7, 0.9, 11, tiny)
    monkeypatch.setattr(errors, "available_memory", lambda: 1024.0)
    con = db.connect(path)
    try:
        tasks = db.extend_tasks(con, [good])
    finally:
        con.close()
    assert [t["label"] for t in tasks] == ["x-2"]
    with pytest.raises(errors.MemoryShortage, match=r"6 load steps of a 64 grid and solving .*"
                                                    r"analysis 'genome_entry'"):
        extend_genome_db(path, [good], workers=1, progress=False)
    assert [e.label for e in db.load_entries(path)] == ["1-1"]


@pytest.mark.parametrize("field, value, message", [
    ("n_nodes", 64.7, r"n_nodes must be an integer >= 16, got 64.7"),
    ("n_steps", 5.9, r"n_steps must be an integer >= 3, got 5.9"),
    ("n_nodes", "abc", r"n_nodes must be an integer >= 16, got 'abc'"),
    ("n_nodes", True, r"n_nodes must be an integer"),
    ("length", "1e-3", r"length \(m\) must be a positive number, got '1e-3'"),
    ("youngs_modulus", "1e6", r"youngs_modulus \(Pa\) must be a positive number"),
    ("threshold", "0.9", r"threshold must be a number in \(0.0, 1.0\), got '0.9'"),
    ("top_fraction", "0.8", r"top_fraction must be a positive number"),
])
def test_settings_refuse_non_integers_and_numbers_given_as_text(field, value, message):
    """n_nodes = 64.7 ran at N = 64 (int() truncated it) while the task's parameters said
    64.7; text such as "abc" or "0.9" was a ValueError or TypeError traceback. Each is an
    InputError naming the setting; integral values are kept exactly."""
    with pytest.raises(InputError, match=message):
        db.settings_from({field: value})
    assert db.settings_from({"n_nodes": np.int64(64), "n_steps": 5}).n_nodes == 64


def test_an_unknown_kernel_is_refused_before_any_task(tmp_path):
    """kernel = "foo" in a genome_db study passed the pre-check and failed every task
    on the workers; the settings now check the kernel name, so the study is refused
    before anything is written."""
    from roughfe.study import run_study, spec_from_mapping

    with pytest.raises(InputError, match=r"kernel must be 'auto' or one of .*'foo'"):
        db.DatabaseSettings(kernel="foo")
    spec = spec_from_mapping({"study": {"analysis": "genome_db", "output": str(tmp_path / "o")},
                              "grid": {"gamma": [1.5], "hurst": [0.5]},
                              "fixed": {"n_nodes": 32, "kernel": "foo"}})
    with pytest.raises(InputError, match=r"kernel must be 'auto'"):
        run_study(spec, progress=False)
    assert not (tmp_path / "o").exists()


def test_db_build_on_a_folder_is_an_input_error(tmp_path, capsys):
    """`db build adir` (a folder) was a sqlite3.OperationalError traceback ("unable to
    open database file"); it is the InputError of `db list adir`, and the folder stays."""
    from roughfe.cli import main

    folder = tmp_path / "adir"
    folder.mkdir()
    for command in ("build", "list"):
        assert main(["db", command, str(folder)]) == 2
        assert "does not exist (it is a folder)" in capsys.readouterr().err
    with pytest.raises(InputError, match="it is a folder"):
        db.connect(folder, create=True)
    assert folder.is_dir()


def test_a_profile_database_refuses_a_surface_genome(tmp_path):
    """A 2-ridge genome with angles (from a --dim 2 database) joined a profile database
    through `db extend` and was realised as a profile with its angles ignored, while a
    surface database refused a profile genome. Both directions are refused, naming the
    dims, before any task runs."""
    from roughfe.study import extend_genome_db

    surface = db.DatabaseSettings(n_nodes=32, n_steps=4, dim=2, top_fraction=0.8)
    genome = db.make_genome(1.7, 0.9, 11, surface, angles=[0.3, 1.2])
    path = tmp_path / "p.sqlite"
    con = db.connect(path, create=True)
    db.write_settings(con, db.DatabaseSettings(n_nodes=64, n_steps=6))
    con.close()
    with pytest.raises(InputError, match=r"profile database \(dim 1\).* 2 ridge\(s\) with "
                                         r"angles \(a surface genome, dim 2\)"):
        extend_genome_db(path, [genome], progress=False)
    con = db.connect(path)
    assert db.labels(con) == []
    con.close()
    assert not (tmp_path / "p.sqlite.study").exists()


def test_make_genome_takes_int_seeds_only_as_scalars():
    """make_genome ran a float scalar 3.0 (and "3", True) as the int seed 3 (1), and a 3.5
    as one phase; a scalar is now a seed only as an integer >= 0 (Python or numpy)."""
    tiny = db.DatabaseSettings(n_nodes=32)
    ref = db.make_genome(1.7, 0.9, 3, tiny).phases
    for seed in (np.int64(3), np.uint16(3), np.array(3)):
        np.testing.assert_array_equal(db.make_genome(1.7, 0.9, seed, tiny).phases, ref)
    for bad in (3.0, np.float64(3.0), 3.5, True, np.bool_(True), "3", -1):
        with pytest.raises(InputError, match=r"^phases \(an int seed; else a phase vector in "
                                             r"rad, M = 1, or a matrix of M rows\) must be "
                                             rf"an integer >= 0, got {re.escape(repr(bad))}$"):
            db.make_genome(1.7, 0.9, bad, tiny)
    np.testing.assert_array_equal(db.make_genome(1.7, 0.9, ref[0], tiny).phases, ref)


def test_a_sobol_design_short_of_phases_is_refused_before_the_build(tmp_path):
    """A design with fewer phases than its smallest gamma realises failed genome by genome
    at build time ("needs 1 x 28 phases", inside each task); the build now refuses it
    first, naming the gamma, the phases needed and those given, and creates no file."""
    design, settings = db.SobolDesign(n_phases=5, n_extra=0), db.DatabaseSettings(n_nodes=256)
    gamma = design.pairs()[:, 0].min()
    from roughfe.genomics.database.task import realised_range
    n_s, n_f = realised_range(gamma, settings)
    assert n_f - n_s + 1 == int(np.log(255) / np.log(gamma)) + 1 == 28      # Eq. (3.5)
    message = (rf"^gamma = {gamma:.6g} \(the design's smallest; gamma_range 1.2 \.\. 2\) "
               r"realises 28 chromosomes at N = 256, .* needs 28 phases per ridge; the "
               r"design gives n_phases \+ n_extra = 5 \+ 0 = 5: raise n_extra to at least 23")
    from roughfe.study import build_genome_db
    with pytest.raises(InputError, match=message):
        build_genome_db(tmp_path / "x.sqlite", settings, design, progress=False, workers=1)
    assert not (tmp_path / "x.sqlite").exists()
    db.SobolDesign(n_phases=5, n_extra=23).check_phases(settings)       # exactly enough
