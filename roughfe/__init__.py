"""roughfe: contact mechanics of rough surfaces.

Surfaces (generation, measured files, statistics) -> BEM contact (production solver)
-> FEM cross-validation (dolfinx) -> leakage (networks, Reynolds flow) -> surface
roughness genomics (sequencing, design) -> parameter studies -> figures and reports.

Data flows one way; see ``tests/test_architecture.py`` for the enforced import order.
All quantities are SI (metres, pascals, newtons) unless a name says otherwise.

The top-level namespace is lazy (PEP 562): ``import roughfe`` loads nothing but this
file, and ``roughfe.Surface`` imports :mod:`roughfe.surfaces` on first use, so the
command line and scripts pay only for what they touch. Each name is defined in the
module :data:`_EXPORTS` gives for it (one table, no copies)::

    import roughfe as rf
    surface = rf.load_surface("scan.x3p").detrended("plane")
    sweep = rf.response.response(surface, rf.Material(E=210e9, nu=0.3),
                                 rf.Loading(pressures=(1e7, 1e8)))

``rf.response`` is the *module* :mod:`roughfe.response` (its function is
``rf.response.response``): a package attribute named like a submodule is replaced by
that submodule as soon as anything imports it, so a function of that name could not be
relied on here.
"""
from importlib import import_module as _import_module

__version__ = "0.1.0"

#: name -> module that defines it (the one table of the top-level namespace)
_EXPORTS = {
    # surfaces: the data type, reading/writing, generators, statistics
    **dict.fromkeys(("Surface", "load_surface", "save_surface", "spectral_surface",
                     "spectral_profile", "rmd_surface", "rmd_profile", "wm_profile",
                     "mwm_surface", "sphere_cap", "surface_statistics", "power_spectrum",
                     "spectral_moments", "fit_hurst"), "roughfe.surfaces"),
    # the contract types shared by the BEM and the FEM
    **dict.fromkeys(("Material", "composite", "Loading", "ContactResult", "SweepResult"),
                    "roughfe.model"),
    # the BEM solver (one problem; a warm-started sweep)
    **dict.fromkeys(("solve_contact", "contact_sweep"), "roughfe.bem"),
    # Persson's theory from the PSD
    **dict.fromkeys(("persson",), "roughfe.theory"),
    # leakage through a contact
    **dict.fromkeys(("leakage_of_contact", "analyse_leakage", "reynolds_flow",
                     "free_volume_network", "critical_constriction"), "roughfe.leakage"),
    # the exceptions and warnings every layer raises
    **dict.fromkeys(("RoughfeError", "InputError", "FileFormatError", "NoConvergenceError",
                     "ResolutionWarning", "TruncatedFileWarning"), "roughfe.errors"),
}

#: subpackages and modules reachable as attributes (``rf.bem``, ``rf.response``, ...);
#: plotting and cli are left out: nothing in the library imports them (STYLE.md (a))
_SUBMODULES = ("surfaces", "model", "response", "theory", "bem", "fem", "leakage",
               "genomics", "study", "reference", "errors", "writers")

__all__ = ["load_render_backend", *_EXPORTS]


def __getattr__(name):
    """Import the module behind a top-level name on first use (PEP 562)."""
    if name in _SUBMODULES:
        return _import_module(f"{__name__}.{name}")
    module = _EXPORTS.get(name)
    if module is None and _is_submodule(name):
        # ``from . import progress`` asks here before it imports the submodule: say no,
        # cheaply (no suggestions: difflib's import is the CLI's start-up time)
        raise AttributeError(f"module 'roughfe' has no attribute {name!r}")
    if module is None:
        import difflib
        # a reader/writer asked for by another verb first (read_surface -> load_surface)
        verbs = name.replace("read", "load").replace("write", "save")
        close = [verbs] if verbs in _EXPORTS else []
        close += [c for c in difflib.get_close_matches(name, [*_EXPORTS, *_SUBMODULES], n=3,
                                                       cutoff=0.6) if c not in close]
        hint = f"; did you mean {', '.join(close)}?" if close else ""
        raise AttributeError(
            f"module 'roughfe' has no attribute {name!r}{hint} (dir(roughfe) lists the "
            f"top-level names; everything else is in its subpackage, e.g. "
            f"roughfe.surfaces.stats)")
    value = getattr(_import_module(module), name)
    globals()[name] = value            # later look-ups skip __getattr__
    return value


def _is_submodule(name) -> bool:
    """Whether ``name`` is a module or package file of roughfe (not yet imported)."""
    from os import path
    here = path.dirname(__file__)
    return (path.isfile(path.join(here, f"{name}.py"))
            or path.isfile(path.join(here, name, "__init__.py")))


def __dir__():
    public = {k for k in globals() if not k.startswith("_") or k.startswith("__")}
    return sorted(public | set(_EXPORTS) | set(_SUBMODULES))


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
