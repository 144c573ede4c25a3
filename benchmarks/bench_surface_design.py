"""CPU time of a surface database and of surface design runs (issue 15 Sec. 3-4).

Target (issue 15): a surface design run < 30 min. A 2D genome database of ``2 K`` Sobol
genomes (K points x 2 phase matrices; N x N periodic, default 64, M = 3 ridges, H in
[0.1, 1.5], 10 approaches to 0.8 of full contact, E = 210 MPa) is built in this process
(CPU per genome recorded), with the period of the evenly mirrored x3p-2 window (259.7 um),
the configuration of ``roughfe validate surface-genomics``. Then M-CCO + the search at the
target pressures (phases and chromosome amplitudes, 100 sweeps per candidate) and the
global stage (IPOP-CMA-ES, 2000 batched strict evaluations, phases and part weights
+-30 %) on (a) K(p), A(p) of y_t1 (a surface genome outside the database) and (b)
K(p), A(p) of the measured x3p-2 (mirrored, periodic BEM, on the database spacing;
`surface_targets`), after `match_spectrum` per wave (its spectrum, 3 matched database
starts): the validation's configuration of both runs. Process CPU times (the machine may be
shared; wall times are inflated by load) go to ``benchmarks/output/
bench_surface_design.json`` with the scores (the scores are the validation's business:
here they only show the run did its work).
Run: .venv/bin/python benchmarks/bench_surface_design.py [K [N]]. Exit status 0 when the
report is written, a missed target included (its row says NOT met), as for every
benchmark (``benchmarks/run_all.py``); a crash exits non-zero.
"""
import resource
import sys
import tempfile
from pathlib import Path

import numpy as np

from roughfe.genomics import database as gdb
from roughfe.genomics.design import (GcmmaOptions, combined_score, match_spectrum,
                                     run_design, search_at_target_pressures, search_global,
                                     surface_targets, target_surface, thesis_targets)
from roughfe.model import DEFAULT_E
from roughfe.surfaces import Surface
from roughfe.surfaces.io import load_surface

from _report import write_report  # benchmarks/_report.py

OUT = Path(__file__).resolve().parent / "output" / "bench_surface_design.json"
X3P = Path(__file__).resolve().parents[2] / "shared" / "data" / "topographies" / "x3p-2.x3p"
TARGET_S = 1800.0
#: the global stage of validation/surface_genomics.py (GLOBAL_EVAL)
GLOBAL_EVAL = 2000


def _cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def main(n_points=24, n_nodes=64):
    x3p = load_surface(X3P)
    thin = x3p.heights[::4, ::4]            # 163 x 163 over the window, as the validation
    window = Surface(thin, tuple(n * d * 4 for n, d in zip(thin.shape, x3p.spacing)))
    length = float(np.sqrt(np.prod(window.detrended("plane").mirrored().size)))
    settings = gdb.DatabaseSettings(length=length, n_nodes=n_nodes, youngs_modulus=DEFAULT_E,
                                    n_steps=10, dim=2, top_fraction=0.8)
    design = gdb.SobolDesign(dim=2, n_pairs=n_points, n_vectors=2, n_ridges=3,
                             hurst_range=(0.1, 1.5))
    c0 = _cpu()
    records = [gdb.genome_entry_task(**t, **settings.to_dict()) for t in gdb.sobol_tasks(design)]
    c_db = _cpu() - c0
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "db.sqlite"
        con = gdb.connect(path, create=True)
        gdb.write_settings(con, settings)
        gdb.insert_records(con, records)
        con.close()
        entries = gdb.load_entries(path)
    cases = [{"case": "database", "n_nodes": n_nodes, "genomes": len(records), "cpu_s": c_db,
              "cpu_per_genome_s": c_db / len(records)}]
    t1, _, t3, curve = thesis_targets(settings)
    tk, ta, mcurve = surface_targets(window, settings, name="x3p-2")
    targets = []
    runs = {"y_t1": (t1, t3, curve, None),
            "x3p-2": (tk, ta, mcurve, target_surface(window, settings))}
    for name, (k, a, c, surface) in runs.items():
        c0 = _cpu()
        res = run_design("mcco", entries, [k, a], settings, pbar=0.4 * c.p_max,
                         options=GcmmaOptions(bound="period"))
        if surface is not None:             # a measured target: its spectrum, 3 more starts
            res = match_spectrum(res, surface, settings, entries=entries, n_entries=3,
                                 directional=True)
        res = search_at_target_pressures(res, settings, n_eval=100, amplitudes=True)
        res = search_global(res, settings, n_eval=GLOBAL_EVAL)
        cpu = _cpu() - c0
        cases.append({"case": f"M-CCO + search + global, {name}", "n_nodes": n_nodes, "cpu_s": cpu,
                      "bem_sweeps": int(res.nit), "f": combined_score(res.best.at_targets)})
        targets.append({"name": f"surface design run {n_nodes}^2, M-CCO {name} (CPU s)",
                        "value": cpu, "target": f"< {TARGET_S:g}", "met": bool(cpu < TARGET_S)})
    print(f"database: {len(records)} genomes at {n_nodes}^2 in {c_db:.1f} s CPU "
          f"({c_db / len(records):.2f} s per genome)")
    for c in cases[1:]:
        print(f"{c['case']}: f = {c['f']:.4f}, {c['bem_sweeps']} sweeps, {c['cpu_s']:.1f} s CPU")
    write_report(OUT, "bench_surface_design", targets, cases,
                 {"cpu_s": "s (process CPU time)", "f": "- (strict, at the target pressures)"})
    return 0


if __name__ == "__main__":
    sys.exit(main(*(int(a) for a in sys.argv[1:3])))
