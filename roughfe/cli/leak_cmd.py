"""``roughfe leak`` and ``roughfe leak-study``: leakage through a rough contact (Sec. 2.3-2.4).

``leak`` loads a surface, solves the BEM contact at each requested approach or mean
pressure, finds the percolating and trapped free volume (Alg. 1), the critical
constriction and the Reynolds leak rate (cell-centred finite volumes); with ``--fsi`` the
fluid pressure acts back on the body (two-way coupling, :mod:`roughfe.leakage.fsi`;
``--pressure`` is the external pressure; options, files and table in
:mod:`roughfe.cli.leak_fsi`). It writes ``results.json`` (inputs and one
record per step), ``fields/step_NNN.npz`` and figures.

``leak-study`` runs the study of Sec. 2.4.2-2.4.5 (RMD surfaces, D x m x replicas) on
the resumable study runner (``roughfe study``), then writes ``summary.json`` (means,
standard deviations, Eq. 2.17 fits, network-vs-Reynolds percolation disagreements) and the
figures.
"""
from __future__ import annotations

from pathlib import Path

from ..bem.interface_law import cell_relief, resolution
from ..errors import InputError
from ..leakage.study import THESIS_D, THESIS_M
from ..writers import write_json
from .info_reliability import print_reliability_note, reliability_block
from .leak_fields import (edge_junction_note, maps_of as _maps_of, network_figure,
                          save_fields, step_units)
from .leak_fsi import print_coupled, run_coupled
from .leak_options import add_coupling_options, add_fluid_material, fluid_pressures
from .plausibility import (check_critical_gaps, check_fluid_load, check_load_magnitudes,
                           check_pocket_pressures, check_solution, persson_basis)
from .options import (ADHESION_WORDS, add_contact_physics_options, add_detrend_option,
                      add_output_folder, add_run_options, add_runner_options,
                      add_surface_options, contact_physics_from_args,
                      material_from_args, nonnegative_int, output_folder_of, positive_float,
                      fmt_or_dash, log_of, positive_int, print_surface_notes,
                      show_progress, surface_from_args)


#: the free-volume columns of both leak tables (one-way and --fsi): header, cells, footnote
_VOLUME_HEAD = f"{'Vp*':>9} {'Vnp*':>9} {'sealed*':>9} {'perc x/y':>8}"
_VOLUME_NOTE = ("Vp*, Vnp*: percolating and trapped (non-percolating, Alg. 1) free volume / "
                "(A_n sigma); sealed*: the part of Vnp* with no open path to inlet or outlet "
                "(the rest are dead ends open to the flow); perc x/y: the network percolates "
                "along x / y (T, F; -: not analysed)")


def _volume_cells(s) -> str:
    """A step's cells under :data:`_VOLUME_HEAD` (``-`` where not computed)."""
    perc = "/".join({True: "T", False: "F"}.get(s.get(f"percolates_{d}"), "-") for d in "xy")
    return " ".join([*(f"{fmt_or_dash(s.get(k), '.3e'):>9}" for k in (
        "percolating_volume_star", "trapped_volume_star", "sealed_volume_star")), f"{perc:>8}"])


def _print_if(line):
    if line:
        print(line)


def _leak(args) -> int:
    if args.maps is not None and args.no_figures:   # was ignored (round 2, session 37)
        raise InputError(f"--maps {args.maps} chooses the steps whose maps are drawn; "
                         "--no-figures draws none: give one of them")
    surface = surface_from_args(args)
    material = material_from_args(args)
    reliability = reliability_block(args, surface)      # trace vs retrace, or None
    with output_folder_of(args, "leak") as out:
        sweep, steps, written, persson = _leak_run(args, surface, material, out,
                                                   reliability)
    print_surface_notes(args, surface)
    print_reliability_note(reliability, surface,
                           "contact patches, the gaps and the junctions that set Q")
    if args.fsi:
        print_coupled(steps, _VOLUME_HEAD, _volume_cells, _VOLUME_NOTE)
        _print_if(edge_junction_note(steps))
        check_pocket_pressures(args, steps)
        persson_basis(args, surface, persson)
        print(f"wrote {len(written)} files in {out}")
        return 0 if sweep.success else 1
    # both directions: Q_x and Q_y side by side (their mean, results.json leak_rate, mixes
    # two geometry factors W/L and can be neither: a user's review, round 2, session 29)
    keys = ["leak_rate_x", "leak_rate_y"] if args.direction == "both" else ["leak_rate"]
    heads = ["Q_x (m^3/s)", "Q_y (m^3/s)"] if args.direction == "both" else ["Q (m^3/s)"]
    print(f"{'step':>4} {'delta (m)':>11} {'p (Pa)':>10} {'A*':>8} {_VOLUME_HEAD} "
          + " ".join(f"{h:>11}" for h in heads))
    for s in steps:
        print(f"{s['step']:>4} {s['delta']:>11.4e} {s['mean_pressure']:>10.4g} "
              f"{s['area_fraction']:>8.3g} {_volume_cells(s)} "
              + " ".join(f"{fmt_or_dash(s[k], '.4e'):>11}" for k in keys))
    p_in, p_out = fluid_pressures(args)
    along = ("x and y (results.json leak_rate is their mean)" if args.direction == "both"
             else args.direction)
    print(_VOLUME_NOTE)
    _print_if(edge_junction_note(steps))
    # the flags the drop came from; no Q line without the Reynolds solve (it described a
    # drop of 1 Pa beside columns of '-': a review, round 2, session 33)
    given = ("--inlet-pressure - --outlet-pressure" if args.inlet_pressure is not None
             else "--pressure-drop")
    if args.no_reynolds:
        print("Q: not solved (--no-reynolds); results.json keeps the critical-junction and "
              "Persson leak rates at the pressure drop "
              f"{p_in - p_out:g} Pa ({given}) and viscosity {args.mu:g} Pa s (--mu)")
    else:
        print(f"Q: leak rate along {along} at the pressure drop {p_in - p_out:g} Pa "
              f"({given}) and viscosity {args.mu:g} Pa s (--mu); Q is proportional to the "
              f"drop and to 1/mu")
    check_critical_gaps(args, steps)
    check_fluid_load(args, steps, p_in, p_out)
    persson_basis(args, surface, persson)
    print(f"wrote {len(written)} files in {out}")
    return 0 if sweep.success else 1


#: leak's words in the messages of :func:`roughfe.bem.adhesive_rules.check_adhesive_run`
#: (its approaches are --delta only: it has no --steps)
LEAK_ADHESION_WORDS = {**ADHESION_WORDS, "approaches": "--delta"}


def _leak_run(args, surface, material, out, reliability=None):
    """Solve and write every file of ``roughfe leak`` into ``out``; results.json last
    (``reliability``: :func:`~roughfe.cli.info_reliability.reliability_block` of the
    surface, its ``inputs.reliability``)."""
    from ..leakage import leakage_sweep
    from ..plotting import leakage as figs
    from ..theory import beside

    p_in, p_out = fluid_pressures(args)
    check_load_magnitudes(surface, material, args.pressure, args.delta)
    physics = contact_physics_from_args(args)
    if physics["adhesion"] is not None and not args.fsi:   # (--fsi refuses --adhesion itself)
        from ..bem.adhesive_rules import check_adhesive_run
        check_adhesive_run(pressure_control=args.pressure is not None,
                           words=LEAK_ADHESION_WORDS)
    for flag, value in (("--bulk-modulus", args.bulk_modulus),
                        ("--trapped-fluid", args.trapped_fluid)):
        if value is not None and not args.fsi:
            raise InputError(f"{flag} needs --fsi (trapped fluid of the coupled solve)")
    base = {"surface": str(args.surface), "shape": list(surface.shape),
            "size": list(surface.size), "periodic": surface.periodic,
            "surface_metadata": dict(surface.metadata), "E": args.E, "nu": args.nu,
            "mu": args.mu, "inlet_pressure": p_in, "outlet_pressure": p_out,
            "pressure_drop": p_in - p_out, "direction": args.direction, "fsi": args.fsi,
            "trapped_fluid": (args.trapped_fluid or "volume") if args.fsi else None,
            "bulk_modulus": args.bulk_modulus,
            "delta": args.delta,
            "pressure": args.pressure, "detrend": args.detrend, "reliability": reliability,
            "hardness": physics["hardness"], "unload": physics["unload"],
            "adhesion": physics["adhesion"] and physics["adhesion"].describe(),
            "units": "SI (m, Pa, Pa s, m^3/s)"}
    if physics["adhesion"] is not None:  # the process zone against the grid (provenance)
        from ..bem.adhesion import cell_compliance
        base["adhesion_resolution"] = resolution(
            physics["adhesion"], material.E_star, surface.spacing,
            cell_compliance(surface, material.E_star), cell_relief(surface.heights))
    if args.fsi:
        return run_coupled(args, surface, material, out, base, physics, p_in, p_out)
    dp = p_in - p_out
    sweep = leakage_sweep(surface, material, deltas=args.delta, pressures=args.pressure,
                          direction=args.direction, mu=args.mu, pressure_drop=dp,
                          reynolds=not args.no_reynolds, contact_options=physics)
    check_solution(args, surface, sweep.contacts, material)
    theory = beside(surface, material.E_star, sweep.records(), pressure_drop=dp,
                    viscosity=args.mu, direction=args.direction,
                    adhesive=physics["adhesion"] is not None, hardness=physics["hardness"])
    steps = theory["steps"]
    inputs = {**base, "reynolds": not args.no_reynolds,
              "references": list(sweep.leakages[0].references)}
    written = []
    for k, (c, lk) in enumerate(zip(sweep.contacts, sweep.leakages)):
        written.append(save_fields(out / "fields" / f"step_{k:03d}.npz", c, lk, surface))
        if not _maps_of(args, k, len(sweep.contacts)):
            continue
        tag = f"step {k}: A*={c.area_fraction:.3f}, p={c.mean_pressure:.3g} Pa"
        written.append(network_figure(c, lk, surface,
                                      out / "figures" / f"step_{k:03d}_network.png",
                                      title=f"free-volume network, {tag}"))
        for d, flow in lk.flows.items():
            written.append(figs.pressure_map(
                flow.pressure, surface.size, out / "figures" / f"step_{k:03d}_pressure_{d}.png",
                title=f"Reynolds pressure (Pa), flow along {d}\n{tag}", at=flow.pressure_at))
            written.append(figs.flux_map(
                flow.flux_magnitude, surface.size, out / "figures" / f"step_{k:03d}_flux_{d}.png",
                title=f"flux magnitude (m^2/s), flow along {d}\nleak rate Q = {flow.leak_rate:.3e} m^3/s"))
    if not args.no_figures:
        written.append(figs.steps_figure(steps, out / "figures" / "steps.png"))
    written.append(write_json(out / "results.json", {
        "inputs": inputs, "steps": steps, "units": step_units(steps),
        "persson": theory["persson"]}))
    return sweep, steps, written, theory["persson"]


def _leak_study(args) -> int:
    from ..leakage.study import study_grid, summarise
    from ..plotting import leakage as figs
    from ..study import run_study, spec_from_mapping, study_status, table_rows
    from ..study.store import study_lock

    out = Path(args.output)
    fixed = {"n_steps": args.steps, "L": args.length, "E": args.E, "nu": args.nu,
             "mu": args.mu,
             "pressure_drop": 1.0 if args.pressure_drop is None else args.pressure_drop,
             "reynolds": not args.no_reynolds, "direction": args.direction}
    spec = spec_from_mapping({
        "study": {"name": "leakage-sec2.4", "analysis": "leakage", "output": str(out),
                  "seed": args.seed, "seed_from": ["replica"]},
        "grid": study_grid(args.D, args.m, args.surfaces), "fixed": fixed})
    # summary.json and figures/ describe the whole study: the run removes them when it
    # starts (a run killed before they are rewritten leaves none of an earlier state)
    summary = run_study(spec, executor=args.executor, workers=args.workers,
                        scheduler=args.scheduler, progress=show_progress(args),
                        log=log_of(args), derived=("summary.json", "figures"))
    with study_lock(out, "`roughfe leak-study`"):      # no run changes the results meanwhile
        _, rows, missing = table_rows(out)
        if not rows:    # the first task's error said here (only `study status` said it)
            fails = study_status(out).failures
            why = f" (task {fails[0][0]}: {fails[0][2]})" if fails else ""
            raise InputError(f"no task of the study in {out} finished{why}; "
                             f"see `roughfe study status {out}`")
        result = summarise(rows)
        # the settings every curve belongs to (Q is at this pressure drop and viscosity;
        # summary.json had none: a user's review, round 2, session 29)
        result["settings"] = dict(fixed, units={"L": "m", "E": "Pa", "mu": "Pa s",
                                                "pressure_drop": "Pa"})
        paths = [] if args.no_figures else figs.study_figures(result, out / "figures")
        write_json(out / "summary.json", result)                # last: the study is complete
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
        description="Leakage through a rough contact (thesis Sec. 2.3): at each approach "
                    "or mean pressure, the BEM contact, the percolating and trapped free "
                    "volume (Alg. 1) and the Reynolds flow through the gap. Writes "
                    "OUTDIR/fields/step_NNN.npz (gap, contact, pressures, fluxes), the "
                    "figures in OUTDIR/figures and, last, OUTDIR/results.json (inputs and one "
                    "record per step). SI units (m, Pa, Pa s, m^3/s).")
    add_surface_options(p)
    add_detrend_option(p)
    load = p.add_argument_group("loading (exactly one)").add_mutually_exclusive_group(required=True)
    load.add_argument("--delta", type=float, nargs="+", metavar="M",
                      help="approaches Delta from first contact, in m (one step each; "
                           "with --adhesion strictly increasing)")
    load.add_argument("--pressure", type=positive_float, nargs="+", metavar="PA",
                      help="mean contact pressures in Pa (one step each)")
    add_fluid_material(p)
    add_contact_physics_options(p, unload_help=(
        "after loading, the same approaches/pressures in reverse (with --hardness the "
        "plastic displacement stays; with --adhesion until the surfaces separate); the "
        "leakage of every step"))
    add_coupling_options(p)
    add_output_folder(p)
    add_run_options(p)
    p.add_argument("--maps", choices=("ends", "all"), default=None,
                   help="the per-step maps (network, pressure, flux) of the first and the "
                        "last step (ends, the default) or of every step (all: about 1 s per "
                        "map); figures/steps.png draws every step in any case; figures, "
                        "so not with --no-figures")
    p.set_defaults(func=_leak, renders_with_dolfinx=True)

    s = sub.add_parser(
        "leak-study", help="the percolation/leakage study of thesis Sec. 2.4 (resumable)",
        description="The percolation/leakage study of thesis Sec. 2.4.2-2.4.5: RMD "
                    "surfaces for every fractal dimension D and resolution m, several "
                    "replicas each, loaded in steps up to h_s. Runs on the resumable study "
                    "runner (rerun the same command after an interruption), then writes "
                    "OUTDIR/summary.json (means, standard deviations, Eq. 2.17 fits, "
                    "percolation-rule disagreements) and the figures.")
    s.add_argument("--D", type=float, nargs="+", default=list(THESIS_D),
                   help="fractal dimensions of the RMD surfaces, in (2, 3)")
    s.add_argument("--m", type=positive_int, nargs="+", default=list(THESIS_M),
                   help="RMD resolutions, 2**m+1 points per side")
    s.add_argument("--surfaces", type=positive_int, default=2,
                   help="surfaces per (D, m) set; the same seeds across D and m (thesis: 20)")
    s.add_argument("--steps", type=positive_int, default=6, help="approach steps up to h_s")
    s.add_argument("--length", type=positive_float, default=1.0e-4, help="lateral size L in m")
    s.add_argument("--seed", type=nonnegative_int, default=2016, help="base seed of the study")
    add_fluid_material(s, fsi=False)
    add_runner_options(s)
    s.add_argument("-o", "--output", required=True, metavar="OUTDIR",
                   help="study folder (rerun the same command to resume)")
    add_run_options(s)
    s.set_defaults(func=_leak_study)
