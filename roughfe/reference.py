"""Analytic reference solutions of frictionless elastic contact (SI units).

Every solver in roughfe (BEM in :mod:`roughfe.bem`, FEM in :mod:`roughfe.fem`) is checked
against these closed forms. All functions take the composite (plane-strain) modulus
``e_star`` = E* = [(1-nu1^2)/E1 + (1-nu2^2)/E2]^-1 in Pa.

* :func:`westergaard` -- a periodic sinusoidal profile ``h(x) = g cos(2 pi x / lambda)``
  pressed on an elastic half-plane (plane strain): contact half-width, pressure field,
  mean gap, full-contact pressure (Westergaard 1939; Johnson 1985, Sec. 13.2).
* :func:`hertz_sphere` -- a rigid sphere of radius R on an elastic half-space: contact
  radius, approach, peak pressure and stiffness (Johnson 1985, Sec. 4.2).
* :func:`hertz_cylinder` -- a rigid cylinder of radius R on an elastic half-plane
  (line contact): half-width and pressure field (Johnson 1985, Sec. 4.3). The approach
  of a 2D half-plane is defined only up to a constant, so it is not given.
* :func:`uniform_strip_displacement` / :func:`uniform_rectangle_displacement` -- the
  surface displacement under a uniform pressure on a strip (half-plane, with a stated
  reference) and on a rectangle (half-space, Love 1929). These are the influence
  coefficients of the non-periodic BEM operators.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import InputError, check_finite_positive

__all__ = ["westergaard", "WestergaardSolution", "hertz_sphere", "hertz_cylinder", "HertzSolution",
           "uniform_strip_displacement", "uniform_rectangle_displacement",
           "uniform_cell_displacement_grid", "maugis_parameter", "maugis_load", "maugis_pull_off",
           "REFERENCES_WESTERGAARD", "REFERENCES_HERTZ", "REFERENCES_LOVE", "REFERENCES_MAUGIS"]

REFERENCES_WESTERGAARD = ("Westergaard H.M. (1939) J. Appl. Mech. 6:A49-A53",
                          "Johnson K.L. (1985) Contact Mechanics, Sec. 13.2")
REFERENCES_HERTZ = ("Hertz H. (1882) J. reine angew. Math. 92:156-171",
                    "Johnson K.L. (1985) Contact Mechanics, Sec. 4.2-4.3")
REFERENCES_LOVE = ("Love A.E.H. (1929) Phil. Trans. R. Soc. A 228:377-420",
                   "Johnson K.L. (1985) Contact Mechanics, Eq. 3.25 and 2.25")


# -- Westergaard: periodic sinusoid in plane strain -------------------------------------
@dataclass(frozen=True)
class WestergaardSolution:
    """Westergaard's solution for ``h(x) = amplitude * cos(2 pi x / wavelength)``.

    Contact is centred on the crest at ``x = 0`` (and its periodic images).

    Attributes
    ----------
    amplitude, wavelength : float
        Sinusoid amplitude g and wavelength lambda (m).
    e_star : float
        Composite plane-strain modulus E* (Pa).
    mean_pressure : float
        Imposed mean pressure p (Pa), 0 <= p.
    full_contact_pressure : float
        p* = pi E* g / lambda (Pa): the smallest mean pressure giving full contact.
    half_width : float
        Contact half-width a (m) from p = p* sin^2(pi a / lambda); lambda/2 at full contact.
    area_fraction : float
        2a / lambda.
    mean_gap : float
        Mean gap between the deformed half-plane and the sinusoid (m),
        gbar / g = 1 - s + s ln s with s = p / p* (0 at full contact). The mean of the
        half-plane displacement is taken as zero (the periodic convention).
    """

    amplitude: float
    wavelength: float
    e_star: float
    mean_pressure: float
    full_contact_pressure: float
    half_width: float
    area_fraction: float
    mean_gap: float

    def pressure(self, x):
        """Contact pressure p(x) (Pa) at positions ``x`` (m), periodic in the wavelength.

        Partial contact: p(x) = 2 p cos(psi x) sqrt(sin^2(psi a) - sin^2(psi x)) /
        sin^2(psi a) for |x| < a, psi = pi / lambda; full contact (p >= p*):
        p(x) = p + p* cos(2 pi x / lambda).
        """
        x = np.asarray(x, dtype=float)
        psi = np.pi / self.wavelength
        xr = (x + 0.5 * self.wavelength) % self.wavelength - 0.5 * self.wavelength
        if self.mean_pressure >= self.full_contact_pressure:
            return self.mean_pressure + self.full_contact_pressure * np.cos(2 * psi * xr)
        sa2 = np.sin(psi * self.half_width) ** 2
        if sa2 == 0.0:
            return np.zeros_like(xr)
        inside = np.clip(sa2 - np.sin(psi * xr) ** 2, 0.0, None)
        return np.where(np.abs(xr) < self.half_width,
                        2 * self.mean_pressure * np.cos(psi * xr) * np.sqrt(inside) / sa2, 0.0)


def westergaard(amplitude, wavelength, e_star, mean_pressure) -> WestergaardSolution:
    """Westergaard's periodic sinusoid contact (plane strain), all quantities SI.

    Parameters
    ----------
    amplitude : float
        g (m), the sinusoid is ``g cos(2 pi x / lambda)`` (peak-to-valley 2g).
    wavelength : float
        lambda (m).
    e_star : float
        Composite modulus E* (Pa).
    mean_pressure : float
        Mean pressure p >= 0 (Pa). Values above p* give full contact.
    """
    g = check_finite_positive("amplitude", amplitude)
    lam = check_finite_positive("wavelength", wavelength)
    e = check_finite_positive("e_star", e_star)
    p = float(mean_pressure)
    if not (np.isfinite(p) and p >= 0):
        raise InputError(f"mean_pressure must be finite and >= 0 (Pa), got {mean_pressure!r}")
    p_star = np.pi * e * g / lam
    s = min(p / p_star, 1.0)
    a = lam / np.pi * np.arcsin(np.sqrt(s))
    gbar = g * (1.0 - s + (s * np.log(s) if s > 0 else 0.0))
    return WestergaardSolution(g, lam, e, p, p_star, a, 2 * a / lam, max(gbar, 0.0))


# -- Hertz --------------------------------------------------------------------------------
@dataclass(frozen=True)
class HertzSolution:
    """Hertz contact of a rigid sphere (``kind="sphere"``) or cylinder (``"cylinder"``).

    Attributes
    ----------
    radius : float
        Indenter radius R (m).
    e_star : float
        Composite modulus E* (Pa).
    load : float
        Total load P: N for the sphere, N/m for the cylinder.
    contact_radius : float
        Contact radius (sphere) or half-width (cylinder) a (m).
    peak_pressure : float
        p0 (Pa): 3P/(2 pi a^2) (sphere), 2P/(pi a) (cylinder).
    approach : float
        Sphere: delta = a^2/R = (9 P^2 / (16 R E*^2))^(1/3) (m). Cylinder: NaN (a 2D
        half-plane approach depends on the displacement reference).
    stiffness : float
        Sphere: dP/d delta = 2 E* a (N/m). Cylinder: NaN. A force per length, unlike
        :attr:`roughfe.model.ContactResult.stiffness` (d p / d Delta, Pa/m): compare it
        with ``result.stiffness * surface.nominal_area``.
    """

    kind: str
    radius: float
    e_star: float
    load: float
    contact_radius: float
    peak_pressure: float
    approach: float
    stiffness: float

    def pressure(self, r):
        """Pressure p0 sqrt(1 - (r/a)^2) (Pa) at distance ``r`` (m) from the centre."""
        r = np.asarray(r, dtype=float)
        if self.contact_radius == 0.0:
            return np.zeros_like(r)
        return self.peak_pressure * np.sqrt(np.clip(1 - (r / self.contact_radius) ** 2, 0, None))


def _check_nonneg(name, value):
    v = float(value)
    if not (np.isfinite(v) and v >= 0):
        raise InputError(f"{name} must be finite and >= 0, got {value!r}")
    return v


def hertz_sphere(radius, e_star, *, load=None, approach=None) -> HertzSolution:
    """Hertz sphere on a half-space; give exactly one of ``load`` (N) or ``approach`` (m).

    a = (3 P R / (4 E*))^(1/3), delta = a^2 / R, p0 = 3 P / (2 pi a^2), K = 2 E* a.
    """
    R = check_finite_positive("radius", radius)
    e = check_finite_positive("e_star", e_star)
    if (load is None) == (approach is None):
        raise InputError("give exactly one of load (N) or approach (m)")
    if load is not None:
        P = _check_nonneg("load", load)
        a = (3 * P * R / (4 * e)) ** (1 / 3)
    else:
        a = np.sqrt(_check_nonneg("approach", approach) * R)
        P = 4 * e * a ** 3 / (3 * R)
    p0 = 3 * P / (2 * np.pi * a ** 2) if a > 0 else 0.0
    return HertzSolution("sphere", R, e, P, a, p0, a ** 2 / R, 2 * e * a)


def hertz_cylinder(radius, e_star, load) -> HertzSolution:
    """Hertz line contact of a cylinder, load ``P`` in N/m: a = sqrt(4 P R / (pi E*)),
    p0 = 2 P / (pi a)."""
    R = check_finite_positive("radius", radius)
    e = check_finite_positive("e_star", e_star)
    P = _check_nonneg("load", load)
    a = np.sqrt(4 * P * R / (np.pi * e))
    p0 = 2 * P / (np.pi * a) if a > 0 else 0.0
    return HertzSolution("cylinder", R, e, P, a, p0, float("nan"), float("nan"))


# -- uniform pressure on a strip / a rectangle -------------------------------------------
def uniform_strip_displacement(x, half_width, e_star, pressure=1.0, reference_length=1.0):
    """Surface displacement (m) of a half-plane under a uniform pressure on |x| < b.

    Plane strain: u(x) = (2 p / (pi E*)) * integral_{-b}^{b} ln(L_ref / |x - s|) ds, i.e.
    the point-load displacement ``(2 P/(pi E*)) ln(L_ref/r)`` integrated over the strip
    (Johnson 1985, Eq. 2.25). A 2D half-plane displacement is defined only up to a
    constant: here it is zero at distance ``reference_length`` L_ref (m) from a line load.

    Parameters
    ----------
    x : array_like
        Positions (m) relative to the strip centre.
    half_width : float
        b (m).
    e_star : float
        E* (Pa).
    pressure : float
        p (Pa), compressive positive.
    reference_length : float
        L_ref (m).
    """
    x = np.asarray(x, dtype=float)

    def prim(t):
        at = np.abs(t)
        with np.errstate(divide="ignore", invalid="ignore"):
            v = t * (1.0 + np.log(reference_length / at))
        return np.where(at > 0, v, 0.0)

    return 2 * pressure / (np.pi * e_star) * (prim(x + half_width) - prim(x - half_width))


def _log_x_plus_hypot(a, b):
    """ln(a + sqrt(a^2 + b^2)) without cancellation for a < 0 (-inf where a<0, b=0)."""
    r = np.hypot(a, b)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(a >= 0, np.log(a + r), np.log(b * b) - np.log(r - a))


def _love_primitive(X, Y):
    """F(X, Y) = X ln(Y + r) + Y ln(X + r), r = sqrt(X^2+Y^2): the antiderivative of
    1/r over X and Y, with the 0 * ln 0 limits set to 0."""
    with np.errstate(invalid="ignore"):
        t1 = np.where(X == 0, 0.0, X * _log_x_plus_hypot(Y, X))
        t2 = np.where(Y == 0, 0.0, Y * _log_x_plus_hypot(X, Y))
    return t1 + t2


def uniform_rectangle_displacement(x, y, half_a, half_b, e_star, pressure=1.0):
    """Love's surface displacement (m) of a half-space under uniform pressure ``p`` on
    the rectangle |x| < a, |y| < b (Love 1929; Johnson 1985, Eq. 3.25):

    u(x, y) = p / (pi E*) * sum over corners of +-F(x -+ a, y -+ b),
    F(X, Y) = X ln(Y + sqrt(X^2+Y^2)) + Y ln(X + sqrt(X^2+Y^2)).

    The centre of a square of side 2a moves by 8 ln(1+sqrt 2) p a / (pi E*) = 2.24 p a/E*.
    """
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    s = (_love_primitive(x + half_a, y + half_b) - _love_primitive(x + half_a, y - half_b)
         - _love_primitive(x - half_a, y + half_b) + _love_primitive(x - half_a, y - half_b))
    return pressure / (np.pi * e_star) * s


def uniform_cell_displacement_grid(n0, n1, d0, d1, e_star):
    """:func:`uniform_rectangle_displacement` of one grid cell (d0 x d1 m, unit pressure:
    m/Pa) at the grid offsets (k0 d0, k1 d1), k0 = 0 .. n0 - 1, k1 = 0 .. n1 - 1.

    The same sum of Love's primitive F over the cell's corners, with F evaluated once per
    corner of the lattice ((k -+ 1/2) d) and the kernel its mixed second difference: one
    evaluation of F per point instead of four (the displacement is even in x and y, so
    the non-negative offsets are all a BEM kernel needs; measured 16x less work than the
    four-corner form on the padded 2n x 2n grid of a non-periodic operator)."""
    X = (np.arange(n0 + 1) - 0.5) * d0
    Y = (np.arange(n1 + 1) - 0.5) * d1
    F = _love_primitive(X[:, None], Y[None, :])
    s = F[1:, 1:] - F[1:, :-1]
    s -= F[:-1, 1:]
    s += F[:-1, :-1]
    s *= 1.0 / (np.pi * e_star)
    return s


# -- Maugis-Dugdale: adhesive sphere ------------------------------------------------------
REFERENCES_MAUGIS = ("Maugis D. (1992) J. Colloid Interface Sci. 150:243-269",
                     "Johnson K.L., Greenwood J.A. (1997) J. Colloid Interface Sci. 192:326-333")


def maugis_parameter(radius, e_star, work, max_traction):
    """Maugis' transition parameter ``lambda = 2 sigma0 (R / (pi w K^2))^(1/3)``,
    ``K = 4 E* / 3`` (dimensionless; lambda ~ 1.16 x Tabor's mu). R in m, E* and
    sigma0 in Pa, w in J/m^2. lambda -> 0: DMT, lambda -> infinity: JKR."""
    r = check_finite_positive("radius (m)", radius)
    k = 4.0 / 3.0 * check_finite_positive("e_star (Pa)", e_star)
    w = check_finite_positive("work of adhesion (J/m^2)", work)
    s0 = check_finite_positive("max_traction (Pa)", max_traction)
    return 2.0 * s0 * (r / (np.pi * w * k ** 2)) ** (1.0 / 3.0)


def _maugis_m(lam, a_bar):
    """Solve Maugis' Eq. (i) for m = c/a > 1 at the reduced contact radius ``a_bar``."""
    import scipy.optimize

    def lhs(m):
        s = np.sqrt(m * m - 1.0)
        t = np.arctan(s)
        return (lam * a_bar ** 2 / 2 * (s + (m * m - 2) * t)
                + 4 * lam ** 2 * a_bar / 3 * (s * t - m + 1) - 1.0)

    hi = 2.0
    while lhs(hi) < 0:
        hi *= 2.0
    return scipy.optimize.brentq(lhs, 1.0 + 1e-15, hi, xtol=1e-14, rtol=1e-14)


def maugis_load(lam, a_bar):
    """Maugis-Dugdale sphere: reduced load ``P/(pi w R)`` and approach
    ``delta (K^2/(pi^2 w^2 R))^(1/3)`` at the reduced contact radius
    ``a_bar = a (K/(pi w R^2))^(1/3)`` (Maugis 1992, Eqs. as in Johnson & Greenwood 1997).
    Returns ``(P_bar, delta_bar, m)`` with ``m = c/a`` the edge of the cohesive zone."""
    lam = check_finite_positive("lambda", lam)
    a_bar = check_finite_positive("a_bar", a_bar)
    m = _maugis_m(lam, a_bar)
    s = np.sqrt(m * m - 1.0)
    t = np.arctan(s)
    p_bar = a_bar ** 3 - lam * a_bar ** 2 * (s + m * m * t)
    d_bar = a_bar ** 2 - 4.0 / 3.0 * lam * a_bar * s
    return float(p_bar), float(d_bar), float(m)


def maugis_pull_off(lam):
    """Pull-off force of the Maugis-Dugdale sphere under load control, ``P_c / (pi w R)``
    (negative: tensile): -2 at lambda -> 0 (DMT), -1.5 at lambda -> infinity (JKR).
    The minimum over the contact radius of :func:`maugis_load`."""
    import scipy.optimize

    lam = check_finite_positive("lambda", lam)
    grid = np.geomspace(1e-3, 10.0, 200)
    vals = [maugis_load(lam, a)[0] for a in grid]
    k = int(np.argmin(vals))
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
    res = scipy.optimize.minimize_scalar(lambda a: maugis_load(lam, a)[0], bounds=(lo, hi),
                                         method="bounded", options={"xatol": 1e-10})
    return float(min(res.fun, vals[k]))
