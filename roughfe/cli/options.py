"""The one option vocabulary of the ``roughfe`` command (docs/guide/02_command_line.md).

Every subcommand builds its options from these helpers, so a name means the same thing
everywhere:

* :func:`add_surface_options` -- ``SURFACE``, ``--size LX [LY]``, ``--periodic`` |
  ``--non-periodic`` (exclusive), ``--channel``; :func:`surface_from_args` reads it.
* :func:`add_detrend_option` -- ``--detrend none|mean|plane|lines|lines-tilt``, default
  ``mean`` (a warning when it leaves a tilt of more than 95 % of the variance of a
  non-periodic surface, and when a map's scan lines look offset from each other), and
  ``--scan-axis x|y`` (:func:`add_scan_axis_option`: the axis the scan lines run along,
  default x; ``design-targets`` adds it alone, beside its own ``--detrend``).
* :func:`add_material_options` -- ``--E`` (Pa, within :data:`E_RANGE`) and ``--nu`` (-),
  default the thesis' E* = 210 MPa (E = 210 MPa, nu = 0); :func:`material_from_args`.
* :func:`add_output_folder` -- ``-o/--output OUTDIR`` (a FOLDER whenever a command writes
  several files) and ``--overwrite``; :func:`output_folder_of` applies the ownership
  contract of :func:`roughfe.writers.output_folder`. :func:`add_output_file` for
  commands that write one file.
* :func:`add_contact_physics_options` -- ``--unload``, ``--adhesion md|exp``
  ``--work-of-adhesion W --range R``, ``--hardness H``; :func:`contact_physics_from_args`
  (``contact`` and ``leak``).
* :func:`add_run_options` -- ``--no-figures`` and ``--quiet`` (no progress bar, no
  summary on stdout; errors still go to stderr).
* :func:`positive_int`, :func:`positive_float`, :func:`nonnegative_int` -- argparse
  types that reject 0/negative values at parse time (exit 2, one line); likewise
  :func:`at_least_two`, :func:`at_least_three`, :func:`unit_fraction`.

:class:`RoughfeParser` shows every default in ``--help``, accepts negative numbers as
option values (``--nu -1.5`` reaches the validator: "nu ... must lie in (-1, 0.5]"), prints
parse errors on one line and refuses an option given twice with different values
(:mod:`roughfe.cli.repeated`).
"""
from __future__ import annotations

import argparse
import re
import sys
import textwrap

from .repeated import GIVEN, StoreOnce, refuse_repeated

#: DEFAULT_E, DEFAULT_NU: the one default material, defined in :mod:`roughfe.model` (shared
#: with the study analyses), imported where the options are made: importing the command
#: line imports no numpy (a Ctrl-C in that import was a traceback, round 2, session 33).
#: Default of --detrend in info, contact and leak.
DEFAULT_DETREND = "mean"
DETRENDS = ("none", "mean", "plane", "lines", "lines-tilt")

# a number, also negative and in exponent form: -1, -1.5, -.5, -1e9, -1.5E-3, -inf, -nan
_NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$|^-(inf|nan)$", re.I)


class HelpFormatter(argparse.HelpFormatter):
    """Wrapped paragraphs (indented blocks kept as written); ``(default: X)`` after every
    option that takes a value and has a default (not after flags, not for ``None``)."""

    def _fill_text(self, text, width, indent):
        out = []
        for block in textwrap.dedent(text).strip().split("\n\n"):
            if block.startswith((" ", "\t")) or "::" in block.splitlines()[-1][-3:]:
                out.append(textwrap.indent(block, indent))
            else:
                out.append(textwrap.fill(" ".join(block.split()), width,
                                         initial_indent=indent, subsequent_indent=indent))
        return "\n\n".join(out)

    def _get_help_string(self, action):
        text = action.help or ""
        default = action.default
        if ("%(default)" in text or action.nargs == 0 or default is None
                or default is argparse.SUPPRESS):
            return text
        if action.option_strings or action.nargs in (argparse.OPTIONAL, argparse.ZERO_OR_MORE):
            values = default if isinstance(default, (list, tuple)) else [default]
            shown = " ".join(format(v, "g") if isinstance(v, float) else str(v) for v in values)
            return f"{text} (default: {shown.replace('%', '%%')})"
        return text


class RoughfeParser(argparse.ArgumentParser):
    """``ArgumentParser`` with roughfe's conventions (see the module docstring)."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("formatter_class", HelpFormatter)
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = _NEGATIVE_NUMBER
        self.register("action", None, StoreOnce)     # subparsers are RoughfeParsers too
        self.register("action", "store", StoreOnce)

    def parse_known_args(self, args=None, namespace=None):
        args, extra = super().parse_known_args(args, namespace)
        vars(args).pop(GIVEN, None)     # the record of refuse_repeated, not an option
        return args, extra

    def error(self, message):
        """One line on stderr, exit code 2 (argparse prints usage + error)."""
        self.exit(2, f"{self.prog}: error: {message} (see `{self.prog} --help`)\n")


def _check(kind, test, what):
    def parse(text):
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected {what}, got {text!r}") from None
        if not test(value):
            raise argparse.ArgumentTypeError(f"must be {what}, got {text!r}")
        return value
    parse.__name__ = what
    return parse


positive_int = _check(int, lambda v: v >= 1, "an integer >= 1")
at_least_two = _check(int, lambda v: v >= 2, "an integer >= 2")
#: the approaches of a K(p) curve: K is differenced over them (2 gave NaN, 1 no curve)
at_least_three = _check(int, lambda v: v >= 3, "an integer >= 3")
nonnegative_int = _check(int, lambda v: v >= 0, "an integer >= 0")
positive_float = _check(float, lambda v: 0.0 < v < float("inf"), "a finite number > 0")
nonnegative_float = _check(float, lambda v: 0.0 <= v < float("inf"), "a finite number >= 0")
#: a relative tolerance: 1 or more asks nothing of a solver (its start is accepted)
unit_fraction = _check(float, lambda v: 0.0 < v < 1.0, "a number in (0, 1)")


def int_in(low: int, high: int):
    """An argparse type: an integer in ``low..high`` (a count whose cost grows with it)."""
    return _check(int, lambda v: low <= v <= high, f"an integer in {low}..{high}")


#: Young's moduli E (Pa) that ``--E`` accepts: three decades beyond the softest solids
#: (gels, ~1 Pa) and the stiffest (diamond, 1.2e12 Pa), so that dimensionless runs (E* = 1)
#: pass. Every solver is linear in E* (it solves p / E*), so the range is no limit of the
#: method; it refuses what is a slip (1e308 or 1e-300 overflowed or underflowed the
#: pressures: a non-convergence line that did not name E, round 2, session 33).
E_RANGE = (1e-3, 1e15)
youngs_modulus = _check(float, lambda v: E_RANGE[0] <= v <= E_RANGE[1],
                        f"a Young's modulus from {E_RANGE[0]:g} Pa to {E_RANGE[1]:g} Pa")


# -- surfaces ------------------------------------------------------------------------------
def add_surface_options(parser, positional: bool = True) -> None:
    """Add ``SURFACE``, ``--size LX [LY]``, ``--periodic``/``--non-periodic``, ``--channel``."""
    if positional:
        parser.add_argument(
            "surface", metavar="SURFACE",
            help="surface file: roughfe .npz, plain .npy/.txt/.csv matrix (heights in m, "
                 "needs --size) or an instrument file (.x3p .sur .opd .plu .di .datx ...)")
    group = parser.add_argument_group("surface file options")
    group.add_argument(
        "--size", nargs="+", type=positive_float, metavar=("LX", "LY"),
        help="physical size in metres (n * spacing per axis); required for plain matrices, "
             "overrides the file's size otherwise; one value = square")
    periodic = group.add_mutually_exclusive_group()
    periodic.add_argument(
        "--periodic", dest="periodic", action="store_true", default=None,
        help="treat the heights as periodic (default: the file's flag; plain matrices: no)")
    periodic.add_argument(
        "--non-periodic", dest="periodic", action="store_false",
        help="treat the heights as non-periodic")
    group.add_argument(
        "--channel", default=None,
        help="channel index or name of a multi-channel instrument file (default: the "
             "first); a name that several channels share is refused (give the index; "
             "`roughfe info` names the channel read and lists the file's channels)")


def surface_file(args, path):
    """The surface file ``path`` with ``--size``/``--periodic``/``--channel`` (the options
    of :func:`add_surface_options`) and ``--scan-axis`` (metadata ``scan_axis``) applied."""
    from ..errors import InputError
    from ..surfaces.io import load_surface

    size = args.size
    if size is not None and len(size) > 2:
        raise InputError(f"--size takes one or two lengths in metres, got {size}")
    if size is not None and len(size) == 1:
        size = size[0]
    surface = load_surface(path, size=size, periodic=args.periodic, channel=args.channel)
    y = getattr(args, "scan_axis", None) == "y" and surface.ndim == 2   # read by the
    return surface.with_heights(surface.heights, scan_axis="y") if y else surface  # levelling


def surface_from_args(args):
    """The :class:`~roughfe.surfaces.surface.Surface` named by ``args.surface`` with
    ``--size``/``--periodic``/``--channel`` applied, detrended by ``--detrend`` when the
    command has that option, after the plausibility warnings
    (:func:`roughfe.cli.surface_warnings.plausible_surface`)."""
    from .surface_warnings import plausible_surface
    surface = surface_file(args, args.surface)
    return plausible_surface(args, surface, getattr(args, "detrend", "none"))


def mirrored_if_asked(args, surface):
    """``surface`` (as :func:`surface_from_args` gave it, detrended) evenly mirrored into a
    periodic one when the command's ``--mirror`` is given (``contact``, ``genome
    chromosomes``); a periodic surface cannot be mirrored."""
    if not getattr(args, "mirror", False):
        return surface
    if surface.periodic:
        from ..errors import InputError
        raise InputError(f"--mirror mirrors a non-periodic window; {args.surface} is "
                         f"read as periodic (drop --mirror, or give --non-periodic)")
    return surface.mirrored()


def surface_notes(surface, channel: bool = False) -> list:
    """Console lines on what an instrument file gave: with ``channel`` the channel read
    (and, of a multi-channel file, all of its channels), and the undefined points that
    the reader filled (``metadata["filled_points"]``; opd-1: 116), which only
    ``--json``/results.json said until round 2, session 24, and that the file gives no
    unit, so that its heights and lengths were taken as metres (``metadata
    ["unit_in_file"]`` is :data:`~roughfe.surfaces.io.ASSUMED_UNIT`; only ``--json``
    said so until round 2, session 25)."""
    from ..surfaces.channels import read_channel_label
    from ..surfaces.io import ASSUMED_UNIT

    meta = surface.metadata
    lines = []
    label = read_channel_label(meta)
    if channel and label is not None:
        every = list(meta.get("channels") or [])
        lines.append(f"channel {label}" + (f"; the file has {len(every)}: "
                                           f"{', '.join(every)} (--channel INDEX)"
                                           if len(every) > 1 else ""))
    if meta.get("filled_points"):
        lines.append(f"{int(meta['filled_points'])} undefined points filled (harmonic "
                     f"interpolation)")
    if meta.get("unit_in_file") == ASSUMED_UNIT:
        lines.append("the file gives no unit; heights and lengths taken as metres (in "
                     "another unit: rescale the file's values to metres, e.g. save the "
                     "heights as .npy in metres and give --size LX [LY]; --size alone "
                     "sets the lengths, not the heights)")
    return lines


def print_surface_notes(args, surface, channel: bool = False) -> None:
    """Print :func:`surface_notes` on stdout, each as ``SURFACE: note``."""
    for note in surface_notes(surface, channel):
        print(f"{args.surface}: {note}")


def add_detrend_option(parser, default: str = DEFAULT_DETREND) -> None:
    """``--detrend none|mean|plane|lines|lines-tilt``; the default is ``mean``, or the
    library's own default of the command's function where that differs (``genome chromosomes``:
    ``plane``, as :func:`roughfe.genomics.bands.band_chromosomes`)."""
    parser.add_argument(
        "--detrend", choices=DETRENDS, default=default,
        help="remove nothing, the mean height, or the least-squares plane before the "
             "analysis (measured topographies usually need 'plane'; on a periodic surface "
             "'plane' removes the mean only: its mean slope is zero); 'mean' on a "
             "non-periodic surface whose plane carries more than 95 %% of the height "
             "variance warns. 'lines' / 'lines-tilt' level each scan line (along x, or "
             "--scan-axis; AFM 'align rows'): its mean / least-squares line; for scan-line "
             "artefacts only (they also remove the real roughness across the lines at zero "
             "wavenumber along them); a map whose lines look offset warns")
    add_scan_axis_option(parser)


def add_scan_axis_option(parser, default="x") -> None:
    """``--scan-axis x|y``, applied by :func:`surface_file` (``design-targets``: None)."""
    parser.add_argument("--scan-axis", choices=("x", "y"), default=default, help=(
        "the axis of the fast-scan lines, for --detrend lines / lines-tilt (and the "
        "scan-line check): x (heights[:, j], an AFM map as the .di reader gives it) or "
        "y (heights[i, :], a map scanned along y, no transposing needed)"
        + ("" if default else " (default: x)")))


# -- material ------------------------------------------------------------------------------
class _Deprecated(argparse.Action):
    """An old option name: stores into the new ``dest`` and warns once."""

    def __init__(self, *args, new=None, **kwargs):
        self.new = new
        super().__init__(*args, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        print(f"{parser.prog}: warning: {option_string} is deprecated, use {self.new}",
              file=sys.stderr)
        refuse_repeated(parser, namespace, self.dest, option_string, values)
        setattr(namespace, self.dest, values)


def add_material_options(parser, title: str = "material (elastic half-space)") -> None:
    """``--E`` (Pa, within :data:`E_RANGE`) and ``--nu`` (-) with the one default (thesis
    E* = 210 MPa).

    The old spellings ``--youngs-modulus``/``--poisson`` are accepted with a warning.
    """
    from ..model import DEFAULT_E, DEFAULT_NU
    group = parser.add_argument_group(title)
    group.add_argument("--E", type=youngs_modulus, default=DEFAULT_E, metavar="PA",
                       help=f"Young's modulus E in Pa, {E_RANGE[0]:g} to {E_RANGE[1]:g}")
    group.add_argument("--nu", type=float, default=DEFAULT_NU, metavar="NU",
                       help="Poisson's ratio nu, in (-1, 0.5]; E* = E / (1 - nu^2)")
    group.add_argument("--youngs-modulus", dest="E", type=youngs_modulus, action=_Deprecated,
                       new="--E", help=argparse.SUPPRESS)
    group.add_argument("--poisson", dest="nu", type=float, action=_Deprecated, new="--nu",
                       help=argparse.SUPPRESS)


def material_from_args(args):
    """``Material(args.E, args.nu)`` (validated: E > 0, -1 < nu <= 0.5)."""
    from ..bem import Material
    return Material(args.E, args.nu)


# -- adhesion --------------------------------------------------------------------------------
def add_adhesion_options(parser) -> None:
    """``--adhesion md|exp``, ``--work-of-adhesion W`` (J/m^2), ``--range R`` (m),
    ``--smoothing S`` (md)."""
    group = parser.add_argument_group("adhesion (roughfe.bem.adhesion; displacement control)")
    group.add_argument("--adhesion", choices=("md", "exp"), default=None,
                       help="interface law: Maugis-Dugdale (constant attraction w/R up to the "
                            "gap R) or exponential (w/R exp(-g/R)); default: no adhesion")
    group.add_argument("--work-of-adhesion", type=positive_float, default=None, metavar="W",
                       help="work of adhesion w in J/m^2 (with --adhesion)")
    group.add_argument("--range", type=positive_float, default=None, metavar="R",
                       help="range of the attraction in m: h0 (md) or rho (exp)")
    group.add_argument("--smoothing", type=float, default=None, metavar="S",
                       help="md only: relative width of the traction ramp about h0, 0 <= S "
                            "< 1 (default 0.05; a wider ramp is resolved by coarser grids, "
                            "see the ResolutionWarning)")


def adhesion_from_args(args):
    """The :class:`roughfe.bem.adhesion.AdhesionLaw` of the options, or None without them."""
    from ..bem.adhesion import AdhesionLaw
    from ..errors import InputError, check_in_interval
    given = [args.work_of_adhesion is not None, args.range is not None]
    smoothing = getattr(args, "smoothing", None)
    if args.adhesion is None:
        if any(given) or smoothing is not None:
            raise InputError("--work-of-adhesion, --range and --smoothing need --adhesion "
                             "md|exp")
        return None
    if not all(given):
        raise InputError(f"--adhesion {args.adhesion} needs --work-of-adhesion W (J/m^2) and "
                         "--range R (m), both finite and > 0")
    if smoothing is None:
        return AdhesionLaw(args.adhesion, args.work_of_adhesion, args.range)
    if args.adhesion != "md":
        raise InputError("--smoothing is the ramp of the Maugis-Dugdale law: it needs "
                         "--adhesion md")
    smoothing = check_in_interval("--smoothing", smoothing, 0, 1, "left")
    return AdhesionLaw("md", args.work_of_adhesion, args.range, smoothing=smoothing)


# -- contact physics: adhesion, hardness, unloading ----------------------------------------
def add_contact_physics_options(parser, unload_help: str = None) -> None:
    """``--unload``, ``--adhesion md|exp --work-of-adhesion W --range R`` and
    ``--hardness H`` (Pa): the interface physics of ``contact`` and ``leak``."""
    parser.add_argument("--unload", action="store_true", help=unload_help or (
        "after loading, trace the unloading branch (with --adhesion: until the surfaces "
        "separate, giving the pull-off force; with --hardness keeping the plastic "
        "displacement)"))
    add_adhesion_options(parser)
    parser.add_argument("--hardness", type=positive_float, default=None, metavar="H",
                        help="indentation hardness H_p (Pa) of a perfectly plastic "
                             "interface: 0 <= p <= H_p; results get plastic_area_fraction "
                             "per step and the fields the plastic displacement")


def contact_physics_from_args(args) -> dict:
    """``{"adhesion": AdhesionLaw or None, "hardness": float or None, "unload": bool}``
    of :func:`add_contact_physics_options` (the keyword options of
    :func:`roughfe.response.response`); --hardness with --adhesion is one clear error, and
    so is a negative --delta without --adhesion (in the flags' words, for both commands)."""
    law = adhesion_from_args(args)
    deltas = getattr(args, "delta", None)
    if law is not None:
        from ..bem.adhesive_rules import check_adhesive_run
        check_adhesive_run(hardness=args.hardness, deltas=deltas, words=ADHESION_WORDS)
    elif deltas:    # said here for both commands (leak said "deltas[0] ... response(")
        from ..model import Loading
        Loading(deltas=deltas).require_contact(words=ADHESION_WORDS)
    return {"adhesion": law, "hardness": args.hardness, "unload": bool(args.unload)}


#: the command line's words for the names in the messages of
#: :func:`roughfe.bem.adhesive_rules.check_adhesive_run`
ADHESION_WORDS = {"hardness": "--hardness", "adhesion": "--adhesion", "solver": "--solver",
                  "coarse_correction": "--coarse-correction",
                  "approaches": "--delta or --steps", "mean pressures": "--pressure",
                  "deltas": "--delta", "unload": "--unload"}


# -- outputs and runs ----------------------------------------------------------------------
def add_output_folder(parser, help: str = "output folder", required: bool = True,
                      default=None) -> None:
    """``-o/--output OUTDIR`` (a folder) and ``--overwrite``."""
    parser.add_argument("-o", "--output", required=required, default=default,
                        metavar="OUTDIR",
                        help=f"{help}; created if missing, refused if it holds files that are "
                             "not an earlier output of this command (see --overwrite)")
    parser.add_argument("--overwrite", action="store_true",
                        help="empty a non-empty output folder/file of any origin first")


def add_output_file(parser, help: str, required: bool = True) -> None:
    """``-o/--output FILE`` and ``--overwrite`` (an existing file is refused without it)."""
    parser.add_argument("-o", "--output", required=required, metavar="FILE", help=help)
    parser.add_argument("--overwrite", action="store_true", help="replace an existing file")


def output_folder_of(args, command: str, *, keep_partial: bool = False):
    """:func:`roughfe.writers.output_folder` for ``args.output`` (context manager)."""
    from ..writers import output_folder
    return output_folder(args.output, command, overwrite=getattr(args, "overwrite", False),
                         keep_partial=keep_partial)


def output_file_of(args, suffixes=None):
    """:func:`roughfe.writers.output_file` for ``args.output``; nothing is written."""
    from ..writers import output_file
    return output_file(args.output, overwrite=getattr(args, "overwrite", False),
                       suffixes=suffixes)


def add_run_options(parser, figures: bool = True) -> None:
    """``--no-figures`` (when the command draws) and ``--quiet``."""
    if figures:
        parser.add_argument("--no-figures", action="store_true",
                            help="skip the figures (they are drawn by default)")
    parser.add_argument("--quiet", action="store_true",
                        help="no progress bar and no summary on stdout (errors still on stderr)")


def fmt_or_dash(value, spec: str) -> str:
    """``format(value, spec)`` for a table cell, ``"-"`` where the value is None (not
    computed for that step)."""
    return "-" if value is None else format(value, spec)


def log_of(args):
    """The log of a long run's driver: one line per message on stderr, nothing with
    ``--quiet``."""
    if getattr(args, "quiet", False):
        return lambda message: None
    return lambda message: print(message, file=sys.stderr)


def show_progress(args) -> bool:
    """True when a progress bar should be drawn: stderr is a terminal and no ``--quiet``."""
    return not getattr(args, "quiet", False) and sys.stderr.isatty()


#: the attributes that name a command's words (a command, then its subcommand)
COMMAND_WORDS = ("command", "genome_command", "db_command", "study_command")


def command_name(args) -> str:
    """The command as typed, subcommand included (``roughfe genome chromosomes``): the
    prefix of every error and warning line of the command."""
    return " ".join(["roughfe"] + [str(getattr(args, k)) for k in COMMAND_WORDS
                                   if getattr(args, k, None)])


def warn(args, message: str) -> None:
    """One warning line on stderr (``roughfe CMD [SUBCMD]: warning: ...``), even with
    --quiet. Until round 2, session 32 it named the command only (``roughfe genome:
    warning``), while the errors and the library's warnings named the subcommand."""
    print(f"{command_name(args)}: warning: {message}", file=sys.stderr)


def add_runner_options(parser) -> None:
    """``--executor``, ``--scheduler``, ``--workers``: the study runner (as `study run`)."""
    from ..study import EXECUTORS

    group = parser.add_argument_group("study runner (as `roughfe study run`)")
    group.add_argument("--executor", choices=EXECUTORS, default="local",
                       help="local: process pool on this machine; dask: dask.distributed "
                            "(LocalCluster, or --scheduler); mpi: mpi4py.futures under mpirun")
    group.add_argument("--scheduler", metavar="ADDRESS", default=None,
                       help="a running dask scheduler: address (tcp://head:8786) or scheduler "
                            "file (*.json, from `dask scheduler --scheduler-file`); dask only")
    group.add_argument("--workers", type=positive_int, default=None, metavar="N",
                       help="worker processes for local and a dask LocalCluster (default: "
                            "the cores)")
