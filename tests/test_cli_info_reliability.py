"""`roughfe info`'s row "trace/retrace reliable to" (roughfe.cli.info_reliability): on a
file with a trace and a retrace channel of the quantity read (di-1), the reliability
cutoff of their coherence, its wavelength and the lag; the warning where the Hurst fit
range reaches above it; nothing on single-channel files."""
import json

from roughfe.cli import main
from roughfe.surfaces.io import load_surface, save_surface

ROW = "trace/retrace reliable to    q < 592.7 rad/um (wavelengths > 0.0106 um) along x"
WARNING = "reaches above 592.7 rad/um (wavelength 0.0106 um), where the trace and the retrace"


def test_info_reports_the_trace_retrace_cutoff_of_di1(topographies_dir, capsys):
    di = str(topographies_dir / "di-1.di")
    assert main(["info", di]) == 0
    out, err = capsys.readouterr()
    assert ROW in out
    assert ("1 'Height' (Retrace) is 0 'Height' (Trace) shifted by -6.79 samples "
            "(-0.00663 um)") in out
    # the default fit range (50.27 - 1608 rad/um) reaches above q_c: warned, with the option
    assert WARNING in err and "--hurst-q-range 5.027e+07 5.927e+08 (rad/m)" in err
    # the same row under another --detrend (the coherence levels each line itself); a
    # range below q_c is not warned of
    assert main(["info", di, "--detrend", "lines", "--hurst-q-range", "5e7", "5e8"]) == 0
    out, err = capsys.readouterr()
    assert ROW in out and WARNING not in err
    # the retrace read: the trace is its partner, the lag changes sign
    assert main(["info", di, "--channel", "1", "--detrend", "plane"]) == 0
    out = capsys.readouterr().out
    assert ROW in out and "0 'Height' (Trace) is 1 'Height' (Retrace) shifted by 6.79" in out


def test_info_json_has_the_reliability_block(topographies_dir, capsys):
    assert main(["info", str(topographies_dir / "di-1.di"), "--json"]) == 0
    block = json.loads(capsys.readouterr().out)["reliability"]
    assert abs(block["q_cutoff"] / 5.927e8 - 1) < 2e-3 and block["integer_lag"] == -6
    assert abs(block["wavelength_cutoff"] / 10.60e-9 - 1) < 2e-3
    assert block["channels"] == ["0 'Height' (Trace)", "1 'Height' (Retrace)"]
    assert block["units"]["q_cutoff"].startswith("rad/m") and block["threshold"] == 0.25
    # the shares of the mean-square slope beyond q_c, of the analysed map (--detrend mean)
    assert round(block["slope_share_x"], 4) == 0.0788
    assert round(block["slope_share_y"], 4) == 0.8431
    assert block["units"]["slope_share_y"].startswith("1 (share of the mean-square slope")
    # --detrend lines removes the line offsets, power across the lines at all q_y
    assert main(["info", str(topographies_dir / "di-1.di"), "--detrend", "lines",
                 "--json"]) == 0
    lines = json.loads(capsys.readouterr().out)["reliability"]
    assert lines["q_cutoff"] == block["q_cutoff"]
    assert abs(lines["slope_share_x"] / block["slope_share_x"] - 1) < 1e-9  # x lines' means
    assert round(lines["slope_share_y"], 4) == 0.7131


def test_no_row_without_a_trace_retrace_pair(topographies_dir, tmp_path, capsys):
    """x3p-2 has one channel; a .npz saved from di-1 keeps di-1's channel list in its
    metadata but holds one channel: no row, no warning, reliability null."""
    assert main(["info", str(topographies_dir / "x3p-2.x3p"), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["reliability"] is None
    saved = save_surface(load_surface(topographies_dir / "di-1.di"), tmp_path / "di.npz")
    assert main(["info", str(saved)]) == 0
    out, err = capsys.readouterr()
    assert "trace/retrace" not in out and "retrace" not in err


def test_a_pair_that_cannot_be_compared_is_said_in_the_row(tmp_path):
    """The row says why instead of failing `info` (here the other channel cannot be read:
    a .npz whose metadata claims to be a trace of a two-channel file)."""
    import argparse

    import numpy as np

    from roughfe.cli.info_reliability import reliability_block, reliability_row
    from roughfe.surfaces import Surface
    path = tmp_path / "claims.npz"
    table = [{"index": 0, "name": "Height", "direction": "Trace"},
             {"index": 1, "name": "Height", "direction": "Retrace"}]
    meta = {"source": str(path), "channel": table[0], "channel_table": table,
            "channels": ["0 'Height' (Trace)", "1 'Height' (Retrace)"]}
    surface = Surface(np.random.default_rng(0).normal(size=(64, 64)) * 1e-9, 6.4e-8,
                      periodic=False, metadata=meta)
    save_surface(surface, path)
    args = argparse.Namespace(surface=str(path), size=None, periodic=None, channel=None,
                              scan_axis="x")
    block = reliability_block(args, load_surface(path))
    assert block["channels"] == meta["channels"] and "channel" in block["error"]
    assert reliability_row(block).startswith("trace/retrace reliable to    n/a (")
    # the same claim in the metadata of a roughfe before session 37 (labels only, no
    # direction): the row says that the directions are not stored as data
    del meta["channel_table"]
    meta["channel"] = {"index": 0, "name": "Height"}
    save_surface(Surface(surface.heights, surface.size, False, meta), path)
    block = reliability_block(args, load_surface(path))
    assert block["channels"] == meta["channels"]
    assert "without their scan directions as data" in reliability_row(block)


def test_info_psd_writes_the_coherence_beside_the_psd(topographies_dir, tmp_path, capsys):
    """--psd FILE.csv on di-1 adds FILE_coherence.csv: the curve whose crossing of 1/4 is
    the row's q_c; an existing one is refused (nothing written) without --overwrite;
    x3p-2 (no pair) gets no second file."""
    import numpy as np
    di = str(topographies_dir / "di-1.di")
    psd = tmp_path / "p.csv"
    assert main(["info", di, "--psd", str(psd)]) == 0
    capsys.readouterr()
    lines = (tmp_path / "p_coherence.csv").read_text().splitlines()
    assert lines[0] == "q (rad/m),coherence gamma^2 (-),snr P_S/P_N (-)"
    q, g, snr = np.array([[float(v) for v in row.split(",")] for row in lines[1:]]).T
    assert q.size == 253 and g[0] > 0.99 and g[-1] < 0.05
    assert np.allclose(snr, np.sqrt(g) / (1 - np.sqrt(g)), rtol=1e-5)   # 10 digits
    last = np.flatnonzero(g >= 0.25)[-1]          # the cutoff lies between two rows
    assert q[last] < 5.927e8 < q[last + 1]
    # the PSD file itself is unchanged in form: its first column's kinds only
    assert {row.split(",")[0] for row in psd.read_text().splitlines()[1:]} == {
        "radial", "x", "y"}
    psd.unlink()
    assert main(["info", di, "--psd", str(psd)]) == 2   # the coherence file exists
    assert "p_coherence.csv exists" in capsys.readouterr().err and not psd.exists()
    assert main(["info", di, "--psd", str(psd), "--overwrite"]) == 0
    x3p = tmp_path / "x"
    x3p.mkdir()
    assert main(["info", str(topographies_dir / "x3p-2.x3p"), "--psd",
                 str(x3p / "p.csv")]) == 0
    assert sorted(p.name for p in x3p.iterdir()) == ["p.csv"]


def test_info_psd_figure_gets_the_coherence(topographies_dir, tmp_path, monkeypatch):
    """--psd FILE.png hands the curve to the figure (a panel and q_c marked), and draws."""
    import roughfe.plotting.surfaces as plotting
    seen = {}
    draw = plotting.plot_psd

    def spy(*args, **kwargs):
        seen["coherence"] = kwargs.get("coherence")
        return draw(*args, **kwargs)
    monkeypatch.setattr(plotting, "plot_psd", spy)
    assert main(["info", str(topographies_dir / "di-1.di"), "--psd",
                 str(tmp_path / "p.png")]) == 0
    assert abs(seen["coherence"].q_cutoff / 5.927e8 - 1) < 2e-3
    assert (tmp_path / "p.png").stat().st_size > 10000
