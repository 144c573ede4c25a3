"""Shared test set-up: headless rendering and the location of the shared test data."""
import os
from pathlib import Path

import pytest

# Headless figures in every test process (the Makefile sets the same).
os.environ.setdefault("MPLBACKEND", "Agg")
os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")

# Load order matters: with Debian's dolfinx and the vtk wheel in one process, vtk must be
# loaded first, otherwise the first off-screen render aborts (measured: import dolfinx, then
# render a pyvista scene with a scalar bar -> SIGABRT). Test modules import dolfinx at
# collection, so vtk is loaded here, before any of them.
try:
    import pyvista  # noqa: F401,E402
except ImportError:  # pragma: no cover - pyvista is a core dependency
    pass

REPO = Path(__file__).resolve().parents[1]
TOPOGRAPHIES = REPO.parent / "shared" / "data" / "topographies"


@pytest.fixture(scope="session")
def topographies_dir():
    """Folder of the five measured instrument files (``../shared/data/topographies``)."""
    if not TOPOGRAPHIES.is_dir():
        pytest.skip(f"measured topographies not found at {TOPOGRAPHIES}")
    return TOPOGRAPHIES
