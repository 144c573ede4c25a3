"""The one render-backend set-up of a roughfe process: headless, and vtk before dolfinx.

With Debian's dolfinx 0.5.2 and the vtk wheel in one process, vtk must be loaded
*before* dolfinx: in the other order vtk's label formatting (``std::regex`` in
``vtk::is_printf_format``, used by scalar bars and axes) aborts the process (SIGABRT /
``std::bad_alloc``) at the first off-screen render. Loading vtk costs about 0.7 s, so it
is loaded only by a process that will render:

* :func:`load_render_backend` -- call it before the first dolfinx import in any process
  that may also render (``roughfe leak``, ``roughfe validate``, the test session). It
  imports pyvista (hence vtk) unless dolfinx is already loaded.
* :func:`can_render_here` -- True when pyvista may render in this process: vtk already
  loaded, or dolfinx not loaded (then importing pyvista now is safe).
* :func:`render_in_fresh_process` -- the fallback when it is not: call a plotting
  function in a fresh interpreter that never loads dolfinx.
* :func:`writer_prefix`, :func:`remove_dead_writers_files` -- the writer's machine and
  pid in the name of a temporary file, so that a later write removes the temporaries of
  writers that no longer run (a SIGKILL during a write leaves one).

Nothing here imports matplotlib, pyvista or dolfinx at import time.
"""
from __future__ import annotations

import contextlib
import functools
import hashlib
import json
import os
import re
import signal
import socket
import subprocess
import sys
import tempfile
import threading
from pathlib import Path

_VTK_CORE = "vtkmodules.vtkCommonCore"
#: Headless defaults: matplotlib Agg, vtk EGL off-screen (a user's own setting wins).
HEADLESS = {"MPLBACKEND": "Agg", "VTK_DEFAULT_OPENGL_WINDOW": "vtkEGLRenderWindow",
            "PYVISTA_OFF_SCREEN": "true"}


#: PETSc option that leaves the process's signals to Python: without it the first import of
#: petsc4py (dolfinx, the FV Reynolds solver) installs PETSc's handlers, and a reader that
#: leaves (``roughfe leak ... | head``) ended the command in an MPI abort banner with exit
#: 59 instead of Python's BrokenPipeError (exit 141, nothing on stderr)
PETSC_KEEP_SIGNALS = "-no_signal_handler"


def python_signals_for_petsc(env=None) -> dict:
    """Append :data:`PETSC_KEEP_SIGNALS` to ``PETSC_OPTIONS`` in ``env`` (default
    ``os.environ``) unless it is there. Effective only before PETSc is initialised (the
    command line calls it first); a user's own PETSC_OPTIONS are kept."""
    env = os.environ if env is None else env
    options = env.get("PETSC_OPTIONS", "")
    if PETSC_KEEP_SIGNALS not in options.split():
        env["PETSC_OPTIONS"] = f"{options} {PETSC_KEEP_SIGNALS}".strip()
    return env


def headless_environment(env=None) -> dict:
    """Put the :data:`HEADLESS` defaults into ``env`` (default ``os.environ``) unless set."""
    env = os.environ if env is None else env
    for key, value in HEADLESS.items():
        env.setdefault(key, value)
    return env


def can_render_here() -> bool:
    """True when pyvista can render in this process (vtk loaded first, or no dolfinx)."""
    return _VTK_CORE in sys.modules or "dolfinx" not in sys.modules


def load_render_backend() -> bool:
    """Load pyvista/vtk now, before dolfinx; return :func:`can_render_here`.

    Idempotent and cheap after the first call. When dolfinx is already loaded (and vtk
    is not), vtk is *not* loaded (it would abort at the first render); renders then go
    through :func:`render_in_fresh_process`.
    """
    headless_environment()
    if can_render_here() and _VTK_CORE not in sys.modules:
        try:
            import pyvista  # noqa: F401  (loads vtk)
        except ImportError:  # pragma: no cover - pyvista is a core dependency
            return False
    return can_render_here()


@contextlib.contextmanager
def interrupts_held():
    """Hold Ctrl-C (SIGINT) and SIGTERM while the block runs and deliver them when it
    ends. For code that must not be interrupted half-way: vtk's module initialisation,
    which pyvista runs lazily when the first plotter is made. A KeyboardInterrupt raised
    inside it came out as an ImportError traceback ("Failed to load
    vtkRenderingContextOpenGL2"), a ValueError from a half-built mesh, or a segmentation
    fault (``generate rmd --m 11`` interrupted at 1.55-1.75 s; round 2, session 33). Only
    in the main thread (signal handlers live there); elsewhere the block runs as it is."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    held = []
    previous = {s: signal.signal(s, lambda signum, frame: held.append(signum))
                for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
        if held:
            signal.raise_signal(held[0])   # now: the handler of before (KeyboardInterrupt)


def render_in_fresh_process(module: str, function: str, arrays: dict, **kwargs) -> None:
    """Call ``module.function(**arrays, **kwargs)`` in a fresh interpreter.

    ``arrays`` go through a temporary ``.npz``, ``kwargs`` through JSON (plain values
    only). The child sees this process's ``sys.path`` first, so it imports the same
    roughfe. Raises ``RuntimeError`` with the child's stderr tail on failure.
    """
    import numpy as np

    with tempfile.TemporaryDirectory() as tmp:
        npz = Path(tmp) / "arrays.npz"
        np.savez(npz, **{k: np.asarray(v) for k, v in arrays.items()})
        code = ("import sys, json, importlib, numpy as np; "
                "a = dict(np.load(sys.argv[1])); "
                f"getattr(importlib.import_module({module!r}), {function!r})"
                "(**a, **json.loads(sys.argv[2]))")
        env = headless_environment(dict(os.environ))
        env["PYTHONPATH"] = os.pathsep.join(p for p in sys.path if p)
        proc = subprocess.run([sys.executable, "-c", code, str(npz), json.dumps(kwargs)],
                              env=env, capture_output=True, text=True)
        if proc.returncode != 0:
            raise RuntimeError(f"rendering in a fresh process ({module}.{function}) failed: "
                               f"{proc.stderr[-2000:]}")


# -- temporaries of writers that no longer run -----------------------------------------
@functools.lru_cache(maxsize=None)
def machine_tag() -> str:
    """8 hex digits naming this machine and pid namespace (hostname and the namespace's
    inode): a pid in a file name is judged only where it was given out (not on another
    host of a shared file system, nor in another container).

    Computed once per process and cached (every temporary file's name has it). Safe
    across fork: a forked child (multiprocessing, the study executors) inherits the cache
    and is in the same pid namespace on the same host, so its tag is the same. Only a
    process that moves its children to a new pid namespace (``unshare(CLONE_NEWPID)``,
    ``setns``) and then forks without exec would hand them a stale tag; roughfe does
    neither."""
    try:
        namespace = os.stat("/proc/self/ns/pid").st_ino
    except OSError:  # pragma: no cover - non-Linux
        namespace = 0
    return hashlib.sha1(f"{socket.gethostname()}:{namespace}".encode()).hexdigest()[:8]


def writer_prefix(prefix: str) -> str:
    """``PREFIX<machine tag>-<pid>-``: the start of a temporary name of this process."""
    return f"{prefix}{machine_tag()}-{os.getpid()}-"


def pid_alive(pid: int) -> bool:
    """False only when no process ``pid`` exists here (signal 0 tests, sends nothing)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError):
        return True               # another user's process, or a pid we cannot judge: kept
    return True


def remove_dead_writers_files(folder, prefix: str) -> list:
    """Remove the files in ``folder`` named by :func:`writer_prefix` (``prefix`` then 8
    random characters and ``.tmp``) whose writer, on this machine, no longer runs: a
    SIGKILL or a power loss during a write leaves its temporary (never the final name).
    Files of live writers, of other machines and of the older form without a pid (before
    round 2, session 34) stay. A pid that was given out again keeps the file (a leftover
    stays, nothing live is lost). Returns the paths removed; housekeeping, so a folder that
    cannot be listed or a file that went meanwhile is no error."""
    name = re.compile(rf"^{re.escape(prefix)}([0-9a-f]{{8}})-(\d+)-[A-Za-z0-9_]{{8}}\.tmp")
    tag, removed = machine_tag(), []
    with contextlib.suppress(OSError), os.scandir(folder) as entries:
        for entry in entries:
            match = name.match(entry.name)
            if (match is None or match.group(1) != tag or pid_alive(int(match.group(2)))
                    or not entry.is_file(follow_symlinks=False)):
                continue
            with contextlib.suppress(OSError):
                os.unlink(entry.path)
                removed.append(Path(entry.path))
    return removed
