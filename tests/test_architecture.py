"""The one-way data flow of STYLE.md (a): packages import only leftward.

optim -> surfaces -> model -> theory -> bem -> fem -> response -> leakage -> genomics -> study
-> plotting -> cli
(errors, writers, reference, caching, frozen, _runtime, progress and validation are the base
layer, importable from anywhere; model.py holds the contract types shared by bem and fem,
response.py the one dispatch to them.)
roughfe/__init__.py is the users' namespace, outside the layers: at module level it imports
the standard library only, it reaches the layers lazily through its one table (PEP 562;
plotting and cli not among them), and no library module imports a name through it (each
imports from the module that defines the name, so the layer of that module is checked).
optim holds generic optimisers without physics (the one GCMMA driver).
No library module is over MAX_LINES lines unless ``LONG_MODULES`` states why.
dolfinx, petsc4py, mpi4py.futures aside, gmsh and ufl are imported only inside roughfe/fem.

validation/ holds the studies of ``roughfe validate`` (each named in its table) and their
helper modules (``_*.py``: imported by a study, never a study themselves); both are held
to MAX_LINES, a study imports helpers and the library but never another study, and none
imports dolfinx & co. directly (they reach the FEM through roughfe.fem).
"""
import ast
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[1] / "roughfe"
VALIDATION = PKG.parent / "validation"
ORDER = ["errors", "writers", "reference", "optim", "surfaces", "model", "theory", "bem", "fem",
         "response", "leakage", "genomics", "study", "plotting", "cli"]
BASE = {"errors", "writers", "reference", "caching", "frozen", "_runtime", "progress",
        "validation", "__init__"}
FEM_ONLY = {"dolfinx", "petsc4py", "gmsh", "ufl", "basix", "ffcx"}
MAX_LINES = 500
#: modules allowed beyond MAX_LINES, each with its reason
LONG_MODULES = {
    "fem/contact.py": "the dolfinx contact solver (mesh, forms, SNES-VI, results) predates "
                      "the limit; its split is open (issue 11)",
    "genomics/genome.py": "the Genome type, its field-by-field JSON checks (the bad-input "
                          "table) and the Eq. 3.5 realisation it defines; 2D genomes are "
                          "being added (issue 15), split with them",
    "model.py": "the contract layer: Material, Loading, ContactResult and SweepResult are "
                "read together by every method and consumer (one module, one import)",
}


def _layer(parts):
    """Layer index of a module given its path parts below roughfe/."""
    head = parts[0].removesuffix(".py")
    if head == "__main__":             # python -m roughfe: the command line's entry point
        head = "cli"
    if head in BASE:
        return -1, head
    if head not in ORDER:
        pytest.fail(f"roughfe/{'/'.join(parts)} is not in a known layer {ORDER}")
    return ORDER.index(head), head


def _imports(path):
    tree = ast.parse(path.read_text(), filename=str(path))
    rel = path.relative_to(PKG).parts
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield node.lineno, alias.name
        elif isinstance(node, ast.ImportFrom):
            if node.level == 0 and node.module == "roughfe":
                for alias in node.names:       # from roughfe import X: X's own layer
                    yield node.lineno, f"roughfe.{alias.name}"
            elif node.level == 0:
                yield node.lineno, node.module or ""
            else:
                base = list(rel[:-1])
                if node.level > 1:
                    base = base[: len(base) - (node.level - 1)]
                mod = ".".join(["roughfe", *base, *(node.module.split(".") if node.module else [])])
                if not node.module:
                    for alias in node.names:
                        yield node.lineno, f"{mod}.{alias.name}"
                else:
                    yield node.lineno, mod


def _namespace():
    """The top-level table: name -> defining module, and the lazy submodules."""
    import roughfe
    return roughfe._EXPORTS, roughfe._SUBMODULES


def test_imports_flow_one_way():
    exports, _ = _namespace()
    bad = []
    for path in sorted(PKG.rglob("*.py")):
        rel = path.relative_to(PKG).parts
        if rel == ("__init__.py",):
            continue
        me, my_name = _layer(rel)
        for lineno, mod in _imports(path):
            top = mod.split(".")[0]
            if top in FEM_ONLY and my_name != "fem":
                bad.append(f"{path.relative_to(PKG.parent)}:{lineno} imports {mod} outside roughfe/fem")
            if top != "roughfe" or mod == "roughfe":
                continue
            target = mod.split(".")[1]
            if target in exports:
                bad.append(f"{path.relative_to(PKG.parent)}:{lineno} imports {target} through "
                           f"the top-level namespace; import it from {exports[target]}")
                continue
            if target in BASE or target == "__version__":
                continue
            other, _ = _layer([target])
            if other > me:
                bad.append(f"{path.relative_to(PKG.parent)}:{lineno} imports {mod} (rightward)")
    assert not bad, "backward imports:\n" + "\n".join(bad)


def test_top_level_namespace_is_lazy_and_stays_left_of_plotting_and_cli():
    exports, submodules = _namespace()
    tree = ast.parse((PKG / "__init__.py").read_text())
    eager = [f"line {node.lineno}" for node in tree.body
             if isinstance(node, ast.ImportFrom) and (node.level or node.module == "roughfe"
                                                     or node.module.startswith("roughfe."))
             or isinstance(node, ast.Import) and any(a.name.startswith("roughfe")
                                                     for a in node.names)]
    assert not eager, f"roughfe/__init__.py imports roughfe modules eagerly at {eager}"
    reached = {m.split(".")[1] for m in exports.values()} | set(submodules)
    assert reached <= set(ORDER) | BASE - {"__init__"}, reached - set(ORDER) - BASE
    assert not reached & {"plotting", "cli"}, "nothing imports plotting or cli (STYLE.md (a))"


def test_no_module_is_over_the_line_limit():
    long = {str(p.relative_to(PKG)): len(p.read_text().splitlines())
            for p in sorted(PKG.rglob("*.py"))}
    over = {k: n for k, n in long.items() if n > MAX_LINES and k not in LONG_MODULES}
    assert not over, f"modules over {MAX_LINES} lines (split them by idea): {over}"


# -- validation/: studies and their helper modules ----------------------------------------
def _validation_modules():
    """(studies, helpers): the stems of validation/*.py, split by the leading ``_``."""
    stems = [p.stem for p in sorted(VALIDATION.glob("*.py"))]
    return ({s for s in stems if not s.startswith("_")}, {s for s in stems if s.startswith("_")})


def _top_level_imports(path):
    """(line, top-level module name) of every import of ``path`` (absolute imports)."""
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Import):
            yield from ((node.lineno, a.name.split(".")[0]) for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            yield node.lineno, node.module.split(".")[0]


def test_no_validation_module_is_over_the_line_limit():
    long = {p.name: len(p.read_text().splitlines()) for p in sorted(VALIDATION.glob("*.py"))}
    over = {k: n for k, n in long.items() if n > MAX_LINES}
    assert long and not over, (f"validation modules over {MAX_LINES} lines (split the study "
                               f"into its script and helper modules _*.py): {over}")


def test_validation_studies_import_helpers_and_the_library_not_each_other():
    studies, helpers = _validation_modules()
    bad, used = [], set()
    for path in sorted(VALIDATION.glob("*.py")):
        for lineno, top in _top_level_imports(path):
            used.add(top)
            if top in studies:
                bad.append(f"validation/{path.name}:{lineno} imports the study {top} (move "
                           "what it shares into a helper module _*.py)")
            if top in FEM_ONLY:
                bad.append(f"validation/{path.name}:{lineno} imports {top} (go through "
                           "roughfe.fem)")
        if path.stem in helpers and any(isinstance(n, ast.FunctionDef) and n.name == "main"
                                        for n in ast.parse(path.read_text()).body):
            bad.append(f"validation/{path.name} defines main: a helper is not a study")
    bad += [f"validation/{h}.py is imported by no study" for h in sorted(helpers - used)]
    assert not bad, "\n".join(bad)


def test_every_validation_study_is_run_by_roughfe_validate():
    """A study that no ``roughfe validate NAME`` names is never run nor paged (docs/generate.py
    pages the validation/*.py without a leading ``_``), and a name must point at a study."""
    from roughfe.cli.validate_cmd import VALIDATIONS
    studies, _ = _validation_modules()
    named = {script for scripts in VALIDATIONS.values() for script in scripts}
    assert studies == named, (f"studies no validation runs: {sorted(studies - named)}; "
                              f"names without a study: {sorted(named - studies)}")
