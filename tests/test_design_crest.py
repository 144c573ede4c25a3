"""The crest-factor step of surface designs (roughfe.genomics.design.crest) and the z_max
penalty of the global stage: phases only, every wave's amplitude kept."""
from dataclasses import replace

import numpy as np
import pytest

from roughfe.errors import InputError
from roughfe.genomics.design import (Design, DesignPart, GlobalSearchOptions, clipped_phases,
                                     crest_phases, wave_modes)
from roughfe.genomics.genome import random_genome

LENGTH, N = 1e-4, 32


def _z_max(design):
    z = design.surface().heights
    return (z.max() - z.mean()) / z.std()


def _aligned_multisine():
    """Two parts of one genome (3 ridges, chromosomes 1-5, the same lattice waves, so
    every mode is shared by two waves), every phase pi: each wave a cos(k.x), all crests
    at the origin, so z_max = sum_modes |c| / rms (the largest crest factor)."""
    g = random_genome(1e-6, 0.8, 2.0, LENGTH, 3, 5, rng=4, angles=[0.0, 1.0, 2.0],
                      anisotropy=[1.0, 0.6, 1.4])
    g = replace(g, phases=np.full_like(g.phases, np.pi))
    return Design((DesignPart(g, (1, 2, 3, 4, 5), 1.0, "a"),
                   DesignPart(g, (2, 3, 4), 0.5, "b")), 1.0, LENGTH, N, "a+b", 2)


def _mode_moduli(design, modes):
    spec = np.fft.fft2(design.surface().heights)
    return np.abs(spec[modes[:, 0], modes[:, 1]])


def test_crest_step_keeps_every_wave_amplitude_and_lowers_z_max():
    """On an aligned multisine (z_max = sum of the wave amplitudes over the rms): every
    wave's amplitude gene and every lattice mode's modulus (the power spectrum) kept to
    1e-12, the rms kept, z_max lowered below the level asked (or its lowest) and well
    below the start."""
    d = _aligned_multisine()
    keys, modes, sign = wave_modes(d)
    z = d.surface().heights
    spec = np.abs(np.fft.fft2(z))
    peak = (spec.sum() - spec[0, 0]) / z.size                          # sum over all modes
    assert _z_max(d) == pytest.approx(peak / z.std(), rel=1e-12, abs=0)  # all crests at 0
    # an even field stays even under clipping (a fixed point): move every phase a little
    d = d.with_phases(keys, d.phase_values(keys) +
                      np.random.default_rng(1).uniform(-0.3, 0.3, len(keys)))
    assert _z_max(d) > 4.3
    out = crest_phases(d, 2.5, clip=0.9, n_iter=200)
    assert _z_max(out) <= 2.5
    for a, b in zip(d.parts, out.parts):
        for n in a.chromosomes:
            np.testing.assert_array_equal(a.genome.wave_amplitude(n), b.genome.wave_amplitude(n))
        np.testing.assert_array_equal(a.genome.anisotropy, b.genome.anisotropy)
        assert a.weight == b.weight
    before, after = _mode_moduli(d, modes), _mode_moduli(out, modes)
    np.testing.assert_allclose(after, before, rtol=1e-12, atol=1e-12 * before.max())
    # the rms of the field the step started from (the phase move changes it where two
    # waves share a mode: 0.26 %; this compared with the aligned start's 1.296e-10 m and
    # passed only through pytest.approx's default abs = 1e-12)
    rms = d.surface().heights.std()
    assert out.surface().heights.std() == pytest.approx(rms, rel=1e-12, abs=0)


def test_crest_phases_realise_the_projected_field():
    """The design returned after one step is the field of one clipping-and-projection
    step (the rotation of every mode mapped to its waves, shared and conjugate modes
    included) to round-off; a design already below the level is returned unchanged."""
    d = _aligned_multisine()
    keys, modes, sign = wave_modes(d)
    assert len(set(map(tuple, modes))) < len(keys)                     # shared modes
    z = d.surface().heights
    fields, _ = clipped_phases(z, modes, 0.8 * 1.0 * z.std(), 1)
    out = crest_phases(d, 1.0, clip=0.8, n_iter=1).surface().heights
    np.testing.assert_allclose(out - out.mean(), fields[0], atol=1e-12 * np.ptp(z))
    assert crest_phases(d, _z_max(d) + 0.1) is d
    with pytest.raises(InputError, match="z_max"):
        crest_phases(d, 0.0)


def test_peak_penalty_of_the_global_stage():
    """GlobalSearchOptions(peak=z): peak_weight x (z_max - z) above z, 0 below or off."""
    d = _aligned_multisine()
    zm = _z_max(d)
    assert GlobalSearchOptions().peak_penalty([d])[0] == 0.0
    opts = GlobalSearchOptions(peak=zm - 0.5, peak_weight=2.0)
    np.testing.assert_allclose(opts.peak_penalty([d, d]), [1.0, 1.0], rtol=1e-12)
    assert GlobalSearchOptions(peak=zm + 0.5).peak_penalty([d])[0] == 0.0
    with pytest.raises(InputError, match="peak_weight"):
        GlobalSearchOptions(peak=2.0, peak_weight=0.0)
