"""Shared test set-up: headless rendering, the location of the shared test data, and a
guard that refuses pytest.approx comparisons decided by its default ``abs = 1e-12``."""
import math
from decimal import Decimal
from numbers import Complex
from pathlib import Path

import _pytest.python_api
import pytest

# Headless figures in every test process, and vtk loaded before any test module imports
# dolfinx (in the other order the first off-screen render aborts): roughfe._runtime.
from roughfe._runtime import load_render_backend  # noqa: E402

load_render_backend()

from roughfe.surfaces.io import topographies_folder  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
TOPOGRAPHIES = topographies_folder()

SWAMPED = "pytest.approx's default abs=1e-12 swamps rel for this SI value; give abs explicitly"


@pytest.fixture(scope="session")
def bench_script():
    """``bench_script(name)`` imports ``benchmarks/<name>.py`` (scripts, not a package),
    with benchmarks/ on sys.path while it loads: the scripts import their siblings."""
    import importlib.util
    import sys
    folder = REPO / "benchmarks"

    def load(name):
        sys.path.insert(0, str(folder))
        try:
            spec = importlib.util.spec_from_file_location(f"bench_{name}", folder / f"{name}.py")
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
        finally:
            sys.path.remove(str(folder))
        return module
    return load


def _refuse_default_abs(eq):
    """``ApproxScalar.__eq__`` that raises where pytest.approx's default ``abs = 1e-12``,
    not ``rel``, would decide the comparison. pytest keeps that abs when ``rel`` is given,
    and roughfe works in SI units: leak rates (1e-14 m^3/s), pocket volumes (1e-19 m^3),
    compliances (1e-13 m/Pa) and mean squares (1e-12 m^2) lie below it, so
    ``approx(x, rel=1e-9)`` passed for any error (three such passes hid wrong
    expectations). Refused: ``abs`` not given, a non-zero finite expected value, and
    1e-12 > rel |expected| (rel defaults to 1e-6). Give ``abs=0`` for a relative
    comparison, or an abs scaled to the quantity where the expected value can be 0."""
    api = _pytest.python_api

    def guarded(self, actual):
        expected = self.expected
        if (self.abs is None and isinstance(expected, (Complex, Decimal))
                and api._as_numpy_array(actual) is None):     # arrays: per element
            size = float(abs(expected))
            rel = float(self.DEFAULT_RELATIVE_TOLERANCE if self.rel is None else self.rel)
            default_abs = float(self.DEFAULT_ABSOLUTE_TOLERANCE)
            if 0 < size < math.inf and default_abs > rel * size:
                raise AssertionError(f"{SWAMPED} (expected {expected!r}, rel {rel:g}, "
                                     f"actual {actual!r})")
        return eq(self, actual)
    return guarded


_pytest.python_api.ApproxScalar.__eq__ = _refuse_default_abs(
    _pytest.python_api.ApproxScalar.__eq__)


@pytest.fixture(scope="session")
def topographies_dir():
    """Folder of the five measured instrument files (``../shared/data/topographies``)."""
    if not TOPOGRAPHIES.is_dir():
        pytest.skip(f"measured topographies not found at {TOPOGRAPHIES}")
    return TOPOGRAPHIES


def same_values(a, b):
    """Equal values: arrays element for element, dataclasses field by field, lists,
    tuples and dicts item by item (NaN is not equal to itself: not the same)."""
    import dataclasses

    import numpy as np
    if a is b:
        return True
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return np.array_equal(a, b)
    if dataclasses.is_dataclass(a) and type(a) is type(b):
        return all(same_values(getattr(a, f.name), getattr(b, f.name))
                   for f in dataclasses.fields(a))
    if isinstance(a, (list, tuple)) and type(a) is type(b):
        return len(a) == len(b) and all(same_values(x, y) for x, y in zip(a, b))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same_values(a[k], b[k]) for k in a)
    return type(a) is type(b) and a == b


@pytest.fixture
def computed_once():
    """``computed_once(real, key=None)``: ``real`` computed once per distinct ``key(*args,
    **kwargs)`` (default: the arguments), compared by :func:`same_values`; a later call
    with an equal key gets the first call's result. For a test whose CLI runs differ only
    in options read after (or before) an expensive call with equal arguments: monkeypatch
    the call with it (results are frozen dataclasses)."""
    def once(real, key=None):
        done = []

        def call(*args, **kwargs):
            this = key(*args, **kwargs) if key else (args, kwargs)
            for seen, out in done:
                if same_values(seen, this):
                    return out
            done.append((this, real(*args, **kwargs)))
            return done[-1][1]
        return call
    return once


@pytest.fixture
def deflations_made(monkeypatch):
    """The grid shapes of the two-level corrections the BEM solves make from now on (the
    periodic BlockDeflation and the non-periodic PaddedBlockDeflation, as
    ``roughfe.bem.contact`` makes them), in order."""
    from roughfe.bem import contact
    made = []
    for name in ("BlockDeflation", "PaddedBlockDeflation"):
        original = getattr(contact, name)

        def make(op, block, _original=original, **options):
            made.append(op.shape)
            return _original(op, block, **options)
        monkeypatch.setattr(contact, name, make)
    return made


@pytest.fixture
def spectral_file(tmp_path):
    """``spectral_file(n, seed)``: the path of an n^2 periodic spectral surface (.npz)
    written by ``roughfe generate spectral`` in the test's folder."""
    from roughfe.cli import main

    def write(n, seed):
        path = tmp_path / f"s{n}_{seed}.npz"
        assert main(["generate", "spectral", "--n", str(n), "--seed", str(seed),
                     "--no-figures", "-o", str(path)]) == 0
        return path
    return write


@pytest.fixture
def surface32(spectral_file):
    """A 32^2 periodic spectral surface file, seed 1."""
    return spectral_file(32, 1)
