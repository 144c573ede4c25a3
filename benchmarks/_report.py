"""The one way a benchmark script writes its report: ``benchmarks/output/<name>.json``
(the target rows with met / NOT met, the measured cases, their units and the load average
at the end of the run, since timings depend on it) and one printed line per target."""
import os

from roughfe.writers import write_json


def write_report(path, name, targets, cases, units, extra=None):
    """Write the JSON report atomically and print each target's value and verdict;
    ``extra`` (a dict) adds the benchmark's own keys (e.g. a fitted law, its settings)."""
    write_json(path, {"benchmark": name, "load_average": os.getloadavg()[0],
                      "targets": targets, "cases": cases, "units": units, **(extra or {})})
    for t in targets:
        print(f"{t['name']}: {t['value']:.2f} ({'met' if t['met'] else 'NOT met'})")
