"""One smooth asperity (a sphere or cylinder cap, e.g. ``roughfe.surfaces.sphere_cap``):
where Persson's random-roughness theory does not apply and Hertz's does (SI).

Persson's theory takes a random (Gaussian) surface of many asperities, described by its
PSD. The PSD of one smooth cap is that of its window's edges and says nothing of the
contact: on a sphere (R = 1 m, 64^2 over 0.21 m, E* = 1 Pa, approaches 0.2-4 mm) the
theory's A* was 0.10-0.47 of the BEM's, drawn beside it as a prediction (round 2,
session 32), where Hertz's is within 1-4 % of the BEM's (K within 2 %).
:func:`single_asperity` recognises such a surface by a quadric fit of its heights;
:func:`beside_hertz` gives Hertz's contact area and stiffness at each step's load in its
place (Hertz 1882; Johnson 1985, Sec. 4.2), the single-asperity theory of a non-adhesive
contact. For an adhesive sphere the Maugis-Dugdale pull-off is
:func:`roughfe.reference.maugis_pull_off`.
"""
from __future__ import annotations

import numpy as np

from ..reference import hertz_cylinder, hertz_sphere

#: a non-periodic surface whose heights a quadric (an elliptic paraboloid with a summit,
#: or a parabola for a profile) fits to this fraction of their variance or better is one
#: smooth asperity (of the variance the plane leaves: sphere_cap 1 to round-off; the five
#: measured files, plu-1.plu 0.011, and a self-affine window have no summit or < 0.02)
QUADRIC_FIT = 0.99
#: principal radii within this ratio are a sphere of radius sqrt(R1 R2) (Hertz's
#: equivalent radius of a slightly elliptic contact); beyond it no Hertz line is drawn
ROUND = 1.1
#: the cap fit samples at most this many points per axis (every step-th point)
FIT_POINTS = 256

REFERENCES = ("Hertz H. (1882) J. reine angew. Math. 92:156-171",
              "Johnson K.L. (1985) Contact Mechanics, Cambridge University Press, Sec. 4.2")

#: the ``persson`` block of a single asperity: no step carries ``persson_*`` values
NOT_RANDOM = {
    "theory": "not applicable: one smooth asperity",
    "note": "Persson's theory is that of a random rough surface of many asperities, from "
            "its PSD; this surface is one smooth cap (single_asperity), whose contact is "
            "Hertz's (hertz_* keys of the steps) and, with adhesion, Maugis' or JKR's, so "
            "no step carries persson_* values (docs/theory/07_adhesion_persson.md)",
}


def single_asperity(surface):
    """The shape of ``surface`` when it is one smooth cap, else None.

    A non-periodic surface (profile) whose heights a quadric with a summit (both
    principal curvatures negative) fits to :data:`QUADRIC_FIT` of the variance that
    their least-squares plane leaves (a tilted measured file is mostly its plane).
    Returns ``{"shape": "sphere" | "ellipsoid" | "cylinder", "radius": R (m; sqrt(R1 R2)
    for a surface, None for an ellipsoid beyond :data:`ROUND`), "radii": [R1, R2] (m),
    "fit": the explained fraction of the variance, "summit_gap": the fitted cap's summit
    above the highest grid point (m; ``sphere_cap``: dx^2 / (4 R), its summit between
    four points)}``."""
    if surface.periodic or min(surface.shape) < 3 or not np.ptp(surface.heights) > 0:
        return None
    # the fit on every step-th point per axis (at most FIT_POINTS per axis): a quadric
    # needs few points, and the full grid's design matrix would be 6 n^2 doubles
    step = [max(1, -(-n // FIT_POINTS)) for n in surface.shape]
    h = np.asarray(surface.heights[tuple(slice(None, None, s) for s in step)], float)
    axes = [(np.arange(0, n, s) - (n - 1) / 2) * d
            for n, s, d in zip(surface.shape, step, surface.spacing)]
    h = h.ravel()
    x = [g.ravel() for g in np.meshgrid(*axes, indexing="ij")]
    if surface.ndim == 1:
        cols = [np.ones_like(x[0]), x[0], x[0] ** 2]
    else:
        cols = [np.ones_like(x[0]), x[0], x[1], x[0] ** 2, x[0] * x[1], x[1] ** 2]
    a = np.column_stack(cols)
    coef, *_ = np.linalg.lstsq(a, h, rcond=None)
    plane = a[:, :surface.ndim + 1]          # of what a plane leaves (a tilted file's
    rest = h - plane @ np.linalg.lstsq(plane, h, rcond=None)[0]    # fit is its tilt)
    fit = 1.0 - float(np.var(h - a @ coef)) / max(float(np.var(rest)), 1e-300)
    hess = (np.array([[2 * coef[2]]]) if surface.ndim == 1 else
            np.array([[2 * coef[3], coef[4]], [coef[4], 2 * coef[5]]]))
    curv = np.linalg.eigvalsh(hess)
    if fit < QUADRIC_FIT or not np.all(curv < 0):
        return None
    radii = sorted(float(-1 / k) for k in curv)
    # the quadric's summit c0 + g.x*/2 (x* = -hess^-1 g) above the highest grid point: the
    # BEM counts the approach from that point, Hertz from the summit
    g = coef[1:surface.ndim + 1]
    gap = float(coef[0] - 0.5 * g @ np.linalg.solve(hess, g) - surface.heights.max())
    if surface.ndim == 1:
        return {"shape": "cylinder", "radius": radii[0], "radii": radii, "fit": fit,
                "summit_gap": gap}
    round_ = radii[1] <= ROUND * radii[0]
    return {"shape": "sphere" if round_ else "ellipsoid",
            "radius": float(np.sqrt(radii[0] * radii[1])) if round_ else None,
            "radii": radii, "fit": fit, "summit_gap": gap}


def beside_hertz(surface, shape, e_star, pressures):
    """Hertz's ``hertz_area_fraction`` (-) and ``hertz_stiffness`` (dp/dDelta, Pa/m;
    None for the cylinder, whose half-plane approach has no reference) at each mean
    pressure (Pa) of ``pressures`` on the nominal area of ``surface``, for the ``shape``
    of :func:`single_asperity`; None where p is not a positive number, where the
    contact does not fit in the window (2a > its shortest side) or for an ellipsoid."""
    out = []
    side, area = min(surface.size), surface.nominal_area
    for p in pressures:
        rec = {"hertz_area_fraction": None, "hertz_stiffness": None}
        if (p is not None and np.isfinite(p) and p > 0 and shape["radius"] is not None):
            if shape["shape"] == "cylinder":
                a = hertz_cylinder(shape["radius"], e_star, p * area).contact_radius
                fits, fraction, k = 2 * a <= side, 2 * a / side, None
            else:
                sol = hertz_sphere(shape["radius"], e_star, load=p * area)
                a = sol.contact_radius
                fits, fraction, k = 2 * a <= side, np.pi * a * a / area, sol.stiffness / area
            if fits:
                rec = {"hertz_area_fraction": float(fraction),
                       "hertz_stiffness": None if k is None else float(k)}
        out.append(rec)
    return out
