"""Reading and writing rough surfaces: native ``.npz``, plain matrices, instrument files.

All readers live in one ordered table, :data:`READERS` (STYLE.md habit 3): the first
entry whose suffixes match the file name reads it; SurfaceTopography's readers are the
last entry and the fallback for every other suffix (30+ instrument formats:
``.x3p .sur .opd .plu .di .datx .xyz ...``), found by :func:`.probe.open_instrument`:
SurfaceTopography picks its reader by content, tried quietly (the readers' prints, logs and
warnings are not shown). Under a suffix one of its formats claims, only that format's
reader is accepted (a cut ``.x3p`` is "damaged or truncated", whatever else its bytes
could be); under any other suffix (``.raw .bin .json``, none) the readers that check no
file signature (:data:`.probe.NO_SIGNATURE`: SRTM ``.hgt``, any file of 2 n^2 bytes;
``.asc``/``.xyz``, any table of numbers) are refused with a :class:`FileFormatError`. A
file none reads is refused in one line; each reader's error is in the exception's notes.
An ``.opd`` shorter than its header announces is read with a
:class:`~roughfe.errors.TruncatedFileWarning`.

Native format (``.npz``, ``format = "roughfe-surface"``, ``version = 1``)
------------------------------------------------------------------------
A numpy ``.npz`` archive (no pickles) with the arrays

``format``    str, ``"roughfe-surface"``
``version``   int, ``1``
``heights``   float64, shape ``(nx,)`` or ``(nx, ny)``, metres, axis 0 = x
``size``      float64, shape ``(ndim,)``, metres (``n * spacing`` per axis)
``periodic``  bool
``metadata``  str, JSON text of the JSON-safe metadata mapping

Plain matrices (``.npy``, ``.txt``, ``.csv``, ``.dat``) carry heights only (taken to be
metres): the physical ``size`` must be given explicitly, and ``periodic`` defaults to
False.

Instrument files are converted to SI: lengths and heights are rescaled from the unit
stored in the file to metres. A file that gives no unit (an ``.xyz`` or ``.asc`` table
of numbers) is read as metres, lengths and heights alike: ``metadata["unit_in_file"]``
is then :data:`ASSUMED_UNIT`, and the command line prints a note saying so. Missing (undefined) points are filled by SurfaceTopography's
harmonic interpolation and their number recorded in ``metadata["filled_points"]``; they
include the points a file marks as not measured whose marker the reader returns as a
height (a ``.sur``'s ``zmin - 2``: :mod:`roughfe.surfaces.nonmeasured`); the
channel read in ``metadata["channel"]`` (index, name, scan direction or None:
:func:`.channels.channel_entry`), the file's channels in ``metadata["channel_table"]``
(the same entries) and, as shown, in ``metadata["channels"]``
(:func:`.channels.channel_label`). Every
instrument format puts the file's stored lines (the fast axis) along x, axis 0 (checked
on the five measured files against readers written by hand:
:mod:`roughfe.surfaces.layout`); a non-square Bruker/Veeco ``.di`` map, which
SurfaceTopography's reader scrambles, is put back in order there
(``metadata["reader_fix"]``).
"""
from __future__ import annotations

import datetime as _dt
import json
import warnings
import zipfile
import zlib
from pathlib import Path

import numpy as np

from ..errors import FileFormatError, InputError, RoughfeError
from ..writers import atomic_path, to_jsonable
from .channels import channel_entry, channel_label, choose_channel
from .file_checks import check_surface_file, numeric_heights, periodic_flag
from .layout import DI_FIX, fix_di_lines
from .nonmeasured import masked, nonmeasured_mask
from .probe import open_instrument, quietly, quote_error, warn_if_shorter_than_announced
from .surface import Surface

NATIVE_FORMAT = "roughfe-surface"
NATIVE_VERSION = 1
#: ``metadata["unit_in_file"]`` of an instrument file that gives no unit: read as metres
ASSUMED_UNIT = "m (assumed: the file gives no unit)"


# -- JSON-safe metadata ------------------------------------------------------------------
#: environment variable naming the folder of the measured instrument files
TOPOGRAPHIES_ENV = "ROUGHFE_TOPOGRAPHIES"


def topographies_folder() -> Path:
    """The folder of the five measured instrument files that the demo, the validation
    studies, the benchmarks and the tests read: ``$ROUGHFE_TOPOGRAPHIES`` when set, else
    ``../shared/data/topographies`` beside the repository checkout. (It may not exist;
    each caller says what it leaves out then.)"""
    import os
    env = os.environ.get(TOPOGRAPHIES_ENV)
    if env:
        return Path(env)
    return Path(__file__).resolve().parents[3] / "shared" / "data" / "topographies"


def json_safe(value, depth=0):
    """Return a JSON-serialisable copy of ``value`` (dicts, lists, numbers, strings).

    For foreign (instrument) metadata: numbers follow the one JSON rule of
    :func:`roughfe.writers.to_jsonable` (non-finite -> None), dates become ISO strings,
    arrays of more than 64 values a shape summary, unknown objects their ``str``, and
    nesting deeper than 8 levels is cut.
    """
    if depth > 8:
        return str(value)
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return to_jsonable(float(value))
    if isinstance(value, (_dt.datetime, _dt.date)):
        return value.isoformat()
    if isinstance(value, np.ndarray):
        return json_safe(value.tolist(), depth + 1) if value.size <= 64 else f"array{value.shape}"
    if isinstance(value, dict):
        return {str(k): json_safe(v, depth + 1) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_safe(v, depth + 1) for v in value]
    return str(value)


# -- native npz --------------------------------------------------------------------------
def _single_channel(path, channel, what):
    if channel is not None:
        raise InputError(f"--channel/channel={channel!r} selects a channel of a multi-channel "
                         f"instrument file; {path} is {what} with one height field")


def _read_native(path, size, periodic, channel):
    _single_channel(path, channel, "a roughfe .npz surface")
    if Path(path).is_file() and not zipfile.is_zipfile(path):
        raise FileFormatError(f"{path}: cannot read as a roughfe .npz (truncated or not a "
                              f"zip archive, which an .npz is: another format?)")
    try:
        with np.load(path, allow_pickle=False) as data:
            keys = set(data.files)
            missing = {"format", "version", "heights", "size", "periodic", "metadata"} - keys
            if missing:
                raise FileFormatError(
                    f"{path}: not a roughfe surface file (missing arrays {sorted(missing)}); "
                    f"a plain height matrix should be saved as .npy with an explicit size")
            fmt, version = str(data["format"]), int(data["version"])
            if fmt != NATIVE_FORMAT or version > NATIVE_VERSION:
                raise FileFormatError(
                    f"{path}: format {fmt!r} version {version} is not readable by this roughfe "
                    f"(reads {NATIVE_FORMAT!r} up to version {NATIVE_VERSION})")
            heights = np.array(data["heights"])
            file_size = tuple(float(s) for s in np.atleast_1d(data["size"]))
            file_periodic = periodic if periodic is not None else periodic_flag(
                data["periodic"], path)         # an override is not read from the file
            metadata = json.loads(str(data["metadata"]))
            if not isinstance(metadata, dict):
                raise FileFormatError(f"{path}: its metadata must be a JSON object, got "
                                      f"{type(metadata).__name__} {str(data['metadata'])[:60]!r}")
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile, zlib.error) as exc:
        if isinstance(exc, FileFormatError):
            raise
        reason = ("truncated or not a zip archive" if isinstance(exc, (zipfile.BadZipFile,
                                                                       EOFError)) else exc)
        raise FileFormatError(f"{path}: cannot read as a roughfe .npz ({reason})") from None
    return Surface(numeric_heights(heights, path), file_size if size is None else size,
                   file_periodic if periodic is None else periodic, metadata)


def save_surface(surface: Surface, path) -> Path:
    """Write ``surface`` to ``path`` in the native ``.npz`` format (atomically).

    Parameters
    ----------
    surface : Surface
    path : str or Path
        Target file; the suffix must be ``.npz``.

    Returns
    -------
    Path
    """
    path = Path(path)
    if path.suffix.lower() != ".npz":
        raise InputError(f"save_surface writes the native .npz format; got file name {str(path)!r}")
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            np.savez(fh, format=np.array(NATIVE_FORMAT), version=np.array(NATIVE_VERSION),
                     heights=surface.heights, size=np.asarray(surface.size, dtype=float),
                     periodic=np.array(surface.periodic),
                     metadata=np.array(json.dumps(json_safe(dict(surface.metadata)))))
    return path


# -- plain matrices ----------------------------------------------------------------------
def _plain_surface(heights, path, size, periodic):
    if size is None:
        raise InputError(
            f"{path}: a plain height matrix has no physical size; give size=(LX[, LY]) in metres "
            f"(command line: --size LX [LY])")
    heights = numeric_heights(heights, path)     # a bool .npy was heights of 0 and 1 m
    if heights.ndim in (1, 2) and heights.size < 2:
        raise InputError(f"{path}: a matrix of shape {heights.shape} holds {heights.size} "
                         f"height(s); a profile needs at least 2 points, a surface 2 x 2")
    if heights.ndim == 2 and 1 in heights.shape:
        heights = heights.ravel()
    if np.issubdtype(heights.dtype, np.floating) and not np.isfinite(heights).all():
        bad = ~np.isfinite(heights)
        first = tuple(int(i) for i in np.argwhere(bad)[0])
        raise InputError(
            f"{path}: {int(bad.sum())} of {heights.size} heights are not finite (NaN or "
            f"inf: missing points?), first at index {first}; a plain matrix is read as it "
            f"is: fill them first (instrument files' undefined points are filled by "
            f"harmonic interpolation on reading)")
    return Surface(heights, size, bool(periodic) if periodic is not None else False,
                   {"source": str(path), "reader": "plain matrix"})


def _read_npy(path, size, periodic, channel):
    _single_channel(path, channel, "a plain .npy matrix")
    with open(path, "rb") as fh:
        magic = fh.read(6)
    if magic != b"\x93NUMPY":
        raise FileFormatError(f"{path}: not a .npy file ("
                              + ("the file is empty" if not magic else "no .npy header") + ")")
    try:
        heights = np.load(path, allow_pickle=False)
    except (OSError, ValueError, EOFError) as exc:
        reason = ("an object array (pickled data is never loaded)" if "pickle" in str(exc)
                  else exc)
        raise FileFormatError(f"{path}: cannot read as .npy ({reason})") from None
    return _plain_surface(heights, path, size, periodic)


def _read_text(path, size, periodic, channel):
    _single_channel(path, channel, "a plain text matrix")
    delimiter = "," if Path(path).suffix.lower() == ".csv" else None
    try:
        heights = np.loadtxt(path, delimiter=delimiter, ndmin=2)
    except (OSError, ValueError) as exc:
        raise FileFormatError(f"{path}: cannot read as a plain text matrix ({exc})") from None
    return _plain_surface(heights, path, size, periodic)


# -- SurfaceTopography (instrument files) ---------------------------------------------
def _read_instrument(path, size, periodic, channel):
    try:
        import SurfaceTopography  # noqa: F401
    except ImportError:
        raise FileFormatError(
            f"{path}: reading instrument files needs SurfaceTopography (pip install "
            f"SurfaceTopography); it is not installed") from None
    reader = open_instrument(path)         # quietly; one line when no reader fits
    try:
        with quietly():                    # the readers' numpy warnings, prints, logs
            surface = _instrument_surface(reader, path, size, periodic, channel)
    except RoughfeError:           # ours: already says what is wrong
        raise
    except Exception as exc:       # the reader's own failure on the data (a truncated file)
        raise FileFormatError(
            f"{path}: SurfaceTopography's {reader.format()!r} reader failed on this file's "
            f"data; is it damaged or truncated? ({quote_error(exc)})") from exc
    warn_if_shorter_than_announced(path, reader.format())
    if "size_in_file" in surface.metadata:      # (outside quietly(), which keeps warnings)
        _warn_if_size_overridden(path, size, surface.metadata["size_in_file"])
    return surface


#: A given size within this relative difference of the file's is the file's: float32
#: lengths (6e-8) or a size typed with 4 digits (<= 5e-4), below the ~1 % lateral
#: calibration uncertainty of profilometers.
SIZE_RTOL = 1e-3


def _warn_if_size_overridden(path, size, file_size):
    """Warn that ``size`` (m) replaces the calibrated lateral scale ``file_size`` (m) of an
    instrument file: silent until round 2, session 32 (only ``metadata["size_in_file"]``
    kept the file's)."""
    given = np.atleast_1d(np.asarray(size, dtype=float))
    given = np.broadcast_to(given, (len(file_size),)) if given.size == 1 else given
    if given.shape == (len(file_size),) and np.allclose(given, file_size, rtol=SIZE_RTOL,
                                                        atol=0.0):
        return
    um = " x ".join(f"{s * 1e6:.6g}" for s in file_size)
    warnings.warn(f"{path}: the size given ({' x '.join(f'{s * 1e6:.6g}' for s in given)} "
                  f"um) replaces the file's own physical size ({um} um): every length, slope "
                  f"and wavenumber then follows the given size; leave size/--size out to "
                  f"keep the file's (metadata['size_in_file'] records it)", UserWarning,
                  stacklevel=4)


def _instrument_surface(reader, path, size, periodic, channel):
    ch = choose_channel(reader, channel, path)
    if ch.dim not in (1, 2):
        raise FileFormatError(f"{path}: channel {ch.name!r} has dimension {ch.dim}, not 1 or 2")
    kwargs = {"channel_index": ch.index}
    if ch.physical_sizes is None:
        if size is None:
            raise InputError(f"{path}: the file gives no physical size; give size=(LX[, LY]) "
                             f"in metres (--size)")
        kwargs["physical_sizes"] = tuple(np.atleast_1d(size).astype(float))
    unit = ch.unit if isinstance(ch.unit, str) else None
    if isinstance(ch.unit, tuple) and len(ch.unit) == 2 and ch.unit[1] is None:
        heights = [f"{c.index} {c.name!r}" for c in reader.channels
                   if isinstance(c.unit, str) or (isinstance(c.unit, tuple)
                                                  and c.unit[-1] is not None)]
        raise FileFormatError(
            f"{path}: channel {ch.index} {ch.name!r} has no height unit (lateral unit "
            f"{ch.unit[0]!r}): its values are not heights (a phase, amplitude or error "
            f"signal), not a topography; height channels of this file: "
            f"{', '.join(heights) or 'none'} (channel=, --channel)")
    if unit is None and isinstance(ch.unit, tuple) and ch.unit and isinstance(ch.unit[0], str):
        unit = ch.unit[0]
    if unit is None:
        kwargs["unit"] = "m"
        unit = ASSUMED_UNIT
    topo, reordered = fix_di_lines(reader, ch, reader.topography(**kwargs))
    marked = nonmeasured_mask(reader, topo)      # a marker the reader kept as a height
    if marked is not None:
        topo = masked(topo, marked)
    filled = 0
    if topo.has_undefined_data:
        filled = int(np.ma.getmaskarray(topo.heights()).sum())
        topo = topo.interpolate_undefined_data()
    topo_m = topo.to_unit("m")
    heights = np.ma.getdata(topo_m.heights()).astype(float)
    file_size = tuple(float(s) for s in np.atleast_1d(topo_m.physical_sizes))
    info = topo.info or {}
    table = [channel_entry(c) for c in reader.channels]
    metadata = {
        "source": str(path), "reader": type(reader).__name__,
        "channel": channel_entry(ch),
        "channels": [channel_label(c) for c in table], "channel_table": table,
        "unit_in_file": unit, "filled_points": filled,
        "instrument": json_safe(info.get("instrument", {})),
    }
    if reordered:
        metadata["reader_fix"] = DI_FIX
    if "acquisition_time" in info:
        metadata["acquisition_time"] = json_safe(info["acquisition_time"])
    if size is not None and ch.physical_sizes is not None:
        metadata["size_in_file"] = list(file_size)
    return Surface(heights, file_size if size is None else size,
                   bool(topo.is_periodic) if periodic is None else periodic, metadata)


# -- the one ordered table ----------------------------------------------------------------
#: (suffixes, reader, description). Order matters: native first (our own format, exact),
#: then plain matrices (need an explicit size), then SurfaceTopography for everything else
#: (``None`` = any suffix). ``.txt``/``.csv`` are plain matrices here; instrument text
#: exports with headers (``.asc``, ``.xyz``) go to SurfaceTopography.
READERS = (
    ((".npz",), _read_native, "roughfe native surface (heights, size, periodic, metadata)"),
    ((".npy",), _read_npy, "plain numpy height matrix in metres (needs size)"),
    ((".txt", ".csv", ".dat"), _read_text, "plain text height matrix in metres (needs size)"),
    (None, _read_instrument, "instrument file via SurfaceTopography.open_topography"),
)


def load_surface(path, size=None, periodic=None, channel=None) -> Surface:
    """Read a profile or surface from ``path`` and return a :class:`Surface` in SI units.

    Parameters
    ----------
    path : str or Path
        ``.npz`` (native), ``.npy``/``.txt``/``.csv``/``.dat`` (plain height matrix in
        metres, axis 0 = x) or any instrument file SurfaceTopography reads (converted
        to metres; one that gives no unit is read as metres, ``metadata["unit_in_file"]
        == ASSUMED_UNIT``).
    size : float or (float, float), optional
        Physical size in metres (``n * spacing`` per axis). Required for plain matrices
        and for instrument files without a size; otherwise it overrides the file's size.
    periodic : bool, optional
        Overrides the periodic flag (default: the file's flag, False for plain matrices).
    channel : int or str, optional
        Channel index or name of a multi-channel instrument file (default: the file's
        default channel, usually the first height channel). A name that several channels
        share (di-1: trace and retrace 'Height') is refused: give the index. The channel
        read is ``metadata["channel"]``, every channel of the file (index, name and the
        scan direction where the file gives one) ``metadata["channel_table"]``, their
        labels ``metadata["channels"]``.

    Returns
    -------
    Surface

    Raises
    ------
    InputError
        Missing or unreadable file, missing size for a plain matrix, unknown channel.
    FileFormatError
        The file cannot be parsed.
    """
    path = check_surface_file(path)     # a file this user may read, not empty
    suffix = path.suffix.lower()
    for suffixes, reader, _ in READERS:
        if suffixes is None or suffix in suffixes:
            return reader(path, size, periodic, channel)
    raise FileFormatError(f"{path}: no reader for suffix {suffix!r}")  # unreachable: fallback
