"""One table of every speed and memory target of issues 12-16, from the benchmarks' JSON.

:data:`EXPECTED` lists each target once: the issue section, the benchmark that measures it,
the text that finds its row among that benchmark's ``targets`` (the name a script gives
it), the target in the issue's words (shown when the row is missing), the unit, and the
text that finds the benchmark's ``skipped`` record that explains a missing row. For each,
:func:`summary_rows` reads ``<folder>/<benchmark>.json`` (and ``<benchmark>_*.json``) and
gives one row per matching target with its value, limit, unit, verdict (the script's own
``met``), the date and the load average of the run:

* ``met`` / ``NOT met``: as the script decided it against the stated limit;
* ``not run``: the benchmark's JSON is missing (``make bench`` has not run it here);
* ``not measured``: the JSON is there but has no such row (a reduced run, e.g.
  ``--quick``, or a case left out): the reason from its ``skipped`` records; or the
  benchmark ran (``run_all.json``) and wrote no report: its exit code;
* ``not checked``: a row without a verdict.

When ``run_all.json`` lists a run of a benchmark, only the files that run wrote (its
``wrote``) are read: a report of an earlier run left in the folder is ignored, and a
row it would have given says so with its date. Target rows of the benchmarks that no
expected entry claims are listed after them, so nothing measured is hidden, then the rows
of ``run_all.json`` itself ("<script> wrote its report", NOT met for a crash).
``run_all.json`` adds the per-benchmark wall, CPU and peak memory of the run. No number
in the table is typed by hand.

Run: ``python benchmarks/summary.py [FOLDER] [OUT.md]`` (defaults ``benchmarks/output``,
``FOLDER/SUMMARY.md``); ``make bench`` runs it last, ``make docs`` writes the same table to
``docs/benchmarks/summary.md``.
"""
from __future__ import annotations

import datetime
import importlib.util
import json
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent

#: (issue section, benchmark, text of the target name, the target as the issue states it,
#: unit, text of the benchmark's ``skipped`` record that explains a missing row)
EXPECTED = (
    ("12 §6, 16 §4", "bench_reynolds", "Reynolds FV 2048^2 CPU",
     "Reynolds leak-rate solve 2048^2 < 10 s", "s CPU", "2048^2"),
    ("12 §6, 16 §4", "bench_reynolds", "Reynolds FV 4096^2 CPU",
     "Reynolds leak-rate solve 4096^2 < 60 s", "s CPU", "4096^2"),
    ("16 §4", "bench_reynolds", "Reynolds FV 4096^2 peak memory",
     "Reynolds 4096^2 < 8 GB", "GB", "4096^2"),
    ("12 §6", "bench_reynolds", "coupled solve 512^2 CPU",
     "coupled solve 512^2 < 1 min", "s CPU", "coupled"),
    ("12 §6", "bench_fsi", "coupled solve 512^2, trapped",
     "coupled solve 512^2 < 1 min, per trapped-fluid model", "s CPU", "coupled"),
    ("13 §4", "bench_bem", "hardness/elastic time at 512^2",
     "hardness-limited solve within 3x the elastic time at 512^2", "ratio of CPU times",
     "hardness"),
    ("13 §4", "bench_adhesion", "/ elastic CPU time at 512^2",
     "adhesive solve within 3x the elastic time at 512^2", "ratio of CPU times", "512"),
    ("15 §4", "bench_sequencing", "sequencing a 512^2 pair",
     "sequencing a pair of 512^2 acquisitions < 10 s", "s CPU", "512"),
    ("15 §4", "bench_bands", "band mechanics 256^2, all",
     "chromosome mechanics of a 256^2 measured surface < 2 min on 2 cores",
     "s wall (2 workers)", "256"),
    ("15 §4", "bench_bands", "band mechanics 256^2, the same in CPU",
     "the same, process CPU (bounds the 2-core wall time from above)", "s CPU", "256"),
    ("15 §4", "bench_surface_design", "surface design run 64^2",
     "a surface design run < 30 min (64^2 database, as the validation)",
     "s CPU", "design"),
    ("16 §1", "bench_bem", "4 loads at 2048^2, cold (",
     "4 loads at 2048^2 <= 500 convolution-equivalents", "convolution-equivalents", "2048"),
    ("16 §1", "bench_bem", "stretch goal", "the same <= 400 (beyond the goal)",
     "convolution-equivalents", "2048"),
    ("16 §1", "bench_bem", "iteration growth", "iterations <= 1.15x per doubling of n",
     "ratio per doubling", "growth"),
    ("16 §1", "bench_bem_growth", ", mean of ",
     "iterations <= 1.15x per doubling of n: new self-affine surfaces, mean of the seeds",
     "ratio per doubling", "growth"),
    ("16 §1", "bench_bem_growth", "refinement of the",
     "iterations <= 1.15x per doubling of n: one surface resolved by more points",
     "ratio per doubling", "growth"),
    ("16 §1", "bench_bem_choice", "automatic / faster CPU",
     "the automatic two-level choice within 1.1x of the faster of on / off (session 13)",
     "ratio of CPU times", "choice"),
    ("16 §1", "bench_bem", "|A* - A*_Tamaas|", "the same A* as Tamaas", "area fraction",
     "Tamaas"),
    ("16 §2", "bench_bem", "peak RSS 4096^2", "4096^2 in <= 1.2 GB", "MB", "4096^2"),
    ("16 §2", "bench_bem", "peak RSS 8192^2", "8192^2 in <= 4.5 GB", "MB", "8192^2"),
    ("16 §2", "bench_bem", "8192^2 solve", "8192^2 in <= 4 min", "s CPU", "8192^2"),
    ("16 §3", "bench_cli", "process start to solve, wall",
     "roughfe contact reaches the solve within 0.5 s of process start", "s wall", "start"),
    ("16 §3", "bench_cli", "process start to solve, CPU", "the same, process CPU", "s CPU",
     "start"),
    ("16 §3", "bench_cli", "figures of a 2048^2 result, wall",
     "figures of a 2048^2 result < 5 s", "s wall", "2048^2"),
    ("16 §3", "bench_cli", "figures of a 2048^2 result, CPU", "the same, process CPU",
     "s CPU", "2048^2"),
    ("16 §4", "bench_fem", "MUMPS VI step",
     "FEM time per VI step against dofs; the largest profile in < 30 s per step",
     "nodes", "fem"),
)
COLUMNS = ("issue", "target", "limit", "measured", "unit", "status", "date (UTC)", "load",
           "benchmark", "note")


def _module(path: Path, name: str):
    """The module of the file ``path`` (loaded under ``name``)."""
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


#: ``docs/generate.py``, whose reading of a report's target rows (``target_rows``: the
#: script's ``met`` as met / **NOT met** / not checked) and cell format this table shares
GEN = _module(HERE.parent / "docs" / "generate.py", "docs_generate")
#: every benchmark script, the stems of ``benchmarks/run_all.py``'s PLAN (one list of
#: names): a report file belongs to the one of its name or the longest one it extends
BENCHMARKS = tuple(s for s in _module(HERE / "run_all.py", "bench_run_all").PLAN
                   if s.startswith("bench_"))


def _cell(value) -> str:
    return "" if value is None else GEN._fmt(value)


def _load(path: Path):
    """(data, error): one benchmark JSON, or None and why it could not be read."""
    try:
        return json.loads(path.read_text()), None
    except (OSError, ValueError) as exc:
        return None, f"unreadable: {exc}"


def _run_facts(data: dict, path: Path) -> dict:
    """Date and load average of a report (older reports without a date: the file's time)."""
    date = data.get("date")
    if date is None:
        stamp = datetime.datetime.fromtimestamp(path.stat().st_mtime, datetime.timezone.utc)
        date = stamp.isoformat(timespec="seconds") + " (file time)"
    loads = [data.get(k) for k in ("load_average_start", "load_average")]
    loads = [v for v in loads if isinstance(v, (int, float))]
    load = "-".join(f"{v:.1f}" for v in loads) if loads else ""
    return {"date (UTC)": date.replace("T", " ").replace("+00:00", ""), "load": load}


def report_files(folder: Path, expected=EXPECTED) -> tuple:
    """(current, older): benchmark stem -> paths of its JSON files. A file belongs to the
    benchmark of its name, else to the longest benchmark name it extends
    (:data:`BENCHMARKS` and the expected ones: ``bench_bem_8192.json`` to ``bench_bem``,
    ``bench_bem_approach.json`` to ``bench_bem_approach`` itself). The folder is never cleaned: when ``run_all.json`` lists
    a run of a file's benchmark and no run wrote that file (its ``wrote`` lists), the file
    is an older run's report and goes to ``older``, never read as this run's."""
    runs = [r for r in _runs(folder) if isinstance(r.get("wrote"), list)]
    listed = {r.get("script") for r in runs}
    wrote = {name for r in runs for name in r["wrote"]}
    names = set(BENCHMARKS) | {e[1] for e in expected}
    current, older = {}, {}
    for path in sorted(Path(folder).glob("*.json")):
        if path.stem == "run_all":
            continue
        stem = owner_of(path.stem, names)
        stale = stem in listed and path.name not in wrote
        (older if stale else current).setdefault(stem, []).append(path)
    return current, older


def read_reports(folder: Path, expected=EXPECTED) -> dict:
    """benchmark stem -> list of (path, data or None, error) of its current JSON files
    (:func:`report_files`: an older run's report left in the folder is not among them)."""
    current, _ = report_files(Path(folder), expected)
    return {stem: [(path, *_load(path)) for path in paths] for stem, paths in current.items()}


def owner_of(file_stem: str, benchmarks) -> str:
    """The benchmark a report file belongs to: the one of its name, else the longest
    benchmark name it extends (``bench_bem_8192`` -> ``bench_bem``, ``bench_bem_growth``
    -> ``bench_bem_growth`` itself when that is a benchmark), else its own name."""
    if file_stem in benchmarks:
        return file_stem
    return next((b for b in sorted(benchmarks, key=len, reverse=True)
                 if file_stem.startswith(b + "_")), file_stem)


def _targets(data, reduced_note=True) -> list:
    """A report's target rows in the table's columns (``docs/generate.target_rows``); the
    rows of a reduced run (``--quick``) say so in their note (``reduced_note``: not those
    of ``run_all.json``, whose rows judge whether a report was written, not a size)."""
    reduced = reduced_note and isinstance(data, dict) and data.get("reduced") is True
    return [{"target": t["name"], "limit": t.get("target"), "measured": t.get("value"),
             "unit": t.get("unit"), "status": t["status"],
             "note": "; ".join(x for x in (REDUCED_NOTE if reduced else None, t.get("note"))
                               if x)}
            for t in (GEN.target_rows(data) if isinstance(data, dict) else [])]


#: the note of every row of a reduced run
REDUCED_NOTE = "reduced run (--quick): a smaller case than the target's"


def _run_all(folder: Path):
    """(path, data or None) of ``<folder>/run_all.json``."""
    path = Path(folder) / "run_all.json"
    data = _load(path)[0] if path.is_file() else None
    return path, data if isinstance(data, dict) else None


def _runs(folder: Path) -> list:
    """The per-script records of ``run_all.json`` (script, exit code, files written), or
    [] without it."""
    data = _run_all(folder)[1]
    cases = data.get("cases") if data else None
    return [c for c in cases if isinstance(c, dict)] if isinstance(cases, list) else []


def _older_note(paths) -> str:
    """"; older report(s) of DATE ignored" for the reports of an earlier run, or ""."""
    dates = [_run_facts(_load(p)[0] or {}, p)["date (UTC)"] for p in paths]
    return (f"; older report{'s' if len(dates) > 1 else ''} of {', '.join(dates)} ignored"
            if dates else "")


def summary_rows(folder, expected=EXPECTED) -> list:
    """The rows of the table (dicts keyed by :data:`COLUMNS`), expected targets first."""
    reports = read_reports(Path(folder), expected)
    older = report_files(Path(folder), expected)[1]
    runs = _runs(Path(folder))
    rows, claimed = [], set()
    for issue, stem, match, what, unit, skip_match in expected:
        files = reports.get(stem, [])
        base = {"issue": issue, "unit": unit, "benchmark": stem, "target": what}
        found = []
        for path, data, error in files:
            if data is None:
                continue
            for k, t in enumerate(_targets(data)):
                if match in str(t["target"]) and (path, k) not in claimed:
                    claimed.add((path, k))
                    found.append({**base, **_run_facts(data, path), **t,
                                  "unit": t.get("unit") or unit})
        if found:
            rows += found
            continue
        readable = [(p, d) for p, d, _ in files if d is not None]
        ran = [r for r in runs if r.get("script") == stem]
        stale = _older_note(older.get(stem, []))
        if not files and ran:        # it ran and wrote no report: it crashed
            codes = ", ".join(str(r.get("exit_code"))
                              for r in [r for r in ran if not r.get("wrote")] or ran)
            rows.append({**base, "status": "not measured",
                         "note": f"{stem} ran (exit code {codes}) and wrote no report: "
                                 f"see its output{stale}"})
        elif not files:
            rows.append({**base, "status": "not run",
                         "note": f"{stem}.json missing: run make bench"})
        elif not readable:
            rows.append({**base, "status": "not run",
                         "note": "; ".join(e for _, _, e in files)})
        else:
            reasons = [f"{s.get('name')}: {s.get('reason')}" for p, d in readable
                       for s in d.get("skipped") or []
                       if skip_match in str(s.get("name", ""))]
            path, data = readable[0]
            rows.append({**base, **_run_facts(data, path), "status": "not measured",
                         "note": ("; ".join(reasons) or "no such row in this run") + stale})
    for stem, files in sorted(reports.items()):
        for path, data, error in files:
            if data is None:
                if stem not in {e[1] for e in expected}:
                    rows.append({"issue": "-", "benchmark": stem, "target": path.name,
                                 "status": "not run", "note": error})
                continue
            for k, t in enumerate(_targets(data)):
                if (path, k) not in claimed:
                    rows.append({"issue": "-", "benchmark": path.stem, **_run_facts(data, path),
                                 **t})
    path, run = _run_all(Path(folder))
    if run:                          # its rows "<script> wrote its report": a crash is NOT met
        rows += [{"issue": "-", "benchmark": "run_all", **_run_facts(run, path), **t}
                 for t in _targets(run, reduced_note=False)]
    return rows


def _table(rows, columns) -> list:
    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    return lines + ["| " + " | ".join(_cell(r.get(c)) for c in columns) + " |" for r in rows]


def summary_markdown(folder, title="Benchmark summary", expected=EXPECTED) -> str:
    """The Markdown page: the target table, what was skipped, and the run's own figures."""
    folder = Path(folder)
    rows = summary_rows(folder, expected)
    counts = {s: sum(r["status"] == s for r in rows)
              for s in ("met", "**NOT met**", "not measured", "not run", "not checked")}
    lines = [f"# {title}", "",
             f"Every speed and memory target of issues 12-16 and every other target row of "
             f"the benchmarks, from the JSON in `{folder.name}/` (written by `make bench`, "
             "`benchmarks/run_all.py`; this table by `benchmarks/summary.py`). Values to 4 "
             "significant digits; *load* is the 1-minute load average at the start and end "
             "of the benchmark on the machine's cores: a time measured at a load above the "
             "number of cores is inflated (CPU times much less than wall times).", "",
             ", ".join(f"{n} {s.strip('*')}" for s, n in counts.items()) + ".", ""]
    n_reduced = sum(REDUCED_NOTE in (r.get("note") or "") for r in rows)
    if n_reduced:
        lines += [f"**{n_reduced} of these rows are of reduced runs (`--quick`, `make "
                  "bench-quick`)**: they judge smaller cases than the targets name, for "
                  "smoke use; the targets' verdicts are those of `make bench`.", ""]
    lines += _table(rows, COLUMNS) + [""]
    skipped = []
    for stem, files in sorted(read_reports(folder, expected).items()):
        for path, data, _ in files:
            skipped += [{"benchmark": path.stem, "skipped": s.get("name"),
                         "reason": s.get("reason")} for s in (data or {}).get("skipped") or []]
    run = _run_all(folder)[1]
    if run:
        skipped += [{"benchmark": s.get("name"), "skipped": "whole benchmark",
                     "reason": s.get("reason")} for s in run.get("skipped") or []]
    if skipped:
        lines += ["## Skipped, and why", ""] + _table(skipped, ("benchmark", "skipped",
                                                                "reason")) + [""]
    if run:
        started = str(run.get("started", "")).replace("T", " ").replace("+00:00", "")
        lines += [f"## The run ({run.get('mode')}, started {started} UTC)", "",
                  f"Total {_cell(run.get('total_wall_s'))} s wall, "
                  f"{_cell(run.get('total_cpu_s'))} s CPU on {run.get('cpus')} cores.", ""]
        lines += _table(run.get("cases") or [], ("script", "args", "exit_code", "wall_s",
                                                 "cpu_s", "peak_rss_mb", "load_average_start",
                                                 "load_average_end")) + [""]
    else:
        lines += ["No `run_all.json`: the benchmarks above were run one by one.", ""]
    return "\n".join(lines)


def write_summary(folder, out) -> Path:
    """Write :func:`summary_markdown` of ``folder`` to ``out`` (atomically)."""
    from roughfe.writers import write_text
    write_text(out, summary_markdown(folder))
    return Path(out)


if __name__ == "__main__":
    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else HERE / "output"
    out = Path(sys.argv[2]) if len(sys.argv) > 2 else folder / "SUMMARY.md"
    print(f"wrote {write_summary(folder, out)}")
