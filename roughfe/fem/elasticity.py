"""The plane-strain stiffness matrix of the FEM body (:mod:`roughfe.fem.contact`), in two
forms of its volumetric term.

The elastic energy density of plane strain (non-dimensional: E = 1) is

    W(u) = mu eps(u) : eps(u) + lambda / 2 (div u)^2,
    mu = 1 / (2 (1 + nu)),   lambda = nu / ((1 + nu)(1 - 2 nu)).

* ``"element"``: both terms integrated exactly on the P1 (constant-strain) triangles,
  K = K_mu + lambda B_e. It locks volumetrically as nu -> 1/2: a P1 field cannot keep
  every element's area, so lambda -> inf makes the body too stiff (measured:
  :data:`roughfe.fem.limits.LOCKING_ERRORS`, +16..42 % in p at nu = 0.499).
* ``"nodal"``: the volumetric term on the nodal average of div u (the average nodal
  pressure idea of Bonet & Burton 1998, Commun. Numer. Meth. Engng 14:437-449): div u
  replaced by its lumped L2 projection on continuous P1, theta = M_L^-1 B u, with
  B_ij = integral phi_i div N_j dA and M_L the row sums of the P1 mass matrix (the nodal
  areas). Then

      K = K_mu + lambda B^T M_L^-1 B,

  which is a u-p mixed form (continuous P1 pressure, lumped pressure mass) with the
  pressure eliminated exactly, because M_L is diagonal. There are as many volumetric
  constraints as nodes, about half the displacement unknowns, so the body does not lock.
  The top vertices and their DOFs are the P1 ones, so the nodal contact of
  :mod:`roughfe.fem.contact` is unchanged. Its matrix couples the neighbours of
  neighbours (more non-zeros than ``"element"``). Measured against the periodic BEM
  (:data:`roughfe.fem.limits.NODAL_ERRORS`): +0.3..0.7 % in p at nu = 0.499 and 0.49999,
  where ``"element"`` is 16..111 % off.

``"auto"`` (the default of :class:`roughfe.fem.FemSolverOptions`) takes ``"nodal"`` above
:data:`roughfe.fem.limits.LOCKING_NU` and ``"element"`` up to it. Up to that nu the FEM
validation's numbers are unchanged (they were measured with ``"element"``).
"""
from __future__ import annotations

from ..errors import InputError
from .limits import LOCKING_NU

#: forms of the volumetric term (module docstring)
VOLUMETRIC = ("auto", "element", "nodal")


def volumetric_form(volumetric: str, nu: float) -> str:
    """``"element"`` or ``"nodal"``: the form ``volumetric`` (one of :data:`VOLUMETRIC`)
    means at Poisson's ratio ``nu``."""
    if volumetric not in VOLUMETRIC:
        raise InputError(f"volumetric must be one of {VOLUMETRIC}, got {volumetric!r}")
    if volumetric == "auto":
        return "nodal" if nu > LOCKING_NU else "element"
    return volumetric


def lame(nu: float) -> tuple:
    """``(lambda, mu)`` of plane strain for E = 1 (module docstring)."""
    return nu / ((1 + nu) * (1 - 2 * nu)), 1.0 / (2 * (1 + nu))


def stiffness_matrix(V, nu: float, bcs, form: str):
    """The assembled stiffness matrix (PETSc Mat, E = 1) of the plane-strain body on the
    vector P1 space ``V``, in the volumetric ``form`` ``"element"`` or ``"nodal"``
    (module docstring). The Dirichlet DOFs of ``bcs`` have a unit diagonal and zero
    rows and columns otherwise (dolfinx's convention)."""
    import ufl
    from dolfinx import fem
    from dolfinx.fem.petsc import assemble_matrix, assemble_vector
    from petsc4py import PETSc

    lam, mu = lame(nu)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)

    def eps(w):
        return ufl.sym(ufl.grad(w))

    if form == "element":          # the form of rounds 1-2 as it was written (same code)
        def sigma(w):
            return lam * ufl.tr(eps(w)) * ufl.Identity(2) + 2 * mu * eps(w)

        K = assemble_matrix(fem.form(ufl.inner(sigma(u), eps(v)) * ufl.dx), bcs=bcs)
        K.assemble()
        return K
    if form != "nodal":
        raise InputError(f"form must be 'element' or 'nodal', got {form!r}")
    K_mu = assemble_matrix(fem.form(2 * mu * ufl.inner(eps(u), eps(v)) * ufl.dx), bcs=bcs)
    K_mu.assemble()
    Q = fem.FunctionSpace(V.mesh, ("CG", 1))
    q = ufl.TestFunction(Q)
    # B with the Dirichlet columns zeroed (the bcs act on V, the trial space), so that
    # B^T M_L^-1 B has zero rows and columns there and K keeps K_mu's unit diagonal
    B = assemble_matrix(fem.form(q * ufl.div(u) * ufl.dx), bcs=bcs)
    B.assemble()
    areas = assemble_vector(fem.form(q * ufl.dx))
    areas.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    areas.reciprocal()
    scaled = B.copy()
    try:
        scaled.diagonalScale(L=areas)                         # M_L^-1 B
        K = B.transposeMatMult(scaled)                        # B^T M_L^-1 B
    finally:
        for obj in (scaled, B, areas):
            obj.destroy()
    K.scale(lam)
    K.axpy(1.0, K_mu, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
    K_mu.destroy()
    return K
