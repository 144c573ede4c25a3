"""The lag search of the trace/retrace coherence (roughfe.surfaces.reliability._best_lag):
its FFT cross-correlation and cumulative overlap sums give, for every lag at once, the
lag and the correlation coefficient that a loop over the lags gives (written here as the
reference, as the function was until round 2, session 37), on random and on shifted
maps, at the ends of the range (+-max_lag) and on short lines; constant sides give 0."""
import numpy as np
import pytest

from roughfe.surfaces.reliability import _best_lag


def _loop(a, b, max_lag):
    """Brute force: the correlation coefficient of a[i, j] and b[i + L, j] over their
    overlap (all lines together) for each L in -max_lag .. max_lag; 0 where a side is
    constant. Returns (lags, r)."""
    n = a.shape[0]
    lags = np.arange(-max_lag, max_lag + 1)
    r = np.zeros(lags.size)
    for k, lag in enumerate(lags):
        u = a[max(0, -lag): n - max(0, lag)]
        v = b[max(0, lag): n - max(0, -lag)]
        u, v = u - u.mean(), v - v.mean()
        norm = np.sqrt(np.sum(u * u) * np.sum(v * v))
        r[k] = np.sum(u * v) / norm if norm > 0 else 0.0
    return lags, r


def _check(a, b, max_lag, expected_lag=None):
    lags, r = _loop(a, b, max_lag)
    lag, corr = _best_lag(a, b, max_lag)
    k = int(np.argmax(r))                           # the loop kept the first maximum
    assert lag == lags[k] and abs(corr - r[k]) < 1e-12, (lag, lags[k], corr, r[k])
    if expected_lag is not None:
        assert lag == expected_lag
    return lag, corr


def _shifted(n, lines, lag, rng, noise=0.3, offset=0.0):
    """b[i + lag] = a[i] (+ noise) on lines of n points: a random walk along each line."""
    walk = np.cumsum(rng.standard_normal((n + abs(lag), lines)), axis=0) + offset
    a = walk[max(0, lag): max(0, lag) + n]
    b = walk[max(0, -lag): max(0, -lag) + n]
    return (a + noise * rng.standard_normal(a.shape),
            b + noise * rng.standard_normal(b.shape))


@pytest.mark.parametrize("n, lines, max_lag", [(256, 40, 32), (97, 13, 12), (16, 5, 15),
                                               (17, 1, 8), (64, 3, 0)])
def test_random_maps_give_the_loops_lag_and_correlation(n, lines, max_lag):
    rng = np.random.default_rng(n + lines)
    for offset in (0.0, 1e3):                       # a mean far from zero changes nothing
        a = rng.standard_normal((n, lines)) + offset
        b = rng.standard_normal((n, lines)) - offset
        _check(a, b, max_lag)


@pytest.mark.parametrize("n, lines, max_lag, lag", [
    (256, 40, 32, 7), (256, 40, 32, -5), (256, 40, 32, 32), (256, 40, 32, -32),
    (20, 8, 4, 4), (20, 8, 4, -4), (16, 3, 15, 15), (16, 3, 15, -15), (128, 10, 16, 0)])
def test_a_shifted_map_is_found_at_its_lag_also_at_the_ends_of_the_range(n, lines, max_lag,
                                                                        lag):
    rng = np.random.default_rng(abs(lag) + n)
    a, b = _shifted(n, lines, lag, rng, noise=0.0 if n == 16 else 0.3, offset=50.0)
    _, corr = _check(a, b, max_lag, expected_lag=lag)
    assert corr > 0.9


def test_constant_sides_give_zero_correlation_and_the_first_lag():
    """The loop's r = 0 where the overlap of a side is constant: every lag ties at 0 and
    the first, -max_lag, is kept."""
    a = np.zeros((32, 4))
    b = np.random.default_rng(0).standard_normal((32, 4))
    assert _best_lag(a, b, 5) == (-5, 0.0) == _check(a, b, 5)
    for low in (0.0, 0.1):               # 0.1: the sums' rounding leaves a variance
        step = np.full((32, 4), low)
        step[:4] = 1.3                   # constant over the overlaps of the lags <= -12
        step[10:12] = 0.7
        lags, r = _loop(step, b, 20)
        assert np.all(np.abs(r[lags <= -12]) < 1e-15)
        _check(step, b, 20)
        _check(step, b[:, :1] * np.ones((1, 4)), 20)
    # a step against its negative: r < 0 wherever both sides vary, and both are constant
    # over the overlaps of |L| >= 4, where the sums' rounding left a variance of 7e-15
    # of the sum of squares (r = 2.3e-9 at L = 6 without reading it as constant)
    step = np.full((32, 4), 0.7)
    step[:4] = 1.3
    lags, r = _loop(step, -step, 6)
    assert np.all(r[np.abs(lags) <= 3] < -0.4) and np.all((np.abs(r) < 1e-15) | (r < -0.4))
    assert _best_lag(step, -step, 6) == (-6, 0.0)


def test_the_lag_search_has_no_python_loop():
    """Every lag at once (an FFT and cumulative sums): no for/while/comprehension in the
    function, which looped over the 2 max_lag + 1 lags with full-array passes until round
    2, session 37 (4096^2: 311 s CPU; docs/theory/01_surfaces.md)."""
    import ast
    import inspect
    import textwrap
    tree = ast.parse(textwrap.dedent(inspect.getsource(_best_lag)))
    loops = (ast.For, ast.While, ast.ListComp, ast.GeneratorExp, ast.SetComp, ast.DictComp)
    assert not [type(node).__name__ for node in ast.walk(tree) if isinstance(node, loops)]
