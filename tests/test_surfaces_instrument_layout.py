"""The layout of instrument files: the stored lines are along x (axis 0), the sizes per axis
are the file's (roughfe.surfaces.layout). Independent readers written here: a Nanoscope
.di file built byte by byte, the raw blocks of di-1, x3p-2 and sur-2 read by hand."""
import struct
import xml.etree.ElementTree as ET
import zipfile

import numpy as np
import pytest

from roughfe.surfaces.io import load_surface, topographies_folder
from roughfe.surfaces.layout import DI_FIX, di_lines_from_reader

pytest.importorskip("SurfaceTopography")

DATA = topographies_folder()
#: m per LSB of the synthetic .di: Z scale 65.536 V / 2^16 LSB x Zsens 20 nm/V
LSB = 65.536 / 65536 * 20e-9


def write_di(path, block, scan_nm, bpp=2):
    """A Nanoscope (V7) .di file of one height channel: ``block`` (shape ``(lines,
    samps/line)``, the lines in file order, in LSB of 16 bits; stored as int16, or as
    int32 times 65536 with ``bpp=4``), scan size ``scan_nm`` = (along the line, across
    the lines) in nm."""
    ny, nx = block.shape
    offset = 8192
    header = [r"\*File list", r"\Version: 0x07200000", r"\Data length: 8192",
              r"\*Equipment list", r"\Description: synthetic",
              r"\*Scanner list", r"\@Sens. Zsens: V 20.00000 nm/V",
              r"\*Ciao scan list", r"\Samps/line: %d" % nx, r"\Lines: %d" % ny,
              r"\*Ciao image list", r"\Data offset: %d" % offset,
              r"\Data length: %d" % (bpp * nx * ny), r"\Bytes/pixel: %d" % bpp,
              r"\Samps/line: %d" % nx, r"\Number of lines: %d" % ny,
              r"\Scan Size: %g %g nm" % tuple(scan_nm), r"\Line Direction: Trace",
              r'\@2:Image Data: S [Height] "Height"',
              r"\@2:Z scale: V [Sens. Zsens] (0.005035400 V/LSB) 65.53600 V",
              r"\*File list end"]
    text = ("\r\n".join(header) + "\r\n").encode("latin-1")
    with open(path, "wb") as fh:
        fh.write(text + b"\x1a" * (offset - len(text)))
        values = np.asarray(block) * (65536 if bpp == 4 else 1)
        fh.write(values.astype("<i2" if bpp == 2 else "<i4").tobytes())


def sloped_block(nx, ny, slope=40):
    """``slope`` LSB per sample along each line, and line offsets that vary irregularly
    from line to line (a scan line's own level)."""
    k = np.arange(ny)[:, None]
    return slope * np.arange(nx)[None, :] + (37 * k ** 2) % 101


@pytest.mark.parametrize("nx, ny, scan, bpp", [(16, 8, (400.0, 200.0), 2),
                                               (8, 16, (100.0, 300.0), 2),
                                               (24, 10, (600.0, 600.0), 2),
                                               (16, 8, (400.0, 200.0), 4)])
def test_non_square_di_keeps_its_scan_lines_along_x(tmp_path, nx, ny, scan, bpp):
    # round 2, session 35: SurfaceTopography's DIReader gave a (ny, nx) grid, the size
    # along the lines on the axis of the lines and each line's points scattered over rows
    block = sloped_block(nx, ny)
    path = tmp_path / "rect.di"
    write_di(path, block, scan, bpp)
    surface = load_surface(path)
    assert surface.shape == (nx, ny)
    assert surface.size == pytest.approx((scan[0] * 1e-9, scan[1] * 1e-9), rel=1e-12,
                                         abs=0)
    expected = LSB * block[::-1, :].T          # line k of the file at j = ny - 1 - k
    np.testing.assert_allclose(surface.heights, expected, rtol=0, atol=1e-12 * LSB)
    # the slope along x is the lines' own, the same on every line
    np.testing.assert_allclose(np.diff(surface.heights, axis=0), 40 * LSB, rtol=1e-12)
    assert surface.metadata["reader_fix"] == DI_FIX


def test_square_di_is_read_as_surfacetopography_reads_it(tmp_path):
    from SurfaceTopography import open_topography
    block = sloped_block(12, 12)
    path = tmp_path / "square.di"
    write_di(path, block, (300.0, 300.0))
    surface = load_surface(path)
    theirs = open_topography(str(path)).topography().to_unit("m")
    np.testing.assert_array_equal(surface.heights, theirs.heights())
    np.testing.assert_allclose(surface.heights, LSB * block[::-1, :].T, rtol=1e-12)
    assert "reader_fix" not in surface.metadata


def test_di_lines_from_reader_undoes_the_readers_reshape():
    nx, ny = 7, 5
    block = np.arange(nx * ny, dtype=float)         # file order
    theirs = np.fliplr(block.reshape(nx, ny).T)      # DIReader.topography's array
    fixed = di_lines_from_reader(theirs, nx, ny)
    assert fixed.shape == (nx, ny)
    for k in range(ny):                              # file line k, along x at j = ny-1-k
        np.testing.assert_array_equal(fixed[:, ny - 1 - k], block[k * nx:(k + 1) * nx])


def _need(name):
    path = DATA / name
    if not path.is_file():
        pytest.skip(f"{path} not present")
    return path


def test_di1_lines_are_the_files_lines():
    path = _need("di-1.di")
    text = path.read_bytes()[:40960].decode("latin-1")
    image = text.split(r"\*Ciao image list")[1]
    field = {k.strip("\\ "): v.strip() for k, _, v in
             (line.partition(":") for line in image.splitlines() if ":" in line)}
    nx, ny = int(field["Samps/line"]), int(field["Number of lines"])
    block = np.fromfile(path, dtype="<i2", count=nx * ny,
                        offset=int(field["Data offset"])).reshape(ny, nx).astype(float)
    mine = block[::-1, :].T
    surface = load_surface(path, channel=0)
    a = (mine - mine.mean()) / mine.std()
    b = (surface.heights - surface.heights.mean()) / surface.heights.std()
    assert np.abs(a - b).max() < 1e-10
    # Scan Size: 500 500 nm
    assert surface.size == pytest.approx((500e-9, 500e-9), rel=1e-12, abs=0)


def test_x3p2_is_x_fastest_with_its_own_increments():
    path = _need("x3p-2.x3p")
    with zipfile.ZipFile(path) as z:
        root = ET.fromstring(z.read("main.xml"))
        axes = root.find("Record1/Axes")
        dims = root.find("Record3/MatrixDimension")
        nx, ny = int(dims.find("SizeX").text), int(dims.find("SizeY").text)
        data = np.frombuffer(z.read(root.find("Record3/DataLink/PointDataLink").text),
                             dtype="<f8")[:nx * ny]
    surface = load_surface(path)
    np.testing.assert_array_equal(surface.heights, data.reshape(ny, nx).T)
    increments = [float(axes.find(f"{c}/Increment").text) for c in ("CX", "CY")]
    assert surface.size == pytest.approx((nx * increments[0], ny * increments[1]),
                                         rel=1e-12, abs=0)


def test_sur2_lines_of_563_points_are_along_x():
    path = _need("sur-2.sur")
    raw = path.read_bytes()
    bits, = struct.unpack_from("<H", raw, 98)                # Digital Surf header
    nx, ny = struct.unpack_from("<ii", raw, 108)
    dx, dy, dz = struct.unpack_from("<fff", raw, 120)
    block = np.frombuffer(raw[len(raw) - nx * ny * bits // 8:],
                          dtype="<i4" if bits == 32 else "<i2").reshape(ny, nx)
    surface = load_surface(path)
    assert surface.shape == (nx, ny) == (563, 484)
    assert surface.size == pytest.approx((nx * dx * 1e-3, ny * dy * 1e-3), rel=1e-6,
                                         abs=0)                      # mm in the file
    measured = block.T > block.min()                          # zmin - 2 marks no data
    a, b = block.T[measured] * dz * 1e-3, surface.heights[measured]
    assert np.abs((a - a.mean()) - (b - b.mean())).max() < 1e-9 * b.std()


@pytest.mark.parametrize("name", ["sur-2.sur", "opd-1.opd", "plu-1.plu"])
def test_non_square_files_are_continuous_along_both_axes(name):
    surface = load_surface(_need(name))
    h = surface.heights - surface.heights.mean()
    nx, ny = h.shape
    rough = [np.diff(h, axis=a).std() / h.std() for a in (0, 1)]
    other = h.T.reshape(-1).reshape(nx, ny).T                  # lines of ny points
    assert max(rough) < 0.5                                    # 0.0014-0.48 measured
    assert np.diff(other, axis=1).std() / h.std() > 0.9        # 0.98-1.50 measured


def test_di1_fast_axis_is_x_trace_and_retrace_are_offset_along_x():
    # the trace and retrace sweeps of a line run in opposite directions along the fast
    # axis: their offset (the piezo's hysteresis, a delay) lies along it (theory/01)
    path = _need("di-1.di")
    trace = load_surface(path, channel=0).detrended("lines-tilt").heights
    retrace = load_surface(path, channel=1).detrended("lines-tilt").heights
    inner = (slice(16, -16), slice(16, -16))
    a = trace[inner]

    def corr(sx, sy):
        b = np.roll(np.roll(retrace, sx, 0), sy, 1)[inner]
        return (a * b).sum() / np.sqrt((a * a).sum() * (b * b).sum())
    best = max((corr(sx, sy), sx, sy) for sx in range(-8, 9) for sy in range(-3, 4))
    assert best[1:] == (6, 1)                   # 6 samples along x, 1 line along y
    assert best[0] > 0.998 > corr(0, 0)
