"""Persson's theory beside the steps of a simulation (the ``persson_*`` keys of
results.json): A*(p) and u(p) of :mod:`roughfe.theory.persson` and the critical-junction
leak rate of :mod:`roughfe.theory.junction` at each step's mean pressure (SI).

The theory is non-adhesive: its A*(p) and u(p) belong to a repulsive load p. In an
adhesive run the net mean pressure is the repulsive load less the attraction (a tensile
net load can hold a contact of A* = 0.2), so the theory at that load is not a prediction
of the adhesive contact, and ``beside(..., adhesive=True)`` evaluates none
(:data:`NOT_ADHESIVE`; docs/theory/07_adhesion_persson.md).

It is elastic as well: a step with plastic flow (a hardness run, ``plastic_area_fraction``
> 0) and every step after it, on a surface recessed by the plastic displacement (the
unloading branch), are not the elastic contact of the surface's PSD, so those steps get
None and ``"persson"`` says why (:data:`NOT_PLASTIC`). Given the run's ``hardness``, the
steps of the first loading get Persson's elastoplastic areas instead
(:mod:`roughfe.theory.plastic`: the real and the plastic area fraction, measured against
the BEM in docs/theory/07_adhesion_persson.md).

It is the theory of a random surface of many asperities: on one smooth cap (a sphere,
:func:`roughfe.theory.asperity.single_asperity`) no step gets it, the elastic steps get
Hertz's instead (``hertz_*`` keys) and ``"persson"`` says why (:data:`NOT_RANDOM`).

It needs the surface's PSD: a non-periodic surface's is taken with a Hann window, which
is zero on a side of fewer than 3 points, so on such a grid (a 2 x N strip) no step gets
the theory and ``"persson"`` says why (:data:`NOT_EVALUATED`); the simulation's own
results are written as usual."""
from __future__ import annotations

import numbers
from collections.abc import Mapping

import numpy as np

from ..errors import InputError
from ..surfaces.stats import HANN_MIN_POINTS, height_moments
from ..surfaces.surface import Surface
from .asperity import NOT_RANDOM, beside_hertz, single_asperity
from .asperity import REFERENCES as ASPERITY_REFERENCES
from .capped_hertz import beside_capped_hertz
from .junction import _geometry_factor, critical_junction
from .persson import GAMMA_DEFAULT, PERCOLATION_THRESHOLD, REFERENCES, _spectrum, persson
from .plastic import beside_elastoplastic

#: ``"persson"`` of an adhesive run: no step gets ``persson_*`` keys, and this says why
NOT_ADHESIVE = {
    "adhesion": "not in the theory",
    "note": "Persson's A*(p), u(p) and critical junction here are non-adhesive: at the "
            "net (repulsive minus attractive) mean pressure of an adhesive step they are "
            "not a prediction of that contact, so no step carries persson_* values "
            "(docs/theory/07_adhesion_persson.md)",
}

#: added to ``"persson"`` when a step had plastic flow; ``plastic_steps`` lists the steps
#: left without ``persson_*`` values (None)
NOT_PLASTIC = {
    "plasticity": "not in the theory",
    "note": "Persson's A*(p), u(p) and critical junction here are elastic: a step with "
            "plastic flow (plastic_area_fraction > 0), and every step after it (on the "
            "surface recessed by the plastic displacement, e.g. the unloading branch), "
            "is not the elastic contact of this PSD, so its persson_* values are None "
            "(with the run's hardness the first loading's steps carry Persson's "
            "elastoplastic areas, persson_elastoplastic_area_fraction and "
            "persson_plastic_area_fraction; docs/theory/07_adhesion_persson.md)",
}

#: ``plastic_note`` of a single asperity's ``"persson"`` block when a step had plastic flow
HERTZ_NOT_PLASTIC = ("Hertz's contact is elastic: a step with plastic flow and every step "
                     "after it get hertz_* None; a sphere's first loading carries the capped "
                     "Hertz reference instead (capped_hertz_* keys, the capped_hertz block)")


#: ``"persson"`` of a grid whose PSD cannot be taken (``grid`` is added: its shape); no
#: step gets ``persson_*`` keys
NOT_EVALUATED = {
    "theory": "not evaluated on this grid",
    "note": "Persson's theory takes the surface's power spectrum; a non-periodic surface's "
            "is taken with a Hann window, which is zero on a side of fewer than 3 points, "
            "so this grid has none and no step carries persson_* values",
}


#: height distribution beyond which the theory is said not to apply: Persson's theory
#: takes a Gaussian (random-phase) surface of the given PSD, whose skewness is 0 and
#: kurtosis 3. Of the five measured files only sur-2 (plane removed: skewness -15.5,
#: kurtosis 785, about 110 points 10-70 rms deep) is beyond; there the BEM's A* is 3-12x
#: the theory's at 850-85000 Pa (re-measured in round 2, session 32, after its 117
#: non-measured points stopped being read as heights: with them it was 5-19x, skewness
#: -30), and plu-1 (kurtosis 9.2) the next.
NON_GAUSSIAN = {"skewness": 2.0, "kurtosis": 20.0}

#: texture aspect ratio Str (ISO 25178-2, :mod:`roughfe.surfaces.texture`) below which a
#: surface is said to have a lay that the theory's isotropic PSD misses. Isotropic
#: self-affine windows (H 0.3 and 0.8, 32^2-256^2, periodic and not, 160 per grid) had
#: Str 0.197-0.26 at the lowest (a window's few long waves align by chance), median
#: 0.45-0.61; measured lays are below: x3p-2 (machined) 0.026 (0.079 on a 256^2 crop,
#: 0.12 on 64^2), where Persson's leak rate fell 10^5-10^6 x below the Reynolds rate along
#: the grooves at 3 GPa (a seals review, round 2, session 31), and plu-1 with its plane
#: removed 0.105, sealed across its lay and open along it at A* 0.23. (ISO calls Str < 0.3
#: strongly directional: too many isotropic windows for a warning.)
ANISOTROPIC_STR = 0.15


#: units of Persson's step keys and of ``u0`` (the ``persson`` block's ``units``; the
#: step units of ``roughfe leak`` take ``persson_stiffness``'s from here)
UNITS = {"persson_mean_gap": "m", "u0": "m",
         "persson_stiffness": "Pa/m (K = -dp/du; null: infinite, the theory's full "
                              "contact u = 0)",
         "persson_leak_rate": "m^3/s"}


def beside(source, e_star, steps, *, pressure_drop=None, viscosity=None, direction="x",
           gamma=GAMMA_DEFAULT, adhesive=False, hardness=None) -> dict:
    """Persson's theory at the mean pressure of each simulation step (results.json).

    Parameters
    ----------
    source : Surface or PowerSpectrum
    e_star : float
        E* (Pa).
    steps : list of dict
        Step records with ``mean_pressure`` (Pa), in the order of the load path; with a
        hardness also ``plastic_area_fraction`` (-): from the first step where it is > 0
        on, no step gets the (elastic) theory (:data:`NOT_PLASTIC`).
    pressure_drop, viscosity : float, optional
        Delta P (Pa) and eta (Pa s): add the critical-junction leak rate (surfaces).
    direction : {"x", "y", "both"}
        Flow direction(s) of the leak rate: the geometry factor (width over length along
        the pressure drop) of each; ``"both"`` reports both and their mean (as the
        simulated ``leak_rate`` of ``roughfe leak --direction both``).
    gamma : float
        As in :func:`persson`.
    adhesive : bool
        The steps are states of an adhesive contact: the (non-adhesive) theory is not
        evaluated; ``"steps"`` are plain copies and ``"persson"`` is :data:`NOT_ADHESIVE`.
        So are they, with ``"persson"`` :data:`NOT_EVALUATED`, for a non-periodic surface
        with fewer than 3 points on a side (no Hann-windowed PSD).
    hardness : float, optional
        H (Pa) of a run with a perfectly plastic interface: every step also gets Persson's
        elastoplastic areas (:func:`roughfe.theory.plastic.beside_elastoplastic`:
        ``persson_elastoplastic_area_fraction``, ``persson_plastic_area_fraction``; None
        from the first unloading step on) and ``"persson"`` an ``"elastoplastic"`` block.

    Returns
    -------
    dict
        ``"steps"``: copies of ``steps`` with ``persson_area_fraction`` (-),
        ``persson_mean_gap`` (m), ``persson_stiffness`` (Pa/m, K = -dp/du) and, with ``pressure_drop``, ``persson_leak_rate_<d>``
        per direction and ``persson_leak_rate`` (their mean; m^3/s) added; steps with no
        positive finite pressure (no theory at zero load) and plastic ones get None.
        ``"persson"``: the sweep-level facts (gamma, kappa, rms gradient, u0 in m,
        percolation threshold, units, references; for a Surface the heights' skewness
        and kurtosis, and a ``"non_gaussian"`` note beyond :data:`NON_GAUSSIAN`; for a 2D
        one its ``texture_aspect_ratio`` Str and ``lay_angle`` (degrees from x), and an
        ``"anisotropic"`` note below :data:`ANISOTROPIC_STR`), with :data:`NOT_PLASTIC` and
        ``plastic_steps`` (their indices) when steps were left out as plastic.
    """
    psd = None if _no_spectrum(source) else _spectrum(source)
    if direction not in ("x", "y", "both"):
        raise InputError(f"direction must be 'x', 'y' or 'both', got {direction!r}")
    dirs = ("x", "y") if direction == "both" else (direction,)
    factors = {d: _geometry_factor(source, d) for d in dirs}
    pressures = [_number_of(k, s, "mean_pressure", "(Pa)") for k, s in enumerate(steps)]
    shape = single_asperity(source) if isinstance(source, Surface) else None
    if shape is not None:       # one smooth cap: Hertz's theory, not Persson's
        return _beside_asperity(source, shape, e_star, steps, pressures, adhesive, hardness)
    if adhesive:
        return {"steps": [dict(s) for s in steps], "persson": dict(NOT_ADHESIVE)}
    if psd is None:
        return {"steps": [dict(s) for s in steps],
                "persson": dict(NOT_EVALUATED, grid=list(source.shape))}
    plastic = _plastic_from(steps)
    ok = [p is not None and np.isfinite(p) and p > 0 and not pl
          for p, pl in zip(pressures, plastic)]
    theory = persson(psd, e_star, [p for p, k in zip(pressures, ok) if k] or [1.0],
                     gamma=gamma)
    out, j = [], 0
    for step, p, k in zip(steps, pressures, ok):
        rec = dict(step)
        rec["persson_area_fraction"] = float(theory.area_fraction[j]) if k else None
        rec["persson_mean_gap"] = float(theory.mean_gap[j]) if k else None
        rec["persson_stiffness"] = float(theory.stiffness[j]) if k else None
        if pressure_drop is not None:
            # Q is linear in the geometry factor: one junction per step, scaled per direction;
            # none where u(p) is inf (y = w p / E* below the smallest float; up to round
            # 2, session 37 from 1e-162: `leak --pressure 1e-200` failed on it)
            unit = (critical_junction(psd, e_star, float(p), pressure_drop, viscosity,
                                      gamma=gamma, geometry_factor=1.0).leak_rate
                    if k and np.isfinite(theory.mean_gap[j]) else None)
            for d, f in factors.items():
                rec[f"persson_leak_rate_{d}"] = None if unit is None else unit * f
            rec["persson_leak_rate"] = (None if unit is None else
                                        float(np.mean([unit * f for f in factors.values()])))
        j += k
        out.append(rec)
    info = {"gamma": theory.gamma, "kappa": theory.kappa, "rms_gradient": theory.rms_gradient,
            "u0": theory.u0, "units": dict(UNITS),
            "references": list(REFERENCES)}
    if pressure_drop is not None:
        info["percolation_threshold"] = PERCOLATION_THRESHOLD
    if isinstance(source, Surface):
        info.update(_height_distribution(source))
        info.update(_texture(source, leak=pressure_drop is not None))
    if any(plastic):
        info.update(NOT_PLASTIC, plastic_steps=[k for k, pl in enumerate(plastic) if pl])
    if hardness is not None:       # the elastoplastic areas beside the first loading
        extra, info["elastoplastic"] = beside_elastoplastic(
            psd, e_star, pressures, [bool(s.get("unloading")) for s in steps], hardness)
        for rec, more in zip(out, extra):
            rec.update(more)
    return {"steps": out, "persson": info}


def _beside_asperity(surface, shape, e_star, steps, pressures, adhesive, hardness) -> dict:
    """:func:`beside` for one smooth cap (:func:`~roughfe.theory.asperity.single_asperity`):
    no ``persson_*`` keys, ``hertz_*`` keys on the elastic non-adhesive steps and
    :data:`~roughfe.theory.asperity.NOT_RANDOM` with the cap's shape as ``"persson"``;
    with a ``hardness`` also the capped Hertz reference on the first loading
    (``capped_hertz_*`` keys, :func:`roughfe.theory.capped_hertz.beside_capped_hertz`;
    None for an ellipsoid or a cylinder, whose ``"capped_hertz"`` block says why)."""
    info = dict(NOT_RANDOM, single_asperity=shape, references=list(ASPERITY_REFERENCES))
    if adhesive:
        return {"steps": [dict(s) for s in steps], "persson": info}
    plastic = _plastic_from(steps)
    hertz = beside_hertz(surface, shape, e_star,
                         [None if pl else p for p, pl in zip(pressures, plastic)])
    if any(plastic):     # NOT_PLASTIC's note is Persson's: it would replace NOT_RANDOM's
        info.update(plasticity=NOT_PLASTIC["plasticity"], plastic_note=HERTZ_NOT_PLASTIC,
                    plastic_steps=[k for k, pl in enumerate(plastic) if pl])
    info["units"] = {"hertz_area_fraction": "-", "hertz_stiffness": "Pa/m (dp/dDelta)"}
    if hardness is not None:
        capped, info["capped_hertz"] = beside_capped_hertz(
            surface, shape, e_star, pressures, [bool(s.get("unloading")) for s in steps],
            hardness)
        hertz = [{**h, **c} for h, c in zip(hertz, capped)]
    return {"steps": [{**s, **h} for s, h in zip(steps, hertz)], "persson": info}


def theory_area_fraction(record):
    """The theory's A* (-) of a step record of :func:`beside`, the one a table shows beside
    the simulation's: with a hardness the theory of the plastic interface (Persson's
    elastoplastic area, the capped Hertz sphere's) where the step has it, else the
    elastic one (Persson's or Hertz's); None where none is given."""
    for key in ("persson_elastoplastic_area_fraction", "capped_hertz_area_fraction",
                "persson_area_fraction", "hertz_area_fraction"):
        if record.get(key) is not None:
            return record[key]
    return None


def _height_distribution(surface) -> dict:
    """Skewness and kurtosis of the heights (about their mean) and, beyond
    :data:`NON_GAUSSIAN`, a ``"non_gaussian"`` note: the theory's surface is Gaussian."""
    skew, kurt = height_moments(surface)
    if not np.isfinite(skew):
        return {}
    out = {"height_skewness": skew, "height_kurtosis": kurt}
    if abs(skew) > NON_GAUSSIAN["skewness"] or kurt > NON_GAUSSIAN["kurtosis"]:
        out["non_gaussian"] = (
            f"the heights are far from Gaussian (skewness {skew:.3g}, kurtosis {kurt:.3g}; "
            f"a Gaussian surface has 0 and 3): Persson's theory takes a Gaussian surface of "
            f"this PSD and does not apply here; read the simulation, not the theory")
    return out


def _texture(surface, leak) -> dict:
    """Str of a 2D surface (``texture_aspect_ratio``, ``lay_angle`` in degrees from x) and,
    below :data:`ANISOTROPIC_STR`, an ``"anisotropic"`` note: the theory takes the radial
    average of the PSD, an isotropic surface, so its A*(p), u(p) and (``leak``) its
    critical-junction leak rate, the same along x and y but for the window's W/L, do not
    see the lay. A ``"texture_bounded"`` note where Str is only an upper bound that is not
    below the limit and one direction stays correlated above
    :data:`~roughfe.surfaces.texture.LAY_PERSISTENCE` over the cell's half period (one wave
    across a 32^2 cell reads Str 0.40, where the lay is infinite; an isotropic self-affine
    cell without roll-off is often bounded too, but its directions decorrelate).
    Nothing for a profile, a flat surface or a grid too small for Str."""
    from ..surfaces.texture import LAY_PERSISTENCE, texture_aspect_ratio
    if surface.ndim != 2 or min(surface.shape) < 2 or not np.ptp(surface.heights) > 0:
        return {}
    tex = texture_aspect_ratio(surface)
    out = {"texture_aspect_ratio": tex.ratio, "lay_angle": tex.lay_angle}
    if tex.ratio < ANISOTROPIC_STR:
        what = ("its critical-junction leak rate (persson_leak_rate_x/_y differ only by the "
                "window's W/L) cannot tell the flow along the lay from the flow across it and "
                "can miss the Reynolds leak rates (leak_rate_x/_y) by orders of magnitude: "
                "read those" if leak else
                "read its A*(p), u(p) and K(p) as those of the direction-averaged PSD")
        out["anisotropic"] = (
            f"the surface has a lay: texture aspect ratio Str = {tex.ratio:.3g} (ISO 25178-2, "
            f"< {ANISOTROPIC_STR:g}; 1: isotropic), heights correlated over "
            f"{tex.longest:.3g} m along {tex.lay_angle:.0f} deg from x and {tex.shortest:.3g} m "
            f"across{' or more' if tex.bounded else ''}; Persson's theory assumes an "
            f"isotropic surface (the radially averaged PSD): {what}")
    elif tex.bounded and tex.persistence >= LAY_PERSISTENCE:
        out["texture_bounded"] = (
            f"the texture aspect ratio Str = {tex.ratio:.3g} is only an upper bound: in one "
            f"direction the heights stay correlated (autocorrelation >= {tex.persistence:.2f}) "
            f"over the whole half period of the periodic cell, a lay longer than the cell "
            f"(one wave across it, grooves as long as it) that Str cannot measure; the "
            f"surface is probably anisotropic, and Persson's theory assumes an isotropic one")
    return out


def _no_spectrum(source) -> bool:
    """The source is a non-periodic surface too narrow for the Hann window of its PSD
    (:func:`roughfe.surfaces.stats.power_spectrum`: fewer than 3 points on a side)."""
    return (isinstance(source, Surface) and not source.periodic
            and min(source.shape) < HANN_MIN_POINTS)


def _plastic_from(steps):
    """Per step (in path order): it or an earlier one had plastic flow
    (``plastic_area_fraction`` > 0), so it is not the elastic contact of the surface."""
    out, flowed = [], False
    for k, step in enumerate(steps):
        fraction = _number_of(k, step, "plastic_area_fraction", "(-)")
        flowed = flowed or (fraction is not None and fraction > 0)
        out.append(flowed)
    return out


def _number_of(k, step, key, unit):
    """The value of ``key`` (in ``unit``) of the step record ``steps[k]``: None when it
    has none, a float when it is a real number (for the mean pressure: NaN and p <= 0 get
    no theory), else an InputError."""
    if not isinstance(step, Mapping):
        raise InputError(f"steps[{k}] must be a step record (a dict with 'mean_pressure' in "
                         f"Pa), got {type(step).__name__}")
    p = step.get(key)
    if p is None:
        return None
    if isinstance(p, (bool, str, bytes)) or not isinstance(p, numbers.Real):
        raise InputError(f"steps[{k}][{key!r}] must be a number {unit} or None, got {p!r}")
    return float(p)
