"""``roughfe contact SURFACE --E .. --nu .. (--steps N | --pressure P .. | --delta D ..) -o DIR``

Runs one warm-started BEM contact sweep (:func:`roughfe.response.response`) and writes
``results.json``, ``fields.h5`` and the figures (A(p), K(p), mean gap, with Persson's
theory beside the BEM curves; a 3D render of the last step for surfaces, a profile plot
for profiles). Each step record carries ``persson_area_fraction``, ``persson_mean_gap``
and ``persson_stiffness`` (:func:`roughfe.theory.beside`), except with ``--adhesion``: the
theory is non-adhesive, so an adhesive run has none (``derived.persson`` says so); with
``--hardness`` the theory is elastic, so from the first step with plastic flow on the
values are None (``derived.persson`` says so and lists those steps). ``--mirror`` solves
the evenly mirrored window of a non-periodic surface (:meth:`Surface.mirrored`) as a
periodic one: a measured window's K is otherwise mostly its bulk compliance
(``derived.window_compliance``). An instrument file with a trace and a retrace channel
gets a ``note:`` line on their reliability cutoff and ``inputs.reliability``
(:mod:`roughfe.cli.info_reliability`).

The options are :mod:`roughfe.cli.contact_options`, the files
:mod:`roughfe.cli.contact_files`, the printed table :mod:`roughfe.cli.contact_table` and
the demo's section :mod:`roughfe.cli.contact_demo`.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import InputError
from ..model import Loading
from ..response import response
from ..theory import pastewka_robbins
from ..writers import write_json
from .contact_demo import section_contact  # noqa: F401  (its name before the split)
from .contact_files import contact_document, write_contact_files
from .contact_files import shown_step as _shown_step  # noqa: F401  (its name before the split)
from .contact_grid import grid_check_of_args
from .contact_options import DEFAULT_STEPS, add_contact_arguments, in_flags, method_options
from .contact_table import print_summary
from .info_reliability import print_reliability_note, reliability_block
from .options import (ADHESION_WORDS, contact_physics_from_args, material_from_args,
                      mirrored_if_asked, output_folder_of, surface_from_args)
from .plausibility import check_load_magnitudes, check_solution


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "contact", help="BEM contact sweep of a rough surface: A(p), K(p), gap, free volume",
        description="Frictionless normal contact of a rigid rough surface on an elastic "
                    "half-space (thesis Sec. 2.2), warm-started from load to load. Writes "
                    "OUTDIR/fields.h5 (pressure, gap, contact per step), the figures and, "
                    "last, OUTDIR/results.json (inputs and one record per step). SI units.")
    add_contact_arguments(p)
    p.set_defaults(func=_run)


def _run(args) -> int:
    read = surface_from_args(args)                      # detrended, before --mirror
    surface = mirrored_if_asked(args, read)
    material = material_from_args(args)
    check_load_magnitudes(surface, material, args.pressure, args.delta)
    law = contact_physics_from_args(args)["adhesion"]
    folder = output_folder_of(args, "contact")  # checked now, taken when writing
    adhesive = maugis = stickiness = None
    tol = args.tol if args.tol is not None else (1e-10 if law is None else 1e-5)
    if args.max_unload_steps is not None and (law is None or not args.unload):
        raise InputError("--max-unload-steps bounds the adhesive unloading branch: it needs "
                         "--adhesion and --unload")
    if args.method == "fem" and law is not None:
        raise InputError("--method fem has no adhesion (--adhesion is the BEM's)")
    if law is None:
        loading = (Loading(pressures=args.pressure) if args.pressure else
                   Loading(deltas=args.delta) if args.delta else
                   Loading(n_steps=args.steps or DEFAULT_STEPS))
        options = method_options(args, tol)
        try:
            sweep = response(surface, material, loading, method=args.method, **options)
        except InputError as exc:      # the solver's rules, said in this command's flags
            raise InputError(in_flags(str(exc))) from None
    else:
        adhesive = _adhesive_sweep(args, surface, material, law, tol)
        sweep = adhesive.sweep
    check_solution(args, surface, sweep.results, material)
    grid = grid_check_of_args(args, surface, material, sweep, law, tol,
                              options if law is None else {})
    r0 = sweep.results[0]
    inputs = {"surface": str(args.surface),
              "E": material.E, "nu": material.nu, "E_star": material.E_star,
              "method": args.method, "kernel": r0.kernel, "solver": r0.solver,
              "tol": tol if args.method == "bem" else None,
              "coarse_correction": args.coarse_correction,
              "control": "pressure" if args.pressure else "delta",
              "hardness": args.hardness, "unload": args.unload,
              "detrend": args.detrend, "mirror": args.mirror, "grid_check": args.grid_check,
              "metadata": dict(surface.metadata),
              "reliability": reliability_block(args, read)}   # trace vs retrace, or None
    doc = contact_document(sweep, surface, material, inputs, adhesive=adhesive is not None)
    if grid is not None:
        doc["derived"]["grid_check"] = grid.describe()
    if adhesive is not None:
        doc["inputs"]["adhesion"] = law.describe()
        doc["derived"]["pull_off_force"] = adhesive.pull_off_force
        doc["derived"]["pull_off_pressure"] = adhesive.pull_off_pressure
        doc["derived"]["detached"] = adhesive.detached
        doc["derived"]["units"]["pull_off_force"] = "N (surface) or N/m (profile)"
        # the process zone against the grid (the ResolutionWarning's numbers, kept)
        doc["derived"]["resolution"] = adhesive.resolution
        doc["derived"]["units"].update(process_zone="m", grid_spacing="m")
        cap = doc["derived"]["persson"].get("single_asperity")
        try:
            if cap is not None:     # a random-roughness criterion, like Persson's theory
                raise InputError(f"one smooth asperity ({cap['shape']}): the criterion is "
                                 f"that of a random rough surface")
            stickiness = pastewka_robbins(surface, material.E_star, law.work, law.range)
            doc["derived"]["stickiness"] = stickiness.describe()
        except InputError as exc:   # e.g. a 2 x N strip: no curvature; the solve stands
            stickiness = None       # (it raised after the solve and wrote nothing)
            doc["derived"]["stickiness"] = {"theory": "Pastewka-Robbins (2014)",
                                            "evaluated": False, "why": str(exc)}
        maugis = _maugis_sphere(cap, law, material)
        if maugis is not None:
            doc["derived"]["maugis_sphere"] = maugis
    name = Path(args.surface).name + (" (mirrored)" if args.mirror else "")
    with folder as out:
        written = write_contact_files(out, sweep, doc, surface, material, name=name,
                                      method=args.method, figures=not args.no_figures,
                                      adhesive=adhesive, law=law, maugis=maugis)
        write_json(out / "results.json", doc)  # last: the run is complete
    print_summary(args, surface, material, sweep, doc, grid, adhesive=adhesive,
                  maugis=maugis, stickiness=stickiness)
    print_reliability_note(inputs["reliability"], read,
                           "contact area, its patches and the gaps")
    print(f"wrote {', '.join(str(w) for w in written)}")
    return 0


def _maugis_sphere(cap, law, material):
    """Maugis' pull-off (load control; Maugis 1992) of a Maugis-Dugdale ``law`` on a
    sphere ``cap`` (:func:`roughfe.theory.asperity.single_asperity`), else None."""
    if cap is None or cap["shape"] != "sphere" or law.kind != "md":
        return None
    from ..reference import maugis_parameter, maugis_pull_off
    lam = maugis_parameter(cap["radius"], material.E_star, law.work, law.max_traction)
    force = maugis_pull_off(lam) * np.pi * law.work * cap["radius"]
    return {"lambda": lam, "radius": cap["radius"], "pull_off_force": force,
            "note": "Maugis (1992) sphere, load control, sharp Dugdale step: the theory "
                    "of this contact (a grid of few cells per Dugdale zone reads a "
                    "more tensile pull-off; docs/theory/07)"}


def _adhesive_sweep(args, surface, material, law, tol):
    """The adhesive continuation in the approach (``--delta`` or ``--steps``)."""
    from ..bem.adhesion import adhesive_sweep
    from ..bem.adhesive_rules import check_adhesive_run

    check_adhesive_run(solver=args.solver, coarse_correction=(
        None if args.coarse_correction == "auto" else args.coarse_correction),
        pressure_control=args.pressure is not None, words=ADHESION_WORDS)
    return adhesive_sweep(surface, material, law, args.delta,
                          n_steps=None if args.delta else args.steps,
                          unload=args.unload, kernel=args.kernel, tol=tol,
                          max_unload_steps=args.max_unload_steps)

