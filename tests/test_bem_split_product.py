"""The product H t of the Polonsky-Keer line search in two halves (issue 16 §1, round 2
session 11): the energy t . H t from the forward transform (Parseval), H t itself only
when the step is kept. The split changes no physics: the energy is the one of the full
product, the completed product is the product, and the solver reaches the same solution
of Eq. 2.5-2.6 in the same iterations."""
import numpy as np
import pytest

from roughfe.bem import Material, contact, solve_contact
from roughfe.bem.operators import FFTWorkspace, influence_operator
from roughfe.errors import InputError
from roughfe.surfaces.spectral import spectral_surface


@pytest.mark.parametrize("kernel", ["spectral", "love"])
@pytest.mark.parametrize("shape", [(64, 64), (63, 50), (32, 17)])
def test_energy_is_parseval_and_finish_is_the_product(shape, kernel):
    # even and odd last axes (the Nyquist column of the half-spectrum counts once);
    # periodic, and on the zero-padded grid of the non-periodic kernel (session 16)
    op = influence_operator(shape, (1.0, 1.3), 2.0, kernel)
    x = np.random.default_rng(0).standard_normal(shape)
    ref = op.apply(x)
    work = FFTWorkspace()                         # one workspace for every product
    for single, rtol in ((False, 1e-13), (True, 1e-6), (False, 1e-13)):
        out = np.empty(shape, np.float32 if single else np.float64)
        energy, finish = op.split_product(x, single=single, out=out, work=work)
        assert energy == pytest.approx(float(np.sum(x * ref)), rel=rtol)
        assert energy > 0.0                       # H is positive semi-definite
        u = finish()
        assert u is out
        assert np.abs(u - ref).max() <= 10 * rtol * np.abs(ref).max()
        # the in-place product through the same workspace is the product
        np.testing.assert_allclose(op.apply(x, work=work), ref, rtol=0,
                                   atol=1e-13 * np.abs(ref).max())


def test_padded_products_through_one_workspace_are_the_allocating_ones():
    # a non-periodic operator's products and preconditioner, float64 and float32,
    # interleaved through one workspace (its padded grids stay zero off the corner)
    op = influence_operator((40, 33), (1.0, 0.8), 1.0, "love")
    rng = np.random.default_rng(4)
    work = FFTWorkspace()
    m32 = op.inverse_spectrum().astype(np.float32)
    for _ in range(3):
        x = rng.standard_normal(op.shape)
        for single in (False, True):
            out = np.empty(op.shape, np.float32 if single else np.float64)
            got = op.apply(x, single=single, out=out, work=work)
            assert got is out
            ref = op.apply(x, single=single)
            assert np.abs(got - ref).max() <= (1e-6 if single else 1e-14) * np.abs(ref).max()
        z = op.precondition(x, m32, work=work)
        np.testing.assert_allclose(z, op.precondition(x, m32), rtol=0,
                                   atol=1e-6 * np.abs(z).max())


def test_split_product_needs_a_workspace():
    op = influence_operator((16, 16), (1.0, 1.0), 1.0)
    with pytest.raises(InputError, match="FFTWorkspace"):
        op.split_product(np.ones((16, 16)))


def test_solve_with_the_split_line_search_same_solution(monkeypatch):
    # 1024^2, p/E* = 0.05, cold (the two-level correction on, and with it the split):
    # the same iterations and contact set as the full product, pressures within the
    # KKT tolerance's scale (measured 8e-9 of max p, 4 loads)
    s = spectral_surface(1024, 1.0, 0.8, rms_slope=1.0, rng=1)
    m = Material(1.0, 0.0)
    kw = dict(mean_pressure=0.05, solver="pk", tol=1e-10, compute_stiffness=False)
    split = solve_contact(s, m, **kw)
    calls = []
    real = contact.polonsky_keer

    def without_split(*args, **kwargs):
        calls.append(kwargs.get("split"))
        kwargs["split"] = None
        return real(*args, **kwargs)

    monkeypatch.setattr(contact, "polonsky_keer", without_split)
    full = solve_contact(s, m, **kw)
    assert calls[-1] is not None          # the fine solve did take the split
    assert split.nit == full.nit
    assert np.array_equal(split.pressure > 0, full.pressure > 0)
    assert np.abs(split.pressure - full.pressure).max() <= 1e-7 * full.pressure.max()
