"""The registered analyses run through the study runner (tiny sizes; 10-20 s on 2 busy cores)."""

import pytest

from roughfe.errors import InputError
from roughfe.study import (ANALYSES, collect, run_study, spec_from_mapping, study_status,
                           table_rows)
from roughfe.study.analyses import check_parameters, resolve


def test_every_registered_target_is_a_module_function_path():
    for name, analysis in ANALYSES.items():
        module, sep, attr = analysis.target.partition(":")
        assert sep == ":" and module.startswith("roughfe.") and attr.isidentifier(), name


def test_missing_analysis_module_is_a_clear_error(monkeypatch):
    from roughfe.study import analyses

    monkeypatch.setitem(analyses.ANALYSES, "ghost",
                        analyses.Analysis("roughfe.nowhere.module:task", "1", "absent"))
    with pytest.raises(InputError, match="'ghost' needs roughfe.nowhere.module:task"):
        resolve("ghost")


@pytest.mark.slow
def test_tiny_contact_sweep_study_runs_and_is_reproducible(tmp_path):
    pytest.importorskip("roughfe.bem")
    study = {"study": {"analysis": "contact_sweep", "output": str(tmp_path / "a"), "seed": 3,
                       "seed_from": ["fractal_dimension", "replica"]},
             "grid": {"fractal_dimension": [2.2, 2.6], "replica": [0, 1]},
             "fixed": {"m": 4, "n_steps": 3, "rms_height": 1e-6, "length": 1e-3}}
    summary = run_study(spec_from_mapping(study), workers=2, progress=False)
    assert summary.complete and summary.n_done == 4
    paths, n_rows, missing, _ = collect(tmp_path / "a", parquet=False)
    assert (n_rows, missing) == (4 * 3, 0)
    header = paths[0].read_text().splitlines()[0].split(",")
    for column in ("fractal_dimension", "replica", "seed", "step", "mean_pressure",
                   "area_fraction"):
        assert column in header
    rows = [dict(zip(header, line.split(","))) for line in paths[0].read_text().splitlines()[1:]]
    # loading sweep: the contact area grows with the approach
    for task in {r["task"] for r in rows}:
        areas = [float(r["area_fraction"]) for r in rows if r["task"] == task]
        assert areas == sorted(areas) and areas[-1] > 0
    # the same spec on dask (other processes, other executor) gives the same table bit for bit
    pytest.importorskip("distributed")
    study["study"]["output"] = str(tmp_path / "b")
    run_study(spec_from_mapping(study), executor="dask", workers=1, progress=False)
    assert collect(tmp_path / "b", parquet=False)[0][0].read_text() == paths[0].read_text()


def test_a_bad_value_anywhere_in_the_grid_refuses_the_study_before_any_task(tmp_path):
    """The analysis' input check runs on every distinct task before submission: one bad
    grid value (an unknown generator) or fixed value (E < 0) fails the study at once,
    naming the task's parameters, and nothing is written (no task ran)."""
    pytest.importorskip("roughfe.bem")
    base = {"study": {"analysis": "contact_sweep", "output": str(tmp_path / "g"),
                      "max_attempts": 1}}
    study = {**base, "grid": {"generator": ["rmd", "fourier"]},
             "fixed": {"m": 3, "n_steps": 2}}
    with pytest.raises(InputError) as info:
        run_study(spec_from_mapping(study), workers=1, progress=False)
    assert "generator must be 'rmd' or 'spectral', got 'fourier'" in str(info.value)
    assert "{'generator': 'fourier', 'm': 3, 'n_steps': 2}" in str(info.value)
    assert not (tmp_path / "g").exists()
    study = {**base, "grid": {"m": [3, 4]}, "fixed": {"E": -1.0}}
    with pytest.raises(InputError, match=r"E \(Young's modulus, Pa\)"):
        run_study(spec_from_mapping(study), workers=1, progress=False)
    assert not (tmp_path / "g").exists()


@pytest.mark.parametrize("name, params, words", [
    ("contact_sweep", {"fractal_dimension": 3.5}, "fractal_dimension D of a surface"),
    ("contact_sweep", {"kernel": "fft"}, "kernel must be 'auto' or one of"),
    ("contact_sweep", {"solver": "cg"}, "solver must be one of"),
    ("contact_sweep", {"tol": 0.0}, "tol"),
    ("contact_sweep", {"nu": 0.6}, "nu"),
    ("contact_sweep", {"n_steps": 0}, "n_steps"),
    ("contact_sweep", {"m": 14}, "1 <= m <= 13"),
    # spectral m had no upper bound: m = 40 passed and numpy refused "array is too big"
    # on the worker (m = 16 asks for 34 GB of heights)
    ("contact_sweep", {"generator": "spectral", "m": 40}, "1 <= m <= 13 (grid 2**m points"),
    ("contact_sweep", {"generator": "spectral", "m": 2.0}, "must be an integer"),
    ("leakage", {"D": 2.3, "m": 20}, "1 <= m <= 13"),
    ("leakage", {"D": 2.3, "m": 3, "mu": -1.0}, "mu (Pa s)"),
    ("leakage", {"D": 2.3, "m": 3, "direction": "z"}, "direction must be"),
    ("leakage", {"D": 1.5, "m": 3}, "D (fractal dimension)"),
    ("leakage", {"D": 2.3, "m": 3, "pressure_drop": 0.0}, "pressure_drop"),
    ("genome_db", {"gamma": 1.5, "hurst": 0.7, "n_nodes": 8}, "n_nodes must be an integer >= 16"),
    ("genome_db", {"gamma": 1.5, "hurst": 0.7, "E": 0.0}, "youngs_modulus"),
    ("genome_entry", {"entry": {"label": "a"}}, "needs gamma, hurst and phases"),
    ("genome_entry", {"entry": {"label": "a", "gamma": 1.5, "hurst": 0.7, "phases": 1},
                      "threshold": 1.5}, "threshold must lie in the open interval (0.0, 1.0)"),
])
def test_the_input_checks_of_the_analyses_name_the_bad_value(name, params, words):
    pytest.importorskip("roughfe.leakage.study")
    with pytest.raises(InputError) as info:
        check_parameters(name, params)
    assert words in str(info.value) and f"analysis {name!r}, task" in str(info.value)


def test_a_task_whose_sweep_cannot_fit_in_memory_refuses_the_study_up_front(tmp_path,
                                                                            monkeypatch):
    """The BEM sweep's memory check (bem.memory.check_sweep_memory) is part of the input
    checks: n_steps = 1e10 on m = 2 failed its task on the worker after the study had
    started (session-37 audit); now the study is refused before any task, naming the
    task, and nothing is written. The grid is the generator's: 2**m + 1 (rmd), 2**m
    (spectral), the database's n_nodes (genome analyses)."""
    from roughfe import errors

    pytest.importorskip("roughfe.leakage.study")
    out = tmp_path / "s"
    study = {"study": {"analysis": "contact_sweep", "output": str(out), "max_attempts": 1},
             "grid": {"n_steps": [2, 10 ** 10]}, "fixed": {"m": 2}}
    with pytest.raises(InputError) as info:
        run_study(spec_from_mapping(study), workers=1, progress=False)
    text = str(info.value)
    assert ("keeping the fields of 10000000000 load steps of a 5 x 5 grid and solving them "
            "(non-periodic: on its zero-padded 9 x 9 FFT grid) needs") in text
    assert "analysis 'contact_sweep', task {'n_steps': 10000000000, 'm': 2}" in text
    assert not out.exists()
    for name, params, grid in [
            ("contact_sweep", {"generator": "spectral", "m": 2}, "4 x 4"),
            ("leakage", {"D": 2.3, "m": 3}, "9 x 9"),
            ("genome_db", {"gamma": 1.5, "hurst": 0.7, "n_nodes": 64}, "64 grid"),
            ("genome_entry", {"entry": {"label": "a", "gamma": 1.5, "hurst": 0.7,
                                        "phases": 1, "angles": [0.3]}, "dim": 2,
                              "n_nodes": 64},
             "64 x 64 grid")]:
        with pytest.raises(InputError, match=f"10000000000 load steps of a {grid}"):
            check_parameters(name, {**params, "n_steps": 10 ** 10})
    # the default n_steps = 10 on m = 13 (8193^2 points) keeps 22 GB of fields, and
    # its solve on the zero-padded 16875^2 grid needs 40 bytes a point: 31.2 GiB in all;
    # on the periodic (spectral) 8192^2 grid 23.1 GiB
    monkeypatch.setattr(errors, "available_memory", lambda: 24 * 2 ** 30)
    with pytest.raises(InputError, match=r"10 load steps of a 8193 x 8193 grid and solving "
                                         r"them \(non-periodic: on its zero-padded 16875 x "
                                         r"16875 FFT grid\) needs 31.2 GiB"):
        check_parameters("contact_sweep", {"m": 13})
    check_parameters("contact_sweep", {"m": 13, "generator": "spectral"})
    check_parameters("contact_sweep", {"m": 12})


def test_a_remote_scheduler_notes_this_machines_memory_shortage(monkeypatch):
    """With a remote dask scheduler the tasks run on machines whose memory the launching
    one cannot see (a 16 GiB login node, 256 GiB compute nodes): a task that needs more
    than this machine has is a note, not a refusal; the worker checks again when the
    task starts. Every other bad value is still refused up front, and the memory check
    comes after the value checks, so a shortage never hides a bad value. Locally the
    shortage stays a refusal."""
    from roughfe import errors
    from roughfe.study.runner import _check_tasks
    from roughfe.study.spec import Task

    pytest.importorskip("roughfe.leakage.study")
    monkeypatch.setattr(errors, "available_memory", lambda: 1 * 2 ** 30)
    big = [Task(0, {"m": 13}, 0, "a"), Task(1, {"m": 12}, 0, "b")]
    note = _check_tasks("contact_sweep", big, remote="the scheduler's workers")
    assert "FFT grid) needs 31.2 GiB" in note and "4097" not in note    # the first only
    assert "on this machine; the tasks run on the scheduler's workers" in note
    assert _check_tasks("contact_sweep", [Task(2, {"m": 4}, 0, "s")],
                        remote="the scheduler's workers") is None
    with pytest.raises(errors.MemoryShortage, match="31.2 GiB of memory, 1.0 GiB"):
        _check_tasks("contact_sweep", big, remote=None)
    for name, params, words in [
            ("contact_sweep", {"m": 13, "tol": 2.0}, "tol"),
            ("leakage", {"D": 2.3, "m": 13, "mu": -1.0}, "mu"),
            ("genome_db", {"gamma": 1.5, "hurst": 7.0, "n_nodes": 8193}, "hurst"),
            ("genome_entry", {"entry": {"label": "a", "gamma": 1.5, "hurst": 0.7},
                              "n_nodes": 8193}, "phases")]:
        with pytest.raises(InputError, match=words) as info:
            _check_tasks(name, [Task(0, params, 0, "c")], remote="the scheduler's workers")
        assert not isinstance(info.value, errors.MemoryShortage), (name, str(info.value))


def test_mpi_ranks_and_a_dask_scheduler_are_remote_a_local_pool_is_not(monkeypatch):
    """mpirun may place the MPI ranks on other nodes, as a dask scheduler's workers are:
    for both a task too big for the launching machine is a note naming where the tasks
    run (the MPI study was refused on the login node's memory before session 39); a
    process pool and a dask LocalCluster run here, where the shortage is refused."""
    from roughfe import errors
    from roughfe.study.runner import _check_tasks, _remote_workers
    from roughfe.study.spec import Task

    pytest.importorskip("roughfe.leakage.study")
    assert _remote_workers("mpi", None) == "the MPI ranks"
    assert _remote_workers("dask", "tcp://10.0.0.1:8786") == "the scheduler's workers"
    assert _remote_workers("dask", None) is None and _remote_workers("local", None) is None
    monkeypatch.setattr(errors, "available_memory", lambda: 1 * 2 ** 30)
    note = _check_tasks("contact_sweep", [Task(0, {"m": 13}, 0, "a")],
                        remote=_remote_workers("mpi", None))
    assert note.endswith("on this machine; the tasks run on the MPI ranks, which check "
                         "their own memory when a task starts")


def test_the_input_checks_accept_the_defaults_and_do_no_work(monkeypatch):
    """Good values pass every check quickly (no surface is generated: m = 13 would take
    seconds and 500 MB with RMD), and the check is the task's own first step. (A machine
    with 32 GiB free: the default 10 steps at m = 13 keep 22 GB of fields and solve on a
    padded 16875^2 grid, 31.2 GiB, refused with less, as the test above shows.)"""
    import time

    from roughfe import errors

    pytest.importorskip("roughfe.leakage.study")
    monkeypatch.setattr(errors, "available_memory", lambda: 32 * 2 ** 30)
    t0 = time.perf_counter()
    check_parameters("contact_sweep", {"m": 13})
    check_parameters("leakage", {"D": 2.3, "m": 13})
    check_parameters("genome_db", {"gamma": 1.5, "hurst": 0.7})
    check_parameters("genome_entry", {"entry": {"label": "a", "source": "sobol",
                                                "gamma": 1.5, "hurst": 0.7, "phases": 3}})
    assert time.perf_counter() - t0 < 2.0


def test_genome_db_parameters_bind():
    pytest.importorskip("roughfe.genomics.database")
    check_parameters("genome_db", {"gamma": 1.5, "hurst": 0.7, "n_nodes": 64, "n_steps": 3})
    with pytest.raises(InputError, match=r"needs \['hurst'\] \(in \[grid\] or \[fixed\]\)"):
        check_parameters("genome_db", {"gamma": 1.5})
    with pytest.raises(InputError, match="does not accept"):
        check_parameters("genome_db", {"gamma": 1.5, "hurst": 0.7, "colour": "red"})


def test_tiny_leakage_study_keeps_the_seed_across_D(tmp_path):
    pytest.importorskip("roughfe.leakage.study")
    study = {"study": {"analysis": "leakage", "output": str(tmp_path / "leak"), "seed": 5,
                       "seed_from": ["replica"]},
             "grid": {"D": [2.3, 2.7], "replica": [0, 1]},
             "fixed": {"m": 3, "n_steps": 2, "reynolds": False}}
    summary = run_study(spec_from_mapping(study), workers=2, progress=False)
    assert summary.complete, study_status(tmp_path / "leak").describe()
    _, rows, missing = table_rows(tmp_path / "leak")
    assert missing == 0 and len(rows) == 4 * 2
    seeds = {(r["D"], r["replica"]): r["seed"] for r in rows}
    assert seeds[(2.3, 0)] == seeds[(2.7, 0)] != seeds[(2.3, 1)]
    assert all("free_volume_star" in r and "D_result" not in r for r in rows)


def test_genome_db_study_fills_a_sqlite_database(tmp_path):
    gdb = pytest.importorskip("roughfe.genomics.database")
    from roughfe.study import genome_db_to_sqlite

    study = {"study": {"analysis": "genome_db", "output": str(tmp_path / "g"), "seed": 1},
             "grid": {"gamma": [1.5, 2.0], "replica": [0, 1]},
             "fixed": {"hurst": 0.7, "n_nodes": 64, "n_steps": 3}}
    assert run_study(spec_from_mapping(study), workers=2, progress=False).complete
    db = tmp_path / "genomes.sqlite"
    assert genome_db_to_sqlite(tmp_path / "g", db) == 4
    assert genome_db_to_sqlite(tmp_path / "g", db) == 0  # idempotent
    entries = gdb.load_entries(db)
    assert len({e.label for e in entries}) == 4
    assert gdb.read_settings(db).n_nodes == 64


@pytest.mark.parametrize("name, n_tasks", [("selftest", 12), ("contact_sweep", 70),
                                           ("leakage_thesis", 700), ("genome_db", 1000)])
def test_example_specs_load_and_bind_to_their_analysis(name, n_tasks):
    from pathlib import Path

    from roughfe.study import load_spec

    spec = load_spec(Path(__file__).resolve().parents[1] / "examples" / "studies" / f"{name}.toml")
    assert spec.n_tasks == n_tasks
    tasks = spec.tasks()
    assert len({t.key for t in tasks}) == n_tasks
    try:
        check_parameters(spec.analysis, tasks[0].kwargs)
    except InputError as exc:
        if "cannot be imported" in str(exc):
            pytest.skip(str(exc))
        raise


def test_study_specs_speak_the_cli_vocabulary(tmp_path):
    """E/nu as on the command line; the old youngs_modulus/poisson are renamed with a
    FutureWarning (same task key as the new spelling), both at once is an error."""
    base = {"study": {"analysis": "contact_sweep", "output": str(tmp_path / "v")},
            "grid": {"m": [3]}}
    new = spec_from_mapping({**base, "fixed": {"E": 2e9, "nu": 0.25}})
    with pytest.warns(FutureWarning, match="youngs_modulus is deprecated: write E"):
        old = spec_from_mapping({**base, "fixed": {"youngs_modulus": 2e9, "poisson": 0.25}})
    assert old.fixed == new.fixed == {"E": 2e9, "nu": 0.25}
    assert [t.key for t in old.tasks()] == [t.key for t in new.tasks()]
    with pytest.raises(InputError, match="both 'poisson' and 'nu'"):
        spec_from_mapping({**base, "fixed": {"poisson": 0.2, "nu": 0.3}})
    check_parameters("contact_sweep", {"E": 1e9, "nu": 0.3})
    with pytest.raises(InputError, match="does not accept"):
        check_parameters("contact_sweep", {"youngs_modulus": 1e9})
