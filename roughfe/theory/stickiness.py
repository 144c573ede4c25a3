"""Pastewka-Robbins stickiness criterion of a rough adhesive contact (SI).

Pastewka & Robbins (2014) found in simulations of self-affine surfaces that the
repulsive contact area stays proportional to the load, ``A_rep / A0 = kappa p /
(E* h'_rms)``, and that adhesion changes only the prefactor: ``kappa`` rises with the
adhesive strength and, above a threshold, changes sign through infinity: the surfaces
become *sticky* (contact survives at zero and tensile load, a finite force pulls them
apart). Their mean-field argument, written out here in our notation (own derivation of
the paper's argument; the O(1) constants follow from the Hertzian edge stated below):

1. Repulsive patches carry the mean pressure ``p_rep = h'_rms E* / kappa_rep`` (the
   non-adhesive result; ``kappa_rep`` ~ 2 in BEM simulations, the default here) and
   have the characteristic diameter ``d_rep = 4 h'_rms / h''_rms`` (rms slope over rms
   curvature), half-width ``a = d_rep / 2``.
2. Outside a repulsive patch the gap opens as at the edge of a Hertzian contact with
   that mean pressure (non-adhesive, DMT-like: adhesion does not change the patch),

       g(xi) = c_d (p_rep / E*) xi^(3/2) / sqrt(a),                                    (1)

   xi the distance from the edge; ``c_2 = 2 sqrt(2)`` for a circular patch of a surface
   (the expansion of Hertz's gap for a sphere) and ``c_1 = 16 sqrt(2) / (3 pi)`` for a
   strip of a profile in plane strain (Hertz's cylinder).
3. The attraction (range ``Delta_r``, mean traction ``sigma_0 = w / Delta_r``: exact for
   Maugis-Dugdale, the peak traction for the exponential law) acts where
   ``g < Delta_r``: a ring of width ``d = (Delta_r sqrt(a) / (c_d p_rep / E*))^(2/3)``
   around every patch, whose area per repulsive area is ``n_d d / a`` (perimeter over
   area: ``n_2 = 2`` for a disc, ``n_1 = 1`` for a strip).
4. The load is the repulsive minus the attractive force,
   ``N = N_rep (1 - S)`` with the stickiness number

       S = N_att / N_rep = n_d (sigma_0 / p_rep) (d / a)
         = n_d (kappa_rep l_a / (h'_rms Delta_r)) (kappa_rep Delta_r / (c_d h'_rms a))^(2/3),
                                                                                       (2)

   ``l_a = w / E*``. Hence ``A_rep = kappa_rep / (1 - S) N / (h'_rms E*)``: the prefactor
   rises linearly for weak adhesion, diverges at ``S = 1`` and is negative beyond:
   **sticky if S > 1**. Like the paper's criterion, S depends on the slopes and
   curvatures (the finest scales) and on w, Delta_r and E*, not on h_rms.

Validity (reported): the ring is thin, ``d / a << 1`` (DMT side); for ``d / a`` of order
one the patches are JKR-like and Eq. (1) no longer holds. The criterion is a mean-field
estimate: Ciavarella (2016) and Ciavarella & Papangelo (2018) point out that finite
pull-off forces are found in simulations that it calls non-sticky (see the measured
comparison in docs/theory/07_adhesion_persson.md).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError, check_finite_positive, check_instance
from ..surfaces.stats import rms_curvature, rms_slope
from ..surfaces.surface import Surface

#: Non-adhesive area prefactor of the criterion (Pastewka & Robbins 2014: ~2 in BEM).
KAPPA_REP = 2.0
#: Gap-opening coefficient c_d of Eq. (1) and perimeter-over-area factor n_d, per dimension.
EDGE_COEFFICIENT = {2: 2.0 * np.sqrt(2.0), 1: 16.0 * np.sqrt(2.0) / (3.0 * np.pi)}
PERIMETER_FACTOR = {2: 2.0, 1: 1.0}

REFERENCES = (
    "Pastewka L., Robbins M.O. (2014) Proc. Natl. Acad. Sci. USA 111:3298-3303 "
    "(stickiness criterion)",
    "Ciavarella M. (2016) J. Tribol. 139:031404 (discussion of the criterion)",
)


@dataclass(frozen=True)
class Stickiness:
    """The Pastewka-Robbins criterion of one surface and interface law (SI).

    Attributes
    ----------
    stickiness : float
        S of Eq. (2) (-); sticky if S > 1.
    sticky : bool
        ``S > 1``.
    kappa_ratio : float
        Predicted ``kappa / kappa_rep = 1 / (1 - S)`` (-), negative when sticky.
    rms_slope, rms_curvature : float
        h'_rms (-) and h''_rms (1/m) of the surface.
    contact_diameter : float
        d_rep = 4 h'_rms / h''_rms (m).
    ring_width : float
        Width d of the attractive ring around a repulsive patch (m).
    ring_over_half_width : float
        d / a (-): the criterion assumes d / a << 1.
    repulsive_pressure : float
        p_rep = h'_rms E* / kappa_rep (Pa).
    adhesion_length : float
        l_a = w / E* (m).
    kappa_rep, work, range, e_star : float
        The inputs (-, J/m^2, m, Pa).
    dimension : int
        1 (profile) or 2 (surface).
    """

    stickiness: float
    sticky: bool
    kappa_ratio: float
    rms_slope: float
    rms_curvature: float
    contact_diameter: float
    ring_width: float
    ring_over_half_width: float
    repulsive_pressure: float
    adhesion_length: float
    kappa_rep: float
    work: float
    range: float
    e_star: float
    dimension: int

    def describe(self) -> dict:
        """JSON-safe record (SI) with the references."""
        out = {k: getattr(self, k) for k in self.__dataclass_fields__}
        out["references"] = list(REFERENCES)
        out["units"] = {"rms_curvature": "1/m", "contact_diameter": "m", "ring_width": "m",
                        "repulsive_pressure": "Pa", "adhesion_length": "m",
                        "work": "J/m^2", "range": "m", "e_star": "Pa"}
        return out


def pastewka_robbins(surface: Surface, e_star, work, interaction_range, *,
                     kappa_rep: float = KAPPA_REP) -> Stickiness:
    """Pastewka-Robbins stickiness of ``surface`` against an elastic body (Eq. (2)).

    Parameters
    ----------
    surface : Surface
        Rigid rough surface or profile (heights in m); its rms slope and rms curvature
        (:func:`roughfe.surfaces.stats.rms_slope`, :func:`~roughfe.surfaces.stats.rms_curvature`)
        enter.
    e_star : float
        Contact modulus E* (Pa).
    work : float
        Work of adhesion w (J/m^2).
    interaction_range : float
        Range Delta_r of the attraction (m): h0 of Maugis-Dugdale, rho of the exponential
        law (``AdhesionLaw.range``).
    kappa_rep : float
        Non-adhesive prefactor of A_rep(p) (default 2).

    Returns
    -------
    Stickiness
    """
    check_instance("surface", surface, Surface, "a roughfe Surface")
    e_star = check_finite_positive("E* (Pa)", e_star)
    work = check_finite_positive("work of adhesion w (J/m^2)", work)
    dr = check_finite_positive("range of adhesion (m)", interaction_range)
    kappa_rep = check_finite_positive("kappa_rep", kappa_rep)
    slope, curv = rms_slope(surface), rms_curvature(surface)
    if not (slope > 0 and curv > 0):
        raise InputError(f"the stickiness criterion needs a rough surface (rms slope "
                         f"{slope:.3g}, rms curvature {curv:.3g} 1/m; both must be > 0)")
    dim = surface.ndim
    c, n = EDGE_COEFFICIENT[dim], PERIMETER_FACTOR[dim]
    d_rep = 4.0 * slope / curv
    a = 0.5 * d_rep
    p_rep = slope * e_star / kappa_rep
    ring = (dr * np.sqrt(a) / (c * p_rep / e_star)) ** (2.0 / 3.0)
    s = n * (work / dr) / p_rep * ring / a
    return Stickiness(stickiness=float(s), sticky=bool(s > 1.0),
                      kappa_ratio=float(1.0 / (1.0 - s)) if s != 1.0 else float("inf"),
                      rms_slope=slope, rms_curvature=curv, contact_diameter=float(d_rep),
                      ring_width=float(ring), ring_over_half_width=float(ring / a),
                      repulsive_pressure=float(p_rep), adhesion_length=work / e_star,
                      kappa_rep=kappa_rep, work=work, range=dr, e_star=e_star,
                      dimension=dim)
