"""`roughfe genome chromosomes` says, before its BEM sweeps start, how many it will run, of
how many steps, on what grid, and roughly how long they take (55 sweeps on a 512^2
window ran 2.5 min without a word; a user's review)."""
import json
import math

import pytest

from roughfe.cli import main
from roughfe.genomics.band_mechanics import band_mechanics
from roughfe.genomics.band_plan import SPREAD, SweepPlan, plan_band_sweeps
from roughfe.genomics.bands import band_chromosomes
from roughfe.surfaces.io import save_surface
from roughfe.surfaces.spectral import spectral_surface


def _surface():
    return spectral_surface(32, 1e-3, 0.8, rms_height=1e-6, rng=4)


def test_the_plan_counts_the_sweeps_band_mechanics_runs():
    bands = band_chromosomes(_surface(), 2.0)
    plan = plan_band_sweeps(bands, youngs_modulus=1e9, n_steps=4)
    mech = band_mechanics(bands, youngs_modulus=1e9, n_steps=4)
    assert plan.n_sweeps == mech.nit      # flat and repeated fields are not swept
    assert plan.shape == (32, 32) and plan.calibration_shape == (32, 32)   # under 64^2
    assert plan.n_steps == 4 and plan.workers == 2
    assert 0 < plan.seconds < math.inf
    # a rough estimate: the timed crop is the whole 32^2 surface here, so it is the
    # complete surface's sweep times the sweeps over two threads; a factor 10 either way
    # only guards against a wrong scale (points, steps, sweeps), not the machine's load
    assert mech.elapsed / 10 < plan.seconds < 10 * mech.elapsed


def test_the_summary_line_and_a_plan_without_estimate():
    plan = SweepPlan(n_sweeps=55, n_steps=20, shape=(512, 512), workers=2,
                     seconds_per_point_step=1e-6, calibration_shape=(64, 64))
    assert plan.seconds == pytest.approx(55 * 20 * 512 ** 2 * 1e-6 / 2, rel=1e-12, abs=0)
    low, high = plan.seconds / SPREAD, plan.seconds * SPREAD      # 72 s .. 288 s
    assert plan.summary() == (
        f"55 BEM sweeps of 20 steps on 512 x 512 points (2 at a time): roughly "
        f"{low:.0f} s to {high / 60:.0f} min (a rough guess, extrapolated from one timed "
        f"sweep of a 64 x 64 crop by the number of points)")
    # both ends rounding to one duration: one number, not "roughly 1 s to 1 s"
    tiny = SweepPlan(1, 3, (32, 32), 2, 1e-4, (32, 32))
    assert ": about 1 s (a rough guess" in tiny.summary()
    none = SweepPlan(55, 20, (512, 512), 2, float("nan"), (64, 64))
    assert none.summary().endswith(": time not estimated (the calibration sweep did not run)")


def test_the_command_prints_the_plan_before_the_sweeps(tmp_path, capsys, monkeypatch):
    import roughfe.genomics.band_mechanics as bm
    path = save_surface(_surface(), tmp_path / "s.npz")
    said_before = []
    real = bm.sweep_fields

    def spy(*args, **kwargs):      # what was on stdout when the sweeps started
        said_before.append(capsys.readouterr().out)
        return real(*args, **kwargs)
    monkeypatch.setattr(bm, "sweep_fields", spy)
    assert main(["genome", "chromosomes", str(path), "--gamma", "2", "--steps", "4",
                 "--E", "1e9", "--no-figures", "-o", str(tmp_path / "out")]) == 0
    nit = json.loads((tmp_path / "out" / "mechanics.json").read_text())["nit"]
    assert said_before[0].startswith(f"mechanics: {nit} BEM sweeps of 4 steps on "
                                     f"32 x 32 points (2 at a time): ")
    assert said_before[0].split(": ")[2].startswith(("roughly ", "about "))
    assert "rough guess" in said_before[0]
    capsys.readouterr()
    assert main(["genome", "chromosomes", str(path), "--gamma", "2", "--steps", "4",
                 "--E", "1e9", "--no-figures", "--quiet", "-o", str(tmp_path / "q")]) == 0
    assert "mechanics:" not in capsys.readouterr().out        # --quiet: no calibration
    assert main(["genome", "chromosomes", "--help"]) == 0
    assert "dominate the run time" in " ".join(capsys.readouterr().out.split())
