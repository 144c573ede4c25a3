"""Run every benchmark (``make bench``) or a smoke subset (``make bench-quick``), then write
the one summary table of every speed and memory target (``benchmarks/summary.py``).

Each run of :data:`PLAN` is a fresh interpreter (``bench_<name>.py ARGS``): a crash or a
missed target of one does not stop the others, and its wall time, CPU time (user + system,
its own subprocesses included) and peak resident memory come from ``os.wait4``, with the
load average before and after. They go to ``<output>/run_all.json``; the summary table
(``<output>/SUMMARY.md``) is written last from the JSON of the benchmarks. Every script
found as ``bench_*.py`` must have a plan (a new benchmark cannot be left out silently).
The exit status is 1 when a benchmark did not write its report (it crashed); a missed
target is a NOT met row in the table, not a failure of the run.

Full run: ``benchmarks/output``; ``--quick`` (4-5 min on 2 quiet cores: 268 s in session 42; reduced sizes,
so most targets read "not measured"): ``benchmarks/output-quick``
(``ROUGHFE_BENCH_OUTPUT``), never overwriting the full run's JSON.
Benchmarks print timings and ratios; they are never part of the timed test suite.
"""
from __future__ import annotations

import argparse
import datetime
import os
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

#: script stem -> (full runs, quick runs); each run is an argument list, ``None`` = not run
#: in that mode, with the reason in :data:`NOT_IN_QUICK`. Run in this order: the short ones
#: first, the 8192^2 BEM last, so that a run cut short still has most rows.
PLAN = {
    "bench_cli": ([[]], [["--quick"]]),
    "bench_sequencing": ([[]], [["128"]]),
    "bench_adhesion": ([[]], [["256"]]),
    "bench_fem": ([["8", "9", "10", "11", "12", "13", "14"]], [["6", "7", "8"]]),
    "bench_reynolds": ([[]], [["256", "512", "--no-coupled"]]),
    "bench_fsi": ([[], ["--steps"]], None),
    "bench_bands": ([[]], [["64"]]),
    "bench_surface_design": ([[]], [["4", "32", "--quick"]]),
    "bench_design_global": ([["20000"]], None),
    "bench_bem_choice": ([[]], [["--quick"]]),
    "bench_bem_padding": ([[]], [["--quick"]]),
    "bench_bem_nonperiodic": ([[]], [["--quick"]]),
    "bench_bem_approach": ([[]], [["--quick"]]),
    "bench_bem_growth": ([[]], [["--quick"]]),
    "bench_bem_mpi": ([["1024", "2048"]], [["--quick"]]),
    "bench_bem": ([["--sizes", "512", "1024", "2048", "--large", "4096", "8192"]],
                  [["--quick", "--tamaas-max", "0"]]),
}
NOT_IN_QUICK = {"bench_fsi": "the coupled 512^2 solve takes 15-35 s CPU per trapped-fluid "
                             "model: make bench only",
                "bench_design_global": "the profile database (N = 512) and a 20000-evaluation "
                                       "global search take ~4-5 min CPU: make bench only"}


def _stamps(folder: Path) -> dict:
    """file name -> (inode, mtime in ns, size) of every report in ``folder``."""
    stamps = {}
    for path in folder.glob("*.json"):
        try:
            st = path.stat()
        except OSError:                  # removed meanwhile
            continue
        stamps[path.name] = (st.st_ino, st.st_mtime_ns, st.st_size)
    return stamps


def run_one(script: Path, args, env) -> dict:
    """Run one benchmark in a fresh interpreter; its figures from ``os.wait4``. ``wrote``:
    its own reports (``summary.owner_of``) that are new or changed (inode, mtime in ns or
    size) against a listing taken before the start: a file written by an earlier run, even
    a second before (bench_fsi then bench_fsi --steps), is not credited to this one."""
    from summary import owner_of  # benchmarks/summary.py
    folder = Path(env["ROUGHFE_BENCH_OUTPUT"])
    before = _stamps(folder)
    load0, t0 = os.getloadavg()[0], time.perf_counter()
    print(f"== {script.name} {' '.join(args)}", flush=True)
    proc = subprocess.Popen([sys.executable, str(script), *args], cwd=HERE, env=env)
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    from _report import megabytes  # benchmarks/_report.py
    wrote = sorted(name for name, stamp in _stamps(folder).items()
                   if stamp != before.get(name)
                   and owner_of(Path(name).stem, PLAN) == script.stem)
    return {"script": script.stem, "args": " ".join(args), "exit_code": proc.returncode,
            "wrote": wrote,
            "wall_s": time.perf_counter() - t0, "cpu_s": usage.ru_utime + usage.ru_stime,
            "user_s": usage.ru_utime, "system_s": usage.ru_stime,
            "peak_rss_mb": megabytes(usage.ru_maxrss), "load_average_start": load0,
            "load_average_end": os.getloadavg()[0]}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the smoke subset (4-5 min)")
    ap.add_argument("--only", nargs="+", metavar="NAME",
                    help="run only these benchmarks (e.g. bench_cli); the summary still "
                         "covers every JSON in the output folder")
    args = ap.parse_args(argv)
    from _report import write_report  # benchmarks/_report.py
    from summary import write_summary  # benchmarks/summary.py

    output = HERE / ("output-quick" if args.quick else "output")
    env = dict(os.environ, ROUGHFE_BENCH_OUTPUT=str(output),
               ROUGHFE_BENCH_REDUCED="1" if args.quick else "0")
    found = {s.stem for s in HERE.glob("bench_*.py")}
    unplanned = sorted(found - set(PLAN))
    if unplanned:
        print(f"run_all.py: no PLAN entry for {', '.join(unplanned)}: add one", file=sys.stderr)
        return 2
    started = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")
    runs, skipped = [], []
    for stem, plans in PLAN.items():
        if stem not in found or (args.only and stem not in args.only):
            continue
        plan = plans[1 if args.quick else 0]
        if plan is None:
            skipped.append({"name": stem, "reason": NOT_IN_QUICK[stem]})
            continue
        runs += [run_one(HERE / f"{stem}.py", a, env) for a in plan]
    # a run that wrote its report ran to the end (every benchmark exits 0 then, a missed
    # target is a NOT met row of its report: tests/test_bench_summary.py)
    status = int(any(not r["wrote"] for r in runs))
    targets = [{"name": f"{r['script']} {r['args']}".strip() + " wrote its report",
                "value": r["exit_code"], "target": "a JSON written", "met": bool(r["wrote"]),
                "note": "exit code in the value"} for r in runs]
    write_report(output / "run_all.json", "run_all", targets, runs,
                 {"wall_s": "s (elapsed)", "cpu_s": "s (user + system, children included)",
                  "peak_rss_mb": "MB"},
                 extra={"mode": "quick" if args.quick else "full", "started": started,
                        "total_wall_s": sum(r["wall_s"] for r in runs),
                        "total_cpu_s": sum(r["cpu_s"] for r in runs)},
                 skipped=skipped)
    path = write_summary(output, output / "SUMMARY.md")
    print(f"wrote {path}")
    return status


if __name__ == "__main__":
    sys.exit(main())
