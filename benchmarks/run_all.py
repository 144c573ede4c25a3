"""Run every ``benchmarks/bench_*.py`` script in turn (``make bench``).

Benchmarks print timings and ratios; they are never part of the timed test suite.
"""
import runpy
import sys
from pathlib import Path

here = Path(__file__).resolve().parent
status = 0
for script in sorted(here.glob("bench_*.py")):
    print(f"== {script.name}", flush=True)
    try:
        runpy.run_path(str(script), run_name="__main__")
    except SystemExit as exc:
        status |= int(exc.code or 0)
sys.exit(status)
