"""Sphinx configuration of the roughfe documentation (``make docs``).

Pages are Markdown (MyST) or reStructuredText. ``index.rst`` collects every page of
``theory/``, ``tutorials/``, ``validation/``, ``benchmarks/`` and ``api/`` by glob, so a new
page needs no edit of the index. The validation and benchmark pages are written by
``docs/generate.py`` from the JSON of ``make validate`` / ``make bench`` before the build.
The API reference imports roughfe (dolfinx included): build with the project's venv python.
"""
import os
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
sys.path.insert(0, str(DOCS.parent))

# Headless rendering, and vtk loaded before dolfinx: autodoc imports roughfe.plotting and
# roughfe.fem in one process (the one set-up: roughfe._runtime).
from roughfe._runtime import load_render_backend  # noqa: E402

load_render_backend()

import roughfe  # noqa: E402

project = "roughfe"
author = "the roughfe developers"
copyright = "roughfe developers, MIT licence"
release = roughfe.__version__
version = release

extensions = [
    "myst_parser",
    "numpydoc",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "sphinx.ext.intersphinx",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "**/.ipynb_checkpoints", "README.md", "api/generated/*.md"]
templates_path = ["_templates"]

# MyST: $...$ and $$...$$ math, ::: fences, definition lists, heading anchors.
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist", "attrs_inline"]
myst_heading_anchors = 3

# API reference: docs/generate.py writes one page per module into api/generated/.
autosummary_generate = False  # docs/generate.py writes the module pages
autosummary_imported_members = False
autodoc_default_options = {}  # module pages ask for :members:; package pages do not
autodoc_typehints = "none"  # numpydoc's Parameters sections carry the types and units
autodoc_member_order = "bysource"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
numpydoc_validation_checks = set()

intersphinx_mapping = {
    "python": ("https://docs.python.org/3", None),
    "numpy": ("https://numpy.org/doc/stable/", None),
    "scipy": ("https://docs.scipy.org/doc/scipy/", None),
}
# The build must work offline: intersphinx inventories are fetched only when asked.
if os.environ.get("ROUGHFE_DOCS_OFFLINE", "1") == "1":
    intersphinx_mapping = {}

html_theme = "pydata_sphinx_theme"
html_title = f"roughfe {release}"
html_static_path = ["_static"]
html_theme_options = {
    "navigation_depth": 3,
    "show_toc_level": 2,
    "header_links_before_dropdown": 6,
    "secondary_sidebar_items": ["page-toc"],
}
html_sidebars = {"**": ["sidebar-nav-bs"]}
html_show_sourcelink = False

highlight_language = "none"  # plain-text formula blocks of the docstrings
nitpicky = False
suppress_warnings = ["myst.header"]


# --- Docstrings are plain-text numpydoc; make them valid reStructuredText -----------------
# roughfe docstrings write formulas as text (|q|, |x - s|), put indented formula blocks
# after a colon and underline module-docstring headings by eye. These are rewritten here
# (the source stays readable in a terminal) instead of littering the code with escapes.
import re  # noqa: E402
import warnings  # noqa: E402

# numpydoc re-reads class docstrings for member lists and warns on "Fields" (handled below)
warnings.filterwarnings("ignore", message="Unknown section", category=UserWarning)
warnings.filterwarnings("ignore", message="potentially wrong underline", category=UserWarning)

_LITERAL_OR_ROLE = re.compile(r"(``.+?``|:[a-z:]+:`[^`]+`|`[^`]+`_?)")
_UNDERLINE = re.compile(r"^(\s*)([-=~^\"'])\2{2,}\s*$")
_LIST_ITEM = re.compile(r"^\s*([-*+]|\d+\.|\(?[a-z0-9]\))\s")
_SECTION_ALIASES = {"Fields": "Attributes"}


_EMPHASIS = re.compile(r"(?<![\w*\\])(\*\*?)(?=[^\s*])([^*]*?[^\s*\\])\1(?![\w*])")
_BULLET = re.compile(r"^(\s*)\* ")


def _escape_markup(text):
    """Escape ``|`` (never a substitution in roughfe) and every ``*`` that is not part of
    ``*emphasis*``/``**strong**`` (``A*``, ``E*|q|``, ``(n, *shape)`` are plain text)."""
    parts = _EMPHASIS.split(text)
    out = []
    for i in range(0, len(parts), 3):
        out.append(parts[i].replace("|", r"\|").replace("*", r"\*"))
        if i + 2 < len(parts):
            out.append(parts[i + 1] + parts[i + 2].replace("|", r"\|") + parts[i + 1])
    return "".join(out)


def _escape_line(line):
    """Plain-text markup outside literals and roles; a ". " inside a literal must not end
    autosummary's first sentence (U+2024, a one-dot leader, looks the same)."""
    bullet = _BULLET.match(line)
    head, line = (line[:bullet.end()], line[bullet.end():]) if bullet else ("", line)
    parts = _LITERAL_OR_ROLE.split(line)
    return head + "".join(p.replace(". ", "\u2024 ") if i % 2 else _escape_markup(p)
                          for i, p in enumerate(parts))


def _indent(line):
    return len(line) - len(line.lstrip())


def _rst_docstring(lines):
    """The docstring lines as valid reStructuredText (see the comment above)."""
    lines = list(lines)
    # a paragraph ending in ":" followed by a blank line and a deeper-indented block
    # (not a list) is a formula or a code block: make it a literal block.
    for i in range(len(lines) - 2):
        cur, blank, nxt = lines[i], lines[i + 1], lines[i + 2]
        if (cur.rstrip().endswith(":") and not cur.rstrip().endswith("::")
                and not blank.strip() and nxt.strip() and _indent(nxt) > _indent(cur)
                and not _LIST_ITEM.match(nxt)
                and not cur.lstrip().startswith((".. ", ":"))):
            lines[i] = cur.rstrip() + ":"
    out, literal_indent, doctest, item_indent = [], None, False, None
    for line in lines:
        # a list item must end with a blank line before less-indented text
        if line.strip() and literal_indent is None and not doctest:
            item = _LIST_ITEM.match(line)
            if (item_indent is not None and _indent(line) < item_indent and not item
                    and out and out[-1].strip()):
                out.append("")
            item_indent = (item.end() if item else
                           item_indent if item_indent is not None
                           and _indent(line) >= item_indent else None)
        elif not line.strip():
            item_indent = None
        if literal_indent is not None:       # inside a literal block: leave verbatim
            if not line.strip() or _indent(line) > literal_indent:
                out.append(line)
                continue
            literal_indent = None
        if doctest or line.lstrip().startswith(">>>"):
            doctest = bool(line.strip())
            out.append(line)
            continue
        m = _UNDERLINE.match(line)
        if m and out and out[-1].strip():
            title = out[-1].strip()
            if title in _SECTION_ALIASES:
                out[-1] = out[-1].replace(title, _SECTION_ALIASES[title])
            line = m.group(1) + m.group(2) * len(out[-1].strip())
        else:
            line = _escape_line(line)
        if line.rstrip().endswith("::"):
            literal_indent = _indent(line)
        out.append(line)
    return out


def _process_docstring(app, what, name, obj, options, lines):
    lines[:] = _rst_docstring(lines)


def setup(app):
    # priority < 500: runs before numpydoc parses the sections
    app.connect("autodoc-process-docstring", _process_docstring, priority=100)
