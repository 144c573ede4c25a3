"""`contact` and `leak` on a file with a trace and a retrace channel (di-1) say the
sweeps' reliability cutoff in a `note:` line and keep info's `reliability` block in
results.json (`inputs.reliability`); no number they compute changes (the same heights
saved as a .npz, which has no pair, give the same steps, no note and `null`); x3p-2 (one
channel) gets neither. Measured effect of the scales below the cutoff on di-1:
docs/theory/01_surfaces.md."""
import json

import pytest

from roughfe.cli import main
from roughfe.surfaces.io import load_surface, save_surface
from roughfe.surfaces.reliability import slope_share_above

NOTE = ("note: trace/retrace reliable to q < 592.7 rad/um (wavelengths > 0.0106 um) along "
        "x, the fast axis; 1 'Height' (Retrace) is 0 'Height' (Trace) shifted by -6.79 "
        "samples")
#: di-1 with the plane removed: most of the slope beyond q_c is across the lines
SHARES = ("beyond it lie 7.84 % of the mean-square slope along x and 84.2 % along y "
          "(across the lines)")


def _results(folder):
    return json.loads((folder / "results.json").read_text())


def test_contact_on_di1_notes_the_cutoff_and_keeps_its_numbers(topographies_dir, tmp_path,
                                                               capsys):
    di = topographies_dir / "di-1.di"
    run = ["--detrend", "plane", "--pressure", "8e6", "--no-figures", "-o"]
    assert main(["contact", str(di), *run, str(tmp_path / "di")]) == 0
    out = capsys.readouterr().out
    assert NOTE in out and "(10.9 pixels)" in out and "0.000977 um" in out
    assert SHARES in out
    doc = _results(tmp_path / "di")
    block = doc["inputs"]["reliability"]
    # the slope shares are of the map contact solves (the plane removed), along x and y
    plane = load_surface(di).detrended("plane")
    for axis in "xy":
        assert block[f"slope_share_{axis}"] == pytest.approx(
            slope_share_above(plane, block["q_cutoff"], axis), rel=1e-12, abs=0)
    # info's block under the same --detrend (the coherence is of the heights as read, and
    # levels each line: the same to round-off; the shares are of the detrended map)
    assert main(["info", str(di), "--detrend", "plane", "--json"]) == 0
    info = json.loads(capsys.readouterr().out)["reliability"]
    assert block.keys() == info.keys() and abs(block["q_cutoff"] / 5.927e8 - 1) < 2e-3
    for key, value in info.items():
        assert (block[key] == pytest.approx(value, rel=1e-12, abs=0)
                if isinstance(value, float) else block[key] == value), key
    # the same heights without the pair: the same steps, no note, null
    npz = save_surface(load_surface(di), tmp_path / "di.npz")
    assert main(["contact", str(npz), *run, str(tmp_path / "npz")]) == 0
    out = capsys.readouterr().out
    assert "trace/retrace" not in out
    other = _results(tmp_path / "npz")
    assert other["inputs"]["reliability"] is None
    for key in ("area_fraction", "stiffness", "mean_gap", "delta"):
        assert other["steps"][0][key] == doc["steps"][0][key]


def test_contact_with_mirror_reads_the_cutoff_of_the_window(topographies_dir, tmp_path,
                                                           capsys):
    """--mirror solves the mirrored period; the cutoff is the measured window's."""
    assert main(["contact", str(topographies_dir / "di-1.di"), "--mirror", "--pressure",
                 "8e6", "--no-figures", "-o", str(tmp_path / "m")]) == 0
    assert NOTE in capsys.readouterr().out
    block = _results(tmp_path / "m")["inputs"]["reliability"]
    assert block["points"] == 506 and block["lines"] == 512


def test_leak_on_di1_notes_the_cutoff(topographies_dir, tmp_path, capsys):
    assert main(["leak", str(topographies_dir / "di-1.di"), "--pressure", "8e6",
                 "--no-reynolds", "--no-figures", "-o", str(tmp_path / "l")]) == 0
    out = capsys.readouterr().out
    assert NOTE in out and "the junctions that set Q" in out
    assert ("beyond it lie 7.88 % of the mean-square slope along x and 84.3 % along y"
            in out)                                   # leak's default --detrend mean
    block = _results(tmp_path / "l")["inputs"]["reliability"]
    assert block["integer_lag"] == -6 and block["channels"][1] == "1 'Height' (Retrace)"


def test_x3p2_has_no_note_and_null(topographies_dir, tmp_path, capsys):
    x3p = str(topographies_dir / "x3p-2.x3p")
    assert main(["contact", x3p, "--detrend", "plane", "--pressure", "8e5", "--no-figures",
                 "-o", str(tmp_path / "c")]) == 0
    assert main(["leak", x3p, "--detrend", "plane", "--pressure", "8e5", "--no-reynolds",
                 "--no-figures", "-o", str(tmp_path / "l")]) == 0
    assert "trace/retrace" not in capsys.readouterr().out
    for name in ("c", "l"):
        assert _results(tmp_path / name)["inputs"]["reliability"] is None


def test_the_note_without_a_cutoff_gives_the_row_only():
    """Sweeps coherent to the Nyquist wavenumber, or a pair that cannot be compared: the
    row's words, no claim about finer scales."""
    from roughfe.cli.info_reliability import reliability_note
    block = {"channels": ["0 'Height' (Trace)", "1 'Height' (Retrace)"], "q_cutoff": None,
             "threshold": 0.25, "axis": "x", "lag": 2.0, "lag_length": 2e-9,
             "reliable_anywhere": True}
    note = reliability_note(block, 1e-9, "contact area")
    assert note.startswith("note: trace/retrace reliable to the pixel (coherence >= 0.25")
    assert "noise" not in note and "slope" not in note
    # with a cutoff the shares are said; NaN ones (a map flat along an axis) are not
    cut = {**block, "q_cutoff": 5e8, "wavelength_cutoff": 2 * 3.14159e-9 / 0.5,
           "slope_share_x": 0.25, "slope_share_y": 0.5}
    assert ("beyond it lie 25 % of the mean-square slope along x and 50 % along y "
            "(across the lines)") in reliability_note(cut, 1e-9, "contact area")
    assert "slope" not in reliability_note({**cut, "slope_share_y": float("nan")}, 1e-9,
                                           "contact area")
    note = reliability_note({"channels": block["channels"], "error": "too few lines"}, 1e-9,
                            "contact area")
    assert note == "note: trace/retrace reliable to n/a (too few lines)"
    assert reliability_note(None, 1e-9, "contact area") == ""
