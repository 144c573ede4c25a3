"""Speed of 2D MWM genome sequencing (issue 15 §4: a pair of 512^2 acquisitions < 10 s).

A resolvable random surface genome (:func:`~roughfe.genomics.sequencing.surface_data.
resolvable_surface_genome`: M = 4 ridges, gamma = 1.6, H = 0.8, seed 3) is realised at two
nested windows L and L / 2.5 with n x n nodes each; :func:`~roughfe.genomics.sequencing.
sequence_surfaces` sequences the pair. Timed in process CPU seconds (``time.process_time``,
all threads: other users of the shared machine do not enter); the recovered genes are
checked against the truth (the §1 exactness targets) so that a fast wrong answer does not
pass. Writes ``benchmarks/output/bench_sequencing.json``.
Run: ``.venv/bin/python benchmarks/bench_sequencing.py [N ...]`` (default 128 256 512).
"""
import os
import sys
import time
from pathlib import Path

import numpy as np

from roughfe.genomics.sequencing import sequence_surfaces
from roughfe.genomics.sequencing.surface_data import resolvable_surface_genome
from roughfe.writers import write_json

OUT = Path(__file__).resolve().parent / "output" / "bench_sequencing.json"
TARGET_S = 10.0
#: CPU seconds of the same cases before the fast linear algebra (commit b1dc6b2, same machine)
BEFORE = {128: None, 256: None, 512: None}


def case(n, seed=3):
    g, acq, _ = resolvable_surface_genome(seed, length=1e-3, n_nodes=n, n_ridges=4, gamma=1.6)
    c0 = time.process_time()
    r = sequence_surfaces(acq)
    cpu = time.process_time() - c0
    s = r.genome
    ok = s is not None and s.M == g.M
    err = {"gamma": abs(s.gamma / g.gamma - 1), "A": abs(s.A / g.A - 1), "H": abs(s.H - g.H),
           "angles": float(np.abs(s.angles - g.angles).max()),
           "anisotropy": float(np.abs(s.anisotropy / g.anisotropy - 1).max())} if ok else {}
    return {"n": n, "cpu_s": cpu, "cpu_before_s": BEFORE.get(n), "success": bool(r.success),
            "M": None if s is None else s.M, "waves": int(r.amplitudes.size), "nit": r.nit,
            "max_gene_error": max(err.values()) if err else None,
            "max_rms_misfit": float(np.max(r.rms_errors))}


def main(sizes):
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    rows = []
    for n in sizes:
        r = case(n)
        rows.append(r)
        print(f"{n:>5}^2 pair: cpu {r['cpu_s']:7.2f} s  success {r['success']}  M {r['M']}  "
              f"waves {r['waves']}  nit {r['nit']}  gene error {r['max_gene_error']:.2g}  "
              f"misfit {r['max_rms_misfit']:.2g}", flush=True)
    targets = [{"name": f"sequencing a {r['n']}^2 pair (CPU s), genes to 1e-8",
                "value": r["cpu_s"], "target": f"< {TARGET_S:g}",
                "met": bool(r["cpu_s"] < TARGET_S and r["success"]
                            and (r["max_gene_error"] or 1.0) < 1e-8)}
               for r in rows if r["n"] == 512]
    write_json(OUT, {"benchmark": "bench_sequencing", "load_average": os.getloadavg()[0],
                     "targets": targets, "cases": rows,
                     "units": {"cpu_s": "s (process CPU time)"}})
    for t in targets:
        print(f"{t['name']}: {t['value']:.2f} ({'met' if t['met'] else 'NOT met'})")
    return 0


if __name__ == "__main__":
    sys.exit(main([int(a) for a in sys.argv[1:]] or [128, 256, 512]))
