"""User arrays at the public entry points: a masked array's hidden values and a complex
array's imaginary part are not data.

``np.asarray(x, dtype=float)`` keeps the values under a mask (a topography's undefined
points) and drops an imaginary part with only a ComplexWarning; a masked gap with a
column of 1 mm samples under its mask leaked 2.6e-9 m^3/s instead of 6.3e-16. Every
entry point routes its arrays through :func:`roughfe.errors.check_real_array`, as
:class:`~roughfe.surfaces.Surface` does.
"""
import functools

import numpy as np
import pytest

from roughfe.bem import solve_contact
from roughfe.bem.batch import solve_batch
from roughfe.bem.contact import surface_displacement
from roughfe.bem.operators import influence_operator
from roughfe.bem.stiffness import load_controlled_gap_response
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


@functools.cache
def _contact():
    return solve_contact(SURFACE, MATERIAL, mean_pressure=1e7)


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
    "load_controlled_gap_response": lambda a: load_controlled_gap_response(_contact(), [a]),
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


OPERATORS = [("spectral", (16, 12)), ("love", (16, 12)), ("strip", (32,))]


@pytest.mark.parametrize("kernel, shape", OPERATORS)
def test_influence_operator_apply_checks_its_pressure(kernel, shape):
    """InfluenceOperator.apply (public) took any shape: the FFT zero-padded a smaller
    pressure and cropped a larger one (a (32, 32) pressure on a (64, 64) operator: 214 %
    off), and a float32 pressure gave a float32 displacement without ``single``."""
    op = influence_operator(shape, (1e-6,) * len(shape), 1e9, kernel)
    p = np.random.default_rng(0).uniform(0, 1e6, shape)
    u = op.apply(p)
    assert u.dtype == np.float64 and u.shape == shape
    np.testing.assert_array_equal(op.apply(p.tolist()), u)      # array_like
    p32 = p.astype(np.float32)
    u32 = op.apply(p32)
    assert u32.dtype == np.float64                              # single only with single=True
    np.testing.assert_allclose(u32, op.apply(p32.astype(float)), rtol=0, atol=1e-13 * abs(u).max())
    assert op.apply(p, single=True).dtype == np.float32
    stack = op.apply(np.stack([p, 2 * p, 0 * p]))               # a stack over a leading axis
    np.testing.assert_allclose(stack, np.stack([u, 2 * u, 0 * u]), rtol=0,
                               atol=1e-12 * abs(u).max())
    wrong = [tuple(n - 1 for n in shape), tuple(2 * n for n in shape), shape[:-1] + (1,),
             shape + (1,), (shape[0] * int(np.prod(shape[1:])),) if len(shape) > 1 else (4, 8)]
    for bad in wrong:
        with pytest.raises(InputError, match=r"trailing axes must be the operator's grid"):
            op.apply(np.ones(bad))
    with pytest.raises(InputError, match="complex"):
        op.apply(p + 1j)
