"""The non-periodic surfaces of the BEM benchmarks (bench_bem_padding, bench_bem_nonperiodic):
RMD surfaces (D = 2.3, 2^m + 1 points per side) and the measured instrument files of
``../shared/data/topographies`` (``ROUGHFE_TOPOGRAPHIES`` overrides the folder); and the
paired runs of two solvers on one case, with their targets (also bench_bem_approach)."""
from __future__ import annotations

from roughfe.surfaces.io import topographies_folder

TOPOGRAPHIES = topographies_folder()


def surface_of(case):
    """The surface of ``case``, ``("rmd", m)`` or ``("file", name)``; None when the file
    is missing."""
    from roughfe.surfaces import rmd_surface
    from roughfe.surfaces.io import load_surface
    kind, arg = case
    if kind == "rmd":
        return rmd_surface(arg, 2.3, 1e-4, rng=1)
    path = TOPOGRAPHIES / arg
    return load_surface(path) if path.exists() else None


def run_summary(cpu, results):
    """One run of :func:`paired_runs`: its CPU (s) and, per step of ``results``
    (ContactResults), the iterations, A* and mean pressure."""
    return {"cpu_s": cpu, "nit": [int(r.nit) for r in results],
            "A*": [float(r.area_fraction) for r in results],
            "mean_pressure": [float(r.mean_pressure) for r in results]}


def paired_runs(run, new, old):
    """``run(mode)`` of the modes ``new`` and ``old`` over two rounds in alternating order
    (each returns ``cpu_s``, ``nit``, ``A*`` and ``mean_pressure``), compared: the smaller
    CPU of each, the speed-up CPU(old) / CPU(new), the first round's iterations, and the
    largest differences of A* and of the loads (relative) between the two."""
    runs = {new: [], old: []}
    for order in ((new, old), (old, new)):
        for mode in order:
            runs[mode].append(run(mode))
    best = {m: min(r["cpu_s"] for r in v) for m, v in runs.items()}
    a, b = runs[new][0], runs[old][0]
    return {"cpu_s": best, "speedup": best[old] / best[new],
            "nit": {new: a["nit"], old: b["nit"]},
            "max|dA*|": max(abs(x - y) for x, y in zip(a["A*"], b["A*"])),
            "max dp/p": max(abs(x - y) / abs(y) for x, y in
                            zip(a["mean_pressure"], b["mean_pressure"]) if y)}


def paired_targets(label, r, speed, not_slower, same_area, same_load):
    """The two target rows of a :func:`paired_runs` comparison ``r``: the speed-up (named
    ``speed``) at least ``not_slower``, and the same answer (A* within ``same_area``,
    loads within ``same_load`` relative)."""
    return [{"name": f"{label}: {speed}", "value": round(r["speedup"], 3),
             "target": f">= {not_slower}", "met": r["speedup"] >= not_slower},
            {"name": f"{label}: the same answer (max |dA*|, max dp/p)",
             "value": [r["max|dA*|"], r["max dp/p"]],
             "target": f"<= {same_area:g}, <= {same_load:g}",
             "met": r["max|dA*|"] <= same_area and r["max dp/p"] <= same_load}]
