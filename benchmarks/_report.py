"""The one way a benchmark script writes its report: ``benchmarks/output/<name>.json``
(the target rows with met / NOT met, the measured cases, their units, what was skipped and
why, and the process figures a timing depends on: the load average at the start and the
end, the process's CPU and wall time and its peak resident memory) and one printed line
per target.

``ROUGHFE_BENCH_OUTPUT`` (set by ``run_all.py --quick``) redirects every report to another
folder, so that a smoke run never overwrites the full run's JSON.
"""
import datetime
import os
import sys
import resource
import time
from pathlib import Path

import numpy as np

from roughfe.writers import write_json

#: 1-minute load average when this module was imported (the start of the benchmark)
LOAD_AT_START = os.getloadavg()[0]
_IMPORTED = time.perf_counter()



def script_args(doc: str, argv=None, *, flags=(), max_ints=None, words=None):
    """The positional arguments and flags of a benchmark script without argparse:
    ``(values, given)``, ``values`` the integers (or, with ``words``, the words of that
    set) in order, ``given`` the set of ``flags`` present. ``-h``/``--help`` prints
    ``doc`` (the script's docstring: its usage line is there) and exits 0; an unknown
    flag, a value that is not an integer (or not one of ``words``) or more than
    ``max_ints`` values exits 2 with a message naming it (was a ``ValueError`` traceback
    from ``int('--help')``)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    script = Path(sys.argv[0]).name
    if "-h" in argv or "--help" in argv:
        try:
            print(doc.strip(), flush=True)
        except BrokenPipeError:          # `--help | head`: quiet, as the roughfe CLI
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
            sys.exit(141)
        sys.exit(0)
    given = {a for a in argv if a in flags}
    values = []
    for a in argv:
        if a in flags:
            continue
        if words is not None:
            if a not in words:
                _usage_error(f"{script}: unknown argument {a!r}; allowed: "
                             f"{', '.join(words)} (--help: usage)")
            values.append(a)
            continue
        try:
            values.append(int(a))
        except ValueError:
            _usage_error(f"{script}: expected integer arguments"
                         f"{' or ' + ', '.join(flags) if flags else ''}, got {a!r} "
                         f"(--help: usage)")
    if max_ints is not None and len(values) > max_ints:
        _usage_error(f"{script}: at most {max_ints} integer arguments, got {len(values)}: "
                     f"{values} (--help: usage)")
    return values, given


def _usage_error(message: str):
    """``message`` on stderr, exit status 2 (a command-line error, as argparse's)."""
    print(message, file=sys.stderr)
    raise SystemExit(2)


def megabytes(ru_maxrss: float) -> float:
    """MB (1e6 bytes, the unit of the issue's GB limits) of a ``ru_maxrss`` (KiB on
    Linux). The benchmarks divided by 1024 (MiB) and called it MB until session 23."""
    return float(ru_maxrss) * 1024 / 1e6


def own_peak_rss_mb() -> float:
    """Peak RSS of this process so far (RUSAGE_SELF) in MB (:func:`megabytes`)."""
    return megabytes(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)


def median_seconds(fn, repeats: int, clock=time.process_time) -> float:
    """Median over ``repeats`` calls of ``fn()`` of the seconds ``clock`` counts (process
    CPU time by default; ``time.perf_counter`` for wall time)."""
    times = []
    for _ in range(repeats):
        t0 = clock()
        fn()
        times.append(clock() - t0)
    return float(np.median(times))

def output_path(path) -> Path:
    """``path`` itself, or its file name in ``$ROUGHFE_BENCH_OUTPUT`` when that is set."""
    folder = os.environ.get("ROUGHFE_BENCH_OUTPUT")
    return Path(folder) / Path(path).name if folder else Path(path)


def _wall_since_start() -> float:
    """Elapsed seconds since this process started (``/proc``: the start time in clock ticks
    after boot against the uptime), else since this module was imported."""
    try:
        with open("/proc/self/stat") as fh:
            start = int(fh.read().rsplit(")", 1)[1].split()[19])
        with open("/proc/uptime") as fh:
            uptime = float(fh.read().split()[0])
        return uptime - start / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, IndexError):  # pragma: no cover - not Linux
        return time.perf_counter() - _IMPORTED


def process_figures() -> dict:
    """CPU (user + system, this process and its waited-for children: the cases that run in
    a subprocess), wall time since the process started, peak RSS (the larger of this
    process and its largest child), load averages and the UTC date."""
    me, kids = (resource.getrusage(w) for w in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN))
    return {"date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
            "load_average_start": LOAD_AT_START, "load_average": os.getloadavg()[0],
            "cpus": os.cpu_count(),
            "cpu_s": me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime,
            "wall_s": _wall_since_start(),
            "peak_rss_mb": megabytes(max(me.ru_maxrss, kids.ru_maxrss))}


def write_report(path, name, targets, cases, units, extra=None, skipped=()):
    """Write the JSON report atomically and print each target's value and verdict.

    ``targets``: records ``name, value, target, met`` (and ``unit``, ``note``; ``met``
    None: a value reported without a verdict, "not checked" in the summary); ``cases``:
    the measured records; ``units``: field -> unit; ``extra`` (a dict) adds the benchmark's
    own keys (e.g. a fitted law, its settings); ``skipped``: records ``name, reason`` of
    the cases this run left out (shown in the summary table, never silently dropped).
    The report records the script's arguments and ``reduced`` (``--quick``, or a run of
    ``run_all.py --quick``): the summary marks the rows of a reduced run as such.
    Returns the path written.
    """
    path = output_path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    reduced = "--quick" in sys.argv[1:] or os.environ.get("ROUGHFE_BENCH_REDUCED") == "1"
    write_json(path, {"benchmark": name, **process_figures(), "argv": sys.argv[1:],
                      "reduced": reduced, "targets": targets,
                      "skipped": list(skipped), "cases": cases, "units": units,
                      **(extra or {})})
    for t in targets:
        value = t["value"]
        shown = f"{value:.4g}" if isinstance(value, (int, float)) else str(value)
        verdict = "not checked" if t["met"] is None else "met" if t["met"] else "NOT met"
        print(f"{verdict:>8s}  {t['name']}: {shown} "
              f"(target {t['target']})")
    for s in skipped:
        print(f" skipped  {s['name']}: {s['reason']}")
    print(f"wrote {path}")
    return path
