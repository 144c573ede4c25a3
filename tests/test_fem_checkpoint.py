"""Per-load checkpoints of a FEM sweep (roughfe.fem.checkpoint) and the resumed levels of
validation/fem_convergence.py (session 36: a crash at load 7 of 9 of level r = 16 lost
80 CPU minutes, because a level was written only when all its loads were finished).

Every load of a sweep starts its Newton from the previous load's displacement. Resumed
from the checkpoint below with that displacement zeroed (a cold start at load 3), the mean
gap differs by 1.2e-14 (relative) and the nodal pressures by 1.3e-14 of their peak
(measured): the bit-for-bit equality here holds only because that state is restored.

Budget: ~5 s CPU together (a 65-node profile; an r = 1 level of three loads, coarse deep
mesh).
"""
import dataclasses
import json
import os
import sys
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("dolfinx")

from roughfe.errors import InputError  # noqa: E402
from roughfe.fem import contact as fem_contact  # noqa: E402
from roughfe.fem import fem_contact_sweep, mesh_profile  # noqa: E402
from roughfe.fem.checkpoint import SweepCheckpoint, layout_digest  # noqa: E402
from roughfe.model import ContactResult, Material  # noqa: E402
from roughfe.surfaces.rmd import rmd_profile  # noqa: E402
from roughfe.writers import current_umask  # noqa: E402

pytestmark = pytest.mark.fem

MAT = Material(E=210e9, nu=0.3)
LOADS = np.array([50e6, 100e6, 200e6, 400e6, 800e6])
SOLVE = fem_contact._ContactProblem.solve_mean_pressure     # one load (load control)


class Crash(Exception):
    """The interruption (an out-of-memory kill, a node failure) of a test run."""


def crash_at(monkeypatch, n_loads, calls):
    """Patch the load-control solve: record every load solved, raise at the
    ``n_loads + 1``-th (``n_loads`` None: never)."""
    def patched(self, target, guess, keep_fields=False):
        if n_loads is not None and len(calls) == n_loads:
            raise Crash(f"interrupted before load {n_loads}")
        calls.append(float(target))
        return SOLVE(self, target, guess, keep_fields)

    monkeypatch.setattr(fem_contact._ContactProblem, "solve_mean_pressure", patched)


def same(x, y) -> bool:
    """Two field values equal, bit for bit (NaN equal to NaN; mappings item by item)."""
    if isinstance(x, Mapping) or isinstance(y, Mapping):
        return x.keys() == y.keys() and all(same(x[k], y[k]) for k in x)
    if isinstance(x, np.ndarray) or isinstance(y, np.ndarray):
        return x.dtype == y.dtype and np.array_equal(x, y, equal_nan=x.dtype.kind == "f")
    if isinstance(x, float) and np.isnan(x):
        return isinstance(y, float) and np.isnan(y)
    return x == y


def assert_same_results(a, b):
    """Every field of two ContactResult equal, bit for bit."""
    for f in dataclasses.fields(ContactResult):
        assert same(getattr(a, f.name), getattr(b, f.name)), f.name


def space(pmesh):
    from dolfinx import fem
    return fem.VectorFunctionSpace(pmesh.mesh, ("CG", 1))


@pytest.fixture(scope="module")
def small_mesh():
    return mesh_profile(rmd_profile(6, 1.5, 1e-3, rng=1, rms_height=1e-6), growth=0.3)


@pytest.fixture(scope="module")
def uninterrupted(small_mesh):
    return fem_contact_sweep(small_mesh, MAT, pressures=LOADS, keep_fields=(-1,))


def test_an_interrupted_sweep_resumes_after_its_last_finished_load(
        small_mesh, uninterrupted, tmp_path, monkeypatch):
    path = tmp_path / "sweep.npz"
    calls = []
    crash_at(monkeypatch, 3, calls)
    with pytest.raises(Crash):
        fem_contact_sweep(small_mesh, MAT, pressures=LOADS, keep_fields=(-1,),
                          checkpoint=path)
    assert calls == LOADS[:3].tolist()
    assert (path.stat().st_mode & 0o777) == 0o666 & ~current_umask()
    assert [p.name for p in tmp_path.iterdir()] == ["sweep.npz"]   # no temporary left

    calls.clear()
    crash_at(monkeypatch, None, calls)
    ckpt = SweepCheckpoint(path)
    resumed = fem_contact_sweep(small_mesh, MAT, pressures=LOADS, keep_fields=(-1,),
                                checkpoint=ckpt)
    assert calls == LOADS[3:].tolist()               # the finished loads are not solved again
    assert (ckpt.resumed_steps, ckpt.not_used) == (3, None)
    assert ckpt.resumed_cpu_seconds > 0
    for a, b in zip(uninterrupted.results, resumed.results, strict=True):
        assert_same_results(a, b)
    for name in ("mean_gap", "stiffness", "stiffness_fd", "delta_applied"):
        assert np.array_equal(getattr(uninterrupted, name), getattr(resumed, name))


def test_a_checkpoint_of_another_sweep_is_not_used(small_mesh, uninterrupted, tmp_path,
                                                   monkeypatch):
    path = tmp_path / "sweep.npz"
    fem_contact_sweep(small_mesh, MAT, pressures=LOADS[:2] * 1.01, keep_fields=(-1,),
                      checkpoint=path)                              # other loads
    calls = []
    crash_at(monkeypatch, None, calls)
    ckpt = SweepCheckpoint(path)
    again = fem_contact_sweep(small_mesh, MAT, pressures=LOADS, keep_fields=(-1,),
                              checkpoint=ckpt)
    assert calls == LOADS.tolist() and ckpt.resumed_steps == 0
    assert "another sweep" in ckpt.not_used
    for a, b in zip(uninterrupted.results, again.results, strict=True):
        assert_same_results(a, b)
    # another profile on the same flat mesh (the heights enter only the gaps): not used
    other = mesh_profile(rmd_profile(6, 1.5, 1e-3, rng=2, rms_height=1e-6), growth=0.3)
    assert layout_digest(space(other)) == layout_digest(space(small_mesh))
    guess = uninterrupted.delta_applied[:1]                       # the same start
    fem_contact_sweep(other, MAT, pressures=LOADS[:1], guesses=guess, checkpoint=path)
    ckpt = SweepCheckpoint(path)
    fem_contact_sweep(small_mesh, MAT, pressures=LOADS[:1], guesses=guess, checkpoint=ckpt)
    assert ckpt.resumed_steps == 0 and "another sweep" in ckpt.not_used
    path.write_bytes(b"not a checkpoint")
    ckpt = SweepCheckpoint(path)
    fem_contact_sweep(small_mesh, MAT, pressures=LOADS[:1], checkpoint=ckpt)
    assert ckpt.resumed_steps == 0 and "not a readable checkpoint" in ckpt.not_used
    with pytest.raises(InputError, match="checkpoint must be a file path"):
        fem_contact_sweep(small_mesh, MAT, pressures=LOADS[:1], checkpoint=5)


# -- validation/fem_convergence.py: an interrupted level resumes -------------------------
@pytest.fixture(scope="module")
def study():
    from roughfe.cli.validate_cmd import _load
    return _load("fem_convergence")


def _level(store: Path, name: str) -> dict:
    data = json.loads((store / f"{name}_r1.json").read_text())
    for key in ("cpu_seconds", "cpu_seconds_mesh"):
        for method in ("bem", "fem"):
            data["level"][method].pop(key, None)
    data["level"].pop("wall_seconds")
    return data


def test_an_interrupted_level_resumes_from_its_last_finished_load(study, tmp_path,
                                                                  monkeypatch):
    monkeypatch.setattr(study, "GROWTH_1", 1.0)     # a cheap level: a coarse deep mesh
    monkeypatch.setattr(study, "FRACTIONS", (0.7,))  # and one window of three loads
    monkeypatch.setattr(sys.modules["_refinement"], "FRACTIONS", (0.7,))   # its loads' module
    name = "rmd"
    surface = study.PROFILES[name]()
    pressures = study.study_pressures(surface)
    loads = study.load_window(pressures).tolist()
    fresh, store = tmp_path / "fresh", tmp_path / "resumed"
    fresh.mkdir(), store.mkdir()
    calls = []
    crash_at(monkeypatch, None, calls)
    study.profile_levels(fresh, name, surface, pressures, (1,))
    assert calls == loads and sorted(os.listdir(fresh)) == [f"{name}_r1.json"]

    calls.clear()
    crash_at(monkeypatch, 2, calls)
    with pytest.raises(Crash):
        study.profile_levels(store, name, surface, pressures, (1,), resume=True)
    partial = f"{name}_r1{study.PARTIAL_SUFFIX}"
    assert sorted(os.listdir(store)) == [partial]   # never looks like a finished level

    calls.clear()
    crash_at(monkeypatch, None, calls)
    study.profile_levels(store, name, surface, pressures, (1,), resume=True)
    assert len(loads) == 3 and calls == loads[2:]   # loads 0, 1 are not solved again
    assert sorted(os.listdir(store)) == [f"{name}_r1.json"]   # the checkpoint removed
    assert _level(store, name) == _level(fresh, name)
