"""The options of ``roughfe contact``: the surface, material, loading, contact physics and
numerics flags (:func:`add_contact_arguments`), and their translation into the keywords of
:func:`roughfe.response.response` (:func:`method_options`) and back (:func:`in_flags`: the
solver's messages said in this command's flags)."""
from __future__ import annotations

from ..bem import KERNELS
from ..bem.contact import SOLVERS
from ..errors import InputError
from ..model import Loading
from .contact_grid import add_grid_check_option
from .options import (add_contact_physics_options, add_detrend_option, add_material_options,
                      add_output_folder, add_run_options, add_surface_options,
                      nonnegative_int, positive_float, positive_int, unit_fraction)

DEFAULT_STEPS = Loading.DEFAULT_STEPS
#: --coarse-correction -> solve_contact(coarse_correction=)
COARSE = {"auto": None, "on": True, "off": False}


def add_contact_arguments(p) -> None:
    """The arguments of ``roughfe contact`` on its parser ``p``."""
    add_surface_options(p)
    add_detrend_option(p)
    p.add_argument("--mirror", action="store_true",
                   help="solve the evenly mirrored window (2 (n - 1) points per axis, "
                        "periodic: Surface.mirrored) instead of the non-periodic window "
                        "itself: K is then the interface stiffness of the mirrored "
                        "periodic surface, without the window's bulk (flat-punch) "
                        "compliance that dominates K of a measured window; 4x the points "
                        "of a surface. A non-periodic SURFACE only; after --detrend")
    add_material_options(p)
    load = p.add_argument_group("loading (one of; default --steps 20)").add_mutually_exclusive_group()
    load.add_argument("--steps", type=positive_int, default=None, metavar="N",
                      help=f"N equispaced approaches k/N (k = 1..N) of the peak-to-valley "
                           f"height, on a periodic surface of max h - mean h (full contact); "
                           f"with --adhesion on a periodic surface k/(N+1) of max h - mean h "
                           f"(full contact left out: the adhesive state is not defined by "
                           f"the approach there); {DEFAULT_STEPS} if no loading is given")
    load.add_argument("--pressure", type=positive_float, nargs="+", metavar="P",
                      help="mean pressures (Pa), solved in the order given")
    load.add_argument("--delta", type=float, nargs="+", metavar="D",
                      help="approaches from first contact (m), solved in the order given; "
                           "with --adhesion strictly increasing (the loading branch; "
                           "--unload traces the unloading one)")
    add_contact_physics_options(p)
    p.add_argument("--max-unload-steps", type=nonnegative_int, default=None, metavar="N",
                   help="with --adhesion --unload: at most N solves beyond the loading "
                        "range while tracing the unloading branch to separation (default "
                        "4 x the loading steps; the steps grow once the load recovers)")
    num = p.add_argument_group("numerics")
    num.add_argument("--method", default="bem", choices=("bem", "fem"),
                     help="bem: the boundary-element solver (production); fem: the dolfinx "
                          "plane-strain FEM body meshed by gmsh below a PROFILE (the "
                          "cross-validation solver, slower than the BEM). The FEM "
                          "solves the evenly mirrored profile's problem: compare it with "
                          "the BEM's --mirror. With fem: --steps, --pressure or --delta "
                          "only (no --mirror, --hardness, --adhesion, --unload, --kernel, "
                          "--solver, --coarse-correction, --tol)")
    num.add_argument("--kernel", default="auto", choices=("auto",) + KERNELS,
                     help="influence operator: auto = spectral if periodic, else strip for "
                          "profiles and love for surfaces; 'thesis' = Eq. 2.4")
    num.add_argument("--solver", default="auto", choices=SOLVERS,
                     help="dense pivoting, scipy NNLS, or matrix-free Polonsky-Keer PCG")
    num.add_argument("--coarse-correction", default="auto", choices=tuple(COARSE),
                     help="the two-level correction of the Polonsky-Keer CG (2D "
                          "surfaces: --pressure; --delta on non-periodic surfaces and on "
                          "periodic grids from 256^2 points, there solved through load "
                          "control): auto = from an FFT grid of 1024^2 points "
                          "on (~512^2 points of a non-periodic surface), where the start's "
                          "contact has >= 32 parts (patches plus islands), off for smooth "
                          "geometries, where it buys no iterations")
    num.add_argument("--tol", type=unit_fraction, default=None,
                     help="relative KKT residual at which a load step is converged, in "
                          "(0, 1) (default 1e-10); with --adhesion the traction residual "
                          "(default 1e-5)")
    add_grid_check_option(num)
    add_output_folder(p)
    add_run_options(p)


def method_options(args, tol) -> dict:
    """The solver options of ``response`` for ``--method``: the BEM's from the numerics
    flags; none for the FEM, which refuses the BEM-only flags given (by name)."""
    if args.method == "bem":
        return dict(kernel=args.kernel, solver=args.solver, tol=tol, unload=args.unload,
                    hardness=args.hardness, coarse_correction=COARSE[args.coarse_correction])
    given = [flag for flag, on in (("--mirror", args.mirror),   # the FEM mirrors itself
                                   ("--hardness", args.hardness is not None),
                                   ("--unload", args.unload), ("--grid-check", args.grid_check),
                                   ("--kernel", args.kernel != "auto"),
                                   ("--solver", args.solver != "auto"),
                                   ("--coarse-correction", args.coarse_correction != "auto"),
                                   ("--tol", args.tol is not None)) if on]
    if given:
        raise InputError(f"--method fem does not take {', '.join(given)} (BEM options; the "
                         f"FEM is the frictionless elastic VI of roughfe.fem)")
    return {}


#: the solver's keyword phrases in its InputErrors -> this command's flags
_FLAGS = (("solver='pk'", "--solver pk"), ("solver 'dense'", "--solver dense"),
          ("solver='dense'", "--solver dense"), ("solver='nnls'", "--solver nnls"),
          ("solver 'nnls'", "--solver nnls"),
          ("impose a mean_pressure", "impose a mean pressure (--pressure)"),
          ("unload appends", "--unload appends"),
          ("coarse_correction=True", "--coarse-correction on"),
          ("load control (mean_pressure)", "load control (--pressure)"),
          ("kernel 'spectral'", "--kernel spectral"),
          ("(Surface(..., periodic=True))", "(without --non-periodic)"),
          ("use 'strip'/'love' otherwise", "use --kernel strip/love otherwise"),
          ("(response(..., adhesion=law))", "(--adhesion)"), ("deltas[", "--delta["))


def in_flags(message: str) -> str:
    """``message`` (a solver's InputError) with its keyword phrases in this command's flags."""
    for phrase, flag in _FLAGS:
        message = message.replace(phrase, flag)
    return message
