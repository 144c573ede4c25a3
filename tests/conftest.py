"""Shared test set-up: headless rendering and the location of the shared test data."""
from pathlib import Path

import pytest

# Headless figures in every test process, and vtk loaded before any test module imports
# dolfinx (in the other order the first off-screen render aborts): roughfe._runtime.
from roughfe._runtime import load_render_backend  # noqa: E402

load_render_backend()

from roughfe.surfaces.io import topographies_folder  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
TOPOGRAPHIES = topographies_folder()


@pytest.fixture(scope="session")
def topographies_dir():
    """Folder of the five measured instrument files (``../shared/data/topographies``)."""
    if not TOPOGRAPHIES.is_dir():
        pytest.skip(f"measured topographies not found at {TOPOGRAPHIES}")
    return TOPOGRAPHIES


@pytest.fixture
def deflations_made(monkeypatch):
    """The grid shapes of the two-level corrections the BEM solves make from now on (the
    periodic BlockDeflation and the non-periodic PaddedBlockDeflation, as
    ``roughfe.bem.contact`` makes them), in order."""
    from roughfe.bem import contact
    made = []
    for name in ("BlockDeflation", "PaddedBlockDeflation"):
        original = getattr(contact, name)

        def make(op, block, _original=original, **options):
            made.append(op.shape)
            return _original(op, block, **options)
        monkeypatch.setattr(contact, name, make)
    return made
