"""``roughfe leak`` and ``roughfe leak-study``: leakage through a rough contact (Sec. 2.3-2.4).

``leak`` loads a surface, solves the BEM contact at each requested approach or mean
pressure, finds the percolating and trapped free volume (Alg. 1) and solves the Reynolds
equation (dolfinx) for the leak rate; it writes ``results.json`` (inputs and one record
per step), ``fields/step_NNN.npz`` and figures.

``leak-study`` runs the study of Sec. 2.4.2-2.4.5 (RMD surfaces, D x m x replicas) on
the resumable study runner (``roughfe study``), then writes ``summary.json`` (means,
standard deviations, Eq. 2.17 fits, network-vs-Reynolds percolation disagreements) and the
figures.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from ..bem import Material
from ..errors import InputError
from ..leakage import leakage_sweep
from ..leakage.study import THESIS_D, THESIS_M, study_grid, summarise
from ..theory import beside
from ..writers import atomic_path, write_json
from .common import add_surface_options, surface_from_args


def _add_fluid_material(p):
    mat = p.add_argument_group("material (elastic body against the rigid surface)")
    mat.add_argument("--E", type=float, default=1.0e9, help="Young's modulus in Pa (default 1e9)")
    mat.add_argument("--nu", type=float, default=0.3, help="Poisson ratio (default 0.3)")
    fl = p.add_argument_group("fluid")
    fl.add_argument("--mu", type=float, default=1.0e-3,
                    help="dynamic viscosity in Pa s (default 1e-3, water)")
    fl.add_argument("--pressure-drop", type=float, default=1.0,
                    help="fluid pressure drop p_in - p_out in Pa (default 1; Q is linear in it)")
    fl.add_argument("--direction", choices=("x", "y", "both"), default="both",
                    help="flow direction(s); percolating volume is the union (default both)")
    fl.add_argument("--no-reynolds", action="store_true",
                    help="network analysis only (skip the Reynolds FE solve)")


def _save_fields(path, contact, leak):
    arrays = {"gap": contact.gap, "contact": contact.contact, "pressure_contact": contact.pressure,
              "percolating": leak.network.percolating, "trapped": leak.network.trapped}
    for d, net in leak.network.directions.items():
        arrays[f"percolating_{d}"] = net.percolating
    for d, flow in leak.flows.items():
        arrays[f"fluid_pressure_{d}"] = flow.pressure
        arrays[f"flux_{d}"] = flow.flux
    for d, con in leak.constrictions.items():
        arrays[f"widest_path_{d}"] = con.path          # (n, 2) cell indices
        arrays[f"parent_channel_{d}"] = con.channel
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, **arrays)
    return path


def _leak(args) -> int:
    # imported before any solve: loads vtk before dolfinx (see roughfe.plotting.leakage)
    from ..plotting import leakage as figs

    if (args.delta is None) == (args.pressure is None):
        raise InputError("give exactly one of --delta (approaches, m) or --pressure "
                         "(mean contact pressures, Pa)")
    surface = surface_from_args(args)
    material = Material(args.E, args.nu)
    sweep = leakage_sweep(surface, material, deltas=args.delta, pressures=args.pressure,
                          direction=args.direction, mu=args.mu,
                          pressure_drop=args.pressure_drop, reynolds=not args.no_reynolds)
    out = Path(args.output)
    theory = beside(surface, material.E_star, sweep.records(), pressure_drop=args.pressure_drop,
                    viscosity=args.mu)
    steps = theory["steps"]
    inputs = {"surface": str(args.surface), "shape": list(surface.shape),
              "size": list(surface.size), "periodic": surface.periodic,
              "surface_metadata": dict(surface.metadata),
              "E": args.E, "nu": args.nu, "mu": args.mu, "pressure_drop": args.pressure_drop,
              "direction": args.direction, "reynolds": not args.no_reynolds,
              "delta": args.delta, "pressure": args.pressure,
              "units": "SI (m, Pa, Pa s, m^3/s)",
              "references": list(sweep.leakages[0].references)}
    write_json(out / "results.json", {"inputs": inputs, "steps": steps,
                                      "persson": theory["persson"]})
    written = [out / "results.json"]
    for k, (c, lk) in enumerate(zip(sweep.contacts, sweep.leakages)):
        written.append(_save_fields(out / "fields" / f"step_{k:03d}.npz", c, lk))
        if args.no_figures:
            continue
        tag = f"step {k}: A*={c.area_fraction:.3f}, p={c.mean_pressure:.3g} Pa"
        widest = np.zeros(c.gap.shape, bool)
        for con in lk.constrictions.values():
            widest[con.path[:, 0], con.path[:, 1]] = True
        written.append(figs.network_map(
            c.gap, lk.network.percolating, lk.network.trapped, surface.size,
            out / "figures" / f"step_{k:03d}_network.png", title=f"free-volume network, {tag}",
            widest_path=widest, junctions=[con.position for con in lk.constrictions.values()
                                           if con.position is not None]))
        for d, flow in lk.flows.items():
            written.append(figs.pressure_map(
                flow.pressure, surface.size, out / "figures" / f"step_{k:03d}_pressure_{d}.png",
                title=f"Reynolds pressure (Pa), flow along {d}\n{tag}", at=flow.pressure_at))
            written.append(figs.flux_map(
                flow.flux_magnitude, surface.size, out / "figures" / f"step_{k:03d}_flux_{d}.png",
                title=f"flux magnitude (m^2/s), flow along {d}\nleak rate Q = {flow.leak_rate:.3e} m^3/s"))
    if not args.no_figures:
        written.append(figs.steps_figure(steps, out / "figures" / "steps.png"))
    print(f"{'step':>4} {'delta (m)':>11} {'p (Pa)':>10} {'A*':>7} {'Vp*':>9} {'Vnp*':>9} "
          f"{'perc x/y':>8} {'Q (m^3/s)':>11}")
    for s in steps:
        q = s["leak_rate"]
        print(f"{s['step']:>4} {s['delta']:>11.4e} {s['mean_pressure']:>10.4g} "
              f"{s['area_fraction']:>7.4f} {s['percolating_volume_star'] or 0:>9.3e} "
              f"{s['trapped_volume_star'] or 0:>9.3e} "
              f"{str(s['percolates_x'])[0]}/{str(s['percolates_y'])[0]:>6} "
              f"{'-' if q is None else format(q, '.4e'):>11}")
    print(f"wrote {len(written)} files in {out}")
    return 0 if sweep.success else 1


def _leak_study(args) -> int:
    from ..plotting import leakage as figs
    from ..study import run_study, spec_from_mapping, table_rows

    out = Path(args.output)
    fixed = {"n_steps": args.steps, "L": args.length, "E": args.E, "nu": args.nu,
             "mu": args.mu, "pressure_drop": args.pressure_drop,
             "reynolds": not args.no_reynolds, "direction": args.direction}
    spec = spec_from_mapping({
        "study": {"name": "leakage-sec2.4", "analysis": "leakage", "output": str(out),
                  "seed": args.seed, "seed_from": ["replica"]},
        "grid": study_grid(args.D, args.m, args.surfaces), "fixed": fixed})
    summary = run_study(spec, executor=args.executor, workers=args.workers,
                        scheduler=args.scheduler, progress=not args.no_progress,
                        log=lambda msg: print(msg, file=sys.stderr))
    _, rows, missing = table_rows(out)
    if not rows:
        raise InputError(f"no task of the study in {out} finished; see `roughfe study status {out}`")
    result = summarise(rows)
    write_json(out / "summary.json", result)
    paths = [] if args.no_figures else figs.study_figures(result, out / "figures")
    perc = result["percolation"]
    print(f"{len(rows)} step records from {spec.n_tasks - missing} surfaces; "
          f"network and Reynolds percolation disagree in {perc['n_disagree']}/{perc['n_compared']}")
    for f in result["fits"]:
        g = "-" if f["g"] is None else f"{f['g']:.3f}"
        b = "-" if f["beta"] is None else f"{f['beta']:.3f}"
        print(f"D={f['D']:.1f} m={f['m']}: g={g} beta={b}")
    print(f"wrote {out / 'summary.json'} and {len(paths)} figures in {out / 'figures'}")
    return 0 if summary.complete else 1


def register(sub):
    p = sub.add_parser(
        "leak", help="leakage through a rough contact: BEM -> free-volume network -> Reynolds",
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_surface_options(p)
    load = p.add_argument_group("loading (one of)")
    load.add_argument("--delta", type=float, nargs="+", metavar="M",
                      help="approaches Delta from first contact, in m (one step each)")
    load.add_argument("--pressure", type=float, nargs="+", metavar="PA",
                      help="mean contact pressures in Pa (one step each)")
    _add_fluid_material(p)
    p.add_argument("-o", "--output", required=True, help="output folder")
    p.add_argument("--no-figures", action="store_true", help="skip the PNG figures")
    p.set_defaults(func=_leak)

    s = sub.add_parser(
        "leak-study", help="the percolation/leakage study of thesis Sec. 2.4 (resumable)",
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    s.add_argument("--D", type=float, nargs="+", default=list(THESIS_D),
                   help=f"fractal dimensions (default {' '.join(map(str, THESIS_D))})")
    s.add_argument("--m", type=int, nargs="+", default=list(THESIS_M),
                   help=f"RMD resolutions, 2**m+1 points (default {' '.join(map(str, THESIS_M))})")
    s.add_argument("--surfaces", type=int, default=2,
                   help="surfaces per (D, m) set; the same seeds across D and m (thesis: 20)")
    s.add_argument("--steps", type=int, default=6, help="approach steps up to h_s (default 6)")
    s.add_argument("--length", type=float, default=1.0e-4, help="lateral size L in m (default 1e-4)")
    s.add_argument("--seed", type=int, default=2016, help="base seed of the study")
    _add_fluid_material(s)
    s.add_argument("--executor", choices=("local", "dask", "mpi"), default="local",
                   help="where tasks run (default: local process pool)")
    s.add_argument("--scheduler", metavar="ADDRESS", default=None,
                   help="a running dask scheduler (tcp://host:8786 or a scheduler file); dask only")
    s.add_argument("--workers", type=int, default=None, help="worker processes (default: cores)")
    s.add_argument("--no-progress", action="store_true", help="no progress bar")
    s.add_argument("--no-figures", action="store_true", help="skip the PNG figures")
    s.add_argument("-o", "--output", required=True, help="study folder (rerun to resume)")
    s.set_defaults(func=_leak_study)
