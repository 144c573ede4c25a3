"""Finding the reader of an instrument file (roughfe.surfaces.probe): a cut file is
"damaged or truncated", not what a reader without file signature makes of its bytes; the
readers say nothing on the terminal while they are tried; a file none reads is one short
line, with each reader's error in the exception's notes; an .opd shorter than its header
announces is read with a warning (a user's review)."""
import logging
import warnings

import numpy as np
import pytest

from roughfe.cli import main
from roughfe.errors import FileFormatError, TruncatedFileWarning
from roughfe.surfaces import load_surface


def _cut(topographies_dir, tmp_path, name, n_bytes, stem="tiny"):
    path = tmp_path / f"{stem}{(topographies_dir / name).suffix}"
    path.write_bytes((topographies_dir / name).read_bytes()[:n_bytes])
    return path


@pytest.mark.parametrize("name", ["x3p-2.x3p", "sur-2.sur", "plu-1.plu", "opd-1.opd"])
def test_a_cut_file_is_damaged_not_an_srtm_grid(topographies_dir, tmp_path, name):
    """200 bytes are 2 x 10^2: SurfaceTopography's SRTM reader opens them as a 10 x 10
    grid; the message said "its content matches SurfaceTopography's 'hgt' reader
    instead". It names the suffix's own reader and its error now."""
    path = _cut(topographies_dir, tmp_path, name, 200)
    suffix = path.suffix
    with pytest.raises(FileFormatError) as info:
        load_surface(path)
    message = str(info.value)
    assert message.startswith(f"{path} is not a readable {suffix} file: damaged or "
                              f"truncated? (SurfaceTopography's '{suffix[1:]}' reader: ")
    assert "hgt" not in message and "instead" not in message and len(message) < 400
    notes = "\n".join(info.value.__notes__)
    assert "'hgt' reader opened it, but it checks no file signature" in notes
    assert info.value.__cause__ is not None       # the suffix's own reader's error


def test_content_of_another_signed_format_is_named(topographies_dir, tmp_path):
    """An x3p file named .sur: the x3p reader recognises it by its signature; that is
    worth saying (a misnamed file), unlike a reader that takes any bytes."""
    path = tmp_path / "scan.sur"
    path.write_bytes((topographies_dir / "x3p-2.x3p").read_bytes())
    with pytest.raises(FileFormatError, match=r"scan\.sur is not a readable \.sur file \(its "
                                              r"content matches SurfaceTopography's 'x3p' "
                                              r"reader instead"):
        load_surface(path)


def test_the_readers_say_nothing_while_they_are_tried(topographies_dir, tmp_path, capfd,
                                                      caplog):
    """A cut .opd: a reader of Igor files logged a binary line `could not reshape data
    from (1701996742,) to b'\\x00...'` on stderr before roughfe's error. Now stderr is the
    one error line (at the file descriptors, as a terminal shows it)."""
    path = _cut(topographies_dir, tmp_path, "opd-1.opd", 200)
    disabled = logging.root.manager.disable
    assert main(["info", str(path)]) == 2
    out, err = capfd.readouterr()
    assert out == "" and "reshape" not in err + caplog.text
    assert err.count("\n") == 1 and err.startswith("roughfe info: error: ")
    assert logging.root.manager.disable == disabled      # logging as it was


def test_reader_warnings_are_not_shown(tmp_path, capfd):
    """SurfaceTopography's XYZ reader divides by zero while it finds the grid of a 2 x 2
    table (numpy's RuntimeWarning with its file and line was printed); the file reads."""
    path = tmp_path / "grid.xyz"
    path.write_text("0 0 1\n1 0 2\n0 1 3\n1 1 4\n")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        s = load_surface(path)
    assert s.shape == (2, 2)
    assert not [w for w in caught if "SurfaceTopography" in w.filename], caught
    assert "RuntimeWarning" not in capfd.readouterr().err


def test_a_file_no_reader_opens_is_one_short_line(tmp_path, capsys):
    """README.md: the message listed every reader's exception on one 2.5 kB line. Now
    it says why in short, with the formats read; the readers' errors are in the notes."""
    path = tmp_path / "README.md"
    path.write_text("# Measured topographies\n\nReal instrument files, copied unchanged.\n")
    with pytest.raises(FileFormatError) as info:
        load_surface(path)
    message = str(info.value)
    assert message.startswith(f"no reader recognises {path} (its suffix .md names no "
                              f"topography format; known formats: roughfe .npz")
    assert ".x3p" in message and "tried" not in message and len(message) < 600
    notes = info.value.__notes__
    assert len(notes) >= 20 and "tried SurfaceTopography's 'xyz' reader" in notes[0]
    assert main(["info", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "no reader recognises" in err and len(err) < 700
    (tmp_path / "README").write_bytes(path.read_bytes())
    with pytest.raises(FileFormatError, match=r"\(the file name has no suffix; known"):
        load_surface(tmp_path / "README")


def test_an_opd_shorter_than_its_header_announces_warns(topographies_dir, tmp_path):
    """Cut to 1.5 of its 4.0 MB, opd-1.opd still has its height block, and was read
    without a word; its directory announces 4 020 870 bytes (exactly the whole file)."""
    whole = topographies_dir / "opd-1.opd"
    path = _cut(topographies_dir, tmp_path, "opd-1.opd", 1_500_000, stem="cut")
    with pytest.warns(TruncatedFileWarning, match=r"cut\.opd is shorter than its header "
                                                  r"announces \(1500000 of 4020870 bytes\)"):
        cut = load_surface(path)
    with warnings.catch_warnings():
        warnings.simplefilter("error", TruncatedFileWarning)
        full = load_surface(whole)
    np.testing.assert_array_equal(cut.heights, full.heights)
