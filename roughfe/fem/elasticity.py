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
  constraints as nodes, about half the displacement unknowns, so the body does not lock
  (a count, not a stability proof: the pair is not inf-sup stable, below). The top
  vertices and their DOFs are the P1 ones, so the nodal contact of
  :mod:`roughfe.fem.contact` is unchanged. The matrix couples the neighbours of
  neighbours: 2.7x the non-zeros of ``"element"``.

What was measured against the periodic BEM (round 2, session 28, and its review):

* The Westergaard cosine (:data:`roughfe.fem.limits.NODAL_ERRORS`): +0.3..0.7 % in p up
  to nu = 0.49999, where ``"element"`` is 16..111 % off.
* Measured lines (``sur-2.sur``, 257 samples), whose contact patches are a few nodes
  wide: the nodal body is **softer** (K_element - K_nodal is positive semidefinite: the
  lumped projection never raises the volumetric energy), p 1-4 % low at nu = 0.46-0.49
  (``"element"``: +2..5 % at 0.46, +8..17 % at 0.49), and 0.5-2.5 % low at nu = 0.3,
  where ``"element"`` is within 0.6 %. It converges under refinement (nu = 0.46, one
  line: -5.0, -3.5, -1.4 % at 129, 257, 513 nodes).
* The pair is not inf-sup stable (the inf-sup constant falls with h, unlike a
  Taylor-Hood pair). Measured on the Westergaard cosine (round 2, session 33; docs/theory/
  03_fem_validation.md): its nodal pressure lambda theta, internal and not returned, has
  the checkerboard, 10-32 % of the peak contact pressure at nu = 0.49999 (1-4 % at nu =
  0.3), not falling with h. What is returned stays reliable, so nothing warns:
  the contact pressure's node-to-node oscillation (inside 0.8 of the contact half-width)
  is 4.3, 1.9, 2.5, 0.7, 0.5 % of the peak at 33, 65, 129, 257, 513 nodes (nu = 0.3:
  1.7, 0.9, 0.4, 0.2, 0.1 %), within 7 % of that from nu = 0.4999 to 0.4999999 (bounded
  as nu -> 1/2); the kept sigma_yy (:func:`roughfe.fem.contact.cell_stress_yy`, theta averaged
  over the triangle) is as close to the half-plane's as the element form's at nu = 0.3
  (0.4-1.5 % rms of the peak in the top W/4); the mean pressure and K are not affected
  (tests/test_fem_incompressible.py). Do not compute a pressure from lambda div u of
  the returned displacement.

``"auto"`` (the default of :class:`roughfe.fem.FemSolverOptions`) takes ``"nodal"`` above
:data:`roughfe.fem.limits.LOCKING_NU` = 0.45 and ``"element"`` up to it: there the
element form is the more accurate one on rough lines, and the FEM validation's numbers
(all at nu = 0.3) are unchanged. The switch makes results jump at 0.45 (cosine, 65
nodes: p -0.75 %, K -1.9 % from nu = 0.45 to 0.450001): a study across nu should fix
``volumetric`` to one form.
"""
from __future__ import annotations

import numpy as np

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


def atol_scale(nu: float) -> float:
    """Factor on the SNES absolute tolerance of the body at ``nu``: the round-off of the
    residual K u grows with the largest modulus lambda + 2 mu (E = 1), so an absolute
    tolerance that the solver reaches at nu = 0.45 is below the round-off near nu = 1/2
    (1e-12 at nu = 0.49999: a warm-started VI step ran to DIVERGED_MAX_IT at |F| ~ 3e-12,
    review of round 2, session 28). ``(lambda + 2 mu)(nu) / (lambda + 2 mu)(0.45)``,
    at least 1, so that nothing changes up to :data:`LOCKING_NU`."""
    lam, mu = lame(nu)
    lam0, mu0 = lame(LOCKING_NU)
    return max(1.0, (lam + 2 * mu) / (lam0 + 2 * mu0))


#: number of unknowns up to which the SNES absolute tolerance is not scaled with the size
#: (:func:`atol_size_scale`): above the finest converged levels (r = 8, 392 080 DOFs) of
#: ``validation/fem_convergence.py``, so that none of their numbers moves
ATOL_REF_DOFS = 500_000


def atol_size_scale(n_dofs: int) -> float:
    """Factor on the SNES absolute tolerance of a body of ``n_dofs`` unknowns:
    ``sqrt(n_dofs / ATOL_REF_DOFS)``, at least 1 (exactly 1 up to :data:`ATOL_REF_DOFS`).

    The residual's 2-norm (non-dimensional: E = 1, u in units of the height range)
    stagnates at a round-off floor of about 2 eps |u|_2 (eps = 2.2e-16; the entries of K
    are O(1), its row sums ~ 11), and at a fixed geometry |u|_2 grows like sqrt(n_dofs).
    Measured (round 2, session 35; RMD profile of ``validation/fem_convergence.py``, one
    cold VI solve at the imposed approach 1.3889e-5 m, SNES run 6 iterations past
    convergence): floor 6.7e-14, 1.34e-13, 2.7e-13, 5.4e-13 at r = 1, 2, 4, 8 (7 246,
    26 240, 99 818, 392 080 DOFs; |u|_2 = 1.91 sqrt(n)): n^0.52, 1.1e-12 extrapolated to
    r = 16 (~1.55 M DOFs), where the fixed 1e-12 stopped a step at DIVERGED_MAX_IT with
    |F| = 1.086e-12. With this factor the default 1e-12 becomes 1.76e-12 there, 1.6x the
    extrapolated floor (r = 8: 1.85x at the unscaled 1e-12)."""
    return max(1.0, float(np.sqrt(n_dofs / ATOL_REF_DOFS)))


def nodal_average(cells, areas, values, n_nodes: int):
    """The lumped L2 projection of a cell-wise constant field on continuous P1:
    ``theta_i = sum_c values_c A_c / 3 / sum_c A_c / 3`` over the triangles ``c`` at node
    ``i`` (``cells`` (C, 3) node indices, ``areas`` (C,), ``values`` (C,)); the nodal
    form's div u (module docstring) when ``values`` is the cell div u."""
    corner = np.repeat(np.asarray(areas, dtype=float) / 3.0, 3)
    mass = np.bincount(cells.ravel(), corner, minlength=n_nodes)
    weighted = np.bincount(cells.ravel(), corner * np.repeat(values, 3), minlength=n_nodes)
    return weighted / np.where(mass > 0, mass, 1.0)


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
    Q = fem.FunctionSpace(V.mesh, ("CG", 1))
    q = ufl.TestFunction(Q)
    K_mu = assemble_matrix(fem.form(2 * mu * ufl.inner(eps(u), eps(v)) * ufl.dx), bcs=bcs)
    # B with the Dirichlet columns zeroed (the bcs act on V, the trial space), so that
    # B^T M_L^-1 B has zero rows and columns there and K keeps K_mu's unit diagonal
    B = assemble_matrix(fem.form(q * ufl.div(u) * ufl.dx), bcs=bcs)
    areas = assemble_vector(fem.form(q * ufl.dx))
    scaled = K = None
    try:
        K_mu.assemble()
        B.assemble()
        areas.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        areas.reciprocal()
        scaled = B.copy()
        scaled.diagonalScale(L=areas)                         # M_L^-1 B
        K = B.transposeMatMult(scaled)                        # B^T M_L^-1 B
        K.scale(lam)
        K.axpy(1.0, K_mu, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
    except Exception:
        if K is not None:
            K.destroy()
        raise
    finally:
        for obj in (scaled, B, areas, K_mu):
            if obj is not None:
                obj.destroy()
    return K
