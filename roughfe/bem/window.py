"""What a finite, non-periodic window (a measured topography) adds to its BEM contact
results: the bulk compliance of the loaded window (SI units).

A non-periodic BEM solve presses the window alone into a half-space. The half-space
then deflects as a whole under the window's load, like a flat punch of the window's
size: its mean deflection per unit uniform pressure is the window compliance

    C = mean(H 1)   (m/Pa),  ~0.9 sqrt(A_n)/E*  (0.946 a/E* for a square of side a),

and the approach Delta = (rough interface closure) + (bulk deflection ~ C p). So

* ``stiffness`` K = dp/dDelta is that of the interface in series with the window's bulk,
  1/K ~ 1/K_interface + C (docs/theory/02_bem_contact.md, measured on the five instrument
  files: K C = 0.87-1.09 at A* = 0.12-0.85, 1.02-1.09 from A* ~ 0.2; C p/Delta up to
  0.71-1.05 of the approach): it is
  correct for the window problem, and a property of the window's size, not of its
  roughness, wherever K C is of order one. :func:`window_report` says so (a
  :class:`~roughfe.errors.WindowStiffnessWarning`).

A periodic surface has no such compliance: its kernel has zero mean displacement.
"""
from __future__ import annotations

import warnings

import numpy as np

from ..errors import WindowStiffnessWarning
from ..model import Material
from ..writers import finite_or_none

#: K C above which :func:`window_report` warns (at the largest load): the bulk of the
#: window then takes more than half of the compliance 1/K
WINDOW_STIFFNESS_SHARE = 0.5


def _mean_deflection(shape, size, e_star, kernel) -> float:
    """mean(H 1) (m/Pa) of the non-periodic operator ``kernel`` on the grid (the solver's
    cached operator: the one a sweep of this grid has just used)."""
    from .contact import _operator     # contact imports this module

    op = _operator(tuple(int(n) for n in shape), tuple(float(s) for s in size),
                   float(e_star), kernel)
    return float(np.mean(op.apply(np.ones(tuple(shape)))))


def window_compliance(surface, youngs_modulus, poisson=0.0, kernel="auto") -> float:
    """Mean surface displacement per unit uniform pressure over a non-periodic window
    (m/Pa): ``C = mean(H 1)`` with the window's non-periodic BEM operator (``"auto"``:
    Love's rectangle kernel for a surface, the strip kernel for a profile; or the
    ``kernel`` of the solve, "thesis" too), E* = E/(1 - nu^2).

    It is the bulk compliance of the loaded window in series with the rough interface
    (module notes); the ``"window"`` targets of
    :func:`roughfe.genomics.design.surface_targets` add it that way. For a rectangle of
    area A_n it is ~0.9 sqrt(A_n)/E* (x3p-2: 5.6e-13 m/Pa at E* = 210 MPa, 0.90
    sqrt(A_n)/E*).
    """
    mat = Material(youngs_modulus, poisson)
    if kernel == "auto":
        kernel = "love" if surface.ndim == 2 else "strip"
    return _mean_deflection(surface.shape, surface.size, mat.E_star, kernel)


def window_report(sweep) -> dict:
    """The window's bulk compliance beside a non-periodic BEM sweep ({} for a periodic
    or a FEM one): ``window_compliance`` C (m/Pa, the kernel of the solve) and per step
    ``bulk_share`` = C p/Delta (the share of the approach that is the window's bulk
    deflection; None at Delta = 0 to round-off and for a tensile load) and
    ``stiffness_compliance`` K C (None where K is not computed). Warns once
    (:class:`~roughfe.errors.WindowStiffnessWarning`) when K C >
    :data:`WINDOW_STIFFNESS_SHARE` at the largest load with a computed K."""
    r0 = sweep.results[0]
    if sweep.method != "bem" or r0.periodic:
        return {}
    c = _mean_deflection(r0.pressure.shape, r0.size, r0.e_star, r0.kernel)
    p = np.asarray(sweep.mean_pressure, float)
    d = np.asarray(sweep.delta, float)
    # defined for a compressive load at an approach above round-off (an adhesive branch
    # unloaded to Delta = 2e-22 m printed C p / Delta = -2e15; a user's review)
    defined = (d > 1e-9 * float(np.max(np.abs(d), initial=0.0))) & (p > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        share = np.where(defined, c * p / d, np.nan)
    kc = np.asarray(sweep.stiffness, float) * c
    ok = np.isfinite(kc)
    if ok.any():
        top = int(np.flatnonzero(ok)[np.argmax(p[ok])])
        if kc[top] > WINDOW_STIFFNESS_SHARE:
            # the 3D facts (C ~ 0.9 sqrt(A_n)/E*, a flat punch's K C ~ 1.08) are not a
            # profile's: the strip kernel's C depends on its reference length
            facts = (" (~0.9 sqrt(A_n)/E*)", " (a rigid flat punch of the window's size "
                     "has K C ~ 1.08)") if len(r0.pressure.shape) == 2 else (
                " (the strip kernel's, which depends on its reference length, the "
                "profile's)", "")
            warnings.warn(
                f"K is the bulk stiffness of the measured window in series with the "
                f"interface (1/K ~ 1/K_interface + C), not a property of the roughness; "
                f"here K C = {kc[top]:.3g} at p = {p[top]:.3g} Pa, with the window "
                f"compliance C = {c:.3g} m/Pa{facts[0]} and the window's bulk "
                f"deflection C p = {share[top]:.2g} of the approach{facts[1]}. "
                f"The interface's own K(p) is that of "
                f"a periodic surface, e.g. the evenly mirrored window (roughfe contact "
                f"--mirror, Surface.mirrored(), roughfe design-targets --boundary "
                f"periodic); C is written to "
                f"results.json (derived.window_compliance)", WindowStiffnessWarning,
                stacklevel=2)

    def listed(a):
        return [finite_or_none(v) for v in a]
    return {"window_compliance": c, "bulk_share": listed(share),
            "stiffness_compliance": listed(kc)}
