"""KrylovSolver (roughfe.fem.petsc_tools): a kept AMG hierarchy solves changed matrices of
the same pattern to the same tolerance, rebuilds when it stalls, and accepts a new size."""
import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

pytest.importorskip("petsc4py")

from roughfe.fem.petsc_tools import KrylovSolver, ksp_solve  # noqa: E402
from roughfe.leakage.finite_volume import REYNOLDS_FV  # noqa: E402


def diffusion(n, k):
    """5-point operator of div(k grad p) on an n x n grid of cells with conductances k
    (harmonic face means) and Dirichlet sides: SPD, the Reynolds form."""
    k = k.reshape(n, n)
    rows, cols, vals = [], [], []
    idx = np.arange(n * n).reshape(n, n)
    diag = np.zeros((n, n))
    for a, b in ((idx[:-1], idx[1:]), (idx[:, :-1], idx[:, 1:])):
        t = 2 * k.ravel()[a] * k.ravel()[b] / (k.ravel()[a] + k.ravel()[b])
        rows += [a.ravel(), b.ravel()]
        cols += [b.ravel(), a.ravel()]
        vals += [-t.ravel(), -t.ravel()]
        np.add.at(diag.ravel(), a.ravel(), t.ravel())
        np.add.at(diag.ravel(), b.ravel(), t.ravel())
    diag[0] += 2 * k[0]
    diag[-1] += 2 * k[-1]
    rows.append(idx.ravel())
    cols.append(idx.ravel())
    vals.append(diag.ravel())
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))))


def test_kept_hierarchy_same_answer_fewer_setups():
    # a sequence of slowly changing conductances (a coupling loop): every answer equals a
    # direct solve to the CG tolerance, with 2 AMG set-ups for the 6 matrices
    rng = np.random.default_rng(3)
    n = 40
    k0 = np.exp(rng.standard_normal(n * n))
    b = rng.standard_normal(n * n)
    with KrylovSolver("t", REYNOLDS_FV, reuse_preconditioner=True) as solver:
        for step in range(6):
            A = diffusion(n, k0 * (1 + 0.05 * step * np.sin(np.arange(n * n))))
            x, nit, ok, message = solver.solve(A, b)
            fresh = ksp_solve(A, b, name="t", options=REYNOLDS_FV)
            exact = spla.spsolve(A.tocsc(), b)
            assert ok and np.abs(x - exact).max() <= 1e-8 * np.abs(exact).max()
            assert nit <= fresh[1] + 3                      # kept: at most 2 more + 1
            assert ("kept preconditioner" in message) == (step in (1, 2, 3, 4))
        assert solver.setups == 2             # the hierarchy of step 0 serves steps 1-4


def test_stalled_hierarchy_is_rebuilt_and_new_size_accepted():
    rng = np.random.default_rng(4)
    n = 40
    b = rng.standard_normal(n * n)
    smooth = diffusion(n, np.ones(n * n))
    rough = diffusion(n, 10.0 ** rng.uniform(-6, 0, n * n))   # conductances over 6 decades
    with KrylovSolver("t", REYNOLDS_FV, reuse_preconditioner=True) as solver:
        solver.solve(smooth, b)
        x, nit, ok, message = solver.solve(rough, b)
        exact = spla.spsolve(rough.tocsc(), b)
        assert ok and "rebuilt" in message and solver.setups == 2
        assert np.abs(x - exact).max() <= 1e-8 * np.abs(exact).max()
        small = diffusion(n // 2, np.ones(n * n // 4))        # PETSc error 60 without a reset
        bs = b[: n * n // 4]
        x, nit, ok, message = solver.solve(small, bs)
        assert ok and solver.setups == 3
        assert nit == ksp_solve(small, bs, name="t", options=REYNOLDS_FV)[1]
        assert np.allclose(small @ x, bs, atol=1e-8 * np.abs(bs).max())


def test_petsc_options_refused_misspelled_or_read_at_set_up():
    """The Reynolds KSP options: a value PETSc refuses was a bare petsc4py.PETSc.Error, a
    misspelled key was dropped without a word (the options were deleted right after
    setFromOptions, so PETSc's own unused-option report never fired), and the MUMPS keys,
    which PETSc reads at the factorization, never reached MUMPS. Now the first two are
    InputErrors naming the key, ICNTL(14) of the factor is the value given, and the
    options database is left as it was."""
    from petsc4py import PETSc

    from roughfe.errors import InputError
    from roughfe.fem.petsc_tools import LU_MUMPS

    before = PETSc.Options().getAll()
    A, b = diffusion(8, np.ones(64)), np.ones(64)
    with pytest.raises(InputError, match=r"ksp_type='foo' .*KSP type foo"):
        ksp_solve(A, b, name="reynolds", options={"ksp_type": "foo"})
    with pytest.raises(InputError, match=r"\['ksp_typ'\] .*never read"):
        ksp_solve(A, b, name="reynolds", options={"ksp_typ": "cg"})
    with pytest.raises(InputError, match=r"ksp_rtol='x1' .*no numeric value"):
        ksp_solve(A, b, name="reynolds", options={"ksp_rtol": "x1"})
    # a default that the caller's pc_type leaves unread (pc_hypre_type) is no error
    assert ksp_solve(A, b, name="t", options={"pc_type": "gamg"})[2]
    with KrylovSolver("t", {**LU_MUMPS, "mat_mumps_icntl_14": 77}) as solver:
        x, nit, ok, message = solver.solve(A, b)
        assert ok and np.allclose(A @ x, b)
        assert solver._ksp.getPC().getFactorMatrix().getMumpsIcntl(14) == 77
    assert PETSc.Options().getAll() == before
