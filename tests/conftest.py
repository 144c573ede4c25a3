"""Shared test set-up: headless rendering and the location of the shared test data."""
import os
from pathlib import Path

import pytest

# Headless figures in every test process (the Makefile sets the same).
os.environ.setdefault("MPLBACKEND", "Agg")
os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")

REPO = Path(__file__).resolve().parents[1]
TOPOGRAPHIES = REPO.parent / "shared" / "data" / "topographies"


@pytest.fixture(scope="session")
def topographies_dir():
    """Folder of the five measured instrument files (``../shared/data/topographies``)."""
    if not TOPOGRAPHIES.is_dir():
        pytest.skip(f"measured topographies not found at {TOPOGRAPHIES}")
    return TOPOGRAPHIES
