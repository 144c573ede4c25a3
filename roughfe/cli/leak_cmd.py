"""``roughfe leak`` and ``roughfe leak-study``: leakage through a rough contact (Sec. 2.3-2.4).

``leak`` loads a surface, solves the BEM contact at each requested approach or mean
pressure, finds the percolating and trapped free volume (Alg. 1), the critical
constriction and the Reynolds leak rate (cell-centred finite volumes); with ``--fsi`` the
fluid pressure acts back on the body (two-way coupling, :mod:`roughfe.leakage.fsi`) and
``--pressure`` is the external pressure. It writes ``results.json`` (inputs and one
record per step), ``fields/step_NNN.npz`` and figures.

``leak-study`` runs the study of Sec. 2.4.2-2.4.5 (RMD surfaces, D x m x replicas) on
the resumable study runner (``roughfe study``), then writes ``summary.json`` (means,
standard deviations, Eq. 2.17 fits, network-vs-Reynolds percolation disagreements) and the
figures.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..bem.interface_law import cell_relief, resolution
from ..errors import InputError
from ..leakage.study import THESIS_D, THESIS_M
from ..writers import atomic_path, write_json
from .plausibility import (check_critical_gaps, check_fluid_load, check_load_magnitudes,
                           check_pocket_pressures, check_solution, persson_basis)
from .options import (ADHESION_WORDS, add_contact_physics_options, add_detrend_option, add_material_options,
                      add_output_folder, add_run_options, add_runner_options,
                      add_surface_options, contact_physics_from_args,
                      material_from_args, nonnegative_int, output_folder_of, positive_float,
                      fmt_or_dash, log_of, positive_int, print_surface_notes,
                      show_progress, surface_from_args)


def _add_fluid_material(p, fsi=True):
    add_material_options(p, "material (elastic body against the rigid surface)")
    fl = p.add_argument_group("fluid")
    fl.add_argument("--mu", type=positive_float, default=1.0e-3,
                    help="dynamic viscosity in Pa s (1e-3: water)")
    fl.add_argument("--pressure-drop", type=positive_float, default=None,
                    help="fluid pressure drop p_in - p_out in Pa (Q is linear in it; "
                         "default 1" + ("; with --fsi: p_in = DP, p_out = 0)" if fsi else ")"))
    fl.add_argument("--direction", choices=("x", "y", "both"), default="both",
                    help="flow direction(s); the percolating volume is their union")
    fl.add_argument("--no-reynolds", action="store_true",
                    help="network analysis only (skip the Reynolds solve)")


def _add_coupling_options(p):
    fs = p.add_argument_group("fluid-structure coupling")
    fs.add_argument("--fsi", action="store_true",
                    help="two-way coupling: the fluid pressure loads the body; --pressure is "
                         "the external pressure (contact + fluid); one flow direction")
    fs.add_argument("--inlet-pressure", type=float, default=None, metavar="PI",
                    help="absolute inlet pressure in Pa (with --outlet-pressure; instead of "
                         "--pressure-drop; PI < PO reverses the flow with --fsi)")
    fs.add_argument("--outlet-pressure", type=float, default=None, metavar="PO",
                    help="absolute outlet pressure in Pa")
    fs.add_argument("--trapped-fluid", choices=("volume", "pressure", "film"),
                    default=None,
                    help="with --fsi: pockets sealed by contact: 'volume' keep their liquid "
                         "(pressure an unknown carrying load; incompressible unless "
                         "--bulk-modulus), 'pressure' keep their pressure at closure, 'film' "
                         "are drained (pressure of their surroundings) (default: volume)")
    fs.add_argument("--bulk-modulus", type=positive_float, default=None, metavar="K",
                    help="bulk modulus of the liquid in Pa for --trapped-fluid volume "
                         "(p = p_closure + K ln(V_closure/V); water 2.2e9); default: "
                         "incompressible")


def _fluid_pressures(args):
    """(p_in, p_out) from --inlet/--outlet-pressure or --pressure-drop (one-line errors)."""
    given = (args.inlet_pressure is not None, args.outlet_pressure is not None)
    if any(given) and args.pressure_drop is not None:
        raise InputError("give either --pressure-drop or --inlet-pressure and "
                         "--outlet-pressure, not both")
    if any(given) and not all(given):
        raise InputError("--inlet-pressure and --outlet-pressure go together (absolute Pa)")
    if all(given):
        p_in, p_out = float(args.inlet_pressure), float(args.outlet_pressure)
        for name, v in (("--inlet-pressure", p_in), ("--outlet-pressure", p_out)):
            if not (np.isfinite(v) and v >= 0):
                raise InputError(f"{name} must be an absolute pressure >= 0 in Pa, got {v!r}")
        if not args.fsi and p_in <= p_out:
            raise InputError(f"--inlet-pressure {p_in:g} Pa must exceed --outlet-pressure "
                             f"{p_out:g} Pa (reversed flow is solved with --fsi only)")
        return p_in, p_out
    dp = 1.0 if args.pressure_drop is None else float(args.pressure_drop)
    return dp, 0.0


#: units of the arrays of fields/step_NNN.npz (key prefix -> unit), stored in the file
FIELD_UNITS = {"gap": "m", "contact": "1", "pressure_contact": "Pa", "fluid_pressure": "Pa",
               "flux": "m^2/s (volume flux per unit width, per cell: x, y components)",
               "percolating": "1", "trapped": "1", "sealed": "1",
               "pockets": "pocket number per cell: k >= 1 the k-th of the step's "
                          "pocket_pressures / pocket_volumes in results.json (largest "
                          "first), 0 none",
               "widest_path": "cell indices (n, 2)", "parent_channel": "cell indices",
               "size_m": "m", "spacing_m": "m"}


#: what the contact keys mean with ``--fsi`` (the solid carries the effective pressure on top
#: of the fluid's, roughfe.leakage.fsi): the npz and results.json said "Pa" and "N" only
FSI_UNITS = {
    "pressure_contact": "Pa (the solid's effective contact pressure on top of the fluid "
                        "pressure: a contact cell's normal traction is pressure_contact + "
                        "fluid_pressure)",
    "mean_pressure": "Pa (the solid's effective pressure: external_pressure - mean fluid "
                     "pressure)",
    "load": "N (carried by the solid's effective pressure)"}


def _write_step_npz(path, arrays: dict, surface, units=None) -> Path:
    """One step's fields, with the grid (``size_m``, ``spacing_m``) and ``units`` (a JSON
    object: array name -> unit; ``units`` overrides :data:`FIELD_UNITS` by name) so that
    the file is read without results.json."""
    import json
    arrays = {**arrays, "size_m": np.asarray(surface.size, float),
              "spacing_m": np.asarray(surface.spacing, float)}
    units = {k: (units or {}).get(k) or next(
        (u for pre, u in FIELD_UNITS.items() if k.startswith(pre)), "") for k in arrays}
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, units=np.array(json.dumps(units)), **arrays)
    return path


def _contact_network_arrays(contact, leak) -> dict:
    """The arrays of a step's contact and free-volume network, the same for the one-way
    and the coupled (``--fsi``) sweep: gap, contact, contact pressure, the percolating,
    trapped and sealed (:attr:`~roughfe.leakage.network.NetworkResult.sealed`) cells, the
    percolating cells and the critical constriction of each analysed direction."""
    net = leak.network
    arrays = {"gap": contact.gap, "contact": contact.contact, "pressure_contact": contact.pressure,
              "percolating": net.percolating, "trapped": net.trapped, "sealed": net.sealed}
    for d, one in net.directions.items():
        arrays[f"percolating_{d}"] = one.percolating
    for d, con in leak.constrictions.items():
        arrays[f"widest_path_{d}"] = con.path          # (n, 2) cell indices
        arrays[f"parent_channel_{d}"] = con.channel
    return arrays


def _save_fields(path, contact, leak, surface):
    arrays = _contact_network_arrays(contact, leak)
    for d, flow in leak.flows.items():
        arrays[f"fluid_pressure_{d}"] = flow.pressure
        arrays[f"flux_{d}"] = flow.flux
    return _write_step_npz(path, arrays, surface)


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


def _leak(args) -> int:
    surface = surface_from_args(args)
    material = material_from_args(args)
    with output_folder_of(args, "leak") as out:
        sweep, steps, written, persson = _leak_run(args, surface, material, out)
    print_surface_notes(args, surface)
    if args.fsi:
        print(f"{'step':>4} {'p_ext (Pa)':>11} {'state':>8} {'A*':>8} {_VOLUME_HEAD} "
              f"{'fluid':>6} {'trap':>6} {'iter':>5} "
              f"{'Q (m^3/s)':>11} {'Q one-way':>11} {'u_c (m)':>10}")
        for s in steps:
            print(f"{s['step']:>4} {s['external_pressure']:>11.4g} {s['fsi_state']:>8} "
                  f"{fmt_or_dash(s.get('area_fraction'), '.3g'):>8} {_volume_cells(s)} "
                  f"{s['fluid_load_fraction']:>6.3f} {s['trapped_load_fraction']:>6.3f} "
                  f"{s['coupled_iterations']:>5} {fmt_or_dash(s['leak_rate'], '.4e'):>11} "
                  f"{fmt_or_dash(s['leak_rate_one_way'], '.4e'):>11} "
                  f"{fmt_or_dash(s.get('critical_gap'), '.3e'):>10}")
        print(_VOLUME_NOTE + "; fluid, trap: the external load's share carried by the fluid "
              "and by its trapped pockets")
        lifted = [f"{s['external_pressure']:.4g}" for s in steps if s["fsi_state"] == "lift-off"]
        if lifted:      # said on the table's '-' (a seals review: nothing explained it)
            print(f"lift-off at p_ext = {', '.join(lifted)} Pa: the fluid pressure alone "
                  f"carries the external load, the surfaces separate and the seal is open "
                  f"(no contact; no finite leak rate of this model)")
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
    p_in, p_out = _fluid_pressures(args)
    along = ("x and y (results.json leak_rate is their mean)" if args.direction == "both"
             else args.direction)
    print(_VOLUME_NOTE)
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


def _leak_fsi(args, surface, material, out, p_in, p_out):
    """``roughfe leak --fsi``: the coupled sweep, its fields and maps (``steps.png`` is drawn
    by the caller, after Persson's theory is added to the steps; results.json last)."""
    from ..leakage.fsi_sweep import coupled_leakage_sweep
    from ..plotting import leakage as figs

    if args.pressure is None:
        raise InputError("--fsi needs --pressure (external pressures, Pa), not --delta")
    if args.direction == "both":
        raise InputError("--fsi solves one flow direction: give --direction x or --direction y")
    if args.no_reynolds:
        raise InputError("--fsi needs the Reynolds solve; drop --no-reynolds")
    if args.bulk_modulus is not None and args.trapped_fluid not in (None, "volume"):
        raise InputError(f"--bulk-modulus belongs to --trapped-fluid volume, not "
                         f"{args.trapped_fluid!r}")
    sweep = coupled_leakage_sweep(surface, material, args.pressure, direction=args.direction,
                                  p_in=p_in, p_out=p_out, mu=args.mu,
                                  trapped=args.trapped_fluid or "volume",
                                  bulk_modulus=(np.inf if args.bulk_modulus is None
                                                else args.bulk_modulus))
    steps = sweep.records()
    written = []
    for k, (r, lk) in enumerate(zip(sweep.results, sweep.leakages)):
        # numbered as results.json's pocket lists, 0 elsewhere (it saved the internal
        # labels, -1 elsewhere and 0 the first pocket, under the unit "0: none"; none at
        # all with --trapped-fluid film, whose drained pockets the lists report)
        arrays = {"fluid_pressure": r.fluid_pressure, "pockets": r.pocket_labels}
        if r.contact is not None:      # the one-way sweep's contact and network arrays
            arrays.update(_contact_network_arrays(r.contact, lk), flux=r.flow.flux)
        path = _write_step_npz(out / "fields" / f"step_{k:03d}.npz", arrays, surface,
                               units=FSI_UNITS)
        written.append(path)
        if not _maps_of(args, k, len(sweep.results)) or r.contact is None:
            continue
        tag = (f"step {k}: p_ext={r.external_pressure:.3g} Pa, A*={r.contact.area_fraction:.3f}, "
               f"fluid load {r.fluid_load_fraction:.3f}")
        widest = np.zeros(r.contact.gap.shape, bool)
        for con in lk.constrictions.values():
            widest[con.path[:, 0], con.path[:, 1]] = True
        written.append(figs.network_map(
            r.contact.gap, lk.network.percolating, lk.network.trapped, surface.size,
            out / "figures" / f"step_{k:03d}_network.png", sealed=lk.network.sealed,
            title=f"coupled free-volume network, {tag}", widest_path=widest,
            junctions=[con.position for con in lk.constrictions.values()
                       if con.position is not None]))
        written.append(figs.pressure_map(   # contact cells grey, as on the one-way maps
            np.where(r.contact.contact, np.nan, r.fluid_pressure), surface.size,
            out / "figures" / f"step_{k:03d}_fluid_pressure.png",
            title=f"fluid pressure (Pa), two-way coupled, contact grey\n{tag}", at="cells",
            clim=(min(p_in, p_out), max(p_in, p_out))))     # pockets above: magenta
    return sweep, steps, written


#: leak's words in the messages of :func:`roughfe.bem.adhesive_rules.check_adhesive_run`
#: (its approaches are --delta only: it has no --steps)
LEAK_ADHESION_WORDS = {**ADHESION_WORDS, "approaches": "--delta"}


def _maps_of(args, k, n) -> bool:
    """Whether step ``k`` of ``n`` gets its maps (network, pressure, flux): every step with
    ``--maps all``, else the first and the last (the maps took ~90 % of a sweep's run time:
    47 s against 4.6 s without figures for 8 steps at 128^2; a user's review, round 2,
    session 29). ``steps.png`` is drawn in any case, none with ``--no-figures``."""
    return not args.no_figures and (args.maps == "all" or k in (0, n - 1))


def _units(steps, fsi: bool = False) -> dict:
    """results.json ``units``: the unit of every step key (:func:`record_units`; with
    ``fsi`` the solid's keys as :data:`FSI_UNITS` says)."""
    from ..leakage.analysis import record_units
    units = record_units(dict.fromkeys(k for s in steps for k in s))
    if fsi:
        units.update({k: v for k, v in FSI_UNITS.items() if k in units})
    return units


def _leak_run(args, surface, material, out):
    """Solve and write every file of ``roughfe leak`` into ``out``; results.json last."""
    from ..leakage import leakage_sweep
    from ..plotting import leakage as figs
    from ..theory import beside

    p_in, p_out = _fluid_pressures(args)
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
            "pressure": args.pressure, "detrend": args.detrend,
            "hardness": physics["hardness"], "unload": physics["unload"],
            "adhesion": physics["adhesion"] and physics["adhesion"].describe(),
            "units": "SI (m, Pa, Pa s, m^3/s)"}
    if physics["adhesion"] is not None:  # the process zone against the grid (provenance)
        from ..bem.adhesion import cell_compliance
        base["adhesion_resolution"] = resolution(
            physics["adhesion"], material.E_star, surface.spacing,
            cell_compliance(surface, material.E_star), cell_relief(surface.heights))
    if args.fsi:
        if physics["adhesion"] is not None or physics["hardness"] is not None \
                or physics["unload"]:
            raise InputError("--fsi couples the elastic, non-adhesive contact: --adhesion, "
                             "--hardness and --unload apply without --fsi")
        sweep, steps, written = _leak_fsi(args, surface, material, out, p_in, p_out)
        base["references"] = list(sweep.results[0].references)
        # Persson's theory at the solid's (effective) mean pressure of each coupled step
        theory = beside(surface, material.E_star, steps,
                        pressure_drop=abs(p_in - p_out) or None, viscosity=args.mu,
                        direction=args.direction)
        steps = theory["steps"]
        if not args.no_figures:     # with Persson's leak rate beside the coupled one
            written.append(figs.steps_figure(steps, out / "figures" / "steps.png"))
        written.append(write_json(out / "results.json", {
            "inputs": base, "steps": steps, "units": _units(steps, fsi=True),
            "persson": theory["persson"]}))
        return sweep, steps, written, theory["persson"]
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
        written.append(_save_fields(out / "fields" / f"step_{k:03d}.npz", c, lk, surface))
        if not _maps_of(args, k, len(sweep.contacts)):
            continue
        tag = f"step {k}: A*={c.area_fraction:.3f}, p={c.mean_pressure:.3g} Pa"
        widest = np.zeros(c.gap.shape, bool)
        for con in lk.constrictions.values():
            widest[con.path[:, 0], con.path[:, 1]] = True
        written.append(figs.network_map(
            c.gap, lk.network.percolating, lk.network.trapped, surface.size,
            out / "figures" / f"step_{k:03d}_network.png", sealed=lk.network.sealed,
            title=f"free-volume network, {tag}",
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
    written.append(write_json(out / "results.json", {
        "inputs": inputs, "steps": steps, "units": _units(steps),
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
    _add_fluid_material(p)
    add_contact_physics_options(p, unload_help=(
        "after loading, the same approaches/pressures in reverse (with --hardness the "
        "plastic displacement stays; with --adhesion until the surfaces separate); the "
        "leakage of every step"))
    _add_coupling_options(p)
    add_output_folder(p)
    add_run_options(p)
    p.add_argument("--maps", choices=("ends", "all"), default="ends",
                   help="the per-step maps (network, pressure, flux) of the first and the "
                        "last step (ends) or of every step (all: about 1 s per map); "
                        "figures/steps.png draws every step in any case")
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
    _add_fluid_material(s, fsi=False)
    add_runner_options(s)
    s.add_argument("-o", "--output", required=True, metavar="OUTDIR",
                   help="study folder (rerun the same command to resume)")
    add_run_options(s)
    s.set_defaults(func=_leak_study)
