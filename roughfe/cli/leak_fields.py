"""The files of ``roughfe leak`` per step: ``fields/step_NNN.npz``, the network map and
the units of results.json (one-way and ``--fsi`` alike; :mod:`roughfe.cli.leak_cmd`,
:mod:`roughfe.cli.leak_fsi`)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..writers import atomic_path

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


def write_step_npz(path, arrays: dict, surface, units=None) -> Path:
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


def contact_network_arrays(contact, leak) -> dict:
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


def save_fields(path, contact, leak, surface):
    """The one-way step's npz: :func:`contact_network_arrays`, the Reynolds pressure and
    flux of each direction."""
    arrays = contact_network_arrays(contact, leak)
    for d, flow in leak.flows.items():
        arrays[f"fluid_pressure_{d}"] = flow.pressure
        arrays[f"flux_{d}"] = flow.flux
    return write_step_npz(path, arrays, surface)


def network_figure(contact, leak, surface, path, title):
    """The step's free-volume network map (:func:`roughfe.plotting.leakage.network_map`)
    with the widest path of each direction and its critical junction; the title says
    which junctions lie at the edge of a non-periodic window (``at_edge``)."""
    from ..plotting import leakage as figs
    edge = [d for d, con in leak.constrictions.items() if con.at_edge]
    if edge:
        title += (f"\njunction ({', '.join(edge)}) at the window's edge: may be the cut's, "
                  f"not the surface's")
    widest = np.zeros(contact.gap.shape, bool)
    for con in leak.constrictions.values():
        widest[con.path[:, 0], con.path[:, 1]] = True
    return figs.network_map(
        contact.gap, leak.network.percolating, leak.network.trapped, surface.size, path,
        sealed=leak.network.sealed, title=title, widest_path=widest,
        junctions=[con.position for con in leak.constrictions.values()
                   if con.position is not None])


def edge_junction_note(steps):
    """The line that names the steps whose critical junction lies at the edge of a
    non-periodic window (``critical_at_edge_<d>`` of the records), or None."""
    at = [f"{s['step']} ({', '.join(d for d in 'xy' if s.get(f'critical_at_edge_{d}'))})"
          for s in steps if s.get("critical_at_edge_x") or s.get("critical_at_edge_y")]
    if not at:
        return None
    return (f"junction at the window's edge in step{'s' if len(at) > 1 else ''} "
            f"{', '.join(at[:8])}{', ...' if len(at) > 8 else ''}: within one cell of an edge "
            f"of the non-periodic window, the constriction may be the cut's, not the "
            f"surface's (critical_gap, critical_width, leak_rate_critical_junction there are "
            f"the window's; critical_at_edge in results.json)")


def maps_of(args, k, n) -> bool:
    """Whether step ``k`` of ``n`` gets its maps (network, pressure, flux): every step with
    ``--maps all``, else the first and the last (the maps took ~90 % of a sweep's run time:
    47 s against 4.6 s without figures for 8 steps at 128^2; a user's review, round 2,
    session 29). ``steps.png`` is drawn in any case, none with ``--no-figures``."""
    return not args.no_figures and (args.maps == "all" or k in (0, n - 1))


def step_units(steps, fsi: bool = False) -> dict:
    """results.json ``units``: the unit of every step key (:func:`record_units`; with
    ``fsi`` the solid's keys as :data:`FSI_UNITS` says)."""
    from ..leakage.analysis import record_units
    units = record_units(dict.fromkeys(k for s in steps for k in s))
    if fsi:
        units.update({k: v for k, v in FSI_UNITS.items() if k in units})
    return units
