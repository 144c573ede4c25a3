"""Frictionless contact of a plane-strain elastic body with a rigid rough/flat obstacle.

The FEM cross-validation of the BEM (thesis Sec. 2.2, Eq. 2.3-2.7). A body meshed by
:func:`roughfe.fem.mesh.mesh_profile` (width W, depth H_d; lateral rollers u_x = 0 at
x = 0, W and a roller bottom u_y = 0) is pushed up against a rigid obstacle that is
lowered by the approach Delta. For each top vertex i (profile sample i) the initial gap
is ``g0_i = max(h) - h_i``, and the non-penetration condition reads

    u_y,i <= g0_i - Delta                                          (Signorini, Eq. 2.5)

in both geometric formulations: (a) ``"flat"`` body + rough rigid obstacle (small slope,
the BEM assumptions) and (b) ``"profile"`` body with the rough top + rigid flat (finite
slopes; the flat is vertical-normal, so the same nodal condition is exact for it).

Weak form (plane strain, linear elasticity): find u with u_x = 0 on left/right and
u_y = 0 on the bottom such that

    a(u, v) = integral_Omega sigma(u) : eps(v) dA = integral_top t . v ds  for all v,
    sigma(u) = lambda tr(eps(u)) I + 2 mu eps(u),   eps(u) = sym(grad u),

(above nu = 0.45, by default, with tr(eps(u)) replaced by its nodal average in the
lambda term: the locking-free form of :mod:`roughfe.fem.elasticity`, selected by
``FemSolverOptions.volumetric``),

with the contact traction t from one of two solvers:

* ``"vi"``: PETSc SNES ``vinewtonrsls`` (reduced-space active set) with upper bounds
  ``g0 - Delta`` on the owned top vertical DOFs (+-inf elsewhere), line search
  ``basic`` (``bt`` stalls with DIVERGED_LINE_SEARCH on large steps), LU by MUMPS.
* ``"penalty"``: residual ``a(u, v) + kappa integral_top <u_y - g>_+ v_y ds`` with
  kappa = k E / delta (k = ``penalty_factor``, delta the top element size), integrated
  with the nodal (2-point Gauss-Lobatto-Legendre) rule. For P1 elements that rule makes
  the term diagonal, ``kappa w_i <u_y,i - g_i>_+`` with trapezoidal weights w_i (dx, and
  dx/2 at the ends), which is what is assembled here (no form recompilation per step).
  Newton (SNES ``newtonls``, line search ``basic``, no divergence test) with the exact
  generalized Jacobian, each step started on the obstacle (so that SNES's relative test
  sees the elastic residual, not kappa times a penetration). A sweep that penetrates by
  more than 1e-3 of its approach warns (:func:`roughfe.fem.limits.warn_penetration`).

Everything is solved in non-dimensional units (coordinates / W, displacements / height
range, E = 1): the SNES VI active-set test uses absolute tolerances, and displacements of
1e-7 m made most steps fail. Results are converted back to SI.

Outputs per load step (:class:`roughfe.model.ContactResult`, the BEM's result type):
the nodal contact forces are the reaction ``-(K u)_y`` on the top vertical DOFs (N/m);
the load is their sum, the mean pressure load / W; ``pressure = force / w_i``; contact
vertices give A* = sum(w_i in contact) / W. Delta is corrected for the finite depth: a
uniform pressure p on a roller-supported layer of depth H_d shortens it by exactly
p H_d / M, M = E (1 - nu) / ((1 + nu)(1 - 2 nu)) (the P-wave/oedometric modulus), and by
Betti's theorem the mean top displacement under any pressure distribution is
-p_mean H_d / M. So ``delta = delta_applied - p_mean H_d / M`` is the approach with
zero mean elastic displacement: the convention of the periodic half-plane BEM. The
stiffness K = dp/dDelta_corrected (thesis Eq. 2.7) is computed exactly for the converged
contact set (and by central differences over a sweep, ``stiffness_fd``).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, Mapping

import numpy as np

from ..errors import (InputError, NoConvergenceError, check_finite_nonnegative,
                      check_finite_positive, check_in_open_interval, check_instance,
                      check_int, check_real_array)
from ..frozen import FrozenMapping
from ..model import ContactResult, Material, SweepResult
from ..surfaces import Surface
from ..surfaces.stats import rms_height, rms_slope
from .elasticity import (VOLUMETRIC, atol_scale, atol_size_scale, lame, nodal_average,
                         stiffness_matrix, volumetric_form)
from .checkpoint import SweepCheckpoint, sweep_key
from .limits import patch_width, warn_locking, warn_sweep
from .mesh import FACET_TAGS, ProfileMesh, mirrored_profile
from .petsc_tools import (LU_MUMPS, PrefixedOptions, check_snes, fresh_pc_on_resize,
                          unique_prefix)

Method = Literal["vi", "penalty"]
METHODS = ("vi", "penalty")
_KSP_PREFIXES = ("ksp_", "pc_", "mg_", "mat_")
#: Load control: relative tolerance on the mean pressure of a step.
LOAD_RTOL = 1e-6
#: The largest ``penalty_factor`` k (kappa = k E / dx): above it the round-off of the
#: penalty term is the error (FemSolverOptions).
MAX_PENALTY = 1e8
REFERENCES = ("Benson S.J., Munson T.S. (2006) Optim. Methods Softw. 21:155-168 (SNES VI)",
              "Wriggers P. (2006) Computational Contact Mechanics, Springer (penalty)",
              "Johnson K.L. (1985) Contact Mechanics, Sec. 13.2 (Westergaard)")


def p_wave_modulus(material: Material) -> float:
    """M = E (1 - nu) / ((1 + nu)(1 - 2 nu)) (Pa): the uniaxial-strain (layer) modulus.

    A roller-supported layer of depth H_d under a uniform pressure p shortens by p H_d / M.
    """
    E, nu = material.E, material.nu
    return E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))


@dataclass(frozen=True)
class FemSolverOptions:
    """Numerical options of the FEM contact solvers (physical data live elsewhere).

    Attributes
    ----------
    method : {"vi", "penalty"}
        SNES variational inequality or penalty + Newton.
    penalty_factor : float
        k in kappa = k E / delta (1e3-1e4 recommended; at most :data:`MAX_PENALTY`).
    rtol, atol : float
        SNES relative / absolute residual tolerances (non-dimensional residual). Above
        nu = 0.45 ``atol`` is scaled by (lambda + 2 mu) / its value at nu = 0.45
        (:func:`roughfe.fem.elasticity.atol_scale`): the residual's round-off grows with
        the modulus, and 1e-12 is below it near nu = 1/2. Above 500 000 unknowns
        (:data:`roughfe.fem.elasticity.ATOL_REF_DOFS`) it is also scaled by
        sqrt(n_dofs / 500 000) (:func:`roughfe.fem.elasticity.atol_size_scale`): the
        residual's round-off floor grows like sqrt(n_dofs), measured 6.7e-14 at 7 246
        DOFs to 5.4e-13 at 392 080 (RMD profile of ``validation/fem_convergence.py``,
        r = 1 ... 8), and the fixed 1e-12 stopped r = 16 (~1.55 M DOFs) at
        DIVERGED_MAX_IT with |F| = 1.086e-12. The value used is in the result's
        ``tolerance`` (the larger of it and ``rtol |F(x_0)|``).
    max_it : int
        SNES iteration limit per load step.
    petsc_options : mapping, optional
        Extra PETSc options (without prefix) overriding the defaults, e.g.
        ``{"snes_linesearch_type": "bt"}``. The linear-solver keys (``ksp_*``, ``pc_*``,
        ``mg_*``, ``mat_*``; default MUMPS LU) apply to the SNES's inner solves and to the
        incremental-stiffness solve, e.g. ``{"ksp_type": "cg", "pc_type": "hypre",
        "ksp_rtol": 1e-12}`` (see ``benchmarks/bench_fem.py`` for their cost). A value
        PETSc refuses (``{"snes_type": "foo"}``) raises InputError when the solver is
        built, a key PETSc never reads (a misspelling, or ``ksp_rtol`` with the default
        ``ksp_type preonly``) after the first solve that takes a Newton step (steps
        without contact take none and set up no linear solver)
        (:class:`roughfe.fem.petsc_tools.PrefixedOptions`). ``rtol`` lies in (0, 1).
    volumetric : {"auto", "element", "nodal"}
        The volumetric term of the stiffness (:mod:`roughfe.fem.elasticity`):
        ``"element"`` exact on the P1 triangles (locks as nu -> 1/2), ``"nodal"`` on the
        nodal average of div u (no locking: +0.3..0.7 % against the BEM on a cosine up to
        nu = 0.49999; softer, 1-4 % low, on measured lines of 257 nodes), ``"auto"``
        ``"nodal"`` above nu = 0.45 (:data:`roughfe.fem.limits.LOCKING_NU`),
        ``"element"`` up to it (results jump by ~1 % at that switch: fix one form for a
        study across nu).
    """

    method: Method = "vi"
    penalty_factor: float = 1e4
    rtol: float = 1e-10
    atol: float = 1e-12
    max_it: int = 50
    petsc_options: Mapping | None = None
    volumetric: str = "auto"

    def __post_init__(self):
        if self.method not in METHODS:
            raise InputError(f"method must be one of {METHODS}, got {self.method!r}")
        if self.volumetric not in VOLUMETRIC:
            raise InputError(f"volumetric must be one of {VOLUMETRIC}, got "
                             f"{self.volumetric!r}")
        if check_finite_positive("penalty_factor", self.penalty_factor) > MAX_PENALTY:
            raise InputError(
                f"penalty_factor must be <= {MAX_PENALTY:g} (1e3-1e4 recommended), got "
                f"{self.penalty_factor!r}: the penalty stiffness k E / dx swamps the body's "
                f"in round-off (cosine, 17 nodes: p off by 2e-6 at 1e10, 4e-4 at 1e12, 1 % "
                f"at 1e14); use method='vi' for the exact constraint")
        check_in_open_interval("rtol (SNES relative tolerance)", self.rtol, 0.0, 1.0)
        check_finite_nonnegative("atol (SNES absolute tolerance)", self.atol)
        check_int("max_it (SNES iterations per step)", self.max_it, 1)
        if self.petsc_options is not None:
            object.__setattr__(self, "petsc_options", FrozenMapping(self.petsc_options))


def _check_body(pmesh, material, options) -> tuple:
    """``(material, options)`` of a FEM body, checked: ``pmesh`` a ProfileMesh, ``material``
    a Material with nu < 0.5 (with ``volumetric="element"`` above
    :data:`roughfe.fem.limits.LOCKING_NU` = 0.45 a ResolutionWarning, volumetric locking
    with the measured error), ``options`` a
    FemSolverOptions (None: the defaults); an InputError naming the argument otherwise."""
    check_instance("pmesh", pmesh, ProfileMesh, "a roughfe.fem.ProfileMesh (mesh_profile)")
    check_instance("material", material, Material, "a roughfe.model.Material")
    if material.nu >= 0.5:
        raise InputError(f"the FEM body needs nu < 0.5 (its Lame lambda is infinite at 0.5; "
                         f"below it the default nodal volumetric form does not lock), got "
                         f"nu = {material.nu!r}")
    options = FemSolverOptions() if options is None else options
    check_instance("options", options, FemSolverOptions, "a roughfe.fem.FemSolverOptions")
    if volumetric_form(options.volumetric, material.nu) == "element":
        warn_locking(material.nu, stacklevel=4)
    return material, options


#: The FEM returns the one result types of :mod:`roughfe.model`; these names are aliases
#: kept for the code written against round 1.
FemContactResult = ContactResult
FemSweepResult = SweepResult


class _ContactProblem:
    """Assembled stiffness, top DOFs and one configured SNES (internal, per mesh+method)."""

    def __init__(self, pmesh: ProfileMesh, material: Material, options: FemSolverOptions):
        from dolfinx import fem
        from petsc4py import PETSc

        self.pmesh, self.material, self.options = pmesh, material, options
        mesh = pmesh.mesh
        h = pmesh.heights
        # displacement unit: the height range (a flat profile -- a flat punch -- uses W/1000)
        self.u_ref = float(h.max() - h.min()) or 1e-3 * pmesh.width
        V = fem.VectorFunctionSpace(mesh, ("CG", 1))
        self.V = V
        fdim = mesh.topology.dim - 1
        ft = pmesh.facet_tags
        bcs = []
        for name, comp in (("left", 0), ("right", 0), ("bottom", 1)):
            facets = ft.find(FACET_TAGS[name])
            dofs = fem.locate_dofs_topological(V.sub(comp), fdim, facets)
            bcs.append(fem.dirichletbc(PETSc.ScalarType(0), dofs, V.sub(comp)))
        self.volumetric = volumetric_form(options.volumetric, material.nu)
        self.K = stiffness_matrix(V, material.nu, bcs, self.volumetric)
        self.bcs = bcs

        # owned top vertices -> profile sample index
        bs = V.dofmap.index_map_bs
        n_owned = V.dofmap.index_map.size_local
        blocks = fem.locate_dofs_topological(V, fdim, ft.find(FACET_TAGS["top"]))
        blocks = blocks[blocks < n_owned]
        xy = V.tabulate_dof_coordinates()[blocks, :2]
        n = h.size
        idx = np.rint(xy[:, 0] * (n - 1)).astype(np.int64)
        if np.any(np.abs(xy[:, 0] * (n - 1) - idx) > 1e-6):
            raise InputError("top vertices of the mesh do not coincide with the profile samples")
        self.sample = idx
        self.top_dofs = (bs * blocks + 1).astype(np.int32)       # local u_y DOFs (owned)
        w = np.full(n, 1.0 / (n - 1))                            # trapezoid weights / W
        w[[0, -1]] *= 0.5
        self.weights = w[idx]
        self.gap0 = (h.max() - h[idx]) / self.u_ref
        # sigma and rms slope of the evenly mirrored (periodic) profile: the problem the
        # body with rollers solves (trapezoidal rms over W)
        mirror = mirrored_profile(Surface(h, h.size * pmesh.element_size))
        self.rms_height, self.rms_slope = rms_height(mirror), rms_slope(mirror)
        self.x, self.y = self.K.createVecs()
        self.x.set(0.0)
        self.r = self.x.duplicate()
        self.kappa = options.penalty_factor * (n - 1)         # k E/delta in units E/W
        self.last_pressure = 0.0
        # a known traction on the body (the fluid pressure of roughfe.fem.fluid): its load
        # vector in the non-dimensional units of K (None: none) and its load (N/m)
        self.traction, self.traction_load = None, 0.0
        self.snes = self._make_snes()

    # -- SNES ---------------------------------------------------------------------------
    def set_traction(self, vector, load: float):
        """Load the body by a known traction as well: ``vector`` is its load vector in the
        units of K (PETSc Vec, zero on the Dirichlet DOFs, owned by the caller), ``load``
        its resultant compressive load on the top (N/m), which enters the layer
        compliance correction of ``delta`` (Betti: the mean top displacement is
        -(total mean pressure) H_d / M). ``None``, 0 removes it."""
        self.traction, self.traction_load = vector, float(load)

    def _residual(self, snes, x, F):
        self.K.mult(x, F)
        if self.traction is not None:
            F.axpy(-1.0, self.traction)
        if self.options.method == "penalty":
            pen = np.maximum(x.array_r[self.top_dofs] - self.bound, 0.0)
            F.array[self.top_dofs] += self.kappa * self.weights * pen

    def _jacobian(self, snes, x, J, P):
        """VI: the constant stiffness K. Penalty: K + kappa w_i on the penetrating u_y."""
        from petsc4py import PETSc

        if self.options.method == "penalty":
            self.K.copy(J, structure=J.Structure.SAME_NONZERO_PATTERN)
            # (>=: a vertex on the obstacle, where the penalty starts, is active, an
            # element of the generalized Jacobian there; with > the first step from
            # the projected start of ``solve`` was a wasted free-body step)
            active = (x.array_r[self.top_dofs] >= self.bound).astype(float)
            d = J.createVecLeft()
            try:        # petsc4py queues a dropped Vec of a non-self comm for a
                        # PETSc.garbage_cleanup() nobody calls: once per Newton step
                d.set(0.0)
                d.array[self.top_dofs] = self.kappa * self.weights * active
                J.setDiagonal(d, addv=PETSc.InsertMode.ADD_VALUES)
            finally:
                d.destroy()
            J.assemble()

    def _make_snes(self):
        from petsc4py import PETSc

        opt = self.options
        snes = PETSc.SNES().create(self.K.getComm())
        J = self.K if opt.method == "vi" else self.K.duplicate(copy=True)
        snes.setFunction(self._residual, self.r)
        snes.setJacobian(self._jacobian, J, J)
        self.atol = (opt.atol * atol_scale(self.material.nu)
                     * atol_size_scale(self.x.getSize()))
        snes.setTolerances(rtol=opt.rtol, atol=self.atol, max_it=int(opt.max_it))
        snes.setConvergenceHistory(reset=True)       # |F(x_0)| of each solve: the tolerance
        # no divergence test (PETSc's default stops at |F| > 1e4 |F(x_0)|): a step started
        # from the previous solution at a smaller approach unloads the body in its first
        # Newton step, a residual jump far beyond that, and the penalty Newton then
        # converges (load control and full contact stopped with DIVERGED_DTOL)
        defaults = {"snes_type": "vinewtonrsls" if opt.method == "vi" else "newtonls",
                    "snes_linesearch_type": "basic", "snes_divergence_tolerance": -1,
                    **LU_MUMPS}
        petsc = {**defaults, **dict(opt.petsc_options or {})}
        # the linear-solver options (ksp_*, pc_*) serve the SNES's inner solves and the
        # incremental-stiffness solve alike (MUMPS LU by default; e.g. CG + hypre)
        self.ksp_options = {k: v for k, v in petsc.items() if k.startswith(_KSP_PREFIXES)}
        prefix = unique_prefix(opt.method)
        what = f"the FEM contact solver ({opt.method})"
        self._options = [PrefixedOptions(
            snes, prefix, {k: v for k, v in petsc.items() if k not in self.ksp_options},
            what, checked=opt.petsc_options or {})]
        ksp = snes.getKSP()
        try:
            self._options.append(PrefixedOptions(ksp, prefix, self.ksp_options, what,
                                                 checked=opt.petsc_options or {}))
        except InputError:
            self._options[0].release()
            raise
        if opt.method == "vi" and self.ksp_options.get("pc_type") == "gamg":
            fresh_pc_on_resize(ksp, self._options[1])      # the reduced system changes size
        self.lower = self.x.duplicate()
        self.upper = self.x.duplicate()
        self.lower.set(-PETSc.INFINITY)
        self.upper.set(PETSc.INFINITY)
        return snes

    def destroy(self):
        """Free the PETSc objects (nothing of this problem outlives its sweep)."""
        for obj in (self.snes, self.K, self.x, self.y, self.r, self.lower, self.upper):
            obj.destroy()
        for options in self._options:
            options.release()

    # -- one load step ----------------------------------------------------------------
    def solve(self, delta: float, keep_fields: bool = False) -> ContactResult:
        """Solve for the imposed approach ``delta`` (m), from the previous solution."""
        self.bound = self.gap0 - float(delta) / self.u_ref
        if self.options.method == "vi":
            self.upper.array[self.top_dofs] = self.bound
            self.snes.setVariableBounds(self.lower, self.upper)
        else:
            # start on the obstacle, as the VI does (it projects on its bounds): from a
            # penetrating start |F(x_0)| is kappa times the penetration, and SNES's
            # relative test rtol |F(x_0)| then passed after one step (cosine, 33 nodes:
            # p 54 % high at k = 1e4, rtol = 1e-3; 1.9 % at k = 1e8, default rtol)
            top = self.x.array[self.top_dofs]
            self.x.array[self.top_dofs] = np.minimum(top, self.bound)
        what = (f"FEM contact ({self.options.method}, {self.pmesh.formulation}) at "
                f"imposed delta = {float(delta):.6g} m")
        try:
            self.snes.solve(None, self.x)
            if self.snes.getIterationNumber() > 0:
                # once, after the first Newton step: a step without contact converges
                # in 0 iterations, before the linear solver (mat_mumps_*, mg_*) is set up
                for options in self._options:
                    options.check_used()
            nit = check_snes(self.snes, what)
        except Exception:
            # the next solve starts from the undeformed body, not from a failed iterate
            # (NaN after an infinite approach made every later solve DIVERGED_FNORM_NAN)
            self.x.set(0.0)
            raise
        return self._result(float(delta), nit, what, keep_fields)

    def solve_half_plane(self, target: float, keep_fields: bool = False) -> ContactResult:
        """Solve for the half-plane approach ``target`` (m), the BEM's Delta.

        Newton on the imposed approach: delta = applied - p H_d/M, so
        d applied = d delta (1 + K H_d/M) with the exact stiffness K of the last solve.
        Converges in 1-3 steps unless the contact set changes (then a few more).
        """
        compliance = self.pmesh.depth / p_wave_modulus(self.material)
        applied = target + (self.last_pressure + self.traction_load / self.pmesh.width) \
            * compliance
        tol = 1e-9 * self.u_ref
        for _ in range(12):
            r = self.solve(applied, keep_fields)
            err = target - r.delta
            if abs(err) <= tol:
                self.last_pressure = r.mean_pressure
                return r
            if np.isinf(r.stiffness):      # full contact: Delta is fixed, whatever the load
                raise NoConvergenceError(
                    f"FEM contact: the half-plane approach {target:.6g} m was not reached: "
                    f"full contact at {r.delta:.6g} m, which no load changes", result=r)
            applied = applied + err * (1.0 + r.stiffness * compliance)
            if self.traction is None:          # dry: never above first contact
                applied = max(applied, 0.0)
        raise NoConvergenceError(
            f"FEM contact: the half-plane approach {target:.6g} m was not reached "
            f"(last {r.delta:.6g} m, imposed {applied:.6g} m)", result=r)

    def solve_mean_pressure(self, target: float, guess: float,
                            keep_fields: bool = False) -> FemContactResult:
        """Solve for the mean pressure ``target`` (Pa) (load control), starting from the
        imposed approach ``guess`` (m).

        Newton on the imposed approach with the exact stiffness of the last solve,
        d applied = d p (1/K + H_d/M), until |p / target - 1| <= :data:`LOAD_RTOL`;
        2-3 solves from a guess within a few per cent (e.g. the BEM's Delta(p)).
        """
        compliance = self.pmesh.depth / p_wave_modulus(self.material)
        applied = float(guess)
        for _ in range(12):
            r = self.solve(applied, keep_fields)
            err = target - r.mean_pressure
            if abs(err) <= LOAD_RTOL * target:
                return r
            if r.stiffness > 0:
                applied = max(applied + err * (1.0 / r.stiffness + compliance), 0.0)
            else:                                  # not touching yet: move half-way up
                applied = applied + 0.5 * self.u_ref
        raise NoConvergenceError(
            f"FEM contact: the mean pressure {target:.6g} Pa was not reached "
            f"(last {r.mean_pressure:.6g} Pa at imposed approach {applied:.6g} m)", result=r)

    def _incremental_stiffness(self, contact_local):
        """Exact dp/d delta_applied (non-dimensional E/W units) with the contact set frozen.

        The contact vertices move with the obstacle (du_y = -1 per unit approach), all
        others are free: one linear solve K_ff du_f = -K_fc du_c (MUMPS LU), then the
        change of the total contact reaction.
        """
        from petsc4py import PETSc

        comm = self.K.getComm()
        rows = self.top_dofs[contact_local]
        if comm.tompi4py().allreduce(rows.size) == 0:
            return 0.0
        rstart = self.K.getOwnershipRange()[0]
        J = self.K.duplicate(copy=True)
        du, b = self.K.createVecs()
        ksp = PETSc.KSP().create(comm)
        options = None
        try:            # (see _jacobian) once per load step
            du.set(0.0)
            b.set(0.0)
            du.array[rows] = -1.0
            J.zeroRowsColumns((rows + rstart).astype(PETSc.IntType), diag=1.0, x=du, b=b)
            ksp.setOperators(J)
            # (the same keys as the SNES's linear solver, which checked them)
            options = PrefixedOptions(ksp, unique_prefix("stiffness"), self.ksp_options,
                                      "the incremental-stiffness solve", checked=())
            ksp.solve(b, du)
            reason = ksp.getConvergedReason()
            if reason <= 0:
                raise NoConvergenceError(
                    f"incremental stiffness: KSP failed with reason {reason}")
            self.K.mult(du, b)
            local = float(-b.array_r[self.top_dofs].sum())
        finally:
            for obj in (ksp, J, du, b):
                obj.destroy()
            if options is not None:
                options.release()
        return comm.tompi4py().allreduce(local)

    def _gather(self, local):
        """Top-vertex values of all ranks, ordered by profile sample."""
        comm = self.pmesh.mesh.comm
        idx = np.concatenate(comm.allgather(self.sample))
        val = np.concatenate(comm.allgather(np.asarray(local, dtype=float)))
        out = np.empty(self.pmesh.heights.size)
        out[idx] = val
        return out

    def _result(self, delta_applied, nit, what, keep_fields):
        pm, mat = self.pmesh, self.material
        W, h = pm.width, pm.heights
        self.K.mult(self.x, self.y)
        if self.traction is not None:
            self.y.axpy(-1.0, self.traction)           # the contact reaction K u - f
        uy_hat = self.x.array_r[self.top_dofs]
        if self.options.method == "vi":
            force_hat = -self.y.array_r[self.top_dofs]
        else:
            force_hat = self.kappa * self.weights * np.maximum(uy_hat - self.bound, 0.0)
        force = self._gather(force_hat) * mat.E * self.u_ref              # N/m per vertex
        uy = self._gather(uy_hat) * self.u_ref
        w = np.full(h.size, pm.element_size)                              # tributary (m)
        w[[0, -1]] *= 0.5
        load = float(force.sum())
        mean_p = load / W
        compliance = pm.depth / p_wave_modulus(mat)
        mean_total = mean_p + self.traction_load / W              # contact + known traction
        delta = delta_applied - mean_total * compliance
        disp = -uy - mean_total * compliance
        gap = disp + h.max() - h - delta
        # as in the BEM, a vertex is in contact when it carries a positive pressure; for the
        # VI that means closed (to round-off) and pushed, for the penalty penetrating
        if self.options.method == "vi":
            contact = (gap <= 1e-8 * self.u_ref) & (force > 0.0)
        else:
            contact = gap < 0.0
        area = float(w[contact].sum())
        mean_h = float(np.sum(w * h)) / W
        mean_gap = float(np.sum(w * gap)) / W
        sigma = self.rms_height
        if contact.all():
            # full contact: the top moves with the obstacle, k_applied = M / H_d, and
            # Delta no longer grows with the load: K = inf, as the periodic BEM's (the
            # difference 1/k_applied - compliance is round-off: K was +-1e28)
            stiffness = float("inf")
        else:
            k_applied = self._incremental_stiffness(contact[self.sample]) * mat.E / W
            stiffness = 1.0 / (1.0 / k_applied - compliance) if k_applied > 0 else 0.0
        return ContactResult(
            x=pm.x.copy(), pressure=np.maximum(force, 0.0) / w, displacement=disp, gap=gap,
            contact=contact, delta=delta, delta_applied=delta_applied,
            layer_compliance=compliance, load=load, mean_pressure=mean_p,
            area_fraction=area / W, contact_area=area, n_contact=int(contact.sum()),
            mean_gap=mean_gap, mean_plane_separation=h.max() - mean_h - delta,
            free_volume=float(np.sum(w * np.maximum(gap, 0.0))),
            free_volume_star=mean_gap / sigma if sigma > 0 else float("nan"),
            stiffness=stiffness, message=f"{what}: converged", nit=nit,
            residual=float(self.snes.getFunctionNorm()), tolerance=self._tolerance(),
            kernel=None, solver=f"fem-{self.options.method}", formulation=pm.formulation,
            e_star=mat.E_star, rms_height=sigma, size=(W,), spacing=(pm.element_size,),
            periodic=False, references=REFERENCES, method="fem", fields=self._fields()
            if keep_fields else None, patch_width=patch_width(contact, force, mirrored_ends=True))

    def _tolerance(self) -> float:
        """The SNES residual test of the last solve: max(atol, rtol * |F(x_0)|)."""
        norms = self.snes.getConvergenceHistory()[0]
        f0 = float(norms[0]) if len(norms) else float(self.snes.getFunctionNorm())
        return max(self.atol, self.options.rtol * f0)

    def _fields(self):
        """Vertices, triangles, displacement (m) and cell-wise sigma_yy (Pa) of the
        body's volumetric form, serial."""
        pm, mat = self.pmesh, self.material
        if pm.mesh.comm.size > 1:
            return None
        pts = self.V.tabulate_dof_coordinates()[:, :2] * pm.length_scale
        cells = self.V.dofmap.list.array.reshape(-1, 3).astype(np.int64)
        disp = self.x.array_r.reshape(-1, 2) * self.u_ref
        return {"points": pts, "cells": cells, "displacement": disp,
                "stress_yy": cell_stress_yy(pts, cells, disp, mat, self.volumetric),
                "formulation": pm.formulation}


def cell_stress_yy(points, cells, displacement, material: Material,
                   volumetric: str = "element"):
    """sigma_yy (Pa) of each linear triangle, plane strain, in the body's volumetric
    form (:mod:`roughfe.fem.elasticity`).

    ``"element"``: sigma_yy = lambda div u + 2 mu eps_yy from the exact P1 gradients
    (constant per triangle). ``"nodal"``: lambda times the nodal average theta of div u
    (the form's own volumetric strain; its mean over the triangle's three nodes) instead
    of the triangle's div u. As nu -> 1/2 a triangle's own div u of the nodal form is
    not small, only theta is: lambda div u was 548x the peak contact pressure at nu =
    0.49999 (review, round 2, session 28), the nodal stress -sigma_yy / p = 1.00 +- 0.04
    at the top.
    """
    p = points[cells]                                  # (C, 3, 2)
    u = displacement[cells]                            # (C, 3, 2)
    d1, d2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    jac = np.stack([d1, d2], axis=-1)                  # columns: edge vectors
    du = np.stack([u[:, 1] - u[:, 0], u[:, 2] - u[:, 0]], axis=-1)   # (C, 2 comps, 2 edges)
    grad = du @ np.linalg.inv(jac)                     # du_i/dx_j
    lam, mu = (material.E * c for c in lame(material.nu))
    div = grad[:, 0, 0] + grad[:, 1, 1]
    if volumetric == "nodal":
        areas = 0.5 * np.abs(np.linalg.det(jac))
        div = nodal_average(cells, areas, div, len(points))[cells].mean(axis=1)
    elif volumetric != "element":
        raise InputError(f"volumetric must be 'element' or 'nodal', got {volumetric!r}")
    return lam * div + 2 * mu * grad[:, 1, 1]


def contact_edge(x, gap, contact):
    """Position (m) of the first contact -> separation edge, to sub-element accuracy.

    Near a smooth contact edge at ``a`` the gap opens as ``(x - a)^(3/2)`` (square-root
    pressure singularity), so ``gap^(2/3)`` is linear in ``x``: it is extrapolated to zero
    from the first two open vertices beyond the last contact vertex ``j`` and the result
    is clipped to ``[x_j, x_{j+1}]``. Returns NaN when there is no such edge.
    Used for the Westergaard contact half-width (contact centred on x = 0).
    """
    x, gap, contact = (np.asarray(v) for v in (x, gap, contact))
    if not contact[0]:
        return float("nan")
    open_ = np.flatnonzero(~contact)
    if open_.size == 0:
        return float("nan")
    j = open_[0] - 1
    if j + 2 >= x.size:
        return float(x[j + 1])
    s1, s2 = np.maximum(gap[j + 1:j + 3], 0.0) ** (2.0 / 3.0)
    if not s2 > s1:
        return float(x[j + 1])
    a = x[j + 1] - s1 * (x[j + 2] - x[j + 1]) / (s2 - s1)
    return float(np.clip(a, x[j], x[j + 1]))


def _edge_offset(ratio):
    """Edge offset s / dx in [0, 1] beyond the last contact vertex, from
    ``ratio = E* g_open / (p_last dx)`` (see :func:`contact_length`); bisection."""
    lo, hi = np.zeros_like(ratio), np.ones_like(ratio)
    for _ in range(52):
        s = 0.5 * (lo + hi)
        # mean of sqrt(s - xi) over the tributary cell xi in [-1/2, 1/2] (units dx, c = 1)
        p_mean = (2.0 / 3.0) * ((s + 0.5) ** 1.5 - (s - np.minimum(s, 0.5)) ** 1.5)
        beyond = (4.0 / 3.0) * (1.0 - s) ** 1.5 / p_mean > ratio   # edge lies further out
        lo, hi = np.where(beyond, s, lo), np.where(beyond, hi, s)
    return 0.5 * (lo + hi)


def contact_length(x, pressure, gap, contact, e_star) -> float:
    """Contact length (m) with every contact edge located inside its element.

    Counting vertices (``contact_area``) puts each edge of a contact patch half-way
    between the last contact vertex and the first open one, so it moves in jumps of dx
    when a grazing vertex changes state. Here each edge ``a`` between the last contact
    vertex ``j`` and the open vertex ``j + 1`` (or ``j - 1``) follows from the
    square-root law of a smooth 2D contact edge (the edge limit of the 2D Hertz and
    Westergaard solutions, as in :func:`contact_edge`): inside, ``p = c sqrt(a - x)``;
    outside, ``g = 4 c (x - a)^(3/2) / (3 E*)``. With ``p_j`` read as the mean of that
    pressure over the tributary cell ``[x_j - dx/2, x_j + dx/2]`` (BEM cell pressure, FEM
    nodal reaction / dx) and ``g_{j+1}`` as the gap at the vertex, ``c`` cancels and
    ``s = a - x_j`` solves ``E* g_{j+1} / (p_j dx) = (4/3)(1 - s/dx)^(3/2) / pbar(s/dx)``
    (monotone; bisection). The length is continuous in the solution: as ``p_j -> 0``
    the edge moves to ``x_j``, as ``g_{j+1} -> 0`` to ``x_{j+1}``.

    The end vertices are symmetry planes (rollers / mirrored profile): a patch that
    reaches ``x[0]`` or ``x[-1]`` ends there. Measured on Westergaard (a = 30-316 um):
    <= 0.2 % error for the BEM (513 samples), <= 0.64 % for the FEM (129 nodes).

    Parameters
    ----------
    x : ndarray (n,)
        Equally spaced vertex positions (m).
    pressure, gap : ndarray (n,)
        Contact pressure (Pa) and gap (m) at the vertices.
    contact : ndarray (n,) of bool
    e_star : float
        E / (1 - nu^2) (Pa).
    """
    x, p, g = (np.asarray(v, dtype=float) for v in (x, pressure, gap))
    c = np.asarray(contact, dtype=bool)
    if not c.any():
        return 0.0
    dx = float(x[1] - x[0])
    step = np.diff(np.concatenate([[0], c.astype(np.int8), [0]]))
    first, last = np.flatnonzero(step == 1), np.flatnonzero(step == -1) - 1
    total = 0.0
    for j0, j1 in zip(first, last):
        ends = []
        for j, k, sign in ((j0, j0 - 1, -1.0), (j1, j1 + 1, 1.0)):
            if k < 0 or k >= x.size:
                ends.append(x[j])                    # symmetry plane: the patch ends here
                continue
            ratio = e_star * max(g[k], 0.0) / (p[j] * dx) if p[j] > 0 else np.inf
            ends.append(x[j] + sign * dx * float(_edge_offset(np.asarray(ratio))))
        total += ends[1] - ends[0]
    return float(total)


def fem_contact_sweep(pmesh: ProfileMesh, material: Material, deltas=None, *,
                      applied_deltas=None, pressures=None, guesses=None,
                      options: FemSolverOptions | None = None,
                      keep_fields=(), checkpoint=None) -> SweepResult:
    """Solve the FEM contact problem for increasing approaches or loads (load stepping).

    Each step starts from the previous solution.

    Parameters
    ----------
    pmesh : ProfileMesh
    material : roughfe.model.Material
        E (Pa) and nu < 0.5 of the body (the obstacle is rigid). Above nu = 0.45 the
        default ``options.volumetric="auto"`` takes the nodal volumetric form (no
        locking; :mod:`roughfe.fem.elasticity`); with ``"element"`` there a
        ResolutionWarning: the P1 elements lock, the pressure comes out too high (measured
        +3.4..8.1 % at nu = 0.49, +16..42 % at 0.499; :mod:`roughfe.fem.limits`).
    deltas : array_like, optional
        Strictly increasing half-plane approaches Delta >= 0 (m), the BEM's Delta
        (``result.delta``); each costs 2-4 solves (Newton on the imposed approach).
    applied_deltas : array_like, optional
        Or: strictly increasing approaches imposed on the layer (m), one solve each;
        ``result.delta`` is then ``applied - p H_d / M``.
    pressures : array_like, optional
        Or: strictly increasing mean pressures > 0 (Pa), load control to a relative
        :data:`LOAD_RTOL`; each costs 2-3 solves (Newton on the imposed approach from the
        periodic BEM's Delta(p) of the mirrored profile). Give exactly one of the three.
    guesses : array_like, optional
        With ``pressures``: imposed approaches (m) to start each step's Newton from
        instead of the BEM's, e.g. ``delta_applied`` of a coarser mesh of the same body.
    options : FemSolverOptions, optional
    keep_fields : int or iterable of int
        Indices of the steps whose full fields (mesh, displacement, sigma_yy) are kept,
        in ``[-n, n)`` for ``n`` steps (negative: from the end); others are an InputError.
    checkpoint : path-like or :class:`roughfe.fem.checkpoint.SweepCheckpoint`, optional
        A ``.npz`` file written after every step (the finished steps and the displacement
        the next one starts from; serial runs). When it exists and belongs to this sweep
        (same loads, guesses, mesh, material, options), the sweep resumes after its last
        step, with results equal bit for bit to an uninterrupted sweep's; otherwise it
        starts from the first step and overwrites it. The caller removes it
        (:mod:`roughfe.fem.checkpoint`).

    Raises
    ------
    NoConvergenceError
        Naming the SNES converged reason of the failed step; ``result`` holds the list
        of the steps solved before it.
    """
    material, options = _check_body(pmesh, material, options)
    given = {k: v for k, v in (("deltas", deltas), ("applied_deltas", applied_deltas),
                               ("pressures", pressures)) if v is not None}
    if len(given) != 1:
        raise InputError("give exactly one of deltas (half-plane approaches, m), "
                         "applied_deltas (approaches imposed on the layer, m) or pressures "
                         f"(mean pressures, Pa); got {sorted(given) or 'none'}")
    (name, values), = given.items()
    values = np.asarray(values, dtype=float).ravel()
    if values.size == 0 or not np.all(np.isfinite(values)) or np.any(values < 0):
        raise InputError(f"{name} must be a non-empty list of finite values >= 0, "
                         f"got {values!r}")
    if name == "pressures" and np.any(values <= 0):
        raise InputError(f"pressures must be > 0 (Pa), got {values!r}")
    if np.any(np.diff(values) <= 0):
        raise InputError(f"{name} must be strictly increasing (load stepping)")
    keep = _kept_steps(keep_fields, values.size)
    full = None
    if name == "deltas":
        full = _full_contact(pmesh, material)
        if values[-1] > full[0] * (1 + 1e-9):
            raise InputError(
                f"delta = {values[-1]:.6g} m exceeds max h - mean h = {full[0]:.6g} m of the "
                f"evenly mirrored profile (the body's periodic reference problem): that is "
                f"full contact already, and the half-plane approach no longer grows with "
                f"the load; give pressures (Pa) to go beyond it")
    problem = _ContactProblem(pmesh, material, options)
    if name == "pressures" and guesses is None:
        guesses = _applied_guesses(pmesh, material, values)
    elif guesses is not None:
        guesses = check_real_array("guesses (imposed approaches)", guesses).ravel()
        if name != "pressures" or guesses.shape != values.shape:
            raise InputError(f"guesses (m) go with pressures, one per load; got {guesses!r}")

    def step(k):
        if name == "pressures":
            return problem.solve_mean_pressure(values[k], guesses[k], k in keep)
        if name == "applied_deltas":
            return problem.solve(values[k], k in keep)
        if values[k] >= full[0] * (1 - 1e-9):
            # full contact: the half-plane approach is flat in the load beyond it, so the
            # Newton on it cannot land; the state is that of the least full-contact
            # pressure, the BEM's closed form (load control from there)
            return problem.solve_mean_pressure(full[1], full[2], k in keep)
        return problem.solve_half_plane(values[k], k in keep)

    results, key = [], None
    try:
        if checkpoint is not None:
            if not isinstance(checkpoint, SweepCheckpoint):
                checkpoint = SweepCheckpoint(checkpoint)
            key = sweep_key(problem, name, values, guesses, keep)
            results = checkpoint.restore(problem, key)
        for k in range(len(results), values.size):
            results.append(step(k))
            if checkpoint is not None:
                checkpoint.save(problem, key, results)
    except NoConvergenceError as exc:
        raise NoConvergenceError(str(exc), result=results) from None
    finally:
        problem.destroy()
    warn_sweep(results, options)            # penalty penetration; unresolved contact patches
    return SweepResult.from_results(results, rms_slope=problem.rms_slope, length=pmesh.width)


def _kept_steps(keep_fields, n: int) -> set:
    """The step indices in ``[0, n)`` named by ``keep_fields`` (an int or an iterable of
    ints in ``[-n, n)``, negative from the end); an InputError otherwise (5 of 2 steps
    was silently step 1)."""
    single = isinstance(keep_fields, (int, np.integer)) and not isinstance(keep_fields, bool)
    try:
        items = list([keep_fields] if single else keep_fields)
    except TypeError:
        raise InputError(f"keep_fields must be a step index or an iterable of step "
                         f"indices, got {keep_fields!r}") from None
    name = f"keep_fields index (one of the {n} steps, -{n} <= k < {n})"
    kept = set()
    for k in items:
        if check_int(name, k, -n) >= n:
            raise InputError(f"{name} must be < {n}, got {k!r}")
        kept.add(int(k) % n)
    return kept


def _full_contact(pmesh: ProfileMesh, material: Material):
    """``(Delta_full, p_full, applied)``: the half-plane approach of full contact (m, max h
    - mean h of the evenly mirrored profile), the least mean pressure that closes every
    gap (Pa, the periodic BEM's closed form) and the imposed approach expected there
    (m)."""
    from ..bem import solve_contact
    from ..surfaces import Surface
    from .mesh import mirrored_profile

    profile = Surface(np.asarray(pmesh.heights), pmesh.heights.size * pmesh.element_size)
    mirrored = mirrored_profile(profile)
    h = mirrored.heights
    d_full = float(h.max() - h.mean())
    p_full = solve_contact(mirrored, material, delta=d_full, kernel="spectral",
                           compute_stiffness=False).mean_pressure
    return d_full, p_full, d_full + p_full * pmesh.depth / p_wave_modulus(material)


def _applied_guesses(pmesh: ProfileMesh, material: Material, pressures) -> np.ndarray:
    """Imposed approaches (m) expected to give ``pressures``: the periodic BEM's Delta(p) of
    the mirrored profile (the FEM body's reference problem) plus the layer shortening."""
    from ..bem import contact_sweep
    from ..surfaces import Surface
    from .mesh import mirrored_profile

    profile = Surface(np.asarray(pmesh.heights), pmesh.heights.size * pmesh.element_size)
    bem = contact_sweep(mirrored_profile(profile), material, pressures=pressures,
                        kernel="spectral", solver="pk", compute_stiffness=False)
    return bem.delta + np.asarray(pressures) * pmesh.depth / p_wave_modulus(material)


def fem_solve_contact(pmesh: ProfileMesh, material: Material, delta=None, *,
                      applied_delta=None, options: FemSolverOptions | None = None,
                      keep_fields: bool = False) -> ContactResult:
    """One FEM contact solve at the half-plane approach ``delta`` or the imposed
    ``applied_delta`` (m), see :func:`fem_contact_sweep`."""
    return fem_contact_sweep(
        pmesh, material, None if delta is None else [delta],
        applied_deltas=None if applied_delta is None else [applied_delta], options=options,
        keep_fields=(0,) if keep_fields else ()).results[0]
