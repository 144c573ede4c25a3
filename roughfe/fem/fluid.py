"""The FEM body of :mod:`roughfe.fem.contact` loaded by a fluid pressure on its top
boundary: the elastic half of the FEM fluid-structure coupling of a profile (issue 12
Sec. 5; the coupling loop is :func:`roughfe.leakage.profile_fsi.coupled_channel`).

The fluid pressure ``p_f`` (Pa, one value per profile sample = top vertex) is the P1
function interpolating those values on the top facets; it acts as the Neumann traction
``t = -p_f n`` (``n`` the outward normal) in the weak form of
:mod:`roughfe.fem.contact`,

    a(u, v) = integral_top t . v ds + (contact reaction),

assembled exactly (consistent load vector of the piecewise-linear pressure; on the flat
top of formulation (a) the vertical resultant is ``W`` times the trapezoidal mean of the
nodal pressures). Contact is the same SNES VI (``vinewtonrsls``) with the approach
imposed as the BEM's half-plane approach ``Delta``: the layer compliance correction uses
the total mean traction (contact + fluid; Betti's theorem, exact also for the discrete
P1 body), so the trapezoidal mean of the elastic displacement is zero, the mean-level
convention of the periodic half-plane BEM on the mirrored profile.

Units: the assembly is done in the non-dimensional units of the contact problem
(coordinates / W, E = 1, displacements / height range), i.e. with the pressure
``p_f W / (E u_ref)``.
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError, check_in_open_interval
from ..model import ContactResult, Material
from .contact import FemSolverOptions, _check_body, _ContactProblem
from .mesh import FACET_TAGS, ProfileMesh


class FluidLoadedBody:
    """A meshed plane-strain body whose top carries a known fluid pressure (module
    docstring). Holds PETSc objects: use as a context manager or call :meth:`close`.

    Parameters
    ----------
    pmesh : ProfileMesh
        From :func:`roughfe.fem.mesh_profile` (formulation ``"flat"`` is the BEM's).
    material : roughfe.model.Material
    options : FemSolverOptions, optional
        Contact solver options (default: VI, MUMPS).

    Raises
    ------
    InputError
        A ``pmesh``, ``material`` or ``options`` of the wrong type (e.g. a dict of
        options), nu >= 0.5; a solve after :meth:`close`.
    """

    def __init__(self, pmesh: ProfileMesh, material: Material,
                 options: FemSolverOptions | None = None):
        import ufl
        from dolfinx import fem
        from dolfinx.fem.petsc import create_vector

        self.problem = _ContactProblem(pmesh, *_check_body(pmesh, material, options))
        self.pmesh = pmesh
        mesh = pmesh.mesh
        fdim = mesh.topology.dim - 1
        Q = fem.FunctionSpace(mesh, ("CG", 1))
        self._pf = fem.Function(Q)
        dofs = fem.locate_dofs_topological(Q, fdim, pmesh.facet_tags.find(FACET_TAGS["top"]))
        n = pmesh.heights.size
        xq = Q.tabulate_dof_coordinates()[dofs, 0] * (n - 1)
        self._dofs, self._sample = dofs, np.rint(xq).astype(np.int64)
        if np.any(np.abs(xq - self._sample) > 1e-6):
            raise InputError("top vertices of the mesh do not coincide with the profile samples")
        ds = ufl.Measure("ds", domain=mesh, subdomain_data=pmesh.facet_tags)
        v = ufl.TestFunction(self.problem.V)
        normal = ufl.FacetNormal(mesh)
        self._form = fem.form(-self._pf * ufl.inner(normal, v) * ds(FACET_TAGS["top"]))
        self._vec = create_vector(self._form)
        self._scale = pmesh.width / (self.problem.material.E * self.problem.u_ref)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self):
        """Free the PETSc objects."""
        if self._vec is not None:
            self.problem.destroy()
            self._vec.destroy()
            self._vec = None

    def load_vector(self, pressure) -> float:
        """Assemble the traction of the nodal ``pressure`` (Pa, one per profile sample)
        and hand it to the contact problem; returns its compressive load (N/m)."""
        from dolfinx.fem.petsc import assemble_vector, set_bc
        from petsc4py import PETSc

        if self._vec is None:
            raise InputError("this FluidLoadedBody is closed (its PETSc objects are freed): "
                             "make a new one")
        p = np.asarray(pressure, dtype=float)
        if p.shape != self.pmesh.heights.shape or not np.all(np.isfinite(p)):
            raise InputError(f"the fluid pressure must be finite, one value per profile "
                             f"sample {self.pmesh.heights.shape} (Pa), got shape {p.shape}")
        self._pf.x.array[self._dofs] = p[self._sample] * self._scale
        self._pf.x.scatter_forward()
        b = self._vec
        with b.localForm() as loc:
            loc.set(0.0)
        assemble_vector(b, self._form)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        set_bc(b, self.problem.bcs)
        pr = self.problem
        local = float(-b.array_r[pr.top_dofs].sum())
        load = pr.K.getComm().tompi4py().allreduce(local) * pr.material.E * pr.u_ref
        pr.set_traction(b, load)
        return load

    def solve(self, pressure, approach: float, keep_fields: bool = False) -> ContactResult:
        """Contact of the body under the fluid ``pressure`` (Pa, nodal) at the half-plane
        approach ``approach`` (m, finite; negative: a clearance before first contact).

        Returns the :class:`~roughfe.model.ContactResult` of the contact problem: its
        ``gap`` and ``displacement`` include the fluid's deformation (zero trapezoidal
        mean), ``pressure``/``load``/``mean_pressure`` are the solid contact's only.
        """
        approach = check_in_open_interval("approach (m)", approach, -np.inf, np.inf)
        self.load_vector(pressure)
        return self.problem.solve_half_plane(approach, keep_fields)
