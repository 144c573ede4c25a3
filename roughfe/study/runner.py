"""Run a study: submit the missing tasks to an executor, store each result atomically.

The driver (this module) owns every file of the study folder; workers only compute and
return JSON-safe records, so workers need no access to the study folder. A task whose
``results/<key>.json`` exists is skipped, hence a study killed at any moment resumes
where it stopped and ends with the same table as an uninterrupted run. Ctrl-C or SIGTERM
(``kill PID``; the command line exits 130 or 143) stops the workers, rewrites
``index.json`` and leaves ``UNFINISHED`` in the folder (store.py) until a run returns.
"""
from __future__ import annotations

import collections
import contextlib
import dataclasses
import os
import shutil
import socket
import subprocess
import sys
import time
import traceback
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Optional

from .. import __version__
from ..errors import InputError, MemoryShortage
from ..writers import to_jsonable, write_json
from . import store
from .analyses import ANALYSES, as_records, check_parameters, resolve
from .executors import make_executor

INDEX_EVERY_S = 2.0


def code_commit():
    """Git commit of the roughfe checkout (``+dirty`` with local edits), or None.

    Recorded in every result as provenance. It is not part of the task key: keys change
    only with the roughfe and analysis versions, so a study survives unrelated commits;
    ``roughfe study status`` warns when the results come from several commits.
    """
    root = Path(__file__).resolve().parents[2]
    if not (root / ".git").exists():
        return None
    try:
        head = subprocess.run(["git", "-C", str(root), "rev-parse", "HEAD"], capture_output=True,
                              text=True, timeout=10, check=True).stdout.strip()
        dirty = subprocess.run(["git", "--no-optional-locks", "-C", str(root), "status",
                                "--porcelain", "--", "roughfe"],
                               capture_output=True, text=True, timeout=10, check=True).stdout
    except (OSError, subprocess.SubprocessError):
        return None
    return head + ("+dirty" if dirty.strip() else "")


def execute_task(analysis: str, params: dict, seed: int) -> dict:
    """Run one task on a worker; never raises (errors are returned as data).

    Returns
    -------
    dict
        ``ok``; ``records`` (JSON-safe list of dicts) or ``error`` and ``traceback``;
        ``elapsed_s`` (wall) and ``cpu_s`` (CPU time of the worker process: the cost on
        an idle core, whatever else shares the machine), ``host`` and ``pid``.
    """
    t0, c0 = time.perf_counter(), time.process_time()
    out = {"host": socket.gethostname(), "pid": os.getpid()}
    try:
        func = resolve(analysis)
        records = as_records(func(**params, seed=seed), analysis)
        out.update(ok=True, records=to_jsonable(records))  # NaN/inf -> null, as every file
    except Exception as exc:  # a failing task is data for the driver, not a crash
        out.update(ok=False, error=f"{type(exc).__name__}: {exc}",
                   traceback=traceback.format_exc())
    out["elapsed_s"] = time.perf_counter() - t0
    out["cpu_s"] = time.process_time() - c0
    return out


@dataclass(frozen=True)
class StudySummary:
    """What one ``run`` did.

    Attributes
    ----------
    n_tasks : int
        Tasks in the study.
    n_cached : int
        Tasks already done before this run (skipped).
    n_done : int
        Tasks finished by this run.
    n_failed : int
        Tasks still failing after ``max_attempts`` attempts in this run.
    n_retries : int
        Failed attempts that were retried.
    wall_s : float
        Wall time of this run (seconds), executor start-up included.
    task_s : float
        Sum of the worker wall times of the tasks finished by this run.
    task_cpu_s : float
        Sum of their CPU times (the cost on idle cores).
    executor : str
        Executor description.
    """

    n_tasks: int
    n_cached: int
    n_done: int
    n_failed: int
    n_retries: int
    wall_s: float
    task_s: float
    executor: str
    task_cpu_s: float = 0.0

    @property
    def complete(self) -> bool:
        return self.n_cached + self.n_done == self.n_tasks

    def describe(self) -> str:
        n = max(self.n_done, 1)
        return (f"{self.n_tasks} tasks: {self.n_cached} already done, {self.n_done} computed, "
                f"{self.n_failed} failed ({self.n_retries} retries); wall {self.wall_s:.1f} s; "
                f"per task {self.task_s / n:.3g} s wall, {self.task_cpu_s / n:.3g} s CPU on "
                f"the workers; {self.executor}")


class _Progress:
    """tqdm bar with done/failed counts, or nothing."""

    def __init__(self, enabled, total, initial, name):
        self.bar = None
        if enabled:
            from tqdm import tqdm

            self.bar = tqdm(total=total, initial=initial, desc=name, unit="task",
                            file=sys.stderr, dynamic_ncols=True)

    def update(self, n, done, failed):
        if self.bar is not None:
            self.bar.set_postfix(done=done, failed=failed, refresh=False)
            self.bar.update(n)

    def close(self):
        if self.bar is not None:
            self.bar.close()


def _check_tasks(analysis: str, tasks, remote: Optional[str] = None) -> Optional[str]:
    """:func:`~roughfe.study.analyses.check_parameters` on every distinct parameter set
    of ``tasks`` (the seeds aside), before anything is written or submitted: a bad value
    anywhere in the grid fails the whole study at once, naming that task's parameters.

    ``remote``: where the tasks run when that may be other machines, whose memory this
    machine cannot see ("the scheduler's workers" of a dask scheduler, "the MPI ranks":
    ``mpirun`` may place them on other nodes; round 2, session 39, the MPI study had
    been refused on the launching node's memory). A task that needs more memory than
    this machine has (:class:`~roughfe.errors.MemoryShortage`, raised by the inputs
    checks after every check of the values) is then no refusal: the first such message
    is returned as a note (None without one; the worker checks its own memory when the
    task starts, and a shortage there fails that task with the same message). Locally
    (``remote`` None) it is raised."""
    from .spec import canonical_json

    seen, note = set(), None
    for t in tasks:
        key = canonical_json(t.kwargs)
        if key not in seen:
            seen.add(key)
            try:
                check_parameters(analysis, t.kwargs)
            except MemoryShortage as exc:
                if remote is None:
                    raise
                note = note or (f"{exc}, on this machine; the tasks run on {remote}, which "
                                f"check their own memory when a task starts")
    return note


def _remote_workers(executor: str, scheduler) -> Optional[str]:
    """Where the tasks of ``executor`` run when that may be other machines (for
    :func:`_check_tasks`), None when they run on this one (a process pool, a dask
    LocalCluster)."""
    if executor == "mpi":
        return "the MPI ranks"
    if executor == "dask" and scheduler is not None:
        return "the scheduler's workers"
    return None


def run_study(spec, *, executor="local", workers=None, scheduler=None, progress=True,
              log=None, derived=()) -> StudySummary:
    """Run every missing task of ``spec`` and store the results in ``spec.output``.

    Parameters
    ----------
    spec : StudySpec
    executor : {"local", "dask", "mpi"}
    workers : int, optional
        Worker count (local: process pool; dask: LocalCluster size). Default: cores.
    scheduler : str, optional
        Address of a running dask scheduler (dask only).
    progress : bool
        Show a tqdm bar (done/failed counts, ETA) on stderr.
    log : callable, optional
        Receives one-line messages (e.g. ``print``).
    derived : sequence of str
        Names of files or folders in ``spec.output`` that the caller writes from the
        results after the run (``leak-study``: ``summary.json``, ``figures``): removed
        when the run starts, as the tables of ``collect`` are, and recorded in
        ``study.json`` so that every later run removes them too.

    Returns
    -------
    StudySummary
        Failed tasks are recorded in ``failures/`` and counted, never raised.
    """
    log = log or (lambda message: None)
    t_start = time.perf_counter()
    tasks = spec.tasks()
    note = _check_tasks(spec.analysis, tasks, remote=_remote_workers(executor, scheduler))
    if note:
        warnings.warn(note, stacklevel=2)
    outdir = spec.output
    with store.study_lock(outdir) as created:
        try:
            summary = _run_locked(spec, tasks, derived, log, progress,
                                  (executor, workers, scheduler))
        except InputError:
            # a run refused before any task finished (e.g. an executor that cannot start)
            # leaves no study folder behind: the command wrote nothing. Only a folder that
            # this process made, and only while it holds the lock: a run started at the
            # same moment that lost the lock never touches the winner's folder.
            if created and not store.done_keys(outdir):
                shutil.rmtree(outdir, ignore_errors=True)
            raise
    summary = dataclasses.replace(summary, wall_s=time.perf_counter() - t_start)
    log(summary.describe())
    return summary


def _run_locked(spec, tasks, derived, log, progress, how) -> StudySummary:
    """The body of :func:`run_study`, under the study's lock (``how``: executor kind,
    workers, scheduler). The executor is started before anything is written, so a run
    refused there (an executor that cannot start) leaves an existing folder as it was."""
    outdir = spec.output
    found = store.recorded_key_format(outdir)
    keys = [t.key for t in tasks]
    readable, unreadable = store.stored_results(outdir, keys)
    done = set(readable)                           # an unreadable result is not done
    del readable                                   # (held no longer than needed)
    todo = [t for t in tasks if t.key not in done]
    n_cached = len(tasks) - len(todo)
    counts = collections.Counter()
    description = "nothing to run"
    if todo:
        log(f"study {spec.name!r}: {len(tasks)} tasks, {n_cached} already done, "
            f"{len(todo)} to run")
    with contextlib.ExitStack() as stack:
        ex = None
        if todo:
            kind, workers, scheduler = how
            ex = stack.enter_context(make_executor(kind, workers=workers, scheduler=scheduler))
            description = ex.describe()
        if unreadable:
            warnings.warn(store.set_aside(outdir, unreadable), stacklevel=3)
        store.write_study(outdir, spec, tasks, __version__, derived)
        store.write_index(outdir, keys)          # the index of the new task list, at once
        store.mark_unfinished(outdir, time.strftime("%Y-%m-%dT%H:%M:%S%z"))
        note = store.old_keys_note(outdir, found, len(todo))
        if note:
            warnings.warn(note, stacklevel=3)
        if ex is not None:
            log(description)
            try:
                _drive(spec, ex, todo, keys, counts, progress, n_total=len(tasks),
                       n_cached=n_cached, commit=code_commit())
            except KeyboardInterrupt:
                # Ctrl-C or SIGTERM (errors.Terminated): the index says what is done,
                # UNFINISHED stays; leaving the block stops the workers (executors.py)
                store.write_index(outdir, keys)
                raise
    store.write_index(outdir, keys)
    store.clear_unfinished(outdir)
    return StudySummary(n_tasks=len(tasks), n_cached=n_cached, n_done=counts["done"],
                        n_failed=counts["failed"], n_retries=counts["retries"], wall_s=0.0,
                        task_s=counts["task_s"], task_cpu_s=counts["task_cpu_s"],
                        executor=description)


def _drive(spec, ex, todo, keys, counts, progress, *, n_total, n_cached, commit=None):
    """Submit ``todo`` through ``ex`` with a bounded window; retry; store results.

    A task that raises is charged one attempt and requeued until ``max_attempts``.
    A task whose worker died (segfault, out of memory, killed) cannot be blamed while
    other tasks shared the pool: it is marked suspect, not charged, and rerun alone
    (nothing else in flight), so that only the task that kills its worker when alone
    is charged, and innocent neighbours never exhaust their attempts.
    """
    outdir = spec.output
    queue = collections.deque(todo)
    suspects = collections.deque()
    attempts = collections.Counter()
    inflight = {}
    completion = ex.completed()
    window = max(4, 2 * ex.n_workers)

    def submit(task, alone):
        future = ex.submit(execute_task, spec.analysis, task.kwargs, task.seed)
        inflight[future] = (task, alone)
        completion.add(future)

    def refill():
        if suspects:  # run suspects one at a time, with nothing else in flight
            if not inflight:
                submit(suspects.popleft(), alone=True)
            return
        while queue and len(inflight) < window:
            submit(queue.popleft(), alone=False)

    bar = _Progress(progress, n_total, n_cached, spec.name)
    last_index = time.monotonic()
    try:
        refill()
        for future in completion:
            task, alone = inflight.pop(future)
            try:
                out = future.result()
            except Exception as exc:  # the worker died or the executor lost the task
                out = {"ok": False, "error": f"{type(exc).__name__}: {exc} (worker lost)",
                       "traceback": "".join(traceback.format_exception(exc)),
                       "elapsed_s": 0.0, "host": "?", "pid": -1, "lost": True}
                if not alone and attempts[task.key] < spec.max_attempts:
                    suspects.append(task)
                    refill()
                    continue
            attempts[task.key] += 1
            if out["ok"]:
                write_json(store.result_path(outdir, task.key), {
                    "key": task.key, "index": task.index, "analysis": spec.analysis,
                    "analysis_version": ANALYSES[spec.analysis].version,
                    "code_version": __version__, "code_commit": commit,
                    "params": dict(task.params),
                    "seed": task.seed, "records": out["records"],
                    "elapsed_s": out["elapsed_s"], "cpu_s": out["cpu_s"],
                    "host": out["host"], "attempts": attempts[task.key]})
                store.clear_failure(outdir, task.key)
                counts["done"] += 1
                counts["task_s"] += out["elapsed_s"]
                counts["task_cpu_s"] += out["cpu_s"]
                bar.update(1, counts["done"] + n_cached, counts["failed"])
            else:
                store.record_failure(outdir, task, {
                    "error": out["error"], "traceback": out["traceback"],
                    "host": out["host"], "elapsed_s": out["elapsed_s"],
                    "time": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())})
                if attempts[task.key] < spec.max_attempts:
                    counts["retries"] += 1
                    (suspects if out.get("lost") else queue).append(task)
                else:
                    counts["failed"] += 1
                    bar.update(1, counts["done"] + n_cached, counts["failed"])
            if time.monotonic() - last_index > INDEX_EVERY_S:
                store.write_index(outdir, keys)
                last_index = time.monotonic()
            refill()
    finally:
        bar.close()
