"""The one way to ask for "a sweep of this surface": :func:`response`.

``response(surface, material, loading, method="bem"|"fem", **solver_options)`` returns a
:class:`roughfe.model.SweepResult` from either method, so genomics, design, studies and
the CLI never call a solver directly and a faster solver or a new physics option reaches
them all at once. It sits above :mod:`roughfe.bem` and :mod:`roughfe.fem` in the layer
order (tests/test_architecture.py); the types it returns live in :mod:`roughfe.model`.
"""
from __future__ import annotations

from typing import Literal, Optional

from .errors import InputError, check_instance
from .model import Loading, Material, SweepResult
from .surfaces import Surface

Method = Literal["bem", "fem"]
METHODS = ("bem", "fem")

#: keyword options of each method (everything else is refused with the list below)
BEM_OPTIONS = ("kernel", "solver", "tol", "max_iter", "compute_stiffness", "hardness",
               "coarse_correction", "unload", "adhesion")
FEM_MESH_OPTIONS = ("depth", "growth", "formulation", "size_max")
FEM_SOLVER_OPTIONS = ("solver", "penalty_factor", "rtol", "atol", "max_it", "petsc_options",
                      "volumetric")
FEM_OPTIONS = FEM_MESH_OPTIONS + FEM_SOLVER_OPTIONS + ("keep_fields",)


#: why the FEM refuses an option of the BEM (said after the list of allowed options)
FEM_REFUSES = {
    "hardness": "the FEM has no plastic interface (it is the frictionless elastic "
                "cross-check of the BEM): a hardness needs method='bem' "
                "(roughfe.bem.solve_contact(..., hardness=))",
}


def _check_options(method, options, allowed):
    unknown = sorted(set(options) - set(allowed))
    if unknown:
        why = "".join(f"; {k}: {FEM_REFUSES[k]}" for k in unknown
                      if method == "fem" and k in FEM_REFUSES)
        raise InputError(f"unknown option(s) {unknown} for method={method!r}; allowed: "
                         f"{list(allowed)}{why}")


def response(surface: Surface, material: Material, loading: Optional[Loading] = None,
             method: Method = "bem", **solver_options) -> SweepResult:
    """Contact response of a rough surface on an elastic body (thesis Sec. 2.2).

    Parameters
    ----------
    surface : Surface
        Heights (m). The FEM needs a 1D profile (plane strain).
    material : Material
        E (Pa) and nu of the elastic body (the rough surface is rigid).
    loading : Loading, optional
        What to impose; default ``Loading()``: 20 equispaced approaches (Eq. 2.5). A
        single ``delta`` / ``mean_pressure`` is a one-step sweep. Negative approaches
        (apart) only with ``adhesion``, whose loading can start apart and jump in.
    method : {"bem", "fem"}
        ``"bem"``: :func:`roughfe.bem.contact_sweep` (the production solver).
        ``"fem"``: :func:`roughfe.fem.fem_contact_sweep` on a gmsh body below the profile,
        approaches (``n_steps`` / ``delta`` / ``deltas``) or mean pressures
        (``mean_pressure`` / ``pressures``, load control to a relative 1e-6), strictly
        increasing: Delta is the half-plane approach, the BEM's; ``n_steps`` gives the BEM's default
        approaches of the evenly mirrored profile, which the body with rollers solves
        (:func:`roughfe.fem.mirrored_profile`), up to full contact. The FEM solves that
        mirrored problem also for a periodic profile: compare it with
        ``response(mirrored_profile(surface), ...)``, not with the periodic BEM of
        ``surface`` itself.
    **solver_options
        BEM: ``kernel``, ``solver``, ``tol``, ``max_iter``, ``compute_stiffness``,
        ``hardness``, ``coarse_correction`` (see :func:`roughfe.bem.solve_contact`), ``unload``
        (:func:`roughfe.bem.contact_sweep`), ``adhesion`` (an
        :class:`roughfe.bem.adhesion.AdhesionLaw`: the adhesive continuation
        :func:`roughfe.bem.adhesion.adhesive_sweep` in the approaches, with ``unload``
        until the surfaces separate; ``kernel``, ``tol``, ``max_iter`` apply, the
        default tolerance is its traction residual 1e-5). FEM: mesh ``depth``, ``growth``,
        ``formulation``, ``size_max`` (:func:`roughfe.fem.mesh_profile`); ``solver``
        (``"vi"`` or ``"penalty"``), ``penalty_factor``, ``rtol``, ``atol``, ``max_it``,
        ``petsc_options``, ``volumetric`` (:class:`roughfe.fem.FemSolverOptions`); ``keep_fields``
        (the index or indices in ``[-n, n)`` of the steps whose full fields are kept,
        :func:`roughfe.fem.fem_contact_sweep`).

    Returns
    -------
    SweepResult
        One :class:`roughfe.model.ContactResult` per step, the same fields from both
        methods; with ``adhesion`` and ``unload`` also ``pull_off_force`` (N, N/m for a
        profile), ``pull_off_pressure`` (Pa) and ``detached`` (False: the force is a
        bound), those of :func:`roughfe.bem.adhesion.adhesive_sweep`.

    Raises
    ------
    InputError
        Unknown method or option, a loading the method can not impose, bad input.
    NoConvergenceError
        A step did not converge.
    """
    loading = Loading() if loading is None else loading
    check_instance("loading", loading, Loading, "a roughfe.model.Loading")
    check_instance("material", material, Material, "a roughfe.model.Material")
    check_instance("surface", surface, Surface, "a roughfe Surface")
    if method == "bem":
        from .bem import contact_sweep

        _check_options(method, solver_options, BEM_OPTIONS)
        if solver_options.get("adhesion") is not None:
            return _adhesive_response(surface, material, loading, solver_options)
        solver_options.pop("adhesion", None)
        return contact_sweep(surface, material, **loading.sweep_arguments(), **solver_options)
    if method == "fem":
        return _fem_response(surface, material, loading, solver_options)
    raise InputError(f"method must be one of {METHODS}, got {method!r}")


def _adhesive_response(surface, material, loading, options) -> SweepResult:
    """``response(..., adhesion=law)``: the adhesive continuation in the approach."""
    from .bem.adhesion import adhesive_sweep, check_adhesive_objects
    from .bem.adhesive_rules import check_adhesive_run

    law = options.pop("adhesion")
    check_adhesive_objects(surface, material, law, law_name="adhesion")
    check_adhesive_run(hardness=options.get("hardness"), solver=options.get("solver", "auto"),
                       coarse_correction=options.get("coarse_correction"),
                       pressure_control=loading.controls_pressure)
    extra = {k: options[k] for k in ("tol", "max_iter") if options.get(k) is not None}
    return adhesive_sweep(surface, material, law, **loading.sweep_arguments(),
                          unload=bool(options.get("unload")),
                          kernel=options.get("kernel", "auto"), **extra).sweep


def _fem_response(surface, material, loading, options) -> SweepResult:
    from .bem.contact_checks import _check_surface
    from .bem.sweep import default_deltas
    from .fem import FemSolverOptions, fem_contact_sweep, mesh_profile, mirrored_profile

    _check_options("fem", options, FEM_OPTIONS)
    if surface.ndim != 1:
        raise InputError(f"method='fem' needs a 1D profile (plane strain), got a surface of "
                         f"shape {surface.shape}")
    _check_surface(surface)            # the BEM's words (n_steps gave no approaches)
    loading.require_contact()          # approaches apart: adhesion only (the BEM's)
    if loading.kind == "n_steps":
        imposed = {"deltas": default_deltas(mirrored_profile(surface), loading.n_steps,
                                            periodic=True)}
    else:
        imposed = loading.sweep_arguments()   # {"deltas": ...} or {"pressures": ...}
    mesh = mesh_profile(surface, **{k: options[k] for k in FEM_MESH_OPTIONS if k in options})
    solver = {("method" if k == "solver" else k): options[k]
              for k in FEM_SOLVER_OPTIONS if k in options}
    return fem_contact_sweep(mesh, material, **imposed, options=FemSolverOptions(**solver),
                             keep_fields=options.get("keep_fields", ()))
