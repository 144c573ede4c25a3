"""Design inputs a user gets wrong (round 2, session 32): each is an InputError before any
design stage runs, naming what was given and what the design takes.

* A stiffness target of 2 points: the verdict's score solved at the target pressures
  takes K by central differences over them (2 points: the derivative at neither); the
  design ran every stage, then failed with "response curve stiffness has non-finite
  values: [nan nan]".
* A target in other units than the database (an area fraction read as K: 0.05 Pa/m): its
  Eq. 4.1 residuals of ~1e12 made GCMMA's subproblem singular (numpy LinAlgError).
* A header naming another unit (pressure_MPa, K [MPa/um], A [%]): the numbers were read
  as SI.
"""
import re

import numpy as np
import pytest

from roughfe.cli import main
from roughfe.errors import FileFormatError, InputError
from roughfe.genomics import database as db
from roughfe.genomics import design as de
from roughfe.genomics.similarity import Target
from roughfe.genomics.target_csv import read_target_csv
from roughfe.study import build_genome_db

SETTINGS = db.DatabaseSettings(n_nodes=64, n_steps=10)
FAST = de.GcmmaOptions(n_it_sog=1, n_it_cross=1, n_it_micro=1, n_micro=2)


@pytest.fixture(scope="module")
def database(tmp_path_factory):
    path = tmp_path_factory.mktemp("design_inputs") / "db.sqlite"
    build_genome_db(path, SETTINGS, limit=3, workers=1, progress=False)
    return path, db.load_entries(path)


def _curve(entries):
    return entries[0].curve


def test_a_stiffness_target_of_two_points_is_refused_before_the_stages(database):
    _, entries = database
    c = _curve(entries)
    two = Target(c.pressure[[4, 9]], c.stiffness[[4, 9]], "K", "two")
    with pytest.raises(InputError, match="2 points with p > 0.*at least 3"):
        de.run_design("sog", entries, [two], SETTINGS, options=FAST)
    # the strict scorer itself says the same (it returned NaN K, then a bare message)
    with pytest.raises(InputError, match="at least 3"):
        de.score_at_target_pressures(de.entry_design(entries[0], SETTINGS).surface(), [two], SETTINGS)
    # three points are enough: the design runs and its solved score is finite
    three = Target(c.pressure[[3, 6, 9]], c.stiffness[[3, 6, 9]], "K", "three")
    res = de.run_design("sog", entries, [three], SETTINGS, options=FAST)
    assert np.isfinite(de.rescore_at_target_pressures(res.best.design, [three],
                                                      SETTINGS)).all()


def test_a_target_in_other_units_than_the_database_is_refused(database):
    """K of every genome after Eq. 4.2 is ~1e11 Pa/m here; a target of the same shape
    1e6 times lower (an area fraction read as K, or K in other units) matches none."""
    _, entries = database
    c = _curve(entries)
    wrong = Target(c.pressure, 1e-6 * c.stiffness, "K", "wrong")
    with pytest.raises(InputError) as e:
        de.run_design("sog", entries, [wrong], SETTINGS, options=FAST)
    msg = str(e.value)
    assert "more than a factor 1000 from every genome" in msg and "Pa/m" in msg
    assert "--quantity" in msg and "E* = " in msg
    # a factor 10 is a poor target, not a unit error: it is designed (and scores < 0)
    poor = Target(c.pressure, 0.1 * c.stiffness, "K", "poor")
    res = de.run_design("sog", entries, [poor], SETTINGS, options=FAST)
    assert res.best.scores[0] < 0


def _never(design):
    raise AssertionError("a design stage ran (a BEM sweep was asked for) before the check")


def test_every_design_method_checks_its_inputs_when_called_directly(database):
    """The checks ran only in run_design (round 2, session 33): a direct sog/gco/cco/mcco
    call with a 2-point K target, or a target 1e6 below every genome, went into the
    stages. Each method now refuses both before its first BEM sweep (``evaluate`` fails
    if it is called), with the message of run_design; and the batched strict scoring
    refuses a 2-point K target (it scored every design -inf, silently)."""
    _, entries = database
    c = _curve(entries)
    good_k = Target(c.pressure[[3, 6, 9]], c.stiffness[[3, 6, 9]], "K", "good")
    good_a = Target(c.pressure, c.area_fraction, "A", "area")
    bad = {"at least 3": Target(c.pressure[[4, 9]], c.stiffness[[4, 9]], "K", "two"),
           "more than a factor 1000": Target(c.pressure, 1e-6 * c.stiffness, "K", "units")}
    pbar = float(c.pressure[5])
    for match, target in bad.items():
        calls = {"sog": lambda: de.sog(entries, target, SETTINGS, evaluate=_never, options=FAST),
                 "gco": lambda: de.gco(entries, target, pbar, SETTINGS, evaluate=_never,
                                       options=FAST),
                 "cco": lambda: de.cco(entries, target, pbar, SETTINGS, evaluate=_never,
                                       options=FAST),
                 "mcco": lambda: de.mcco(entries, target, good_a, SETTINGS, evaluate=_never,
                                         options=FAST)}
        for method, call in calls.items():
            with pytest.raises(InputError, match=match):
                call()
    off_a = Target(c.pressure, 1e-4 * c.area_fraction, "A", "area in 1e-4")
    with pytest.raises(InputError, match="target area in 1e-4 .*more than a factor 1000"):
        de.mcco(entries, good_k, off_a, SETTINGS, evaluate=_never, options=FAST)
    with pytest.raises(InputError, match="database is empty"):
        de.sog([], good_k, SETTINGS, evaluate=_never, options=FAST)
    design = de.entry_design(entries[0], SETTINGS)
    with pytest.raises(InputError, match="at least 3"):
        de.score_batch_at_target_pressures([design, design], [bad["at least 3"]], SETTINGS)
    assert np.isfinite(de.score_batch_at_target_pressures([design], [good_k], SETTINGS)).all()


@pytest.mark.parametrize("header, said", [("pressure_MPa,value", "'mpa'"),
                                          ("p_kPa,K", "'kpa'"),
                                          ("p [Pa],K [MPa/um]", "'mpa'"),
                                          ("p [Pa],K [N/mm^3]", "'n/mm^3'"),
                                          ("p,A [%]", "'%'")])
def test_a_header_naming_another_unit_is_refused(tmp_path, header, said):
    path = tmp_path / "t.csv"
    path.write_text(f"{header}\n1e7,0.5\n2e7,0.6\n3e7,0.7\n")
    with pytest.raises(FileFormatError, match="gives the (pressure|value) in "
                                              + re.escape(said)):
        read_target_csv(path)


@pytest.mark.parametrize("header", ["pressure_Pa,value", "p [Pa],K [Pa/m]",
                                    "mean pressure (N/m^2),stiffness per unit area",
                                    "p,A", "pressure,area_fraction"])
def test_si_headers_are_read(tmp_path, header):
    path = tmp_path / "t.csv"
    path.write_text(f"{header}\n1e7,0.5\n2e7,0.6\n3e7,0.7\n")
    np.testing.assert_array_equal(read_target_csv(path).pressure, [1e7, 2e7, 3e7])


def test_the_command_refuses_them_and_an_empty_database(database, tmp_path, capsys):
    path, _ = database
    bad = tmp_path / "bad.csv"
    bad.write_text("pressure_Pa,value\n0,1e10\n2e7,2e10\n3e7,3e10\n")
    args = ["design", "--db", str(path), "--method", "sog", "--no-figures"]
    assert main(args + ["--target", str(bad), "-o", str(tmp_path / "o")]) == 2
    assert "at least 3" in capsys.readouterr().err
    assert not (tmp_path / "o" / "result.json").exists()
    import sqlite3
    empty = tmp_path / "empty.sqlite"
    empty.write_bytes(path.read_bytes())
    with sqlite3.connect(empty) as con:
        con.execute("DELETE FROM genomes")
    assert main(["design", "--db", str(empty), "--target", "y_t1", "--method", "sog",
                 "-o", str(tmp_path / "e")]) == 2
    err = capsys.readouterr().err
    assert "holds no genomes" in err and "db build" in err
