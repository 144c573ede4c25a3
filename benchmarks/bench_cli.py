"""A light command line and figures that scale (issue 16 §3), timed through the real CLI.

Targets (issue 16 §3): ``roughfe contact`` reaches its solve within 0.5 s of process start;
the figures of a 2048^2 result take < 5 s (decimated render, figures on by default).

start    ``roughfe contact SURF.npz --pressure P --no-figures`` on a 512^2 periodic surface
         (H = 0.8, L = 0.1 mm, rms slope 0.1, E = 1 GPa, nu = 0.3, P = 0.02 E* gbar), run
         ``--repeats`` times, each in a fresh interpreter through ``roughfe.cli.main``. At the
         entry of the solve (``roughfe.response.response``, wrapped before the command
         module imports it; importing it first adds nothing, the command imports it at
         once) the child records its process CPU time (interpreter start-up included), its
         clock and the number of loaded modules; the wall time to the solve is that clock
         minus the parent's clock just before the spawn. Whole-process wall and CPU times
         are recorded too. Median over the repeats.
figures  ``roughfe contact`` on a 2048^2 surface of the same kind, one load, figures on: the
         CPU and wall time of the figure block (the import of ``roughfe.plotting.contact``
         plus its ``plot_area_stiffness`` and ``render_contact`` calls, pyvista/vtk loaded
         lazily inside, exactly as the command draws them), measured by wrapping those
         functions in the child; the solve is not in it.

The machine may be shared: wall times are inflated by the load (reported with them), CPU
times much less; both rows are shown, the wall row is the target as the issue states it.
Writes ``benchmarks/output/bench_cli.json``.
Run: ``.venv/bin/python benchmarks/bench_cli.py [--quick] [--repeats R]`` (``--quick``:
3 repeats, figures of a 1024^2 result, which is not the target size).
"""
import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
OUT = HERE / "output" / "bench_cli.json"
START_TARGET_S, FIGURES_TARGET_S = 0.5, 5.0
E, NU, SLOPE = 1e9, 0.3, 0.1


def _pressure():
    return 0.02 * E / (1 - NU ** 2) * SLOPE


# -- the child: the real command, instrumented -------------------------------------------
def child(mode, argv):
    """Run ``roughfe ARGV`` in this (fresh) interpreter and print one JSON line of timings."""
    rec = {}
    if mode == "start":
        import roughfe.response as response_module
        solve = response_module.response

        def timed_solve(*a, **kw):
            rec.setdefault("solve_entry_clock", time.time())
            rec.setdefault("solve_entry_cpu_s", time.process_time())
            rec.setdefault("modules_at_solve", len(sys.modules))
            return solve(*a, **kw)
        response_module.response = timed_solve
    else:
        c0, w0 = time.process_time(), time.perf_counter()
        import roughfe.plotting.contact as plots
        rec["figures_cpu_s"] = time.process_time() - c0
        rec["figures_wall_s"] = time.perf_counter() - w0

        def wrap(name):
            fn = getattr(plots, name)

            def timed(*a, **kw):
                c, w = time.process_time(), time.perf_counter()
                try:
                    return fn(*a, **kw)
                finally:
                    rec["figures_cpu_s"] += time.process_time() - c
                    rec["figures_wall_s"] += time.perf_counter() - w
            setattr(plots, name, timed)
        wrap("plot_area_stiffness")
        wrap("render_contact")
    from roughfe.cli import main
    with open(os.devnull, "w") as quiet:
        saved, sys.stdout = sys.stdout, quiet
        try:
            code = main(argv)
        finally:
            sys.stdout = saved
    usage = resource.getrusage(resource.RUSAGE_SELF)
    rec.update(exit_code=code, process_cpu_s=usage.ru_utime + usage.ru_stime,
               peak_rss_mb=usage.ru_maxrss * 1024 / 1e6,   # MB = 1e6 B (_report.megabytes)
               end_clock=time.time())
    print(json.dumps(rec))


def _run_child(mode, argv):
    t0 = time.time()
    res = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--child", mode,
                          json.dumps(argv)], capture_output=True, text=True, check=False)
    if res.returncode != 0:
        raise RuntimeError(f"bench_cli child {mode} failed:\n{res.stderr[-2000:]}")
    rec = json.loads(res.stdout.strip().splitlines()[-1])
    rec["process_wall_s"] = rec.pop("end_clock") - t0
    if "solve_entry_clock" in rec:
        rec["start_to_solve_wall_s"] = rec.pop("solve_entry_clock") - t0
    return rec


def _surface_file(n, folder):
    from roughfe.surfaces.io import save_surface
    from roughfe.surfaces.spectral import spectral_surface
    return save_surface(spectral_surface(n, 1e-4, 0.8, rms_slope=SLOPE, rng=1),
                        Path(folder) / f"surface_{n}.npz")


def _contact_argv(surface, out, figures):
    return (["contact", str(surface), "--E", str(E), "--nu", str(NU), "--pressure",
             str(_pressure()), "-o", str(out)] + ([] if figures else ["--no-figures"]))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--figures-size", type=int, default=2048)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--child", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        child(args.child[0], json.loads(args.child[1]))
        return 0
    if args.quick:
        args.repeats, args.figures_size = 3, 1024
    sys.path.insert(0, str(HERE))
    from _report import write_report  # benchmarks/_report.py

    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores", flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        small = _surface_file(512, tmp)
        starts = []
        for k in range(args.repeats):
            r = _run_child("start", _contact_argv(small, Path(tmp) / f"start{k}", False))
            r.update(case="start", n=512, repeat=k, load_average=os.getloadavg()[0])
            starts.append(r)
            print(f"512^2 --no-figures: start to solve {r['start_to_solve_wall_s']:.2f} s wall, "
                  f"{r['solve_entry_cpu_s']:.2f} s CPU, {r['modules_at_solve']} modules; "
                  f"whole process {r['process_wall_s']:.2f} s wall, {r['process_cpu_s']:.2f} s "
                  f"CPU", flush=True)
        big = _surface_file(args.figures_size, tmp)
        fig = _run_child("figures", _contact_argv(big, Path(tmp) / "figures", True))
        fig.update(case="figures", n=args.figures_size, load_average=os.getloadavg()[0])
        print(f"{args.figures_size}^2 figures: {fig['figures_wall_s']:.2f} s wall, "
              f"{fig['figures_cpu_s']:.2f} s CPU (whole process {fig['process_wall_s']:.1f} s "
              f"wall, {fig['peak_rss_mb']:.0f} MB)", flush=True)
    wall = statistics.median(r["start_to_solve_wall_s"] for r in starts)
    cpu = statistics.median(r["solve_entry_cpu_s"] for r in starts)
    load = statistics.median(r["load_average"] for r in starts)
    targets = [
        {"name": "roughfe contact 512^2: process start to solve, wall (s)", "value": wall,
         "target": f"< {START_TARGET_S:g}", "met": bool(wall < START_TARGET_S), "unit": "s",
         "note": f"median of {len(starts)}, load {load:.1f}"},
        {"name": "roughfe contact 512^2: process start to solve, CPU (s)", "value": cpu,
         "target": f"< {START_TARGET_S:g}", "met": bool(cpu < START_TARGET_S), "unit": "s",
         "note": f"median of {len(starts)}; the quiet-machine wall time when I/O is cached"},
        {"name": f"figures of a {args.figures_size}^2 result, wall (s)",
         "value": fig["figures_wall_s"], "target": f"< {FIGURES_TARGET_S:g}",
         "met": bool(fig["figures_wall_s"] < FIGURES_TARGET_S), "unit": "s",
         "note": f"load {fig['load_average']:.1f}"},
        {"name": f"figures of a {args.figures_size}^2 result, CPU (s)",
         "value": fig["figures_cpu_s"], "target": f"< {FIGURES_TARGET_S:g}",
         "met": bool(fig["figures_cpu_s"] < FIGURES_TARGET_S), "unit": "s"}]
    skipped = ([] if args.figures_size == 2048 else
               [{"name": "figures of a 2048^2 result",
                 "reason": f"--figures-size {args.figures_size} (--quick)"}])
    write_report(OUT, "bench_cli", targets, starts + [fig],
                 {"start_to_solve_wall_s": "s (spawn to the solve's entry)",
                  "solve_entry_cpu_s": "s (process CPU at the solve's entry)",
                  "figures_wall_s": "s", "figures_cpu_s": "s", "process_wall_s": "s",
                  "process_cpu_s": "s", "peak_rss_mb": "MB"}, skipped=skipped)
    return 0


if __name__ == "__main__":
    sys.exit(main())
