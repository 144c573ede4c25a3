"""The study runner: executor equivalence, kill -9 resume, failure isolation, specs.

All studies here use the built-in ``selftest`` analysis so that they test the runner,
not physics. Budget: about 20 s on 2 shared cores (dask and mpirun start-up dominate).
"""
import importlib.util
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from roughfe.cli import main as cli_main
from roughfe.errors import InputError
from roughfe.study import (collect, derive_seed, load_spec, run_study, spec_from_mapping,
                           study_status)
from roughfe.study.store import study_lock

ROOT = Path(__file__).resolve().parents[1]
PY = sys.executable

# 2 x-values ("D") x 2 replicas ("seeds") x 2 y-values ("m") x 3 records ("steps").
GRID = {"x": [0.5, 1.5], "replica": [0, 1], "y": [2.0, 3.0]}


def _spec(outdir, **fixed):
    return spec_from_mapping({
        "study": {"name": "t", "analysis": "selftest", "output": str(outdir), "seed": 7,
                  "seed_from": ["x", "replica"], "max_attempts": 2},
        "grid": GRID, "fixed": {"n_records": 3, **fixed}})


def _write_toml(path, outdir, sleep):
    path.write_text(f"""
[study]
name = "t"
analysis = "selftest"
output = "{outdir}"
seed = 7
seed_from = ["x", "replica"]
[grid]
x = [0.5, 1.5, 2.5, 3.5]
replica = [0, 1]
y = [2.0, 3.0]
[fixed]
n_records = 3
sleep = {sleep}
""")
    return path


def _results(outdir):
    """The result files of a study folder (not a writer's hidden temporary file)."""
    folder = outdir / "results"
    return [p for p in folder.glob("*.json") if not p.name.startswith(".")] \
        if folder.is_dir() else []


def _table(outdir):
    paths, n_rows, missing, _ = collect(outdir, parquet=False)
    assert missing == 0
    return paths[0].read_text()


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The uninterrupted local run of the small study: its CSV text."""
    out = tmp_path_factory.mktemp("ref") / "study"
    summary = run_study(_spec(out), executor="local", workers=2, progress=False)
    assert summary.complete and summary.n_done == 8
    return _table(out)


def test_table_is_tidy_and_seeded(reference):
    lines = reference.splitlines()
    assert lines[0] == "task,key,x,replica,y,n_records,seed,step,f,u"
    assert len(lines) == 1 + 8 * 3
    rows = [line.split(",") for line in lines[1:]]
    # seed_from = [x, replica]: the same seed (and draws u) for both y values
    by = {(r[2], r[3], r[4], r[7]): (r[6], r[9]) for r in rows}
    assert by[("0.5", "0", "2.0", "1")] == by[("0.5", "0", "3.0", "1")]
    assert by[("0.5", "0", "2.0", "1")] != by[("0.5", "1", "2.0", "1")]
    assert int(by[("1.5", "1", "3.0", "2")][0]) == derive_seed(7, "selftest",
                                                                 {"x": 1.5, "replica": 1})


def test_seed_is_a_stable_hash():
    # Fixed value: a change of the hashing scheme would silently change every surface.
    assert derive_seed(7, "selftest", {"x": 1.5, "replica": 1}) == \
        derive_seed(7, "selftest", {"replica": 1, "x": 1.5})
    assert derive_seed(2026, "selftest", {"x": 1.0}) == 1280465425094832
    assert derive_seed(2026, "selftest", {"x": 1.0}) != derive_seed(2027, "selftest", {"x": 1.0})


@pytest.mark.slow
def test_dask_local_cluster_gives_identical_table(reference, tmp_path):
    pytest.importorskip("distributed")
    out = tmp_path / "dask"
    summary = run_study(_spec(out), executor="dask", workers=2, progress=False)
    assert summary.complete
    assert _table(out) == reference


def _mpirun():
    exe = shutil.which("mpirun")
    if exe is None:
        pytest.skip("mpirun is not installed")
    if importlib.util.find_spec("mpi4py") is None:  # not imported: MPI_Init here would
        pytest.skip("mpi4py is not installed")      # leak OMPI_* variables to mpirun
    return [exe, "--allow-run-as-root", "--oversubscribe", "-n", "2"]


def test_mpi_two_ranks_gives_identical_table(reference, tmp_path):
    mpirun = _mpirun()
    script = shutil.which("roughfe", path=str(Path(PY).parent))
    if script is None:
        pytest.skip("the roughfe console script is not installed next to the interpreter")
    d = _spec(tmp_path / "mpi").to_dict()
    spec_path = tmp_path / "spec.toml"  # the same spec as TOML (JSON scalars are TOML here)
    spec_path.write_text("\n".join(
        line for section in ("study", "grid", "fixed")
        for line in (f"[{section}]", *(f"{k} = {json.dumps(v)}" for k, v in d[section].items())))
        + "\n")
    proc = subprocess.run(
        [*mpirun, PY, "-m", "mpi4py.futures", script, "study", "run", str(spec_path),
         "--executor", "mpi"],
        capture_output=True, text=True, timeout=300, cwd=tmp_path, env=dict(os.environ))
    said = proc.stdout + proc.stderr     # the summary line is run_study's log (stderr)
    if proc.returncode != 0 and "mpi executor" not in said:
        pytest.skip(f"mpirun does not work here (exit {proc.returncode}): "
                    f"{proc.stdout[-800:]} {proc.stderr[-800:]}")
    assert proc.returncode == 0, proc.stderr
    assert "mpi executor, 1 worker(s)" in said
    assert _table(tmp_path / "mpi") == reference


def _children(pid):
    kids = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            kids.append(int(stat.parent.name))
    return kids


def _alive(pid):
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


@pytest.mark.slow
def test_kill_9_then_resume_gives_identical_table(tmp_path):
    out = tmp_path / "killed"
    spec_path = _write_toml(tmp_path / "spec.toml", out, sleep=0.25)
    proc = subprocess.Popen(
        [PY, "-m", "roughfe.cli", "study", "run", str(spec_path), "--workers", "2",
         "--quiet"], cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 180  # generous: spawn is slow on a loaded machine
    while time.monotonic() < deadline:
        n = len(_results(out))
        if n >= 4:
            break
        assert proc.poll() is None, proc.stderr.read().decode()
        time.sleep(0.05)
    workers = _children(proc.pid)
    os.kill(proc.pid, signal.SIGKILL)  # the driver only, as `kill -9 PID` would
    proc.wait()
    # orphaned pool workers notice that the driver is gone and leave; a worker may
    # finish the task it holds first (its result is written atomically and is as
    # valid as any other), so the results are counted once every worker has left
    deadline = time.monotonic() + 30
    while any(_alive(p) for p in workers) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not any(_alive(p) for p in workers)
    # a driver killed while writing leaves its hidden temporary .roughfe-*.tmp.json
    # (counted as a result here, the test failed 1 run in ~10 under load)
    n_before = len(_results(out))
    assert 4 <= n_before < 16

    status = study_status(out)
    assert status.n_done == n_before and status.n_missing == 16 - n_before
    spec = load_spec(spec_path)
    resumed = run_study(spec, executor="local", workers=2, progress=False)
    assert resumed.n_cached == n_before and resumed.n_done == 16 - n_before
    assert resumed.complete

    fresh = tmp_path / "fresh"
    run_study(load_spec(spec_path, output=fresh), executor="local", workers=2, progress=False)
    assert _table(out) == _table(fresh)
    assert not list(out.rglob(".*.tmp*")), "temporary files left behind"

    again = run_study(spec, executor="local", workers=2, progress=False)
    assert again.n_done == 0 and again.n_cached == 16 and again.executor == "nothing to run"


@pytest.mark.slow
@pytest.mark.parametrize("signum, code, line", [
    (signal.SIGTERM, 143, "roughfe study run: interrupted (SIGTERM)"),
    (signal.SIGINT, 130, "roughfe study run: interrupted")])
def test_sigterm_stops_a_study_as_ctrl_c_does(signum, code, line, tmp_path):
    """`kill PID` (SIGTERM) to the driver alone, as Ctrl-C: one "interrupted" line,
    exit 143 (130 for SIGINT), no traceback, no leaked semaphore (the resource tracker's
    warning), no worker left, UNFINISHED kept with an index of what is done; a rerun
    resumes and removes UNFINISHED. Before, SIGTERM killed the driver silently and the
    resource tracker warned of 5 leaked semaphores."""
    out = tmp_path / "stopped"
    spec_path = _write_toml(tmp_path / "spec.toml", out, sleep=0.3)
    proc = subprocess.Popen(
        [PY, "-m", "roughfe.cli", "study", "run", str(spec_path), "--workers", "2",
         "--quiet"], cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 60
    while len(_results(out)) < 2 and time.monotonic() < deadline:
        assert proc.poll() is None, proc.stderr.read().decode()
        time.sleep(0.02)
    workers = _children(proc.pid)
    assert workers, "the pool's worker processes"
    t0 = time.monotonic()
    os.kill(proc.pid, signum)              # the driver only, as `kill PID` would
    _, err = proc.communicate(timeout=30)  # EOF: every holder of stderr (workers,
    stopped_s = time.monotonic() - t0      # the resource tracker) has exited
    err = err.decode()
    assert proc.returncode == code, err
    assert err.strip().splitlines()[-1] == line, err
    assert "Traceback" not in err and "leaked" not in err, err
    deadline = time.monotonic() + 5    # a worker that closed its files may still be exiting
    while any(_alive(p) for p in workers) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not any(_alive(p) for p in workers)
    assert stopped_s < 10              # the running tasks are stopped, not waited for
    n_done = len(_results(out))
    assert 2 <= n_done < 16
    assert (out / "UNFINISHED").is_file()
    assert json.loads((out / "index.json").read_text())["n_done"] == n_done
    status = study_status(out)
    assert status.unfinished and "unfinished" in status.describe()
    assert status.n_done == n_done and status.n_missing == 16 - n_done

    resumed = run_study(load_spec(spec_path), executor="local", workers=2, progress=False)
    assert resumed.complete and resumed.n_cached == n_done
    assert not (out / "UNFINISHED").exists() and not study_status(out).unfinished


def test_failing_task_is_recorded_retried_and_not_fatal(tmp_path):
    out = tmp_path / "fail"
    summary = run_study(_spec(out, fail_x=1.5), executor="local", workers=2, progress=False)
    assert summary.n_done == 4 and summary.n_failed == 4 and summary.n_retries == 4
    assert not summary.complete
    status = study_status(out)
    assert (status.n_done, status.n_failed, status.n_missing) == (4, 4, 0)
    assert all("selftest asked to fail at x=1.5" in err for _, _, err in status.failures)
    record = json.loads(next((out / "failures").glob("*.json")).read_text())
    assert len(record["attempts"]) == 2
    assert "Traceback" in record["attempts"][0]["traceback"]
    index = json.loads((out / "index.json").read_text())
    assert len(index["done"]) == 4 and len(index["failed"]) == 4
    paths, n_rows, missing, _ = collect(out, parquet=False)
    assert missing == 4 and n_rows == 4 * 3
    # the CLI reports the incomplete study with a non-zero exit code
    assert cli_main(["study", "status", str(out)]) == 1
    assert cli_main(["study", "collect", str(out), "--no-parquet"]) == 1


def test_cli_run_status_collect(tmp_path, capsys):
    out = tmp_path / "cli"
    spec_path = _write_toml(tmp_path / "spec.toml", out, sleep=0.0)
    assert cli_main(["study", "run", str(spec_path), "--workers", "2", "--quiet"]) == 0
    assert cli_main(["study", "status", str(out)]) == 0
    assert cli_main(["study", "collect", str(out)]) == 0
    text = capsys.readouterr().out
    assert "16/16 done, 0 failed, 0 missing" in text and "48 rows" in text
    assert "CPU per task" in text
    assert ("pyarrow is not installed" in text) != (out / "table.parquet").exists()


def test_second_driver_on_the_same_folder_is_refused(tmp_path):
    spec = _spec(tmp_path / "locked")
    with study_lock(spec.output):
        with pytest.raises(InputError, match="another `roughfe study run`"):
            run_study(spec, progress=False)


@pytest.mark.parametrize("change, message", [
    ({"study": {"analysis": "nope", "output": "o"}}, "analysis 'nope' is unknown"),
    ({"study": {"analysis": "selftest"}}, "needs 'output'"),
    ({"study": {"analysis": "selftest", "output": "o", "colour": 1}}, "unknown key"),
    ({"study": {"analysis": "selftest", "output": "o"}, "grids": {}}, "unknown section"),
    ({"study": {"analysis": "selftest", "output": "o"}, "grid": {"x": []}}, "non-empty list"),
    ({"study": {"analysis": "selftest", "output": "o"}, "grid": {"x": [1, 1]}}, "more than once"),
    ({"study": {"analysis": "selftest", "output": "o"}, "grid": {"x": [1]}, "fixed": {"x": 2}},
     "both in"),
    ({"study": {"analysis": "selftest", "output": "o", "seed_from": ["z"]}, "grid": {"x": [1]}},
     "not parameters"),
    ({"study": {"analysis": "selftest", "output": "o", "seed": -1}}, "seed must be"),
    ({"study": {"analysis": "selftest", "output": "o"}, "grid": {"x": [float("nan")]}},
     "finite"),
])
def test_spec_errors_say_what_is_wrong(change, message):
    with pytest.raises(InputError, match=message):
        spec_from_mapping(change)


def test_unknown_parameter_fails_before_any_task(tmp_path):
    spec = spec_from_mapping({"study": {"analysis": "selftest", "output": str(tmp_path / "o")},
                              "grid": {"x": [1.0], "wavelength": [2.0]}})
    with pytest.raises(InputError, match="does not accept the parameters"):
        run_study(spec, progress=False)
    assert not (tmp_path / "o").exists()


def test_worker_crash_charges_only_the_crashing_task(tmp_path):
    # x = 2.5 kills its worker process; the pool breaks and every task in flight is lost.
    # Lost tasks are rerun alone, so only the crashing task uses up its attempts.
    out = tmp_path / "crash"
    spec = spec_from_mapping({
        "study": {"analysis": "selftest", "output": str(out), "max_attempts": 2},
        "grid": {"x": [0.5, 1.5, 2.5, 3.5]}, "fixed": {"crash_x": 2.5, "sleep": 0.1}})
    summary = run_study(spec, executor="local", workers=2, progress=False)
    assert (summary.n_done, summary.n_failed) == (3, 1)
    (failure,) = study_status(out).failures
    assert failure[1]["x"] == 2.5 and "worker lost" in failure[2]
    attempts = json.loads(next((out / "failures").glob("*.json")).read_text())["attempts"]
    assert len(attempts) == 2


def test_non_finite_result_is_stored_as_null():
    from roughfe.study import execute_task

    out = execute_task("selftest", {"x": float("inf")}, 0)  # f = inf**2: undefined -> null
    assert out["ok"] and out["records"][0]["f"] is None
    json.dumps(out["records"], allow_nan=False)
    assert execute_task("selftest", {"x": 2.0}, 0)["records"][0]["f"] == 4.0


def test_status_warns_when_results_come_from_several_commits(tmp_path):
    out = tmp_path / "prov"
    run_study(_spec(out), executor="local", workers=1, progress=False)
    status = study_status(out)
    assert "different code commits" not in status.describe()
    first = next((out / "results").glob("*.json"))
    record = json.loads(first.read_text())
    record["code_commit"] = "0" * 40
    first.write_text(json.dumps(record))
    assert "warning: the results come from" in study_status(out).describe()


def test_a_temporary_file_left_by_a_killed_writer_is_no_result(tmp_path):
    # pathlib's glob("*.json") matches hidden names: a driver killed in write_json left
    # .roughfe-XXXX.tmp.json, which done_keys counted as the result of a key ".roughfe-..."
    from roughfe.study.store import done_keys, failed_keys
    for sub in ("results", "failures"):
        (tmp_path / sub).mkdir()
        (tmp_path / sub / "abc.json").write_text("{}")
        (tmp_path / sub / ".roughfe-15jb_9h0.tmp.json").write_text("{")
    assert done_keys(tmp_path) == {"abc"} == failed_keys(tmp_path)


@pytest.mark.parametrize("study, fixed, names", [
    ({"seed_from": ["x"]}, {}, r"replica.*seed_from = \['x'\].*Add 'replica' to seed_from"),
    ({}, {"seed": 5}, r"replica.*parameter 'seed'.*Drop 'seed'"),
    ({"seed_from": ["x", "replica"]}, {"seed": 5}, r"replica.*parameter 'seed'"),
])
def test_replicas_that_cannot_select_the_seed_are_refused(study, fixed, names):
    """``replica`` only selects the seed: with a seed_from without it, or a fixed seed,
    three replicas were three task keys of one surface (spread 0). Such a spec is refused;
    one replica, or replica in seed_from, gives one distinct seed per replica."""
    layout = {"study": {"analysis": "selftest", "output": "o", **study},
              "grid": {"x": [0.5], "replica": [0, 1, 2]}, "fixed": fixed}
    with pytest.raises(InputError, match=names):
        spec_from_mapping(layout)
    layout["study"].pop("seed_from", None)
    layout["fixed"].pop("seed", None)
    for seed_from in (None, ["x", "replica"]):
        spec = spec_from_mapping({**layout, "study": {**layout["study"], "seed_from": seed_from}})
        assert len({t.seed for t in spec.tasks()}) == 3
    spec_from_mapping({**layout, "grid": {"x": [0.5], "replica": [0]},
                       "study": {**layout["study"], "seed_from": ["x"]}})
