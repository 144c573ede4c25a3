"""The (1+1) evolution strategy (roughfe.optim.es) on analytic staircase problems: it
reaches the top plateau of a piecewise-constant objective a gradient cannot see into,
is deterministic for a seed, and a tuple value breaks ties lexicographically."""
import numpy as np
import pytest

from roughfe.errors import InputError
from roughfe.optim import one_plus_one_es

CENTRE = np.array([0.2, 0.7, 0.45, 0.9, 0.35])


def staircase(u):
    """-(number of 0.05-wide steps between u and CENTRE, summed): 0 only on the top plateau."""
    return -float(np.sum(np.floor(np.abs(u - CENTRE) / 0.05)))


def test_reaches_the_top_plateau_of_a_staircase():
    r = one_plus_one_es(staircase, np.full(5, 0.5), 800, rng=3)
    assert r.fun0 == staircase(np.full(5, 0.5)) < -10
    assert r.fun == 0.0 and np.all(np.abs(r.x - CENTRE) < 0.05)
    assert r.nfev == 800 and r.n_improved >= 5
    again = one_plus_one_es(staircase, np.full(5, 0.5), 800, rng=3)
    np.testing.assert_array_equal(again.x, r.x)                        # deterministic


def test_ties_move_on_a_plateau_and_a_second_value_breaks_them():
    flat = one_plus_one_es(lambda u: 0.0, np.full(3, 0.5), 50, rng=0)
    assert flat.fun == 0.0 and not np.allclose(flat.x, 0.5) and flat.n_improved == 0

    def lex(u):                    # the staircase first, the distance to CENTRE second
        return staircase(u), -float(np.linalg.norm(u - CENTRE))
    r = one_plus_one_es(lex, np.full(5, 0.5), 800, rng=3)
    assert r.fun[0] == 0.0 and -r.fun[1] < 0.02        # well inside the top step


def test_bad_input_is_refused():
    for kw in ({"n_eval": 0}, {"n_eval": 5, "sigma": 0.0}):
        with pytest.raises(InputError, match="n_eval"):
            one_plus_one_es(staircase, np.full(5, 0.5), **kw)


def test_a_nan_start_counts_as_the_worst():
    """A NaN start value froze the run (every comparison with NaN is false): it returned
    the start. Non-finite values, alone or in a tuple, now count as -inf; the run says it
    stopped at its budget (there is no convergence test)."""
    start = np.full(5, 0.5)

    def nan_at_start(u):
        return np.nan if np.all(u == start) else staircase(u)
    r = one_plus_one_es(nan_at_start, start, 800, rng=3)
    assert r.fun0 == -np.inf and r.fun == 0.0 and not np.allclose(r.x, start)
    lex = one_plus_one_es(lambda u: (nan_at_start(u), 0.0), start, 200, rng=3)
    assert lex.fun0 == (-np.inf, 0.0) and lex.fun[0] > -np.inf
    assert "stopped at the budget of 800 evaluations" in r.message
