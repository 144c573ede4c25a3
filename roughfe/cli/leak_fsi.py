"""``roughfe leak --fsi``: the two-way coupled sweep of :mod:`roughfe.leakage.fsi_sweep`
(the fluid pressure loads the body; ``--pressure`` is the external pressure), its options,
files and table. The one-way command is :mod:`roughfe.cli.leak_cmd`."""
from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..writers import write_json
from .leak_fields import FSI_UNITS, contact_network_arrays, maps_of, network_figure, \
    step_units, write_step_npz
from .options import fmt_or_dash


def _coupled_sweep(args, surface, material, out, p_in, p_out):
    """The coupled sweep, its fields and maps (``steps.png`` is drawn by the caller, after
    Persson's theory is added to the steps; results.json last)."""
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
            arrays.update(contact_network_arrays(r.contact, lk), flux=r.flow.flux)
        path = write_step_npz(out / "fields" / f"step_{k:03d}.npz", arrays, surface,
                              units=FSI_UNITS)
        written.append(path)
        if not maps_of(args, k, len(sweep.results)) or r.contact is None:
            continue
        tag = (f"step {k}: p_ext={r.external_pressure:.3g} Pa, A*={r.contact.area_fraction:.3f}, "
               f"fluid load {r.fluid_load_fraction:.3f}")
        written.append(network_figure(r.contact, lk, surface,
                                      out / "figures" / f"step_{k:03d}_network.png",
                                      title=f"coupled free-volume network, {tag}"))
        written.append(figs.pressure_map(   # contact cells grey, as on the one-way maps
            np.where(r.contact.contact, np.nan, r.fluid_pressure), surface.size,
            out / "figures" / f"step_{k:03d}_fluid_pressure.png",
            title=f"fluid pressure (Pa), two-way coupled, contact grey\n{tag}", at="cells",
            clim=(min(p_in, p_out), max(p_in, p_out))))     # pockets above: magenta
    return sweep, steps, written


def run_coupled(args, surface, material, out, base, physics, p_in, p_out):
    """Solve and write every file of ``roughfe leak --fsi`` into ``out`` (``base``: the
    inputs of results.json); results.json last. Returns (sweep, steps, written files,
    Persson's theory)."""
    from ..plotting import leakage as figs
    from ..theory import beside

    if physics["adhesion"] is not None or physics["hardness"] is not None \
            or physics["unload"]:
        raise InputError("--fsi couples the elastic, non-adhesive contact: --adhesion, "
                         "--hardness and --unload apply without --fsi")
    sweep, steps, written = _coupled_sweep(args, surface, material, out, p_in, p_out)
    base["references"] = list(sweep.results[0].references)
    # Persson's theory at the solid's (effective) mean pressure of each coupled step
    theory = beside(surface, material.E_star, steps,
                    pressure_drop=abs(p_in - p_out) or None, viscosity=args.mu,
                    direction=args.direction)
    steps = theory["steps"]
    if not args.no_figures:     # with Persson's leak rate beside the coupled one
        written.append(figs.steps_figure(steps, out / "figures" / "steps.png"))
    written.append(write_json(out / "results.json", {
        "inputs": base, "steps": steps, "units": step_units(steps, fsi=True),
        "persson": theory["persson"]}))
    return sweep, steps, written, theory["persson"]


def print_coupled(steps, volume_head, volume_cells, volume_note):
    """The table of ``roughfe leak --fsi`` (the free-volume columns as the one-way table's)
    and the line on lift-off."""
    print(f"{'step':>4} {'p_ext (Pa)':>11} {'state':>8} {'A*':>8} {volume_head} "
          f"{'fluid':>6} {'trap':>6} {'iter':>5} "
          f"{'Q (m^3/s)':>11} {'Q one-way':>11} {'u_c (m)':>10}")
    for s in steps:
        print(f"{s['step']:>4} {s['external_pressure']:>11.4g} {s['fsi_state']:>8} "
              f"{fmt_or_dash(s.get('area_fraction'), '.3g'):>8} {volume_cells(s)} "
              f"{s['fluid_load_fraction']:>6.3f} {s['trapped_load_fraction']:>6.3f} "
              f"{s['coupled_iterations']:>5} {fmt_or_dash(s['leak_rate'], '.4e'):>11} "
              f"{fmt_or_dash(s['leak_rate_one_way'], '.4e'):>11} "
              f"{fmt_or_dash(s.get('critical_gap'), '.3e'):>10}")
    print(volume_note + "; fluid, trap: the external load's share carried by the fluid "
          "and by its trapped pockets")
    lifted = [f"{s['external_pressure']:.4g}" for s in steps if s["fsi_state"] == "lift-off"]
    if lifted:      # said on the table's '-' (a seals review: nothing explained it)
        print(f"lift-off at p_ext = {', '.join(lifted)} Pa: the fluid pressure alone "
              f"carries the external load, the surfaces separate and the seal is open "
              f"(no contact; no finite leak rate of this model)")
