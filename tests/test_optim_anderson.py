"""The generic Anderson fixed-point loop (roughfe.optim.anderson)."""
import numpy as np

from roughfe.optim.anderson import RejectedIterate, anderson_fixed_point


def _linear_map(n=40, seed=3):
    """G(x) = A x + b with spectral radius 0.95: Picard converges slowly."""
    rng = np.random.default_rng(seed)
    q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    A = q @ np.diag(np.linspace(-0.5, 0.95, n)) @ q.T
    b = rng.standard_normal(n)
    return (lambda x: A @ x + b), np.linalg.solve(np.eye(n) - A, b)


def test_anderson_reaches_the_exact_fixed_point_faster_than_picard():
    G, exact = _linear_map()
    fp = anderson_fixed_point(G, np.zeros(exact.size), tol=1e-10, max_iter=200, memory=10)
    assert fp.converged and fp.residual <= 1e-10
    # residual 1e-10 relative to |G(x)|: the error is of that order times the conditioning
    assert np.linalg.norm(fp.x - exact) <= 1e-8 * np.linalg.norm(exact)
    picard = anderson_fixed_point(G, np.zeros(exact.size), tol=1e-10, max_iter=200, memory=0)
    assert picard.status == "max_iter"            # 0.95^200 = 3.5e-5 > 1e-10
    assert fp.iterations < 100                    # Picard would need ~450 (0.95^450 = 1e-10)
    assert len(fp.residuals) == fp.iterations + 1


def test_a_refused_iterate_is_damped_before_the_loop_stops():
    G, exact = _linear_map()
    calls = []

    def refusing(x):
        calls.append(x.copy())
        if len(calls) == 3:               # an extrapolated iterate is refused once
            raise RejectedIterate()
        return G(x)

    fp = anderson_fixed_point(refusing, np.zeros(exact.size), tol=1e-10, max_iter=200)
    assert fp.converged and np.allclose(fp.x, exact, rtol=0, atol=1e-7)

    def always(x):
        if np.any(x != 0):
            raise RejectedIterate()
        return G(x)

    # the full step, then beta r / 2^j for j = 1 .. backoff (j = 0 is the full step)
    stop = anderson_fixed_point(always, np.zeros(exact.size), tol=1e-10, max_iter=200,
                                backoff=3)
    assert stop.status == "rejected" and stop.iterations == 4 and not stop.converged
    assert np.all(stop.x == 0)                    # the last accepted iterate


def test_one_refused_full_step_does_not_stop_the_loop():
    # G(x) = 1.9 - 0.9 x (fixed point 1) refuses x > 1.5: the first full step from 0 is
    # G(0) = 1.9; the plain iterate G(x_0) that the loop fell back to is the same point,
    # so it stopped "rejected" after one step. The half step 0.95 is accepted.
    def G(x):
        if np.any(x > 1.5):
            raise RejectedIterate()
        return 1.9 - 0.9 * x

    fp = anderson_fixed_point(G, np.zeros(3), tol=1e-12, max_iter=20)
    assert fp.converged and np.allclose(fp.x, 1.0, rtol=0, atol=1e-10)
    damped = anderson_fixed_point(G, np.zeros(3), tol=1e-12, max_iter=200, memory=0,
                                  relaxation=0.5)
    assert damped.converged and np.allclose(damped.x, 1.0, rtol=0, atol=1e-10)


def test_the_residual_norm_holds_at_any_scale_of_the_field():
    # G(x) = s (A x/s + b) for s = 2^+-600 is the same map in other units: the same
    # iterates times s, bit for bit (powers of two scale exactly), and the same residuals.
    # Was: the 2-norm's squares overflowed at s = 2^600 (~4e180: inf norms, a NaN residual,
    # max_iter) and underflowed at 2^-600 (a zero norm: "converged" at the first iterate)
    G, exact = _linear_map()
    ref = anderson_fixed_point(G, np.zeros(exact.size), tol=1e-10, max_iter=200, memory=10)
    for s in (2.0 ** 600, 2.0 ** -600):
        fp = anderson_fixed_point(lambda x, s=s: s * G(x / s), np.zeros(exact.size), tol=1e-10,
                                  max_iter=200, memory=10)
        assert fp.status == ref.status == "converged" and fp.iterations == ref.iterations
        assert fp.residuals == ref.residuals
        assert np.array_equal(fp.x, s * ref.x)
