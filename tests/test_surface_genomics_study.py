"""validation/surface_genomics.py's design chain (issue 15 §3) on a small surface
database: every design the study saves is re-scored by an independent BEM run of its
saved heights to the same strict scores, and the global stage runs where GLOBAL says."""
import importlib.util
from pathlib import Path

import numpy as np
import pytest

from roughfe.genomics import database as gdb
from roughfe.genomics.design import thesis_targets

pytestmark = pytest.mark.slow


def _study():
    spec = importlib.util.spec_from_file_location(
        "surface_genomics_study",
        Path(__file__).resolve().parents[1] / "validation" / "surface_genomics.py")
    study = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(study)
    return study


def test_design_runs_are_reproduced_by_the_saved_heights(tmp_path):
    sg = _study()
    path = tmp_path / "db.sqlite"
    settings, info = sg.surface_database(path, 2.6e-4, 2, 1, 16, 5, sg.DB_HURST)
    assert info["computed"] == len(gdb.load_entries(path)) == 2      # 2 Sobol points x 1
    entries = gdb.load_entries(path)
    t1, _, t3, curve = thesis_targets(settings)
    rows = sg.design_runs(entries, settings, t1, t3, 0.4 * curve.p_max, 3, tmp_path, "y_t1",
                          quick=True)
    assert [r["method"] for r in rows] == ["sog", "gco", "cco", "mcco"]
    for r in rows:
        scores = np.asarray(r["scores_at_target_pressures"])
        assert np.all((scores >= 0) & (scores <= 1))
        # two independent routes to the same strict scores: the design's own sweep and a
        # fresh load-controlled BEM run of the heights read back from the saved file
        assert r["reproduced"] <= 1e-12
        assert (tmp_path / f"surface_design_y_t1_{r['method']}.npz").is_file()
        expected = min(sg.GLOBAL.get(("y_t1", r["method"]), 0), 12)
        assert r["global_evaluations"] == expected
        assert (r["global_sigma"] is None) == (expected == 0)
