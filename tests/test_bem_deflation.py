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
                                              ((48, 48), 12, {}),
                                              ((64, 64), 8, {"coarse_tol": 0.0}),
                                              ((64, 64), 8, {"settle": -1.0})])
def test_block_deflation_bad_input(shape, block, kw):
    op = influence_operator(shape, (1.0, 1.0), 1.0)
    with pytest.raises(InputError, match="multiple|coarse_tol|settle"):
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


@pytest.mark.parametrize("points", [1, 1 << 30])
def test_lean_passes_are_the_dense_formulas(monkeypatch, points):
    # the coarse correction's passes over F (whole block rows, bit-packed masks, no
    # F-sized index array) give what the one-line dense formulas give: the block
    # sums Z^T s, the prolongation z + Z c, the blocks' mask rows and point counts;
    # one block row per pass (points = 1) and one pass over the whole grid
    from roughfe.bem import coarse_blocks
    monkeypatch.setattr(coarse_blocks, "_POINTS", points)
    shape, b = (48, 64), 8
    n0, n1 = shape
    m1 = n1 // b
    op = influence_operator(shape, (0.75, 1.0), 1.0)
    rng = np.random.default_rng(4)
    F = np.flatnonzero(rng.random(n0 * n1) < 0.3)
    blk = (F // n1 // b) * m1 + (F % n1) // b
    s = rng.standard_normal(F.size)
    assert np.array_equal(coarse_blocks._restrict(F, s, shape, b),
                          np.bincount(blk, weights=s, minlength=(n0 // b) * m1))
    c = rng.standard_normal((n0 // b) * m1)
    z = rng.standard_normal(F.size)
    out = coarse_blocks._a_def2(F, s, z, lambda x: np.zeros_like(x), shape, b, lambda r: c)
    dense = z + c[blk]
    assert np.array_equal(out, dense - dense.mean())
    for bb in (8, 16):      # the blocks' mask rows from the grid mask: a block row is
        mb = n1 // bb       # one byte (b = 8) or several (b = 16)
        X, counts = BlockDeflation(op, bb)._free_rows(F)
        bk = (F // n1 // bb) * mb + (F % n1) // bb
        Xd = np.zeros(((n0 // bb) * mb, bb * bb), bool)
        Xd[bk, (F // n1 % bb) * bb + F % n1 % bb] = True
        assert X.dtype == np.uint8 and X.shape == ((n0 // bb) * mb, bb * bb // 8)
        assert np.array_equal(np.unpackbits(X, axis=1).astype(bool), Xd)
        assert np.array_equal(counts, np.bincount(bk, minlength=Xd.shape[0]))


def test_kernel_and_full_blocks_from_the_half_spectrum():
    # the near-field kernel window and K (Galerkin matrix of full blocks) are built from
    # the half spectrum without a full grid: they equal the real-space kernel
    # irfftn(spectrum) and H applied to a block indicator summed over blocks (their
    # definitions) to rounding, on a non-square grid
    from roughfe.bem.coarse_blocks import _full_block_galerkin, _kernel_window
    import scipy.fft
    shape, b = (48, 64), 8
    op = influence_operator(shape, (0.75, 1.0), 1.0)
    kern = scipy.fft.irfftn(op.spectrum, s=shape)
    rows, cols = np.arange(1 - b, 2 * b), np.arange(1 - 2 * b, 2 * b)
    window = _kernel_window(op, rows, cols)
    assert np.allclose(window, kern[np.ix_(rows % shape[0], cols % shape[1])],
                       rtol=0, atol=1e-14 * np.abs(kern).max())
    chi = np.zeros(shape)
    chi[:b, :b] = 1.0
    K = op.apply(chi).reshape(shape[0] // b, b, shape[1] // b, b).sum(axis=(1, 3))
    assert np.allclose(_full_block_galerkin(op, b), K, rtol=0, atol=1e-14 * np.abs(K).max())


@pytest.mark.parametrize("n", [256, 512])
def test_lean_passes_same_solve(monkeypatch, n):
    # in the real loop (cold, load control, tol 1e-10) the correction in passes of one
    # block row gives the solve of a single pass over the grid (the unchunked layout):
    # the same outer and coarse iterations and pressures
    from roughfe.bem import coarse_blocks
    runs = []
    for points in (8 * n, 1 << 40):
        monkeypatch.setattr(coarse_blocks, "_POINTS", points)
        made = []
        out = _solve(n, lambda op: made.append(BlockDeflation(op, 8)) or made[-1],
                     mean_pressure=0.05)
        runs.append((out, made[0].inner_iterations))
    (a, ia), (b, ib) = runs
    assert a.nit == b.nit and ia == ib and len(ia) > 0
    assert np.abs(a.pressure - b.pressure).max() <= 1e-12 * float(b.pressure.max())


def test_stable_part_coarse_matrix_is_the_galerkin_one():
    # while F changes, the coarse space holds the unchanged blocks only: restricted to
    # them, the kept near field (computed under earlier masks, updated only where a
    # mask changed) is the exact Galerkin matrix of the current F; a block left out and
    # changed meanwhile is recomputed when it comes back (3 x 3 coarse grid: every
    # entry is near field)
    n, b = 24, 8
    op = influence_operator((n, n), (1.0, 1.0), 1.0)
    rng = np.random.default_rng(5)
    u = rng.random((n, n))
    F1 = np.flatnonzero(u < 0.3)
    moved = np.zeros((n, n), bool)
    moved[:b, :b] = moved[b:2 * b, b:2 * b] = True           # blocks 0 and 4 change
    F2 = np.flatnonzero((u < 0.3) ^ (moved & (u > 0.9)))
    d = BlockDeflation(op, b)
    d.coarse_operator(F1)
    X, counts = d._free_rows(F2)
    keep = np.ones(9, bool)
    keep[4] = False
    apply, _, diag = d._coarse(X, np.where(keep, counts, 0))
    exact = _galerkin(op, F2, b)
    E = np.stack([apply(e.reshape(3, 3)).ravel() for e in np.eye(9)], axis=1)
    scale = np.abs(exact).max()
    assert np.abs(E - exact)[np.ix_(keep, keep)].max() <= 1e-6 * scale
    apply, _, diag = d._coarse(X, counts)                    # block 4 back in
    E = np.stack([apply(e.reshape(3, 3)).ravel() for e in np.eye(9)], axis=1)
    assert np.abs(E - exact).max() <= 1e-6 * scale
    assert np.allclose(diag.ravel(), np.diag(exact), rtol=1e-6)


def test_stable_part_during_the_search_same_solution(monkeypatch):
    # solve_contact at 512^2 (coarse start, two-level range widened to 512), p/E* =
    # 0.05, tol 1e-10: the correction on the stable part of F while the contact set is
    # searched (search = 1) against the default that skips it there (search = settle
    # = 0.3): the same solution to the KKT tolerance in no more iterations (measured
    # 23 -> 21 before the binding set of session 10, 21 -> 21 with it; 2048^2, 4 loads:
    # 115 -> 97 before, 102 -> 93 with it)
    from roughfe.bem import Material, contact, solve_contact
    surface = spectral_surface(512, 1.0, 0.8, rms_slope=1.0, rng=1)
    monkeypatch.setattr(contact, "DEFLATION_SIDES", (512, 8192))
    runs = []
    for search in (0.3, 1.0):
        monkeypatch.setattr(contact, "BlockDeflation",
                            functools.partial(BlockDeflation, search=search))
        runs.append(solve_contact(surface, Material(1.0, 0.0), mean_pressure=0.05,
                                  solver="pk", tol=1e-10, compute_stiffness=False))
    old, new = runs
    assert new.nit <= old.nit
    scale = float(old.pressure.max())
    assert np.abs(new.pressure - old.pressure).max() <= 1e-8 * scale
    assert np.array_equal(new.contact, old.contact)
    assert new.delta == pytest.approx(old.delta, rel=1e-8)
