"""CPU time of the two-way coupled solve at 512^2 per trapped-fluid model (issue 12 §6:
coupled solve at 512^2 < 1 min).

Surface: periodic self-affine (H = 0.8, rms height 1 um, L = 0.1 mm, seed 1), E = 1 GPa,
nu = 0.3, p_ext = 30 MPa, p_in = 20 MPa, p_out = 0 (the case of
``benchmarks/bench_reynolds.py``), one step from first contact. Per model: process CPU
time, Anderson iterations, pocket passes, pockets, whether they settled, fluid and
trapped load fractions. Each model runs in a fresh process. The machine is shared: the
CPU time is the measure (wall printed beside it).
Writes ``benchmarks/output/bench_fsi.json``.

Run: ``python benchmarks/bench_fsi.py [MODEL ...]`` (default: volume pressure film).

``python benchmarks/bench_fsi.py --steps`` measures instead what placing the closure of a
pocket at the end of its load step costs (``roughfe.leakage.pockets``): the 64^2 sweep
(seed 4, ``p_in`` = 5 MPa, ``volume``) from 10 to 60 MPa in steps of 10, 5, 2.5, 1.25 and
0.625 MPa; trapped volume, load shares, A* and leak rate at 20, 40, 60 MPa per step size.
Writes ``benchmarks/output/bench_fsi_steps.json`` (about 80 s CPU).
"""
import json
import os
import subprocess
import sys
import time
from pathlib import Path

from _report import script_args, write_report  # benchmarks/_report.py

N, TARGET_S = 512, 60.0
OUT = Path(__file__).resolve().parent / "output"


def one(model):
    from roughfe.leakage.fsi import coupled_leakage
    from roughfe.model import Material
    from roughfe.surfaces.spectral import spectral_surface
    s = spectral_surface(N, 1e-4, 0.8, rms_height=1e-6, rng=1)
    t0, c0 = time.perf_counter(), time.process_time()
    r = coupled_leakage(s, Material(1e9, 0.3), 3e7, p_in=2e7, p_out=0.0, trapped=model)
    return {"model": model, "wall_s": time.perf_counter() - t0,
            "cpu_s": time.process_time() - c0, "coupled_iterations": r.coupled_iterations,
            "pocket_passes": r.pocket_passes, "pockets": len(r.pocket_pressures),
            "pockets_settled": r.pockets_settled, "residual": r.residual,
            "fluid_load_fraction": r.fluid_load_fraction,
            "trapped_load_fraction": r.trapped_load_fraction, "leak_rate": r.leak_rate,
            "one_way_leak_rate": r.one_way_leak_rate,
            "area_fraction": r.contact.area_fraction}


def closure_steps(steps=(10e6, 5e6, 2.5e6, 1.25e6, 0.625e6)):
    import numpy as np
    from roughfe.leakage.fsi_sweep import coupled_sweep
    from roughfe.model import Material
    from roughfe.surfaces.spectral import spectral_surface
    s = spectral_surface(64, 1e-4, 0.8, rms_height=1e-6, rng=4)
    cases = []
    for dp in steps:
        loads = np.arange(10e6, 60e6 + 1, dp)
        c0 = time.process_time()
        rs = coupled_sweep(s, Material(1e9, 0.3), loads, p_in=5e6, p_out=0.0)
        cpu = time.process_time() - c0
        for r in rs:
            p = round(r.external_pressure / 1e6, 6)
            if p in (20, 40, 60):
                cases.append({"step_mpa": dp / 1e6, "load_mpa": p, "cpu_s": cpu,
                              "settled": all(x.pockets_settled for x in rs),
                              "pocket_volume": r.pocket_volume,
                              "trapped_load_fraction": r.trapped_load_fraction,
                              "contact_load_fraction": r.contact_load_fraction,
                              "area_fraction": r.contact.area_fraction,
                              "pockets": len(r.pocket_pressures), "leak_rate": r.leak_rate})
                c = cases[-1]
                print(f"step {dp / 1e6:6.3f} MPa, {p:4.0f} MPa: trapped volume "
                      f"{c['pocket_volume']:.4e} m^3, trapped {c['trapped_load_fraction']:.4f}, "
                      f"contact {c['contact_load_fraction']:.4f}, A* {c['area_fraction']:.4f}, "
                      f"{c['pockets']} pockets, Q {c['leak_rate']:.4e} (sweep cpu {cpu:.1f} s)",
                      flush=True)
    write_report(OUT / "bench_fsi_steps.json", "bench_fsi --steps", [], cases,
                 {"pocket_volume": "m^3", "leak_rate": "m^3/s", "cpu_s": "s"})
    return 0


def main(models):
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    rows, targets = [], []
    for m in models:
        out = subprocess.run([sys.executable, __file__, "--one", m], capture_output=True,
                             text=True, check=True)
        r = json.loads(out.stdout.strip().splitlines()[-1])
        rows.append(r)
        print(f"{m:>8}: cpu {r['cpu_s']:.1f} s (wall {r['wall_s']:.1f}), "
              f"{r['coupled_iterations']} iterations, {r['pocket_passes']} passes, "
              f"{r['pockets']} pockets (settled {r['pockets_settled']}), fluid load "
              f"{r['fluid_load_fraction']:.3f}, trapped {r['trapped_load_fraction']:.4f}",
              flush=True)
        targets.append({"name": f"coupled solve {N}^2, trapped {m}, CPU time (s)",
                        "value": r["cpu_s"], "target": f"< {TARGET_S}",
                        "met": r["cpu_s"] < TARGET_S, "note": f"wall {r['wall_s']:.1f} s"})
    OUT.mkdir(exist_ok=True)
    write_report(OUT / "bench_fsi.json", "bench_fsi", targets, rows,
                 {"cpu_s": "s", "wall_s": "s", "leak_rate": "m^3/s"})
    return 0


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--one":
        print(json.dumps(one(sys.argv[2])))
        sys.exit(0)
    if sys.argv[1:] == ["--steps"]:
        OUT.mkdir(exist_ok=True)
        sys.exit(closure_steps())
    models = ("volume", "pressure", "film")
    sys.exit(main(script_args(__doc__, words=models)[0] or list(models)))
