"""The full-grid passes of the BEM over threads (roughfe.bem._parallel): the same results
as the serial numpy calls, for the helpers, the FFT products and whole solves."""
import multiprocessing

import numpy as np
import pytest

from roughfe.bem import Material, _parallel, influence_operator, operators, solve_contact
from roughfe.errors import InputError
from roughfe.surfaces.spectral import spectral_surface


@pytest.fixture
def split(monkeypatch):
    """Every pass above 16 elements split over 3 threads (the test grids are small)."""
    monkeypatch.setattr(_parallel, "MIN_BLOCK", 16)
    monkeypatch.setattr(_parallel, "THREADS", 3)


def test_blocks_cover_the_range_in_order(split):
    for n in (0, 5, 16, 47, 48, 1000):
        got = _parallel.blocks(n, lambda a, b: (a, b))
        assert got[0][0] == 0 and got[-1][1] == n
        assert all(x[1] == y[0] for x, y in zip(got, got[1:]))
        assert len(got) == max(1, min(3, n // 16))


def test_gather_scatter_and_index_passes_equal_numpy(split):
    rng = np.random.default_rng(0)
    a = rng.standard_normal(1001)
    for density in (0.0, 0.01, 0.3, 1.0):
        mask = rng.random(a.size) < density
        idx = _parallel.flatnonzero(mask)
        assert idx.dtype == np.flatnonzero(mask).dtype
        assert np.array_equal(idx, np.flatnonzero(mask))
        assert np.array_equal(_parallel.take(a, idx), a[idx])
        out = np.empty(idx.size)
        assert _parallel.take(a, idx, out=out) is out
        b, ref = a.copy(), a.copy()
        v = rng.standard_normal(idx.size)
        _parallel.put(b, idx, v)
        ref[idx] = v
        assert np.array_equal(b, ref)
        _parallel.put(b, idx, 0.0)
        ref[idx] = 0.0
        assert np.array_equal(b, ref)
        c = np.zeros(a.size, np.float32)          # values cast to the target's dtype
        _parallel.put(c, idx, v)
        assert np.array_equal(c[idx], v.astype(np.float32))


def test_split_products_are_bit_identical(split):
    work = operators.FFTWorkspace()
    p = np.random.default_rng(1).random((32, 24))
    op = influence_operator(p.shape, (1e-3, 1e-3), 1e9)
    for single in (False, True):
        ref = op.apply(p, single=single)
        got = op.apply(p, single=single, out=np.empty(p.shape, ref.dtype), work=work)
        assert np.array_equal(got, ref)


@pytest.mark.parametrize("hardness", [None, 0.06])
def test_split_solve_equals_the_serial_one(monkeypatch, hardness):
    """The same iterations and the same state with the passes split over 3 threads as
    with ROUGHFE_THREADS=1 (block sums round differently only at 1e-16)."""
    surf = spectral_surface(64, 1.0, 0.8, rms_slope=1.0, rng=2)
    mat = Material(1.0, 0.0)

    def solve():
        return solve_contact(surf, mat, mean_pressure=0.02, solver="pk", tol=1e-10,
                             compute_stiffness=False, hardness=hardness)

    monkeypatch.setattr(_parallel, "THREADS", 1)
    serial = solve()
    monkeypatch.setattr(_parallel, "MIN_BLOCK", 16)
    monkeypatch.setattr(_parallel, "THREADS", 3)
    split = solve()
    assert split.nit == serial.nit
    assert split.area_fraction == serial.area_fraction
    assert np.abs(split.pressure - serial.pressure).max() <= 1e-9 * serial.pressure.max()
    # the load is carried exactly either way (Eq. 2.6 in load control)
    assert split.pressure.mean() == pytest.approx(0.02, rel=1e-12, abs=0)
    if hardness is not None:
        assert split.plastic_area_fraction == serial.plastic_area_fraction > 0


@pytest.mark.parametrize("value", ["0", "-2", "two"])
def test_bad_thread_count_is_a_clear_error(monkeypatch, value):
    monkeypatch.setenv("ROUGHFE_THREADS", value)
    with pytest.raises(InputError, match="ROUGHFE_THREADS must be a positive integer"):
        _parallel._thread_count()
    monkeypatch.setenv("ROUGHFE_THREADS", "3")
    assert _parallel._thread_count() == 3


def _split_pass_in_child():
    a = np.arange(1000.0)
    idx = np.arange(0, 1000, 3)
    raise SystemExit(0 if np.array_equal(_parallel.take(a, idx), a[idx]) else 1)


def test_a_forked_child_makes_its_own_pool(monkeypatch):
    """The parent's pool threads do not exist in a forked child: a split pass there must
    not wait for them (with one idle worker, as on 2 cores, it would hang for ever)."""
    monkeypatch.setattr(_parallel, "MIN_BLOCK", 16)
    monkeypatch.setattr(_parallel, "THREADS", 2)
    monkeypatch.setattr(_parallel, "_pool", None)       # a fresh pool of one worker
    _parallel.blocks(1000, lambda a, b: None)
    pool = _parallel._pool
    child = multiprocessing.get_context("fork").Process(target=_split_pass_in_child)
    child.start()
    child.join(30)
    if child.exitcode is None:
        child.kill()
    pool.shutdown()
    assert child.exitcode == 0
