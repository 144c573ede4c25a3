"""``roughfe validate NAME``: run a validation script of ``validation/`` and write its report.

Each script ``validation/<script>.py`` defines ``main(outdir: pathlib.Path) -> bool``
(True when every target is met) and writes ``<outdir>/<script>.md`` with its figures.
They are readable physics scripts that compare roughfe with analytic solutions, FEM and
the literature; they need the repository checkout (they are not installed modules).
"""
from __future__ import annotations

import importlib.util
from pathlib import Path

from .. import progress
from ..errors import InputError

# name on the command line -> script in validation/ (explicit, ordered)
VALIDATIONS = {
    "bem": "bem_contact",
    "fem": "bem_vs_fem",
    "sequencing": "genomics_sequencing",
    "design": "design_study",
    "leakage": "leakage_flow",
}


def _validation_dir() -> Path:
    here = Path(__file__).resolve().parents[2] / "validation"
    if not here.is_dir():
        raise InputError(f"validation scripts not found at {here}: run from a roughfe checkout")
    return here


def run_validation(name: str, outdir: Path) -> bool:
    """Import ``validation/<script>.py`` and run its ``main(outdir)``."""
    if name not in VALIDATIONS:
        raise InputError(f"unknown validation {name!r}; choose from {sorted(VALIDATIONS)} or 'all'")
    path = _validation_dir() / f"{VALIDATIONS[name]}.py"
    if not path.is_file():
        raise InputError(f"validation script {path} is missing")
    spec = importlib.util.spec_from_file_location(f"roughfe_validation_{VALIDATIONS[name]}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return bool(module.main(Path(outdir)))


def _script_doc(name: str) -> str:
    """The docstring of ``validation/<script>.py`` (read with ast: nothing is imported)."""
    import ast
    try:
        path = _validation_dir() / f"{VALIDATIONS[name]}.py"
        return ast.get_docstring(ast.parse(path.read_text())) or ""
    except (InputError, OSError, SyntaxError):
        return "(validation script not found: run from a roughfe checkout)"


def _run(args) -> int:
    names = list(VALIDATIONS) if args.name == "all" else [args.name]
    failed = []
    for name in progress.iterate(names, "validations"):
        print(f"== validation {name}")
        if not run_validation(name, Path(args.output)):
            failed.append(name)
    print("all validation targets met" if not failed else f"targets missed in: {', '.join(failed)}")
    return 1 if failed else 0


def register(sub):
    p = sub.add_parser(
        "validate", help="run a validation study (analytic, FEM, literature) and write its report",
        description="Run a validation study of validation/ and write its Markdown report, JSON "
                    "and figures into OUTDIR. Each prints its checks and exits 1 when a target "
                    "is missed. Studies take minutes (fem, design: tens of minutes); "
                    "`roughfe validate NAME --help` describes one.")
    names = p.add_subparsers(dest="name", metavar="NAME")
    names.required = True
    for name in [*VALIDATIONS, "all"]:
        doc = ("every validation in turn: " + ", ".join(VALIDATIONS) if name == "all"
               else _script_doc(name))
        v = names.add_parser(name, help=doc.splitlines()[0] if doc else name, description=doc)
        v.add_argument("-o", "--output", default="validation/output", metavar="OUTDIR",
                       help="report folder (each study writes its own <script>.md/.json and "
                            "figures there; other files are kept)")
        v.set_defaults(func=_run, renders_with_dolfinx=True)
