"""``roughfe contact SURFACE --E .. --nu .. (--steps N | --pressure P .. | --delta D ..) -o DIR``

Runs one warm-started BEM contact sweep (:func:`roughfe.bem.contact_sweep`) and writes
``results.json``, ``fields.h5`` and the figures (A(p), K(p); a 3D render of the last
step for surfaces, a profile plot for profiles).
"""
from __future__ import annotations

from pathlib import Path

from ..bem import KERNELS, Material, contact_sweep
from ..bem.contact import SOLVERS
from ..bem.output import write_fields_h5, write_results_json
from .common import add_surface_options, surface_from_args


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "contact", help="BEM contact sweep of a rough surface: A(p), K(p), gap, free volume",
        description="Frictionless normal contact of a rigid rough surface on an elastic "
                    "half-space (thesis Sec. 2.2). Writes OUTDIR/results.json, "
                    "OUTDIR/fields.h5 and figures. SI units.")
    add_surface_options(p)
    mat = p.add_argument_group("material")
    mat.add_argument("--E", type=float, required=True, help="Young's modulus (Pa)")
    mat.add_argument("--nu", type=float, required=True, help="Poisson's ratio, in (-1, 0.5]")
    load = p.add_argument_group("loading (one of)").add_mutually_exclusive_group()
    load.add_argument("--steps", type=int, default=None,
                      help="N equispaced approaches up to the peak-to-valley height (up to "
                           "full contact for periodic surfaces); default 20")
    load.add_argument("--pressure", type=float, nargs="+", metavar="P",
                      help="mean pressures (Pa), solved in the order given")
    load.add_argument("--delta", type=float, nargs="+", metavar="D",
                      help="approaches from first contact (m), solved in the order given")
    num = p.add_argument_group("numerics")
    num.add_argument("--kernel", default="auto", choices=("auto",) + KERNELS,
                     help="influence operator (default: spectral if periodic, else strip "
                          "for profiles and love for surfaces; 'thesis' = Eq. 2.4)")
    num.add_argument("--solver", default="auto", choices=SOLVERS,
                     help="dense pivoting, scipy NNLS, or matrix-free Polonsky-Keer PCG")
    num.add_argument("--tol", type=float, default=1e-10, help="relative KKT residual")
    p.add_argument("-o", "--output", required=True, metavar="OUTDIR", help="output folder")
    p.add_argument("--no-figures", action="store_true", help="skip the figures")
    p.set_defaults(func=_run)


def _run(args) -> int:
    surface = surface_from_args(args)
    material = Material(args.E, args.nu)
    sweep = contact_sweep(surface, material, n_steps=args.steps or 20, deltas=args.delta,
                          pressures=args.pressure, kernel=args.kernel, solver=args.solver,
                          tol=args.tol)
    out = Path(args.output)
    r0 = sweep.results[0]
    inputs = {"surface": str(args.surface), "shape": list(surface.shape),
              "size": list(surface.size), "periodic": surface.periodic,
              "E": material.E, "nu": material.nu, "E_star": material.E_star,
              "kernel": r0.kernel, "solver": r0.solver, "tol": args.tol,
              "control": "pressure" if args.pressure else "delta",
              "metadata": dict(surface.metadata)}
    write_results_json(out / "results.json", sweep, inputs)
    write_fields_h5(out / "fields.h5", sweep)
    if not args.no_figures:
        from ..plotting.contact import plot_area_stiffness, plot_profile_state, render_contact
        plot_area_stiffness(sweep.to_records(), out / "contact_area_stiffness.png",
                            title=f"{Path(args.surface).name}, E* = {material.E_star:.4g} Pa")
        last = sweep.results[-1]
        if surface.ndim == 2:
            render_contact(surface.heights, last, out / "contact_render.png",
                           title=Path(args.surface).name)
        else:
            plot_profile_state(surface.heights, last, out / "contact_profile.png",
                               title=Path(args.surface).name)
    print(f"{'delta (m)':>12s} {'p (Pa)':>12s} {'A*':>8s} {'K (Pa/m)':>12s} {'gap (m)':>12s} "
          f"{'nit':>5s}")
    for s in sweep.to_records():
        k = s["stiffness"] if s["stiffness"] is not None else float("inf")
        print(f"{s['delta']:12.4e} {s['mean_pressure']:12.4e} {s['area_fraction']:8.4f} "
              f"{k:12.4e} {s['mean_gap']:12.4e} {s['iterations']:5d}")
    print(f"wrote {out / 'results.json'}, {out / 'fields.h5'}")
    return 0
