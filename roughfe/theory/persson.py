"""Persson's contact theory from the PSD of a surface: A(p), u(p) and the critical junction.

All quantities are SI: pressures and E* in Pa, lengths in m, the PSD in the
normalisation of :mod:`roughfe.surfaces.stats` (``<h^2> = sum C * weight``).

Area of real contact (Persson 2001)
-----------------------------------
At magnification zeta (all roughness with ``|q| <= q = zeta q0`` resolved) the
probability density of the contact stress obeys a diffusion equation whose solution with
``P(sigma = 0) = 0`` gives

    A(q, p) / A0 = erf( 1 / (2 sqrt(G(q))) ),    G(q) = <sigma^2>_q / (2 p^2),

where ``<sigma^2>_q = (E*/2)^2 m(q)`` is the variance of the stress needed to flatten the
roughness up to ``q`` and ``m(q) = sum_{|q'| <= q} |q'|^2 |h~(q')|^2`` its mean-square
gradient. For an isotropic surface ``m(q) = 2 pi int_q0^q q'^3 C dq'``, so
``G = (pi/4)(E*/p)^2 int q'^3 C dq'`` as in Persson (2001); for a profile on an elastic
half-plane in plane strain (same E* and the same kernel ``2/(E*|q|)``) ``m(q) = int q'^2
C dq'`` over both signs of q' (the derivation is identical, only the sum over the
wavevectors is one-dimensional). The result at full magnification is therefore the same
formula in 1D and 2D,

    A*(p) = erf( sqrt(2) p / (E* gbar) ),        gbar^2 = m(q1) = <|grad h|^2>,      (1)

with gbar the rms gradient (2D) or rms slope (1D). At small load
``A* -> kappa p / (E* gbar)`` with ``kappa = sqrt(8/pi) = 1.596`` in both dimensions.

Small-A* correction: BEM simulations of self-affine surfaces (Hyun et al. 2004; Campana &
Muser 2007; Prodanov, Dapp & Muser 2014) find kappa ~ 1.9-2.1 for surfaces and an
A*(p) that is not linear for profiles; the P(sigma = 0) = 0 boundary condition
underestimates the area at small A*. Persson's later work (Persson 2007; Yang & Persson
2008) corrects the *elastic energy* at small A* with ``S(q) = gamma + (1 - gamma) P(q)^2``
(it enters u(p) below) and leaves Eq. (1) as is. :func:`area_fraction` accepts
``kappa`` to use the measured small-load slope instead of sqrt(8/pi) (Eq. (1) with
``sqrt(2)`` replaced by ``kappa sqrt(pi) / 2``: the same erf, still -> 1 at large p); the
default is Persson's sqrt(8/pi).

Mean interfacial separation (Persson 2007; Yang & Persson 2008)
---------------------------------------------------------------
With the elastic energy ``U/A0 = (E*/4) sum_q |q| |h~(q)|^2 P(q, p) S(q, p)`` and
``p A0 = -dU/du``:

    u(p) = (1/4) sum_k |q_k| C_k weight_k w_k J(w_k p / E*),                          (2)
    w_k  = sqrt(2 / m(q_k)),
    J(y) = (2/sqrt(pi)) int_y^inf exp(-x^2) [gamma + 3 (1 - gamma) erf(x)^2] dx / x,

which for an isotropic surface is Yang & Persson's
``u = sqrt(pi) int dq q^2 C w int_p^inf dp'/p' [gamma + 3(1-gamma)P^2] exp(-(w p'/E*)^2)``
with ``w = (pi int_q0^q q'^3 C)^(-1/2)``. u is the separation of the mean planes, which
equals the BEM ``mean_gap`` (mean of the gap field). gamma ~ 0.4-0.5 (Persson 2007 uses
0.4, Yang & Persson 0.45); the default here is **gamma = 0.45**. At intermediate
pressures ``u = u0 ln(p_ref / p)``, i.e. ``p ~ exp(-u / u0)``, with

    u0 = -du/dln p (p -> 0) = (1 / (2 sqrt(pi))) gamma sum_k |q_k| C_k weight_k w_k,   (3)

(:attr:`PerssonResult.u0`). Persson (2007) writes ``u0 ~ gamma h_rms``; that is an
order-of-magnitude statement (the ratio u0 / (gamma h_rms) depends on the spectrum, see
docs/theory/07_adhesion_persson.md); Eq. (3) is what the theory gives.

Normal contact stiffness (Persson 2007; Akarapu, Sharp & Robbins 2011)
-----------------------------------------------------------------------
``K = -dp/du``: the derivative of Eq. (2), ``dJ/dy = -(2/sqrt(pi)) exp(-y^2) [gamma + 3
(1 - gamma) erf(y)^2] / y`` with ``y = w p / E*``, gives::

    K(p) = p / D(p),                                                                 (4)
    D(p) = (2/sqrt(pi)) sum_k (1/4) |q_k| C_k weight_k w_k exp(-y_k^2) [gamma + 3 (1 -
           gamma) erf(y_k)^2],

so ``K -> p / u0`` at small p (Eq. (3)). For a periodic surface the mean gap falls as
the approach grows (u = const - Delta), and K is the BEM's dp/dDelta; for a
non-periodic window the BEM's K also holds the window's bulk compliance.

The critical junction of Lorenz & Persson is in :mod:`roughfe.theory.junction`, the
theory beside a simulation's steps in :mod:`roughfe.theory.beside`.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import scipy.special

from ..errors import (InputError, check_finite_nonnegative, check_finite_positive,
                      check_in_interval, check_real_array)
from ..frozen import ReadOnlyArrays, compact_repr, read_only_arrays
from ..surfaces.stats import PowerSpectrum, power_spectrum
from ..surfaces.surface import Surface

KAPPA_PERSSON = float(np.sqrt(8.0 / np.pi))
GAMMA_DEFAULT = 0.45
PERCOLATION_THRESHOLD = 0.42

REFERENCES = (
    "Persson B.N.J. (2001) J. Chem. Phys. 115:3840-3861 (A(p), Eq. (1))",
    "Persson B.N.J. (2007) Phys. Rev. Lett. 99:125502 (u(p), gamma)",
    "Yang C., Persson B.N.J. (2008) J. Phys.: Condens. Matter 20:215214 (u(p), Eq. (2))",
    "Lorenz B., Persson B.N.J. (2009) Eur. Phys. J. E 31:159-167 (critical junction)",
    "Akarapu S., Sharp T., Robbins M.O. (2011) Phys. Rev. Lett. 106:204301 (K = -dp/du)",
)


# -- inputs ---------------------------------------------------------------------------------
def _spectrum(source) -> PowerSpectrum:
    if isinstance(source, PowerSpectrum):
        return source
    if isinstance(source, Surface):
        return power_spectrum(source)
    raise InputError(f"expected a roughfe Surface or PowerSpectrum, got {type(source).__name__}")


def _pressures(mean_pressure):
    p = np.atleast_1d(check_real_array("mean_pressure", mean_pressure, unit="Pa"))
    if p.ndim != 1 or p.size == 0 or np.any(p <= 0):
        raise InputError(f"mean_pressure must be finite and > 0 (Pa), got {mean_pressure!r}")
    return p


def _arrays(psd: PowerSpectrum):
    """``(q, q2, power)`` of the PSD's values with power: q (rad/m), the power-weighted
    mean |q|^2 of each value's modes (:attr:`PowerSpectrum.q2`; exact gradient moments
    of a binned surface spectrum), |h~|^2 per value (m^2)."""
    power = np.asarray(psd.C, float) * np.asarray(psd.weight, float)     # |h~|^2 per value
    return _with_power(np.asarray(psd.q, float), np.asarray(psd.q_squared, float), power)


def _with_power(q, q2, power):
    """``(q, q2, power)`` of the values with power > 0 only: a value without power adds
    nothing to Eq. (2) but, below the first with power, has m(q) = 0 and so w = inf (its
    0 * inf term made u(p) NaN); :class:`InputError` when no value has power."""
    keep = power > 0
    if not keep.any():
        raise InputError("the PSD is zero everywhere: a flat surface has no Persson theory")
    return q[keep], q2[keep], power[keep]


def _check_gamma(gamma) -> float:
    """``gamma`` of Persson's elastic-energy factor ``S = gamma + (1 - gamma) P^2``
    (Persson 2007), in (0, 1]: S lies between gamma at small contact and 1 at full
    contact, and J(y) of Eq. (2) is positive; otherwise :class:`InputError`."""
    return check_in_interval("gamma (Persson's elastic-energy factor S = gamma + "
                             "(1 - gamma) P^2)", gamma, 0, 1, "right")


def _cumulative_gradient(q2, power):
    """m(q_k): mean-square gradient of the roughness up to q_k (midpoint in the bin)."""
    term = q2 * power
    return np.cumsum(term) - 0.5 * term


# -- the universal function J(y) of Eq. (2) -------------------------------------------------
_X_MAX = 7.0


@lru_cache(maxsize=None)
def _erf2_table():
    """``K(y) = int_y^inf exp(-x^2) erf(x)^2 / x dx`` tabulated on [0, 7] (trapezoid,
    dx = 3.5e-4, error < 1e-8; the integrand is smooth and 0 at x = 0)."""
    x = np.linspace(0.0, _X_MAX, 20001)
    f = np.zeros_like(x)
    f[1:] = np.exp(-x[1:] ** 2) * scipy.special.erf(x[1:]) ** 2 / x[1:]
    seg = 0.5 * (f[1:] + f[:-1]) * np.diff(x)
    k = np.concatenate([np.cumsum(seg[::-1])[::-1], [0.0]])
    return x, k


def j_function(y, gamma=GAMMA_DEFAULT):
    """``J(y)`` of Eq. (2) (dimensionless) for y = w p / E* >= 0 (J(0) = inf: the
    integral diverges at its lower end) and gamma in (0, 1] (:func:`_check_gamma`).

    ``J = (2/sqrt(pi)) [gamma E1(y^2)/2 + 3 (1 - gamma) K(y)]`` with the exponential
    integral E1 and the tabulated ``K`` (:func:`_erf2_table`).

    Raises
    ------
    InputError
        y not finite or < 0 (J was evaluated on y^2 and returned J(|y|)), gamma outside
        (0, 1] (gamma = 5 gave J < 0).
    """
    gamma = _check_gamma(gamma)
    y = check_real_array("y (w p / E*)", y, unit="-")
    if np.any(y < 0):
        raise InputError(f"y (w p / E*) must be >= 0, got {float(y.min())!r}")
    x, k = _erf2_table()
    kk = np.interp(y, x, k, right=0.0)
    return (2 / np.sqrt(np.pi)) * (0.5 * gamma * _exp1_of_square(y)
                                   + 3 * (1 - gamma) * kk)


#: below this y, E1(y^2) is taken from its series -euler_gamma - 2 ln y (the next term, y^2,
#: is below 1e-16 of it)
_E1_SERIES_BELOW = 1e-8


def _exp1_of_square(y):
    """``E1(y^2)`` for y >= 0, finite for every y > 0: below :data:`_E1_SERIES_BELOW` the
    series ``-euler_gamma - 2 ln y`` (its first omitted term y^2 < 1e-16), where y^2 itself
    underflows to 0 for y < 1e-162 and E1(0) = inf made u(p) infinite (Persson's u grows
    like -ln p as p -> 0: on a 1 um rms surface 85 um at 1e-100 Pa, 125 um at 1e-150 Pa,
    and inf at 1e-200 Pa until round 2, session 37). E1(0) = inf stays (J(0) = inf)."""
    y = np.asarray(y, dtype=float)
    small = (y > 0) & (y < _E1_SERIES_BELOW)
    series = -np.euler_gamma - 2.0 * np.log(np.where(small, y, 1.0))
    return np.where(small, series, scipy.special.exp1(np.where(small, 1.0, y) ** 2))


# -- pure functions on arrays ---------------------------------------------------------------
def area_fraction(rms_gradient, e_star, mean_pressure, kappa=KAPPA_PERSSON):
    """Persson's A*(p) = erf(kappa sqrt(pi)/2 * p / (E* gbar)), Eq. (1) (dimensionless).

    Parameters
    ----------
    rms_gradient : float
        gbar: rms gradient of a surface / rms slope of a profile (-).
    e_star : float
        Composite modulus E* (Pa).
    mean_pressure : float or array
        Nominal mean pressure p (Pa), > 0.
    kappa : float
        Small-load slope, default Persson's sqrt(8/pi) (then the argument is
        ``sqrt(2) p / (E* gbar)``).
    """
    g = check_finite_positive("rms_gradient", rms_gradient)
    e = check_finite_positive("e_star (Pa)", e_star)
    k = check_finite_positive("kappa", kappa)
    p = _pressures(mean_pressure)
    return scipy.special.erf(0.5 * k * np.sqrt(np.pi) * p / (e * g))


def _checked_spectrum(q, power, q2=None):
    """``(q, q2, power)`` of :func:`mean_separation` and :func:`normal_stiffness`, checked
    (1D, one length, q >= 0 increasing, power >= 0; q2 default q^2) and without the
    values that carry no power (:func:`_with_power`)."""
    q = check_real_array("q (wavenumbers)", q, unit="rad/m")
    power = check_real_array("power", power, unit="m^2")
    if q.ndim != 1 or q.shape != power.shape:
        raise InputError(f"q and power must be 1D arrays of the same length, got shapes "
                         f"{q.shape} and {power.shape}")
    if q.min(initial=0.0) < 0 or power.min(initial=0.0) < 0 or np.any(np.diff(q) < 0):
        raise InputError("q (rad/m) must be finite, >= 0 and increasing, and power (m^2) "
                         "finite and >= 0")
    q2 = q * q if q2 is None else check_real_array("q2", q2, unit="rad^2/m^2")
    if q2.shape != q.shape:
        raise InputError(f"q2 must have the shape of q {q.shape}, got {q2.shape}")
    return _with_power(q, q2, power)


def _gap_modes(q, q2, power):
    """``(w_k, weight_k)`` of Eq. (2): ``w = sqrt(2 / m(q))`` (m(q) the cumulative
    gradient moment) and ``weight = |q| C w / 4`` (m per unit J)."""
    w = np.sqrt(2.0 / _cumulative_gradient(q2, power))
    return w, 0.25 * q * power * w


def mean_separation(q, power, e_star, mean_pressure, gamma=GAMMA_DEFAULT, q_min=0.0,
                    q2=None):
    """Persson's mean separation u(p) (m), Eq. (2), from the roughness with |q| > q_min.

    Parameters
    ----------
    q : array
        Wavenumbers |q| of the PSD values (rad/m), increasing.
    power : array
        ``C * weight`` per value: the mean-square height each carries (m^2), >= 0; the
        values without power are left out (as by :func:`persson`: they add nothing to
        Eq. (2)), and a spectrum without any is an :class:`InputError`.
    e_star : float
        E* (Pa).
    mean_pressure : float or array
        Pressure(s) p > 0 (Pa).
    gamma : float
        Persson's elastic-energy factor, in (0, 1].
    q_min : float
        Only the roughness at |q| > q_min counts (Eq. (4) of the critical junction).
    q2 : array, optional
        |q|^2 of each value for the gradient moment m(q) (rad^2/m^2; default q**2; the
        :attr:`~roughfe.surfaces.stats.PowerSpectrum.q2` of a binned surface spectrum).

    Returns
    -------
    ndarray
        u(p) for each pressure (m).
    """
    e = check_finite_positive("e_star (Pa)", e_star)
    gamma = _check_gamma(gamma)
    p = _pressures(mean_pressure)
    q_min = check_finite_nonnegative("q_min (rad/m)", q_min)
    q, q2, power = _checked_spectrum(q, power, q2)
    sel = q > q_min
    q, q2, power = q[sel], q2[sel], power[sel]
    if q.size == 0:
        return np.zeros(p.shape)
    w, weight = _gap_modes(q, q2, power)
    return j_function(np.outer(p, w / e), gamma) @ weight


def normal_stiffness(q, power, e_star, mean_pressure, gamma=GAMMA_DEFAULT, q2=None):
    """Persson's normal contact stiffness K(p) = -dp/du (Pa/m), Eq. (4): the derivative of
    :func:`mean_separation` (same arguments, every |q|), ``p / u0`` at small p.

    At the theory's full contact -du/dp = (2/sqrt(pi)) sum weight exp(-y^2) (...) with
    y = p w / E* underflows to 0 in double precision (every mode closed: u = 0 and
    A* = 1 there too; a 16^2 crop of x3p-2 at 2e11 Pa, E* = 2.3e11 Pa), and K = -dp/du
    is infinite: those pressures get ``inf`` (written null in results.json), not a
    division by zero (whose numpy warning reached the user until round 2, session 31)."""
    e = check_finite_positive("e_star (Pa)", e_star)
    gamma = _check_gamma(gamma)
    p = _pressures(mean_pressure)
    w, weight = _gap_modes(*_checked_spectrum(q, power, q2))
    y = np.outer(p, w / e)
    kernel = np.exp(-y ** 2) * (gamma + 3 * (1 - gamma) * scipy.special.erf(y) ** 2)
    compliance = (2 / np.sqrt(np.pi)) * (kernel @ weight)          # -du/dp (m/Pa)
    return np.divide(p, compliance, out=np.full(p.shape, np.inf), where=compliance > 0)


# -- results ---------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class PerssonResult(ReadOnlyArrays):
    """Persson's theory for one surface at a set of mean pressures (SI).

    Attributes
    ----------
    mean_pressure : ndarray
        p (Pa).
    area_fraction : ndarray
        A*(p), Eq. (1).
    mean_gap : ndarray
        u(p), Eq. (2) (m): separation of the mean planes, comparable with the BEM mean gap.
    stiffness : ndarray
        K(p) = -dp/du, Eq. (4) (Pa/m): the BEM's dp/dDelta of a periodic surface; inf
        at the theory's full contact (u = 0 in double precision:
        :func:`normal_stiffness`).
    rms_gradient : float
        gbar from the PSD (-).
    rms_height : float
        From the PSD (m).
    u0 : float
        Decay length of p ~ exp(-u/u0) at intermediate p, Eq. (3) (m).
    e_star, gamma, kappa : float
        Inputs (Pa, -, -).
    ndim : int
        1 (profile) or 2 (surface).
    references : tuple of str
    """

    mean_pressure: np.ndarray
    area_fraction: np.ndarray
    mean_gap: np.ndarray
    rms_gradient: float
    rms_height: float
    u0: float
    e_star: float
    gamma: float
    kappa: float
    ndim: int
    references: tuple = REFERENCES
    stiffness: np.ndarray = None

    __repr__ = compact_repr

    def __post_init__(self):       # read-only copies: a result never changes
        read_only_arrays(self, copy=True)

    def records(self) -> list:
        """One JSON-safe dict per pressure (keys as in results.json)."""
        return [{"mean_pressure": float(p), "persson_area_fraction": float(a),
                 "persson_mean_gap": float(u), "persson_stiffness": float(k)}
                for p, a, u, k in zip(self.mean_pressure, self.area_fraction, self.mean_gap,
                                      self.stiffness)]


def persson(source, e_star, mean_pressure, *, gamma=GAMMA_DEFAULT,
            kappa=KAPPA_PERSSON) -> PerssonResult:
    """Persson's A*(p), u(p) and K(p) for a surface or profile (or its PSD), Eqs. (1)-(4).

    Parameters
    ----------
    source : Surface or PowerSpectrum
        A surface's PSD is taken with :func:`roughfe.surfaces.stats.power_spectrum`
        (radial average for surfaces; Hann window for non-periodic data).
    e_star : float
        E* (Pa).
    mean_pressure : float or array
        Nominal pressures p > 0 (Pa).
    gamma : float
        Elastic-energy factor of u(p), default 0.45.
    kappa : float
        Small-load slope of A*, default sqrt(8/pi).

    Returns
    -------
    PerssonResult
    """
    psd = _spectrum(source)
    q, q2, power = _arrays(psd)
    p = _pressures(mean_pressure)
    gbar = float(np.sqrt(np.sum(q2 * power)))          # <|grad h|^2>^1/2, every mode
    u = mean_separation(q, power, e_star, p, gamma, q2=q2)
    weight = _gap_modes(q, q2, power)[1]
    u0 = float(2 * gamma / np.sqrt(np.pi) * np.sum(weight))      # Eq. (3)
    return PerssonResult(mean_pressure=p, area_fraction=area_fraction(gbar, e_star, p, kappa),
                         mean_gap=u, rms_gradient=gbar, rms_height=float(np.sqrt(power.sum())),
                         u0=u0, e_star=float(e_star), gamma=float(gamma), kappa=float(kappa),
                         ndim=psd.ndim,
                         stiffness=normal_stiffness(q, power, e_star, p, gamma, q2=q2))
