"""The light command (issue 16 sec. 3) and the one render-backend set-up (roughfe._runtime):
what a command imports, progress reporting, rendering after dolfinx was loaded first."""
import json
import subprocess
import sys

import numpy as np
import pytest

from roughfe import progress

_PROBE = """
import os, sys, json
import roughfe.cli.contact_cmd as C
seen = {}
def stop(*a, **k):
    seen.update({m: m in sys.modules for m in ("pyvista", "vtkmodules", "matplotlib",
                                                "dolfinx", "roughfe.genomics", "roughfe.study")})
    print(json.dumps(seen), flush=True)
    os._exit(0)
C.response = stop  # the solve: roughfe.response.response
from roughfe.cli import main
main(sys.argv[1:])
"""


def test_contact_reaches_its_solve_without_render_or_fem_modules(tmp_path):
    from roughfe.surfaces import Surface
    from roughfe.surfaces.io import save_surface
    path = save_surface(Surface(np.outer(np.hanning(8), np.hanning(8)) * 1e-6, 1e-4,
                                periodic=True), tmp_path / "s.npz")
    proc = subprocess.run([sys.executable, "-c", _PROBE, "contact", str(path),
                           "-o", str(tmp_path / "o")], capture_output=True, text=True,
                          timeout=120)
    seen = json.loads(proc.stdout.strip().splitlines()[-1])
    assert len(seen) == 6 and not any(seen.values()), seen          # vtk/matplotlib/dolfinx only when drawn/used


def test_sweeps_report_progress_to_the_listener_only():
    from roughfe.bem import Material, contact_sweep
    from roughfe.surfaces import Surface
    x = np.arange(64) / 64
    s = Surface(1e-6 * np.cos(2 * np.pi * x), 1e-4, periodic=True)
    calls = []
    with progress.listening(lambda d, k, n: calls.append((d, k, n))):
        contact_sweep(s, Material(1e9, 0.0), n_steps=3)
    assert calls == [("BEM load steps", k, 3) for k in range(4)]
    contact_sweep(s, Material(1e9, 0.0), n_steps=2)       # no listener: nothing reported
    assert len(calls) == 4
    assert list(progress.iterate(iter("ab"), "no len")) == ["a", "b"]


@pytest.mark.slow
@pytest.mark.fem
def test_a_picture_after_dolfinx_was_loaded_first_renders_in_a_fresh_process(tmp_path):
    pytest.importorskip("dolfinx")
    code = ("import sys, dolfinx, numpy as np; from roughfe import _runtime; "
            "assert not _runtime.can_render_here() and not _runtime.load_render_backend(); "
            "from roughfe.plotting.leakage import pressure_map; "
            "pressure_map(np.outer(np.arange(8.), np.ones(8)), (1e-4, 1e-4), sys.argv[1]); "
            "assert 'vtkmodules.vtkCommonCore' not in sys.modules")
    proc = subprocess.run([sys.executable, "-c", code, str(tmp_path / "p.png")],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert (tmp_path / "p.png").stat().st_size > 5000



def test_public_render_backend_call_orders_vtk_before_dolfinx():
    """roughfe.load_render_backend (the notebook entry point) loads vtk in a fresh process
    before dolfinx, after which an off-screen render with a scalar bar (the label
    formatting that aborts in the other order) works."""
    import os

    from roughfe._runtime import headless_environment
    code = ("import sys, roughfe; assert roughfe.load_render_backend(); "
            "assert 'vtkmodules.vtkCommonCore' in sys.modules; "
            "import dolfinx, pyvista; p = pyvista.Plotter(off_screen=True); "
            "m = pyvista.Sphere(); m['z'] = m.points[:, 2]; p.add_mesh(m, scalars='z'); "
            "img = p.screenshot(return_img=True); assert img.ndim == 3; print('rendered')")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=headless_environment(dict(os.environ)), timeout=180)
    assert out.returncode == 0, out.stderr[-2000:]
    assert "rendered" in out.stdout


def test_python_dash_m_roughfe_is_the_command(tmp_path):
    """``python -m roughfe`` runs the roughfe command (it said "No module named
    roughfe.__main__"; three reviewers tried it first)."""
    proc = subprocess.run([sys.executable, "-m", "roughfe", "--version"], capture_output=True,
                          text=True, timeout=120, cwd=tmp_path)
    assert proc.returncode == 0 and proc.stdout.startswith("roughfe "), proc.stderr


def test_a_reader_leaving_the_pipe_stops_the_command_quietly(tmp_path):
    """`roughfe ... | head -1`: the reader closes the pipe; the command stopped with
    "error: Broken pipe" and exit 2, now quietly with SIGPIPE's 141."""
    from roughfe.surfaces import Surface
    from roughfe.surfaces.io import save_surface
    path = save_surface(Surface(np.random.default_rng(0).normal(size=(16, 16)) * 1e-6, 1e-4,
                                periodic=True), tmp_path / "s.npz")
    script = ("import sys\nfrom roughfe.cli import main\n"
              "import roughfe.cli.surface_cmds as S\n"
              "def chatty(args):\n"
              "    for k in range(200000):\n"
              "        print('line', k)\n"
              "S._info = chatty\n"
              "sys.exit(main(sys.argv[1:]))\n")
    proc = subprocess.run(f"{sys.executable} -c \"{script}\" info {path} | head -1; "
                          f"exit ${{PIPESTATUS[0]}}", shell=True, executable="/bin/bash",
                          capture_output=True, text=True, timeout=120)
    assert proc.stdout == "line 0\n" and proc.returncode == 141, proc.stderr
    assert "error" not in proc.stderr and "Exception" not in proc.stderr, proc.stderr


def test_help_into_a_closed_pipe_is_141_without_a_traceback(tmp_path):
    """`roughfe contact --help | true`: argparse's print_help met the closed pipe before
    main's handler (a BrokenPipeError traceback, exit 1). The read end is closed before
    the command starts, so the write fails every time (no race with the reader)."""
    import os
    read, write = os.pipe()
    os.close(read)
    try:
        proc = subprocess.run([sys.executable, "-m", "roughfe", "contact", "--help"],
                              stdout=write, stderr=subprocess.PIPE, text=True, timeout=120,
                              cwd=tmp_path)
    finally:
        os.close(write)
    assert proc.returncode == 141, proc.stderr
    assert "Traceback" not in proc.stderr and "Error" not in proc.stderr, proc.stderr


def test_a_reader_leaving_a_command_that_loaded_petsc_is_still_141(tmp_path):
    """`roughfe leak ... | true`: the FV Reynolds solve imports petsc4py, whose signal
    handlers took SIGPIPE from Python: exit 59 and an MPI abort banner on stderr. The
    command line leaves the signals to Python (PETSc's -no_signal_handler)."""
    from roughfe.surfaces import spectral_surface
    from roughfe.surfaces.io import save_surface
    path = save_surface(spectral_surface(32, 1e-4, 0.8, rms_height=1e-6, rng=1),
                        tmp_path / "s.npz")
    env = {k: v for k, v in __import__("os").environ.items() if k != "PETSC_OPTIONS"}
    proc = subprocess.run(f"{sys.executable} -m roughfe leak {path} --pressure 1e7 "
                          f"--no-figures -o {tmp_path / 'out'} | true; exit ${{PIPESTATUS[0]}}",
                          shell=True, executable="/bin/bash", capture_output=True, text=True,
                          timeout=300, env=env, cwd=tmp_path)
    assert proc.returncode == 141, proc.stderr[-2000:]
    assert "PETSC ERROR" not in proc.stderr and "MPI_ABORT" not in proc.stderr, proc.stderr


def test_python_signals_for_petsc_keeps_the_users_options():
    from roughfe._runtime import python_signals_for_petsc
    env = python_signals_for_petsc({"PETSC_OPTIONS": "-log_view"})
    assert env["PETSC_OPTIONS"].split() == ["-log_view", "-no_signal_handler"]
    assert python_signals_for_petsc(dict(env))["PETSC_OPTIONS"] == env["PETSC_OPTIONS"]
    assert python_signals_for_petsc({})["PETSC_OPTIONS"] == "-no_signal_handler"


def test_machine_tag_is_computed_once_and_the_same_after_fork():
    """machine_tag (in every temporary file's name) hashed the hostname on each write;
    it is cached now (internal: no number or name changes). The cached tag is the one a
    fresh computation gives, here and in a forked child (same host, same pid namespace)."""
    import os
    from roughfe._runtime import machine_tag, writer_prefix
    tag = machine_tag()
    assert tag == machine_tag.__wrapped__() and len(tag) == 8
    hits = machine_tag.cache_info().hits
    assert writer_prefix("p").startswith(f"p{tag}-{os.getpid()}-")
    assert machine_tag.cache_info().hits == hits + 1
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:            # the child: a fresh computation, reported through the pipe
        try:
            os.write(write, machine_tag.__wrapped__().encode())
        finally:
            os._exit(0)
    os.close(write)
    with os.fdopen(read) as pipe:
        child = pipe.read()
    os.waitpid(pid, 0)
    assert child == tag
