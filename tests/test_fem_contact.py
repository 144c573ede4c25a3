"""FEM contact (roughfe.fem) against analytic solutions and against itself.

Budget: all FEM tests together < 60 s on 2 cores (each mesh here has < 4000 triangles).
"""
import numpy as np
import pytest

pytest.importorskip("dolfinx")

from roughfe.errors import InputError, NoConvergenceError  # noqa: E402
from roughfe.fem import FACET_TAGS, mesh_profile, mirrored_profile  # noqa: E402
from roughfe.bem import Material  # noqa: E402
from roughfe.fem.contact import (FemSolverOptions, contact_edge, contact_length,  # noqa: E402
                                 fem_contact_sweep, fem_solve_contact, p_wave_modulus)
from roughfe.reference import westergaard  # noqa: E402
from roughfe.surfaces import Surface  # noqa: E402

pytestmark = pytest.mark.fem

LAM, G = 1e-3, 1e-6                       # Westergaard wavelength and amplitude (m)
MAT = Material(E=1e9, nu=0.3)


def cosine_half_period(n):
    """g cos(2 pi x / lambda) on [0, lambda/2] with n samples; mirrored it is the cosine."""
    dx = (LAM / 2) / (n - 1)
    x = np.arange(n) * dx
    return Surface(G * np.cos(2 * np.pi * x / LAM), n * dx)


@pytest.fixture(scope="module")
def westergaard_mesh():
    return mesh_profile(cosine_half_period(129), growth=0.1)


def test_westergaard_width_and_mean_gap(westergaard_mesh):
    """Coarse graded mesh (dx = lambda/256, growth 0.1): contact half-width within 1 %
    of Westergaard (measured 0.1-0.4 %), and the mean gap, which tests the finite-depth
    correction of Delta, within 2 % of g (1 - s + s ln s) (measured 0.1-0.5 %)."""
    pm = westergaard_mesh
    targets = np.array([0.2, 0.5, 0.8]) * G          # half-plane approaches (full contact: G)
    sweep = fem_contact_sweep(pm, MAT, targets)
    res = sweep.results
    assert np.allclose(sweep.delta, targets, rtol=1e-8, atol=0)
    for r in res:
        ref = westergaard(G, LAM, MAT.E_star, r.mean_pressure)
        a = contact_edge(r.x, r.gap, r.contact)
        assert abs(a / ref.half_width - 1) < 0.01, (a, ref.half_width)
        # the sub-element contact length (edge from pressure and gap; measured 0.4-0.6 %)
        length = contact_length(r.x, r.pressure, r.gap, r.contact, MAT.E_star)
        assert abs(length / ref.half_width - 1) < 0.01, (length, ref.half_width)
        w = np.full(r.x.size, 1.0 / (r.x.size - 1))
        w[[0, -1]] *= 0.5
        mean_gap = float(np.sum(w * r.gap))
        assert mean_gap == pytest.approx(ref.mean_gap, rel=0.02, abs=0.002 * G)
        assert r.mean_gap == pytest.approx(mean_gap, rel=1e-12, abs=0)
        # the corrected approach equals max h - mean h - mean gap (Betti, exact)
        assert r.mean_plane_separation == pytest.approx(mean_gap, rel=1e-6, abs=0)
        assert np.sum(w * r.displacement) == pytest.approx(0.0, abs=1e-9 * G)
    # pressure rises with the approach, the stiffness is positive
        # Westergaard stiffness: delta = g - gbar(p) gives K = dp/d delta = -p* / (g ln s);
        # the exact incremental FEM stiffness of the frozen contact set is within 3 %
        # (measured <= 1.6 %: it jumps as single nodes enter the contact)
        s = r.mean_pressure / ref.full_contact_pressure
        assert r.stiffness == pytest.approx(-ref.full_contact_pressure / (G * np.log(s)), rel=0.03)
    assert np.all(np.diff(sweep.mean_pressure) > 0) and np.all(sweep.stiffness > 0)
    assert np.all(sweep.delta < sweep.delta_applied)


def random_profile(n, seed):
    """A smooth random profile (sum of 6 cosines with seeded phases), ~1 um rms."""
    rng = np.random.default_rng(seed)
    dx = 1e-3 / (n - 1)
    x = np.arange(n) * dx
    k = np.arange(1, 7)
    h = (1e-6 * k[:, None] ** -1.5 * np.cos(np.pi * k[:, None] * x / 1e-3 * 2
                                            + rng.uniform(0, 2 * np.pi, 6)[:, None])).sum(0)
    return Surface(h, n * dx, metadata={"seed": seed})


def test_vi_and_penalty_agree():
    """VI and penalty (k = 1e4) on a random profile: mean pressure within 1e-4 (target
    0.5 %; measured 6e-6, the penalty penetration p/(k E/delta)), the same contact
    vertices up to one at an edge, nodal pressures within 0.1 % of the peak."""
    pm = mesh_profile(random_profile(65, seed=4), growth=0.1)
    hr = np.ptp(pm.heights)
    deltas = np.array([0.1, 0.3, 0.5]) * hr
    vi = fem_contact_sweep(pm, MAT, applied_deltas=deltas,
                           options=FemSolverOptions(method="vi")).results
    pen = fem_contact_sweep(pm, MAT, applied_deltas=deltas,
                            options=FemSolverOptions(method="penalty", penalty_factor=1e4)).results
    for a, b in zip(vi, pen):
        assert b.mean_pressure == pytest.approx(a.mean_pressure, rel=1e-4)
        assert np.sum(a.contact != b.contact) <= 1
        assert np.max(np.abs(a.pressure - b.pressure)) < 1e-3 * a.pressure.max()
        assert a.success and b.success and a.nit <= 20 and b.nit <= 20
    assert vi[-1].n_contact > vi[0].n_contact >= 1


def test_penalty_agrees_with_vi_under_load_control():
    """Load control (each step re-solved from the previous solution at a smaller imposed
    approach, so the first Newton step unloads the body) and full contact: the penalty
    Newton stopped after 1 iteration with DIVERGED_DTOL (PETSc's default divergence test,
    |F| > 1e4 |F(x_0)|). Now it gives the VI's pressures (measured 1e-6: the penalty
    penetration p / (k E / dx)), and response(n_steps) up to full contact as well."""
    from roughfe.model import Loading
    from roughfe.response import response
    surf = cosine_half_period(33)
    pm = mesh_profile(surf)
    p_star = np.pi * MAT.E_star * G / LAM
    loads = np.array([0.1, 0.5, 0.9]) * p_star
    vi, pen = (fem_contact_sweep(pm, MAT, pressures=loads, options=FemSolverOptions(method=m))
               for m in ("vi", "penalty"))
    full_vi, full_pen = (response(surf, MAT, Loading(n_steps=3), method="fem", solver=m)
                         for m in ("vi", "penalty"))
    assert np.allclose(pen.mean_pressure, loads, rtol=1e-5)
    for a, b in zip(vi.results + full_vi.results, pen.results + full_pen.results):
        assert b.mean_pressure == pytest.approx(a.mean_pressure, rel=1e-5)
        assert np.max(np.abs(a.pressure - b.pressure)) < 1e-4 * a.pressure.max()
        assert np.sum(a.contact != b.contact) <= 1
    assert full_pen.delta[-1] == pytest.approx(G, rel=1e-3)          # full contact


def test_jacobian_and_stiffness_solve_free_their_petsc_objects():
    """The penalty Jacobian (every Newton step) and the incremental stiffness (every load
    step) created work vectors and dropped them undestroyed: petsc4py only queues a
    dropped object of a non-self communicator for PETSc.garbage_cleanup(), so memory grew
    with every solve. Every Vec and Mat they create is now destroyed (a subclass of
    PETSc.Mat records what is created from the stiffness matrix: its copies are of the
    same class). A memory (RSS) test would need thousands of calls to rise above the
    allocator's noise."""
    from petsc4py import PETSc
    from roughfe.fem.contact import _ContactProblem

    made = []

    class Recording(PETSc.Mat):
        def createVecLeft(self):
            made.append(super().createVecLeft())
            return made[-1]

        def createVecs(self, side=None):
            vecs = super().createVecs(side)
            made.extend(vecs if isinstance(vecs, tuple) else [vecs])
            return vecs

        def duplicate(self, copy=False):
            made.append(super().duplicate(copy))
            return made[-1]

    problem = _ContactProblem(mesh_profile(cosine_half_period(17), growth=0.3), MAT,
                              FemSolverOptions(method="penalty"))
    try:
        K = Recording()
        problem.K.convert(out=K)
        problem.K.destroy()
        problem.K = K
        problem.bound = problem.gap0 - 0.5                 # half the top nodes penetrate
        J = K.duplicate(copy=True)
        problem._jacobian(None, problem.x, J, J)
        J.destroy()
        assert problem._incremental_stiffness(problem.gap0 < 0.5) > 0
        assert len(made) >= 5
        assert [type(obj).__name__ for obj in made if obj.handle] == []
    finally:
        problem.destroy()


@pytest.mark.parametrize("formulation", ["flat", "profile"])
def test_uniform_layer_compliance_exact(formulation):
    """A flat punch on a roller-supported layer is uniaxial strain: p = M Delta / H_d
    exactly, so the half-plane delta = 0, uniform pressure and sigma_yy = -p in every cell.
    (A layer of 0.7 W is no half-plane: the warning says so, yet a uniform load is exact.)"""
    from roughfe.errors import ResolutionWarning
    n, L = 17, 1e-3
    flat = Surface(np.zeros(n), n * L / (n - 1))
    with pytest.warns(ResolutionWarning, match="depth = 0.0007 m = 0.7 W is shallower"):
        pm = mesh_profile(flat, depth=0.7e-3, growth=0.3, formulation=formulation)
    delta = 2e-6
    r = fem_solve_contact(pm, MAT, applied_delta=delta, keep_fields=True)
    M = MAT.E * 0.7 / (1.3 * 0.4)
    assert p_wave_modulus(MAT) == pytest.approx(M, rel=1e-15)
    p = M * delta / 0.7e-3
    assert r.mean_pressure == pytest.approx(p, rel=1e-10)
    assert r.layer_compliance == pytest.approx(0.7e-3 / M, rel=1e-14, abs=0)
    assert abs(r.delta) < 1e-10 * delta and r.delta_applied == delta
    assert np.allclose(r.pressure, p, rtol=1e-9)
    assert r.n_contact == n and r.area_fraction == pytest.approx(1.0)
    assert np.allclose(r.fields["stress_yy"], -p, rtol=1e-8)


@pytest.mark.filterwarnings("ignore:depth = .* is shallower:roughfe.errors.ResolutionWarning")
@pytest.mark.parametrize("formulation", ["flat", "profile"])
def test_facet_tags_on_the_right_edges(formulation):
    surf = random_profile(33, seed=1)
    pm = mesh_profile(surf, depth=1.5e-3, growth=0.2, formulation=formulation)
    mesh, ft = pm.mesh, pm.facet_tags
    mesh.topology.create_connectivity(1, 0)
    f2v = mesh.topology.connectivity(1, 0)
    X = mesh.geometry.x[:, :2] * pm.length_scale
    top_y = 0.0 if formulation == "flat" else surf.heights - surf.heights.mean()
    for name, tag in FACET_TAGS.items():
        facets = ft.find(tag)
        pts = np.array([X[f2v.links(f)] for f in facets])          # (F, 2 vertices, 2)
        if name == "top":
            assert facets.size == 32
            xi = pts[..., 0] / pm.element_size
            assert np.allclose(xi, np.rint(xi), atol=1e-8)
            expect = np.broadcast_to(top_y, (33,))[np.rint(xi).astype(int)]
            assert np.allclose(pts[..., 1], expect, atol=1e-12)
        elif name == "bottom":
            assert np.allclose(pts[..., 1], -1.5e-3, rtol=0, atol=1e-12 * pm.width)
        elif name == "left":
            assert np.allclose(pts[..., 0], 0.0, rtol=0, atol=1e-12 * pm.width)
        else:
            assert np.allclose(pts[..., 0], pm.width, rtol=0, atol=1e-12 * pm.width)
    # tags are disjoint and cover exactly the exterior facets
    assert np.unique(ft.indices).size == ft.indices.size


def test_forced_non_convergence_names_the_snes_reason():
    pm = mesh_profile(random_profile(33, seed=2), growth=0.3)
    opts = FemSolverOptions(method="vi", max_it=1)
    with pytest.raises(NoConvergenceError, match="DIVERGED_MAX_IT"):
        fem_contact_sweep(pm, MAT, applied_deltas=[0.5 * np.ptp(pm.heights)], options=opts)


def test_mirrored_profile_and_bad_input():
    s = Surface(np.array([0.0, 1.0, 3.0, 2.0]) * 1e-6, 4e-3)
    m = mirrored_profile(s)
    assert m.periodic and m.shape == (6,) and m.size[0] == pytest.approx(6e-3)
    assert np.allclose(m.heights * 1e6, [0, 1, 3, 2, 3, 1])
    with pytest.raises(InputError, match="formulation"):
        mesh_profile(s, formulation="curved")
    with pytest.raises(InputError, match="method"):
        FemSolverOptions(method="lagrange")
    with pytest.raises(InputError, match="nu < 0.5"):
        fem_solve_contact(mesh_profile(s), Material(E=1e9, nu=0.5), 1e-7)
    # solver controls and the mesh argument are named before any PETSc object is made
    # (rtol = -1 and max_it = 2.5 were accepted, a path instead of the mesh was an
    # AttributeError)
    for kwargs, words in (({"rtol": -1.0}, "rtol"), ({"atol": -1.0}, "atol"),
                          ({"max_it": 2.5}, "max_it"), ({"max_it": 0}, "max_it")):
        with pytest.raises(InputError, match=words):
            FemSolverOptions(**kwargs)
    assert FemSolverOptions(atol=0.0).atol == 0.0            # relative tolerance only
    with pytest.raises(InputError, match="pmesh must be a roughfe.fem.ProfileMesh"):
        fem_solve_contact("profile.msh", Material(E=1e9, nu=0.3), 1e-7)


@pytest.mark.parametrize("method", ["vi", "penalty"])
def test_petsc_options_refused_or_never_read_are_input_errors(method):
    """A key PETSc never reads ({"snes_typo_option": 1}, {"ksp_typ": "cg"}) was dropped
    without a word (the options were deleted right after setFromOptions, so PETSc's
    unused-option report never fired); a value PETSc refuses was a bare
    petsc4py.PETSc.Error. Both are InputErrors naming the key (and the value), and the
    options database is left as it was."""
    from petsc4py import PETSc

    pm = mesh_profile(cosine_half_period(17), growth=0.3)
    before = PETSc.Options().getAll()
    for petsc, words in (({"snes_typo_option": 1}, r"\['snes_typo_option'\] .*never read"),
                         ({"ksp_typ": "cg"}, r"\['ksp_typ'\] .*never read"),
                         ({"ksp_rtol": 1e-12}, r"\['ksp_rtol'\] .*never read"),  # preonly
                         ({"snes_type": "foo"}, r"snes_type='foo' .*SNES type foo"),
                         ({"pc_type": "bogus"}, r"pc_type='bogus' .*PC type bogus"),
                         ({"snes_max_it": "abc"}, r"snes_max_it='abc' .*no integer value")):
        with pytest.raises(InputError, match=words):
            fem_solve_contact(pm, MAT, 0.3 * G,
                              options=FemSolverOptions(method=method, petsc_options=petsc))
    assert PETSc.Options().getAll() == before


def test_mumps_options_reach_every_factorization():
    """The mat_mumps_* keys of FemSolverOptions (documented) are read by PETSc when MUMPS
    factorizes, after setFromOptions, and were deleted before: ICNTL(14) stayed at its
    default 20 %. It is now the value given, also at the second load step."""
    from roughfe.fem.contact import _ContactProblem

    problem = _ContactProblem(mesh_profile(cosine_half_period(17), growth=0.3), MAT,
                              FemSolverOptions(method="penalty",
                                               petsc_options={"mat_mumps_icntl_14": 77}))
    try:
        for delta in (0.2 * G, 0.4 * G):
            problem.solve(delta)
            factor = problem.snes.getKSP().getPC().getFactorMatrix()
            assert factor.getMumpsIcntl(14) == 77
    finally:
        problem.destroy()


def test_fluid_loaded_body_refuses_a_non_finite_approach_and_recovers_from_a_failure():
    """FluidLoadedBody.solve(p, inf) ran the SNES on an infinite bound, left NaN in its
    solution vector, and every later valid solve failed (DIVERGED_FNORM_NAN); nan was
    reported as a NoConvergenceError. A non-finite approach is now an InputError, and a
    failed solve restarts the next one from the undeformed body: its result is the fresh
    one's. NaN guesses of load control are refused too."""
    from roughfe.fem import FluidLoadedBody

    pm = mesh_profile(cosine_half_period(33), growth=0.3)
    zero = np.zeros(pm.heights.size)
    with FluidLoadedBody(pm, MAT) as body:
        fresh = body.solve(zero, 0.5 * G).mean_pressure
        for bad in (np.inf, np.nan, "1e-7"):
            with pytest.raises(InputError, match="approach"):
                body.solve(zero, bad)
        with pytest.raises(NoConvergenceError, match="DIVERGED_FNORM_NAN"):
            body.problem.solve(np.inf)             # (internal: a failed SNES solve)
        assert body.solve(zero, 0.5 * G).mean_pressure == pytest.approx(fresh, rel=1e-6)
    with pytest.raises(InputError, match="guesses"):
        fem_contact_sweep(pm, MAT, pressures=[1e5], guesses=[np.nan])


def test_keep_fields_names_steps_in_range():
    """keep_fields=(5,) of a 2-step sweep silently kept step 1 (5 % 2), and a lone index
    through response(keep_fields=5) was a TypeError. Indices in [-n, n) (a lone int too)
    keep those steps; anything else is an InputError."""
    from roughfe.model import Loading
    from roughfe.response import response

    prof = cosine_half_period(17)
    pm = mesh_profile(prof, growth=0.3)
    deltas = [0.2 * G, 0.4 * G]
    for keep, kept in (((1,), [False, True]), (-2, [True, False]),
                       (np.int64(1), [False, True]), ((), [False, False])):
        r = fem_contact_sweep(pm, MAT, deltas, keep_fields=keep)
        assert [c.fields is not None for c in r.results] == kept
    for bad in ((5,), (-3,), 2, (0.5,), True, "all"):
        with pytest.raises(InputError, match="keep_fields"):
            fem_contact_sweep(pm, MAT, deltas, keep_fields=bad)
    one = response(prof, MAT, Loading(delta=0.3 * G), method="fem", growth=0.3, keep_fields=0)
    assert one.results[0].fields is not None
    with pytest.raises(InputError, match="keep_fields"):
        response(prof, MAT, Loading(delta=0.3 * G), method="fem", growth=0.3, keep_fields=5)


def test_fluid_loaded_body_checks_its_arguments_and_refuses_use_after_close():
    """A dict of options was "AttributeError: 'dict' object has no attribute
    'penalty_factor'" (also through coupled_channel(fem_options={...})), a pmesh that is
    not a ProfileMesh was not checked, and a solve after close() was "'NoneType' object
    has no attribute 'localForm'". They are InputErrors naming the argument, as in
    fem_contact_sweep (one check for both)."""
    from roughfe.fem import FluidLoadedBody
    from roughfe.leakage.profile_fsi import coupled_channel

    prof = cosine_half_period(17)
    pm = mesh_profile(prof, growth=0.3)
    with pytest.raises(InputError, match="options must be a roughfe.fem.FemSolverOptions, "
                                         "got dict"):
        FluidLoadedBody(pm, MAT, {"method": "penalty"})
    with pytest.raises(InputError, match="pmesh must be a roughfe.fem.ProfileMesh"):
        FluidLoadedBody(prof, MAT)
    with pytest.raises(InputError, match="options must be a roughfe.fem.FemSolverOptions"):
        coupled_channel(prof, MAT, -1e-6, p_in=2e6, p_out=1e5, method="fem", growth=0.3,
                        fem_options={"method": "penalty"})
    body = FluidLoadedBody(pm, MAT)
    assert body.solve(np.zeros(17), 0.5 * G).mean_pressure > 0
    body.close()
    body.close()                                   # twice is harmless
    with pytest.raises(InputError, match="closed"):
        body.solve(np.zeros(17), 0.5 * G)


@pytest.mark.parametrize("method", ["vi", "penalty"])
def test_option_check_waits_for_the_first_newton_step(method):
    """A step without contact (delta = 0: the crest just touches) converges in 0 Newton
    iterations and sets up no linear solver, so MUMPS has not read mat_mumps_icntl_14
    yet: the check of unread options ran there and refused the valid key as "never
    read". It now runs after the first step that takes a Newton iteration: the key
    reaches the factorization of the contact step, a sweep without any contact never
    refuses, and a misspelled key is still refused at the first contact step."""
    from roughfe.fem.contact import _ContactProblem

    pm = mesh_profile(cosine_half_period(17), growth=0.3)
    fem_solve_contact(pm, MAT, applied_delta=0.0, options=FemSolverOptions(
        method=method, petsc_options={"mat_mumps_icntl_14": 50}))
    for petsc in ({"mat_mumps_icntl_14": 50}, {"mat_mumps_icntl_14": 50, "ksp_typo": 1}):
        problem = _ContactProblem(pm, MAT, FemSolverOptions(method=method,
                                                            petsc_options=petsc))
        try:
            assert problem.solve(0.0).mean_pressure == 0.0
            if "ksp_typo" in petsc:
                with pytest.raises(InputError, match=r"\['ksp_typo'\] .*never read"):
                    problem.solve(0.4 * G)
            else:
                assert problem.solve(0.4 * G).mean_pressure > 0.0
                factor = problem.snes.getKSP().getPC().getFactorMatrix()
                assert factor.getMumpsIcntl(14) == 50
        finally:
            problem.destroy()


def test_multigrid_options_reach_the_rebuilt_gamg_of_the_vi():
    """With the VI and GAMG the preconditioner is rebuilt by FreshOnResize, which was
    given only the pc_* keys: mg_levels_* / mg_coarse_* never reached the GAMG and were
    refused as "never read" (the penalty method accepted them). Now every non-ksp_* key
    reaches the inner GAMG (its level smoothers take mg_levels_ksp_max_it = 3, the
    coarse solve mg_coarse_pc_type = lu), and a misspelled mg_ key is still refused."""
    from roughfe.fem.contact import _ContactProblem

    pm = mesh_profile(cosine_half_period(17), growth=0.3)
    base = {"ksp_type": "cg", "pc_type": "gamg", "ksp_rtol": 1e-12}
    good = {**base, "mg_levels_ksp_max_it": 3, "mg_coarse_pc_type": "lu"}
    problem = _ContactProblem(pm, MAT, FemSolverOptions(method="vi", petsc_options=good))
    try:
        assert problem.solve(0.4 * G).mean_pressure > 0.0
        gamg = problem.snes.getKSP().getPC().getPythonContext().inner
        levels = gamg.getMGLevels()
        assert levels > 1
        assert all(gamg.getMGSmoother(i).getTolerances()[3] == 3 for i in range(1, levels))
        assert gamg.getMGCoarseSolve().getPC().getType() == "lu"
    finally:
        problem.destroy()
    with pytest.raises(InputError, match=r"\['mg_levels_ksp_max_itt'\] .*never read"):
        fem_solve_contact(pm, MAT, 0.4 * G, options=FemSolverOptions(
            method="vi", petsc_options={**base, "mg_levels_ksp_max_itt": 3}))


@pytest.mark.filterwarnings("ignore:depth = .* is shallower:roughfe.errors.ResolutionWarning")
def test_mesh_files_for_inspection(tmp_path):
    """.msh keeps gmsh's physical groups; it and the XDMF hold the same triangles in
    metres."""
    meshio = pytest.importorskip("meshio")
    surf = random_profile(33, seed=3)
    pm = mesh_profile(surf, depth=1e-3, growth=0.2, write_to=tmp_path, name="r33")
    m = meshio.read(pm.files["xdmf"])
    tri = m.cells_dict["triangle"]
    assert tri.shape[0] == pm.n_cells
    used = m.points[np.unique(tri)]
    assert used[:, 0].min() == pytest.approx(0.0, abs=1e-15)
    assert used[:, 0].max() == pytest.approx(pm.width, rel=1e-12, abs=0)
    assert used[:, 1].min() == pytest.approx(-1e-3, rel=1e-12, abs=0)
    msh = meshio.read(pm.files["msh"])
    assert set(msh.field_data) >= {"top", "bottom", "left", "right", "body"}
    # the .msh is in metres as well (it was in units of W, x in [0, 1]): the same
    # vertices and triangles as the XDMF; the solver's mesh stays in units of W
    assert np.allclose(msh.points[:, :2], m.points[:, :2], rtol=0, atol=1e-12 * pm.width)
    assert np.array_equal(msh.cells_dict["triangle"], tri)
    assert msh.points[:, 0].max() == pytest.approx(pm.width, rel=1e-12, abs=0)
    assert pm.mesh.geometry.x[:, 0].max() == pytest.approx(1.0, rel=1e-12)
    lines = msh.cells_dict["line"]
    top = lines[msh.cell_data_dict["gmsh:physical"]["line"] == FACET_TAGS["top"]]
    assert np.allclose(np.sort(msh.points[np.unique(top), 0]), pm.x, rtol=0,
                       atol=1e-12 * pm.width)
    # element size grows with depth: the bottom triangles are much larger than the top ones
    area = 0.5 * np.abs(np.cross(m.points[tri[:, 1], :2] - m.points[tri[:, 0], :2],
                                 m.points[tri[:, 2], :2] - m.points[tri[:, 0], :2]))
    yc = m.points[tri, 1].mean(axis=1)
    assert area[yc < -0.8e-3].mean() > 20 * area[yc > -0.05e-3].mean()


def test_mesh_profile_refuses_bad_growth_and_output_paths(tmp_path):
    """growth="a" was a bare ValueError, write_to=<an existing file> a FileExistsError,
    name="" gmsh's "Unknown output file format", and name="../escape" wrote beside the
    folder. They are InputErrors now, raised before gmsh runs and before anything is
    written."""
    s = cosine_half_period(17)
    for growth in ("a", float("nan"), 0.0, 1.5):
        with pytest.raises(InputError, match="growth"):
            mesh_profile(s, growth=growth)
    (tmp_path / "afile").write_text("mine")
    with pytest.raises(InputError, match="write_to must be a folder"):
        mesh_profile(s, write_to=tmp_path / "afile")
    with pytest.raises(InputError, match="is not a folder"):
        mesh_profile(s, write_to=tmp_path / "afile" / "sub")
    for name in ("", "../escape", "a/b", 3):
        with pytest.raises(InputError, match="name .* must be a non-empty name without '/'"):
            mesh_profile(s, write_to=tmp_path / "m", name=name)
    assert (tmp_path / "afile").read_text() == "mine"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile"]


def test_contact_length_is_continuous_when_a_node_changes_state():
    """A node that closes (gap -> 0+) and then carries a pressure (p -> 0+) moves the
    sub-element edge continuously to that node; the node count jumps by dx there."""
    x = np.arange(8) * 1e-6
    e_star, p0 = 1e9, 1e6
    contact = np.array([1, 1, 1, 0, 0, 0, 0, 0], bool)
    pressure = np.array([p0, p0, 0.5 * p0, 0, 0, 0, 0, 0])
    gap = np.array([0, 0, 0, 1e-9, 4e-9, 9e-9, 1.6e-8, 2.5e-8])
    lengths = []
    for eps in (1e-6, 1e-9):
        g_open = gap.copy()
        g_open[3] = eps * 1e-9                                 # node 3 just open
        lengths.append(contact_length(x, pressure, g_open, contact, e_star))
        c_closed = contact.copy()
        c_closed[3] = True                                     # node 3 just closed
        p_closed = pressure.copy()
        p_closed[3] = eps * p0
        lengths.append(contact_length(x, p_closed, gap, c_closed, e_star))
    assert lengths[2] == pytest.approx(x[3], rel=1e-6)          # both sides tend to x_3
    assert lengths[3] == pytest.approx(x[3], rel=1e-6)
    assert abs(lengths[0] - lengths[1]) < 0.02 * (x[1] - x[0])
    # the end vertex is a symmetry plane; no contact -> 0
    assert contact_length(x, pressure, gap, np.zeros(8, bool), e_star) == 0.0
    assert x[0] <= contact_length(x, pressure, gap, contact, e_star) - 2e-6 <= x[1]


def test_contact_length_westergaard_bem():
    """The same edge law on the mirrored periodic BEM (257 samples on a half period):
    contact length within 0.5 % of Westergaard's half-width (measured <= 0.2 %)."""
    from roughfe.bem import contact_sweep
    n = 257
    surf = cosine_half_period(n)
    sweep = contact_sweep(mirrored_profile(surf), MAT, deltas=np.array([0.2, 0.5, 0.8]) * G,
                          kernel="spectral", compute_stiffness=False)
    x = np.arange(n) * surf.spacing[0]
    for r in sweep.results:
        ref = westergaard(G, LAM, MAT.E_star, r.mean_pressure)
        length = contact_length(x, r.pressure[:n], r.gap[:n], r.contact[:n], MAT.E_star)
        assert length == pytest.approx(ref.half_width, rel=0.005)


def test_load_control_reaches_the_pressure_and_equals_displacement_control(westergaard_mesh):
    """fem_contact_sweep(pressures=...): each step reaches its mean pressure to LOAD_RTOL,
    is the solution of the displacement-controlled problem at its own imposed approach
    (same p, A*, K to 1e-9), and its half-width matches Westergaard at that load (1 %)."""
    from roughfe.fem.contact import LOAD_RTOL
    p_star = np.pi * MAT.E_star * G / LAM
    targets = np.array([0.15, 0.4, 0.7]) * p_star
    sweep = fem_contact_sweep(westergaard_mesh, MAT, pressures=targets)
    assert np.all(np.abs(sweep.mean_pressure / targets - 1) <= LOAD_RTOL)
    again = fem_contact_sweep(westergaard_mesh, MAT, applied_deltas=sweep.delta_applied)
    for key in ("mean_pressure", "area_fraction", "stiffness", "mean_gap"):
        assert np.allclose(getattr(again, key), getattr(sweep, key), rtol=1e-9, atol=0), key
    for r in sweep.results:
        ref = westergaard(G, LAM, MAT.E_star, r.mean_pressure)
        assert abs(contact_edge(r.x, r.gap, r.contact) / ref.half_width - 1) < 0.01
    with pytest.raises(InputError, match="exactly one of"):
        fem_contact_sweep(westergaard_mesh, MAT, [1e-7], pressures=targets)
    with pytest.raises(InputError, match="pressures must be > 0"):
        fem_contact_sweep(westergaard_mesh, MAT, pressures=[0.0, 1.0])


def test_full_contact_approach_is_the_least_full_contact_load(westergaard_mesh):
    """Delta = max h - mean h of the mirrored profile is full contact: beyond it the
    half-plane approach no longer grows with the load, and the Newton on it ran off
    (a NoConvergenceError at Delta_full, an imposed approach of 1e7 m beyond it). The
    step is now the state at the least full-contact load, Westergaard's p* = pi E* g /
    lambda, as the BEM's closed form; beyond it, a clear InputError."""
    p_star = np.pi * MAT.E_star * G / LAM
    sweep = fem_contact_sweep(westergaard_mesh, MAT, [0.5 * G, G])
    assert sweep.mean_pressure[-1] == pytest.approx(p_star, rel=1e-3)
    assert sweep.area_fraction[-1] > 0.95 and sweep.delta[-1] == pytest.approx(G, rel=1e-3)
    with pytest.raises(InputError, match="exceeds max h - mean h .* full contact already"):
        fem_contact_sweep(westergaard_mesh, MAT, [0.5 * G, 1.2 * G])


def test_stiffness_beyond_full_contact_is_infinite_as_the_bem():
    """Beyond the full-contact load the half-plane approach no longer grows: the periodic
    BEM returns K = inf. The FEM returned 1 / (1/k_applied - H_d/M) of a round-off
    difference, -1e26..-3e28 Pa/m, and the penalty's load control, reading that negative
    K as no contact, ran off to 4x the load (NoConvergenceError)."""
    from roughfe.bem import solve_contact
    surf = cosine_half_period(33)
    pm = mesh_profile(surf)
    load = 1.5 * np.pi * MAT.E_star * G / LAM                      # 1.5 p*
    bem = solve_contact(mirrored_profile(surf), MAT, mean_pressure=load, kernel="spectral")
    assert bem.stiffness == np.inf and bem.area_fraction == 1.0
    for method in ("vi", "penalty"):
        r = fem_contact_sweep(pm, MAT, pressures=[load],
                              options=FemSolverOptions(method=method)).results[0]
        assert r.mean_pressure == pytest.approx(load, rel=1e-6)
        assert r.area_fraction == 1.0 and r.stiffness == np.inf, (method, r.stiffness)
        # the penalty penetrates by p / (k E / dx) = 8e-6 G
        assert r.delta == pytest.approx(bem.delta, rel=2e-5)


def test_near_incompressible_body_warns_with_the_measured_locking_error():
    """P1 triangles with the element-wise volumetric term lock as nu -> 1/2: the FEM's
    pressure came out too high with no word (+8 % at nu = 0.49 on 33 nodes, +26 % at
    0.499 on 65). With ``volumetric="element"`` above nu = 0.45 a ResolutionWarning names
    the error measured at that nu and the cure, and the error is in its range; the
    default ("auto": the nodal form there) does not lock and does not warn."""
    import warnings
    from roughfe.bem import solve_contact
    from roughfe.errors import ResolutionWarning
    surf = cosine_half_period(33)
    pm = mesh_profile(surf)
    deltas = np.array([0.3, 0.7]) * G
    soft = Material(E=1e9, nu=0.49)
    with pytest.warns(ResolutionWarning, match=r"nu = 0.49 > 0.45: the P1 displacement FEM "
                      r"locks.* p \+3.4..8.1 %, K .* at nu = 0.49.*volumetric='nodal'.*"
                      r"method='bem'"):
        fem = fem_contact_sweep(pm, soft, deltas,
                                options=FemSolverOptions(volumetric="element"))
    bem = [solve_contact(mirrored_profile(surf), soft, delta=d, kernel="spectral")
           for d in deltas]
    error = fem.mean_pressure / [b.mean_pressure for b in bem] - 1      # measured 8.1, 6.4 %
    assert np.all((0.0335 <= error) & (error < 0.0815)), error       # the range, rounded
    with warnings.catch_warnings():
        warnings.simplefilter("error", ResolutionWarning)
        fem_contact_sweep(pm, MAT, deltas[:1])                             # nu = 0.3
        fem_contact_sweep(pm, soft, deltas[:1])                            # auto: nodal


@pytest.mark.parametrize("nu", [0.499, 0.49999])
def test_nodal_volumetric_form_does_not_lock(nu):
    """The volumetric term on the nodal average of div u (roughfe.fem.elasticity) against
    the periodic BEM of the mirrored cosine, a near-incompressible body: within 1 % in p
    and K on 33 top nodes (measured +0.5..0.7 %), closer on 65 (the discretisation error
    falls), where the element-wise form is 16-111 % off (LOCKING_ERRORS). The penalty
    solver builds on the same matrix and agrees with the VI to its penetration."""
    from roughfe.bem import solve_contact
    soft = Material(E=1e9, nu=nu)
    deltas = np.array([0.3, 0.7]) * G
    errors = []
    for n in (33, 65):
        surf = cosine_half_period(n)
        fem = fem_contact_sweep(mesh_profile(surf), soft, deltas)
        bem = [solve_contact(mirrored_profile(surf), soft, delta=d, kernel="spectral")
               for d in deltas]
        ep = fem.mean_pressure / [b.mean_pressure for b in bem] - 1
        ek = fem.stiffness / [b.stiffness for b in bem] - 1
        assert np.all(np.abs(ep) < 0.01) and np.all(np.abs(ek) < 0.01), (n, ep, ek)
        errors.append(np.max(np.abs(ep)))
    assert errors[1] < errors[0]
    penalty = fem_contact_sweep(mesh_profile(cosine_half_period(65)), soft, deltas,
                                options=FemSolverOptions(method="penalty"))
    assert np.allclose(penalty.mean_pressure, fem.mean_pressure, rtol=1e-4)
    from roughfe.errors import ResolutionWarning
    with pytest.warns(ResolutionWarning, match="locks volumetrically"):
        locked = fem_contact_sweep(mesh_profile(cosine_half_period(33)), soft, deltas[:1],
                                   options=FemSolverOptions(volumetric="element")).mean_pressure
    assert locked[0] > 1.15 * fem_contact_sweep(
        mesh_profile(cosine_half_period(33)), soft, deltas[:1]).mean_pressure[0]


def test_nodal_form_stress_and_convergence_near_incompressibility():
    """With the nodal form the kept sigma_yy is the form's own (lambda times the nodal
    average of div u): at the top of a parabolic contact -sigma_yy / p is 1 within a few
    per cent at nu = 0.499 (lambda times a triangle's own div u was up to 548x the peak
    pressure at 0.49999). And the SNES absolute tolerance grows with the modulus: at nu =
    0.499999 warm-started VI steps 1e-6 apart converge (they ran to DIVERGED_MAX_IT at
    |F| ~ 1e-11 with the fixed 1e-12) and agree with the penalty solver."""
    from roughfe.fem.elasticity import atol_scale
    W, n = 1e-3, 129
    x = np.arange(n) * W / (n - 1)
    pm = mesh_profile(Surface(-G * (x / W) ** 2, n * W / (n - 1)))
    r = fem_contact_sweep(pm, Material(E=1e9, nu=0.499), [0.06 * G], keep_fields=0).results[0]
    pts, cells, s = r.fields["points"], r.fields["cells"], r.fields["stress_yy"]
    cx = pts[cells, 0].mean(axis=1)
    top = np.isclose(pts[cells, 1].max(axis=1), 0.0) & (cx < 0.5 * r.contact_area)
    ratio = -s[top] / np.interp(cx[top], r.x, r.pressure)
    assert top.sum() >= 20 and np.all(np.abs(ratio - 1) < 0.05), ratio
    assert np.abs(s).max() < 1.05 * r.pressure.max()
    assert atol_scale(0.3) == atol_scale(0.45) == 1.0 and atol_scale(0.499999) > 1e4
    stiff = Material(E=1e9, nu=0.499999)
    fine = 0.05 * G * (1 + np.arange(6) * 1e-6)
    vi = fem_contact_sweep(pm, stiff, fine)
    pen = fem_contact_sweep(pm, stiff, fine, options=FemSolverOptions(method="penalty"))
    assert np.allclose(vi.mean_pressure, pen.mean_pressure, rtol=1e-4)


def test_volumetric_forms_auto_choice_and_bad_value():
    """``"auto"`` is the element form up to nu = 0.45 (bit-identical results: the FEM
    validation was measured with it) and the nodal form above; the nodal matrix is
    symmetric with unit Dirichlet rows (rollers and bottom held); a wrong name is an
    InputError that lists the choices."""
    from roughfe.fem.elasticity import stiffness_matrix, volumetric_form
    surf = cosine_half_period(33)
    pm = mesh_profile(surf)
    deltas = np.array([0.3, 0.7]) * G
    auto = fem_contact_sweep(pm, MAT, deltas)
    element = fem_contact_sweep(pm, MAT, deltas, options=FemSolverOptions(volumetric="element"))
    nodal = fem_contact_sweep(pm, MAT, deltas, options=FemSolverOptions(volumetric="nodal"))
    assert np.array_equal(auto.mean_pressure, element.mean_pressure)
    assert np.array_equal(auto.stiffness, element.stiffness)
    # at nu = 0.3 both forms are discretisations of the same body: within their errors
    assert np.allclose(nodal.mean_pressure, element.mean_pressure, rtol=0.01)
    assert not np.array_equal(nodal.mean_pressure, element.mean_pressure)
    assert [volumetric_form("auto", nu) for nu in (0.3, 0.45, 0.46)] == [
        "element", "element", "nodal"]
    from dolfinx import fem
    from petsc4py import PETSc
    V = fem.VectorFunctionSpace(pm.mesh, ("CG", 1))
    bcs = []
    for name, comp in (("left", 0), ("right", 0), ("bottom", 1)):     # as _ContactProblem
        dofs = fem.locate_dofs_topological(V.sub(comp), 1, pm.facet_tags.find(FACET_TAGS[name]))
        bcs.append(fem.dirichletbc(PETSc.ScalarType(0), dofs, V.sub(comp)))
    K = stiffness_matrix(V, 0.49, bcs, "nodal")
    try:
        dense = K.convert("dense").getDenseArray()
        assert np.allclose(dense, dense.T, atol=1e-12 * np.abs(dense).max())
        held = np.unique(np.concatenate([bc.dof_indices()[0] for bc in bcs]))
        eye = np.eye(dense.shape[0])
        assert np.array_equal(dense[held], eye[held])
        assert np.array_equal(dense[:, held], eye[:, held])
        free = np.setdiff1d(np.arange(dense.shape[0]), held)
        np.linalg.cholesky(dense[np.ix_(free, free)])        # positive definite there
    finally:
        K.destroy()
    with pytest.raises(InputError, match=r"volumetric must be one of \('auto', 'element', "
                       r"'nodal'\), got 'mixed'"):
        FemSolverOptions(volumetric="mixed")


def test_shallow_body_warns_and_a_body_thinner_than_dx_is_refused():
    """A body of depth W/2 on its roller bottom is stiffer than the half-plane: the FEM's
    pressure came out 18..40 % above the BEM's with no word. Below 2 W a ResolutionWarning
    names the error measured at that depth, and the error is in its range. A body thinner
    than dx (depth 1e-4 dx: slivers, then DIVERGED_MAX_IT) is an InputError."""
    import warnings
    from roughfe.bem import solve_contact
    from roughfe.errors import ResolutionWarning
    surf = cosine_half_period(33)
    W, dx = LAM / 2, surf.spacing[0]
    with pytest.warns(ResolutionWarning, match=r"depth = 0.00025 m = 0.5 W is shallower than "
                      r"the 2 W .* p \+18..40 %, K \+18..48 % at 0.5 W"):
        pm = mesh_profile(surf, depth=0.5 * W)
    deltas = np.array([0.3, 0.7]) * G
    fem = fem_contact_sweep(pm, MAT, deltas)
    bem = [solve_contact(mirrored_profile(surf), MAT, delta=d, kernel="spectral")
           for d in deltas]
    error = fem.mean_pressure / [b.mean_pressure for b in bem] - 1      # measured 27, 40 %
    assert np.all((0.175 <= error) & (error < 0.405)), error
    for formulation, depth in (("flat", 1e-4 * dx), ("profile", G + 0.5 * dx)):
        with pytest.raises(InputError, match=r"depth = .* m leaves a body .* thick, less "
                           r"than the top element size dx = 1.56e-05 m.* give depth >= dx"):
            mesh_profile(surf, depth=depth, formulation=formulation)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ResolutionWarning)
        mesh_profile(surf, depth=2 * W)                                    # the default


@pytest.mark.slow
@pytest.mark.parametrize("pc", ["hypre", "gamg"])
def test_iterative_inner_solver_gives_the_direct_solution(westergaard_mesh, pc):
    """CG + hypre or GAMG for the SNES-VI inner solves and the stiffness solve
    (petsc_options ksp_*/pc_*) reproduces the MUMPS solution (p, A*, K to 1e-6). GAMG runs
    inside a PC rebuilt when the VI's reduced system changes size (PETSc error 60 before:
    fem.petsc_tools.FreshOnResize)."""
    applied = np.array([0.5]) * G
    direct = fem_contact_sweep(westergaard_mesh, MAT, applied_deltas=applied)
    cg = fem_contact_sweep(westergaard_mesh, MAT, applied_deltas=applied, options=FemSolverOptions(
        petsc_options={"ksp_type": "cg", "pc_type": pc, "ksp_rtol": 1e-13}))
    for key in ("mean_pressure", "area_fraction", "stiffness"):
        assert np.allclose(getattr(cg, key), getattr(direct, key), rtol=1e-6, atol=0), key


def test_the_dimensionless_answer_does_not_depend_on_the_unit_of_length():
    """One 65-point profile at dx = 1 m, 1 mm and 1 pm (heights and approaches scaled with
    dx): the same mesh in units of W and the same p/E*, area fraction, K dx/E* and mean
    gap/dx. The mesh was built from x / W = i dx / ((n-1) dx), whose last bit depends on
    dx, and gmsh turned the 1-ulp differences into different interior meshes: p/E*
    0.0418401343 at dx = 1 m and 0.0418419674 at 1 mm (4.4e-5 apart, K 5e-5)."""
    base = random_profile(65, seed=4)
    h0 = base.heights / base.spacing[0]             # heights in units of dx
    meshes, answers = [], []
    for dx in (1.0, 1e-3, 1e-12):
        pm = mesh_profile(Surface(h0 * dx, 65 * dx), growth=0.1)
        deltas = np.array([0.1, 0.3, 0.5]) * np.ptp(h0) * dx
        res = fem_contact_sweep(pm, MAT, applied_deltas=deltas).results
        meshes.append(pm.mesh.geometry.x)
        answers.append(np.array([[r.mean_pressure / r.e_star, r.area_fraction,
                                  r.stiffness * dx / r.e_star, r.mean_gap / dx] for r in res]))
    for x, a in zip(meshes[1:], answers[1:]):
        assert x.shape == meshes[0].shape and np.array_equal(x, meshes[0])
        np.testing.assert_allclose(a, answers[0], rtol=1e-12, atol=0)


def test_response_takes_pressures_with_the_fem():
    """response(method="fem") refused load control ("use method='bem'") while
    fem_contact_sweep has it, and the FEM's own message for an approach beyond full
    contact said "give pressures" (a user's review). Now Loading(pressures=...) is the
    FEM's load control: the loads are met, the sweep is fem_contact_sweep's, and a load
    above the mirrored profile's full-contact pressure is full contact."""
    from roughfe.model import Loading
    from roughfe.response import response
    surf = cosine_half_period(33)
    p_star = np.pi * MAT.E_star * G / LAM                # Westergaard: full contact
    loads = np.array([0.2, 0.6, 1.5]) * p_star
    got = response(surf, MAT, Loading(pressures=tuple(loads)), method="fem")
    direct = fem_contact_sweep(mesh_profile(surf), MAT, pressures=loads)
    assert np.allclose(got.mean_pressure, loads, rtol=1e-5)
    np.testing.assert_array_equal(got.area_fraction, direct.area_fraction)
    assert got.area_fraction[0] < got.area_fraction[1] < 1.0 == got.area_fraction[2]
    one = response(surf, MAT, Loading(mean_pressure=0.6 * p_star), method="fem")
    assert one.mean_pressure[0] == pytest.approx(0.6 * p_star, rel=1e-5)
    assert one.area_fraction[0] == got.area_fraction[1]


def test_contact_command_runs_the_fem_on_a_profile(tmp_path, capsys):
    """`roughfe contact --method fem` (it had no way to run the FEM on a user's profile;
    a user's review): the FEM solves the evenly mirrored profile's problem, so it agrees
    with the BEM's --mirror at the same approaches (pressures within 2 %, contact
    fractions within 2 grid points); BEM-only flags and a 2D surface are refused by name."""
    import json
    from roughfe.cli import main
    from roughfe.surfaces.io import save_surface
    from roughfe.surfaces.rmd import rmd_profile
    prof = rmd_profile(7, 1.3, 1e-4, rng=3)
    save_surface(prof, tmp_path / "p.npz")
    common = [str(tmp_path / "p.npz"), "--steps", "3", "--E", "2e8", "--nu", "0.3",
              "--no-figures"]
    assert main(["contact", *common, "--method", "fem", "-o", str(tmp_path / "fem")]) == 0
    assert main(["contact", *common, "--mirror", "-o", str(tmp_path / "bem")]) == 0
    fem, bem = (json.loads((tmp_path / k / "results.json").read_text()) for k in ("fem", "bem"))
    assert fem["inputs"]["method"] == "fem" and fem["inputs"]["solver"].startswith("fem")
    for f, b in zip(fem["steps"][:-1], bem["steps"][:-1]):         # below full contact
        assert f["delta"] == pytest.approx(b["delta"], rel=1e-12, abs=0)
        assert f["mean_pressure"] == pytest.approx(b["mean_pressure"], rel=0.02, abs=0)
        assert abs(f["area_fraction"] - b["area_fraction"]) <= 2 / prof.shape[0] + 1e-12
    capsys.readouterr()
    assert main(["contact", *common, "--method", "fem", "--kernel", "strip", "--tol",
                 "1e-8", "--mirror", "-o", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err
    assert "--method fem does not take --mirror, --kernel, --tol" in err
    save_surface(Surface(np.outer(prof.heights[:64], np.ones(64)), (1e-4, 1e-4)),
                 tmp_path / "s.npz")
    assert main(["contact", str(tmp_path / "s.npz"), "--method", "fem", "-o",
                 str(tmp_path / "y")]) == 2
    assert "needs a 1D profile" in capsys.readouterr().err
