"""``roughfe validate NAME``: run a validation script of ``validation/`` and write its report.

Each script ``validation/<script>.py`` defines ``main(outdir: pathlib.Path, quick=False)
-> bool`` (True when every target is met) and writes ``<outdir>/<script>.md`` with its
figures and ``<outdir>/<script>.json`` whose ``"targets"`` rows follow the schema of
:mod:`roughfe.validation`; ``roughfe validate`` collects them in ``<outdir>/summary.json``.
``--quick`` runs the reduced cases of the scripts that have them (``make validate-quick``,
CI): same kinds of targets, smaller problems. A script without a reduced case
(:data:`NOT_QUICK`) is reported as a row with ``"met": null`` ("not run"), and a
validation none of whose scripts ran has ``"met": null``: never "met". A target a script
was to check and did not (an optional tool such as Tamaas or ``mpirun`` missing, a case
``--quick`` leaves out) is its :func:`roughfe.validation.skipped` row: printed as "not
run", listed in ``not_run`` (``"script: target"``; a whole script by its name) and
``all_met`` false; the exit code is 1 only for a target NOT met (a script whose
``main`` returns True while one of its rows is NOT met is a failed study). A row
merely reported beside the targets (:func:`roughfe.validation.reported`) is not
counted. They are readable
physics scripts that compare roughfe with analytic solutions, FEM and the literature;
they need the repository checkout (they are not installed modules).

``summary.json`` is written before the first study and after every one: it lists the
``planned`` validations and says ``"complete": false`` until the last one is done, so a
killed run never leaves a summary that reads "all met" (:func:`summary_record`).

``OUTDIR`` is owned like every output folder (:class:`roughfe.writers.OutputFolder`):
locked, ``UNFINISHED`` while the studies run, refused when it holds files that are not an
earlier output of the same ``roughfe validate NAME`` (``--overwrite`` to replace them),
the previous run's files removed first. A study that raises is reported as a failed
target row (with the error) and the others still run, so a crash late in ``make
validate`` does not lose the reports already written; Ctrl-C or an error of the harness
keeps them too (``keep_partial``: ``UNFINISHED`` stays and ``.roughfe-output.json`` says
``"interrupted"`` or ``"failed"``; an older run's files stay set aside in
``.roughfe-previous``, never beside the new ones), and so does a kill (SIGKILL).
"""
from __future__ import annotations

import importlib.util
import inspect
import json
import time
from pathlib import Path

from .. import progress
from ..errors import InputError
from ..validation import NOT_RUN, Target, is_skipped, skipped
from ..writers import write_json
from .options import add_output_folder, output_folder_of

# name on the command line -> scripts in validation/ (explicit, ordered)
VALIDATIONS = {
    "bem": ("bem_contact",),
    "fem": ("bem_vs_fem", "richardson_calibration", "fem_convergence"),
    "sequencing": ("genomics_sequencing",),
    "design": ("design_study",),
    "leakage": ("leakage_flow",),
    "fsi": ("fsi_fem",),
    "adhesion": ("adhesion_maugis",),
    "surface-genomics": ("surface_genomics",),
}
#: scripts without a reduced case, left out of ``--quick``
NOT_QUICK = {"fem_convergence",
             "richardson_calibration"}   # ~50 CPU min; tests/test_validation_tools.py


def _validation_dir() -> Path:
    here = Path(__file__).resolve().parents[2] / "validation"
    if not here.is_dir():
        raise InputError(f"validation scripts not found at {here}: run from a roughfe checkout")
    return here


def _load(script: str):
    path = _validation_dir() / f"{script}.py"
    if not path.is_file():
        raise InputError(f"validation script {path} is missing")
    spec = importlib.util.spec_from_file_location(f"roughfe_validation_{script}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _targets(outdir: Path, script: str, ok: bool) -> list:
    """The script's target rows from its JSON; one summary row if it wrote none."""
    path = Path(outdir) / f"{script}.json"
    try:
        rows = json.loads(path.read_text()).get("targets")
    except (OSError, ValueError, AttributeError):
        rows = None
    if isinstance(rows, list) and rows and all(isinstance(r, dict) for r in rows):
        return rows
    return [Target(f"{script}: all targets", "every target of the script",
                   "met" if ok else "NOT met", ok,
                   f"the script wrote no target rows in {path.name}").to_dict()]


def run_validation(name: str, outdir: Path, quick: bool = False) -> dict:
    """Run the scripts of validation ``name``; ``{"met": bool or None, "targets": [rows],
    "not_run": [...], ...}``: ``met`` None when no script ran, else whether every target
    that ran is met; ``not_run`` names each script not run and each skipped target row
    (:func:`roughfe.validation.is_skipped`) as ``"script: target"``."""
    if name not in VALIDATIONS:
        raise InputError(f"unknown validation {name!r}; choose from {sorted(VALIDATIONS)} or 'all'")
    out = {"met": True, "targets": [], "seconds": {}, "cpu_seconds": {}, "not_run": []}
    ran = 0
    for script in VALIDATIONS[name]:
        if quick and script in NOT_QUICK:
            out["not_run"].append(script)
            out["targets"].append(skipped(
                script, "its targets",
                f"no reduced case: `roughfe validate {name}` (without --quick) runs it"
            ).to_dict())
            continue
        ran += 1
        module = _load(script)
        takes_quick = "quick" in inspect.signature(module.main).parameters
        t0, c0 = time.perf_counter(), _cpu_seconds()
        try:
            ok = bool(module.main(Path(outdir),
                                  **({"quick": True} if quick and takes_quick else {})))
            rows = _targets(outdir, script, ok)
            # the verdict follows the rows too: a row NOT met is never a met study, even
            # when the script's own return value missed it
            ok = ok and not any(r.get("met") is False for r in rows)
        except Exception as exc:   # noqa: BLE001 -- reported as a failed row, others still run
            ok = False
            rows = [Target(f"{script}: ran to the end", "no error",
                           f"{type(exc).__name__}: {exc}".splitlines()[0][:300], False,
                           "the study raised; its report is missing or partial").to_dict()]
            print(f"   {script} raised {type(exc).__name__}: {exc}", flush=True)
        out["seconds"][script] = time.perf_counter() - t0
        out["cpu_seconds"][script] = _cpu_seconds() - c0
        out["met"] = out["met"] and ok
        out["targets"] += rows
        out["not_run"] += [f"{script}: {r['name'][:-len(NOT_RUN)]}" for r in rows
                           if is_skipped(r)]
    if not ran:
        out["met"] = None                       # nothing was checked
    return out


def _cpu_seconds() -> float:
    """CPU seconds of this process and its finished children (MPI, render, workers)."""
    import resource
    own, kids = (resource.getrusage(w) for w in (resource.RUSAGE_SELF,
                                                  resource.RUSAGE_CHILDREN))
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


def _script_doc(name: str) -> str:
    """The docstring of ``validation/<script>.py`` (read with ast: nothing is imported)."""
    import ast
    try:
        return "\n\n".join(
            ast.get_docstring(ast.parse((_validation_dir() / f"{script}.py").read_text())) or ""
            for script in VALIDATIONS[name])
    except (InputError, OSError, SyntaxError):
        return "(validation script not found: run from a roughfe checkout)"


def summary_record(planned: list, summary: dict, quick: bool) -> dict:
    """The content of ``summary.json``: the ``planned`` validations, those done so far
    (``validations``, in order) and ``pending``; ``complete`` once every planned one is
    done; ``failed`` (validations with a target NOT met); ``not_run`` (scripts and skipped
    targets); ``all_met`` only for a complete run in which every target ran and is met (a
    killed run's summary is never all met). Also what :func:`_run` prints at the end."""
    failed = [n for n, v in summary.items() if v["met"] is False]
    not_run = [s for v in summary.values() for s in v["not_run"]]
    complete = all(n in summary for n in planned)
    return {"planned": list(planned), "complete": complete,
            "pending": [n for n in planned if n not in summary], "validations": summary,
            "quick": bool(quick), "all_met": complete and not failed and not not_run,
            "failed": failed, "not_run": not_run}


def _first_sentence(doc: str) -> str:
    """The first sentence of a docstring (its first paragraph up to a '. ' before a capital), on one
    line: the one-line help of ``roughfe validate --help`` (the first line cut it
    mid-sentence where a script wraps its first sentence)."""
    import re
    text = " ".join(doc.split("\n\n", 1)[0].split())
    return re.split(r"\.\s+(?=[A-Z])", text, maxsplit=1)[0].rstrip(".")


def _run(args) -> int:
    names = list(VALIDATIONS) if args.name == "all" else [args.name]
    summary = {}
    with output_folder_of(args, f"validate {args.name}", keep_partial=True) as outdir:
        # before the first study and after every one: a killed run's summary says what
        # it had planned and that it is not complete
        write_json(outdir / "summary.json", summary_record(names, summary, args.quick))
        for name in progress.iterate(names, "validations"):
            print(f"== validation {name}{' (quick)' if args.quick else ''}", flush=True)
            summary[name] = run_validation(name, outdir, quick=args.quick)
            for script in summary[name]["seconds"]:
                print(f"   {script}: {summary[name]['seconds'][script]:.0f} s wall, "
                      f"{summary[name]['cpu_seconds'][script]:.0f} s CPU", flush=True)
            for t in summary[name]["targets"]:
                if is_skipped(t):
                    print(f"   not run: {t['name'][:-len(NOT_RUN)]} ({t.get('reason')})")
                elif t["met"] is None:
                    continue                            # reported beside the targets
                elif not t["met"]:
                    print(f"   NOT met: {t.get('name')}: {t.get('measured', t.get('value'))} "
                          f"(target {t.get('target')})")
            write_json(outdir / "summary.json", summary_record(names, summary, args.quick))
    record = summary_record(names, summary, args.quick)
    failed, not_run = record["failed"], record["not_run"]
    ran = [n for n, v in summary.items() if v["met"] is not None]
    if failed:
        print(f"targets missed in: {', '.join(failed)}")
    elif not ran:
        print(f"nothing validated: no reduced case in {', '.join(not_run)} (run without "
              f"--quick)")
    if failed and not_run:
        print(f"not run either: {'; '.join(not_run)}")
    elif not_run and ran:
        print(f"all targets met of those that ran; not run: {'; '.join(not_run)}")
    elif not failed and ran:
        print("all validation targets met")
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
        v = names.add_parser(name, help=_first_sentence(doc) or name, description=doc)
        add_output_folder(v, "report folder (every study writes its <script>.md/.json and "
                             "figures there, and summary.json)", required=False,
                          default="validation/output")
        v.add_argument("--quick", action="store_true",
                       help="the reduced cases of the scripts that have one (make "
                            "validate-quick); the others are reported as not run")
        v.set_defaults(func=_run, renders_with_dolfinx=True)
