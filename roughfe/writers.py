"""Every file roughfe writes goes through here: atomic, umask-honouring, JSON-safe.

* :func:`atomic_path` -- write to a temporary file beside the target, ``fsync`` it, then
  rename it (``os.replace`` is atomic on POSIX within one file system) and ``fsync`` the
  folder: an interrupted run, or a power loss, never leaves a half-written or empty file
  under the target's name. The file gets the mode a plain ``open()`` would give
  (``0o666 & ~umask``: 0644 under umask 022), not ``mkstemp``'s private 0600.
* :func:`to_jsonable` -- the ONE JSON rule of the package: numpy scalars and arrays
  become numbers and lists, paths strings, and non-finite floats (NaN, +-inf) ``null``.
  :func:`write_json` and :func:`to_json_text` apply it.
* :class:`OutputFolder` -- the ownership contract of a command that writes a folder
  (checked before the work, lock, ``UNFINISHED`` marker, no files of two runs mixed);
  :func:`output_file` the same check for a command that writes one file.
"""
from __future__ import annotations

import contextlib
import dataclasses
import datetime as _dt
import errno
import json
import math
import os
import shutil
import tempfile
import time
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from ._runtime import remove_dead_writers_files, writer_prefix
from .errors import InputError

#: Prefix of every temporary file (``.roughfe-<tag>-<pid>-<8 random characters>.tmp<suffix>``,
#: :func:`roughfe._runtime.writer_prefix`): short, so that a target name of any legal
#: length (255 bytes) still has a legal temporary name.
TMP_PREFIX = ".roughfe-"
_MAX_TMP_SUFFIX = 16
#: folders already cleared of dead writers' temporaries by this process
_SWEPT = set()


def current_umask() -> int:
    """The process umask, read without changing it where Linux allows (``/proc``)."""
    with contextlib.suppress(OSError, ValueError):
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    old = os.umask(0o022)  # pragma: no cover - non-Linux fallback
    os.umask(old)
    return old


@contextlib.contextmanager
def atomic_path(path, suffix=None):
    """Yield a temporary path beside ``path``; rename it onto ``path`` on success.

    Use it for writers that want a file name (``np.savez``, ``h5py.File``, matplotlib
    ``savefig``, pyvista ``screenshot``). On an exception the temporary file is removed
    and ``path`` is left untouched. The final file has mode ``0o666 & ~umask``; it is
    ``fsync``-ed before the rename and its folder after it, so that after a power loss
    ``path`` holds the old content or the new, never an empty or partial file.

    Parameters
    ----------
    path : path-like
        The target file; its folder is created if missing.
    suffix : str, optional
        Suffix of the temporary name (writers that infer the format from it); default
        the target's suffix (dropped if longer than 16 characters).
    """
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"cannot create folder {path.parent}: {exc.strerror}") from None
    suffix = path.suffix if suffix is None else suffix
    if len(suffix) > _MAX_TMP_SUFFIX:
        suffix = ""
    folder = os.path.abspath(path.parent)
    if folder not in _SWEPT:   # a killed writer's temporary goes (once per folder and process)
        _SWEPT.add(folder)
        remove_dead_writers_files(folder, TMP_PREFIX)
    try:
        fd, tmp = tempfile.mkstemp(prefix=writer_prefix(TMP_PREFIX), suffix=f".tmp{suffix}",
                                   dir=path.parent)
    except OSError as exc:
        raise InputError(f"cannot write in {path.parent}: {exc.strerror}") from None
    os.close(fd)
    try:
        yield Path(tmp)
        _fsync(tmp)            # the data on disk before the name: never an empty renamed file
        os.chmod(tmp, 0o666 & ~current_umask())
        os.replace(tmp, path)
        _fsync(path.parent, os.O_DIRECTORY)     # and the rename itself
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def _fsync(path, flags=0):
    """``fsync`` the file or folder ``path``: its content (or, for a folder, its entries)
    reaches the disk before we go on. A folder whose file system refuses it is left as is
    (the file's own fsync, which must work, is what matters most)."""
    try:
        fd = os.open(path, os.O_RDONLY | flags)
    except OSError:
        if flags:
            return
        raise
    try:
        os.fsync(fd)
    except OSError:
        if not flags:
            raise
    finally:
        os.close(fd)


# -- the one JSON rule -----------------------------------------------------------------
def to_jsonable(obj):
    """A JSON-ready copy of ``obj``: THE rule of every roughfe JSON file.

    ``None``, ``bool``, ``int`` and ``str`` pass; floats pass when finite and become
    ``None`` (JSON ``null``) when NaN or infinite (JSON has no NaN/inf, and a reader must
    not mistake an undefined value for a number); numpy scalars and arrays become Python
    numbers and (nested) lists by the same rule; mappings become dicts with ``str`` keys;
    tuples, lists and sets lists; paths strings; dates ISO strings; objects with a
    ``to_dict()`` method and dataclasses their dict. Anything else (complex numbers,
    arbitrary objects) raises ``TypeError``: it has no faithful JSON form.
    """
    if obj is None or isinstance(obj, (bool, str)):
        return obj
    if isinstance(obj, int):
        return int(obj)
    if isinstance(obj, float):
        return finite_or_none(obj)
    if isinstance(obj, np.ndarray):
        if np.iscomplexobj(obj):
            raise TypeError(f"a complex array {obj.shape} has no JSON form")
        return to_jsonable(obj.tolist())
    if isinstance(obj, np.generic):
        return to_jsonable(obj.item())
    if isinstance(obj, Mapping):
        return {str(to_jsonable(k)) if not isinstance(k, str) else k: to_jsonable(v)
                for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, (set, frozenset)):
        return [to_jsonable(v) for v in sorted(obj, key=repr)]
    if isinstance(obj, os.PathLike):
        return os.fspath(obj)
    if isinstance(obj, (_dt.datetime, _dt.date)):
        return obj.isoformat()
    if callable(getattr(obj, "to_dict", None)):
        return to_jsonable(obj.to_dict())
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return to_jsonable({f.name: getattr(obj, f.name) for f in dataclasses.fields(obj)})
    raise TypeError(f"object of type {type(obj).__name__} is not JSON serialisable")


def finite_or_none(value):
    """``float(value)`` when ``value`` is a finite number (a Python or numpy scalar), else
    ``None``: the number rule of :func:`to_jsonable` for one value (NaN and infinities are
    undefined values, JSON ``null``; ``None`` stays ``None``). The one place of the
    idiom; modules that write JSON-safe summaries by hand use it."""
    if value is None:
        return None
    v = float(value)
    return v if math.isfinite(v) else None


def to_json_text(data, indent=2) -> str:
    """JSON text of :func:`to_jsonable` of ``data`` (non-finite floats are ``null``)."""
    return json.dumps(to_jsonable(data), indent=indent, allow_nan=False)


def json_scalars(obj, keys) -> dict:
    """``{key: to_jsonable(getattr(obj, key))}`` for the named attributes of ``obj``."""
    return {key: to_jsonable(getattr(obj, key)) for key in keys}


def write_json(path, data):
    """Write ``data`` as indented JSON (:func:`to_jsonable`), atomically. Returns the path."""
    text = to_json_text(data)
    with atomic_path(path) as tmp:
        tmp.write_text(text + "\n")
    return Path(path)


def write_text(path, text):
    """Write a text file atomically. Returns the path."""
    with atomic_path(path) as tmp:
        tmp.write_text(text)
    return Path(path)


# -- output ownership ------------------------------------------------------------------
#: The record of the run that owns an output folder (command, status, times).
OWNER_FILE = ".roughfe-output.json"
#: Present (and visible) while a run is writing the folder or after it failed/was killed.
UNFINISHED_FILE = "UNFINISHED"
#: Sub-folder holding an earlier run's output while a new run writes: restored when the
#: new run fails or is interrupted (left there with ``keep_partial``), removed when it
#: completes
PREVIOUS_DIR = ".roughfe-previous"
#: flock-ed by the run writing the folder (released by the OS if the process dies).
LOCK_FILE = ".lock"


@contextlib.contextmanager
def folder_lock(folder, holder: str):
    """Hold an exclusive ``flock`` on ``folder/.lock`` or raise :class:`InputError`.

    The OS releases the lock when the process dies, so a killed run never blocks the
    next one. The holder writes ``holder`` (its command) and pid into the lock file; a
    refused command names them. A lock file this user may not open is an InputError too.
    """
    import fcntl

    folder = Path(folder)
    lock = folder / LOCK_FILE
    try:        # "a+", not "w": the holder's record stays while refused
        fh = open(lock, "a+")
    except OSError as exc:   # another user's folder said "Permission denied: OUTDIR/.lock"
        if exc.errno not in (errno.EACCES, errno.EPERM, errno.EROFS):
            raise
        raise InputError(f"cannot write in output folder {folder}: its lock file {lock} "
                         f"cannot be opened for writing ({exc.strerror.lower()}; another "
                         "user's output folder?); choose another output folder") from None
    with fh:
        try:
            fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            fh.seek(0)
            held_by = fh.read(300).strip()
            raise InputError(f"another {held_by or holder} is writing to {folder} (it holds "
                             f"{lock}); wait for it or choose another output folder") from None
        fh.seek(0)
        fh.truncate()
        fh.write(f"{holder} (pid {os.getpid()})\n")
        fh.flush()
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


def _read_owner(folder: Path):
    with contextlib.suppress(OSError, ValueError):
        data = json.loads((folder / OWNER_FILE).read_text())
        if isinstance(data, dict):
            return data
    return None


def _relative_files(folder: Path) -> list:
    """Every file below ``folder`` (relative, sorted) but the lock and the owner record."""
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*")
                  if not p.is_dir() and p.name not in (LOCK_FILE, OWNER_FILE)
                  and PREVIOUS_DIR not in p.relative_to(folder).parts)


def _added_files(folder: Path, owner) -> list:
    """Files in a completed output folder that its run did not write (a user's own files:
    never removed without --overwrite). Empty for a run that did not complete."""
    if not owner or owner.get("status") != "complete" or "files" not in owner:
        return []
    return sorted(set(_relative_files(folder)) - set(owner["files"]))


def _refuse_to_clear(folder: Path):
    """Folders ``--overwrite`` must never empty: /, home, the working directory (or an
    ancestor of it) and a version-controlled checkout."""
    real = folder.resolve()
    cwd = Path.cwd().resolve()
    if real == Path(real.anchor) or real == Path.home().resolve() or real == cwd \
            or real in cwd.parents or (real / ".git").exists():
        raise InputError(f"refusing to clear {folder}: it is the file-system root, the home "
                         "folder, the working directory (or above it) or a git checkout; "
                         "choose a dedicated output folder")


def _clear(folder: Path, keep=(LOCK_FILE,)):
    for entry in folder.iterdir():
        if entry.name in keep:
            continue
        if entry.is_dir() and not entry.is_symlink():
            shutil.rmtree(entry)
        else:
            entry.unlink()


def _set_aside(folder: Path) -> bool:
    """Move an earlier run's output into ``folder/PREVIOUS_DIR`` (a killed run's leftover
    there is dropped first: its folder was marked unfinished); True when there was any."""
    previous = folder / PREVIOUS_DIR
    if previous.exists():
        shutil.rmtree(previous)
    entries = [e for e in folder.iterdir() if e.name != LOCK_FILE]
    if not entries:
        return False
    previous.mkdir()
    for entry in entries:
        os.rename(entry, previous / entry.name)
    return True


def _restore(folder: Path) -> None:
    """Drop what the failed run wrote and put the earlier output back."""
    previous = folder / PREVIOUS_DIR
    _clear(folder, keep=(LOCK_FILE, PREVIOUS_DIR))
    for entry in previous.iterdir():
        os.rename(entry, folder / entry.name)
    previous.rmdir()


class OutputFolder:
    """The ownership contract of a command that writes a folder (docs/guide/02_command_line.md).

    ``OutputFolder(folder, command, overwrite=...)`` checks, writing nothing, that the
    folder can be taken: not an existing file, creatable and writable, not locked by
    another run, and empty, or written by an earlier run of the same ``command`` (with
    no file added since, when that run completed: its file list is recorded), or any
    other content with ``overwrite`` (never /, home, the working directory or a git
    checkout). Create it before a long computation, so bad output arguments fail at once.

    ``with OutputFolder(...) as out:`` then takes the folder for the writes:

    * it is locked (:func:`folder_lock`) until the block ends;
    * its old content is set aside in ``.roughfe-previous`` (no file of two runs ever
      sits side by side; stale temporary files of a killed run go with it);
    * ``UNFINISHED`` exists and ``.roughfe-output.json`` says ``"status": "running"``
      until the block returns normally; then ``UNFINISHED`` and the old content are
      removed and the status is ``"complete"``. A killed run never leaves a folder that
      looks complete (its ``.roughfe-previous`` goes with the next run). When the block
      raises (a bad value found during the work, a solver failure, Ctrl-C), a folder
      this run created is removed again and an older folder gets its old content back
      (an earlier complete output survives a failed rerun); a folder that was empty
      keeps ``UNFINISHED`` and ``"status": "failed"`` with the error (``"interrupted"``
      for Ctrl-C, KeyboardInterrupt).
    * ``keep_partial=True`` (``roughfe validate``, whose studies each finish a report):
      when the block raises, what the run wrote stays, with ``UNFINISHED`` and
      ``"status": "interrupted"`` (Ctrl-C) or ``"failed"`` with the error; an older
      run's files stay set aside in ``.roughfe-previous`` (never beside the new ones;
      the next run drops them, as after a kill).
    """

    def __init__(self, folder, command: str, *, overwrite: bool = False,
                 keep_partial: bool = False):
        if not str(folder).strip():    # `-o "$UNSET"` wrote there (round 2, session 37)
            raise InputError(f"output must name a folder, got {str(folder)!r} (the results "
                             "would be written into the working directory)")
        self.path = Path(folder)
        self.command = command
        self.overwrite = overwrite
        self.keep_partial = keep_partial
        self._check(self.path)
        # the command's work starts here (checked before the computation), not when the
        # folder is taken for the writes
        self._started, self._t0 = _now(), time.perf_counter()

    def _check(self, folder: Path):
        if folder.exists() and not folder.is_dir():
            raise InputError(f"output {folder} is an existing file; -o takes a folder here "
                             "(the command writes several files)")
        if not folder.is_dir():
            _probe_writable(folder)
            return
        if (folder / LOCK_FILE).exists():
            with folder_lock(folder, f"`roughfe {self.command}` (or another roughfe run)"):
                pass  # free now; taken for the writes by __enter__
        entries = [e.name for e in folder.iterdir() if e.name != LOCK_FILE]
        owner = _read_owner(folder) if entries else None
        added = _added_files(folder, owner)
        if entries and (owner is None or owner.get("command") != self.command or added):
            if not self.overwrite:
                what = ("not a roughfe output folder" if owner is None else
                        f"the output of `roughfe {owner.get('command')}`"
                        if owner.get("command") != self.command else
                        f"an output of `roughfe {self.command}` with files it did not write "
                        f"({', '.join(added[:3])})")
                raise InputError(
                    f"output folder {folder} is not empty and is {what} ({len(entries)} "
                    f"entries, e.g. {sorted(entries)[0]!r}); choose a new or empty folder, "
                    "or pass --overwrite to replace its contents")
            _refuse_to_clear(folder)
        _probe_writable(folder)

    def __enter__(self) -> Path:
        folder = self.path
        self._check(folder)
        self._created = not folder.exists()
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise InputError(f"cannot create output folder {folder}: {exc.strerror}") from None
        self._lock = contextlib.ExitStack()
        self._lock.enter_context(folder_lock(folder, f"`roughfe {self.command}`"))
        self._kept = _set_aside(folder)
        self._record = {"command": self.command, "status": "running", "pid": os.getpid(),
                        "started": self._started, "writing": _now()}
        write_text(folder / UNFINISHED_FILE,
                   f"`roughfe {self.command}` started {self._record['started']} and has not "
                   "finished: the files here are incomplete. Rerun the command to replace "
                   "them.\n")
        write_json(folder / OWNER_FILE, self._record)
        return folder

    def __exit__(self, kind, exc, tb):
        folder = self.path
        try:
            if kind is None:
                if self._kept:
                    shutil.rmtree(folder / PREVIOUS_DIR)
                (folder / UNFINISHED_FILE).unlink()
                write_json(folder / OWNER_FILE, {
                    **self._record, "status": "complete", "finished": _now(),
                    "elapsed_s": time.perf_counter() - self._t0,
                    "files": _relative_files(folder)})
            elif self.keep_partial or not (self._created or self._kept):
                with contextlib.suppress(Exception):   # UNFINISHED stays
                    write_json(folder / OWNER_FILE, {
                        **self._record, "status": "interrupted" if issubclass(
                            kind, KeyboardInterrupt) else "failed",
                        "error": f"{kind.__name__}: {exc}", "stopped": _now(),
                        "elapsed_s": time.perf_counter() - self._t0})
            elif self._created:
                shutil.rmtree(folder, ignore_errors=True)
            else:
                _restore(folder)
        finally:
            self._lock.close()  # releases the flock (after a removed folder: harmless)
        return False


def _probe_writable(folder: Path) -> None:
    """Raise :class:`InputError` unless ``folder`` is a writable folder or can be created.

    A missing folder is probed by creating and removing a temporary folder in its nearest
    existing parent (permission bits alone do not tell, e.g. for root); an existing one
    by its permissions and mount flags (no probe entry: nothing in it is touched)."""
    existing = next((p for p in (folder, *folder.parents) if os.path.lexists(p)), None)
    if existing is not None and not existing.exists():
        # a link to nothing: it passed here, and mkdir failed ("File exists") after the
        # work (round 2, session 37)
        raise InputError(f"cannot create output folder {folder}: {existing} is a broken "
                         f"symbolic link (to {os.readlink(existing)}); create what it points "
                         "to, or give another path")
    if existing is None or not existing.is_dir():
        raise InputError(f"cannot create output folder {folder}: {existing} is not a folder")
    if existing == folder:  # no probe entry (it would touch the folder's mtime)
        if not os.access(folder, os.W_OK | os.X_OK) or \
                os.statvfs(folder).f_flag & os.ST_RDONLY:
            raise InputError(f"cannot write in output folder {folder} (permission denied or "
                             "read-only file system)")
        return
    try:
        os.rmdir(tempfile.mkdtemp(prefix=TMP_PREFIX, dir=existing))
    except OSError as exc:
        raise InputError(f"cannot create or write output folder {folder}: {exc.strerror} "
                         f"(in {existing})") from None


def _now() -> str:
    return _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")


def output_folder(folder, command: str, *, overwrite: bool = False,
                  keep_partial: bool = False) -> OutputFolder:
    """:class:`OutputFolder` (checked now; ``with`` it to write)."""
    return OutputFolder(folder, command, overwrite=overwrite, keep_partial=keep_partial)


def output_file(path, *, overwrite: bool = False, suffixes=None,
                option: str = "-o/--output") -> Path:
    """Check ``path`` as the output FILE of a command; return it as a ``Path``.

    Refuses a folder, a parent folder that cannot be created or written, an existing
    file unless ``overwrite``, a name longer than 255 bytes, and (with ``suffixes``,
    lower case with the dot) another extension. Nothing is written. ``option`` is the
    command-line option that named the file, for the messages (``info --psd FILE`` was
    told "-o/--output must name a .csv or .png file" until round 2, session 37).
    """
    path = Path(path)
    if len(path.name.encode()) > 255:
        raise InputError(f"output file name is {len(path.name.encode())} bytes long; file "
                         "systems allow at most 255")
    if suffixes and path.suffix.lower() not in suffixes:
        raise InputError(f"{option} must name a {' or '.join(suffixes)} file, got "
                         f"{str(path)!r}")
    if path.is_dir():
        raise InputError(f"output {path} is a folder; {option} takes a file name here")
    if path.exists() and not overwrite:
        raise InputError(f"output file {path} exists; pass --overwrite to replace it")
    _probe_writable(path.parent)
    return path
