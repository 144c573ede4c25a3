"""Figures of the FEM cross-validation: they read results and write PNGs (smoke + content)."""
import numpy as np
import pytest

pytest.importorskip("dolfinx")

from roughfe.bem import Material  # noqa: E402
from roughfe.fem import mesh_profile  # noqa: E402
from roughfe.fem.contact import fem_solve_contact  # noqa: E402
from roughfe.plotting.fem import plot_area_stiffness, render_deformed_mesh  # noqa: E402
from roughfe.surfaces import Surface  # noqa: E402

pytestmark = pytest.mark.fem


def test_deformed_mesh_picture_after_a_dolfinx_solve(tmp_path):
    """After a dolfinx solve the picture renders (in-process: conftest loaded vtk first
    through roughfe._runtime); the stresses handed to it are compressive under the contact."""
    n = 17
    x = np.arange(n) * 1e-3 / (n - 1)
    surf = Surface(1e-6 * np.cos(np.pi * x / 1e-3), n * 1e-3 / (n - 1))
    r = fem_solve_contact(mesh_profile(surf, growth=0.3), Material(E=1e9, nu=0.3), 0.5e-6,
                          keep_fields=True)
    assert r.fields["stress_yy"].min() < 0 and r.fields["stress_yy"].size > 100
    path = render_deformed_mesh(r.fields, tmp_path / "mesh.png", window_size=(400, 300))
    assert path.stat().st_size > 5000
    curves = [{"label": "FEM", "mean_pressure": [1e6, 2e6], "area_fraction": [0.1, 0.2],
               "stiffness": [1e12, 2e12]}]
    assert plot_area_stiffness(curves, tmp_path / "c.png").stat().st_size > 5000
