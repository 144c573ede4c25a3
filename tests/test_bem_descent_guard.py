"""The safeguards of the two-level Polonsky-Keer CG. The descent guard (round 2, session
12): a coarse correction that leaves the direction without descent (g . z2 <=
DESCENT_GUARD g . M g) is dropped for that iteration, so that an inexact coarse operator
can slow a solve but not stall it (measured: a band-limited surface resampled to 8192^2
froze at a KKT residual of 9.7e-6 without it; ``docs/theory/02b_bem_performance.md``).
The stall watch (session 13): a correction that keeps the descent but makes no progress
is dropped for the rest of the solve after STALL_WINDOW iterations without halving the
residual."""
import numpy as np
import pytest

from roughfe.bem import directions, pk
from roughfe.bem.contact import _cg_preconditioner
from roughfe.bem.operators import influence_operator
from roughfe.bem.solvers import kkt_residual
from roughfe.errors import NoConvergenceError
from roughfe.surfaces.spectral import spectral_surface


def test_guard_keeps_a_descent_direction_and_drops_the_others():
    rng = np.random.default_rng(5)
    g = rng.standard_normal(500)
    z = g + 0.1 * rng.standard_normal(500)            # g . z > 0: the plain direction
    # (with the gradient's dot product with the direction returned, the CG's g . z)
    out, gz = pk._descent_guard(g, z, z)
    assert out is z and gz == float(np.dot(g, z))     # skipped correction: z itself
    good = 0.5 * z + 0.05 * rng.standard_normal(500)  # keeps ~half of the descent
    out, gz = pk._descent_guard(g, z, good)
    assert out is good and gz == float(np.dot(g, good))
    for bad in (-z, 0.02 * z, np.zeros(500)):         # ascent, too little, none
        out, gz = pk._descent_guard(g, z, bad)
        assert out is z and gz == float(np.dot(g, z))


class _Adversary:
    """A 'coarse correction' that turns the direction uphill at every iteration."""

    def __init__(self):
        self.calls = 0

    def correct(self, F, gF, zF, apply_free, free_mask=None, pressure=None):
        self.calls += 1
        return -zF


def _solve(h, op, deflation, max_iter=400):
    return pk.polonsky_keer(op.apply, h, float(np.ptp(h)), diagonal=op.diagonal,
                            precond=_cg_preconditioner(op), tol=1e-10,
                            offset=-float(h.max()), mean_pressure=0.05,
                            max_iter=max_iter, deflation=deflation)


def test_an_uphill_correction_cannot_stall_the_solve(monkeypatch):
    # 128^2, p/E* = 0.05: with the guard the adversarial correction is dropped at every
    # iteration and the solve is the plain preconditioned one (same contact set and
    # pressures within the KKT tolerance scale); without it the stall watch drops the
    # correction after its window, and without both the same solve does not converge
    h = spectral_surface(128, 1.0, 0.8, rms_slope=1.0, rng=2).heights
    op = influence_operator((128, 128), (1.0, 1.0), 1.0)
    bad = _Adversary()
    guarded = _solve(h, op, bad)
    plain = _solve(h, op, None)
    assert bad.calls >= guarded.nit - 3      # every iteration but the confirmations
    p, q = guarded.pressure, plain.pressure
    assert np.array_equal(p > 0, q > 0)
    assert np.abs(p - q).max() <= 2e-8 * q.max()
    assert p.mean() == pytest.approx(0.05, rel=1e-12, abs=0)
    gap = op.apply(p) - (h - h.max()) - guarded.delta
    assert kkt_residual(p, gap, float(np.ptp(h))) <= 1e-10

    monkeypatch.setattr(directions, "DESCENT_GUARD", -np.inf)   # the guard off:
    with pytest.warns(RuntimeWarning, match="made no progress"):  # the stall watch
        late = _solve(h, op, _Adversary())                         # catches it, later
    assert late.nit > guarded.nit and np.array_equal(late.pressure > 0, q > 0)
    monkeypatch.setattr(directions, "STALL_WINDOW", 10 ** 9)    # and without both
    with pytest.raises(NoConvergenceError):
        _solve(h, op, _Adversary(), max_iter=200)


class _Useless:
    """A 'coarse correction' that keeps the plain direction's descent exactly (so the
    guard lets it through) but buries it under a large random part orthogonal to the
    gradient: the exact line search then takes steps ~1e-3 of the plain ones."""

    def __init__(self):
        self.rng, self.calls = np.random.default_rng(0), 0

    def correct(self, F, gF, zF, apply_free, free_mask=None, pressure=None):
        self.calls += 1
        v = self.rng.standard_normal(zF.size)
        v -= v.mean()                                  # gF has zero mean: so keeps v
        v -= (np.dot(gF, v) / np.dot(gF, gF)) * gF     # g . v = 0: g . z2 = g . zF
        return zF + 1e3 * np.linalg.norm(zF) / np.linalg.norm(v) * v


def test_a_correction_without_progress_is_dropped(monkeypatch):
    h = spectral_surface(128, 1.0, 0.8, rms_slope=1.0, rng=2).heights
    op = influence_operator((128, 128), (1.0, 1.0), 1.0)
    useless = _Useless()
    with pytest.warns(RuntimeWarning, match="dropped at iteration"):
        out = _solve(h, op, useless)
    plain = _solve(h, op, None)
    # the watch fired after its window (the correction was called every iteration up
    # to then, never after) and the plain CG finished the solve
    assert useless.calls >= directions.STALL_WINDOW
    assert out.nit <= useless.calls + 2 * plain.nit
    p, q = out.pressure, plain.pressure
    assert np.array_equal(p > 0, q > 0)
    assert np.abs(p - q).max() <= 2e-8 * q.max()
    gap = op.apply(p) - (h - h.max()) - out.delta
    assert kkt_residual(p, gap, float(np.ptp(h))) <= 1e-10

    monkeypatch.setattr(directions, "STALL_WINDOW", 10 ** 9)     # the watch off
    with pytest.raises(NoConvergenceError):
        _solve(h, op, _Useless(), max_iter=200)


def test_stall_watch_counts_iterations_without_halving():
    # window 3: stalled when none of the last 3 residuals is at most half the one before
    w = directions._StallWatch(3)
    assert [w.stalled(r) for r in (1.0, 0.9, 0.8, 0.5)] == [False] * 4   # 0.5 halves 1.0
    assert w.stalled(0.46)          # 0.9 -> 0.8, 0.5, 0.46: not halved in 3
    w = directions._StallWatch(5)   # a rise after a good start, back below half of it
    assert not any(w.stalled(r) for r in (1e-6, 1e-4, 4e-5, 1e-5, 2e-6, 4e-7, 1e-7))
    w = directions._StallWatch(5)   # the same rise, not back within the window
    assert [w.stalled(r) for r in (1e-6, 1e-4, 4e-5, 1e-5, 2e-6, 6e-7)][-1]
