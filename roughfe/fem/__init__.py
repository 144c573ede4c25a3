"""Finite-element cross-validation of the BEM (the only importer of dolfinx/petsc4py/gmsh).

dolfinx, petsc4py, gmsh and ufl are imported inside the functions that need them, so
``import roughfe.fem`` works (and fails only on use) where dolfinx is not installed.
"""
from .mesh import FACET_TAGS, ProfileMesh, mesh_profile, mirrored_profile

__all__ = ["FACET_TAGS", "ProfileMesh", "mesh_profile", "mirrored_profile"]
