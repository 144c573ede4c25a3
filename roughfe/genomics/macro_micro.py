"""Macro- and micro-scale roughness of a realisation (thesis Sec. 4.1.1, Alg. 2).

``Z(x) = Z_L(x) + Z_S(x)``: the macro-scale roughness (waviness) ``Z_L`` sums the
chromosomes ``C_n`` whose stiffness curve K_n(p) correlates with the K(p) of the complete
profile by ``c_n > threshold`` (0.95 in the thesis); the micro-scale roughness ``Z_S``
sums the rest. Every curve comes from ``n_t`` far-field displacements up to the
peak-valley amplitude of its own profile (:func:`profile_response`).

Correlation: loading steps or pressure axis
-------------------------------------------
Each chromosome is loaded to its own peak-valley amplitude in the same n_t equal steps
as the complete profile. Alg. 2 takes "the correlation coefficient of y_r and y_n", the
two n_t-point sequences, i.e. K paired step by step (``axis="steps"``, default: the
thesis). With ``axis="pressure"`` the chromosome curve is first rescaled with Eq. (4.2)
to the complete profile's p_max and interpolated at its pressures, so K is compared at
equal pressure as in the design score. Measured on the Table 1 genome (10x, seed 0):
"steps" puts the long wavelengths n <= 9 (all but n = 5 at 0.949) above 0.95 and the
short ones lower, the pattern of Fig. 47; "pressure" gives c_n > 0.9 almost everywhere,
because any two increasing K(p) curves correlate strongly at equal pressure. A constant
curve (K_n, or the complete profile's K) has no defined correlation: c_n is NaN
(:func:`correlation`), which is never above the threshold, so the chromosome is micro;
files and tables write it as null or "nan", not as a number.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..errors import InputError
from ..model import Loading, Material, SweepResult
from ..response import response as contact_response
from ..surfaces.surface import Surface
from .similarity import ResponseCurve, read_curve


STIFFNESS_KINDS = ("fd", "exact")


def top_approach(surface: Surface, kernel: str = "auto", top_fraction: float = 1.0) -> float:
    """The last approach of :func:`profile_sweep` (m): ``top_fraction`` times the
    peak-valley height, or times max h - mean h (full contact) with a periodic kernel."""
    h = surface.heights
    full = h.max() - h.mean() if periodic_approach(surface, kernel) else np.ptp(h)
    return float(top_fraction) * float(full)


def periodic_approach(surface: Surface, kernel: str = "auto") -> bool:
    """True when the BEM solves ``surface`` with the periodic kernel (approaches measured
    up to full contact, max h - mean h)."""
    return bool(surface.periodic and kernel in ("auto", "spectral"))


def profile_sweep(surface: Surface, *, youngs_modulus: float, poisson: float = 0.0,
                  n_steps: int = 20, kernel: str = "auto", stiffness: str = "fd",
                  top_fraction: float = 1.0) -> SweepResult:
    """The BEM sweep behind :func:`profile_response`: ``n_steps`` equal approaches
    ``Delta_j = j/n_t * top`` (:func:`top_approach`: ``max h - min h`` for a profile, the
    thesis) through :func:`roughfe.response.response` (the one response function), with
    the exact per-step stiffness only when ``stiffness`` is ``"exact"``. Parameters as
    :func:`profile_response`."""
    if stiffness not in STIFFNESS_KINDS:
        raise InputError(f"stiffness must be one of {STIFFNESS_KINDS}, got {stiffness!r}")
    if top_fraction == 1.0:
        loading = Loading(n_steps=int(n_steps))
    else:
        top = top_approach(surface, kernel, top_fraction)
        loading = Loading(deltas=tuple(top * np.arange(1, int(n_steps) + 1) / int(n_steps)))
    return contact_response(surface, Material(youngs_modulus, poisson), loading,
                            kernel=kernel, compute_stiffness=stiffness == "exact")


def sweep_curve(sweep: SweepResult, stiffness: str = "fd") -> ResponseCurve:
    """K(p) (Pa/m) and A(p) of a sweep at its steps with p > 0: K = dp/dDelta by central
    differences over the steps (``"fd"``) or exact per step (``"exact"``)."""
    p = np.asarray(sweep.mean_pressure, dtype=float)
    k = np.asarray(sweep.stiffness if stiffness == "exact" else sweep.stiffness_fd, dtype=float)
    keep = p > 0
    return ResponseCurve(p[keep], k[keep], np.asarray(sweep.area_fraction, dtype=float)[keep])


def profile_response(surface: Surface, *, youngs_modulus: float, poisson: float = 0.0,
                     n_steps: int = 20, kernel: str = "auto", stiffness: str = "fd",
                     top_fraction: float = 1.0) -> ResponseCurve:
    """K(p) and A(p) of a profile by the BEM at ``n_steps`` equal approaches (Sec. 4.2.1).

    Parameters
    ----------
    surface : Surface
        The rigid rough profile (heights in m).
    youngs_modulus, poisson : float
        E (Pa) and nu of the elastic body.
    n_steps : int
        n_t: approaches ``Delta_j = j/n_t * (max h - min h)``, j = 1..n_t.
    kernel : str
        BEM influence kernel (``"auto"``: ``"strip"`` for a non-periodic profile).
    stiffness : {"fd", "exact"}
        K = dp/dDelta (Eq. 2.7) by central differences of p over the n_t approaches
        (``"fd"``, as the thesis computes it from its 20 steps) or the exact incremental
        stiffness of the contact set at each step (``"exact"``). On a profile the exact
        K jumps whenever a node enters the contact set; the difference quotient over a
        step averages those jumps. Measured on the Sobol database: the best Alg. 3 score
        for y_t1 is 0.89 with "fd" and 0.83 with "exact". Both are invariant under the
        Eq. (4.2) rescaling.
    top_fraction : float
        The last approach is ``top_fraction`` times the default one (:func:`top_approach`);
        surface databases stop before the full contact of a periodic surface.

    Returns
    -------
    ResponseCurve
        Mean pressure (Pa), stiffness K (Pa/m) and area fraction at the steps with p > 0.
    """
    sweep = profile_sweep(surface, youngs_modulus=youngs_modulus, poisson=poisson,
                          n_steps=n_steps, kernel=kernel, stiffness=stiffness,
                          top_fraction=top_fraction)
    return sweep_curve(sweep, stiffness)


CORRELATION_AXES = ("steps", "pressure")


def is_flat(z, scale: float = 0.0) -> bool:
    """True when heights are constant to round-off: such a field has no contact curve.

    Round-off is judged against ``scale`` (m, e.g. the largest height of the complete
    surface a chromosome belongs to) as well as the field itself: a chromosome whose
    waves cancel (3e-22 m on a 2e-6 m profile) is round-off of the surface, which its
    own maximum could never show."""
    ref = max(float(np.max(np.abs(z))), float(scale), 1e-300)
    return bool(np.ptp(z) <= 1e-12 * ref)


def correlation(reference: ResponseCurve, curve: ResponseCurve, quantity: str = "K",
                axis: str = "steps") -> float:
    """c_n of Alg. 2: Pearson coefficient of two curves (see the module notes).

    ``axis="steps"``: the values paired step by step (equal step counts needed; curves
    of different lengths fall back to the pressure axis). ``axis="pressure"``: ``curve``
    rescaled to the reference p_max (Eq. 4.2) and read at its pressures by the design's
    rule (:func:`roughfe.genomics.similarity.read_curve`: linear between computed
    points, the end values held beyond them).

    Returns
    -------
    float
        c_n in [-1, 1]; NaN when either curve is constant (its standard deviation is 0:
        the Pearson coefficient is 0/0, undefined). Earlier versions returned 0.0 here,
        which read as "uncorrelated". NaN compares False with any
        threshold (:func:`classify` makes the chromosome micro); a caller that needs a
        number must test ``np.isfinite``.
    """
    if axis not in CORRELATION_AXES:
        raise InputError(f"axis must be one of {CORRELATION_AXES}, got {axis!r}")
    y_r = reference.values(quantity)
    if axis == "steps" and curve.pressure.size == reference.pressure.size:
        y_n = curve.values(quantity)
    else:
        c = curve.to_target_range(reference.p_max)
        y_n = read_curve(reference.pressure, c.pressure, c.values(quantity))
    if np.ptp(y_r) == 0 or np.ptp(y_n) == 0:
        return float("nan")            # 0/0: a constant curve has no correlation
    return float(np.corrcoef(y_r, y_n)[0, 1])


@dataclass(frozen=True, eq=False)
class MacroMicroResult:
    """Result of Alg. 2 for one realisation.

    Fields
    ------
    chromosomes : ndarray of int
        Chromosome indices n of the realisation (n_s..n_f).
    curve : ResponseCurve
        y_r = K(p), A(p) of the complete profile.
    chromosome_curves : tuple of ResponseCurve
        y_n of every chromosome (same order as ``chromosomes``).
    corr_k, corr_a : ndarray
        c_n for K(p) (the classification) and for A(p) (reported, Fig. 47); NaN where
        a curve is constant (undefined, micro), 0 for a chromosome that is round-off.
    threshold : float
    macro, micro : tuple of int
        Chromosome indices with ``corr_k > threshold`` (Z_L) and the others (Z_S).
    success, message, nit : scipy-like report (nit = number of BEM sweeps).
    """

    chromosomes: np.ndarray
    curve: ResponseCurve
    chromosome_curves: tuple
    corr_k: np.ndarray
    corr_a: np.ndarray
    threshold: float
    macro: tuple
    micro: tuple
    success: bool = True
    message: str = "classified"
    nit: int = 0


def classify(full: ResponseCurve, chromosome_curves, chromosomes, threshold: float = 0.95,
             axis: str = "steps", flat=None) -> MacroMicroResult:
    """Steps 4 and 6 of Alg. 2 from computed curves: c_n and the macro/micro split.

    An undefined c_n (NaN: a constant curve, :func:`correlation`) is not above the
    threshold: that chromosome is micro.

    ``flat`` (optional, one bool per chromosome): chromosomes whose realisation is
    round-off of the complete profile (waves that cancel) take c_n = 0, micro: Alg. 2
    loads each chromosome to its own peak-to-valley, so its curve does not see that the
    chromosome is nothing (a cancelled one was classified macro with c_n = 0.97-0.99)."""
    if not (0.0 < float(threshold) < 1.0):
        raise InputError(f"threshold must lie in (0, 1), got {threshold!r}")
    chromosomes = np.asarray(chromosomes, dtype=int)
    curves = tuple(chromosome_curves)
    if len(curves) != chromosomes.size:
        raise InputError(f"{len(curves)} chromosome curves for {chromosomes.size} chromosomes")
    ck = np.array([correlation(full, c, "K", axis) for c in curves])
    ca = np.array([correlation(full, c, "A", axis) for c in curves])
    if flat is not None:
        ck[np.asarray(flat, bool)] = 0.0
        ca[np.asarray(flat, bool)] = 0.0
    macro = tuple(int(n) for n, c in zip(chromosomes, ck) if c > threshold)
    micro = tuple(int(n) for n, c in zip(chromosomes, ck) if not c > threshold)
    return MacroMicroResult(chromosomes, full, curves, ck, ca, float(threshold), macro, micro,
                            True, f"{len(macro)} macro, {len(micro)} micro chromosomes",
                            len(curves) + 1)


def classify_profiles(total: Surface, parts, chromosomes, response: Callable[[Surface], ResponseCurve],
                      threshold: float = 0.95, axis: str = "steps") -> MacroMicroResult:
    """Alg. 2 on explicit profiles: ``total`` and the chromosome profiles ``parts``.

    ``response(surface) -> ResponseCurve`` runs the n_t-step contact solution (Steps 1, 3).
    """
    full = response(total)
    curves = [response(p) for p in parts]
    scale = float(np.max(np.abs(total.heights)))
    return classify(full, curves, chromosomes, threshold, axis,
                    flat=[is_flat(p.heights, scale) for p in parts])


def macro_micro(genome, settings, *, response=None) -> MacroMicroResult:
    """Alg. 2 for a genome realised with ``settings`` (a ``DatabaseSettings``).

    Parameters
    ----------
    genome : roughfe.genomics.genome.Genome
    settings : roughfe.genomics.database.DatabaseSettings
        Length L (m), nodes N, dim (profile or periodic surface,
        :func:`roughfe.genomics.periodic.realization`), E (Pa), nu, n_t, threshold, kernel.
    response : callable, optional
        ``Surface -> ResponseCurve``; default :func:`profile_response` with ``settings``.
    """
    from .periodic import realization
    if response is None:
        def response(s):
            return profile_response(s, **settings.response_options())
    total = realization(genome, settings.length, settings.n_nodes, settings.dim)
    ns = np.asarray(total.metadata["chromosomes"], dtype=int)
    parts = [realization(genome, settings.length, settings.n_nodes, settings.dim, [n])
             for n in ns]
    return classify_profiles(total, parts, ns, response, settings.threshold, settings.correlation)
