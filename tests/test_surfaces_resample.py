"""One band-limited interpolant (roughfe.surfaces.resample, round 2, session 34):
``Surface.resampled`` (any shape) and ``Surface.refined`` (integer factor) are the same
routine, and the Nyquist mode of an even grid is the cosine its samples see: split between
+-n/2 on refinement, joined from +-m/2 on coarsening (``resampled`` dropped it until
session 34, which changed every sample of a refined measured window)."""
import numpy as np
import pytest
import scipy.signal

from roughfe.errors import InputError
from roughfe.surfaces import Surface
from roughfe.surfaces.resample import refined, resampled


def test_refining_a_nyquist_cosine_gives_the_cosine_between_the_nodes():
    """h_j = 1 + (-1)^j on 8 points is 1 + cos(pi x / dx): on 16 points 2, 1, 0, 1, ...
    (the old rule, dropping the mode, gave 1 everywhere)."""
    p = Surface(1.0 + (-1.0) ** np.arange(8), 8.0, periodic=True)
    x = np.arange(16) / 2.0
    np.testing.assert_allclose(p.resampled(16).heights, 1.0 + np.cos(np.pi * x),
                               rtol=0, atol=1e-14)
    # the continuous mean square counts the cosine at 1/2 (the samples' crests at 1),
    # the same on every finer grid, odd or even
    for m in (9, 16, 24, 41):
        assert np.mean((p.resampled(m).heights - 1.0) ** 2) == pytest.approx(0.5, abs=1e-14)


def test_coarsening_keeps_the_part_of_the_new_nyquist_wave_the_nodes_see():
    """cos(2 pi 8 x / L + phi) on 40 points, resampled to 16 (new Nyquist wavenumber 8):
    the new nodes see cos(phi) (-1)^j, which the result keeps (dropped before); a wave
    beyond it (k = 9) is removed, not aliased."""
    phi = 0.7
    x = np.arange(40) / 40
    s = Surface(np.cos(2 * np.pi * 8 * x + phi) + 0.3 * np.cos(2 * np.pi * 9 * x), 1.0,
                periodic=True)
    np.testing.assert_allclose(s.resampled(16).heights,
                               np.cos(phi) * (-1.0) ** np.arange(16), rtol=0, atol=1e-14)


def test_refine_then_coarsen_back_is_the_identity_and_samples_are_kept():
    rng = np.random.default_rng(5)
    s = Surface(rng.normal(size=(16, 10)) * 1e-9, (2e-6, 1e-6), periodic=True)
    fine = s.resampled((32, 25))
    assert fine.shape == (32, 25) and fine.size == s.size and fine.periodic
    assert fine.metadata["resampled_from"] == [16, 10]
    np.testing.assert_allclose(fine.heights[::2, ::5][:, :5], s.heights[:, ::2],
                               rtol=0, atol=1e-22)
    np.testing.assert_allclose(fine.resampled((16, 10)).heights, s.heights,
                               rtol=0, atol=1e-22)
    np.testing.assert_allclose(fine.heights.mean(), s.heights.mean(), rtol=0, atol=1e-24)
    # the same grid: the identity (the old rule dropped the Nyquist lines there too)
    np.testing.assert_array_equal(s.resampled((16, 10)).heights, s.heights)


@pytest.mark.parametrize("n, m", [(8, 16), (8, 13), (9, 16), (16, 10), (15, 10),
                                  (16, 9), (12, 12)])
def test_resampled_is_scipys_fourier_resampling(n, m):
    """Two implementations: scipy.signal.resample (the same split/join rule)."""
    rng = np.random.default_rng(n * 100 + m)
    s = Surface(rng.normal(size=(n, n + 3)), (1.0, 1.3), periodic=True)
    want = scipy.signal.resample(scipy.signal.resample(s.heights, m, axis=0), 7, axis=1)
    np.testing.assert_allclose(s.resampled((m, 7)).heights, want, rtol=0, atol=1e-13)


def test_refined_periodic_is_resampled_to_factor_n():
    rng = np.random.default_rng(2)
    s = Surface(rng.normal(size=(12, 7)), (1.0, 1.0), periodic=True)
    np.testing.assert_array_equal(refined(s, 3).heights, resampled(s, (36, 21)).heights)


def test_resampling_refuses_what_it_cannot_do():
    with pytest.raises(InputError, match="resampled.*Surface, got ndarray"):
        resampled(np.zeros((4, 4)), (8, 8))
    with pytest.raises(InputError, match="periodic"):
        Surface(np.zeros((4, 4)), (1.0, 1.0)).resampled((8, 8))


def test_resampling_beyond_the_memory_is_refused_before_any_allocation(monkeypatch):
    """A grid whose axis passes need more than the available memory is refused at once
    with what, how much and what is free (``design --match-spectrum`` onto a 7.8 nm
    database spacing took x3p-2 towards ~80 GB and hung; round 2, session 37). The limit
    is the available memory: with 1 MB available a 64^2 -> 256^2 resampling (256^2 x 64
    bytes = 4 MB) is refused and a 64^2 -> 64 x 100 one (0.4 MB) is not."""
    import roughfe.errors as errors
    s = Surface(np.random.default_rng(0).normal(size=(64, 64)), (1.0, 1.0), periodic=True)
    with pytest.raises(InputError, match=r"resampling a 64 x 64 grid onto 100000 x 100000 "
                                         r"points needs [\d.]+ GiB of memory"):
        resampled(s, (100_000, 100_000))
    with pytest.raises(InputError, match=r"onto 640000 x 640000 points needs"):
        refined(s, 10_000)
    window = Surface(s.heights, s.size, periodic=False)      # refined through its mirror
    with pytest.raises(InputError, match=r"resampling a 126 x 126 grid onto 1260000 x "):
        refined(window, 10_000)
    monkeypatch.setattr(errors, "available_memory", lambda: 1_000_000)
    with pytest.raises(InputError, match="needs 0.0 GiB of memory, 0.0 GiB are available"):
        resampled(s, (256, 256))
    assert resampled(s, (64, 100)).shape == (64, 100)
