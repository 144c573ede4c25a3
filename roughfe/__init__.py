"""roughfe: contact mechanics of rough surfaces.

Surfaces (generation, measured files, statistics) -> BEM contact (production solver)
-> FEM cross-validation (dolfinx) -> leakage (networks, Reynolds flow) -> surface
roughness genomics (sequencing, design) -> parameter studies -> figures and reports.

Data flows one way; see ``tests/test_architecture.py`` for the enforced import order.
All quantities are SI (metres, pascals, newtons) unless a name says otherwise.
"""
__version__ = "0.1.0"


def load_render_backend() -> bool:
    """Make pyvista renders safe in a process that will also use dolfinx.

    Call it once, before the first ``import dolfinx`` (or ``roughfe.fem``), in a notebook
    or script that both solves with the FEM and renders with pyvista: with Debian's
    dolfinx 0.5.2 and the vtk wheel, vtk must be loaded first, otherwise the first
    off-screen render aborts the process. Returns True when this process can render.
    The command line and the test session do this for you. See :mod:`roughfe._runtime`.
    """
    from ._runtime import load_render_backend as _load

    return _load()

