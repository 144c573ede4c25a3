"""docs/generate.py: result pages carry the JSON's numbers and verdicts, never invented ones."""
import importlib.util
import json
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def gen():
    spec = importlib.util.spec_from_file_location("docs_generate", ROOT / "docs" / "generate.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _pages(gen, tmp_path, payloads):
    """Write fake scripts + JSON, run the generator, return {stem: page text}."""
    scripts, output, pages = tmp_path / "validation", tmp_path / "output", tmp_path / "pages"
    scripts.mkdir()
    output.mkdir()
    for stem, data in payloads.items():
        (scripts / f"{stem}.py").write_text("")
        if data is not None:
            (output / f"{stem}.json").write_text(json.dumps(data))
    report = gen.write_results(sorted(scripts.glob("*.py")), output, pages, "Validation",
                               {"alpha": "roughfe validate alpha"})
    assert len(report) == len(payloads)
    return {p.stem: p.read_text() for p in pages.glob("*.md")}


def test_targets_records_give_values_and_verdicts(gen, tmp_path):
    data = {"title": "Alpha check", "elapsed_s": 12.5,
            "targets": [{"name": "width error", "value": 0.0012, "target": 0.005, "met": True,
                         "unit": "relative"},
                        {"name": "area error", "value": 0.0912, "target": 0.02, "met": False}],
            "cases": {"rmd": [{"r": 1, "A": 0.123456789}, {"r": 2, "A": None}]},
            "diffs": [{"max|dp|/max p": 1e-10}]}
    page = _pages(gen, tmp_path, {"alpha": data})["alpha"]
    assert "# Validation: Alpha check" in page
    assert "1 of 2 met." in page
    assert "| width error | 0.0012 | 0.005 | relative | met |" in page
    assert "| area error | 0.0912 | 0.02 | n/a | **NOT met** |" in page
    assert "| elapsed_s | 12.5 |" in page            # top-level scalar summary
    assert "| max\\|dp\\|/max p |" in page                 # a pipe in a header is escaped
    assert "## cases / rmd" in page and "| 1 | 0.1235 |" in page and "| 2 | n/a |" in page
    assert "roughfe validate alpha" in page
    assert page.count("width error") == 1                  # the targets are listed once


def test_legacy_flag_maps_are_found_at_any_depth(gen, tmp_path):
    data = {"checks": {"hertz": True, "line": False},
            "cases": {"rmd": {"ok_by_target": {"area": False}}},
            "targets": {"hertz": 0.02}}
    page = _pages(gen, tmp_path, {"beta": data})["beta"]
    assert "1 of 3 met." in page
    assert "| hertz | 0.02 | met |" in page
    assert "| line | n/a | **NOT met** |" in page
    assert "| cases.rmd: area | n/a | **NOT met** |" in page


def test_quick_run_is_used_and_named_when_the_full_run_is_missing(gen, tmp_path):
    scripts, full, quick, pages = (tmp_path / d for d in ("v", "full", "quick", "pages"))
    for d in (scripts, full, quick):
        d.mkdir()
    (scripts / "alpha.py").write_text("")
    (quick / "alpha.json").write_text(json.dumps(
        {"targets": [{"name": "w", "target": "<= 1 %", "measured": "0.2 %", "value": 0.002,
                      "met": True, "reason": ""}]}))
    gen.write_results([scripts / "alpha.py"], full, pages, "Validation",
                      {"alpha": "roughfe validate alpha"}, fallback=quick)
    page = (pages / "alpha.md").read_text()
    assert f"roughfe validate alpha --quick -o {quick}" in page and "1 of 1 met." in page
    assert "| w | 0.002 | <= 1 % | 0.2 % |" in page
    from roughfe.validation import NOT_RUN
    # a row the quick run skips is counted apart, not as missed (a user's review)
    (quick / "alpha.json").write_text(json.dumps(
        {"targets": [{"name": "w", "value": 0.002, "target": 0.01, "met": True},
                     {"name": "refined" + NOT_RUN, "value": None, "target": 0.01,
                      "met": None}]}))
    gen.write_results([scripts / "alpha.py"], full, pages, "Validation",
                      {"alpha": "roughfe validate alpha"}, fallback=quick)
    page = (pages / "alpha.md").read_text()
    assert "1 of 1 run met; 1 not run" in page and "**not run**" in page
    # the page of a missing run names the folder the page is read from
    (quick / "alpha.json").unlink()
    gen.write_results([scripts / "alpha.py"], full, pages, "Validation",
                      {"alpha": "roughfe validate alpha"}, fallback=quick)
    assert f"roughfe validate alpha -o {full}" in (pages / "alpha.md").read_text()


def test_a_page_takes_its_own_variants_not_another_scripts_results(gen, tmp_path):
    # bench_x.py writes bench_x.json and a variant bench_x_8192.json; bench_x_pad.py is a
    # script of its own: its JSON is on its page only
    page = _pages(gen, tmp_path, {"bench_x": {"targets": [{"name": "x", "met": True}]},
                                  "bench_x_pad": {"targets": [{"name": "pad", "met": False}]}})
    (tmp_path / "output" / "bench_x_8192.json").write_text(
        json.dumps({"targets": [{"name": "big", "met": True}]}))
    scripts, output, pages = (tmp_path / d for d in ("validation", "output", "pages"))
    gen.write_results(sorted(scripts.glob("*.py")), output, pages, "Benchmark", {})
    own, pad = ((pages / f"{s}.md").read_text() for s in ("bench_x", "bench_x_pad"))
    assert "| x |" in own and "| big |" in own and "| pad |" not in own
    assert "| pad |" in pad and "| x |" not in pad and "| big |" not in pad
    assert page["bench_x"].count("| pad |") == 0


def test_a_page_from_an_incomplete_validation_run_says_so(gen, tmp_path):
    """summary.json of a killed `roughfe validate` run ("complete": false): every page
    from that folder says the run did not finish and what was not done; a skipped
    target row is shown as not run, not as "not checked"."""
    alpha = {"targets": [{"name": "w", "met": True},
                         {"name": "vs Tamaas: not run", "met": None, "measured": "not run"}]}
    page = _pages(gen, tmp_path, {"alpha": alpha})["alpha"]
    assert "Incomplete run" not in page and "| vs Tamaas: not run | **not run** |" in page
    (tmp_path / "output" / "summary.json").write_text(json.dumps(
        {"planned": ["bem", "fem"], "complete": False, "pending": ["fem"],
         "validations": {}, "all_met": False, "not_run": []}))
    scripts, output, pages = (tmp_path / d for d in ("validation", "output", "pages"))
    gen.write_results(sorted(scripts.glob("*.py")), output, pages, "Validation", {})
    page = (pages / "alpha.md").read_text()
    assert "**Incomplete run**" in page and "not done: fem" in page


def test_missing_json_says_so_and_shows_no_numbers(gen, tmp_path):
    page = _pages(gen, tmp_path, {"gamma": None})["gamma"]
    assert "Not run yet" in page and "gamma.json" in page
    assert "| " not in page and "met" not in page.replace("make docs", "")


def test_api_pages_cover_every_public_module(gen, tmp_path):
    n = gen.write_api(tmp_path)
    modules = [p for p in (ROOT / "roughfe").rglob("*.py")
               if not any(part.startswith(("_", ".")) for part in p.relative_to(ROOT).parts)
               or p.name == "__init__.py"]
    expected = {".".join(p.relative_to(ROOT).with_suffix("").parts).removesuffix(".__init__")
                for p in modules
                if not any(part.startswith(("_", ".")) for part in p.relative_to(ROOT).parts[:-1])}
    written = {p.stem for p in tmp_path.glob("*.rst")}
    assert written == expected and n == len(expected)
    page = (tmp_path / "roughfe.bem.rst").read_text()
    assert ".. automodule:: roughfe.bem\n" in page and ":members:" not in page  # no re-exports


def test_cli_reference_has_every_command(gen, tmp_path):
    from roughfe.cli import SUBCOMMANDS
    page = tmp_path / "cli.md"
    n = gen.write_cli_reference(page)
    text = page.read_text()
    for command in (c for cs in SUBCOMMANDS.values() for c in cs):
        assert f"## `roughfe {command}`" in text
    assert n == text.count("\n## `roughfe") and "## `roughfe genome sequence`" in text
    assert "--E" in text and "(default:" in text


def test_plain_text_docstrings_become_valid_rst():
    """docs/conf.py rewrites the plain-text habits of roughfe docstrings for Sphinx."""
    spec = importlib.util.spec_from_file_location("docs_conf", ROOT / "docs" / "conf.py")
    conf = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(conf)
    lines = ["Solve Eq. (2.12):", "", "    q = -h^3/(12 mu) grad p,   |q| in m^2/s", "",
             "A* = 2 p/(E* gbar) and *emphasis*, ``literal |x|. ok``", "",
             "* item", "  more", "Glued paragraph", "", "Title (long)", "-----", "x"]
    out = conf._rst_docstring(lines)
    assert out[0] == "Solve Eq. (2.12)::"                         # formula block -> literal
    assert out[2] == "    q = -h^3/(12 mu) grad p,   |q| in m^2/s"  # untouched inside it
    assert out[4] == r"A\* = 2 p/(E\* gbar) and *emphasis*, ``literal |x|" + "\u2024 ok``"
    assert out[6:10] == ["* item", "  more", "", "Glued paragraph"]
    assert out[-2] == "-" * len("Title (long)")
