"""CPU time of a surface database and of surface design runs (issue 15 Sec. 3-4).

Target (issue 15): a surface design run < 30 min. A 2D genome database of ``2 K`` Sobol
genomes (K points x 2 phase matrices; N x N periodic, default 64) is built in this process
with ``surface_database`` of ``validation/surface_genomics.py`` (CPU per genome recorded),
on the period of the evenly mirrored x3p-2 window. Then M-CCO on (a) K(p), A(p) of y_t1 (a
surface genome outside the database) and (b) K(p), A(p) of the measured x3p-2 (mirrored,
periodic BEM, on the database spacing), each run by the study's own ``design_chain``
(GCMMA stages, spectrum matching for the measured target, the search at the target
pressures and the global stage, with the study's constants SEARCH_LONG, GLOBAL,
GLOBAL_SIGMA, GLOBAL_AMPLITUDES, GLOBAL_POPSIZE, GLOBAL_MODULATION): the benchmark times
the configuration the validation runs, not a copy of it. Process CPU times (the machine
may be shared; wall times are inflated by load) go to
``benchmarks/output/bench_surface_design.json`` with the scores (the scores are the
validation's business: here they only show the run did its work; with the full database
they equal the validation's, the runs being deterministic).
Run: .venv/bin/python benchmarks/bench_surface_design.py [K [N]] [--quick] (--quick: the
study's reduced global stage of 12 evaluations and the y_t1 design only, for smoke use). Exit status 0 when the
report is written, a missed target included (its row says NOT met), as for every
benchmark (``benchmarks/run_all.py``); a crash exits non-zero.
"""
import importlib.util
import resource
import sys
import tempfile
from pathlib import Path

import numpy as np

from roughfe.genomics import database as gdb
from roughfe.genomics.design import combined_score, target_surface, thesis_targets
from roughfe.surfaces.io import load_surface

from _report import script_args, write_report  # benchmarks/_report.py

OUT = Path(__file__).resolve().parent / "output" / "bench_surface_design.json"
STUDY = Path(__file__).resolve().parents[1] / "validation" / "surface_genomics.py"
TARGET_S = 1800.0


def _study():
    """``validation/surface_genomics.py`` (a script of the checkout, not an installed module)."""
    spec = importlib.util.spec_from_file_location("roughfe_validation_surface_genomics", STUDY)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def main(n_points=24, n_nodes=64, quick=False):
    sg = _study()
    x3p = sg.TOPOGRAPHIES / "x3p-2.x3p"
    if not x3p.is_file():           # the database's length is the measured window's
        reason = (f"measured file not found: {x3p} (the topographies folder, "
                  f"$ROUGHFE_TOPOGRAPHIES or ../shared/data/topographies)")
        print(f"{reason}; skipped")
        write_report(OUT, "bench_surface_design", [], [], {},
                     skipped=[{"name": f"surface design {n_nodes}^2 (database, y_t1, x3p-2)",
                               "reason": reason}])
        return 0
    measured = sg._thinned(load_surface(x3p), sg.X3P_POINTS)
    length = float(np.sqrt(np.prod(measured.mirrored().size)))
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "db.sqlite"
        c0 = _cpu()
        settings, _ = sg.surface_database(path, length, n_points, 2, n_nodes, 10, sg.DB_HURST)
        c_db = _cpu() - c0
        entries = gdb.load_entries(path)
    cases = [{"case": "database", "n_nodes": n_nodes, "genomes": len(entries), "cpu_s": c_db,
              "cpu_per_genome_s": c_db / len(entries)}]
    t1, _, t3, curve = thesis_targets(settings)
    tk, ta, _ = sg.measured_targets(measured, settings)
    targets = []
    runs = {"y_t1": ([t1, t3], 0.4 * curve.p_max, None),
            "x3p-2": ([tk, ta], 0.4 * tk.p_max, target_surface(measured, settings))}
    skipped = []
    if quick:       # the measured target's chain: 585 s CPU and 1922 sweeps at 32^2 (s41)
        del runs["x3p-2"]
        skipped.append({"name": f"surface design run {n_nodes}^2, M-CCO x3p-2 (CPU s)",
                        "reason": "--quick runs the y_t1 design only: the measured target's "
                                  "chain took 585 s CPU at 32^2 (1922 BEM sweeps), 3/4 of "
                                  "make bench-quick; run without --quick"})
    for name, (pair, pbar, surface) in runs.items():
        c0 = _cpu()
        res, stage = sg.design_chain(entries, settings, pair, pbar, name, "mcco", surface,
                                     sg.SEARCH_LONG.get((name, "mcco"), sg.SEARCH), quick)
        cpu = _cpu() - c0
        cases.append({"case": f"M-CCO, {name} (the study's chain)", "n_nodes": n_nodes,
                      "cpu_s": cpu, "bem_sweeps": int(res.nit),
                      "f": combined_score(res.best.at_targets), **stage})
        targets.append({"name": f"surface design run {n_nodes}^2, M-CCO {name} (CPU s)",
                        "value": cpu, "target": f"< {TARGET_S:g}", "met": bool(cpu < TARGET_S)})
    print(f"database: {len(entries)} genomes at {n_nodes}^2 in {c_db:.1f} s CPU "
          f"({c_db / len(entries):.2f} s per genome)")
    for c in cases[1:]:
        print(f"{c['case']}: f = {c['f']:.4f}, {c['bem_sweeps']} sweeps, {c['cpu_s']:.1f} s CPU")
    write_report(OUT, "bench_surface_design", targets, cases,
                 {"cpu_s": "s (process CPU time)", "f": "- (strict, at the target pressures)"},
                 skipped=skipped)
    return 0


if __name__ == "__main__":
    sizes, given = script_args(__doc__, flags=("--quick",), max_ints=2)
    sys.exit(main(*sizes, quick="--quick" in given))
