"""The conftest guard: pytest.approx's default abs = 1e-12 may not decide a comparison."""
from decimal import Decimal

import numpy as np
import pytest


@pytest.mark.parametrize("compare", [
    lambda: 1e-15 == pytest.approx(2e-15, rel=1e-9),        # a leak rate 100 % off passed
    lambda: 3e-6 == pytest.approx(3e-6, rel=1e-12),         # abs 1e-12 >> rel |x| = 3e-18
    lambda: 0.5 == pytest.approx(0.5, rel=1e-13),
    lambda: [1.0, 4e-20] == pytest.approx([1.0, 4e-20], rel=1e-6),
    lambda: np.array([1.0, 4e-20]) == pytest.approx(np.array([1.0, 4e-20])),
    lambda: np.array([4e-20, 5e-20]) == pytest.approx(4e-20),
    lambda: {"q": 4e-14} == pytest.approx({"q": 4e-14}, rel=1e-3),
    lambda: Decimal("1e-15") == pytest.approx(Decimal("1e-15")),
], ids=["leak rate", "micrometre", "unit scale", "list", "array", "array vs scalar", "dict",
        "decimal"])
def test_a_comparison_the_default_abs_would_decide_is_refused(compare):
    with pytest.raises(AssertionError, match="default abs=1e-12 swamps rel for this SI "
                                             "value; give abs explicitly"):
        compare()


def test_explicit_abs_zero_values_and_unit_scale_values_compare_as_before():
    assert not 1e-15 == pytest.approx(2e-15, rel=1e-9, abs=0)  # the error is seen
    assert 1e-15 == pytest.approx(1e-15 * (1 + 1e-10), rel=1e-9, abs=0)
    assert 1e-15 == pytest.approx(0.0, abs=1e-12 * 1e-3)      # abs scaled to the quantity
    assert 0.0 == pytest.approx(0.0)                          # expected 0: only abs can say
    assert 1.0 == pytest.approx(1.0 + 1e-7) and 1e-6 == pytest.approx(1e-6, rel=1e-6)
    assert float("inf") == pytest.approx(float("inf")) and "a" == pytest.approx("a")
    assert np.array([1.0, 2.0]) == pytest.approx([1.0, 2.0], rel=1e-9)
