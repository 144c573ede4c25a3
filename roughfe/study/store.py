"""The results store of a study: one folder, plain JSON, every file written atomically.

::

    OUTDIR/study.json          the spec and the full task list (index, key, params, seed)
    OUTDIR/index.json          manifest: keys done, keys failed (rewritten every few seconds)
    OUTDIR/results/<key>.json  one finished task: its records and provenance
    OUTDIR/failures/<key>.json one failing task: every attempt's error and traceback
    OUTDIR/table.csv           the tidy table written by ``collect`` (tables.py)
    OUTDIR/.lock               held (flock) by the running driver
    OUTDIR/UNFINISHED          while a run works, and after it was interrupted or killed

The result files are the truth: a task is done if and only if ``results/<key>.json``
exists and can be read (an fsync-ed file renamed into place, so it is complete; one that
cannot be read all the same is not done, and the next run sets it aside). ``index.json`` is a convenience summary: a
run rewrites it when it starts, every few seconds and at its end, and ``status``
rebuilds it from the files when it is missing or stale (a run killed between two
writes). The files that describe the whole study (the tables, a wrapper's summary) are
removed when a run starts (:func:`write_study`) and written again by their command.
``UNFINISHED`` (:data:`roughfe.writers.UNFINISHED_FILE`, the marker of every output folder
being written) is written when a run starts and removed when it returns: a folder that
holds it was left by a run that was interrupted (Ctrl-C, SIGTERM) or killed, or is being
written now; ``study status`` says so and the next run removes it.
"""
from __future__ import annotations

import contextlib
import json
import os
import shutil
import statistics
from dataclasses import dataclass
from pathlib import Path

from ..errors import FileFormatError, InputError
from ..writers import UNFINISHED_FILE, folder_lock, write_json, write_text
from .spec import KEY_FORMAT, canonical_json, spec_from_mapping


def study_file(outdir) -> Path:
    return Path(outdir) / "study.json"


def result_path(outdir, key) -> Path:
    return Path(outdir) / "results" / f"{key}.json"


def failure_path(outdir, key) -> Path:
    return Path(outdir) / "failures" / f"{key}.json"


@contextlib.contextmanager
def study_lock(outdir, holder="`roughfe study run`"):
    """Hold an exclusive lock on ``OUTDIR/.lock`` (released by the OS if the driver dies).

    A folder that holds files but no ``study.json`` is not a study folder: it is refused
    (InputError), so a study never mixes its files into another command's output.

    Yields True when this call made the folder (``mkdir`` succeeded here, not in another
    process started at the same moment): only such a caller, holding the lock, may remove
    the folder again (a refused run leaves nothing behind). ``holder`` names the command
    holding the lock.
    """
    outdir = Path(outdir)
    if outdir.exists() and not outdir.is_dir():
        raise InputError(f"study output {outdir} is an existing file; give a folder")
    if outdir.is_dir() and not study_file(outdir).exists():
        other = sorted(e.name for e in outdir.iterdir() if e.name != ".lock")
        if other:
            raise InputError(f"study output {outdir} holds files but is not a study folder (no "
                             f"study.json; e.g. {other[0]!r}); choose a new or empty folder")
    try:
        outdir.parent.mkdir(parents=True, exist_ok=True)
        outdir.mkdir()
        created = True
    except FileExistsError:
        created = False
    except OSError as exc:
        raise InputError(f"cannot create the study folder {outdir}: {exc.strerror}") from None
    with folder_lock(outdir, holder):
        yield created


#: files derived from the results by ``collect``: stale once a run changes the results
TABLE_FILES = ("table.csv", "table.parquet")
#: what a study folder is made of: never removed as a derived file
_OWN = frozenset({"", ".", "..", "study.json", "index.json", "results", "failures", ".lock",
                  UNFINISHED_FILE})


def mark_unfinished(outdir, started: str) -> None:
    """Write ``OUTDIR/UNFINISHED``: a run started at ``started`` (ISO time) is working."""
    write_text(Path(outdir) / UNFINISHED_FILE,
               f"A study run started {started} (pid {os.getpid()}) and has not finished: it "
               "is running, or it was interrupted or killed, so tasks may be missing. Rerun "
               "the same command to resume; `roughfe study status` lists what is done.\n")


def clear_unfinished(outdir) -> None:
    """Remove ``OUTDIR/UNFINISHED`` (a run returned: ``index.json`` says what is done)."""
    (Path(outdir) / UNFINISHED_FILE).unlink(missing_ok=True)


def _raw_study(outdir):
    """The mapping in ``study.json`` as it is (no checks), or None when unreadable."""
    try:
        data = json.loads(study_file(outdir).read_text())
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


def _derived_names(names) -> list:
    """Plain names of files or folders inside the study folder (nothing else is ever
    removed as derived: no path, none of the study's own files)."""
    if not isinstance(names, (list, tuple)):
        return []
    return sorted({n for n in names
                   if isinstance(n, str) and Path(n).name == n and n not in _OWN})


def write_study(outdir, spec, tasks, code_version, derived=()):
    """Start a run: remove what describes the whole study and write ``study.json``.

    Removed: the tables of an earlier ``collect`` (:data:`TABLE_FILES`) and the files or
    folders ``derived`` that a command wrapping the runner writes from the results
    (``leak-study``: ``summary.json``, ``figures``), both those given now and those
    recorded by earlier runs. They describe an earlier state of the study: a run killed
    before it rewrites them must not leave them beside the new task list. The caller
    rewrites ``index.json`` next (:func:`write_index`). ``study.json`` records the spec,
    the task list (index, key, params, seed), the key format and ``derived``.
    """
    outdir = Path(outdir)
    recorded = (_raw_study(outdir) or {}).get("derived")
    derived = _derived_names([*(recorded if isinstance(recorded, list) else []), *derived])
    for name in (*TABLE_FILES, *derived):
        path = outdir / name
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path)
        else:
            path.unlink(missing_ok=True)
    write_json(study_file(outdir), {
        "spec": spec.to_dict(), "code_version": code_version, "key_format": KEY_FORMAT,
        "derived": derived, "n_tasks": len(tasks),
        "tasks": [{"index": t.index, "key": t.key, "params": dict(t.params), "seed": t.seed}
                  for t in tasks]})


def recorded_key_format(outdir):
    """The task-key format of the ``study.json`` in ``outdir`` (1 when none is recorded:
    written before roughfe recorded it), or None without a readable ``study.json``."""
    data = _raw_study(outdir)
    found = None if data is None else data.get("key_format", 1)
    return found if isinstance(found, int) else None


def old_keys_note(outdir, found, n_rerun=None) -> str:
    """A note when the study folder ``outdir`` holds results under the task keys of an
    older format ``found`` (empty otherwise): what changed, and what a run does."""
    if found is None or found >= KEY_FORMAT:
        return ""
    what = ("the next `roughfe study run` computes its tasks once more under the new keys"
            if n_rerun is None else
            f"this run computes {n_rerun} task(s) that have no result under the new keys")
    return (f"{outdir} was written with task key format {found}, which hashed only the "
            f"parameters written in the spec, not the analysis' defaults (a changed default "
            f"reused old results); roughfe now uses key format {KEY_FORMAT}: {what}; the "
            f"old result files stay in {Path(outdir) / 'results'}, unused")


def read_study(outdir) -> dict:
    """Read ``study.json`` of a study folder, checked: FileFormatError naming the file
    and what is wrong in it when it is not what ``roughfe study run`` writes."""
    path = study_file(outdir)
    if not path.is_file():
        raise InputError(f"{outdir} is not a study folder: {path} is missing "
                         "(run `roughfe study run SPEC.toml` first)")
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (ValueError, OSError) as exc:     # JSON and UTF-8 errors are ValueErrors
        raise FileFormatError(f"{path} cannot be read as JSON: {exc}") from None
    _check_study_data(path, data)
    try:
        data["spec_obj"] = spec_from_mapping(data["spec"])
    except InputError as exc:
        raise FileFormatError(f"{path} holds a spec that is not valid: {exc}") from None
    return data


#: the fields of a task in ``study.json`` and their JSON types
_TASK_FIELDS = {"index": int, "key": str, "params": dict, "seed": int}


def _check_study_data(path, data) -> None:
    """Raise FileFormatError unless ``data`` has the layout of :func:`write_study`."""
    def refuse(what):
        raise FileFormatError(f"{path} is not a study file as roughfe writes it: {what}; "
                              "rerun `roughfe study run SPEC.toml` to write it again")
    if not isinstance(data, dict):
        refuse(f"a JSON object is expected, it holds a {type(data).__name__}")
    if not isinstance(data.get("spec"), dict):
        refuse(f"'spec' (the study spec) must be an object, got {data.get('spec')!r:.80}")
    if not isinstance(data.get("key_format", 1), int):
        refuse(f"'key_format' must be an integer, got {data['key_format']!r:.80}")
    if not isinstance(data.get("tasks"), list):
        refuse(f"'tasks' (the task list) must be a list, got {data.get('tasks')!r:.80}")
    for i, task in enumerate(data["tasks"]):
        if not isinstance(task, dict):
            refuse(f"tasks[{i}] must be an object, got {task!r:.80}")
        for name, kind in _TASK_FIELDS.items():
            value = task.get(name)
            if not isinstance(value, kind) or isinstance(value, bool):
                refuse(f"tasks[{i}] needs {name!r} ({kind.__name__}), got {value!r:.80}")
        if not (len(task["key"]) == 64 and all(c in "0123456789abcdef" for c in task["key"])):
            refuse(f"tasks[{i}] has the key {task['key']!r:.80}; a key is 64 hex digits")


def read_result(outdir, key):
    """The stored result of task ``key``, or None if it is not there or cannot be read
    (empty, cut short, or not what the runner writes: a JSON object of that key with a
    list of records)."""
    try:
        data = json.loads(result_path(outdir, key).read_text(encoding="utf-8"))
    except (OSError, ValueError):          # missing, unreadable; JSON or UTF-8 errors
        return None
    if not isinstance(data, dict) or data.get("key", key) != key \
            or not isinstance(data.get("records"), list) \
            or not all(isinstance(r, dict) for r in data["records"]):
        return None
    return data


def stored_results(outdir, keys) -> tuple:
    """The results of the tasks ``keys`` that have a result file: ``(readable,
    unreadable)``, a mapping key -> result for the files :func:`read_result` can read and
    the list of keys (in the order given) whose file it cannot. The one answer to "done
    and readable" for ``study run`` (what to skip, what to set aside) and ``study status``
    (what to count)."""
    files = done_keys(outdir)
    readable, unreadable = {}, []
    for key in keys:
        if key in files:
            result = read_result(outdir, key)
            if result is None:
                unreadable.append(key)
            else:
                readable[key] = result
    return readable, unreadable


def set_aside(outdir, keys) -> str:
    """Rename the unreadable result files of ``keys`` to ``<key>.json.unreadable`` (kept
    for a look; no longer a result); return a message saying so, or ""."""
    for key in keys:
        path = result_path(outdir, key)
        os.replace(path, path.with_name(path.name + ".unreadable"))
    if not keys:
        return ""
    return (f"{len(keys)} result file(s) in {Path(outdir) / 'results'} could not be read "
            f"(empty, cut short or not a result, e.g. {keys[0]}.json): renamed to "
            "*.json.unreadable; their tasks run again")


def done_keys(outdir) -> set:
    """Keys with a result file (the truth about what is done); a writer's temporary file
    (hidden, ``.roughfe-*.tmp.json``: a run killed while writing leaves one) is none."""
    folder = Path(outdir) / "results"
    if not folder.is_dir():
        return set()
    return {p.stem for p in folder.glob("*.json") if not p.name.startswith(".")}


def failed_keys(outdir) -> set:
    folder = Path(outdir) / "failures"
    if not folder.is_dir():
        return set()
    return {p.stem for p in folder.glob("*.json") if not p.name.startswith(".")}


def record_failure(outdir, task, attempt: dict) -> int:
    """Append one failed attempt to ``failures/<key>.json``; return the attempt count."""
    path = failure_path(outdir, task.key)
    try:
        data = json.loads(path.read_text())
    except (FileNotFoundError, json.JSONDecodeError):
        data = {"key": task.key, "index": task.index, "params": dict(task.params),
                "seed": task.seed, "attempts": []}
    data["attempts"].append(attempt)
    write_json(path, data)
    return len(data["attempts"])


def clear_failure(outdir, key):
    """Forget the failures of a task that has now succeeded."""
    with contextlib.suppress(FileNotFoundError):
        os.unlink(failure_path(outdir, key))


def _index(keys_in_order, done, failed) -> dict:
    """The content of ``index.json``."""
    failed = failed - done
    return {"n_tasks": len(keys_in_order),
            "n_done": sum(k in done for k in keys_in_order),
            "n_failed": sum(k in failed for k in keys_in_order),
            "done": [k for k in keys_in_order if k in done],
            "failed": [k for k in keys_in_order if k in failed]}


def write_index(outdir, keys_in_order):
    """Rewrite ``index.json`` from the result and failure files."""
    write_json(Path(outdir) / "index.json",
               _index(keys_in_order, done_keys(outdir), failed_keys(outdir)))


def _refresh_index(outdir, index: dict) -> None:
    """Rewrite a missing or stale ``index.json`` (``status``), unless a run holds the
    folder (it rewrites the index itself) or the folder is read-only."""
    path = Path(outdir) / "index.json"
    with contextlib.suppress(OSError, ValueError):
        if json.loads(path.read_text()) == index:
            return
    with contextlib.suppress(InputError, OSError):
        with folder_lock(outdir, "`roughfe study status`"):
            write_json(path, index)


@dataclass(frozen=True)
class StudyStatus:
    """What a study folder holds.

    Attributes
    ----------
    name, analysis : str
    n_tasks, n_done, n_failed, n_missing : int
        ``n_failed`` counts tasks with a recorded failure and no result;
        ``n_missing`` counts tasks never attempted or interrupted.
    failures : tuple of (int, dict, str)
        (task index, parameters, last error line) of each failed task.
    cost_s : tuple of float
        Wall time in seconds of each finished task on its worker.
    cpu_s : tuple of float
        CPU time in seconds of each finished task (its cost on an idle core).
    commits : tuple of str
        The distinct code commits (provenance) of the finished results.
    note : str
        Said about the folder as a whole (results under an older task-key format).
    unreadable : tuple of int
        Indices of the tasks whose result file cannot be read (counted missing: the
        next run runs them again).
    unfinished : bool
        The folder holds ``UNFINISHED``: its last run was interrupted or killed (or is
        running now).
    """

    name: str
    analysis: str
    n_tasks: int
    n_done: int
    n_failed: int
    n_missing: int
    failures: tuple
    cost_s: tuple
    cpu_s: tuple = ()
    commits: tuple = ()
    note: str = ""
    unreadable: tuple = ()
    unfinished: bool = False

    def describe(self) -> str:
        """Human-readable multi-line summary."""
        lines = [f"study {self.name!r} (analysis {self.analysis}): {self.n_done}/{self.n_tasks} "
                 f"done, {self.n_failed} failed, {self.n_missing} missing"]
        if self.unfinished:
            lines.append("unfinished: the last run was interrupted or killed (or is still "
                         "running); rerun the command that wrote the folder to resume")
        if self.cost_s:
            lines.append(f"cost per task: mean {statistics.fmean(self.cost_s):.3g} s, median "
                         f"{statistics.median(self.cost_s):.3g} s, max {max(self.cost_s):.3g} s "
                         f"(worker wall time, {len(self.cost_s)} tasks)")
        if self.cpu_s:
            lines.append(f"CPU per task: mean {statistics.fmean(self.cpu_s):.3g} s, median "
                         f"{statistics.median(self.cpu_s):.3g} s, max {max(self.cpu_s):.3g} s, "
                         f"total {sum(self.cpu_s):.4g} s (the cost on an idle core)")
        if len(self.commits) > 1:
            lines.append(f"warning: the results come from {len(self.commits)} different code "
                         f"commits ({', '.join(map(_short_commit, self.commits))}); bump the "
                         "analysis version or use a new output folder after a physics change")
        for index, params, error in self.failures:
            lines.append(f"  failed task {index} {canonical_json(params)}: {error}")
        if self.unreadable:
            lines.append(f"{len(self.unreadable)} result file(s) cannot be read (tasks "
                         f"{', '.join(map(str, self.unreadable[:10]))}"
                         f"{', ...' if len(self.unreadable) > 10 else ''}): counted missing; "
                         "`roughfe study run` runs them again")
        if self.note:
            lines.append(f"note: {self.note}")
        return "\n".join(lines)


def _short_commit(commit: str) -> str:
    """A commit as ``git log --oneline`` shows it, with ``+dirty`` kept (``abc+dirty`` and
    ``abc`` are two states of the code)."""
    head, plus, rest = commit.partition("+")
    return head[:12] + plus + rest


def study_status(outdir) -> StudyStatus:
    """Status of the study in ``outdir`` from its files."""
    data = read_study(outdir)
    failed = failed_keys(outdir)
    results, bad = stored_results(outdir, [t["key"] for t in data["tasks"]])
    unreadable = tuple(t["index"] for t in data["tasks"] if t["key"] in set(bad))
    done = set(results)
    failures, costs, cpus, commits = [], [], [], set()
    n_done = n_failed = 0
    for t in data["tasks"]:
        if t["key"] in done:
            n_done += 1
            result = results[t["key"]]
            if "elapsed_s" in result:
                costs.append(float(result["elapsed_s"]))
                if "cpu_s" in result:
                    cpus.append(float(result["cpu_s"]))
                if result.get("code_commit"):
                    commits.add(result["code_commit"])
        elif t["key"] in failed:
            n_failed += 1
            try:
                last = json.loads(failure_path(outdir, t["key"]).read_text())["attempts"][-1]
                error = last.get("error", "?")
            except (FileNotFoundError, json.JSONDecodeError, KeyError, IndexError):
                error = "?"
            failures.append((t["index"], t["params"], error))
    _refresh_index(outdir, _index([t["key"] for t in data["tasks"]], done, failed))
    spec = data["spec_obj"]
    return StudyStatus(name=spec.name, analysis=spec.analysis, n_tasks=len(data["tasks"]),
                       n_done=n_done, n_failed=n_failed,
                       n_missing=len(data["tasks"]) - n_done - n_failed,
                       failures=tuple(failures), cost_s=tuple(costs), cpu_s=tuple(cpus),
                       commits=tuple(sorted(commits)), unreadable=unreadable,
                       unfinished=(Path(outdir) / UNFINISHED_FILE).exists(),
                       note=old_keys_note(outdir, data.get("key_format", 1)))
