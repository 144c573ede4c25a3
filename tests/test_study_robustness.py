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
        "study": {"name": "r", "analysis": "selftest", "output": str(outdir), "seed": 3},
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
    assert json.loads((spec.output / "index.json").read_text())["n_done"] == 2
