"""``roughfe validate NAME``: run a validation script of ``validation/`` and write its report.

Each script ``validation/<script>.py`` defines ``main(outdir: pathlib.Path) -> bool``
(True when every target is met) and writes ``<outdir>/<script>.md`` with its figures.
They are readable physics scripts that compare roughfe with analytic solutions, FEM and
the literature; they need the repository checkout (they are not installed modules).
"""
from __future__ import annotations

import importlib.util
from pathlib import Path

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


def _run(args) -> int:
    names = list(VALIDATIONS) if args.name == "all" else [args.name]
    failed = []
    for name in names:
        print(f"== validation {name}")
        if not run_validation(name, Path(args.output)):
            failed.append(name)
    print("all validation targets met" if not failed else f"targets missed in: {', '.join(failed)}")
    return 1 if failed else 0


def register(sub):
    p = sub.add_parser(
        "validate", help="run a validation study (analytic, FEM, literature) and write its report",
        description=__doc__)
    p.add_argument("name", choices=[*VALIDATIONS, "all"], help="which validation to run")
    p.add_argument("-o", "--output", default="validation/output", help="report folder")
    p.set_defaults(func=_run)
