"""User arrays at the public entry points: a masked array's hidden values and a complex
array's imaginary part are not data.

``np.asarray(x, dtype=float)`` keeps the values under a mask (a topography's undefined
points) and drops an imaginary part with only a ComplexWarning; a masked gap with a
column of 1 mm samples under its mask leaked 2.6e-9 m^3/s instead of 6.3e-16. Every
entry point routes its arrays through :func:`roughfe.errors.check_real_array`, as
:class:`~roughfe.surfaces.Surface` does.
"""
import numpy as np
import pytest

from roughfe.bem import solve_contact
from roughfe.bem.batch import solve_batch
from roughfe.bem.contact import surface_displacement
from roughfe.bem.operators import influence_operator
from roughfe.errors import InputError
from roughfe.leakage import (analyse_leakage, channel_flow, critical_constriction,
                             directional_network, finite_volume_leak_rate,
                             free_volume_network, reynolds_flow)
from roughfe.model import Material
from roughfe.surfaces import Surface, spectral_surface
from roughfe.theory import mean_separation, persson

N, L = 16, 1e-4
SPACING = (L / N, L / N)


def _gap():
    s = spectral_surface(N, L, hurst=0.8, rms_height=1e-6, rng=1)
    return s.heights - s.heights.min()


def _masked(a):
    """``a`` with one column replaced by 1 mm samples and masked out."""
    bad = np.array(a, dtype=float)
    bad[..., N // 2] = 1e-3
    m = np.zeros(bad.shape, bool)
    m[..., N // 2] = True
    return np.ma.masked_array(bad, mask=m)


def _complex(a):
    return np.asarray(a) + 1e-7j


SURFACE = spectral_surface(N, L, hurst=0.8, rms_height=1e-6, rng=1)
MATERIAL = Material(1e9, 0.3)
PRESSURE = np.full(SURFACE.shape, 1e6)
Q, POWER = np.linspace(1e4, 1e6, 16), np.full(16, 1e-14)

# name -> a call of the entry point with its array argument replaced by ``a``
CALLS = {
    "reynolds_flow": lambda a: reynolds_flow(a, SPACING),
    "finite_volume_leak_rate": lambda a: finite_volume_leak_rate(a, SPACING),
    "analyse_leakage": lambda a: analyse_leakage(a, None, SPACING, sigma=1e-6),
    "free_volume_network": lambda a: free_volume_network(a, None, SPACING),
    "directional_network": lambda a: directional_network(np.ones((N, N), bool), a, SPACING),
    "critical_constriction": lambda a: critical_constriction(a, SPACING),
    "channel_flow": lambda a: channel_flow(a[0], L / N, p_in=1.0, p_out=0.0),
    "Surface.with_heights": lambda a: SURFACE.with_heights(a),
    "solve_contact initial": lambda a: solve_contact(
        SURFACE, MATERIAL, mean_pressure=1e6, initial=a * 1e12),
    "surface_displacement": lambda a: surface_displacement(SURFACE, MATERIAL, a * 1e12),
    "solve_batch initial": lambda a: solve_batch(
        influence_operator(SURFACE.shape, SURFACE.size, MATERIAL.E_star), SURFACE.heights[None],
        mean_pressure=[1e6], initial=a[None] * 1e12),
    "solve_batch mean_pressure": lambda a: solve_batch(
        influence_operator(SURFACE.shape, SURFACE.size, MATERIAL.E_star), SURFACE.heights[None],
        mean_pressure=a[:1, N // 2] * 1e12 + 1e6),
    "solve_contact plastic_displacement": lambda a: solve_contact(
        SURFACE, MATERIAL, mean_pressure=1e6, hardness=1e8, plastic_displacement=a * 1e-3),
    "mean_separation power": lambda a: mean_separation(Q, a[0, :16] * 1e-8, 1e9, 1e6),
    "persson mean_pressure": lambda a: persson(SURFACE, 1e9, a[0] * 1e12 + 1.0),
}


@pytest.mark.parametrize("name", sorted(CALLS))
def test_masked_and_complex_arrays_are_refused(name):
    call, gap = CALLS[name], _gap()
    call(gap)                                          # the plain array is accepted
    with pytest.raises(InputError, match=r"masked array with \d+ masked"):
        call(_masked(gap))
    with pytest.raises(InputError, match="complex"):
        call(_complex(gap))


def test_an_unmasked_masked_array_is_its_data():
    """A masked array without masked points is the plain array: the same leak rate."""
    g = _gap()
    plain = reynolds_flow(g, SPACING).leak_rate
    assert reynolds_flow(np.ma.masked_array(g, mask=False), SPACING).leak_rate == plain
