"""Similarity score (Eq. 4.1), amplitude rescaling (Eq. 4.2) and targets: maths only, no BEM."""
import numpy as np
import pytest

from roughfe.errors import FileFormatError, InputError
from roughfe.genomics.similarity import (ResponseCurve, Target, amplitude_factor,
                                         linear_then_flat_target, similarity, split_ranges)
from roughfe.genomics.target_csv import read_target_csv, write_target_csv


def _curve(scale=1.0, k0=2.0):
    p = np.linspace(0.1, 1.0, 10)
    return ResponseCurve(p * scale, k0 * np.sqrt(p), np.minimum(p, 1.0) * 0.5)


def test_identical_curves_score_one_and_relative_error_is_inf_norm():
    c = _curve()
    t = Target.from_curve(c, "K")
    assert similarity(t, c) == pytest.approx(1.0, abs=1e-14)
    # a curve 3 % too stiff everywhere, 10 % at one point -> s = 0.9 (the worst point)
    k = c.stiffness * 1.03
    k[4] = c.stiffness[4] * 0.9
    assert similarity(t, ResponseCurve(c.pressure, k, c.area_fraction)) == pytest.approx(0.9)


def test_rescaling_is_a_stretch_of_the_pressure_axis():
    """Eq. (4.2): heights x eta -> p x eta, K and A unchanged; scoring rescales first."""
    c = _curve()
    t = Target.from_curve(c, "A")
    stretched = c.rescaled(3.7)
    assert stretched.p_max == pytest.approx(3.7 * c.p_max)
    np.testing.assert_array_equal(stretched.stiffness, c.stiffness)
    assert amplitude_factor(t.p_max, stretched.p_max) == pytest.approx(1 / 3.7)
    assert similarity(t, stretched) == pytest.approx(1.0, abs=1e-12)
    assert similarity(t, stretched, rescale=False) < 0.5


def test_partial_ranges_pick_the_right_points():
    c = _curve()
    t = Target.from_curve(c, "K")
    k = c.stiffness.copy()
    k[-3:] *= 1.2          # wrong only at high pressure
    bad = ResponseCurve(c.pressure, k, c.area_fraction)
    low, high = split_ranges(t, 0.65)
    assert similarity(t, bad, low) == pytest.approx(1.0)
    assert similarity(t, bad, high) == pytest.approx(0.8)
    assert similarity(t, bad) == pytest.approx(0.8)


def test_target_y_t2_shape_and_bad_inputs(tmp_path):
    t = linear_then_flat_target(p_max=2.0, pbar=0.5, plateau=4.0, n_points=20)
    assert t.values[0] == pytest.approx(4.0 * 0.1 / 0.5)
    assert np.all(t.values[t.pressure >= 0.5] == 4.0)
    path = write_target_csv(tmp_path / "t.csv", t)
    back = read_target_csv(path)
    np.testing.assert_allclose(back.values, t.values)
    # the file says what it holds: an A(p) target is read as A, and asking K of it is an
    # error (it was read as a stiffness: a silent, meaningless design objective)
    area = write_target_csv(tmp_path / "a.csv", Target(t.pressure, 0.01 * t.values, "A",
                                                       "y_t3"))
    assert read_target_csv(area).quantity == "A" and back.quantity == "K"
    assert read_target_csv(area, "A").quantity == "A"
    with pytest.raises(InputError, match=r"its comment says contact area fraction .* \(A\) "
                                         r"but --quantity K says normal contact stiffness .*"
                                         r"--quantity A or none"):
        read_target_csv(area, "K")
    plain = tmp_path / "plain.csv"
    plain.write_text("pressure_Pa,value\n1e5,0.1\n2e5,0.2\n")
    assert read_target_csv(plain).quantity == "K"             # says nothing: the default
    assert read_target_csv(plain, "A").quantity == "A"
    with pytest.raises(InputError, match="finite"):
        Target([0.1, 0.2], [1.0, np.nan])
    with pytest.raises(InputError, match=">= 0"):
        Target([0.1, 0.2], [1.0, -1.0])
    with pytest.raises(InputError, match="> 0 where p > 0"):
        Target([0.1, 0.2], [1.0, 0.0])
    with pytest.raises(InputError, match="pbar"):
        t.check_pbar(2.5)
    with pytest.raises(InputError, match="quantity"):
        Target([0.1, 0.2], [1.0, 2.0], quantity="E")


def test_target_csv_header_is_a_line_of_names_not_a_line_number(tmp_path):
    """Header detection used the line number: a headerless file with a UTF-8 BOM, or a
    first row with a typo, silently lost its first row, and a header after two comment
    lines was refused. Now only names are a header, and every bad row is an error
    naming its line and content."""
    from roughfe.errors import FileFormatError
    rows = "1e7,1e11\n2e7,1.1e11\n3e7,1.2e11\n"
    bom = tmp_path / "bom.csv"
    bom.write_bytes(b"\xef\xbb\xbf" + rows.encode())
    t = read_target_csv(bom)
    np.testing.assert_array_equal(t.pressure, [1e7, 2e7, 3e7])
    bom_header = tmp_path / "bom_header.csv"
    bom_header.write_bytes(b"\xef\xbb\xbfpressure_Pa,value\n" + rows.encode())
    assert read_target_csv(bom_header).pressure.size == 3
    comments = tmp_path / "comments.csv"
    comments.write_text("# my target\n# made by hand\npressure_Pa,value\n" + rows)
    np.testing.assert_array_equal(read_target_csv(comments).values, [1e11, 1.1e11, 1.2e11])
    typo = tmp_path / "typo.csv"
    typo.write_text("1e7,1e11x\n2e7,1.1e11\n3e7,1.2e11\n")
    with pytest.raises(FileFormatError, match=r"line 1 .*'1e7,1e11x'"):
        read_target_csv(typo)
    late = tmp_path / "late.csv"
    late.write_text("pressure_Pa,value\n" + rows + "p,K\n")
    with pytest.raises(FileFormatError, match=r"line 5 .*'p,K'"):
        read_target_csv(late)
    second = tmp_path / "second.csv"
    second.write_text("pressure_Pa,value\nin Pa,in Pa/m\n" + rows)
    with pytest.raises(FileFormatError, match="line 2"):
        read_target_csv(second)
    latin = tmp_path / "latin.csv"
    latin.write_bytes(b"# \xb5m\n" + rows.encode())
    with pytest.raises(FileFormatError, match="UTF-8"):
        read_target_csv(latin)


def test_target_csv_contents_are_checked(tmp_path):
    """A header 'value,pressure_Pa' was read as pressure,value (values as pressures); a
    third column was silently dropped; an area target in percent (5-60) was accepted.
    Now the header must name the pressure first, rows hold two values, and 0 < A <= 1."""
    from roughfe.errors import FileFormatError

    def target(name, text, quantity=None):
        path = tmp_path / name
        path.write_text(text)
        return read_target_csv(path, quantity)

    with pytest.raises(FileFormatError, match=r"line 1: the header 'value,pressure_Pa' does "
                                              r"not name the pressure first \(swapped"):
        target("swapped.csv", "value,pressure_Pa\n1e11,1e7\n1.1e11,2e7\n")
    with pytest.raises(FileFormatError, match=r"'x,y' does not name the pressure first"):
        target("xy.csv", "x,y\n1e7,1e11\n2e7,1.1e11\n")
    with pytest.raises(FileFormatError, match=r"'pressure_Pa,K,A' names 3 column"):
        target("three.csv", "pressure_Pa,K,A\n1e7,1e11,0.01\n2e7,1.1e11,0.02\n")
    with pytest.raises(FileFormatError, match=r"line 1 .*'1e7,1e11,0.01'"):
        target("three_bare.csv", "1e7,1e11,0.01\n2e7,1.1e11,0.02\n")   # no header
    with pytest.raises(InputError, match=r"0 < A <= 1 .*value 5.0 at p = 10000000.0 Pa.*"
                                         r"not percent"):
        target("percent.csv", "pressure_Pa,value\n1e7,5\n2e7,20\n3e7,60\n", "A")
    with pytest.raises(InputError, match="0 < A <= 1"):
        Target([1.0, 2.0], [0.5, 1.5], "A")
    # accepted: pressure-first names with units, a trailing comma, A up to 1
    for header in ("p,K", "p [Pa],K [Pa/m]", "Pressure (Pa),stiffness", "mean_pressure,value"):
        assert target("ok.csv", f"{header}\n1e7,1e11\n2e7,1.1e11\n").pressure.size == 2
    assert target("trail.csv", "pressure_Pa,value,\n1e7,1e11,\n2e7,1.1e11,\n").values[1] == 1.1e11
    assert target("full.csv", "p,A\n1e7,0.5\n2e7,1\n", "A").values[-1] == 1.0


def test_target_csv_header_names_the_quantity(tmp_path):
    """A header 'p [Pa],A' (a valid header, listed in read_target_csv's docstring) was read
    as K: the quantity came only from a # comment, --quantity or the default K. Now the
    value column's name says it, and a conflict with --quantity or the comment is an
    InputError naming both."""
    from roughfe.errors import FileFormatError
    rows = "1e7,0.01\n2e7,0.02\n"

    def read(header, quantity=None, comment=""):
        path = tmp_path / "t.csv"
        path.write_text(comment + header + "\n" + rows)
        return read_target_csv(path, quantity).quantity

    for header, q in (("p [Pa],A", "A"), ("p,A*", "A"), ("pressure,area_fraction", "A"),
                      ("p,a", "A"), ("p,A_r/A_n", "A"), ("p,K", "K"), ("p [Pa],K [Pa/m]", "K"),
                      ("p,K_Pa_per_m", "K"), ("Pressure (Pa),stiffness", "K"),
                      ("pressure_Pa,value", "K"), ("p,amplitude", "K"),     # K: the default
                      # "per unit area" qualifies K (was refused as naming both); Ar/An is
                      # the usual area-fraction notation (was read as the default K)
                      ("p,stiffness_per_unit_area_Pa_per_m", "K"),
                      ("p,K (contact stiffness per area)", "K"),
                      ("p,area-normalised stiffness", "K"), ("p,Ar/An", "A"), ("p,Ar", "A"),
                      ("p,A_r/A_0", "A")):
        assert read(header) == q, header
    assert read("p [Pa],A", "A") == "A" and read("pressure_Pa,value", "A") == "A"
    with pytest.raises(InputError, match=r"the header 'p \[Pa\],A' says contact area fraction "
                                         r".*\(A\) but --quantity K says normal contact "
                                         r"stiffness .*\(K\)"):
        read("p [Pa],A", "K")
    with pytest.raises(InputError, match=r"its comment says normal contact stiffness .*\(K\) "
                                         r"but the header 'p,A' says contact area fraction"):
        read("p,A", comment="# t: normal contact stiffness K = dp/dDelta (Pa/m) vs pressure\n")
    with pytest.raises(FileFormatError, match="names both stiffness K and area A"):
        read("p,A (stiffness)")


def test_a_curve_below_its_first_pressure_is_read_at_its_first_value():
    """The one reading rule (similarity.read_curve) for the score, the objective and the
    figures: linear between computed points, the last value above p_max, the first value
    held below p_1 -- chosen by the solved scores of the designs the optimiser reaches
    with it (docs/theory/06_design.md: the chord of session 26 and a power law, the
    better readings, led the optimiser to worse designs)."""
    from roughfe.genomics.design import Objective
    c = ResponseCurve([2.0, 4.0, 6.0], [20.0, 22.0, 24.0], [0.2, 0.4, 0.5])
    np.testing.assert_allclose(c.at([0.5, 1.0, 3.0, 9.0], "K"), [20.0, 20.0, 21.0, 24.0],
                               rtol=1e-14)
    np.testing.assert_allclose(c.at([1.0, 5.0], "A"), [0.2, 0.45], rtol=1e-14)
    t = Target([1.0, 6.0], [16.0, 24.0], "K")        # the design reads 20 at p = 1: 25 % over
    assert similarity(t, c) == pytest.approx(0.75, abs=1e-14)
    np.testing.assert_allclose(Objective((t,)).residuals(c), [-0.25, 0.0], atol=1e-14)
    p, k = c.points("K")                      # the figures draw what is read
    np.testing.assert_array_equal(p, [0.0, 2.0, 4.0, 6.0])
    np.testing.assert_allclose(k, c.at(p, "K"), rtol=1e-14)


def test_the_reading_rule_derivative_is_exact():
    """read_curve's derivative with moving points (the design Jacobian's chain): against
    central differences, below p_1 (the held value moves with y_1), on a segment and
    above p_max."""
    from roughfe.genomics.similarity import read_curve
    rng = np.random.default_rng(3)
    p0, y0 = np.array([1.0, 1.7, 2.5, 4.0]), np.array([5.0, 6.0, 6.5, 7.0])
    dp, dy = rng.normal(size=(4, 2)), rng.normal(size=(4, 2))
    q = np.array([0.2, 0.6, 1.2, 3.0, 5.0])
    y, jac = read_curve(q, p0, y0, dp, dy)
    np.testing.assert_allclose(y, read_curve(q, p0, y0), rtol=1e-15)
    h = 1e-6
    for m in range(2):
        up = read_curve(q, p0 + h * dp[:, m], y0 + h * dy[:, m])
        down = read_curve(q, p0 - h * dp[:, m], y0 - h * dy[:, m])
        np.testing.assert_allclose(jac[:, m], (up - down) / (2 * h), rtol=1e-7, atol=1e-9)
    assert np.all(np.abs(jac[:2]) > 1e-3)


def test_the_last_target_pressure_is_eq42s_p_max_unless_p_top_says_otherwise():
    """Eq. (4.2) takes the target's last pressure as its pressure at Delta = peak-valley
    amplitude: a curve cut short is stretched onto the wrong range and its own profile
    no longer matches it (measured on a database genome: 7 of 10 points, s = 0.658).
    ``p_top`` gives that pressure; the cut curve then scores 1 against its profile."""
    c = _curve()
    cut = Target(c.pressure[:7], c.stiffness[:7], "K")
    assert cut.p_max == c.pressure[6] and similarity(cut, c) < 0.9
    told = Target(c.pressure[:7], c.stiffness[:7], "K", p_top=c.p_max)
    assert told.p_max == c.p_max
    assert similarity(told, c) == pytest.approx(1.0, abs=1e-14)
    assert similarity(told, c.rescaled(3.0)) == pytest.approx(1.0, abs=1e-14)  # any amplitude
    assert Target.from_dict(told.to_dict()).p_top == c.p_max
    assert "p_top" not in cut.to_dict()                      # files of before: unchanged
    assert told.check_pbar(0.5) == 0.5
    with pytest.raises(InputError, match="pbar must lie inside"):
        told.check_pbar(0.8)                                  # beyond the last point
    for bad in (0.5, np.inf, "x"):
        with pytest.raises(InputError, match=r"p_top .* >= its last pressure 0\.7"):
            Target(c.pressure[:7], c.stiffness[:7], "K", p_top=bad)


def test_target_csv_keeps_p_top(tmp_path):
    """Eq. 4.2's p_max^t of a target that stops early (Target.p_top) is written as a
    comment and read back (write_target_csv dropped it: the file read back was
    stretched onto its last pressure, a different objective)."""
    from dataclasses import replace
    t = replace(linear_then_flat_target(p_max=2.0, pbar=0.5, plateau=4.0, n_points=20),
                p_top=3.5)
    back = read_target_csv(write_target_csv(tmp_path / "t.csv", t))
    assert back.p_top == 3.5 and back.p_max == 3.5
    np.testing.assert_array_equal(back.pressure, t.pressure)
    plain = read_target_csv(write_target_csv(tmp_path / "p.csv", replace(t, p_top=None)))
    assert plain.p_top is None and plain.p_max == t.pressure[-1]
    bad = tmp_path / "bad.csv"
    bad.write_text("# p_top: 3.5e6Pa\npressure_Pa,value\n1e5,0.1\n2e5,0.2\n")
    with pytest.raises(FileFormatError, match=r"line 1: .* p_top '3.5e6Pa', not a number"):
        read_target_csv(bad)
    low = tmp_path / "low.csv"               # below the last pressure: Target's own check
    low.write_text("# p_top: 1.5e5\npressure_Pa,value\n1e5,0.1\n2e5,0.2\n")
    with pytest.raises(InputError, match="p_top"):
        read_target_csv(low)
