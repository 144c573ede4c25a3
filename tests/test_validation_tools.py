"""roughfe.validation: Richardson extrapolation and the target rows of validation/output."""
import dataclasses
import json

import numpy as np
import pytest

from roughfe.errors import InputError
from roughfe.validation import (Target, judge_claim, judge_richardson, observed_orders,
                                richardson, within)


@pytest.mark.parametrize("order", [1.0, 1.5, 2.0])
def test_richardson_recovers_limit_and_order_of_an_exact_power_law(order):
    h = 2.0 ** -np.arange(4)
    q = 3.0 + 0.7 * h ** order
    r = richardson(q)
    assert r.asymptotic
    assert r.order == pytest.approx(order, rel=1e-12)
    assert r.limit == pytest.approx(3.0, rel=1e-13, abs=0)
    assert np.allclose(r.orders, order, rtol=1e-12)
    # the estimated error of every level bounds (and here equals) its true error
    true = np.abs(q - 3.0)
    assert np.all(np.array(r.errors) >= true - 1e-14)
    assert np.allclose(np.array(r.errors) - r.uncertainty, true, rtol=1e-10, atol=1e-15)


def test_richardson_uncertainty_has_the_calibrated_floor():
    """Session 43's calibration: 1.25x the larger of the last two differences is the
    floor of the uncertainty in both branches (the quarter step alone covered the known
    limit of 25-30 % of the asymptotic BEM sequences)."""
    q = [0.183926, 0.1996, 0.2030, 0.2040]          # asymptotic, order ~1.8
    r = richardson(q)
    assert r.asymptotic
    floor = 1.25 * max(abs(q[-1] - q[-2]), abs(q[-2] - q[-3]))
    assert r.uncertainty == pytest.approx(floor, rel=1e-12, abs=0)
    assert r.uncertainty > 0.25 * abs(q[-1] - r.limit)
    assert "at least 1.25 x the larger of the last two" in r.method


def test_richardson_with_a_higher_order_term_bounds_the_true_error():
    """Q_h = Q + h + c h^2 with the h^2 term up to 1/8 of the h term at the finest level:
    the order is observed between 1 and 1.25, the limit is 6x closer to Q than the
    finest value, and every level's estimated error bounds its true error. (With c = 2
    the observed order is 1.35 and the estimate falls short by 0.08 % of Q: the safety
    factor 1.25 is a heuristic, not a bound.)"""
    h = 2.0 ** -np.arange(1, 5)
    for c in (0.5, 1.0):
        q = 1.0 + h + c * h ** 2
        r = richardson(q)
        assert r.asymptotic and 1.0 < r.order < 1.25
        assert abs(r.limit - 1.0) < abs(q[-1] - 1.0) / 6
        assert np.all(np.array(r.errors) >= np.abs(q - 1.0))


def test_richardson_falls_back_when_the_sequence_oscillates():
    q = [1.0, 1.2, 1.05, 1.1]                       # differences change sign
    r = richardson(q)
    assert not r.asymptotic and np.isnan(r.order)
    assert r.limit == 1.1
    # 1.25x the larger of the last two differences (0.15, 0.05; session 43's calibration)
    assert r.uncertainty == pytest.approx(1.25 * 0.15)
    assert "not in the asymptotic range" in r.method
    assert np.isnan(observed_orders(q)[-1])
    json.dumps(r.to_dict())                          # JSON-safe (NaN -> null)


def test_richardson_rejects_short_or_non_finite_input():
    with pytest.raises(InputError, match=">= 3 finite values"):
        richardson([1.0, 2.0])
    with pytest.raises(InputError, match=">= 3 finite values"):
        richardson([1.0, np.nan, 2.0])
    with pytest.raises(InputError, match="ratio must be > 1"):
        richardson([1.0, 2.0, 3.0], ratio=1.0)


def test_target_rows_follow_the_schema():
    t = within("x vs y", -0.004, 0.01, "why")
    assert t.met and t.measured == "-0.400 %" and t.target == "<= 1 %"
    row = t.to_dict()
    assert set(row) == {"name", "target", "measured", "met", "reason", "value"}
    assert not within("x", np.nan, 0.01).met
    # a limit and a value below 1e-4 keep their digits (a 1e-8 limit read "<= 0 %", beside
    # a measured "0.000 %" of 1.8e-12: a verdict the row itself could not show)
    tiny = within("dense vs PCG", 1.82e-12, 1e-8)
    assert tiny.met and tiny.target == "<= 1e-08" and tiny.measured == "1.8e-12"
    assert json.loads(json.dumps(Target("a", "b", "c", False, value=np.inf).to_dict()))["value"] is None


def test_a_claim_is_judged_only_where_the_reference_can_judge_it():
    # |Q_ref - L| = 1 against a claimed 2: covered unless the reference is uncertain by > 1
    assert judge_claim(1.0, 2.0, 0.5) == "covered"
    assert judge_claim(1.0, 2.0, 1.0) == "covered"          # the boundary counts
    assert judge_claim(1.0, 2.0, 1.5) == "undecided"
    # |Q_ref - L| = 3 against 2: missed unless the reference is uncertain by >= 1
    assert judge_claim(3.0, 2.0, 0.5) == "missed"
    assert judge_claim(3.0, 2.0, 1.0) == "undecided"
    for bad in ((-1.0, 1.0, 0.0), (1.0, float("nan"), 0.0), (1.0, 1.0, float("inf") * 0)):
        with pytest.raises(InputError, match="non-negative"):
            judge_claim(*bad)


def test_richardson_claims_against_known_limits():
    """An exact second-order sequence: both claims hold. The plateau of session 36's RMD
    BEM sequence at 1744 MPa (r = 1 ... 16) against its value at r = 256 (session 43)."""
    exact = richardson([1.0 + 0.1 * r ** -2.0 for r in (1, 2, 4, 8, 16)])
    assert judge_richardson(exact, 1.0, 0.0) == {"limit": "covered", "levels": "covered"}
    plateau = [0.183926, 0.197255, 0.202609, 0.204392, 0.204390]
    est = richardson(plateau)          # fallback: 1.25x the larger of the last two steps
    assert not est.asymptotic and est.uncertainty == pytest.approx(1.25 * 1.783e-3, abs=1e-9)
    # the reference of r = 256 (0.204305 +- 5.4e-5) is within it
    assert judge_richardson(est, 0.204305, 5.4e-5) == {"limit": "covered", "levels": "covered"}
    # judged by the last difference alone (before session 43), the same claim is missed
    last_only = dataclasses.replace(est, uncertainty=3 * 2e-6)
    assert judge_richardson(last_only, 0.204305, 5.4e-5)["limit"] == "missed"
    # a reference too uncertain to tell: undecided, never counted either way
    assert judge_richardson(last_only, 0.204305, 1e-4)["limit"] == "undecided"
