"""Finding the SurfaceTopography reader of an instrument file, quietly, and saying in one
short line why none fits.

SurfaceTopography picks its reader by content: ``open_topography`` tries its ~30 readers in
turn and takes the first that opens the file. :func:`open_instrument` does the same with
two changes. The readers that claim the file's suffix are tried first, and what the readers
print, log or warn while they are tried (a reader of Igor files logs ``could not reshape
data from (1701996742,) to b'\\x00...'`` on a cut ``.opd``; the XYZ reader's numpy warns
``divide by zero``) is captured by :func:`quietly`, never shown. When the file is refused,
the :class:`~roughfe.errors.FileFormatError` says why in one line; each reader's own error
is in the exception's notes (``__notes__``) and the error of the suffix's own reader is its
``__cause__`` (there is no verbose option whose output they would go to).

The readers of :data:`NO_SIGNATURE` check no file signature: they read anything of the
right length or characters. They are never the answer for a suffix that another reader
claims (a ``.x3p`` cut to 200 bytes is 2 x 10^2 bytes, which the SRTM ``.hgt`` reader
takes as a 10 x 10 grid: it is a damaged or truncated ``.x3p``), and under a suffix no
reader claims they are refused with the list of formats read.
"""
from __future__ import annotations

import contextlib
import io
import logging
import struct
import warnings
from pathlib import Path

from ..errors import FileFormatError, TruncatedFileWarning

#: SurfaceTopography readers that check no file signature, with what they accept: under
#: a suffix no format claims they read anything of the right length or characters
#: (8 bytes of text in x.json as a 2 x 2 grid, 256^2 float64 values in heights.raw as a
#: 512 x 512 surface of 5.12e8 m, until round 2, session 25); under a suffix another
#: reader claims, a cut file of 2 n^2 bytes (a .x3p of 200 bytes) as an n x n grid
NO_SIGNATURE = {"hgt": "an SRTM .hgt grid is any file of 2 n^2 bytes",
                "asc": "any table of numbers", "xyz": "any table of numbers"}

#: characters of a reader's own error quoted in a message (the rest is in the notes)
QUOTE = 160


@contextlib.contextmanager
def quietly():
    """Run SurfaceTopography's readers without a word on the terminal.

    Yields a list that receives, when the block ends, what they said: their stdout and
    stderr (Python level), their log records (``logging`` is disabled meanwhile and its
    level restored after) and their warnings, as text lines."""
    said: list = []
    out = io.StringIO()
    disabled = logging.root.manager.disable
    with warnings.catch_warnings(record=True) as caught, \
            contextlib.redirect_stdout(out), contextlib.redirect_stderr(out):
        warnings.simplefilter("always")
        logging.disable(logging.CRITICAL)
        try:
            yield said
        finally:
            logging.disable(disabled)
            said.extend(line for line in out.getvalue().splitlines() if line.strip())
            said.extend(f"{w.category.__name__}: {w.message} "
                        f"({Path(w.filename).name}:{w.lineno})" for w in caught)


def _claims(reader, suffix) -> bool:
    return suffix == reader.format() or suffix in reader.file_extensions()


def quote_error(exc) -> str:
    text = " ".join(f"{type(exc).__name__}: {exc}".split())
    return text if len(text) <= QUOTE else text[:QUOTE - 3] + "..."


def _known_formats() -> str:
    """The formats :func:`roughfe.surfaces.io.load_surface` reads, for a message."""
    from SurfaceTopography.IO import readers

    from .io import READERS     # at call time: io imports this module
    ours = {s.lstrip(".") for suffixes, _, _ in READERS if suffixes for s in suffixes}
    known = sorted({e for r in readers for e in (r.format(), *r.file_extensions())} - ours)
    return ("roughfe .npz, a plain height matrix .npy .txt .csv .dat (metres, with "
            "--size/size=), or an instrument file ." + " .".join(known))


def _refusal(message, tried, said, cause=None) -> FileFormatError:
    """A FileFormatError with ``message``; every reader's error and what the readers said
    as notes, ``cause`` as ``__cause__``."""
    err = FileFormatError(message)
    for name, exc in tried:
        err.add_note(f"tried SurfaceTopography's {name!r} reader: {type(exc).__name__}: {exc}")
    if said:
        err.add_note("the readers said (not shown): " + " | ".join(said))
    err.__cause__ = cause
    return err


def _damaged(path, suffix, owner_failure, tried, said, taken_by=None) -> FileFormatError:
    """The suffix's own reader failed: a damaged or truncated file of that format."""
    name, exc = owner_failure
    message = (f"{path} is not a readable .{suffix} file: damaged or truncated? "
               f"(SurfaceTopography's {name!r} reader: {quote_error(exc)})")
    err = _refusal(message, tried, said, exc)
    if taken_by:
        err.add_note(f"SurfaceTopography's {taken_by!r} reader opened it, but it checks no "
                     f"file signature ({NO_SIGNATURE[taken_by]}): not taken for a "
                     f".{suffix} file")
    return err


def open_instrument(path):
    """The SurfaceTopography reader of ``path`` (a ``ReaderBase``), or a FileFormatError.

    The readers that claim the suffix are tried first, then the others in
    SurfaceTopography's order (:data:`SurfaceTopography.IO.readers`), all inside
    :func:`quietly`. Accepted: a reader that claims the suffix; a reader that checks a file
    signature, when no reader claims the suffix. Refused, with one line: a suffix whose
    own reader fails (damaged or truncated, whatever a reader of :data:`NO_SIGNATURE`
    makes of the bytes), a suffix claimed by another format than the content's, a reader
    of :data:`NO_SIGNATURE` under a suffix no reader claims, and a file no reader opens.
    """
    from SurfaceTopography.IO import readers

    path = Path(path)
    suffix = path.suffix.lower().lstrip(".")
    owners = [r for r in readers if _claims(r, suffix)]
    order = owners + [r for r in readers if r not in owners]
    tried, reader = [], None
    with quietly() as said:
        for candidate in order:
            try:
                reader = candidate(str(path))
                break
            except Exception as exc:        # noqa: BLE001 - ST raises many types
                tried.append((candidate.format(), exc))
    own_failure = tried[0] if owners and tried else None
    if reader is None:
        if own_failure:
            raise _damaged(path, suffix, own_failure, tried, said)
        what = (f"its suffix .{suffix} names no topography format" if suffix
                else "the file name has no suffix")
        raise _refusal(f"no reader recognises {path} ({what}; known formats: "
                       f"{_known_formats()})", tried, said)
    fmt = reader.format()
    if owners and not _claims(reader, suffix):
        if fmt in NO_SIGNATURE:
            raise _damaged(path, suffix, own_failure, tried, said, taken_by=fmt)
        raise _refusal(f"{path} is not a readable .{suffix} file (its content matches "
                       f"SurfaceTopography's {fmt!r} reader instead: a .{fmt} file "
                       f"misnamed?)", tried, said, own_failure[1])
    if not owners and fmt in NO_SIGNATURE:
        raise _refusal(
            f"{path}: its suffix {path.suffix or '(none)'!r} names no format, and "
            f"SurfaceTopography's {fmt!r} reader took its content, which checks no file "
            f"signature ({NO_SIGNATURE[fmt]}). Give the file its format's suffix: "
            f"{_known_formats()}", tried, said)
    return reader


# -- a file shorter than its header announces -------------------------------------------
def _opd_announced_bytes(path):
    """Bytes a Wyko OPD file announces: 2 header bytes, then its directory block and the
    blocks it lists, back to back, each with its length in the directory (opd-1.opd:
    4 020 870 bytes, exactly). None when the directory cannot be read."""
    with open(path, "rb") as fh:
        fh.read(2)

        def length():
            entry = fh.read(24)      # 16 bytes name, int16 type, int32 length, uint16 attr
            if len(entry) < 24:
                raise ValueError("short directory")
            return struct.unpack("<hlH", entry[16:])[1]
        try:
            directory = length()
            if directory <= 0 or directory % 24:
                return None
            return 2 + directory + sum(max(length(), 0) for _ in range(directory // 24 - 1))
        except (ValueError, struct.error):
            return None


#: format -> the bytes its header announces (a reader of a cut file can succeed when the
#: blocks it reads lie before the cut: an .opd cut to 1.5 of its 4.0 MB was read without
#: a word); formats whose header gives no total are not checked
ANNOUNCED_BYTES = {"opd": _opd_announced_bytes}


def warn_if_shorter_than_announced(path, fmt) -> None:
    """A :class:`~roughfe.errors.TruncatedFileWarning` when ``path`` (read by the
    ``fmt`` reader) has fewer bytes than its header announces: the heights were read
    whole (the reader found them), the blocks after the cut are missing."""
    count = ANNOUNCED_BYTES.get(fmt)
    announced = count(path) if count else None
    size = Path(path).stat().st_size
    if announced is not None and size < announced:
        warnings.warn(TruncatedFileWarning(
            f"{path} is shorter than its header announces ({size} of {announced} bytes): a "
            f"truncated copy? Its heights lie before the cut and were read whole; the "
            f"blocks after the cut (instrument metadata) are missing"), stacklevel=2)
