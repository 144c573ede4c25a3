"""The README and the tutorials run as written: their code cannot rot.

Every ```python block and every ``roughfe ...`` line of a ```bash block of a page is run
in order, in a fresh folder, in ONE separate process per page (python blocks share one
namespace, as in a notebook; ``roughfe ARGS`` is ``roughfe.cli.main(ARGS)``, the entry
point of the ``roughfe`` script, which must return 0; vtk is loaded first, as in a
separate ``roughfe`` process). A block preceded by the line
``<!-- not-run -->`` is shown but not run (long runs such as ``make validate``); other
shell lines (``make ...``) are never run here.
"""
import json
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs" / "tutorials").glob("*.md"))]
FENCE = re.compile(r"^(<!-- not-run -->\n)?```(\w+)[^\n]*\n(.*?)^```", re.M | re.S)

DRIVER = r"""
import json, sys, traceback
from roughfe._runtime import load_render_backend; load_render_backend()  # vtk before dolfinx
steps = json.load(sys.stdin)
namespace = {"__name__": "__main__"}
for i, (kind, payload) in enumerate(steps):
    try:
        if kind == "python":
            exec(compile(payload, f"<python block {i}>", "exec"), namespace)
        else:
            from roughfe.cli import main
            code = main(payload)
            if code != 0:
                sys.exit(f"step {i}: roughfe {' '.join(payload)} exited with {code}")
    except SystemExit:
        raise
    except BaseException:
        traceback.print_exc()
        sys.exit(f"step {i} ({kind}) failed: {payload if kind == 'cli' else payload[:300]}")
"""


def snippets(text):
    """The page's steps in order: ("python", source) or ("cli", argv)."""
    steps = []
    for skip, lang, body in FENCE.findall(text):
        if skip:
            continue
        if lang == "python":
            steps.append(("python", body))
        elif lang in ("bash", "sh", "shell"):
            for line in body.replace("\\\n", " ").splitlines():
                words = shlex.split(line, comments=True)
                if words and words[0] == "roughfe":
                    steps.append(("cli", words[1:]))
    return steps


def test_snippets_are_found():
    steps = snippets("```bash\nmake test  # no\nroughfe info a.npz --json  # comment\n"
                     "roughfe contact a.npz \\\n  --E 1e9\n```\n<!-- not-run -->\n"
                     "```python\nskipped()\n```\n```python\nx = 1\n```\n")
    assert steps == [("cli", ["info", "a.npz", "--json"]),
                     ("cli", ["contact", "a.npz", "--E", "1e9"]), ("python", "x = 1\n")]
    assert "make demo" in PAGES[0].read_text() and "make test" in PAGES[0].read_text()


@pytest.mark.slow
@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_page_runs_as_written(page, tmp_path):
    steps = snippets(page.read_text())
    if not steps:
        pytest.skip(f"{page.name} has no code")
    env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg", PYVISTA_OFF_SCREEN="true")
    proc = subprocess.run([sys.executable, "-c", DRIVER], input=json.dumps(steps), text=True,
                          capture_output=True, cwd=tmp_path, env=env, timeout=600)
    assert proc.returncode == 0, f"{page.name}:\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"


def test_docs_pages_named_in_the_code_exist():
    # a docstring or comment that sends the reader to a docs page must name one that is
    # there (theory/adhesion-persson.md, theory/leakage.md and usage/cli.md were not:
    # the pages are theory/07_adhesion_persson.md, theory/04_leakage.md and
    # 04b_leakage_ii.md, guide/02_command_line.md; benchmarks/ names a generated page)
    named = re.compile(r"docs/[\w./-]+?\.(?:md|rst)\b")
    missing = set()
    for folder in ("roughfe", "tests", "validation"):
        for path in (ROOT / folder).rglob("*.py"):
            for ref in named.findall(path.read_text()):
                if not (ROOT / ref).exists():
                    missing.add(f"{path.relative_to(ROOT)}: {ref}")
    assert not missing, sorted(missing)
