"""FEM contact: the penalty's convergence, solver options and mesh size refused before
PETSc or gmsh sees them (session 32 review).

Budget: < 5 s together (meshes of < 1000 triangles; the refused meshes are never built).
"""
import warnings

import numpy as np
import pytest

pytest.importorskip("dolfinx")

from roughfe.errors import InputError, ResolutionWarning  # noqa: E402
from roughfe.fem import mesh_profile  # noqa: E402
from roughfe.fem.contact import FemSolverOptions, fem_contact_sweep  # noqa: E402
from roughfe.fem.limits import MAX_TRIANGLES, estimated_triangles  # noqa: E402
from roughfe.model import Material  # noqa: E402
from roughfe.surfaces import Surface  # noqa: E402

pytestmark = pytest.mark.fem

LAM, G = 1e-3, 1e-6
MAT = Material(E=1e9, nu=0.3)


def cosine_half_period(n):
    dx = (LAM / 2) / (n - 1)
    return Surface(G * np.cos(2 * np.pi * np.arange(n) * dx / LAM), n * dx)


@pytest.fixture(scope="module")
def coarse_mesh():
    return mesh_profile(cosine_half_period(33), growth=0.3)


@pytest.mark.parametrize("factor, rtol", [(1e4, 1e-3), (1e8, 1e-10)])
def test_penalty_converges_to_the_vi_whatever_its_first_residual(coarse_mesh, factor, rtol):
    """The penalty sweep gives the VI's pressure to its penetration error (1/k).

    It used to start each step from a penetrating state, where |F(x_0)| is kappa times
    the penetration, so SNES's relative test rtol |F(x_0)| passed after one Newton step:
    the pressure was 54 % high at k = 1e4, rtol = 1e-3, and the second load step 1.9 %
    high at k = 1e8 with the default rtol. Now the step starts on the obstacle (as the VI
    does) and agrees with the VI to 6e-6 (measured)."""
    applied = [0.3 * G, 0.6 * G]
    vi = fem_contact_sweep(coarse_mesh, MAT, applied_deltas=applied,
                           options=FemSolverOptions(rtol=rtol))
    pen = fem_contact_sweep(coarse_mesh, MAT, applied_deltas=applied, options=FemSolverOptions(
        method="penalty", penalty_factor=factor, rtol=rtol))
    # the penalty penetrates by ~1/k of the approach, and its pressure is lower by that
    assert np.allclose(pen.mean_pressure, vi.mean_pressure, rtol=1e-4, atol=0)
    assert np.all(pen.mean_pressure <= vi.mean_pressure * (1 + 1e-6))


def test_a_small_penalty_warns_with_its_penetration(coarse_mesh):
    """k = 10 lets the body into the obstacle by ~1 % of the approach and the pressure is
    ~1 % low: a ResolutionWarning names the penetration; the default k = 1e4 is silent."""
    applied = [0.5 * G]
    vi = fem_contact_sweep(coarse_mesh, MAT, applied_deltas=applied)
    with pytest.warns(ResolutionWarning, match="penalty_factor = 10 lets the body into"):
        pen = fem_contact_sweep(coarse_mesh, MAT, applied_deltas=applied,
                                options=FemSolverOptions(method="penalty", penalty_factor=10))
    r = pen.results[0]
    penetration = -r.gap.min() / r.delta_applied
    low = 1 - r.mean_pressure / vi.mean_pressure[0]
    assert 0.3 * penetration < low < penetration        # measured 0.7-0.9 x
    with warnings.catch_warnings():
        warnings.simplefilter("error", ResolutionWarning)
        fem_contact_sweep(coarse_mesh, MAT, applied_deltas=applied,
                          options=FemSolverOptions(method="penalty"))


def test_solver_options_petsc_refuses_are_input_errors():
    """rtol >= 1 was a petsc4py.Error (SNESSetTolerances, error code 63) at the first
    solve; a penalty factor beyond 1e8 is round-off (1 % off at 1e14) and was accepted."""
    for rtol in (1.0, 2.0):
        with pytest.raises(InputError, match=r"rtol .*\(0(\.0)?, 1(\.0)?\)"):
            FemSolverOptions(rtol=rtol)
    with pytest.raises(InputError, match="penalty_factor must be <= 1e"):
        FemSolverOptions(method="penalty", penalty_factor=1e10)
    assert FemSolverOptions(rtol=0.5, penalty_factor=1e8).rtol == 0.5


def test_a_mesh_too_large_is_refused_before_gmsh_runs(monkeypatch):
    """depth = 1e5 W asked gmsh for ~4e6 triangles (1e3 m under a 0.5 mm profile: 7e7,
    and gmsh stopped on the terminal to ask whether to continue)."""
    import gmsh

    def no_gmsh(*args, **kwargs):
        raise AssertionError("gmsh ran")

    monkeypatch.setattr(gmsh, "initialize", no_gmsh)
    s = cosine_half_period(17)
    W = LAM / 2
    with pytest.raises(InputError, match=r"triangles.*depth = .*size_max"):
        mesh_profile(s, depth=1e5 * W)
    with pytest.raises(InputError, match="triangles"):
        mesh_profile(s, size_max=1e-12, depth=1e4 * W)      # size_max -> dx: 6e6


def test_triangle_estimate_against_gmsh_and_gmsh_never_asks(monkeypatch):
    """The estimate is 0.6-1.0 of gmsh's count; gmsh meshes in expert mode (otherwise it
    asks "Do you really want to continue?" on the terminal when the body's size over the
    mean point size exceeds 1e5, e.g. a profile of > ~45k samples at the default depth)."""
    import gmsh

    generate = gmsh.model.mesh.generate
    seen = []

    def spy(dim):
        seen.append(gmsh.option.getNumber("General.ExpertMode"))
        return generate(dim)

    monkeypatch.setattr(gmsh.model.mesh, "generate", spy)
    for n, growth in ((33, 0.1), (33, 0.3)):
        pm = mesh_profile(cosine_half_period(n), growth=growth)
        dx = pm.element_size
        est = estimated_triangles(pm.width, pm.depth, dx, growth, pm.width / 4)
        assert 0.6 * pm.n_cells < est < 1.05 * pm.n_cells, (est, pm.n_cells)
    assert seen == [1.0, 1.0]
    assert MAX_TRIANGLES >= 1e6           # a 65k-sample profile (~1.5e6) is still meshed


def test_the_absolute_tolerance_grows_with_the_round_off_floor_of_large_meshes(
        coarse_mesh, monkeypatch):
    """The residual's 2-norm stagnates at a round-off floor ~ eps |u|_2 ~ sqrt(n_dofs)
    (measured 6.7e-14 ... 5.4e-13 from 7 246 to 390 000 DOFs; r = 16 of the RMD
    convergence study, ~1.55 M DOFs, stopped at |F| = 1.086e-12 > atol = 1e-12). The
    absolute tolerance is the documented rule atol sqrt(n / ATOL_REF_DOFS), at least atol:
    unchanged below the reference size, twice it at four times the size. An atol below the
    floor of this small mesh never converges (DIVERGED_MAX_IT); with the reference size
    set so that the same atol is scaled above the floor, the same solve converges to the
    default solve's pressure, and the result reports the scaled tolerance."""
    from roughfe.errors import NoConvergenceError
    from roughfe.fem import elasticity
    ref = elasticity.ATOL_REF_DOFS
    assert elasticity.atol_size_scale(ref // 10) == elasticity.atol_size_scale(ref) == 1.0
    assert elasticity.atol_size_scale(4 * ref) == pytest.approx(2.0, rel=1e-15, abs=0)
    applied = [0.5 * G]
    base = fem_contact_sweep(coarse_mesh, MAT, applied_deltas=applied).results[0]
    tiny = FemSolverOptions(rtol=1e-30, atol=1e-18, max_it=15)   # atol below the floor
    with pytest.raises(NoConvergenceError, match="DIVERGED_MAX_IT"):
        fem_contact_sweep(coarse_mesh, MAT, applied_deltas=applied, options=tiny)
    n_dofs = coarse_mesh.mesh.geometry.x.shape[0] * 2
    monkeypatch.setattr(elasticity, "ATOL_REF_DOFS", n_dofs / 1e8)   # factor 1e4
    r = fem_contact_sweep(coarse_mesh, MAT, applied_deltas=applied, options=tiny).results[0]
    assert r.tolerance == pytest.approx(1e-14, rel=1e-12, abs=0)
    assert r.residual <= r.tolerance
    assert r.mean_pressure == pytest.approx(base.mean_pressure, rel=1e-10, abs=0)
