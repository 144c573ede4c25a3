"""Executors for studies behind one ``concurrent.futures``-style interface.

Each executor has ``submit(fn, *args) -> future`` (the future has ``result()``),
``completed()`` (an ``as_completed`` iterator to which futures can be added while
iterating), ``n_workers``, ``name``, ``shutdown()`` and ``stop_workers()``; each is a
context manager, which on KeyboardInterrupt (Ctrl-C, or SIGTERM turned into
:class:`~roughfe.errors.Terminated` by the command line) stops the tasks in flight
before it shuts down (the local pool terminates its workers instead of waiting).
No engine is home-made:

``local``
    :class:`concurrent.futures.ProcessPoolExecutor` sized to the cores available.
``dask``
    ``distributed.Client`` to a running scheduler (``scheduler="tcp://host:8786"``, or a
    scheduler file ``scheduler="sched.json"``, e.g. started by dask-jobqueue or
    ``dask scheduler --scheduler-file`` on SLURM) or to a ``LocalCluster`` of ``workers``
    processes (one thread each, no dashboard) when no scheduler is given.
``mpi``
    :class:`mpi4py.futures.MPIPoolExecutor`, run under
    ``mpirun -n K python -m mpi4py.futures $(which roughfe) study run ... --executor mpi``
    (rank 0 drives, K-1 ranks work). Give the ``roughfe`` script's path, not
    ``-m roughfe.cli``: mpi4py's workers re-run the main module, and the script is the
    entry point guarded by ``if __name__ == "__main__"``.
"""
from __future__ import annotations

import concurrent.futures as cf
import contextlib
import json
import multiprocessing
import os
import threading
import time

from ..errors import InputError

EXECUTORS = ("local", "dask", "mpi")


def available_cores() -> int:
    """Number of cores this process may use (affinity-aware)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


#: Most worker processes of a pool: each holds pipes (file descriptors, 1024 by default per
#: process) and a LocalCluster starts them all at once. (Up to round 2, session 33 there was
#: no bound: --workers 99999999999 ended in a traceback, "Python int too large to convert
#: to C int", from multiprocessing's semaphore.)
MAX_WORKERS = 1024


def _check_workers(workers):
    if workers is None:
        return None
    if isinstance(workers, bool) or not isinstance(workers, int) or \
            not 1 <= workers <= MAX_WORKERS:
        raise InputError(f"workers must be an integer in 1..{MAX_WORKERS} (this machine has "
                         f"{available_cores()} cores), got {workers!r}")
    return workers


class _FuturesCompletion:
    """``as_completed`` over concurrent.futures futures that accepts additions."""

    def __init__(self):
        self._pending = set()

    def add(self, future):
        self._pending.add(future)

    def __iter__(self):
        while self._pending:
            done, self._pending = cf.wait(self._pending, return_when=cf.FIRST_COMPLETED)
            yield from done


def _init_worker(parent_pid):
    """Worker initializer: one BLAS/OpenMP thread, and exit when the driver is gone.

    One thread per worker process avoids oversubscribing the cores (numpy is not yet
    imported when this runs in a fresh ``spawn`` worker). The watchdog makes workers
    leave after the driver is killed (``kill -9``) instead of lingering as orphans.
    """
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")

    def watch():
        while True:
            time.sleep(0.5)
            if os.getppid() != parent_pid:
                os._exit(1)

    threading.Thread(target=watch, name="roughfe-parent-watch", daemon=True).start()


class _Base:
    name = ""
    n_workers = 1

    def __enter__(self):
        return self

    def __exit__(self, kind, exc, tb):
        if kind is not None and issubclass(kind, KeyboardInterrupt):
            self.stop_workers()         # Ctrl-C or SIGTERM: do not wait for running tasks
        self.shutdown()
        return False

    def stop_workers(self):
        """Stop the tasks in flight at once (an interrupted run); default: nothing (the
        executor's ``shutdown`` cancels what has not started)."""

    def describe(self) -> str:
        """One line for logs: executor name and worker count."""
        return f"{self.name} executor, {self.n_workers} worker(s)"


class LocalExecutor(_Base):
    """A process pool on this machine (``workers`` defaults to the available cores).

    Workers are started with ``spawn`` (clean interpreters, no inherited threads) and
    exit by themselves if the driver dies.
    """

    name = "local"

    def __init__(self, workers=None):
        self.n_workers = _check_workers(workers) or available_cores()
        self._pool = self._new_pool()

    def _new_pool(self):
        return cf.ProcessPoolExecutor(
            max_workers=self.n_workers, mp_context=multiprocessing.get_context("spawn"),
            initializer=_init_worker, initargs=(os.getpid(),))

    def submit(self, fn, *args):
        try:
            return self._pool.submit(fn, *args)
        except cf.process.BrokenProcessPool:
            # A worker died (segfault, out of memory): its tasks are reported failed by
            # their futures; start a fresh pool for the rest of the study.
            self._pool.shutdown(wait=False, cancel_futures=True)
            self._pool = self._new_pool()
            return self._pool.submit(fn, *args)

    def completed(self):
        return _FuturesCompletion()

    def stop_workers(self):
        """Terminate the worker processes (SIGTERM): their tasks are lost, not stored
        (an interrupted study resumes them); the pool's own thread then sees them gone
        and :meth:`shutdown` joins everything, so the pool's semaphores are released."""
        terminate = getattr(self._pool, "terminate_workers", None)   # Python >= 3.14
        if terminate is not None:
            terminate()
            return
        processes = getattr(self._pool, "_processes", None) or {}  # CPython's pool before
        for process in list(processes.values()):
            with contextlib.suppress(OSError, ValueError):   # already gone
                process.terminate()

    def shutdown(self):
        self._pool.shutdown(wait=True, cancel_futures=True)


def _scheduler_address(scheduler) -> str:
    """The address of the dask scheduler ``scheduler``: an address as given, or the one a
    scheduler file (``*.json``, from ``dask scheduler --scheduler-file``) holds. The file
    is read here: ``distributed.Client`` would wait forever for a missing one (holding
    the study's lock) and fails with an AssertionError on one without an address."""
    text = str(scheduler)
    if not text.endswith(".json"):
        return text
    try:
        with open(text) as fh:
            data = json.load(fh)
    except FileNotFoundError:
        raise InputError(f"the dask scheduler file {text!r} does not exist; start the "
                         f"scheduler first (`dask scheduler --scheduler-file {text}`) or give "
                         "its address, e.g. tcp://host:8786") from None
    except (OSError, ValueError) as exc:
        raise InputError(f"cannot read the dask scheduler file {text!r}: {exc}") from None
    address = data.get("address") if isinstance(data, dict) else None
    if not isinstance(address, str) or not address:
        raise InputError(f"{text!r} is not a dask scheduler file: it holds no 'address' "
                         "of a scheduler (a JSON object with 'address': 'tcp://host:port')")
    return address


class DaskExecutor(_Base):
    """dask.distributed: a running scheduler at ``scheduler``, or a LocalCluster."""

    name = "dask"

    def __init__(self, workers=None, scheduler=None):
        address = _scheduler_address(scheduler) if scheduler else None
        try:
            import distributed
        except ImportError:
            raise InputError("the dask executor needs dask.distributed: "
                             "pip install 'dask[distributed]' (the 'study' extra)") from None
        self._distributed = distributed
        workers = _check_workers(workers)
        self._cluster = None
        if scheduler:
            try:
                self._client = distributed.Client(address, timeout="30s")
            except (OSError, TimeoutError, ValueError) as exc:
                raise InputError(f"cannot reach the dask scheduler at {address!r}: "
                                 f"{exc}") from None
            self.n_workers = max(1, len(self._client.scheduler_info()["workers"]))
        else:
            self.n_workers = workers or available_cores()
            self._cluster = distributed.LocalCluster(
                n_workers=self.n_workers, threads_per_worker=1, processes=True,
                dashboard_address=None)
            self._client = distributed.Client(self._cluster)

    def submit(self, fn, *args):
        # pure=False: a resubmitted (retried) task must run again, not reuse a key.
        return self._client.submit(fn, *args, pure=False)

    def completed(self):
        return self._distributed.as_completed()

    def describe(self):
        where = self._client.scheduler.address if self._cluster is None else "LocalCluster"
        return f"dask executor ({where}), {self.n_workers} worker(s)"

    def shutdown(self):
        self._client.close()
        if self._cluster is not None:
            self._cluster.close()


class MPIExecutor(_Base):
    """mpi4py.futures under ``mpirun ... python -m mpi4py.futures`` (K-1 workers)."""

    name = "mpi"

    def __init__(self, workers=None):
        try:
            from mpi4py import MPI
            from mpi4py.futures import MPIPoolExecutor
        except ImportError:
            raise InputError("the mpi executor needs mpi4py (Debian: python3-mpi4py)") from None
        size = MPI.COMM_WORLD.Get_size()
        if size < 2:
            raise InputError(
                "the mpi executor must run under mpirun with mpi4py.futures, e.g. "
                "`mpirun -n 3 python -m mpi4py.futures $(which roughfe) study run SPEC "
                "--executor mpi` (as root add --allow-run-as-root; more ranks than cores "
                "needs --oversubscribe); MPI world size here is 1")
        self.n_workers = size - 1
        self._pool = MPIPoolExecutor()

    def submit(self, fn, *args):
        return self._pool.submit(fn, *args)

    def completed(self):
        return _FuturesCompletion()

    def shutdown(self):
        self._pool.shutdown(wait=True)


def make_executor(kind="local", *, workers=None, scheduler=None):
    """Create the executor ``kind`` (one of ``local``, ``dask``, ``mpi``)."""
    if kind not in EXECUTORS:
        raise InputError(f"executor must be one of {list(EXECUTORS)}, got {kind!r}")
    if scheduler and kind != "dask":
        raise InputError(f"--scheduler is for the dask executor, not {kind!r}")
    if kind == "local":
        return LocalExecutor(workers)
    if kind == "dask":
        return DaskExecutor(workers, scheduler)
    return MPIExecutor(workers)
