"""The README and the guides (docs/guide/*.md) say what the code does.

A user copies the pages' code; this test fails when a name they use is renamed or
removed:

* every ```python block of README.md and of each guide runs as written (one process per
  page, the blocks sharing one namespace, with ``test_docs_snippets``' driver; the
  README's ``roughfe`` lines run too, as its tour builds on them). A block preceded by
  ``<!-- not-run -->`` is shown only: say why beside it. The guides' ``roughfe`` lines
  are parsed, not run: they name placeholders (``SPEC.toml``, a dask scheduler, mpirun);
  the guide's TOML study spec is read and checked by the runner's own input check;
* every ``roughfe`` line of a code block parses with the command's argparse parser, and
  every ``--option`` of a code span or code line is an option of the command named with
  it (``contact --mirror``, ``genome mechanics/natural --steps``), or, named alone
  (``--E``), of some command; options of other programs are listed below. This and the
  next check cover docs/getting_started.md and the tutorials too;
* every ``roughfe.x.y`` on the pages imports, every called name (``run_study(...)``,
  ``Surface.cropped(index=...)``) is defined in roughfe with the keywords written, and
  guide 04's namespace table is ``roughfe._EXPORTS``;
* every key, column, dataset or attribute that guide 02's file table (and the README's
  tour) names is in the files the commands write (a tiny run of each writer; the few
  that need a long run are listed with the reason).

The pages' own sizes are small (128^2 surfaces, 512-node profiles): the whole module
takes 15-35 s on 2 shared cores (the README's run 6-12 s of it), so no environment
variable shrinks them.
"""
import ast
import builtins
import contextlib
import csv
import functools
import importlib
import io
import json
import os
import re
import shlex
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

from test_docs_snippets import DRIVER, snippets

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
GUIDES = sorted((ROOT / "docs" / "guide").glob("*.md"))
PAGES = [README, *GUIDES]
# the names and options of the getting-started page and the tutorials are checked too (the
# tutorials run in tests/test_docs_snippets.py)
NAMED_PAGES = [*PAGES, ROOT / "docs" / "getting_started.md",
               *sorted((ROOT / "docs" / "tutorials").glob("*.md"))]
FENCE = re.compile(r"^(<!-- not-run -->\n)?```(\w*)[^\n]*\n(.*?)^```", re.M | re.S)
SHELL = ("bash", "sh", "shell", "console", "")

# options of other programs that the pages name on their own (a span that starts with the
# program, `mpirun -n 9 ...`, `dask worker ...`, is skipped as a whole: FOREIGN_PROGRAMS)
FOREIGN_OPTIONS = {
    "--system-site-packages": "python3 -m venv (README set-up)",
    "--allow-run-as-root": "OpenMPI's mpirun (guide 01, on a cluster)",
    "--oversubscribe": "OpenMPI's mpirun (guide 01, on a cluster)",
}
# calls of other libraries (or formulas) written in code spans
FOREIGN_CALLS = {
    "SLURMCluster": "dask_jobqueue (guide 01, on a cluster)",
    "cluster.scale": "dask_jobqueue's cluster (guide 01)",
    "sqrt": "a formula (guide 03)",
}
FOREIGN_PROGRAMS = {"python", "python3", "/usr/bin/python3", "mpirun", "srun", "dask",
                    "make", "nice", "pip", "git"}


# -- the command line -----------------------------------------------------------------------
@functools.lru_cache(maxsize=None)
def _parser():
    """The whole ``roughfe`` parser (argparse does not change it while parsing)."""
    from roughfe.cli import build_parser
    return build_parser()


def _children(parser):
    import argparse
    subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    return subs[0].choices if subs else {}


def _options(parser):
    return {o for a in parser._actions for o in a.option_strings}


def _all_options(parser):
    found = set(_options(parser))
    for child in _children(parser).values():
        found |= _all_options(child)
    return found


def cells(line):
    """The cells of a Markdown table row (``\\|`` inside a cell is not a border)."""
    return re.split(r"(?<!\\)\|", line)


def _prose(text):
    """The page without its code blocks, and with the "before" cells of tables whose header
    has a "before" column blanked (guide 03 names the old behaviour there: history, not an
    instruction)."""
    text = FENCE.sub("", text)
    out, before = [], None
    for line in text.splitlines():
        if line.startswith("|"):
            row = cells(line)
            heads = [c.strip() for c in row]
            if "before" in heads and before is None:
                before = heads.index("before")
            elif before is not None and len(row) > before:
                row[before] = " "
                line = "|".join(row)
        else:
            before = None
        out.append(line)
    return "\n".join(out)


def code_spans(text):
    """The code spans of the prose, a span wrapped over lines included."""
    return [s for s in re.findall(r"(?<!`)`([^`]+)`(?!`)", _prose(text)) if "\n\n" not in s]


def command_mentions(text):
    """("line", words) for each ``roughfe`` line of a shell block and ("span", words) for
    each code span of the prose; words with ``\\|`` unescaped."""
    found = []
    for skip, lang, body in FENCE.findall(text):
        if lang in SHELL:
            for line in body.replace("\\\n", " ").splitlines():
                try:
                    words = shlex.split(line, comments=True)
                except ValueError:
                    continue
                if any(w in ("roughfe", "roughfe)") for w in words):
                    found.append(("line", words))
    for span in code_spans(text):
        found.append(("span", span.replace("\\|", "|").split()))
    return found


def _long_options(words):
    """The ``--option`` tokens of ``words`` (``--a/--b`` is two; ``--global-*`` a prefix)."""
    names = []
    for word in words:
        for part in word.split("/"):
            m = re.match(r"--[A-Za-z][\w-]*\*?", part)
            if m:
                names.append(m.group(0))
    return names


def unknown_options(words, parser, every):
    """The options in ``words`` that the command they name does not have."""
    at = next((i for i, w in enumerate(words) if w in ("roughfe", "roughfe)")), None)
    if at is None and words and words[0] in FOREIGN_PROGRAMS:
        return []
    words = words if at is None else words[at + 1:]
    commands, top = [], _children(parser)
    if words and words[0] in top:
        commands, words = [top[words[0]]], words[1:]
        subs = _children(commands[0])
        if subs:
            named = re.split(r"[|/]", words[0]) if words else []
            if named and all(n in subs for n in named):
                commands, words = [subs[n] for n in named], words[1:]
            else:    # `validate ... --quick`, `generate --overwrite`: any of its commands
                commands = [commands[0], *subs.values()]
    have = set().union(*map(_options, commands)) if commands else every
    bad = []
    for name in _long_options(words):
        if name.endswith("*"):
            ok = any(o.startswith(name[:-1]) for o in have)
        else:
            ok = name in have or (not commands and name in FOREIGN_OPTIONS)
        if not ok:
            bad.append(name)
    return bad


def parse_error(words, parser):
    """argparse's error for the ``roughfe`` line ``words`` (None when it parses)."""
    at = next(i for i, w in enumerate(words) if w in ("roughfe", "roughfe)"))
    err = io.StringIO()
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            parser.parse_args(words[at + 1:])
    except SystemExit as exc:
        return f"exit {exc.code}: {err.getvalue().strip().splitlines()[-1:]}"
    return None


def test_the_option_check_finds_a_renamed_option():
    parser = _parser()
    every = _all_options(parser)
    page = ("```bash\nroughfe contact a.npz --E 1e9 --no-such-option 3 -o x\n```\n"
            "`contact --mirror` and `contact --mirrored`, `genome natural|mechanics --steps`, "
            "`genome mechanics --row`, `--global-*`, `--nope-*`, `--E`, `--Youngs`, "
            "`mpirun -n 2 --oversubscribe`, `--oversubscribe`\n\n"
            "| what | before | now |\n|---|---|---|\n| x | `contact --old` | `contact --new` |\n")
    bad = [unknown_options(w, parser, every) for _, w in command_mentions(page)]
    assert bad == [["--no-such-option"], [], ["--mirrored"], [], ["--row"], [], ["--nope-*"],
                   [], ["--Youngs"], [], [], ["--new"]]
    (line,) = [w for kind, w in command_mentions(page) if kind == "line"]
    assert "unrecognized arguments: --no-such-option" in parse_error(line, _parser())


@pytest.mark.parametrize("page", NAMED_PAGES, ids=lambda p: p.name)
def test_table_cells_close_their_code_spans(page):
    # a `|` in a code span of a table row ends the cell (GFM, MyST): the row renders with
    # a cell too many and the spans pair across cells (guide 03 had `roughfe leak ... | head`)
    bad = [cell.strip()[:60] for line in FENCE.sub("", page.read_text()).splitlines()
           if line.startswith("|") for cell in cells(line) if cell.count("`") % 2]
    assert not bad, f"{page.name}: write | inside a table's code span as \\|: {bad}"


@pytest.mark.parametrize("page", NAMED_PAGES, ids=lambda p: p.name)
def test_every_option_on_the_page_exists(page):
    parser = _parser()
    every = _all_options(parser)
    bad = {}
    for kind, words in command_mentions(page.read_text()):
        unknown = unknown_options(words, parser, every)
        if unknown:
            bad[" ".join(words)] = unknown
        if kind == "line":
            error = parse_error(words, parser)
            if error:
                bad[" ".join(words)] = error
    assert not bad, f"{page.name}: options the command does not have: {bad}"


# -- names of the Python API ----------------------------------------------------------------
@functools.lru_cache(maxsize=None)
def _signatures():
    """name -> parameter names (None: takes **kwargs) of every function, method and class
    (dataclass fields, __init__) defined in roughfe, merged over equal names."""
    sigs = {}

    def add(name, params):
        old = sigs.get(name, set())
        sigs[name] = None if params is None or old is None else old | params

    for path in (ROOT / "roughfe").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                a = node.args
                params = {x.arg for x in a.posonlyargs + a.args + a.kwonlyargs}
                add(node.name, None if a.kwarg else params)
            elif isinstance(node, ast.ClassDef):
                fields = {s.target.id for s in node.body
                          if isinstance(s, ast.AnnAssign) and isinstance(s.target, ast.Name)}
                inits = [s for s in node.body
                         if isinstance(s, ast.FunctionDef) and s.name == "__init__"]
                if inits and inits[0].args.kwarg:
                    add(node.name, None)
                else:
                    init = {x.arg for s in inits for x in s.args.args + s.args.kwonlyargs}
                    add(node.name, fields | init)
    return sigs


def calls(text):
    """(name, keywords) of every call written in a code span: ``a.b(x, k=1)`` ->
    ("a.b", {"k"}); nested calls count too."""
    found = []
    for span in code_spans(text):
        span = " ".join(span.split())
        for m in re.finditer(r"(?<![\w.])([A-Za-z_][\w.]*)\(", span):
            depth, i = 1, m.end()
            while i < len(span) and depth:
                depth += {"(": 1, ")": -1}.get(span[i], 0)
                i += 1
            inner = span[m.end():i - 1]
            # keywords at this call's own level only
            flat = re.sub(r"\([^()]*\)", "", inner)
            found.append((m.group(1), set(re.findall(r"(?<![\w.=])(\w+)\s*=(?!=)", flat))))
    return found


def test_calls_are_found():
    text = ("`run_study(load_spec(\"S.toml\"), executor=\"dask\", scheduler=...)`, "
            "`adhesive_sweep(spring=)`, `x == y`")
    assert calls(text) == [("run_study", {"executor", "scheduler"}), ("load_spec", set()),
                           ("adhesive_sweep", {"spring"})]


def missing_names(text):
    """The ``roughfe.x.y`` names that do not import and the calls (name or keyword) that
    roughfe does not define, of the code spans of ``text``."""
    missing = []
    for dotted in sorted(set(re.findall(r"(?<![\w.])roughfe(?:\.\w+)+", _prose(text)))):
        parts = dotted.split(".")
        for i in range(len(parts), 0, -1):
            try:
                obj = importlib.import_module(".".join(parts[:i]))
                break
            except ImportError:
                continue
        for attr in parts[i:]:
            obj = getattr(obj, attr, None)
        if obj is None:
            missing.append(dotted)
    sigs = _signatures()
    for name, keywords in calls(text):
        last = name.split(".")[-1]
        if hasattr(builtins, last) or name in FOREIGN_CALLS:
            continue
        if last not in sigs:
            missing.append(f"{name}()")
        elif sigs[last] is not None and keywords - sigs[last]:
            missing.append(f"{name}({', '.join(sorted(keywords - sigs[last]))}=)")
    return missing


def test_the_name_check_finds_a_renamed_name():
    text = ("`roughfe.model.RECORD_KEYS`, `roughfe.model.RECORD_KEYZ`, `roughfe.nothing`, "
            "`Surface.cropped(index=...)`, `Surface.cropped(indices=...)`, "
            "`load_surfaces(path)`, `open()`, `SLURMCluster(cores=1)`")
    assert missing_names(text) == ["roughfe.model.RECORD_KEYZ", "roughfe.nothing",
                                   "Surface.cropped(indices=)", "load_surfaces()"]


@pytest.mark.parametrize("page", NAMED_PAGES, ids=lambda p: p.name)
def test_names_of_the_api_on_the_page_exist(page):
    missing = missing_names(page.read_text())
    assert not missing, f"{page.name} names what roughfe does not define: {missing}"


def test_the_namespace_table_is_the_exports():
    import roughfe
    text = (ROOT / "docs" / "guide" / "04_python_api.md").read_text()
    table = {}
    for line in text.splitlines():
        cells = [c.strip() for c in line.strip("|").split("|")]
        if len(cells) == 2 and cells[1].startswith("`roughfe.") and "subpackages" not in line:
            for name in re.findall(r"`(\w+)`", cells[0]):
                table[name] = cells[1].strip("`")
    assert table == roughfe._EXPORTS
    row = next(line for line in text.splitlines() if "the subpackages" in line)
    for sub in re.findall(r"`(\w+)`", row.split("|")[1]):
        assert importlib.import_module(f"roughfe.{sub}") is getattr(roughfe, sub)


def test_the_study_spec_of_guide_01_is_accepted():
    from roughfe.study import spec_from_mapping
    from roughfe.study.analyses import check_parameters
    (body,) = [b for _, lang, b in FENCE.findall(GUIDES[0].read_text()) if lang == "toml"]
    spec = spec_from_mapping(tomllib.loads(body))
    tasks = spec.tasks()
    assert len(tasks) == 7 * 5 * 2    # m x D x replica, as its comments say
    for params in {json.dumps(t.kwargs, sort_keys=True) for t in tasks}:
        check_parameters(spec.analysis, json.loads(params))


# -- running the pages ----------------------------------------------------------------------
def run_steps(steps, cwd):
    env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg", PYVISTA_OFF_SCREEN="true")
    proc = subprocess.run([sys.executable, "-c", DRIVER], input=json.dumps(steps), text=True,
                          capture_output=True, cwd=cwd, env=env, timeout=600)
    assert proc.returncode == 0, f"{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
    return proc


# what guide 02's file table describes, written by small runs of each writer (the README's
# tour writes contact/, leak/, genome.json, 100x.npz, surface.npz and sequenced/)
EXTRA_RUNS = """
roughfe generate spectral --n 32 --length 1e-4 --hurst 0.8 --rms-height 1e-6 --seed 0 --no-figures -o s32.npz
roughfe contact s32.npz --non-periodic --E 210e9 --nu 0.3 --steps 3 --unload --hardness 2e9 --no-figures --quiet -o window
roughfe leak s32.npz --E 210e9 --nu 0.3 --pressure 1e8 --fsi --direction x --no-figures --quiet -o fsi
roughfe genome chromosomes s32.npz --steps 3 --no-figures --quiet -o chromosomes
roughfe genome mechanics genome.json --nodes 64 --steps 3 --max-chromosomes 4 --no-figures --quiet -o mechanics
roughfe genome natural 100x.npz --nodes 64 --steps 3 --no-figures --quiet -o natural
roughfe db build tiny.sqlite --nodes 128 --steps 5 --limit 4 --workers 1 --quiet
roughfe design --db tiny.sqlite --target y_t1 --method sog --iterations 2 --no-figures --quiet -o design
"""

# row of the file table -> (files of the runs, keys it names that these runs cannot show)
FILE_ROWS = {
    "`results.json`": (["contact/results.json", "leak/results.json", "window/results.json",
                        "fsi/results.json"], {"ContactResult": "the type giving the units",
                                              "null": "a value, not a key"}),
    "`fields.h5`": (["contact/fields.h5", "window/fields.h5"], {}),
    "`fields/step_NNN.npz`": (["leak/fields/step_000.npz", "fsi/fields/step_000.npz"], {}),
    "`.npz` surface": (["surface.npz", "100x.npz", "natural/100x_acq1.npz",
                        "design/profile.npz"], {}),
    "`genome.json`": (["genome.json", "sequenced/genome.json", "natural/100x_genome.json",
                       "design/genome.json"],
                      {k: "2D genomes: sequencing a surface takes ~7 s"
                       for k in ("angles", "anisotropy")}),
    "`chromosomes.npz`": (["chromosomes/chromosomes.npz"], {}),
    "`mechanics.json`": (["chromosomes/mechanics.json", "mechanics/mechanics_strip.json"], {}),
    "`macro_micro.json`": (["chromosomes/macro_micro.json"], {}),
    "`report.json`, `STEM_report.json`": (
        ["sequenced/report.json", "natural/100x_report.json"],
        {k: "2D acquisitions: sequencing a surface takes ~7 s"
         for k in ("angles_deg", "anisotropy", "n_first", "n_last", "signal_rms_m",
                   "fit_rms_errors")}),
    "`result.json`, `design.json`, `curves.csv`, `stages.csv`": (
        ["design/result.json", "design/design.json", "design/curves.csv", "design/stages.csv"],
        {"K_exact_Pa_per_m": "a database built with --stiffness exact",
         "target_NAME_K": "target_y_t1_K here",
         "_A": "the suffix of target_NAME_A", "nan": "a value, not a key"}),
}
NOT_CHECKED = {"`genome_partK.json`": "a design of several genomes (a larger database)",
               "`FILE.csv`, `FILE_coherence.csv`; `FILE.png`":
                   "an instrument file with a trace and a retrace channel (di-1, not in the "
                   "guide's blocks): tests/test_cli_info_reliability.py checks its columns"}


def _names_in(path):
    """Every key (JSON, nested), column (CSV), array (npz; its ``units`` JSON too) and
    dataset or attribute (HDF5) of the file."""
    def keys(obj):
        if isinstance(obj, dict):
            return set(obj) | set().union(*map(keys, obj.values()))
        if isinstance(obj, list):
            return set().union(*map(keys, obj))
        return set()
    if path.suffix == ".json":
        return keys(json.loads(path.read_text()))
    if path.suffix == ".csv":
        return set(next(csv.reader(path.open())))
    if path.suffix == ".npz":
        with np.load(path) as z:
            names = set(z.files)
            if "units" in names:
                names |= keys(json.loads(str(z["units"])))
        return names
    import h5py
    with h5py.File(path, "r") as f:
        return set(f) | set(f.attrs) | {a for d in f.values() for a in d.attrs}


def _documented(cell):
    """Identifiers in the code spans of a table cell (``x_a/_b`` is x_a and x_b)."""
    names = set()
    for span in re.findall(r"`([^`]+)`", cell):
        first, *alts = span.split("/")
        if re.fullmatch(r"\w+", first) and all(re.fullmatch(r"_\w+", a) for a in alts):
            names.add(first)
            names |= {first.rsplit("_", 1)[0] + a for a in alts}
    return names


@pytest.fixture(scope="module")
def readme_run(tmp_path_factory):
    """The README's tour (its roughfe lines and python blocks), then EXTRA_RUNS, in one
    folder."""
    cwd = tmp_path_factory.mktemp("readme")
    steps = snippets(README.read_text())
    assert sum(kind == "python" for kind, _ in steps) >= 1
    steps += [("cli", shlex.split(line)[1:]) for line in EXTRA_RUNS.strip().splitlines()]
    proc = run_steps(steps, cwd)
    return cwd, proc.stdout


@pytest.mark.slow
def test_readme_runs_and_its_numbers_are_those_it_quotes(readme_run):
    cwd, stdout = readme_run
    # "contact/results.json holds one record per load step (`mean_pressure`, ...)"
    para = README.read_text().split("`contact/results.json` holds")[1].split("\n\n")[0]
    results = json.loads((cwd / "contact" / "results.json").read_text())
    assert len(results["steps"]) == 3
    for key in ("mean_pressure", "area_fraction", "stiffness", "mean_gap"):
        assert f"`{key}`" in para and key in results["steps"][0]
    assert (cwd / "contact" / "fields.h5").exists()
    # "H = 0.79 +- 0.04 against 0.75 here; ... `M_support` gives its likelihood range, 4..20"
    report = json.loads((cwd / "sequenced" / "report.json").read_text())
    h, h_err = re.search(r"H = ([\d.]+) \+- ([\d.]+) against 0.75", README.read_text()).groups()
    m_range = re.search(r"likelihood range, (\d+)\.\.(\d+)", README.read_text()).groups()
    assert f"{report['genes']['H']:.2f}" == h and f"{report['H_stderr']:.2f}" == h_err
    assert report["M_support"] == [int(m) for m in m_range]
    # "the three profiles are reproduced to round-off and gamma, lambda1 come back exact"
    assert max(report["rms_errors"]) < 1e-12 and report["genes"]["gamma"] == 1.5
    # and the python block's own round trip
    assert "sequenced: gamma = 1.5, success = True" in stdout


@pytest.mark.slow
def test_every_file_key_of_guide_02_is_written(readme_run):
    cwd, _ = readme_run
    text = (ROOT / "docs" / "guide" / "02_command_line.md").read_text()
    files_table = text.split("| file | written by | content |")[1].split("\n\n")[0]
    rows = {cells(line)[1].strip(): "|".join(cells(line)[3:])
            for line in files_table.splitlines() if line.startswith("| `")}
    assert set(rows) == set(FILE_ROWS) | set(NOT_CHECKED), "a new row: add it to FILE_ROWS"
    parser = _parser()
    commands = set(_children(parser)) | {s for c in _children(parser).values()
                                         for s in _children(c)}
    missing = {}
    for row, (files, exempt) in FILE_ROWS.items():
        written = set().union(*(_names_in(cwd / f) for f in files))
        lost = _documented(rows[row]) - written - set(exempt) - commands
        if lost:
            missing[row] = sorted(lost)
    assert not missing, f"guide 02 names keys that the commands do not write: {missing}"


# claims of a guide's code comments, checked in the page's own namespace after its blocks
CLAIMS = {
    "04_python_api.md": "assert window.heights.shape == (64, 64) and not window.periodic\n"
                        "assert len(sweep.area_fraction) == 2\n",
}


@pytest.mark.slow
@pytest.mark.parametrize("page", GUIDES, ids=lambda p: p.name)
def test_python_blocks_of_the_guide_run(page, tmp_path):
    steps = [s for s in snippets(page.read_text()) if s[0] == "python"]
    if not steps:
        pytest.skip(f"{page.name} has no python block")
    run_steps(steps + [("python", CLAIMS.get(page.name, ""))], tmp_path)
