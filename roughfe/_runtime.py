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

Nothing here imports matplotlib, pyvista or dolfinx at import time.
"""
from __future__ import annotations

import contextlib
import json
import os
import signal
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
