"""The options of ``roughfe leak`` and ``roughfe leak-study``: the fluid (viscosity,
pressure drop, direction; their ranges), the fluid-structure coupling, and the (p_in, p_out)
they give."""
from __future__ import annotations

from ..errors import InputError
from .options import _check, add_material_options, positive_float


#: pressure drops (Pa) that --pressure-drop accepts, and the absolute pressures of
#: --inlet-pressure / --outlet-pressure (from 0): three decades beyond the drops across
#: seals (~1 Pa heads to ~1e9 Pa hydraulics), so that dimensionless runs (1) pass. Q is
#: linear in the drop and in 1/mu (the Reynolds solve is scaled, roughfe.leakage.reynolds),
#: so the ranges are no limit of the method; they refuse what is a slip (--pressure-drop
#: 1e308 wrote null leak rates after a lift-off warning, --mu 1e308 a null flow imbalance:
#: round 2, session 34).
PRESSURE_RANGE = (1e-6, 1e12)
#: viscosities (Pa s) that --mu accepts: about three decades beyond the thinnest gas
#: (hydrogen, 9e-6 Pa s) and glass near its transition (~1e12 Pa s)
VISCOSITY_RANGE = (1e-9, 1e15)
pressure_drop_type = _check(float, lambda v: PRESSURE_RANGE[0] <= v <= PRESSURE_RANGE[1],
                            f"a pressure drop from {PRESSURE_RANGE[0]:g} Pa to "
                            f"{PRESSURE_RANGE[1]:g} Pa")
absolute_pressure_type = _check(float, lambda v: 0.0 <= v <= PRESSURE_RANGE[1],
                                f"an absolute pressure from 0 Pa to {PRESSURE_RANGE[1]:g} Pa")
viscosity_type = _check(float, lambda v: VISCOSITY_RANGE[0] <= v <= VISCOSITY_RANGE[1],
                        f"a viscosity from {VISCOSITY_RANGE[0]:g} Pa s to "
                        f"{VISCOSITY_RANGE[1]:g} Pa s")


def add_fluid_material(p, fsi=True):
    """The material (elastic body) and the option group "fluid" of ``leak`` and
    ``leak-study``."""
    add_material_options(p, "material (elastic body against the rigid surface)")
    fl = p.add_argument_group("fluid")
    fl.add_argument("--mu", type=viscosity_type, default=1.0e-3,
                    help=f"dynamic viscosity in Pa s (1e-3: water), {VISCOSITY_RANGE[0]:g} "
                         f"to {VISCOSITY_RANGE[1]:g}")
    fl.add_argument("--pressure-drop", type=pressure_drop_type, default=None,
                    help=f"fluid pressure drop p_in - p_out in Pa, {PRESSURE_RANGE[0]:g} to "
                         f"{PRESSURE_RANGE[1]:g} (Q is linear in it; default 1"
                         + ("; with --fsi: p_in = DP, p_out = 0)" if fsi else ")"))
    fl.add_argument("--direction", choices=("x", "y", "both"), default="both",
                    help="flow direction(s); the percolating volume is their union")
    fl.add_argument("--no-reynolds", action="store_true",
                    help="network analysis only (skip the Reynolds solve)")


def fluid_pressures(args):
    """(p_in, p_out) from --inlet/--outlet-pressure or --pressure-drop (one-line errors)."""
    given = (args.inlet_pressure is not None, args.outlet_pressure is not None)
    if any(given) and args.pressure_drop is not None:
        raise InputError("give either --pressure-drop or --inlet-pressure and "
                         "--outlet-pressure, not both")
    if any(given) and not all(given):
        raise InputError("--inlet-pressure and --outlet-pressure go together (absolute Pa)")
    if all(given):
        p_in, p_out = float(args.inlet_pressure), float(args.outlet_pressure)
        if not args.fsi and p_in <= p_out:
            raise InputError(f"--inlet-pressure {p_in:g} Pa must exceed --outlet-pressure "
                             f"{p_out:g} Pa (reversed flow is solved with --fsi only)")
        return p_in, p_out
    dp = 1.0 if args.pressure_drop is None else float(args.pressure_drop)
    return dp, 0.0


def add_coupling_options(p):
    """The option group "fluid-structure coupling" of ``roughfe leak``."""
    fs = p.add_argument_group("fluid-structure coupling")
    fs.add_argument("--fsi", action="store_true",
                    help="two-way coupling: the fluid pressure loads the body; --pressure is "
                         "the external pressure (contact + fluid); one flow direction")
    fs.add_argument("--inlet-pressure", type=absolute_pressure_type, default=None,
                    metavar="PI",
                    help=f"absolute inlet pressure in Pa, 0 to {PRESSURE_RANGE[1]:g} (with "
                         f"--outlet-pressure; instead of --pressure-drop; PI < PO reverses "
                         f"the flow with --fsi)")
    fs.add_argument("--outlet-pressure", type=absolute_pressure_type, default=None,
                    metavar="PO",
                    help=f"absolute outlet pressure in Pa, 0 to {PRESSURE_RANGE[1]:g}")
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
