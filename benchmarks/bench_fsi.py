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
"""
import json
import os
import subprocess
import sys
import time
from pathlib import Path

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
    from roughfe.writers import write_json
    write_json(OUT / "bench_fsi.json", {"targets": targets, "coupled": rows})
    return 0


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--one":
        print(json.dumps(one(sys.argv[2])))
        sys.exit(0)
    sys.exit(main(sys.argv[1:] or ["volume", "pressure", "film"]))
