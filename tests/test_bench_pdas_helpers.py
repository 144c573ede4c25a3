"""The helpers of the research script benchmarks/pdas_eisenstat_walker.py (session 40):
its restart after a set change (benchmarks/_pdas_restart.py) and its per-step trace
against the converged set (benchmarks/_pdas_trace.py)."""

import numpy as np
import pytest


class _Fine:
    """A symmetric positive smoothing operator on a periodic 16 x 16 grid (H x = K * x,
    K the FFT of a positive kernel), its products counted as the script's Fine does."""

    def __init__(self, n=16):
        q = np.fft.fftfreq(n)
        self.k = 1.0 / (1.0 + 40.0 * (q[:, None] ** 2 + q[None, :] ** 2))
        self.shape = (n, n)
        self.products = 0

    def H(self, x):
        self.products += 1
        return np.fft.ifft2(self.k * np.fft.fft2(x.reshape(self.shape))).real.reshape(-1)


@pytest.mark.parametrize("how", ["scale", "shift"])
def test_restart_keeps_the_load_zero_off_the_new_set_and_u_equal_to_H_p(how, bench_script):
    restart = bench_script("_pdas_restart").restart
    fine = _Fine()
    rng = np.random.default_rng(4)
    mask = rng.random(256) < 0.5
    new = mask & (rng.random(256) < 0.8)           # some points leave, one enters
    new[np.flatnonzero(~mask)[0]] = True
    p = np.where(mask, rng.normal(1.0, 0.8, 256), 0.0)    # some p < 0 on I
    target = 0.3 * 256
    p *= target / p.sum()
    u = fine.H(p)
    restart(fine, p, u, mask, new, target, how)
    assert p.sum() == pytest.approx(target, rel=1e-12)
    assert not p[~new].any()
    np.testing.assert_allclose(u, fine.H(p), atol=1e-12)


def test_shift_adds_one_constant_on_the_new_set_where_scale_multiplies(bench_script):
    restart = bench_script("_pdas_restart").restart
    fine = _Fine()
    mask = np.zeros(256, bool)
    mask[:100] = True
    new = mask.copy()
    new[:10] = False
    p = np.where(mask, 1.0, 0.0)
    p[:10] = -0.5                                   # the leaving points were tensile
    p[50] = 2.0
    target = float(p.sum())                         # 91 - 5 = 86
    runs = {}
    for how in ("scale", "shift"):
        q = p.copy()
        restart(fine, q, fine.H(q), mask, new, target, how)
        runs[how] = q
    # without the tensile points the 90 points carry 91 instead of 86: shift takes 5/90
    # off each, scale multiplies each by 86/91 (the point of 2 loses twice as much)
    np.testing.assert_allclose(runs["shift"][10:100], p[10:100] - 5.0 / 90.0)
    np.testing.assert_allclose(runs["scale"][10:100], p[10:100] * 86.0 / 91.0)


def test_trace_splits_the_changes_by_the_edge_of_the_final_set_and_new_tiny_patches(bench_script):
    tr = bench_script("_pdas_trace")
    shape = (16, 16)
    A = np.zeros(shape, bool)
    A[4:10, 4:10] = True                            # one 6 x 6 patch ...
    A[13, 13] = True                                # ... and a one-point patch
    I1 = np.zeros(shape, bool)
    I1[3:11, 3:11] = True                           # a ring of extras, the spot missed
    I2 = A.copy()
    I2[0, 0] = True                                 # a wrong entry far out
    trace = tr.Trace(shape)
    terms = {"comp": 1e-3, "feas": 2e-3, "neg": 0.0}
    for k, I in enumerate((I1, I2, A)):
        row = {"inner": 3, "eta": 0.03, "residual": 1e-3, "changed": 0}
        trace.step(I.reshape(-1), row, terms, bad=k, tighten=False)
    out = trace.finish(A.reshape(-1))
    s = out["summary"]
    assert (s["A"], s["patches"], s["tiny_new_patches"], s["tiny_new_points"]) == (37, 2, 1, 1)
    st1, st2 = out["steps"][0], out["steps"][1]
    assert (st1["err"], st1["miss"], st1["extra"]) == (29, 1, 28)
    assert (st1["leave"], st1["leave_ok"], st1["enter"], st1["enter_ok"]) == (28, 28, 2, 1)
    # the ring's sides and the spot lie 1 pixel (4-neighbour) from A's edge, the ring's
    # 4 corners 2 pixels; (0, 0) is 4+ pixels out
    assert (st1["edge"], st1["near"], st1["in"], st1["out"]) == (25, 4, 0, 1)
    assert (st1["tiny"], st1["tiny_missing"]) == (1, 1)
    assert (st2["err"], st2["leave"], st2["leave_ok"], st2["out"]) == (1, 1, 1, 1)
    assert st1["dominant"] == "feas" and out["steps"][2]["err"] == 0
    assert any("enter(ok)" in line for line in tr.lines(out))
