"""``roughfe demo -o DIR``: the embedded default case, written to ``DIR/index.md``.

The demo is an ordered tuple of sections, :data:`SECTIONS`. Each section is a function
``section(outdir, context) -> str`` that writes its files into ``outdir`` and returns
markdown text for ``index.md``; ``context`` is a dict shared by the sections (the first
section puts the demo surface in ``context["surface"]``), so later sections can use
earlier results. To extend the demo, add a function and append it to ``SECTIONS``.
"""
from __future__ import annotations

from pathlib import Path

from ..surfaces.stats import surface_statistics
from ..writers import write_text


def section_surface(outdir: Path, context: dict) -> str:
    """RMD surface of thesis Fig. 7 (D = 2.3, m = 7, L = 0.1 mm) and its statistics."""
    from ..surfaces.rmd import rmd_surface
    surface = rmd_surface(m=7, fractal_dimension=2.3, length=1e-4, rng=0)
    context["surface"] = surface
    s = surface_statistics(surface)
    return (f"## RMD surface (thesis Fig. 7)\n\nD = 2.3, m = 7, L = 0.1 mm, seed 0: "
            f"{surface.shape[0]} x {surface.shape[1]} points, rms height "
            f"{s.rms_height * 1e6:.4g} um, fitted D = {s.fractal_dimension:.3f}\n")


SECTIONS = (section_surface,)


def run_demo(outdir) -> Path:
    """Run every section in order and write ``outdir/index.md``; return its path."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    context: dict = {}
    parts = ["# roughfe demo\n"]
    for section in SECTIONS:
        print(f"demo: {section.__name__}")
        parts.append(section(outdir, context))
    return write_text(outdir / "index.md", "\n".join(parts))


def _run(args) -> int:
    index = run_demo(args.output)
    print(f"demo written: {index}")
    return 0


def register(sub):
    p = sub.add_parser("demo", help="run the default case and write figures + index.md",
                       description=__doc__)
    p.add_argument("-o", "--output", default="demo-output", help="output folder")
    p.set_defaults(func=_run)
