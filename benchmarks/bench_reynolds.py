"""Speed and memory of the Reynolds leak-rate solve (cell-centred FV, CG + BoomerAMG), the
critical constriction, and the two-way coupled solve (issue 12 §6, issue 16 §4).

Gap fields: periodic self-affine surfaces (H = 0.8, rms height 1 um, L = 0.1 mm) cut by a
rigid plane at the 85 % height quantile (A* = 0.15, percolating; the timed case) and, for
the leak-rate/iteration table, at the 70 % and 60 % quantiles (A* = 0.30, 0.40). The gap
source does not change the linear solve; a BEM contact at 4096^2 would dominate the run,
so the coupled benchmark (which needs it) runs at 512^2 only. Each size runs in a fresh
process so the peak resident memory (ru_maxrss) is that size's alone (the A* = 0.15 solve
runs first).

Per size and A*: process-CPU time (user + system; the system part printed) of
``solve_reynolds_fv`` (component labelling, assembly on the live cells, AMG set-up and CG
solve, fluxes), the AMG set-up / CG solve
split (from the solver report), CG iterations, the live fraction (unknowns / cells), the
leak rate and the relative inlet/outlet imbalance (about twice the leak-rate error from the
solver tolerance), peak memory; at A* = 0.15 the critical constriction's time. Targets:
Reynolds 2048^2 < 10 s, 4096^2 < 60 s and < 8 GB (A* = 0.15); coupled (two-way) solve at
512^2 < 60 s. The machine is shared: wall times are inflated by the load (printed), the
CPU time is the better measure.
Writes ``benchmarks/output/bench_reynolds.json`` through ``benchmarks/_report.write_report``
(the Reynolds rows as ``cases``, the coupled case as ``coupled``, load, CPU, wall and peak RSS).

Run: ``python benchmarks/bench_reynolds.py [N ...] [--no-coupled]`` (default 512 1024 2048
4096, with the coupled case).
"""
import json
import os
import re
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from _report import own_peak_rss_mb, script_args, write_report  # benchmarks/_report.py

OUT = Path(__file__).resolve().parent / "output"
TARGETS = {2048: 10.0, 4096: 60.0}
MEMORY_TARGET_GB = 8.0
COUPLED_N, COUPLED_TARGET_S = 512, 60.0


QUANTILES = (0.85, 0.70, 0.60)       # rigid-plane heights: A* = 0.15, 0.30, 0.40


def _split(message):
    """AMG set-up and CG solve CPU seconds from the KSP report."""
    m = re.search(r"set-up ([0-9.e+-]+) s \+ solve ([0-9.e+-]+) s", message)
    return (float(m.group(1)), float(m.group(2))) if m else (None, None)


def _seconds(value) -> str:
    """A 6-wide column of CPU seconds; "-" where the solver made no linear solve (a gap
    whose open components do not reach both inlet and outlet: Q = 0 without a KSP, so its
    report has no set-up/solve split)."""
    return f"{'-':>6}" if value is None else f"{value:>6.2f}"


def row_line(r) -> str:
    """One printed table row of a case of :func:`one_size`."""
    return (f"{r['n']:>5} {r['area_fraction']:>5.2f} {r['live_fraction']:>5.2f} "
            f"{r['wall_s']:>7.1f} {r['cpu_s']:>6.2f} {r['system_cpu_s']:>5.2f} "
            f"{_seconds(r['amg_setup_cpu_s'])} "
            f"{_seconds(r['cg_solve_cpu_s'])} {r['nit']:>4} {r['leak_rate']:>10.4e} "
            f"{r['balance']:>8.1e} {r['peak_memory_gb']:>5.2f} "
            f"{r.get('junction_cpu_s', float('nan')):>8.2f}")


def _cpu():
    """User and system CPU seconds of this process (the system part is mostly the kernel
    zeroing freshly touched pages: large first allocations)."""
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime, r.ru_stime


def one_size(n):
    from roughfe.leakage.finite_volume import solve_reynolds_fv
    from roughfe.leakage.junction import critical_constriction
    from roughfe.surfaces.spectral import spectral_surface
    s = spectral_surface(n, 1e-4, 0.8, rms_height=1e-6, rng=1)
    rows, con = [], None
    for q in QUANTILES:
        g = np.maximum(np.quantile(s.heights, q) - s.heights, 0.0)
        t0, (u0, s0) = time.perf_counter(), _cpu()
        r = solve_reynolds_fv(g, s.spacing, p_in=1e5, p_out=0.0, periodic=True)
        (u1, s1), wall = _cpu(), time.perf_counter() - t0
        cpu = (u1 - u0) + (s1 - s0)
        setup, solve = _split(r.message)
        row = {"n": n, "quantile": q, "area_fraction": float((g == 0).mean()),
               "live_fraction": float(r.connected.mean()), "wall_s": wall, "cpu_s": cpu,
               "system_cpu_s": s1 - s0,
               "amg_setup_cpu_s": setup, "cg_solve_cpu_s": solve, "nit": r.nit,
               "leak_rate": r.leak_rate,
               "balance": abs(r.inlet_flow / r.outlet_flow - 1) if r.outlet_flow else 0.0,
               "peak_memory_gb": own_peak_rss_mb() / 1e3}
        if con is None:
            t0, c0 = time.perf_counter(), time.process_time()
            con = critical_constriction(g, s.spacing, periodic=True)
            row.update(junction_wall_s=time.perf_counter() - t0,
                       junction_cpu_s=time.process_time() - c0,
                       critical_gap=con.critical_gap)
        rows.append(row)
    return rows


def coupled(n=COUPLED_N):
    from roughfe.leakage.fsi import coupled_leakage
    from roughfe.model import Material
    from roughfe.surfaces.spectral import spectral_surface
    s = spectral_surface(n, 1e-4, 0.8, rms_height=1e-6, rng=1)
    t0, c0 = time.perf_counter(), time.process_time()
    r = coupled_leakage(s, Material(1e9, 0.3), 3e7, p_in=2e7, p_out=0.0)
    return {"n": n, "wall_s": time.perf_counter() - t0, "cpu_s": time.process_time() - c0,
            "coupled_iterations": r.coupled_iterations, "residual": r.residual,
            "leak_rate": r.leak_rate, "one_way_leak_rate": r.one_way_leak_rate,
            "fluid_load_fraction": r.fluid_load_fraction,
            "area_fraction": r.contact.area_fraction,
            "peak_memory_gb": own_peak_rss_mb() / 1e3}


def _child(arg):
    out = subprocess.run([sys.executable, __file__, "--one", arg], capture_output=True,
                         text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(sizes, coupled_case=True):
    load = os.getloadavg()[0]
    print(f"load average {load:.1f} on {os.cpu_count()} cores")
    print(f"{'n':>5} {'A*':>5} {'live':>5} {'wall s':>7} {'cpu s':>6} {'sys':>5} {'setup':>6} "
          f"{'solve':>6} {'nit':>4} {'leak rate':>10} {'in/out-1':>8} {'GB':>5} {'junction':>8}")
    rows = []
    for n in sizes:
        for r in _child(str(n)):
            rows.append(r)
            print(row_line(r), flush=True)
    c = _child("coupled") if coupled_case else None
    if c is not None:
        print(f"coupled {COUPLED_N}^2: wall {c['wall_s']:.1f} s, cpu {c['cpu_s']:.1f} s, "
              f"{c['coupled_iterations']} iterations, residual {c['residual']:.1e}, "
              f"Q {c['leak_rate']:.3e} (one-way {c['one_way_leak_rate']:.3e}), "
              f"fluid load {c['fluid_load_fraction']:.3f}")
    targets = []
    for r in rows:
        if r["quantile"] != QUANTILES[0]:
            continue
        if r["n"] in TARGETS:
            lim = TARGETS[r["n"]]
            targets.append({"name": f"Reynolds FV {r['n']}^2 CPU time (s)", "value": r["cpu_s"],
                            "target": f"< {lim}", "met": r["cpu_s"] < lim,
                            "note": f"wall {r['wall_s']:.1f} s at load {load:.1f}"})
        if r["n"] == 4096:
            targets.append({"name": "Reynolds FV 4096^2 peak memory (GB)",
                            "value": r["peak_memory_gb"], "target": f"< {MEMORY_TARGET_GB}",
                            "met": r["peak_memory_gb"] < MEMORY_TARGET_GB})
    if c is not None:
        targets.append({"name": f"coupled solve {COUPLED_N}^2 CPU time (s)",
                        "value": c["cpu_s"], "target": f"< {COUPLED_TARGET_S}",
                        "met": c["cpu_s"] < COUPLED_TARGET_S,
                        "note": f"wall {c['wall_s']:.1f} s"})
    skipped = [{"name": f"Reynolds FV {n}^2", "reason": "not in the sizes given"}
               for n in sorted(set(TARGETS) - set(sizes))]
    if c is None:
        skipped.append({"name": f"coupled solve {COUPLED_N}^2",
                        "reason": "--no-coupled (bench_fsi.py times it per trapped-fluid "
                                  "model)"})
    write_report(OUT / "bench_reynolds.json", "bench_reynolds", targets, rows,
                 {"cpu_s": "s (process CPU time, user + system)", "wall_s": "s (elapsed)",
                  "system_cpu_s": "s", "amg_setup_cpu_s": "s", "cg_solve_cpu_s": "s",
                  "junction_cpu_s": "s", "leak_rate": "m^3/s", "peak_memory_gb": "GB"},
                 extra={"coupled": c},
                 skipped=skipped)
    return 0


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--one":
        res = coupled() if sys.argv[2] == "coupled" else one_size(int(sys.argv[2]))
        print(json.dumps(res))
        sys.exit(0)
    sizes, given = script_args(__doc__, flags=("--no-coupled",))
    sys.exit(main(sizes or [512, 1024, 2048, 4096], coupled_case="--no-coupled" not in given))
