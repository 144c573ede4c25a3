"""The ``roughfe`` command: argparse subcommands, one library call each.

Each module listed in :data:`SUBCOMMANDS` defines ``register(subparsers)``, which adds
its subcommand(s) and sets ``func`` (a callable taking the parsed arguments and
returning an exit code). No physics lives here: a subcommand parses, calls the library,
writes outputs and prints a summary. Options come from :mod:`roughfe.cli.options` (the
one vocabulary).

The command stays light: only the module of the command given on the command line is
imported (all of them for ``roughfe --help``), command modules import the library
lazily, and pyvista/vtk is loaded only by commands that render (before any dolfinx
import, :mod:`roughfe._runtime`) -- ``roughfe contact`` reaches its solve in ~0.3 s.
"""
from __future__ import annotations

import contextlib
import importlib
import os
import signal
import sys
import threading
import warnings

from .. import progress
from ..errors import RoughfeError, Terminated
from .options import RoughfeParser, command_name, show_progress

# module -> the commands it registers (explicit and ordered; no import-time magic)
SUBCOMMANDS = {
    "surface_cmds": ("generate", "info"),
    "contact_cmd": ("contact",),
    "demo_cmd": ("demo",),
    "validate_cmd": ("validate",),
    "study_cmd": ("study",),
    "leak_cmd": ("leak", "leak-study"),
    "genome_cmd": ("genome",),
    "db_cmd": ("db",),
    "design_cmd": ("design", "design-targets"),
}


class ProgressBars:
    """A :mod:`roughfe.progress` listener: one tqdm bar on stderr per running loop
    (nested loops, e.g. the BEM load steps of each design candidate, stack)."""

    def __init__(self):
        self.bars = {}

    def __call__(self, description, done, total):
        from tqdm import tqdm

        bar = self.bars.get(description)
        if done == 0:
            if bar is not None:
                bar.close()
            self.bars[description] = tqdm(total=total, desc=description, file=sys.stderr,
                                          leave=False, dynamic_ncols=True,
                                          position=len(self.bars))
            return
        if bar is not None:
            bar.update(done - bar.n)
            if total is not None and done >= total:
                bar.close()
                del self.bars[description]

    def close(self):
        for bar in self.bars.values():
            bar.close()
        self.bars.clear()


def build_parser(command: str | None = None) -> RoughfeParser:
    """The argument parser; with ``command``, only that command's module is registered."""
    parser = RoughfeParser(
        prog="roughfe",
        description="Contact mechanics of rough surfaces: generation, BEM contact, FEM "
                    "cross-validation, leakage and surface roughness genomics. SI units "
                    "(m, Pa, s) everywhere.")
    from .. import __version__
    parser.add_argument("--version", action="version", version=f"roughfe {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for module, commands in SUBCOMMANDS.items():
        if command is None or command in commands:
            importlib.import_module(f"{__name__}.{module}").register(sub)
    return parser


def _command_of(argv) -> str | None:
    """The subcommand named in ``argv`` (first word not starting with '-'), if known."""
    word = next((a for a in argv if not a.startswith("-")), None)
    known = {c for cs in SUBCOMMANDS.values() for c in cs}
    return word if word in known else None


def _warning_printer(name, show):
    """A ``warnings.showwarning`` that prints roughfe's own warnings as one line
    ``roughfe CMD: warning: ...`` on stderr (the library's file and line mean nothing to
    a command-line user); other packages' warnings go to ``show`` unchanged."""
    package = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

    def printer(message, category, filename, lineno, file=None, line=None):
        if not os.path.abspath(filename).startswith(package + os.sep):
            return show(message, category, filename, lineno, file, line)
        print(f"roughfe {name}: warning: {' '.join(str(message).split())}",
              file=sys.stderr if file is None else file)
    return printer


def _reader_left() -> int:
    """The reader of stdout left (``| head``): stop quietly, as a command killed by SIGPIPE
    would (exit 128 + 13); stdout goes to /dev/null so that the interpreter's final flush
    does not print a traceback."""
    try:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    except (OSError, ValueError):     # stdout without a file descriptor (a test)
        pass
    return 141


def _interrupted(name: str) -> int:
    """Ctrl-C before the command ran (its modules loading): one line, exit 130."""
    print(f"{name}: interrupted", file=sys.stderr)
    return 130


def _raise_terminated(signum, frame):
    """SIGTERM handler: stop as after Ctrl-C (:class:`~roughfe.errors.Terminated`). A
    second SIGTERM during the clean-up ends the process at once (default action)."""
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    raise Terminated("SIGTERM")


@contextlib.contextmanager
def _sigterm_as_interrupt():
    """Turn SIGTERM (``kill PID``) into :class:`~roughfe.errors.Terminated` while the
    command runs, so that it stops as after Ctrl-C: clean-up code runs (a study's worker
    pool is shut down, no semaphore leaks; an output folder keeps ``UNFINISHED`` or gets
    its earlier content back). Only in the main thread (signal handlers live there)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _raise_terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def main(argv=None) -> int:
    """Run ``roughfe ARGV``; return the exit code (0 ok, 1 targets/checks missed, 2 bad
    input: one line ``roughfe CMD: error: ...`` on stderr, nothing written; 130
    interrupted by Ctrl-C (SIGINT), 143 by SIGTERM (``kill PID``), either with one line
    ``roughfe CMD: interrupted`` on stderr; 141 the reader of stdout left, as with
    SIGPIPE). The library's warnings are printed as one line ``roughfe CMD: warning: ...``."""
    argv = sys.argv[1:] if argv is None else list(argv)
    try:
        parser = build_parser(_command_of(argv))
    except KeyboardInterrupt:   # Ctrl-C while the command's modules load: nothing written
        return _interrupted("roughfe")    # (was a traceback through numpy's import)
    try:
        args, extra = parser.parse_known_args(argv)
    except SystemExit as exc:  # --help, --version, or a parse error (one line, exit 2)
        return int(exc.code or 0)
    except BrokenPipeError:    # `roughfe CMD --help | head`
        return _reader_left()
    if extra:    # said by the command that did not know them (argparse's top parser
        # said "roughfe: ... (see `roughfe --help`)" for `roughfe leak ... --mirror`)
        cmd = command_name(args)
        print(f"{cmd}: error: unrecognized arguments: {' '.join(extra)} (see `{cmd} "
              f"--help`)", file=sys.stderr)
        return 2
    from .._runtime import python_signals_for_petsc
    python_signals_for_petsc()   # a closed stdout is exit 141, not PETSc's abort (exit 59)
    if getattr(args, "renders_with_dolfinx", False) and not getattr(args, "no_figures", False):
        from .._runtime import load_render_backend
        try:
            load_render_backend()  # vtk before dolfinx: this command solves with dolfinx, draws
        except KeyboardInterrupt:
            return _interrupted(command_name(args))
    name = command_name(args).removeprefix("roughfe ")
    quiet = open(os.devnull, "w") if getattr(args, "quiet", False) else None
    bars = ProgressBars() if show_progress(args) else None
    try:
        with contextlib.ExitStack() as stack:
            stack.enter_context(_sigterm_as_interrupt())
            stack.enter_context(warnings.catch_warnings())   # restores showwarning
            warnings.showwarning = _warning_printer(name, warnings.showwarning)
            if quiet:
                stack.enter_context(contextlib.redirect_stdout(quiet))
            if bars:
                stack.enter_context(progress.listening(bars))
                stack.callback(bars.close)
            return int(args.func(args) or 0)
    except RoughfeError as exc:
        message = str(exc)
    except MemoryError as exc:   # Python's own MemoryError has no text: say what failed
        message = (f"not enough memory ({str(exc) or 'an allocation failed'}): an option "
                   "asks for more than this machine has; lower a grid size or a count")
    except BrokenPipeError:       # the reader of stdout left (`| head`)
        return _reader_left()
    except OSError as exc:
        message = f"{exc.strerror or exc}" + (f": {exc.filename}" if exc.filename else "")
    except KeyboardInterrupt as exc:       # Ctrl-C, or SIGTERM (Terminated)
        terminated = isinstance(exc, Terminated)
        print(f"roughfe {name}: interrupted{' (SIGTERM)' if terminated else ''}",
              file=sys.stderr)
        return 143 if terminated else 130
    finally:
        if quiet:
            quiet.close()
    print(f"roughfe {name}: error: {' '.join(message.split())}", file=sys.stderr)
    return 2
