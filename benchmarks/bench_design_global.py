"""Cost of one strict design evaluation, single against batched, and the curve of the
global search (issue 14 Sec. 2).

1. One strict evaluation = a profile solved at the target's own pressures (N = 512,
   y_t1/y_t3: one displacement solve for p_max, Eq. 4.2, then 20 load-controlled steps):
   ``design.rescore_at_target_pressures`` one design at a time against
   ``design.score_batch_at_target_pressures`` on B designs at once (B = 16, 64, 256;
   process CPU per design, back to back, and the largest score difference).
2. ``design.search_global`` (IPOP-CMA-ES) from the thesis-stage M-CCO result on the
   60-genome database of ``roughfe validate design`` (built here if not given), with a
   budget of ``N_EVAL`` strict evaluations: the best f at p_t against the evaluations
   spent, CPU. Writes ``benchmarks/output/bench_design_global.json``.
Run: .venv/bin/python benchmarks/bench_design_global.py [N_EVAL [DB]]
"""
import resource
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from roughfe.genomics import database as gdb
from roughfe.genomics import design as de
from roughfe.study import build_genome_db

from _report import script_args, write_report  # benchmarks/_report.py

OUT = Path(__file__).resolve().parent / "output" / "bench_design_global.json"
GOAL = 0.9


def _cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def main(n_eval=100000, db_path=None):
    settings = gdb.DatabaseSettings()
    if db_path is None:
        db_path = Path(tempfile.mkdtemp()) / "genomes.sqlite"
        build_genome_db(db_path, settings, workers=1, progress=False)
    entries = gdb.load_entries(db_path)
    t1, _, t3, _ = de.thesis_targets(settings)
    rm = de.run_design("mcco", entries, [t1, t3], settings, options=de.GcmmaOptions())
    d0 = rm.best.design
    keys = d0.keys("all")
    rng = np.random.default_rng(0)
    cost = []
    for B in (16, 64, 256):
        designs = [d0.with_phases(keys, d0.phase_values(keys) + 0.3 * rng.standard_normal(len(keys)))
                   for _ in range(B)]
        c0 = _cpu()
        batch = de.score_batch_at_target_pressures(designs, [t1, t3], settings)
        c1 = _cpu()
        single = np.array([de.rescore_at_target_pressures(d, [t1, t3], settings)
                           for d in designs[:16]])
        c2 = _cpu()
        cost.append({"B": B, "batch_ms": 1e3 * (c1 - c0) / B, "single_ms": 1e3 * (c2 - c1) / 16,
                     "max_diff": float(np.abs(batch[:16] - single).max())})
        print(f"B = {B}: batched {cost[-1]['batch_ms']:.2f} ms, single "
              f"{cost[-1]['single_ms']:.2f} ms per design (CPU), largest difference "
              f"{cost[-1]['max_diff']:.1e}", flush=True)
    c0, w0 = _cpu(), time.perf_counter()
    rg = de.search_global(rm, settings, n_eval=int(n_eval), seed=0)
    cpu = _cpu() - c0
    h = np.asarray(rg.search_history[0])
    f = de.combined_score(rg.best.at_targets)
    print(rg.message, f"[{cpu:.0f} s CPU, {time.perf_counter() - w0:.0f} s wall]")
    ratio = cost[-1]["single_ms"] / cost[-1]["batch_ms"]
    targets = [{"name": "single / batched CPU per strict evaluation (B = 256)", "value": ratio,
                "target": ">= 3", "met": bool(ratio >= 3)},
               {"name": f"M-CCO f at p_t after {int(h[-1, 0])} evaluations", "value": f,
                "target": f">= {GOAL}", "met": bool(f >= GOAL)}]
    write_report(OUT, "bench_design_global", targets, cost, {"batch_ms": "ms CPU per design"},
                 extra={"history": h.tolist(), "cpu_s": cpu, "message": rg.message,
                        "strict_scores": list(rg.best.at_targets)})


if __name__ == "__main__":
    args = sys.argv[1:]
    n_eval = script_args(__doc__, args[:1], max_ints=1)[0]    # [N_EVAL [DB]]: DB is a path
    main(*n_eval, **({"db_path": Path(args[1])} if len(args) > 1 else {}))
