"""The ``roughfe`` command: argparse subcommands, one library call each.

Each module listed in ``_SUBCOMMAND_MODULES`` defines ``register(subparsers)``, which
adds its subcommand(s) and sets ``func`` (a callable taking the parsed arguments and
returning an exit code). No physics lives here: a subcommand parses, calls the library,
writes outputs and prints a summary.
"""
from __future__ import annotations

import argparse
import importlib
import sys

from ..errors import RoughfeError

# Explicit, ordered list (no import-time registration magic).
_SUBCOMMAND_MODULES = (
    "surface_cmds",   # generate, info
    "contact_cmd",    # contact
    "demo_cmd",       # demo
    "validate_cmd",   # validate
    "study_cmd",      # study run|status|collect
    "leak_cmd",       # leak, leak-study
    "genome_cmd",     # genome example|realize|sequence|mechanics|natural|validity
    "db_cmd",         # db build|extend|list|map
    "design_cmd",     # design, design-targets
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="roughfe",
        description="Contact mechanics of rough surfaces: generation, BEM contact, FEM "
                    "cross-validation, leakage and surface roughness genomics. SI units.")
    from .. import __version__
    parser.add_argument("--version", action="version", version=f"roughfe {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name in _SUBCOMMAND_MODULES:
        importlib.import_module(f"{__name__}.{name}").register(sub)
    return parser


def _load_vtk_before_dolfinx():
    """Load vtk before any subcommand can load dolfinx.

    With Debian's dolfinx 0.5.2 and the vtk wheel in one process, vtk must be loaded
    first: the other order aborts (SIGABRT) at the first off-screen render. Commands
    that solve with dolfinx and then draw with pyvista (validate fem, leak) need this.
    """
    try:
        import pyvista  # noqa: F401
    except ImportError:  # pragma: no cover - pyvista is a core dependency
        pass


def main(argv=None) -> int:
    _load_vtk_before_dolfinx()
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except RoughfeError as exc:
        print(f"roughfe {args.command}: error: {exc}", file=sys.stderr)
        return 2
