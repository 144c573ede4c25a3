"""Short waves modulated by the long-wave height (roughfe.genomics.design.modulation, issue
15 session 9): what the transform keeps, the direction it moves the crests' roughness,
and a modulated design's JSON."""
import numpy as np
import pytest

from roughfe.errors import InputError
from roughfe.genomics.design import (Design, DesignPart, crest_roughness, modulated_heights,
                                     wave_split)
from roughfe.genomics.genome import random_genome

L = 1e-4


def _field(n0=48, n1=40, seed=4):
    """A periodic Gaussian field with power at every wavenumber (m)."""
    rng = np.random.default_rng(seed)
    return 1e-7 * np.real(np.fft.ifft2(np.fft.fft2(rng.normal(size=(n0, n1)))))


def _design(modulation=0.0):
    g = random_genome(1.0, 0.8, 1.5, L, 3, 12, rng=1, angles=[0.3, 1.2, 2.5],
                      anisotropy=[1.0, 0.7, 1.3])
    return Design((DesignPart(g, tuple(range(g.n_first, g.n_last + 1)), 1.0, "g"),), 1.0, L,
                  32, "g", 2, modulation)


def test_modulation_keeps_the_long_waves_and_the_short_wave_rms():
    """Z' = Z_lo + Z_hi g rms(Z_hi)/rms(Z_hi g): Z_lo + Z_hi = Z - mean Z with Z_lo
    exactly the modes at |q| <= cut q_N; Z' - Z_lo has the rms of Z_hi (to round-off);
    depth 0 returns Z - mean Z."""
    h = _field() + 3e-7
    lo, hi = wave_split(h)
    np.testing.assert_allclose(lo + hi, h - h.mean(), rtol=0, atol=1e-20)
    r = np.hypot(np.fft.fftfreq(48)[:, None] * 2, np.fft.fftfreq(40)[None, :] * 2)
    assert np.abs(np.fft.fft2(lo)[r > 0.5]).max() < 1e-18
    assert np.abs(np.fft.fft2(hi)[r <= 0.5]).max() < 1e-18
    np.testing.assert_array_equal(modulated_heights(h, 0.0), lo + hi)
    for depth in (-0.4, 0.3, 1.0):
        out = modulated_heights(h, depth)
        assert np.isclose((out - lo).std(), hi.std(), rtol=1e-12, atol=0)
        assert np.abs(out - lo - hi).max() > 1e-3 * hi.std()       # it did move them


def test_positive_depth_moves_short_wave_roughness_off_the_crests():
    """crest_roughness (rms of Z_hi where Z_lo is in its top 10 %, over its rms) falls
    strictly as the depth rises: d/d eps log ratio^2 = -2 (weighted mean of Z_lo on the
    crest - on all nodes) < 0; about 1 for the unmodulated Gaussian field."""
    h = _field()
    c = [crest_roughness(modulated_heights(h, e)) for e in (-0.5, 0.0, 0.25, 0.5, 1.0)]
    assert np.all(np.diff(c) < 0)
    assert abs(c[1] - 1) < 0.15 and c[-1] < 0.75 < 1.4 < c[0]
    with pytest.raises(InputError, match="0 < top < 1"):
        crest_roughness(h, top=1.0)
    with pytest.raises(InputError, match="cut"):
        wave_split(h, cut=0.0)
    with pytest.raises(InputError, match="long and short waves"):
        modulated_heights(np.ones((8, 8)), 0.3)
    # a non-array, a profile or a NaN is named, not a numpy error from inside
    with pytest.raises(InputError, match="heights must be a numeric array"):
        crest_roughness("x")
    with pytest.raises(InputError, match=r"heights must be a 2D array, got shape \(8,\)"):
        wave_split(np.ones(8))
    bad = h.copy()
    bad[3, 4] = np.nan
    with pytest.raises(InputError, match=r"1 non-finite value\(s\), first at index \(3, 4\)"):
        modulated_heights(bad, 0.3)


def test_a_modulated_design_round_trips_and_an_unmodulated_one_stays_version_1():
    """A design carries its modulation into its heights and its JSON (version 2); without
    one it is written as before (version 1, no key); a profile cannot carry one."""
    plain, mod = _design(), _design(0.35)
    assert plain.to_dict()["version"] == 1 and "modulation" not in plain.to_dict()
    d = mod.to_dict()
    assert d["version"] == 2 and d["modulation"] == 0.35
    again = Design.from_dict(d)
    np.testing.assert_array_equal(again.surface().heights, mod.surface().heights)
    np.testing.assert_array_equal(mod.surface().heights,
                                  modulated_heights(plain.surface().heights, 0.35))
    keys = mod.keys("all")
    moved = mod.with_phases(keys, mod.phase_values(keys) + 0.1).split_chromosomes()
    assert moved.modulation == 0.35 and mod.as_genome() is None
    assert plain.as_genome() is not None
    with pytest.raises(InputError, match="modulation"):
        Design(plain.parts, 1.0, L, 32, "p", 1, 0.2)
    with pytest.raises(InputError, match="modulation"):
        _design(float("nan"))
