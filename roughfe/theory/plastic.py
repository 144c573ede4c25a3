"""Persson's elastoplastic contact: the elastic and the plastic area of real contact of a
surface pressed on a perfectly plastic interface of hardness H (Pa), from its PSD (SI).

Theory (Persson 2001, PRL 87:116101 and J. Chem. Phys. 115:3840, Sec. on plastic
yield; Persson 2006, Surf. Sci. Rep. 61:201, Sec. 3.4). The stress distribution P(sigma,
zeta) of the contact obeys the diffusion equation of the elastic theory,
dP/dzeta = f(zeta) d2P/dsigma2 with f dzeta = (pi/4) E*^2 q^3 C(q) dq, from
P(sigma, 1) = delta(sigma - p), now with two absorbing boundaries: P(0) = 0 (contact
lost) and P(H) = 0 (the point yields and stays at sigma = H). At full magnification the
"diffusion time" is

    tau = int f dzeta = <sigma^2> / 2 = (E* gbar)^2 / 8       (gbar: rms gradient),

the same as in :mod:`roughfe.theory.persson` (G = tau / p^2 there; <sigma^2> = (E*/2)^2
gbar^2 is the variance of the full-contact stress). On 0 <= sigma <= H,

    P(sigma) = (2/H) sum_n sin(k_n sigma) sin(k_n p) exp(-k_n^2 tau),   k_n = n pi / H,

so that, with x = pi p / H and s = tau / H^2,

    A_el / A0 = (2/pi) sum_n (1 - (-1)^n) sin(n x) / n exp(-n^2 pi^2 s),            (1)
    A_pl / A0 = p / H - (2/pi) sum_n (-1)^(n+1) sin(n x) / n exp(-n^2 pi^2 s).      (2)

Eq. (2) is the load balance p = int_0^H sigma P dsigma + H A_pl / A0 (the yielded area
carries H, the area that left contact carries nothing), as in Persson's papers (and the
constant-hardness case of Almqvist & Persson 2025, who compare it with a BEM of the same
perfectly plastic interface). Limits: H -> inf gives A_el = erf(sqrt(2) p / (E* gbar)),
Eq. (1) of :mod:`roughfe.theory.persson`, and A_pl -> 0; E* gbar / H -> inf gives
A_pl -> p / H (rigid-plastic). The sine series converges fast where s is not small; for
small s the method of images gives the same P as a sum of Gaussians of variance 2 tau
(sources at p + 2kH, sinks at -p + 2kH; Xu, Li & Mulvihill 2022), whose moments on
[0, H] are closed forms in erf: :func:`elastoplastic_area` takes the images below
``IMAGE_BELOW`` and the series above (tested to agree to 1e-12 on both sides).

Like the elastic theory it is a theory of a loading from the virgin surface: it has no
unloading branch. Measured against the BEM (``roughfe.bem.solve_contact(hardness=)``,
256^2 self-affine surfaces, docs/theory/07_adhesion_persson.md): where most of the contact
flows (H <= 0.25 E* gbar) the total and plastic areas agree within 12 %; near
H = E* gbar the theory's plastic area is 2-7x the BEM's, as its Gaussian stress tail
above 2 sigma_rms is 1.5-4x the BEM's elastic one.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.special

from ..errors import InputError, check_finite_positive
from ..frozen import ReadOnlyArrays, compact_repr, read_only_arrays
from .persson import _arrays, _pressures, _spectrum

#: s = tau / H^2 below which the image sum is used, above it the sine series (at
#: s = 0.02 the series needs 16 terms to 1e-17, the images 7 pairs, k = -3..3)
IMAGE_BELOW = 0.02

REFERENCES = (
    "Persson B.N.J. (2001) Phys. Rev. Lett. 87:116101 (elastoplastic contact)",
    "Persson B.N.J. (2001) J. Chem. Phys. 115:3840-3861 (P(sigma) with yield)",
    "Persson B.N.J. (2006) Surf. Sci. Rep. 61:201-227 (Sec. 3.4)",
    "Xu Y., Li X., Mulvihill D.M. (2022) arXiv:2208.02665 (Gaussian image form)",
)


@dataclass(frozen=True, eq=False)
class ElastoplasticArea:
    """Persson's elastoplastic contact at a set of mean pressures (SI).

    Attributes
    ----------
    mean_pressure : ndarray
        p (Pa).
    area_fraction : ndarray
        (A_el + A_pl) / A0: the real contact area, as the BEM's ``area_fraction``.
    elastic_area_fraction, plastic_area_fraction : ndarray
        A_el / A0, Eq. (1), and A_pl / A0, Eq. (2) (the BEM's ``plastic_area_fraction``).
    hardness, e_star : float
        H and E* (Pa).
    rms_gradient : float
        gbar of the PSD (-).
    references : tuple of str
    """

    mean_pressure: np.ndarray
    area_fraction: np.ndarray
    elastic_area_fraction: np.ndarray
    plastic_area_fraction: np.ndarray
    hardness: float
    e_star: float
    rms_gradient: float
    references: tuple = REFERENCES

    __repr__ = compact_repr

    def __post_init__(self):
        read_only_arrays(self, copy=True)


def stress_distribution(sigma, mean_pressure, diffusion, hardness, terms=None):
    """P(sigma) (1/Pa) on 0 <= sigma <= H by the sine series (module docstring):
    ``diffusion`` = tau (Pa^2), ``terms`` (default: until exp(-k_n^2 tau) < 1e-17)."""
    sigma = np.asarray(sigma, float)
    n = np.arange(1, (terms or _series_terms(diffusion / hardness ** 2)) + 1)
    k = n * np.pi / hardness
    modes = np.sin(k * mean_pressure) * np.exp(-k ** 2 * diffusion)
    return (2.0 / hardness) * (np.sin(np.multiply.outer(sigma, k)) @ modes)


def _series_terms(s):
    """Terms of the sine series for exp(-n^2 pi^2 s) < 1e-17 (at least 1)."""
    return int(np.ceil(np.sqrt(np.log(1e17) / (np.pi ** 2 * s)))) + 1


def _series(x, s):
    """Eqs. (1), (2) without the p/H term: (A_el, sum (-1)^(n+1) sin(n x)/n e_n), x array."""
    n = np.arange(1, _series_terms(s) + 1)
    e = np.exp(-(n * np.pi) ** 2 * s) / n
    sn = np.sin(np.multiply.outer(x, n))
    elastic = (2 / np.pi) * (sn @ ((1 - (-1.0) ** n) * e))
    alternating = sn @ ((-1.0) ** (n + 1) * e)
    return elastic, alternating


def _images(p, hardness, std):
    """(A_el, int_0^H sigma P dsigma) by the method of images: P = sum_k g(sigma - p -
    2kH) - g(sigma + p - 2kH), g the normal density of standard deviation ``std``."""
    k = np.arange(-(2 + int(np.ceil(4 * std / hardness))), 3 + int(np.ceil(4 * std / hardness)))
    with np.errstate(over="ignore"):     # a hardness near the float limit: far images inf
        c_plus = p[:, None] + 2 * k * hardness
        c_minus = -p[:, None] + 2 * k * hardness

    def moments(c):      # int_0^H g(sigma - c) dsigma and int_0^H sigma g(sigma - c) dsigma
        far = ~np.isfinite(c)                     # an image at infinity carries nothing
        c = np.where(far, 0.0, c)
        hi, lo = (hardness - c) / std, -c / std
        mass = 0.5 * (scipy.special.erf(hi / np.sqrt(2)) - scipy.special.erf(lo / np.sqrt(2)))
        dens = (np.exp(-lo ** 2 / 2) - np.exp(-hi ** 2 / 2)) / np.sqrt(2 * np.pi)
        return np.where(far, 0.0, mass), np.where(far, 0.0, c * mass + std * dens)

    with np.errstate(over="ignore"):     # (H / std)^2 beyond the float range: exp(-inf) = 0
        m0p, m1p = moments(c_plus)
        m0m, m1m = moments(c_minus)
    return (m0p - m0m).sum(axis=1), (m1p - m1m).sum(axis=1)


def elastoplastic_area(source, e_star, mean_pressure, hardness) -> ElastoplasticArea:
    """Persson's elastic and plastic area of real contact, Eqs. (1)-(2) (module docstring).

    Parameters
    ----------
    source : Surface or PowerSpectrum
        As in :func:`roughfe.theory.persson.persson` (only its rms gradient enters).
    e_star : float
        E* (Pa).
    mean_pressure : float or array
        Nominal pressures 0 < p < H (Pa).
    hardness : float
        Indentation hardness H (Pa), the cap of the BEM's ``hardness``.

    Returns
    -------
    ElastoplasticArea
    """
    e = check_finite_positive("e_star (Pa)", e_star)
    H = check_finite_positive("hardness (Pa, the yield pressure of the interface)", hardness)
    p = _pressures(mean_pressure)
    if np.any(p >= H):
        raise InputError(f"mean_pressure must be below the hardness {H:.6g} Pa (at p = H "
                         f"everything flows), got {mean_pressure!r}")
    _, q2, power = _arrays(_spectrum(source))
    gbar = float(np.sqrt(np.sum(q2 * power)))
    tau = (e * gbar) ** 2 / 8.0
    s = (np.sqrt(tau) / H) ** 2       # H ** 2 overflows a float beyond 1.3e154 Pa
    if s < IMAGE_BELOW:
        elastic, first = _images(p, H, np.sqrt(2 * tau))
        plastic = (p - first) / H
    else:
        elastic, alternating = _series(np.pi * p / H, s)
        plastic = p / H - (2 / np.pi) * alternating
    elastic = np.clip(elastic, 0.0, 1.0)
    plastic = np.clip(plastic, 0.0, 1.0)
    return ElastoplasticArea(mean_pressure=p, area_fraction=elastic + plastic,
                             elastic_area_fraction=elastic, plastic_area_fraction=plastic,
                             hardness=H, e_star=e, rms_gradient=gbar)


#: ``"elastoplastic"`` of the ``persson`` block of a run with a hardness
ELASTOPLASTIC_NOTE = (
    "Persson's elastoplastic theory (hardness H as the yield boundary of P(sigma)): "
    "persson_elastoplastic_area_fraction (A_el + A_pl) and persson_plastic_area_fraction "
    "(A_pl) on each step of the first loading (None on unloading and after the load first "
    "falls: the theory has no unloading branch). Measured against the BEM on 256^2 "
    "self-affine surfaces: within 12 % where most of the contact flows (H <= 0.25 E* "
    "gbar); near H = E* gbar the theory's plastic area is 2-7x the BEM's "
    "(docs/theory/07_adhesion_persson.md)")


def first_loading(pressures, unloading, hardness):
    """Per step (in path order): it is on the first loading from the virgin surface, the
    one load path of a theory with no unloading branch: the mean pressure (Pa or None)
    has not yet fallen, no step so far is flagged ``unloading``, and 0 < p < H (Pa)."""
    ok, peak, fell = [], 0.0, False
    for p, down in zip(pressures, unloading):
        fell = fell or bool(down) or (p is not None and np.isfinite(p) and p < peak)
        good = p is not None and np.isfinite(p) and 0 < p < hardness and not fell
        peak = max(peak, p) if good else peak
        ok.append(good)
    return ok


def beside_elastoplastic(source, e_star, pressures, unloading, hardness):
    """The elastoplastic areas of :func:`elastoplastic_area` beside a load path.

    ``pressures`` (Pa or None) and ``unloading`` (bool) per step, in path order. The
    theory is that of a first loading: a step gets it while the mean pressure has not yet
    fallen (and is not flagged as unloading) and 0 < p < H; the others get None.
    Returns ``(records, info)``: per step a dict with ``persson_elastoplastic_area_fraction``
    and ``persson_plastic_area_fraction``, and the ``"elastoplastic"`` facts (H, the
    note, references)."""
    H = check_finite_positive("hardness (Pa, the yield pressure of the interface)", hardness)
    ok = first_loading(pressures, unloading, H)
    theory = (elastoplastic_area(source, e_star, [p for p, k in zip(pressures, ok) if k], H)
              if any(ok) else None)
    records, j = [], 0
    for k in ok:
        records.append({
            "persson_elastoplastic_area_fraction":
                float(theory.area_fraction[j]) if k else None,
            "persson_plastic_area_fraction":
                float(theory.plastic_area_fraction[j]) if k else None})
        j += k
    info = {"hardness": H, "note": ELASTOPLASTIC_NOTE, "references": list(REFERENCES)}
    return records, info
