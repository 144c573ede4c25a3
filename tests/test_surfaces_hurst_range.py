"""Is the Hurst fit's range one power law (psd_fit.split_fit), the small-grid default
range, and a size that overrides an instrument file's own (round 2, session 32)."""
import warnings

import numpy as np
import pytest

from roughfe.surfaces import Surface, fit_hurst, load_surface, power_spectrum, spectral_surface
from roughfe.surfaces.psd_fit import split_fit
from roughfe.surfaces.stats import surface_statistics


def _crop(hurst, seed):
    """A non-periodic (Hann-windowed) window of a larger periodic self-affine surface."""
    big = spectral_surface(256, 2e-4, hurst, rms_height=1e-6, rng=seed)
    return Surface(big.heights[:128, :100], (1e-4, 1e-4 * 100 / 128), periodic=False)


@pytest.mark.parametrize("hurst", [0.3, 0.5, 0.8])
def test_self_affine_surfaces_are_one_power_law_and_keep_their_h(hurst):
    """The check only reports: on self-affine surfaces (periodic, and windowed crops) it
    says nothing, the default range is unchanged, the two halves agree within their
    stated errors, and the periodic fits recover H (mean of 4 seeds; one seed's sd 0.04)."""
    fits = []
    for seed in range(4):
        for s in (spectral_surface(128, 1e-4, hurst, rms_height=1e-6, rng=seed),
                  _crop(hurst, seed)):
            fit = fit_hurst(s)
            assert fit.message == "fit converged"
            assert fit.q_range == pytest.approx((8 * np.pi / max(s.size),
                                                 np.pi / (2 * max(s.spacing))), rel=1e-12)
            half = split_fit(power_spectrum(s), fit.q_range, s.size)
            gap = abs(half.hurst_low - half.hurst_high)
            assert gap < 4 * np.hypot(half.hurst_low_error, half.hurst_high_error)
            if s.periodic:
                fits.append(fit.hurst)
    assert np.mean(fits) == pytest.approx(hurst, abs=0.04)


def test_a_white_noise_floor_in_the_range_is_reported():
    """H = 0.8 plus white noise whose floor crosses the upper half of the default range:
    the single fit slides towards H = -1 (white noise) and says why, and the range below
    the floor gives back H."""
    s = spectral_surface(128, 1e-4, 0.8, rms_height=1e-6, rng=0)
    noisy = Surface(s.heights + 5e-7 * np.random.default_rng(1).standard_normal(s.shape),
                    s.size, periodic=True)
    fit = fit_hurst(noisy)
    half = split_fit(power_spectrum(noisy), fit.q_range, noisy.size)
    assert fit.hurst < 0.5 and half.hurst_high < 0 < half.hurst_low
    assert "not one power law" in fit.message and "noise floor" in fit.message
    assert "q_range" in fit.message and "--hurst-q-range" in fit.message
    below = fit_hurst(noisy, q_range=(fit.q_range[0], half.q_split))
    assert below.hurst == pytest.approx(0.8, abs=0.15)      # low half's error: 0.14


def test_opd1_is_curved_not_a_noise_floor(topographies_dir):
    """opd-1.opd (H = 0.03): its white floor (flat PSD, H ~ -1) lies beyond the default
    range, which ends at pi / (2 dx); inside it the PSD is curved, and the fit says so."""
    s = load_surface(topographies_dir / "opd-1.opd").detrended("plane")
    fit = fit_hurst(s)
    psd = power_spectrum(s)
    q_nyquist = np.pi / max(s.spacing)
    floor = split_fit(psd, (q_nyquist, psd.q.max()), s.size)     # the tail beyond Nyquist
    tail = fit_hurst(s, q_range=(q_nyquist, psd.q.max()))
    assert tail.hurst < -0.5 and fit.q_range[1] < q_nyquist        # flat, and not fitted
    assert floor.note == "" or "power law" in floor.note
    half = split_fit(psd, fit.q_range, s.size)
    assert half.hurst_low < fit.hurst < half.hurst_high
    assert "not one power law" in fit.message
    assert "noise floor" not in fit.message          # its high half is the steeper one
    assert surface_statistics(s).hurst_message == fit.message


@pytest.mark.parametrize("n", [8, 16])
def test_small_grid_reports_no_inverted_range(n):
    """The default range 8 pi / L .. pi / (2 dx) is empty for <= 16 points per side: it
    was returned as q_range with low > high; now no range (NaN) and the reason."""
    s = spectral_surface(n, 1e-5, 0.5, rms_height=1e-7, rng=0)
    fit = fit_hurst(s)
    assert not fit.success and np.isnan(fit.q_range).all()
    assert "grid too small" in fit.message and "q_range" in fit.message
    assert np.isnan(surface_statistics(s).hurst_q_range).all()
    given = fit_hurst(s, q_range=(2 * np.pi / 1e-5, np.pi * n / 1e-5))   # still possible
    assert given.q_range[0] < given.q_range[1]


def test_size_overriding_an_instrument_files_size_warns(topographies_dir):
    path = topographies_dir / "di-1.di"                    # 500 nm x 500 nm AFM scan
    with pytest.warns(UserWarning, match=r"\(1 x 1 um\).*file's own physical size "
                                         r"\(0\.5 x 0\.5 um\)"):
        s = load_surface(path, size=(1e-6, 1e-6))
    assert s.size == (1e-6, 1e-6)
    assert s.metadata["size_in_file"] == pytest.approx([5e-7, 5e-7], rel=1e-12, abs=0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")                     # the file's own size: silent
        load_surface(path, size=(5e-7, 5e-7 * (1 + 1e-6)))
        load_surface(path, size=5e-7)
        load_surface(path)
