"""A seals engineer's review of the leakage outputs (round 2, session 33).

* ``roughfe leak --fsi``: the ``pockets`` map of ``fields/step_NNN.npz`` numbers the pockets
  of the step's ``pocket_pressures`` / ``pocket_volumes`` (1.., largest first, 0 elsewhere,
  as its stored unit says); it held the internal labels (-1 elsewhere, 0 a pocket, another
  order) and, with ``--trapped-fluid film``, no pocket at all. Checked cell by cell: the
  fluid pressure and the gap volume of pocket k are the k-th entries of results.json.
* the coupled records carry the Reynolds solve's own report (percolation verdict, in/out
  imbalance, iterations): they were null, so network and flow could not be compared; the
  units of the solid's keys with ``--fsi`` say that they are its effective pressure.
* the 1D coupling under load control reports the approach of the gap it returns: a closed
  channel reported the last balanced approach (0 before any), 17 nm off its gap.
* a Reynolds flow imbalance can be the linear solver's tolerance, not only round-off.
* ``leak --no-reynolds`` prints no leak-rate line for columns of '-'.
"""
import json
import warnings

import numpy as np
import pytest

from roughfe.cli import main
from roughfe.errors import FlowImbalanceWarning
from roughfe.leakage import reynolds_flow
from roughfe.leakage.profile_fsi import coupled_channel
from roughfe.model import Material
from roughfe.surfaces import Surface
from roughfe.surfaces.io import save_surface
from roughfe.surfaces.spectral import spectral_surface


@pytest.fixture(scope="module")
def surface():
    return spectral_surface(32, 1e-4, 0.8, rms_height=1e-6, rng=4)


@pytest.mark.parametrize("trapped", ["volume", "film"])
def test_fsi_pocket_map_numbers_the_pockets_of_results_json(tmp_path, surface, trapped):
    path = save_surface(surface, tmp_path / "s.npz")
    out = tmp_path / trapped
    assert main(["leak", str(path), "--fsi", "--direction", "x", "--pressure", "2e7",
                 "--inlet-pressure", "1e7", "--outlet-pressure", "0", "--E", "1e9",
                 "--nu", "0.3", "--trapped-fluid", trapped, "--no-figures", "--quiet",
                 "-o", str(out)]) == 0
    step = json.loads((out / "results.json").read_text())["steps"][0]
    fields = np.load(out / "fields" / "step_000.npz")
    lab, pf, gap = fields["pockets"], fields["fluid_pressure"], fields["gap"]
    cell = float(np.prod(fields["spacing_m"]))
    n = len(step["pocket_pressures"])
    assert n >= 3                                    # measured: 4 pockets
    assert "0 none" in json.loads(str(fields["units"]))["pockets"]
    # 0 elsewhere, 1..n each a pocket (the old map had -1 elsewhere, and none with film)
    assert lab.min() == 0 and np.array_equal(np.unique(lab), np.arange(n + 1))
    for k in range(1, n + 1):
        assert pf[lab == k].mean() == pytest.approx(step["pocket_pressures"][k - 1],
                                                    rel=1e-12, abs=0)
        assert gap[lab == k].sum() * cell == pytest.approx(step["pocket_volumes"][k - 1],
                                                           rel=1e-12, abs=0)
    # the trapped share is the pockets' fluid over the nominal area
    assert pf[lab > 0].sum() / pf.size / step["external_pressure"] == pytest.approx(
        step["trapped_load_fraction"], rel=1e-12, abs=0)
    # the coupled Reynolds report (was null): same verdict as the network (face
    # connectivity both), in = out to the solver, its iterations
    assert step["percolates_reynolds_x"] is step["percolates_x"] is True
    assert step["flow_imbalance_x"] is not None and step["flow_imbalance_x"] < 1e-6
    assert step["reynolds_nit_x"] >= 1
    # the contact keys are the solid's effective pressure (said "Pa" / "N" only): on top of
    # the fluid pressure they carry the external load
    units = json.loads(str(fields["units"]))
    assert "effective" in units["pressure_contact"]
    assert "effective" in json.loads((out / "results.json").read_text())["units"][
        "mean_pressure"]
    total = fields["pressure_contact"] + pf
    assert total.mean() == pytest.approx(step["external_pressure"], rel=1e-8, abs=0)


def wavy(n):
    """The wavy channel of tests/test_leakage_channel_fsi.py (throat at the inlet)."""
    w, a = 1e-3, 5e-6
    x = np.arange(n) * w / (n - 1)
    return Surface(a * (np.cos(4 * np.pi * x / w) + 0.5 * np.cos(3 * np.pi * x / w)),
                   n * w / (n - 1))


@pytest.mark.parametrize("p_ext, p_in, p_out, state", [
    (1.5e6, 2e6, 0.0, "closed"), (1.5e6, 0.0, 2e6, "open"), (5e5, 0.0, 2e6, "lift-off")])
def test_channel_under_load_control_reports_the_approach_of_its_gap(p_ext, p_in, p_out,
                                                                     state):
    # g = max h - h - Delta + u (module docstring of roughfe.leakage.profile_fsi): the
    # closed channel reported Delta = 0 (no balance was reached), 0.29 um off its gap
    prof = wavy(65)
    h = prof.heights
    r = coupled_channel(prof, Material(E=1.5e8, nu=0.3), external_pressure=p_ext,
                        p_in=p_in, p_out=p_out)
    assert r.state == state
    expected = h.max() - h - r.approach + r.displacement
    assert np.abs(r.gap - expected).max() < 1e-9 * np.ptp(h)
    if state == "closed":
        assert r.gap.min() == 0.0 and abs(r.approach) > 1e-3 * np.ptp(h)


def _random_gap():
    """A 10 x 9 gap (m) of random open cells, gaps 150x apart (replays the draws of the
    review's search, seed 3, 12th field)."""
    rng = np.random.default_rng(3)
    for _ in range(12):
        nx, ny = rng.integers(3, 20, 2)
        g = rng.random((nx, ny)) * 1e-6
        g[rng.random((nx, ny)) < 0.3 + 0.3 * rng.random()] = 0
        rng.integers(2)
    return g


def test_flow_imbalance_can_be_the_solver_tolerance_and_the_warning_says_so():
    g = _random_gap()
    spacing = (1e-6, 1.7e-6)
    assert g.shape == (10, 9)
    with pytest.warns(FlowImbalanceWarning, match="linear solver's tolerance") as caught:
        r = reynolds_flow(g, spacing, direction="x")
    assert "round-off" in str(caught[0].message)
    with warnings.catch_warnings():
        warnings.simplefilter("error")               # no warning at rtol 1e-14
        tight = reynolds_flow(g, spacing, direction="x",
                              petsc_options={"ksp_rtol": 1e-14})
    # the imbalance was the CG tolerance (measured 2.8e-6 -> 4e-10), not round-off; the
    # dissipation leak rate keeps the tolerance either way
    assert r.flow_imbalance > 1e-6 > 1e-3 * r.flow_imbalance > tight.flow_imbalance
    assert tight.leak_rate == pytest.approx(r.leak_rate, rel=1e-12, abs=0)


def test_leak_without_reynolds_prints_no_leak_rate_line(tmp_path, capsys, surface):
    path = save_surface(surface, tmp_path / "s.npz")
    base = ["leak", str(path), "--pressure", "1e6", "--E", "1e9", "--nu", "0.3",
            "--no-figures", "--overwrite", "-o", str(tmp_path / "o")]
    assert main(base + ["--no-reynolds"]) == 0
    out = capsys.readouterr().out
    assert "Q: not solved (--no-reynolds)" in out and "Q: leak rate" not in out
    assert main(base + ["--inlet-pressure", "3e5", "--outlet-pressure", "1e5"]) == 0
    out = capsys.readouterr().out
    assert "pressure drop 200000 Pa (--inlet-pressure - --outlet-pressure)" in out


def test_unloading_flag_has_a_unit():
    from roughfe.leakage.analysis import record_units
    assert record_units(["unloading"]) == {"unloading": "bool (a step of the unloading "
                                                        "path, --unload)"}
