"""What :func:`roughfe.surfaces.io.load_surface` asks of a surface file and of the values
read from it, before they become a :class:`~roughfe.surfaces.surface.Surface`.

Found by the fresh-eyes audit of bad input (round 2, session 37): a ``.npz`` whose
``periodic`` entry was ``"no"`` or ``0.5`` was read as periodic (by truthiness); a file
without read permission was said to be damaged (each reader failed in its own words),
``/dev/null`` not to exist, and ``/proc/cpuinfo`` (size 0 on disk) to be empty.
"""
from __future__ import annotations

import os
import stat
from pathlib import Path

import numpy as np

from ..errors import FileFormatError, InputError, check_bool


#: what a path is that is neither a folder nor a regular file
_NOT_REGULAR = ((stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                (stat.S_ISFIFO, "a named pipe (FIFO)"), (stat.S_ISSOCK, "a socket"))


def check_surface_file(path) -> Path:
    """``path`` as a Path, or an error unless it is a regular file this user may read, and
    not empty: :class:`InputError` for a missing file (or a broken symbolic link), a
    folder, a device, pipe or socket (``/dev/null`` was said not to exist), a file
    without read permission (before round 2, session 37 each reader gave its own wrong
    cause: a ``.npz`` "truncated or not a zip archive", an ``.x3p`` "damaged or
    truncated?"), :class:`FileFormatError` for an empty file, :class:`InputError` for a
    kernel file of size 0 (``/proc/cpuinfo``: no file on disk; :func:`_refuse_empty`)."""
    path = Path(path)
    try:
        info = path.stat()
    except PermissionError:             # is_dir() and is_file() raise it too
        raise InputError(f"cannot read surface file {path}: permission denied (on a "
                         f"folder of its path)") from None
    except OSError:                     # missing, or a path below a file
        if path.is_symlink():
            raise InputError(f"surface file {str(path)!r} is a broken symbolic link (to "
                             f"{os.readlink(path)})") from None
        raise InputError(f"surface file {str(path)!r} does not exist") from None
    mode = info.st_mode
    if stat.S_ISDIR(mode):
        raise InputError(f"surface file {str(path)!r} is a folder, not a file")
    if not stat.S_ISREG(mode):          # /dev/null said "does not exist" (session 37)
        kind = next((k for test, k in _NOT_REGULAR if test(mode)), "a special file")
        raise InputError(f"surface file {str(path)!r} is {kind}, not a regular file")
    if not os.access(path, os.R_OK):
        raise InputError(f"cannot read surface file {path}: permission denied")
    if info.st_size == 0:
        _refuse_empty(path)
    return path


#: the kernel's file systems: their files are made on reading, and reading one may
#: consume it (``/proc/kmsg`` hands each kernel message to one reader)
KERNEL_FOLDERS = ("/proc", "/sys")


def _refuse_empty(path: Path) -> None:
    """Raise for a regular file of size 0: :class:`FileFormatError` when it is empty,
    :class:`InputError` when it is a kernel interface, made on reading (``/proc/cpuinfo``
    was said to be "empty", round 2, session 37). A file under :data:`KERNEL_FOLDERS` is
    refused without reading it (reading ``/proc/kmsg`` as root took a message from the
    kernel's log, until session 39); elsewhere (another mount of such a file system, a
    FUSE file) one byte is read, without waiting (``O_NONBLOCK``)."""
    give = "give a surface file (.npz, a height matrix or an instrument file)"
    real = os.path.realpath(path)
    kernel = [top for top in KERNEL_FOLDERS if real.startswith(top + os.sep)]
    if kernel:
        raise InputError(f"surface file {str(path)!r} is no file on disk: a file of "
                         f"{kernel[0]} (size 0 bytes), made by the kernel on reading (not "
                         f"read); {give}")
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    try:
        data = os.read(fd, 1)
    except BlockingIOError:
        data = None
    finally:
        os.close(fd)
    if data == b"":
        raise FileFormatError(f"{path}: the file is empty")
    gives = "gives data" if data else "waits for data"
    raise InputError(f"surface file {str(path)!r} is no file on disk: its size is 0 bytes, "
                     f"yet reading it {gives}, made on the fly (a kernel interface, as the "
                     f"files of /proc); {give}")


#: what heights of a non-numeric dtype are, by numpy's dtype kind
_NOT_NUMBERS = {"b": "booleans", "c": "complex numbers", "U": "text", "S": "text",
                "O": "Python objects", "M": "dates or times", "m": "dates or times",
                "V": "records"}


def numeric_heights(heights, path) -> np.ndarray:
    """``heights`` (a plain matrix or a ``.npz``'s, metres) as an array, or an
    :class:`InputError` naming the dtype unless they are real numbers, integer or
    floating-point: a boolean ``.npy`` was read as heights of 0 and 1 m, text of digits
    as its numbers (round 2, session 37)."""
    heights = np.asarray(heights)
    if heights.dtype.kind not in "iuf":
        what = _NOT_NUMBERS.get(heights.dtype.kind, "no numbers")
        raise InputError(f"{path}: the heights are {what} (dtype {heights.dtype}); a "
                         f"surface's heights are real numbers in metres, of an integer or "
                         f"floating-point dtype (a mask or a flag map is no topography)")
    return heights


def _shown(a: np.ndarray) -> str:
    """``text 'no'``, ``float64 0.5``, ``an array of shape (2,)``: a value read from a
    file, for an error message."""
    if a.size != 1:
        return f"an array of shape {a.shape}"
    kind = {"U": "text", "S": "text", "O": "an object"}.get(a.dtype.kind, a.dtype.name)
    return f"{kind} {a.item()!r}" if kind != "text" else f"text {str(a.item())!r}"


def periodic_flag(value, path) -> bool:
    """The ``periodic`` entry of a native ``.npz`` as a bool: a bool, or the integer 1 or
    0, of one element (:func:`~roughfe.surfaces.io.save_surface` has always written
    ``np.array(bool)``); anything else (text such as ``"no"``, ``0.5``, ``2``, several
    values) is a :class:`FileFormatError` naming what was found."""
    a = np.asarray(value)
    try:
        return check_bool("periodic", a)
    except InputError:
        pass
    raise FileFormatError(
        f"{path}: its 'periodic' entry is {_shown(a)}; it must be a bool, True or False "
        f"(the integers 1 or 0 are read as such), as save_surface writes it: give "
        f"--periodic/--non-periodic (periodic=) to read the file as one or the other")
