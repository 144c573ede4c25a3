"""Line levelling of a mirrored window from a file (round 2, session 36).

A mirrored window (:meth:`Surface.mirrored`, ``--mirror``) saved without its metadata (a
``.npy``) and read by ``info``, ``contact``, ``leak`` or ``genome chromosomes`` with
``--detrend lines | lines-tilt`` had each mirrored line levelled in silence: its lines are
measured lines joined to their mirror images, not scan lines. The library
(``band_chromosomes``) refused it since session 35, the commands level on reading and
said nothing. They now warn, from the one check
:func:`roughfe.surfaces.scan_lines.is_mirrored` (heights even about the first row and
column bit for bit, or the metadata); a measured file never is.
"""
import argparse
import warnings

import numpy as np
import pytest

from roughfe.cli import main
from roughfe.surfaces import Surface, save_surface, spectral_surface
from roughfe.surfaces.scan_lines import is_even_mirror, is_mirrored

MIRRORED = "but this map is a mirrored window"
SIZE = (1e-6, 2e-6 / 3)


def _window():
    """A 48 x 32 non-periodic window with offset scan lines along x (rms 30 % of Sq)."""
    h = spectral_surface((48, 32), SIZE, 0.7, rms_height=1e-8, rng=1).heights
    return Surface(h + 3e-9 * np.random.default_rng(3).standard_normal(32)[None, :], SIZE,
                   False)


def _run(tmp_path, capsys, argv):
    capsys.readouterr()
    assert main(argv) == 0
    return capsys.readouterr().err


COMMANDS = {
    "info": ["info"],
    "contact": ["contact", "--pressure", "1e5", "--no-figures", "--quiet"],
    "leak": ["leak", "--pressure", "1e5", "--no-figures", "--quiet"],
    "genome chromosomes": ["genome", "chromosomes", "--steps", "0", "--no-figures",
                           "--quiet"],
}


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_line_levelling_of_a_mirrored_npy_warns(tmp_path, capsys, command):
    """The mirrored window as a plain .npy (no metadata): lines and lines-tilt warn, naming
    what was detected (heights even about the first row and column, the window's 48 x 32
    points), why (the lines are not scan lines) and what to do (level the window before
    mirroring, or --detrend mean); --detrend mean does not; the window itself with
    --detrend lines does not (its lines are the scan lines)."""
    w = _window()
    m = w.mirrored()
    np.save(tmp_path / "m.npy", m.heights)
    save_surface(w, tmp_path / "w.npz")
    size = ["--size", repr(m.size[0]), repr(m.size[1])]

    def err(name, mode, extra=()):
        out = ["-o", str(tmp_path / f"o_{name}_{mode}")] if command != "info" else []
        return _run(tmp_path, capsys, [*COMMANDS[command], str(tmp_path / name), "--detrend",
                                       mode, *extra, *out])
    for mode in ("lines", "lines-tilt"):
        said = err("m.npy", mode, size)
        assert f"warning: --detrend {mode} levels each scan line along x, {MIRRORED}" in said
        assert "even about the first row and column bit for bit" in said
        assert "a window of 48 x 32 points (1e-06 x 6.667e-07 m)" in said
        assert "not the instrument's scan lines" in said
        assert "Level the measured window before mirroring" in said
        assert MIRRORED not in err("w.npz", mode)
    assert "levels each scan line" not in err("m.npy", "mean", size)


def test_saved_mirrored_metadata_warns_and_the_scan_line_advice_says_mirrored(tmp_path,
                                                                             capsys):
    """A roughfe .npz of Surface.mirrored() keeps the metadata 'mirrored': the warning says
    so. Under --detrend mean the scan-line check fires on the mirrored map's offsets; its
    advice (--detrend lines) would level the mirrored lines, so it says to level the
    window before mirroring instead."""
    save_surface(_window().mirrored(), tmp_path / "m.npz")
    said = _run(tmp_path, capsys, ["info", str(tmp_path / "m.npz"), "--detrend", "lines"])
    assert f"{MIRRORED} (its metadata says so)" in said
    said = _run(tmp_path, capsys, ["info", str(tmp_path / "m.npz")])
    assert "the scan lines along x (heights[:, j]) look offset" in said
    assert f"; {MIRRORED} (its metadata says so): level the measured window before " \
           f"mirroring" in said


def test_no_measured_file_is_taken_for_a_mirrored_window(topographies_dir, capsys):
    """The five measured files as their readers give them: none is even about its first
    row and column, so --detrend lines on them says nothing of mirroring (the CLI's path,
    plausible_surface); each one's mirror image, rebuilt without its metadata, is."""
    from roughfe.cli.surface_warnings import plausible_surface
    from roughfe.surfaces import load_surface
    args = argparse.Namespace(command="info", periodic=None)
    for name in ("di-1.di", "opd-1.opd", "plu-1.plu", "sur-2.sur", "x3p-2.x3p"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            s = load_surface(topographies_dir / name)
        assert not is_even_mirror(s.heights) and not is_mirrored(s), name
        capsys.readouterr()
        plausible_surface(args, s, "lines")
        assert "mirrored" not in capsys.readouterr().err, name
        m = s.mirrored()
        assert is_even_mirror(m.heights) and is_mirrored(Surface(m.heights, m.size, False))


def test_info_table_row_gives_the_warnings_advice_on_a_mirrored_window(tmp_path, capsys):
    """`info`'s table row of the scan-line check advised "(--detrend lines)" on a mirrored
    window too (round 2, session 36), where the warning on stderr says that levelling its
    lines is wrong: it now gives the warning's advice, level the measured window before
    mirroring, also under --detrend plane, whose levelled heights are no longer even bit
    for bit (the row judges the map as read, as the warning does). The window itself keeps
    "(--detrend lines)"."""
    w = _window()
    m = w.mirrored()
    np.save(tmp_path / "m.npy", m.heights)
    save_surface(w, tmp_path / "w.npz")
    size = ["--size", repr(m.size[0]), repr(m.size[1])]

    def row(*argv):
        capsys.readouterr()
        assert main(["info", *map(str, argv)]) == 0
        out = capsys.readouterr()
        lines = [x for x in out.out.splitlines() if x.startswith("scan-line check R")]
        assert len(lines) == 1
        return lines[0], out.err

    for mode in ("mean", "plane"):
        said, err = row(tmp_path / "m.npy", "--detrend", mode, *size)
        assert "the scan lines look offset (a mirrored window: level the measured window " \
               "before mirroring)" in said and "--detrend lines" not in said
        assert "level the measured window before mirroring" in err
    said, _ = row(tmp_path / "w.npz")
    assert said.endswith("the scan lines look offset (--detrend lines)")
