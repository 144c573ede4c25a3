"""Reading and writing surfaces: native npz round trip, plain matrices, instrument files."""
import json
import pickle

import numpy as np
import pytest

from roughfe.errors import FileFormatError, InputError
from roughfe.surfaces import Surface, load_surface, save_surface
from roughfe.surfaces.channels import channel_label
from roughfe.surfaces.io import READERS
from roughfe.surfaces.stats import rms_height

# From ../shared/data/topographies/README.md: grid, physical size (m), rms height (m).
# sur-2.sur: the README says 31.2 um, but the file's data unit is mm and its heights have
# a standard deviation of 3.12e-5 mm = 31.2 nm (read with SurfaceTopography's raw
# metadata: data_unit 'mm'); the README's unit is a slip. Its 31.2 nm counts the 117 points
# the file marks as not measured as heights (test_sur_nonmeasured_points_are_filled);
# filled, as roughfe reads them, the rms height is 17.7 nm (asserted there, not here).
# opd-1.opd has 116 undefined points (README: none); they are filled and counted.
MEASURED = {
    "x3p-2.x3p": ((650, 650), (82.98e-6, 204.48e-6), 77.3e-9, "m"),
    "sur-2.sur": ((563, 484), (1.961e-3, 1.686e-3), None, "mm"),
    "opd-1.opd": ((640, 480), (125.9e-6, 94.4e-6), 8.36e-9, "mm"),
    "plu-1.plu": ((768, 576), (1274.9e-6, 956.2e-6), 2.83e-6, "µm"),
    "di-1.di": ((512, 512), (500e-9, 500e-9), 9.95e-9, "nm"),
}


def test_npz_round_trip(tmp_path):
    rng = np.random.default_rng(0)
    s = Surface(rng.standard_normal((9, 7)) * 1e-6, (3e-4, 2e-4), periodic=True,
                metadata={"generator": "test", "seed": 3, "nested": {"a": [1, 2.5]}})
    path = save_surface(s, tmp_path / "s.npz")
    t = load_surface(path)
    np.testing.assert_array_equal(t.heights, s.heights)
    assert t.size == s.size and t.periodic is True and t.metadata == s.metadata
    with np.load(path, allow_pickle=False) as data:          # documented, pickle-free format
        assert str(data["format"]) == "roughfe-surface" and int(data["version"]) == 1
    # profile, and overrides of size / periodic
    p = Surface(np.arange(5.0) * 1e-9, 1e-6)
    q = load_surface(save_surface(p, tmp_path / "p.npz"), size=2e-6, periodic=True)
    assert q.ndim == 1 and q.size == (2e-6,) and q.periodic


def test_save_is_atomic_and_checks_suffix(tmp_path):
    s = Surface(np.zeros((2, 2)), 1.0)
    with pytest.raises(InputError, match="npz"):
        save_surface(s, tmp_path / "s.npy")
    save_surface(s, tmp_path / "s.npz")
    assert [f.name for f in tmp_path.iterdir()] == ["s.npz"]      # no temporary left over


@pytest.mark.parametrize("suffix", [".npy", ".txt", ".csv"])
def test_plain_matrices_need_a_size(tmp_path, suffix):
    h = np.arange(12.0).reshape(4, 3) * 1e-9
    path = tmp_path / f"h{suffix}"
    if suffix == ".npy":
        np.save(path, h)
    else:
        np.savetxt(path, h, delimiter="," if suffix == ".csv" else " ")
    with pytest.raises(ValueError) as info:
        load_surface(path)
    assert "size" in str(info.value) and path.name in str(info.value)
    s = load_surface(path, size=(4e-6, 3e-6))
    np.testing.assert_allclose(s.heights, h, rtol=1e-15)
    assert s.size == (4e-6, 3e-6) and s.periodic is False
    assert load_surface(path, size=1e-6, periodic=True).periodic


def test_bad_files(tmp_path):
    with pytest.raises(InputError, match="does not exist"):
        load_surface(tmp_path / "missing.npz")
    np.savez(tmp_path / "other.npz", x=np.zeros(3))
    with pytest.raises(FileFormatError, match="not a roughfe surface"):
        load_surface(tmp_path / "other.npz")
    np.save(tmp_path / "cube.npy", np.zeros((2, 2, 2)))
    with pytest.raises(ValueError, match=r"\(2, 2, 2\)"):
        load_surface(tmp_path / "cube.npy", size=1.0)
    np.save(tmp_path / "nan.npy", np.array([[0.0, np.nan], [1.0, 2.0]]))
    with pytest.raises(ValueError, match="finite"):
        load_surface(tmp_path / "nan.npy", size=1.0)
    (tmp_path / "junk.xyz9").write_text("not a topography\n")
    with pytest.raises(FileFormatError, match="no reader"):
        load_surface(tmp_path / "junk.xyz9")


def _raw_float64(path):
    np.random.default_rng(0).standard_normal((256, 256)).tofile(path)   # 2 * 512^2 bytes


@pytest.mark.parametrize("name, write, reader", [
    ("heights.raw", _raw_float64, "'hgt'"),                     # read as 512 x 512, 5.12e8 m
    ("x.json", lambda p: p.write_text("abcdefgh"), "'hgt'"),    # read as a 2 x 2 grid
    ("r.bin", lambda p: p.write_bytes(np.random.default_rng(1).bytes(2 * 128 ** 2)), "'hgt'"),
    ("table.foo", lambda p: p.write_text("1 2 3\n4 5 6\n7 8 9\n"), "'xyz'"),
])
def test_unknown_suffix_is_not_read_by_a_reader_without_signature(tmp_path, name, write,
                                                                  reader):
    """SurfaceTopography's SRTM reader takes any file of 2 n^2 bytes, its text readers any
    table of numbers: under a suffix no format claims, they are refused (until round 2,
    session 25 each of these files was a surface and ``roughfe info`` exited 0)."""
    path = tmp_path / name
    write(path)
    with pytest.raises(FileFormatError) as info:
        load_surface(path, size=1e-4)
    message = str(info.value)
    assert name in message and reader in message and "no file signature" in message
    assert ".npy .txt" in message and ".x3p" in message      # the formats accepted


def test_suffix_of_another_format_is_refused(tmp_path):
    """.spm is a suffix of SurfaceTopography's DI reader (not its format name): 8 bytes of
    text there are not a readable .spm, not an SRTM grid (the 'hgt' reader, which checks
    no signature, read them as a 2 x 2 grid: it is not offered as what the file is)."""
    (tmp_path / "scan.spm").write_text("abcdefgh")
    with pytest.raises(FileFormatError, match=r"scan\.spm is not a readable \.spm file: "
                                              r"damaged or truncated\? \(SurfaceTopography's "
                                              r"'di' reader: ") as info:
        load_surface(tmp_path / "scan.spm")
    assert "'hgt'" not in str(info.value)


@pytest.mark.parametrize("name, renamed", [("x3p-2.x3p", "scan.foo"), ("di-1.di", "scan.006")])
def test_signed_instrument_file_reads_under_any_suffix(topographies_dir, tmp_path, name,
                                                       renamed):
    """Readers that recognise a file by its signature (an x3p zip, a Bruker header) still
    read it under a suffix no format claims (Bruker numbers its files .000, .001, ...)."""
    (tmp_path / renamed).write_bytes((topographies_dir / name).read_bytes())
    np.testing.assert_array_equal(load_surface(tmp_path / renamed).heights,
                                  load_surface(topographies_dir / name).heights)


def test_reader_table_is_ordered_with_fallback_last():
    assert READERS[0][0] == (".npz",)
    assert READERS[-1][0] is None and all(r[0] is not None for r in READERS[:-1])


@pytest.mark.parametrize("name", sorted(MEASURED))
def test_instrument_files_in_si(topographies_dir, name):
    shape, size, rms, unit = MEASURED[name]
    s = load_surface(topographies_dir / name)
    assert s.shape == shape
    np.testing.assert_allclose(s.size, size, rtol=2e-3)     # README gives 4 digits
    if rms is not None:
        assert rms_height(s) == pytest.approx(rms, rel=0.01)
    assert s.metadata["unit_in_file"] == unit and not s.periodic
    json.dumps(s.metadata, allow_nan=False)                  # JSON-safe instrument metadata
    t = pickle.loads(pickle.dumps(s))                         # picklable (dask/MPI studies)
    np.testing.assert_array_equal(t.heights, s.heights)
    if name == "opd-1.opd":
        assert s.metadata["filled_points"] == 116


def test_multichannel_choice(topographies_dir):
    path = topographies_dir / "di-1.di"
    first = load_surface(path)
    second = load_surface(path, channel=1)
    by_index = load_surface(path, channel="0")
    assert second.metadata["channel"]["index"] == 1
    np.testing.assert_array_equal(by_index.heights, first.heights)
    assert not np.array_equal(first.heights, second.heights)
    # trace (rms 9.95 nm) and retrace (114 nm) are both 'Height': the name took the
    # first without a word until round 2, session 24; now it is refused with the list
    with pytest.raises(InputError, match=r"2 channels are named 'Height'.*give the channel "
                                         r"index.*0 'Height' \(Trace\), 1 'Height' "
                                         r"\(Retrace\), 2 'Phase'"):
        load_surface(path, channel="Height")
    assert first.metadata["channels"][:2] == ["0 'Height' (Trace)", "1 'Height' (Retrace)"]
    # the scan directions as data (round 2, session 37), the labels made from them
    assert second.metadata["channel"] == {"index": 1, "name": "Height", "direction": "Retrace"}
    assert first.metadata["channel_table"][:3] == [
        {"index": 0, "name": "Height", "direction": "Trace"},
        {"index": 1, "name": "Height", "direction": "Retrace"},
        {"index": 2, "name": "Phase", "direction": "Trace"}]
    assert first.metadata["channels"] == [channel_label(c)
                                          for c in first.metadata["channel_table"]]
    with pytest.raises(InputError, match="out of range"):
        load_surface(path, channel=9)
    with pytest.raises(InputError, match="no channel named"):
        load_surface(path, channel="Nope")


@pytest.mark.parametrize("name, keep", [("sur-2.sur", 0.25), ("opd-1.opd", 0.25),
                                        ("di-1.di", 0.25), ("di-1.di", 0.001)])
def test_truncated_instrument_file_is_a_file_format_error(topographies_dir, tmp_path, name,
                                                         keep):
    """A truncated file: the reader's own failure (a reshape, a short buffer, an index)
    becomes a FileFormatError naming the file, not a traceback from SurfaceTopography."""
    data = (topographies_dir / name).read_bytes()
    cut = tmp_path / name
    cut.write_bytes(data[:max(int(len(data) * keep), 600)])
    with pytest.raises(FileFormatError, match=name.replace(".", r"\.")):
        load_surface(cut)


def test_masked_heights_are_refused_not_unmasked():
    """The values under a mask (a topography's undefined points) are not heights."""
    h = np.ma.masked_array(np.arange(12.0).reshape(3, 4), mask=False)
    h[1, 2] = np.ma.masked
    with pytest.raises(InputError, match=r"masked array with 1 masked .* index \(1, 2\)"):
        Surface(h, (3e-6, 4e-6))
    s = Surface(np.ma.masked_array(np.ones((3, 4)), mask=False), (3e-6, 4e-6))
    assert type(s.heights) is np.ndarray      # no mask set: the data



def test_sur_nonmeasured_points_are_filled_not_read_as_heights(topographies_dir):
    """A Digital Surf file with its special-points flag set marks a point not measured by
    the count zmin - 2 (two below the lowest measured one); SurfaceTopography 1.18's reader
    returns it as a height. sur-2 has 117: read as heights they were 1.25 um deep "pits" on
    a 17.7 nm rms surface (rms 31.2 nm, the README's number; skewness -30). They are filled
    like any undefined point; every other height is the file's."""
    from SurfaceTopography import open_topography
    path = topographies_dir / "sur-2.sur"
    raw_topo = open_topography(str(path)).topography()
    header = raw_topo.info["raw_metadata"]
    assert header["special_points"] == 1
    counts = np.asarray(raw_topo.heights()) / header["height_scale_factor"]
    marker = np.abs(counts - (header["zmin"] - 2)) < 0.5
    s = load_surface(path)
    assert s.metadata["filled_points"] == int(marker.sum()) > 0
    metres = np.asarray(raw_topo.to_unit("m").heights())
    np.testing.assert_array_equal(s.heights[~marker], metres[~marker])      # the file's
    # the filled points lie within the range the header gives the measured ones
    lo, hi = (header[k] * header["height_scale_factor"] * 1e-3 for k in ("zmin", "zmax"))
    assert lo <= s.heights[marker].min() and s.heights[marker].max() <= hi
    # the README's rms height is the one with the markers read as heights
    assert float(np.std(metres)) == pytest.approx(31.2e-9, rel=0.01, abs=0)
    assert rms_height(s) < 0.6 * float(np.std(metres))


@pytest.mark.parametrize("suffix", [".npy", ".txt", ".csv"])
def test_plain_matrix_with_missing_points_names_the_file_and_the_points(tmp_path, suffix):
    """NaN in a plain matrix (missing points) or a 1-point matrix: the error names the file,
    the count and where (it said 'heights must be finite' / 'got shape (1,)' of a (1, 1)
    matrix, without the file)."""
    h = np.arange(12.0).reshape(4, 3) * 1e-9
    h[2, 1] = h[3, 0] = np.nan
    path = tmp_path / f"gaps{suffix}"
    if suffix == ".npy":
        np.save(path, h)
    else:
        np.savetxt(path, h, delimiter="," if suffix == ".csv" else " ")
    with pytest.raises(InputError, match=rf"gaps\{suffix}: 2 of 12 heights are not finite.*"
                                         r"first at index \(2, 1\).*fill them"):
        load_surface(path, size=1e-6)
    np.save(tmp_path / "one.npy", np.zeros((1, 1)))
    with pytest.raises(InputError, match=r"one\.npy: a matrix of shape \(1, 1\) holds 1 "):
        load_surface(tmp_path / "one.npy", size=1e-6)
