"""The study layer under concurrent runs, killed runs, broken files and changed defaults.

Each test reproduces a defect found in review (it failed before the fix). All use the
cheap ``selftest`` analysis unless the defect is in another one; a few seconds in all.
"""
import contextlib
import json

import pytest

from roughfe.errors import InputError
from roughfe.study import run_study, spec_from_mapping
from roughfe.study import runner, store


def _spec(outdir, grid=None, **fixed):
    return spec_from_mapping({
        "study": {"name": "r", "analysis": "selftest", "output": str(outdir), "seed": 3,
                  "seed_from": ["x"]},
        "grid": grid or {"x": [0.5, 1.5]}, "fixed": fixed})


def test_the_loser_of_two_runs_started_at_once_touches_nothing(tmp_path, monkeypatch):
    """Two runs on a new folder: the winner makes the folder and takes the lock first; the
    loser (which saw no folder when it started) is refused and leaves the winner's live
    folder alone (it removed it: the winner ran on without study.json)."""
    spec = _spec(tmp_path / "race")
    real_lock = store.study_lock
    winner = contextlib.ExitStack()

    def winner_first(outdir):
        winner.enter_context(real_lock(outdir))      # the other run wins the race
        store.write_study(outdir, spec, spec.tasks(), "winner")
        return real_lock(outdir)

    monkeypatch.setattr(runner.store, "study_lock", winner_first)
    with winner, pytest.raises(InputError, match="another `roughfe study run`"):
        run_study(spec, progress=False)
    assert (spec.output / "study.json").is_file() and (spec.output / ".lock").exists()


def test_a_refused_run_removes_the_folder_it_made(tmp_path):
    """The clean-up kept for the run that made the folder: an executor that cannot start
    leaves no folder behind."""
    spec = _spec(tmp_path / "new")
    with pytest.raises(InputError, match="executor must be one of"):
        run_study(spec, executor="slurm", progress=False)
    assert not spec.output.exists()
    spec = _spec(tmp_path / "old")
    run_study(spec, workers=1, progress=False)
    with pytest.raises(InputError, match="executor must be one of"):
        run_study(_spec(spec.output, n_records=2), executor="slurm", progress=False)
    assert len(list((spec.output / "results").glob("*.json"))) == 2


def test_a_changed_analysis_default_gives_new_task_keys(tmp_path, monkeypatch):
    """The key covers the parameters as the task runs them: a default that changes
    (contact_sweep's E and nu did, with no version bump) makes new keys, so a resumed
    study does not reuse results of the other physics; a value written in the spec that
    equals the default (outside seed_from) is the same task as leaving it out."""
    from roughfe.study.analyses import selftest_task

    spec = _spec(tmp_path / "d")
    assert [t.key for t in spec.tasks()] == [t.key for t in _spec(spec.output, y=0.0).tasks()]
    assert run_study(spec, workers=1, progress=False).n_done == 2
    monkeypatch.setattr(selftest_task, "__kwdefaults__",
                        {**selftest_task.__kwdefaults__, "y": 0.5})
    again = run_study(spec, workers=1, progress=False)
    assert (again.n_cached, again.n_done) == (0, 2)
    assert json.loads((spec.output / "study.json").read_text())["key_format"] == 2


def test_a_folder_of_the_old_key_format_is_recognised_and_said(tmp_path):
    """A study folder written before the key format was recorded is named as such by
    status and by the run that recomputes its tasks (not silently)."""
    from roughfe.study import study_status

    spec = _spec(tmp_path / "old")
    run_study(spec, workers=1, progress=False)
    path = spec.output / "study.json"
    data = json.loads(path.read_text())
    del data["key_format"]
    path.write_text(json.dumps(data))
    assert "written with task key format 1" in study_status(spec.output).describe()
    with pytest.warns(UserWarning, match=r"key format 1, which hashed only the parameters"):
        run_study(spec, workers=1, progress=False)
    assert "key format" not in study_status(spec.output).describe()


def test_genome_db_tasks_sharing_a_seed_are_distinct_genomes(tmp_path):
    """seed_from = ["replica"] with two gamma: one seed, two genomes. Both are inserted
    (they shared the label genome-<seed> and the database kept one, exit 0); two tasks
    that do make one label are refused, naming them, and nothing is inserted."""
    gdb = pytest.importorskip("roughfe.genomics.database")
    from roughfe.cli import main as cli_main
    from roughfe.study import genome_db_to_sqlite

    out = tmp_path / "g"
    spec = spec_from_mapping({
        "study": {"analysis": "genome_db", "output": str(out), "seed": 3,
                  "seed_from": ["replica"]},
        "grid": {"gamma": [1.5, 1.8], "replica": [0]},
        "fixed": {"hurst": 0.6, "n_nodes": 64, "n_steps": 3}})
    assert run_study(spec, workers=1, progress=False).complete
    db = tmp_path / "g.sqlite"
    assert cli_main(["study", "collect", str(out), "--no-parquet", "--genome-db",
                     str(db)]) == 0
    seed = spec.tasks()[0].seed
    assert sorted(e.label for e in gdb.load_entries(db)) == [
        f"genome-{seed}-gamma1.5-hurst0.6", f"genome-{seed}-gamma1.8-hurst0.6"]
    for path in (out / "results").glob("*.json"):    # as a label given in [fixed] would
        record = json.loads(path.read_text())
        record["records"][0]["label"] = "same"
        path.write_text(json.dumps(record))
    with pytest.raises(InputError, match="both made the genome label 'same'"):
        genome_db_to_sqlite(out, tmp_path / "other.sqlite")
    assert not (tmp_path / "other.sqlite").exists()


@pytest.mark.timeout(60)
def test_a_missing_dask_scheduler_file_is_a_clear_error_not_a_hang(tmp_path):
    """--scheduler typo.json: distributed waited forever for the file, holding the
    study's lock; a file without an address ended in an AssertionError."""
    pytest.importorskip("distributed")
    from roughfe.study import make_executor

    spec = _spec(tmp_path / "s")
    with pytest.raises(InputError, match="scheduler file '.*typo.json' does not exist"):
        run_study(spec, executor="dask", scheduler=str(tmp_path / "typo.json"),
                  progress=False)
    assert not spec.output.exists()
    (tmp_path / "bad.json").write_text('{"id": "Scheduler-1"}')
    with pytest.raises(InputError, match="holds no 'address'"):
        make_executor("dask", scheduler=str(tmp_path / "bad.json"))


def _broken_pyarrow(tmp_path, monkeypatch):
    """A pyarrow that is found but does not import (as one built for numpy 2 under
    numpy 1.24 does)."""
    import sys

    fake = tmp_path / "site" / "pyarrow"
    fake.mkdir(parents=True)
    (fake / "__init__.py").write_text(
        'raise ImportError("pyarrow requires NumPy 2.0 or newer, found 1.24.2")\n')
    for name in [m for m in sys.modules if m == "pyarrow" or m.startswith("pyarrow.")]:
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.syspath_prepend(str(tmp_path / "site"))


def test_collect_writes_the_csv_when_pyarrow_is_found_but_does_not_import(
        tmp_path, monkeypatch, capsys):
    from roughfe.cli import main as cli_main

    spec = _spec(tmp_path / "c")
    run_study(spec, workers=1, progress=False)
    _broken_pyarrow(tmp_path, monkeypatch)
    assert cli_main(["study", "collect", str(spec.output)]) == 0
    out = capsys.readouterr().out
    assert "Parquet not written: pyarrow is installed but cannot be imported here " \
           "(ImportError: pyarrow requires NumPy 2.0 or newer, found 1.24.2)" in out
    assert (spec.output / "table.csv").is_file()
    assert not (spec.output / "table.parquet").exists()


def test_a_column_of_numbers_and_lists_is_text_in_parquet(tmp_path):
    """A record field that is a list in one task and a number in another: the Parquet
    column is JSON text, as in the CSV (pyarrow raised ArrowTypeError)."""
    from roughfe.study import collect
    from roughfe.study.tables import _parquet_column

    assert _parquet_column([[1, 2], 3, None, "a"]) == ["[1,2]", "3", None, "a"]
    assert _parquet_column([1, 2.5, None]) == [1, 2.5, None]
    assert _parquet_column([[1], [2.5]]) == ["[1]", "[2.5]"]
    pytest.importorskip("pyarrow")
    import pandas as pd

    spec = _spec(tmp_path / "m")
    run_study(spec, workers=1, progress=False)
    path = sorted((spec.output / "results").glob("*.json"))[0]
    record = json.loads(path.read_text())
    record["records"][0]["f"] = [1.0, 2.0]
    path.write_text(json.dumps(record))
    paths, n_rows, missing, note = collect(spec.output)
    assert note == "" and spec.output / "table.parquet" in paths
    column = pd.read_parquet(spec.output / "table.parquet")["f"].tolist()
    assert "[1.0,2.0]" in column and all(isinstance(v, str) for v in column)


class _Killed(BaseException):
    """Stands for kill -9 in the middle of a run (no clean-up code runs after it)."""


def _killed_while_running(*args, **kwargs):
    raise _Killed


def test_a_killed_run_leaves_no_whole_study_file_of_an_earlier_state(tmp_path, monkeypatch):
    """A completed 2-task study, collected, then extended to 4 tasks and killed before a
    task finished: index.json said 2/2 done beside a 4-task study.json, and table.csv was
    gone only because of an earlier fix. Now the index describes the 4 tasks at once."""
    from roughfe.study import collect

    spec = _spec(tmp_path / "k")
    run_study(spec, workers=1, progress=False)
    collect(spec.output, parquet=False)
    monkeypatch.setattr(runner, "_drive", _killed_while_running)
    with pytest.raises(_Killed):
        run_study(_spec(spec.output, grid={"x": [0.5, 1.5, 2.5, 3.5]}), progress=False)
    index = json.loads((spec.output / "index.json").read_text())
    assert (index["n_tasks"], index["n_done"]) == (4, 2)
    assert not (spec.output / "table.csv").exists()


def test_status_rebuilds_a_stale_index(tmp_path):
    from roughfe.study import study_status

    spec = _spec(tmp_path / "i")
    run_study(spec, workers=1, progress=False)
    index = json.loads((spec.output / "index.json").read_text())
    (spec.output / "index.json").write_text(json.dumps({"n_tasks": 20, "n_done": 20}))
    assert study_status(spec.output).n_done == 2
    assert json.loads((spec.output / "index.json").read_text()) == index
    (spec.output / "index.json").unlink()
    study_status(spec.output)
    assert json.loads((spec.output / "index.json").read_text()) == index


def test_a_killed_leak_study_leaves_no_summary_of_an_earlier_run(tmp_path, monkeypatch):
    """leak-study completed, rerun with more D and killed: its summary.json (and
    figures) described the earlier study beside the larger, unfinished one."""
    pytest.importorskip("roughfe.leakage.study")
    from roughfe.cli import main as cli_main

    out = tmp_path / "leak"
    args = ["leak-study", "--m", "2", "--surfaces", "1", "--steps", "2", "--workers", "1",
            "--no-figures", "--quiet", "-o", str(out)]
    assert cli_main([*args, "--D", "2.3"]) == 0
    assert (out / "summary.json").is_file()
    (out / "figures").mkdir()          # as the figures of the earlier run
    monkeypatch.setattr(runner, "_drive", _killed_while_running)
    with pytest.raises(_Killed):
        cli_main([*args, "--D", "2.3", "2.7"])
    assert not (out / "summary.json").exists() and not (out / "figures").exists()
    assert json.loads((out / "index.json").read_text())["n_tasks"] == 2
    # a plain `study run` of the folder (the spec extended again) removes them as well
    monkeypatch.undo()
    assert cli_main([*args, "--D", "2.3"]) == 0 and (out / "summary.json").is_file()
    spec = spec_from_mapping(json.loads((out / "study.json").read_text())["spec"])
    monkeypatch.setattr(runner, "_drive", _killed_while_running)
    with pytest.raises(_Killed):
        run_study(spec_from_mapping({**spec.to_dict(), "grid": {**spec.to_dict()["grid"],
                                                                "D": [2.3, 2.9]}}),
                  progress=False)
    assert not (out / "summary.json").exists()


def test_a_run_refused_at_executor_start_leaves_the_folder_as_it_was(tmp_path):
    """The executor starts before anything is written: a typo of the executor (or a
    scheduler that cannot be reached) did remove the collected table and rewrite
    study.json with a task list that was never run."""
    from roughfe.study import collect

    spec = _spec(tmp_path / "f")
    run_study(spec, workers=1, progress=False)
    collect(spec.output, parquet=False)
    def files():     # the lock file aside: it names whoever holds (held) the lock
        return {p.name: p.read_bytes() for p in spec.output.iterdir()
                if p.is_file() and p.name != ".lock"}

    before = files()
    with pytest.raises(InputError, match="executor must be one of"):
        run_study(_spec(spec.output, grid={"x": [0.5, 1.5, 2.5]}), executor="slurm",
                  progress=False)
    assert files() == before


@pytest.mark.parametrize("study, words", [
    ({"analysis": "selftest", "output": 5}, "output must be a folder name (a string), got int 5"),
    ({"analysis": "selftest", "output": ""}, "output must name a folder, got ''"),
    ({"analysis": ["selftest"], "output": "o", "name": "n"},
     "analysis must be the name of an analysis (a string), got list ['selftest']"),
    ({"analysis": {"a": 1}, "output": "o", "name": "n"}, "got dict {'a': 1}"),
    ({"analysis": 5, "output": "o"}, "analysis must be the name of an analysis (a string), "
                                     "got int 5"),
])
def test_bad_spec_values_are_input_errors_naming_them(study, words, tmp_path):
    """They were raw TypeErrors (Path(5), an unhashable list), an error about [study] name
    for analysis = 5, or "" silently became the working directory."""
    with pytest.raises(InputError) as info:
        spec_from_mapping({"study": study, "grid": {"x": [1.0]}})
    assert words in str(info.value)


def test_a_spec_file_that_is_not_utf8_is_an_input_error(tmp_path, capsys):
    from roughfe.cli import main as cli_main
    from roughfe.study import load_spec

    path = tmp_path / "latin1.toml"
    path.write_bytes('[study]\nname = "caf\u00e9"\nanalysis = "selftest"\noutput = "o"\n'
                     .encode("latin-1"))
    with pytest.raises(InputError, match=r"is not UTF-8 text .* byte 0xe9 at offset 19"):
        load_spec(path)
    assert cli_main(["study", "run", str(path)]) == 2
    assert "Traceback" not in capsys.readouterr().err


@pytest.mark.parametrize("edit, words", [
    (lambda d: d.pop("tasks"), "'tasks' (the task list) must be a list"),
    (lambda d: d.update(tasks={"a": 1}), "'tasks' (the task list) must be a list"),
    (lambda d: d["tasks"][1].pop("key"), "tasks[1] needs 'key' (str), got None"),
    (lambda d: d["tasks"][0].update(key="../../etc/passwd"), "a key is 64 hex digits"),
    (lambda d: d["tasks"][0].update(params=[1]), "tasks[0] needs 'params' (dict)"),
    (lambda d: d.update(spec=None), "'spec' (the study spec) must be an object"),
    (lambda d: d["spec"].update(study={"analysis": "nope", "output": "o"}),
     "holds a spec that is not valid: [study] analysis 'nope' is unknown"),
    (lambda d: d.update(key_format="2"), "'key_format' must be an integer"),
])
def test_a_hand_broken_study_json_is_a_file_format_error(edit, words, tmp_path, capsys):
    """status and collect said KeyError 'tasks' or TypeError with a traceback."""
    from roughfe.cli import main as cli_main
    from roughfe.errors import FileFormatError
    from roughfe.study import study_status

    spec = _spec(tmp_path / "b")
    run_study(spec, workers=1, progress=False)
    path = spec.output / "study.json"
    data = json.loads(path.read_text())
    edit(data)
    path.write_text(json.dumps(data))
    with pytest.raises(FileFormatError) as info:
        study_status(spec.output)
    assert str(path) in str(info.value) and words in str(info.value)
    for action in ("status", "collect"):
        assert cli_main(["study", action, str(spec.output)]) == 2
        err = capsys.readouterr().err
        assert "error:" in err and "Traceback" not in err


def test_an_unreadable_result_is_not_done_and_runs_again(tmp_path):
    """An empty results/<key>.json (as a power loss could leave) counted as done
    forever: run said nothing to run, status n/n done exit 0, collect 1 missing."""
    from roughfe.cli import main as cli_main
    from roughfe.study import study_status

    spec = _spec(tmp_path / "u")
    run_study(spec, workers=1, progress=False)
    key = spec.tasks()[1].key
    (spec.output / "results" / f"{key}.json").write_text("")
    status = study_status(spec.output)
    assert (status.n_done, status.n_missing, status.unreadable) == (1, 1, (1,))
    assert "1 result file(s) cannot be read (tasks 1)" in status.describe()
    assert cli_main(["study", "status", str(spec.output)]) == 1
    with pytest.warns(UserWarning, match=rf"could not be read .*{key}\.json.* run again"):
        again = run_study(spec, workers=1, progress=False)
    assert (again.n_cached, again.n_done) == (1, 1)
    assert (spec.output / "results" / f"{key}.json.unreadable").read_text() == ""
    assert study_status(spec.output).n_done == 2


def test_atomic_files_are_fsynced_before_the_rename(tmp_path, monkeypatch):
    """Without an fsync a power loss after the rename can leave an empty file under the
    target's name (a result that then looked done)."""
    import os

    from roughfe import writers

    events = []
    real_fsync, real_replace = os.fsync, os.replace
    monkeypatch.setattr(writers.os, "fsync", lambda fd: (events.append(
        ("fsync", os.readlink(f"/proc/self/fd/{fd}"))), real_fsync(fd))[1])
    monkeypatch.setattr(writers.os, "replace", lambda a, b: (events.append(
        ("replace", str(b))), real_replace(a, b))[1])
    writers.write_json(tmp_path / "r.json", {"a": 1})
    kinds = [kind for kind, _ in events]
    assert kinds == ["fsync", "replace", "fsync"], events
    assert events[0][1].startswith(str(tmp_path / ".roughfe-")) and \
        events[2][1] == str(tmp_path)


def test_the_commit_warning_keeps_dirty_and_a_refusal_names_the_holder(tmp_path):
    """The warning printed '(1819729b9141, 1819729b9141)' for a commit and its +dirty
    state; a collect holding the lock was called 'another `roughfe study run`'."""
    from roughfe.study import study_status
    from roughfe.writers import folder_lock

    spec = _spec(tmp_path / "c")
    run_study(spec, workers=1, progress=False)
    for path, commit in zip(sorted((spec.output / "results").glob("*.json")),
                            ["1819729b9141" + "0" * 28, "1819729b9141" + "0" * 28 + "+dirty"]):
        record = json.loads(path.read_text())
        record["code_commit"] = commit
        path.write_text(json.dumps(record))
    assert "2 different code commits (1819729b9141, 1819729b9141+dirty)" in \
        study_status(spec.output).describe()
    with folder_lock(spec.output, "`roughfe study collect`"):
        with pytest.raises(InputError, match=r"another `roughfe study collect` \(pid \d+\) is "
                                             "writing to"):
            run_study(spec, progress=False)


def test_a_refused_db_build_or_import_leaves_no_new_database_file(tmp_path):
    """A refused `db build` (a design the task check refuses: H up to 4 > 3; the mpi
    executor outside mpirun) and a refused `collect --genome-db` (entries of two
    settings) left a new file with the settings/design and 0 genomes, which then refused
    the corrected command ("the database was built with ..."). A refused call removes
    the file it made; an existing database is left as it was."""
    pytest.importorskip("roughfe.genomics.database")
    from roughfe.cli import main as cli_main
    from roughfe.study import genome_db_to_sqlite

    path = tmp_path / "e.sqlite"
    small = ["--nodes", "32", "--steps", "3", "--workers", "1"]
    assert cli_main(["db", "build", str(path), "--hurst-range", "0.5", "4", "--limit", "12",
                     *small]) == 2
    assert not path.exists()
    assert cli_main(["db", "build", str(path), "--limit", "1", "--executor", "mpi",
                     *small]) == 2
    assert not path.exists()
    assert cli_main(["db", "build", str(path), "--limit", "1", *small]) == 0   # corrected
    before = path.read_bytes()
    assert cli_main(["db", "build", str(path), "--limit", "2", "--executor", "mpi",
                     *small]) == 2
    assert path.read_bytes() == before
    out = tmp_path / "g"
    spec = spec_from_mapping({"study": {"analysis": "genome_db", "output": str(out)},
                              "grid": {"n_nodes": [32, 48]},
                              "fixed": {"gamma": 1.5, "hurst": 0.6, "n_steps": 3}})
    assert run_study(spec, workers=1, progress=False).complete
    with pytest.raises(InputError, match="settings"):
        genome_db_to_sqlite(out, tmp_path / "c.sqlite")
    assert not (tmp_path / "c.sqlite").exists()


def test_collect_of_tasks_with_two_settings_names_the_setting(tmp_path):
    """A genome_db grid over n_nodes without 'label' (seed_from without n_nodes: one
    label per gamma) was refused as a label collision advising "leave 'label' out",
    which it was. The refusal now says one database holds one set of settings and names
    the differing setting; nothing is written."""
    pytest.importorskip("roughfe.genomics.database")
    from roughfe.study import genome_db_to_sqlite

    out = tmp_path / "g"
    spec = spec_from_mapping({"study": {"analysis": "genome_db", "output": str(out),
                                        "seed_from": ["gamma"]},
                              "grid": {"n_nodes": [32, 48]},
                              "fixed": {"gamma": 1.5, "hurst": 0.6, "n_steps": 3}})
    assert run_study(spec, workers=1, progress=False).complete
    with pytest.raises(InputError) as info:
        genome_db_to_sqlite(out, tmp_path / "c.sqlite")
    message = str(info.value)
    assert "n_nodes (32 vs 48)" in message and "one set of settings" in message
    assert "leave 'label' out" not in message
    assert not (tmp_path / "c.sqlite").exists()
