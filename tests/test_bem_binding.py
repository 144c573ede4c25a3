"""The binding set of the Polonsky-Keer CG (issue 16 §1, round 2 session 10): no step
below p = 0 at points of the free set where p is 0. The rule changes the path of the
iteration, never its end: the same solution of Eq. 2.5-2.6 (the same contact and
plastic sets, pressures within the KKT tolerance scale), in fewer iterations where the
free set is still being searched. It acts with the two-level correction (``solve_contact``
from 1024^2 on), where it was measured to pay."""
import functools

import numpy as np
import pytest

from roughfe.bem import Material, pk, solve_contact
from roughfe.bem.contact import _cg_preconditioner
from roughfe.bem.deflation import BlockDeflation
from roughfe.bem.operators import influence_operator
from roughfe.bem.solvers import kkt_residual
from roughfe.surfaces.spectral import spectral_surface


def test_bind_lower_drops_the_steps_below_zero_and_keeps_the_load():
    rng = np.random.default_rng(3)
    t = rng.standard_normal(1000)
    t -= t.mean()
    positive = rng.random(1000) < 0.7
    bound = ~positive & (t > 0)             # p = 0 and p - tau t < 0 for tau > 0
    assert bound.any()

    load = t.copy()
    pk._bind_lower(load, positive, True)
    assert np.all(load[bound] == 0.0)
    assert abs(load.sum()) <= 1e-12 * np.abs(t).sum()           # the step keeps the load
    kept = ~bound                            # the others move by one common shift
    shift = load[kept] - t[kept]
    assert np.ptp(shift) <= 1e-12 and shift[0] > 0.0    # the dropped part was positive

    disp = t.copy()
    pk._bind_lower(disp, positive, False)    # displacement control: no shift
    assert np.all(disp[bound] == 0.0) and np.array_equal(disp[~bound], t[~bound])

    same = t.copy()                          # nothing binds: the direction is untouched
    pk._bind_lower(same, np.ones(1000, bool), True)
    assert np.array_equal(same, t)


def _pair(monkeypatch, n, pm):
    s = spectral_surface(n, 1.0, 0.8, rms_slope=1.0, rng=1)
    m = Material(1.0, 0.0)
    kw = dict(mean_pressure=pm, solver="pk", tol=1e-10, compute_stiffness=False)
    rule = solve_contact(s, m, **kw)
    with monkeypatch.context() as mp:
        mp.setattr(pk, "_bind_lower", lambda tF, positive, load: None)
        raw = solve_contact(s, m, **kw)
    return s, rule, raw


def test_binding_set_same_solution_fewer_iterations(monkeypatch):
    # 1024^2 (the two-level correction on), cold, p/E* = 0.1: 26 -> 25 iterations
    # (measured; the gain grows with the search: 2048^2, 4 loads, 103 against 115
    # before session 10, benchmarks/bench_bem.py); two converged solutions at KKT
    # residual 1e-10 lie within ~2e-8 of max p
    s, rule, raw = _pair(monkeypatch, 1024, 0.1)
    assert rule.success and raw.success
    assert rule.nit <= raw.nit
    assert np.array_equal(rule.contact, raw.contact)
    assert rule.area_fraction == raw.area_fraction
    scale = float(raw.pressure.max())
    assert np.abs(rule.pressure - raw.pressure).max() <= 2e-8 * scale
    assert rule.delta == pytest.approx(raw.delta, rel=1e-8)
    assert rule.pressure.mean() == pytest.approx(0.1, rel=1e-12, abs=0)


def test_binding_set_with_a_hardness_same_plastic_set(monkeypatch):
    # 256^2, p/E* = 0.05 under a cap H_p = 0.3 E* that saturates ~1 % of the points, the
    # bounded CG with the two-level correction (the rule's setting) called directly
    h = spectral_surface(256, 1.0, 0.8, rms_slope=1.0, rng=1).heights
    op = influence_operator((256, 256), (1.0, 1.0), 1.0)

    def solve():
        return pk.polonsky_keer(op.apply, h, float(np.ptp(h)), diagonal=op.diagonal,
                                precond=_cg_preconditioner(op), tol=1e-10,
                                offset=-float(h.max()), mean_pressure=0.05, hardness=0.3,
                                apply_single=functools.partial(op.apply, single=True),
                                deflation=BlockDeflation(op, 8))

    rule = solve()
    with monkeypatch.context() as mp:
        mp.setattr(pk, "_bind_lower", lambda tF, positive, load: None)
        raw = solve()
    p, q = rule.pressure, raw.pressure
    assert np.array_equal(p > 0, q > 0)
    assert np.array_equal(p >= 0.3, q >= 0.3)
    assert (p >= 0.3).mean() > 1e-3
    assert np.abs(p - q).max() <= 2e-8 * 0.3
    assert 0.0 <= p.min() and p.max() <= 0.3
    assert p.mean() == pytest.approx(0.05, rel=1e-12, abs=0)
    gap = op.apply(p) - (h - h.max()) - rule.delta
    assert kkt_residual(p, gap, float(np.ptp(h)), upper=0.3) <= 1e-10
