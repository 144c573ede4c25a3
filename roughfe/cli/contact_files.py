"""The files of ``roughfe contact``: results.json's document (:func:`contact_document`, also
the demo's), fields.h5 and the figures (A(p), K(p), mean gap with the theory beside them;
the adhesive load-approach curve; a 3D render of the shown step for surfaces, a profile
plot for profiles)."""
from __future__ import annotations

import numpy as np

from ..bem.output import sweep_document, write_fields_h5
from ..theory import beside


def write_contact_files(out, sweep, doc, surface, material, *, name, method, figures=True,
                        adhesive=None, law=None, maugis=None) -> list:
    """fields.h5 and (``figures``) the figures of a contact sweep in the folder ``out``;
    the paths written, results.json first (:mod:`roughfe.cli.contact_cmd` writes it last,
    when the run is complete)."""
    write_fields_h5(out / "fields.h5", sweep)
    written = [out / "results.json", out / "fields.h5"]
    if figures:
        from ..plotting.contact import (plot_area_stiffness, plot_profile_state,
                                        render_contact)
        plot_area_stiffness(doc["steps"], out / "contact_area_stiffness.png",
                            title=f"{name}, E* = {material.E_star:.4g} Pa",
                            rms_height=sweep.rms_height,
                            window_compliance=doc["derived"].get("window_compliance"),
                            method=method.upper())
        if adhesive is not None:
            from ..plotting.contact import plot_adhesion
            plot_adhesion(doc["steps"], out / "adhesion_load_approach.png",
                          pull_off_force=adhesive.pull_off_force, reference=None if
                          maugis is None else (maugis["pull_off_force"],
                                               "Maugis (1992) sphere"),
                          title=f"{name}, {law.kind}: w = {law.work:.3g} "
                                f"J/m^2, range {law.range:.3g} m")
        last = sweep.results[shown_step(sweep.area_fraction)]
        if surface.ndim == 2:
            render_contact(surface.heights, last, out / "contact_render.png", title=name)
        else:
            plot_profile_state(surface.heights, last, out / "contact_profile.png", title=name)
        written += sorted(out.glob("*.png"))
    return written


def shown_step(area_fraction) -> int:
    """The step the state figure shows: the one of largest contact below full contact
    (a fully flattened periodic surface, the last default step, is a blank plane), the
    last such one; full contact only when every step is (not the detached end of an
    unloading branch)."""
    a = np.asarray(area_fraction)
    partial = np.flatnonzero(a < 1.0)
    pool = partial if partial.size else np.arange(a.size)
    return int(pool[len(pool) - 1 - int(np.argmax(a[pool][::-1]))])


def contact_document(sweep, surface, material, inputs: dict, *, adhesive=False) -> dict:
    """results.json of a contact sweep (the one builder of ``roughfe contact`` and of the
    demo): :func:`~roughfe.bem.output.sweep_document` with the surface's grid in its
    inputs and Persson's theory beside every step (``persson_*`` keys, ``derived.persson``);
    for an ``adhesive`` sweep no step gets the (non-adhesive) theory and
    ``derived.persson`` says so (:data:`roughfe.theory.beside.NOT_ADHESIVE`), nor does a
    step with plastic flow or one after it (:data:`roughfe.theory.beside.NOT_PLASTIC`).
    On one smooth asperity (:func:`roughfe.theory.asperity.single_asperity`) the window
    note is not given: the half-space's deflection is Hertz's own, and K matches his."""
    import warnings

    from ..errors import WindowStiffnessWarning
    from ..theory.asperity import single_asperity
    with warnings.catch_warnings():
        if single_asperity(surface) is not None:
            warnings.simplefilter("ignore", WindowStiffnessWarning)
        doc = sweep_document(sweep, {"surface": inputs.get("surface"),
                                     "shape": list(surface.shape),
                                     "size": list(surface.size),
                                     "periodic": surface.periodic, **inputs})
    theory = beside(surface, material.E_star, doc["steps"], adhesive=adhesive,
                    hardness=inputs.get("hardness"))
    doc["steps"], doc["derived"]["persson"] = theory["steps"], theory["persson"]
    return doc
