"""The memory check of a BEM solve (roughfe.bem.memory): before the operator is built,
on the FFT grid the kernel needs, and never above what a solve really allocates."""
import tracemalloc

import numpy as np
import pytest

from roughfe import errors
from roughfe.bem import Material, solve_contact
from roughfe.bem.memory import SOLVE_BYTES_PER_FFT_POINT, check_solve_memory, fft_points
from roughfe.surfaces import Surface
from roughfe.surfaces.spectral import spectral_surface


def _waves(n, periodic):
    x = np.arange(n) / n
    h = 1e-6 * np.cos(2 * np.pi * x)[:, None] * np.cos(2 * np.pi * x)[None, :]
    return Surface(h, 1e-4, periodic=periodic)


def test_a_solve_too_large_for_the_memory_is_refused_before_the_operator(monkeypatch):
    """A non-periodic 16384^2 solve died in numpy or by the OOM killer building its
    kernel on the padded 32768^2 grid. With the memory between what the periodic 64^2
    grid and the padded 128^2 grid need (40 bytes per FFT point), the periodic solve
    runs and the non-periodic one is refused, naming both grids, before any operator is
    built (the padded grid is what costs: 4x the points)."""
    import roughfe.bem.contact as contact

    assert fft_points((64, 64), True) == (64, 64)
    assert fft_points((64, 64), False) == (128, 128)
    assert fft_points((100,), False) == (200,)             # a profile: 2n - 1, made fast
    steel = Material(E=210e9, nu=0.3)
    monkeypatch.setattr(errors, "available_memory",
                        lambda: 2 * 64 * 64 * SOLVE_BYTES_PER_FFT_POINT)
    done = solve_contact(_waves(64, True), steel, mean_pressure=1e6)
    assert 0 < done.contact_area < 1
    built = []
    original = contact._operator
    monkeypatch.setattr(contact, "_operator", lambda *a: built.append(a) or original(*a))
    with pytest.raises(errors.MemoryShortage,
                       match=r"^a contact solve on a 64 x 64 grid \(non-periodic: on its "
                             r"zero-padded 128 x 128 FFT grid\) needs 0.0 GiB of memory"):
        solve_contact(_waves(64, False), steel, delta=1e-7)
    assert built == []
    with pytest.raises(errors.MemoryShortage, match="16384 x 16384 grid .* 32768 x 32768 "
                                                    "FFT grid.* needs 40.0 GiB"):
        check_solve_memory((16384, 16384), periodic=False)


@pytest.mark.parametrize("periodic", [True, False])
def test_the_check_counts_less_than_a_solve_allocates(periodic):
    """The check's 40 bytes per FFT point is a lower bound (a shortage it reports is
    certain): a light load (the fewest free points, the smallest allocation measured)
    on a 256^2 grid allocates more than that through numpy (tracemalloc's peak; 74 and
    55, of which the operator, built as the check assumes, is ~16 on the padded grid)."""
    import roughfe.bem.contact as contact

    s = spectral_surface(256, 1e-3, 0.8, rms_slope=1.0, rng=1)
    s = s if periodic else Surface(s.heights, 1e-3, periodic=False)
    material = Material(1.0, 0.0)
    contact._operator.cache_clear()         # built in the solve, as the check counts it
    contact._inverse_spectrum.cache_clear()
    tracemalloc.start()
    try:
        solve_contact(s, material, mean_pressure=0.005 * material.E_star)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    per_point = peak / np.prod(fft_points(s.shape, periodic))
    assert SOLVE_BYTES_PER_FFT_POINT < per_point < 4 * SOLVE_BYTES_PER_FFT_POINT, per_point
