"""The Sec. 2.4 leakage study: per-task records, summary statistics and Eq. 2.17 fits."""
import numpy as np
import pytest

from roughfe.leakage.study import leakage_task, summarise, study_grid
from roughfe.writers import to_json_text


@pytest.fixture(scope="module")
def records():
    # two fractal dimensions with the same seeds (as the thesis), two surfaces each
    return [r for D in (2.3, 2.7) for seed in (11, 12) for r in leakage_task(D, 3, seed)]


def test_task_records_are_physical(records):
    to_json_text(records)                                   # JSON-safe
    assert len(records) == 2 * 2 * 6
    for D in (2.3, 2.7):
        for seed in (11, 12):
            rs = [r for r in records if r["D"] == D and r["seed"] == seed]
            a = [r["area_fraction"] for r in rs]
            d = [r["separation_star"] for r in rs]
            v = [r["free_volume_star"] for r in rs]
            # loading: contact area grows, separation and free volume shrink
            assert np.all(np.diff(a) > 0) and np.all(np.diff(d) < 0) and np.all(np.diff(v) < 0)
            assert rs[-1]["delta_star"] == pytest.approx(1.0)
            for r in rs:
                # Eq. 2.15 + 2.16 partition the free volume
                assert r["percolating_volume_star"] + r["trapped_volume_star"] == pytest.approx(
                    r["free_volume_star"], rel=1e-12, abs=0)
                assert 0 < r["m0_star"] < 1 and 0 < r["m2_star"] < 1.5
                if r["percolates_x"] or r["percolates_y"]:
                    assert r["leak_rate"] > 0 and r["percolating_volume_star"] > 0
                for k in ("x", "y"):
                    # inflow = outflow; no through-flow at all when nothing percolates
                    if r[f"percolates_reynolds_{k}"]:
                        assert r[f"flow_imbalance_{k}"] < 1e-6 and r[f"leak_rate_{k}"] > 0
                    else:
                        assert r[f"flow_imbalance_{k}"] is None and r[f"leak_rate_{k}"] == 0.0


def test_summary_statistics_and_fits(records):
    s = summarise(records)
    to_json_text(s)
    assert s["n_records"] == len(records)
    assert len(s["curves"]) == 2 * 6 and all(c["n"] == 2 for c in s["curves"])
    c = next(c for c in s["curves"] if c["D"] == 2.3 and c["step"] == 0)
    vals = [r["percolating_volume_star"] for r in records if r["D"] == 2.3 and r["step"] == 0]
    assert c["percolating_volume_star_mean"] == pytest.approx(np.mean(vals))
    assert c["percolating_volume_star_std"] == pytest.approx(np.std(vals, ddof=1))
    for f in s["fits"]:
        rs = [r for r in records if r["D"] == f["D"]]
        v = np.array([r["free_volume_star"] for r in rs])
        vp = np.array([r["percolating_volume_star"] for r in rs])
        # least squares through the origin: the residual is orthogonal to V*
        assert np.dot(vp - f["g"] * v, v) == pytest.approx(0.0, abs=1e-12 * np.dot(v, v))
        assert 0 < f["g"] <= 1.0 + 1e-12                       # V_p <= V
    p = s["percolation"]
    assert p["n_compared"] == 2 * len(records)
    assert p["n_disagree"] == len(p["disagreements"])
    # default FV scheme and network with its connectivity: never a disagreement
    assert p["n_disagree"] == 0


def test_fits_recover_exact_power_laws():
    v = np.array([0.9, 0.6, 0.4, 0.2])
    recs = [{"D": 2.5, "m": 4, "step": k, "free_volume_star": x,
             "percolating_volume_star": 0.8 * x, "trapped_volume_star": x ** 2.5}
            for k, x in enumerate(v)]
    f = summarise(recs)["fits"][0]
    assert f["g"] == pytest.approx(0.8, rel=1e-12, abs=0)
    assert f["beta"] == pytest.approx(2.5, rel=1e-12)


def test_study_grid_defaults_are_the_thesis():
    g = study_grid(n_surfaces=20)
    assert g["D"] == [2.1, 2.3, 2.5, 2.7, 2.9] and g["m"] == list(range(2, 9))
    assert g["replica"] == list(range(20))
