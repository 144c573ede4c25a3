"""Mixed precision in the Polonsky-Keer CG (issue 16 §1): float32 products almost
everywhere, the float64 solution of Eq. 2.5-2.6 at the end (same contact set, pressures
within the tolerance scale, the residual of a double-precision u = H p)."""
import functools

import numpy as np
import pytest

from roughfe.bem.contact import _cg_preconditioner
from roughfe.bem.operators import influence_operator
from roughfe.bem.pk import _axpy, polonsky_keer
from roughfe.bem.solvers import kkt_residual
from roughfe.surfaces.spectral import spectral_surface


def _counted(fn, calls, key):
    def wrapped(*args, **kw):
        calls[key] += 1
        return fn(*args, **kw)
    return wrapped


def _solve(n, mixed, **target):
    h = spectral_surface(n, 1.0, 0.8, rms_slope=1.0, rng=1).heights
    op = influence_operator((n, n), (1.0, 1.0), 1.0)
    calls = {"f64": 0, "f32": 0}
    single = (_counted(functools.partial(op.apply, single=True), calls, "f32")
              if mixed else None)
    out = polonsky_keer(_counted(op.apply, calls, "f64"), h, float(np.ptp(h)),
                        diagonal=op.diagonal, precond=_cg_preconditioner(op), tol=1e-10,
                        offset=-float(h.max()), apply_single=single, **target)
    return out, calls, h, op


@pytest.mark.parametrize("hardness", [None, 0.3])
def test_mixed_precision_gives_the_double_precision_solution(hardness):
    # 256^2, cold, p/E* = 0.05 (elastic and with a cap that saturates ~1 % of the
    # points): the CG with float32 products (u in float32 above a residual of 1e-5, then
    # a float64 u updated by float32 products of the direction and of the pressure's
    # increments) ends on the solution of the all-float64 CG: the same contact (and
    # plastic) set, pressures within 1e-8 of max p, Delta to 1e-8; its residual is that
    # of a freshly computed float64 u = H p
    ref, ref_calls, h, op = _solve(256, False, mean_pressure=0.05, hardness=hardness)
    mix, calls, _, _ = _solve(256, True, mean_pressure=0.05, hardness=hardness)
    assert ref_calls["f32"] == 0 and ref_calls["f64"] >= ref.nit
    # float64 products only to start the double-precision phase, to refresh u every
    # 50 iterations and to confirm the converged state
    assert calls["f64"] <= 2 + mix.nit // 50 + 2
    assert calls["f32"] >= mix.nit
    assert abs(mix.nit - ref.nit) <= 3
    scale = float(ref.pressure.max())
    assert np.abs(mix.pressure - ref.pressure).max() <= 1e-8 * scale
    assert np.array_equal(mix.pressure > 0, ref.pressure > 0)
    if hardness is not None:
        assert np.array_equal(mix.pressure >= hardness, ref.pressure >= hardness)
        assert (ref.pressure >= hardness).mean() > 1e-3
    assert mix.delta == pytest.approx(ref.delta, rel=1e-8)
    u = op.apply(mix.pressure)
    assert np.array_equal(u, mix.displacement)      # the returned u is H p in float64
    gap = u - (h - h.max()) - mix.delta
    assert kkt_residual(mix.pressure, gap, float(np.ptp(h)),
                        upper=np.inf if hardness is None else hardness) <= 1e-10


def test_axpy_adds_a_float32_increment_to_a_float64_field():
    # the cast in chunks covers every element (a size that is not a multiple of the
    # chunk) and equals the float64 axpy of the same float32 values
    rng = np.random.default_rng(3)
    n = (1 << 17) + 12345
    u = rng.standard_normal(n)
    r = rng.standard_normal(n).astype(np.float32)
    want = u + (-0.37) * r.astype(np.float64)
    _axpy(u, -0.37, r)
    assert np.array_equal(u, want)
    v = rng.standard_normal(n)
    r64 = rng.standard_normal(n)
    want = v + 2.5 * r64
    _axpy(v, 2.5, r64)
    assert np.allclose(v, want, rtol=0, atol=1e-15)
