"""Bad surface files that the session-37 audit of bad input found read wrongly or said
wrongly (round 2, session 37, helper aud2): each test fails on the code before its fix."""
import os

import numpy as np
import pytest

from roughfe.cli import main
from roughfe.errors import FileFormatError, InputError
from roughfe.surfaces import Surface, load_surface, save_surface


def _surface():
    return Surface(np.random.default_rng(0).normal(size=(16, 16)) * 1e-6, 1e-4, False)


def _with_periodic(tmp_path, name, value):
    """A roughfe .npz whose 'periodic' entry is ``np.array(value)``."""
    path = save_surface(_surface(), tmp_path / "ok.npz")
    arrays = dict(np.load(path))
    arrays["periodic"] = np.array(value)
    np.savez(tmp_path / name, **arrays)
    return tmp_path / name


@pytest.mark.parametrize("value, shown", [("no", "text 'no'"), ("yes", "text 'yes'"),
                                          ("True", "text 'True'"), (0.5, "float64 0.5"),
                                          (1.0, "float64 1.0"), (2, "int64 2"),
                                          ([True, False], "an array of shape (2,)")])
def test_a_periodic_entry_that_is_no_bool_is_refused(tmp_path, value, shown):
    # 'no', 'yes', 0.5 were all read as periodic (truthiness): a silently wrong reading
    path = _with_periodic(tmp_path, "bad.npz", value)
    with pytest.raises(FileFormatError) as info:
        load_surface(path)
    msg = str(info.value)
    assert str(path) in msg and f"'periodic' entry is {shown}" in msg, msg
    assert "True or False" in msg and "1 or 0" in msg, msg


@pytest.mark.parametrize("value, periodic", [(True, True), (False, False), (1, True),
                                             (0, False), (np.uint8(1), True),
                                             ([True], True), ([0], False)])
def test_a_periodic_entry_that_means_a_bool_is_read(tmp_path, value, periodic):
    assert load_surface(_with_periodic(tmp_path, "p.npz", value)).periodic is periodic
    # the --periodic/--non-periodic override is not read from the file
    assert load_surface(_with_periodic(tmp_path, "q.npz", "no"), periodic=False).periodic \
        is False


def _unreadable(monkeypatch, *paths):
    """``os.access`` answering for ``paths`` as for a user without read permission (root,
    who runs these tests, ignores the mode bits)."""
    import os
    from pathlib import Path
    real, denied = os.access, {Path(p).absolute() for p in paths}

    def access(path, mode, *args, **kwargs):
        if Path(path).absolute() in denied and mode & os.R_OK:
            return False
        return real(path, mode, *args, **kwargs)
    monkeypatch.setattr(os, "access", access)


@pytest.mark.parametrize("value", ["no", "True", 0.5, 2, 1.0, None, [True, False]])
def test_a_periodic_argument_that_is_no_bool_is_refused(tmp_path, value):
    """From Python too: ``Surface(..., periodic="no")`` and ``load_surface(periodic=0.5)``
    were read by truthiness ("no" as periodic); now an InputError naming the value. Fails
    on the code before (round 2, session 37)."""
    h = np.random.default_rng(0).normal(size=(8, 8)) * 1e-9
    with pytest.raises(InputError, match=r"periodic must be a bool, True or False"):
        Surface(h, (1e-6, 1e-6), periodic=value)
    if value is not None:           # None is load_surface's "as the file says"
        save_surface(Surface(h, (1e-6, 1e-6)), tmp_path / "s.npz")
        with pytest.raises(InputError, match=r"periodic must be a bool"):
            load_surface(tmp_path / "s.npz", periodic=value)
    for good, periodic in ((True, True), (np.False_, False), (1, True), (np.int64(0), False)):
        assert Surface(h, (1e-6, 1e-6), periodic=good).periodic is periodic


def test_a_file_without_read_permission_is_said_to_be_unreadable(tmp_path, monkeypatch,
                                                                  topographies_dir, capsys):
    # as user nobody: a .npz said "truncated or not a zip archive", an .x3p "damaged or
    # truncated? (... PermissionError ...)", a .txt "cannot read as a plain text matrix
    # ([Errno 13] ...)", a .npy "Permission denied: X"
    import shutil
    files = [save_surface(_surface(), tmp_path / "s.npz"),
             shutil.copy(topographies_dir / "x3p-2.x3p", tmp_path / "s.x3p")]
    np.save(tmp_path / "s.npy", _surface().heights)
    np.savetxt(tmp_path / "s.txt", _surface().heights)
    files += [tmp_path / "s.npy", tmp_path / "s.txt"]
    _unreadable(monkeypatch, *files)
    for path in files:
        with pytest.raises(InputError) as info:
            load_surface(path, size=1e-4)
        assert str(info.value) == f"cannot read surface file {path}: permission denied"
    capsys.readouterr()
    assert main(["info", str(files[0])]) == 2
    err = capsys.readouterr().err
    assert f"roughfe info: error: cannot read surface file {files[0]}: permission denied" \
        in err and "Traceback" not in err and "zip" not in err


def test_a_path_that_is_no_regular_file_says_what_it_is(tmp_path, capsys):
    # `info /dev/null` said "surface file '/dev/null' does not exist"; a FIFO (which a
    # reader would wait on) and a broken symbolic link said the same
    import os
    os.mkfifo(tmp_path / "pipe.npz")
    (tmp_path / "link.npz").symlink_to(tmp_path / "gone.npz")
    for path, what in (("/dev/null", "is a character device, not a regular file"),
                       (tmp_path / "pipe.npz", "is a named pipe (FIFO), not a regular file"),
                       (tmp_path / "link.npz",
                        f"is a broken symbolic link (to {tmp_path / 'gone.npz'})")):
        with pytest.raises(InputError) as info:
            load_surface(path)
        assert f"surface file {str(path)!r} {what}" in str(info.value)
        assert "does not exist" not in str(info.value)
    capsys.readouterr()
    assert main(["info", "/dev/null"]) == 2
    assert "error: surface file '/dev/null' is a character device, not a regular file" \
        in capsys.readouterr().err
    with pytest.raises(InputError, match="does not exist"):
        load_surface(tmp_path / "missing.npz")


@pytest.mark.skipif(not os.path.exists("/proc/cpuinfo")
                    or os.stat("/proc/cpuinfo").st_size != 0,
                    reason="needs Linux's /proc/cpuinfo (size 0 on disk)")
def test_a_kernel_file_of_size_0_is_no_empty_file(tmp_path, capsys, monkeypatch):
    # `info /proc/cpuinfo` said "the file is empty": its size on disk is 0, yet reading it
    # gives text (made by the kernel on reading). Session 37, helper aud3. Since session
    # 39 a file of /proc or /sys is refused without being read: reading /proc/kmsg as
    # root took a message from the kernel's log
    from roughfe.surfaces import file_checks
    cpu = "/proc/cpuinfo"
    said = (f"surface file {cpu!r} is no file on disk: a file of /proc (size 0 bytes), "
            "made by the kernel on reading (not read)")
    opened = os.open

    def no_open(p, *args, **kwargs):
        assert not str(p).startswith("/proc"), f"{p} was opened"
        return opened(p, *args, **kwargs)
    with monkeypatch.context() as m:
        m.setattr(os, "open", no_open)
        with pytest.raises(InputError) as info:
            load_surface(cpu)
        assert said in str(info.value) and "empty" not in str(info.value)
        capsys.readouterr()
        assert main(["info", cpu]) == 2
        assert f"error: {said}" in capsys.readouterr().err
    for name in ("empty.txt", "empty.npz"):      # a file that is empty still says so
        (tmp_path / name).write_bytes(b"")
        with pytest.raises(FileFormatError, match=f"{name}: the file is empty"):
            load_surface(tmp_path / name, size=1e-4)
    # elsewhere (a kernel file system mounted in another place) one byte is read
    monkeypatch.setattr(file_checks, "KERNEL_FOLDERS", ())
    with pytest.raises(InputError, match="its size is 0 bytes, yet reading it gives data, "
                                         r"made on the fly \(a kernel interface"):
        load_surface(cpu)
    real = os.read

    def read(fd, n):       # as /proc/kmsg without a message: the read would wait
        if os.readlink(f"/proc/self/fd/{fd}") == cpu:
            raise BlockingIOError(11, "Resource temporarily unavailable")
        return real(fd, n)
    monkeypatch.setattr(os, "read", read)
    with pytest.raises(InputError, match="size is 0 bytes, yet reading it waits for data"):
        load_surface(cpu)


@pytest.mark.parametrize("heights, what", [
    (np.eye(4, dtype=bool), "booleans (dtype bool)"),
    (np.eye(4) + 1j, "complex numbers (dtype complex128)"),
    (np.array([["1", "2"], ["3", "4"]]), "text (dtype <U1)"),
    (np.zeros(4, dtype="datetime64[s]"), "dates or times (dtype datetime64[s])")])
def test_heights_that_are_no_real_numbers_are_refused_with_their_dtype(tmp_path, heights,
                                                                       what):
    # a boolean .npy was read as heights of 0 and 1 m, text of digits as their numbers;
    # a complex one was refused without the file's name
    np.save(tmp_path / "h.npy", heights)
    arrays = dict(np.load(save_surface(_surface(), tmp_path / "s.npz")))
    np.savez(tmp_path / "h.npz", **{**arrays, "heights": heights})
    for path in (tmp_path / "h.npy", tmp_path / "h.npz"):
        with pytest.raises(InputError) as info:
            load_surface(path, size=1e-4)
        msg = str(info.value)
        assert msg.startswith(f"{path}: the heights are {what}"), msg
        assert "integer or floating-point" in msg, msg


def test_integer_heights_are_still_read(tmp_path):
    np.save(tmp_path / "i.npy", np.arange(16, dtype=np.int32).reshape(4, 4))
    s = load_surface(tmp_path / "i.npy", size=1e-4)
    assert s.heights.dtype == float and s.heights[3, 3] == 15.0


def test_a_channel_given_with_spaces_is_read_without_them(topographies_dir, capsys):
    # `--channel " 1"` said "no channel named ' 1'" (a shell quote or a copied table cell)
    path = topographies_dir / "di-1.di"
    second = load_surface(path, channel=1)
    for given in (" 1", "1 ", "\t1\n"):
        s = load_surface(path, channel=given)
        assert s.metadata["channel"]["index"] == 1
        np.testing.assert_array_equal(s.heights, second.heights)
    with pytest.raises(InputError, match=r"2 channels are named 'Height'"):
        load_surface(path, channel=" Height ")       # the name, stripped: shared, refused
    with pytest.raises(InputError, match=r"channel ' ' is blank; give a channel index or "
                                         r"name: channels \(index name\) are 0 'Height'"):
        load_surface(path, channel=" ")
    capsys.readouterr()
    assert main(["info", str(path), "--channel", " 1", "--json"]) == 0
    assert '"Retrace"' in capsys.readouterr().out
