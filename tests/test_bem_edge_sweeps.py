"""The load-conserving window sweeps of the contact edges inside the PK solve
(:mod:`roughfe.bem.edge_sweeps`, issue 16 section 1): each window keeps its load, the
step along a sweep lowers the energy, and a solve with the sweeps has the answer of the
solve without them."""
import numpy as np
import pytest

import roughfe.bem.contact as bem_contact
import roughfe.bem.edge_sweeps as es
from roughfe.bem import Material, solve_contact
from roughfe.bem.contact import _operator
from roughfe.surfaces.spectral import spectral_surface

pytest.importorskip("numba", reason="the window kernel is compiled by numba")


def _state(n=64, seed=1, fill=0.3):
    """A rough surface, a positive pressure on a random ~``fill`` of the grid and its
    displacement u = H p (periodic operator)."""
    s = spectral_surface(n, 1.0, 0.5, rms_slope=1.0, rng=seed)
    op = _operator(s.shape, s.size, 1.0, "spectral")
    rng = np.random.default_rng(seed)
    p = np.where(rng.random(s.shape) < fill, rng.random(s.shape), 0.0).ravel()
    u = op.apply(p.reshape(s.shape)).ravel()
    return s, op, p, u


def _energy(op, p, h):
    return 0.5 * float(np.dot(p, op.apply(p.reshape(op.fft_shape)).ravel())) - float(
        np.dot(p, h))


def test_a_sweep_keeps_each_window_load_and_lowers_the_energy():
    s, op, p, u = _state()
    h = s.heights.ravel()
    sweeps = es.EdgeSweeps(s.shape, es._kernel())
    e = np.zeros(p.size)
    e[0] = 1.0
    sweeps.set_block(op.apply(e.reshape(s.shape)).ravel())
    dp = np.empty(p.size)
    slope = sweeps.changes(p, u, h, dp)
    assert slope is not None and slope < 0              # a descent direction
    # zero-sum in every 4 x 4 window of the (unshifted) tiling, and p + dp >= 0
    windows = dp.reshape(16, 4, 16, 4).sum(axis=(1, 3))
    assert np.abs(windows).max() <= 1e-12 * np.abs(p).max()
    assert (p + dp).min() >= -1e-12 and np.count_nonzero(dp) > 0
    assert slope == pytest.approx(float(np.dot(dp, u - h)), rel=1e-9, abs=0)
    hd = op.apply(dp.reshape(s.shape)).ravel()
    step = min(1.0, -slope / float(np.dot(dp, hd)))
    assert 0 < step <= 1
    q = p + step * dp
    assert q.sum() == pytest.approx(p.sum(), rel=1e-12, abs=0) and q.min() >= -1e-12
    assert _energy(op, q, h) < _energy(op, p, h)
    sweeps.made()
    assert sweeps.count == 1 and sweeps._offset() == 2       # the shifted tiling next


def test_solves_with_and_without_sweeps_agree(monkeypatch):
    """At 256^2 with the two-level correction on (as the sweeps are from 1024^2 on by
    default): the same contact set and pressures to the solver's tolerance, and the
    sweeps were made (counted as iterations)."""
    s = spectral_surface(256, 1.0, 0.5, rms_slope=1.0, rng=2)
    made = []

    def spy(*args, **kwargs):
        made.append(es.edge_sweeps_for(*args, **kwargs))
        return made[-1]

    monkeypatch.setattr(bem_contact, "edge_sweeps_for", spy)
    out = {}
    for side in (10 ** 9, 64):
        monkeypatch.setattr(es, "MIN_SIDE", side)
        out[side] = solve_contact(s, Material(1.0, 0.0), mean_pressure=0.02, solver="pk",
                                  tol=1e-10, compute_stiffness=False, coarse_correction=True)
    assert made[0] is None and made[-1] is not None and made[-1].count >= es.START_SWEEPS
    a, b = out[10 ** 9], out[64]
    assert np.array_equal(a.pressure > 0, b.pressure > 0)
    assert np.abs(a.pressure - b.pressure).max() <= 1e-6 * a.pressure.max()
    assert b.mean_pressure == pytest.approx(0.02, rel=1e-12, abs=0)


def test_no_sweeps_where_they_do_not_apply(monkeypatch):
    """Displacement control, a hardness, a coarse tolerance, no two-level correction, a
    side not divisible by the window, or no numba: no sweeps (the plain solve)."""
    op = _operator((1024, 1024), (1.0, 1.0), 1.0, "spectral")
    kw = dict(load=True, hardness=None, tol=1e-10)
    assert es.edge_sweeps_for(op, object(), **kw) is not None
    assert es.edge_sweeps_for(op, None, **kw) is None
    assert es.edge_sweeps_for(op, object(), **dict(kw, load=False)) is None
    assert es.edge_sweeps_for(op, object(), **dict(kw, hardness=0.1)) is None
    assert es.edge_sweeps_for(op, object(), **dict(kw, tol=1e-4)) is None
    odd = _operator((1026, 1026), (1.0, 1.0), 1.0, "spectral")
    assert es.edge_sweeps_for(odd, object(), **kw) is None
    monkeypatch.setattr(es, "_kernel", lambda: None)
    assert es.edge_sweeps_for(op, object(), **kw) is None
