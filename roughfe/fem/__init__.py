"""Finite-element cross-validation of the BEM (the only importer of dolfinx/petsc4py/gmsh).

* :func:`mesh_profile` -> :class:`ProfileMesh` -- gmsh mesh of the plane-strain body below
  a profile (formulation (a) ``"flat"`` or (b) ``"profile"``), tagged top/bottom/left/right.
* :func:`fem_contact_sweep` -> :class:`roughfe.model.SweepResult` of
  :class:`roughfe.model.ContactResult` (the BEM's result types; ``FemSweepResult`` and
  ``FemContactResult`` are aliases of them) -- SNES VI or penalty contact with rollers.
* :mod:`roughfe.fem.checkpoint` -- per-step checkpoint file of a sweep
  (``fem_contact_sweep(..., checkpoint=path)``): an interrupted sweep resumes after its last
  finished step, bit for bit.
* :class:`FluidLoadedBody` -- that body with a known fluid pressure as the traction of its
  top (the FEM half of :func:`roughfe.leakage.coupled_channel`).
* :func:`mirrored_profile` -- the periodic profile whose BEM solution is the reference of
  the FEM body with rollers.

dolfinx, petsc4py, gmsh and ufl are imported inside the functions that need them, so
``import roughfe.fem`` works (and fails only on use) where dolfinx is not installed.
"""
from .contact import FemContactResult, FemSweepResult  # noqa: F401 (aliases, round 1)
from .contact import (FemSolverOptions, contact_edge, contact_length, fem_contact_sweep,
                      fem_solve_contact, p_wave_modulus)
from .fluid import FluidLoadedBody
from .mesh import FACET_TAGS, ProfileMesh, mesh_profile, mirrored_profile

__all__ = ["FACET_TAGS", "ProfileMesh", "mesh_profile", "mirrored_profile",
           "FemSolverOptions", "fem_contact_sweep",
           "fem_solve_contact", "contact_edge", "contact_length",
           "p_wave_modulus", "FluidLoadedBody"]
