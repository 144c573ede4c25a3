"""benchmarks/bench_reynolds.py: a gap whose open components do not percolate is a row of
the table (the Reynolds solver makes no linear solve there: Q = 0 and no KSP report), not
a TypeError that loses every Reynolds target of a full `make bench` (1024^2 at A* = 0.40
on 2026-11-29, after the one-sided components stopped being unknowns)."""
import numpy as np


def test_a_row_without_a_linear_solve_is_printed(bench_script):
    from roughfe.leakage.finite_volume import solve_reynolds_fv
    bench = bench_script("bench_reynolds")
    gap = np.full((16, 16), 1e-6)
    gap[8, :] = 0.0                           # a closed band across the flow (x): no percolation
    r = solve_reynolds_fv(gap, (1e-6, 1e-6), p_in=1e5, p_out=0.0, periodic=True)
    assert r.leak_rate == 0.0
    setup, solve = bench._split(r.message)
    assert setup is None and solve is None, r.message
    row = {"n": 16, "area_fraction": 1 / 16, "live_fraction": float(r.connected.mean()),
           "wall_s": 0.0, "cpu_s": 0.0, "system_cpu_s": 0.0, "amg_setup_cpu_s": setup,
           "cg_solve_cpu_s": solve, "nit": r.nit, "leak_rate": r.leak_rate, "balance": 0.0,
           "peak_memory_gb": 0.1}
    line = bench.row_line(row)
    assert line.split()[6:8] == ["-", "-"], line
