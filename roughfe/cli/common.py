"""Options shared by every subcommand that takes a surface file.

``add_surface_options`` adds the positional ``SURFACE`` and the options a plain height
matrix needs (``--size LX [LY]`` in metres, ``--periodic/--non-periodic``) plus
``--channel`` for multi-channel instrument files; ``surface_from_args`` reads the file
through :func:`roughfe.surfaces.io.load_surface`. No other parsing of surfaces exists.
"""
from __future__ import annotations

import argparse

from ..surfaces.io import load_surface
from ..surfaces.surface import Surface


def add_surface_options(parser: argparse.ArgumentParser, positional: bool = True) -> None:
    """Add ``SURFACE``, ``--size LX [LY]``, ``--periodic/--non-periodic`` and ``--channel``."""
    if positional:
        parser.add_argument(
            "surface", metavar="SURFACE",
            help="surface file: roughfe .npz, plain .npy/.txt/.csv matrix (heights in m, "
                 "needs --size) or an instrument file (.x3p .sur .opd .plu .di .datx ...)")
    group = parser.add_argument_group("surface file options")
    group.add_argument(
        "--size", nargs="+", type=float, metavar=("LX", "LY"),
        help="physical size in metres (n * spacing per axis); required for plain matrices, "
             "overrides the file's size otherwise; one value = square")
    group.add_argument(
        "--periodic", dest="periodic", action="store_true", default=None,
        help="treat the heights as periodic (default: the file's flag; plain matrices: no)")
    group.add_argument(
        "--non-periodic", dest="periodic", action="store_false",
        help="treat the heights as non-periodic")
    group.add_argument(
        "--channel", default=None,
        help="channel index or name of a multi-channel instrument file (default: the first)")


def surface_from_args(args: argparse.Namespace) -> Surface:
    """The :class:`Surface` named by ``args.surface`` with the ``--size``/``--periodic``/
    ``--channel`` options applied."""
    size = args.size
    if size is not None and len(size) > 2:
        from ..errors import InputError
        raise InputError(f"--size takes one or two lengths in metres, got {size}")
    if size is not None and len(size) == 1:
        size = size[0]
    return load_surface(args.surface, size=size, periodic=args.periodic, channel=args.channel)
