"""The lazy top-level namespace (roughfe/__init__.py, PEP 562): every name resolves to the
object its defining module holds, dir() lists them, a wrong name says what exists, and
``import roughfe`` alone loads none of the numerical layers."""
import importlib
import json
import subprocess
import sys

import pytest

import roughfe


@pytest.mark.parametrize("name", sorted(roughfe._EXPORTS))
def test_every_exported_name_is_its_defining_modules_object(name):
    module = importlib.import_module(roughfe._EXPORTS[name])
    assert getattr(roughfe, name) is getattr(module, name)
    assert name in dir(roughfe) and name in roughfe.__all__


@pytest.mark.parametrize("name", roughfe._SUBMODULES)
def test_submodules_are_attributes_whatever_was_imported_first(name):
    # rf.response is the module roughfe.response before and after an explicit import:
    # a package attribute named like a submodule is that submodule
    assert getattr(roughfe, name) is importlib.import_module(f"roughfe.{name}")
    assert name in dir(roughfe)


def test_the_namespace_runs_a_script():
    import numpy as np
    rf = roughfe
    surface = rf.Surface(np.outer(np.hanning(16), np.hanning(16)) * 1e-6, 1e-4, periodic=True)
    result = rf.solve_contact(surface, rf.Material(E=1e9, nu=0.3), mean_pressure=1e6)
    assert isinstance(result, rf.ContactResult)
    assert result.mean_pressure == pytest.approx(1e6, rel=1e-6)   # imposed load returned


def test_unknown_name_is_an_attribute_error_that_names_the_reader():
    with pytest.raises(AttributeError, match="read_surface.*did you mean load_surface"):
        roughfe.read_surface
    with pytest.raises(AttributeError, match="dir\\(roughfe\\)"):
        roughfe.no_such_thing
    assert not hasattr(roughfe, "plotting_unknown")
    from_import = "from roughfe import read_surface"
    with pytest.raises(ImportError):
        exec(from_import, {})


def test_import_roughfe_loads_no_numerical_layer():
    probe = ("import sys, json, roughfe; print(json.dumps(sorted(m for m in sys.modules "
             "if m.split('.')[0] in ('roughfe', 'numpy', 'scipy', 'dolfinx', 'pyvista'))))")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         timeout=60, check=True).stdout
    assert json.loads(out) == ["roughfe"]
    # one name loads its own layer and not the solvers behind the others
    probe = probe.replace("roughfe;", "roughfe; roughfe.Surface;")
    loaded = json.loads(subprocess.run([sys.executable, "-c", probe], capture_output=True,
                                       text=True, timeout=60, check=True).stdout)
    assert "roughfe.surfaces" in loaded
    assert not {"roughfe.bem", "roughfe.fem", "dolfinx", "pyvista"} & set(loaded)
