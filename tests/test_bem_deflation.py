"""The two-level (deflation) coarse correction of the Polonsky-Keer CG (issue 16 §1):
the same solution of Eq. 2.5-2.6, fewer outer iterations, exact coarse matrix."""
import functools

import numpy as np
import pytest

from roughfe.bem.contact import _cg_preconditioner
from roughfe.bem.deflation import BlockDeflation, ProbedBlockDeflation
from roughfe.bem.operators import influence_operator
from roughfe.bem.pk import polonsky_keer
from roughfe.errors import InputError
from roughfe.surfaces.spectral import spectral_surface


def _solve(n, deflation, **target):
    h = spectral_surface(n, 1.0, 0.8, rms_slope=1.0, rng=1).heights
    op = influence_operator((n, n), (1.0, 1.0), 1.0)
    return polonsky_keer(op.apply, h, float(np.ptp(h)), diagonal=op.diagonal,
                         precond=_cg_preconditioner(op), tol=1e-10,
                         offset=-float(h.max()),
                         apply_single=functools.partial(op.apply, single=True),
                         deflation=None if deflation is None else deflation(op), **target)


def test_same_solution_fewer_iterations():
    # 128^2, cold, load control: 30 -> 21 outer iterations (measured); the solutions
    # agree to the KKT tolerance (pressures within 1e-8 of their maximum, the same
    # contact set), and every probe is counted as an operator product
    plain = _solve(128, None, mean_pressure=0.05)
    defl = _solve(128, lambda op: ProbedBlockDeflation(op, 8, 1), mean_pressure=0.05)
    assert defl.nit < 0.8 * plain.nit
    assert defl.n_products - plain.n_products >= 12 * defl.nit   # 16 probes + 1 per it
    scale = float(plain.pressure.max())
    assert np.abs(defl.pressure - plain.pressure).max() <= 1e-8 * scale
    assert np.array_equal(defl.pressure > 1e-9 * scale, plain.pressure > 1e-9 * scale)
    assert defl.delta == pytest.approx(plain.delta, rel=1e-8)


@pytest.mark.parametrize("radius, rtol", [(1, 2e-2), (3, 1e-9)])
def test_coarse_correction_is_the_galerkin_one(radius, rtol):
    # on a fixed free set F (zero-mean vectors, load control) the A-DEF2 direction with
    # the probed coarse matrix equals the one with the exact E = Z^T H_FF Z (dense, on
    # the zero-mean coarse space) up to the far-field approximation of the probes'
    # same-colour blocks: 1.2e-2 of the correction with radius 1 on this scattered F
    # (3e-3 on a real contact set), exact when every block has its own colour
    # (radius 3 on the 8 x 8 coarse grid)
    n, b = 64, 8
    op = influence_operator((n, n), (1.0, 1.0), 1.0)
    rng = np.random.default_rng(2)
    F = np.flatnonzero(rng.random(n * n) < 0.3)
    Hd = op.dense(F)
    g = rng.standard_normal(F.size)
    g -= g.mean()
    z = rng.standard_normal(F.size)
    z -= z.mean()
    blk = (F // n // b) * (n // b) + (F % n) // b
    Z = np.zeros((F.size, (n // b) ** 2))
    Z[np.arange(F.size), blk] = 1.0
    Z = Z[:, Z.any(axis=0)]
    Z -= Z.mean(axis=0)                      # the zero-mean coarse space
    c = np.linalg.lstsq(Z.T @ Hd @ Z, Z.T @ (g - Hd @ z + np.mean(Hd @ z)), rcond=None)[0]
    exact = z + Z @ c
    probed = ProbedBlockDeflation(op, b, radius).correct(F, g, z, lambda x: Hd @ x)
    assert np.linalg.norm(probed - exact) <= rtol * np.linalg.norm(exact - z)


@pytest.mark.parametrize("shape, block, radius", [((64, 64), 6, 1), ((64, 48), 8, 1),
                                                   ((64, 64), 8, 4)])
def test_bad_blocks(shape, block, radius):
    # blocks must tile the grid; probing needs a colouring that divides the coarse grid
    op = influence_operator(shape, (1.0, 1.0), 1.0)
    with pytest.raises(InputError, match="multiples of block|colouring"):
        ProbedBlockDeflation(op, block, radius)


def _galerkin(op, F, b):
    """The exact coarse matrix Z^T H_FF Z of the b x b block aggregates of F (dense)."""
    n0, n1 = op.shape
    m1 = n1 // b
    blk = (F // n1 // b) * m1 + (F % n1) // b
    Z = np.zeros((F.size, (n0 // b) * m1))
    Z[np.arange(F.size), blk] = 1.0
    return Z.T @ op.dense(F) @ Z


@pytest.mark.parametrize("n", [24, 64])
def test_block_deflation_coarse_matrix(n):
    # the coarse matrix built from the free-set mask: the near field (Chebyshev block
    # distance <= 1) is the exact Galerkin product Z^T H_FF Z (single-precision
    # rounding), so on a 3 x 3 coarse grid (every block a neighbour) the whole matrix
    # is; farther entries are the fill-scaled full-block ones, within 1 % here
    b = 8
    op = influence_operator((n, n), (1.0, 1.0), 1.0)
    F = np.flatnonzero(np.random.default_rng(2).random(n * n) < 0.3)
    exact = _galerkin(op, F, b)
    apply, counts, diag = BlockDeflation(op, b).coarse_operator(F)
    m = n // b
    E = np.stack([apply(e.reshape(m, m)).ravel() for e in np.eye(m * m)], axis=1)
    i, j = np.divmod(np.arange(m * m), m)
    di = np.abs(i[:, None] - i[None, :])
    dj = np.abs(j[:, None] - j[None, :])
    near = (np.minimum(di, m - di) <= 1) & (np.minimum(dj, m - dj) <= 1)
    scale = np.abs(exact).max()
    assert np.abs(E - exact)[near].max() <= 1e-6 * scale
    assert np.allclose(diag.ravel(), np.diag(exact), rtol=1e-6)
    assert np.array_equal(counts.ravel(), np.bincount(
        (F // n // b) * m + (F % n) // b, minlength=m * m))
    if m == 3:
        assert near.all()
    else:
        far = np.abs(E - exact)[~near].max()
        assert 0 < far <= 1e-2 * scale


def test_block_deflation_same_solution_fewer_iterations():
    # the production form in the real loop (128^2, cold, load control): 30 -> 21 outer
    # iterations, as the reference with probed E (measured), the same solution to the
    # KKT tolerance; one extra fine product per iteration only
    plain = _solve(128, None, mean_pressure=0.05)
    defl = _solve(128, lambda op: BlockDeflation(op, 8), mean_pressure=0.05)
    assert defl.nit < 0.8 * plain.nit
    assert defl.n_products <= plain.n_products + defl.nit
    scale = float(plain.pressure.max())
    assert np.abs(defl.pressure - plain.pressure).max() <= 1e-8 * scale
    assert np.array_equal(defl.pressure > 1e-9 * scale, plain.pressure > 1e-9 * scale)
    assert defl.delta == pytest.approx(plain.delta, rel=1e-8)


def test_block_deflation_update_is_exact():
    # the near field is recomputed only where the free set changed: after a first F,
    # the coarse matrix of a second one equals that of a fresh object
    n, b = 64, 8
    op = influence_operator((n, n), (1.0, 1.0), 1.0)
    rng = np.random.default_rng(3)
    u = rng.random(n * n)
    F1, F2 = np.flatnonzero(u < 0.3), np.flatnonzero((u < 0.3) ^ (u > 0.995))
    c = rng.standard_normal((n // b, n // b))
    kept = BlockDeflation(op, b)
    kept.coarse_operator(F1)
    again, counts, diag = kept.coarse_operator(F2)
    fresh, counts0, diag0 = BlockDeflation(op, b).coarse_operator(F2)
    assert np.array_equal(counts, counts0) and np.array_equal(diag, diag0)
    assert np.allclose(again(c), fresh(c), rtol=0, atol=1e-12 * np.abs(fresh(c)).max())


@pytest.mark.parametrize("shape, block, kw", [((64, 64), 6, {}), ((16, 16), 8, {}),
                                              ((64, 64), 8, {"coarse_tol": 0.0}),
                                              ((64, 64), 8, {"settle": -1.0})])
def test_block_deflation_bad_input(shape, block, kw):
    op = influence_operator(shape, (1.0, 1.0), 1.0)
    with pytest.raises(InputError, match="multiples of block|coarse_tol|settle"):
        BlockDeflation(op, block, **kw)


def test_solve_contact_uses_it_in_its_range(monkeypatch):
    # solve_contact takes the two-level correction for periodic elastic load-controlled
    # solves with sides in DEFLATION_SIDES (here widened to 128): the same contact
    # (A*, pressures within the KKT tolerance, Delta) as without, in fewer iterations
    from roughfe.bem import Material, solve_contact
    from roughfe.bem import contact

    surface = spectral_surface(128, 1.0, 0.8, rms_slope=1.0, rng=1)
    mat = Material(1.0, 0.0)
    plain = solve_contact(surface, mat, mean_pressure=0.05)
    monkeypatch.setattr(contact, "DEFLATION_SIDES", (128, 128))
    assert isinstance(contact._deflation(contact._operator(
        surface.shape, surface.size, 1.0, "spectral"), None, None), BlockDeflation)
    defl = solve_contact(surface, mat, mean_pressure=0.05)
    assert defl.nit < 0.8 * plain.nit
    assert defl.n_contact == plain.n_contact
    scale = float(plain.pressure.max())
    assert np.abs(defl.pressure - plain.pressure).max() <= 1e-8 * scale
    assert defl.delta == pytest.approx(plain.delta, rel=1e-8)
    # not with a hardness (its saturated points are not in the coarse space's load)
    assert contact._deflation(contact._operator(surface.shape, surface.size, 1.0,
                                                "spectral"), 1.0, None) is None
