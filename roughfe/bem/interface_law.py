"""Interface laws of adhesion (SI): Maugis-Dugdale and exponential, per unit area of the
gap g >= 0, ``phi(0) = -w`` (w the work of adhesion, J/m^2), ``phi(inf) = 0``; used by
:mod:`roughfe.bem.adhesion`.

* Maugis-Dugdale (``"md"``): a constant attraction sigma0 up to the range h0,
  ``w = sigma0 h0``; ``phi = -w + sigma0 g`` for g < h0, 0 beyond (Maugis 1992). The
  kink at h0 is smoothed by a linear ramp of the traction from sigma0 to 0 over
  ``[h0 (1 - s/2), h0 (1 + s/2)]`` (s = ``smoothing``, default 0.05), symmetric about h0
  so that ``int phi' dg = sigma0 h0 = w`` is kept exactly: a quasi-Newton method cannot
  converge on a traction that jumps; the effect on the pull-off force is O(s^2).
* exponential (``"exp"``): ``phi = -w exp(-g / rho)``, traction ``(w/rho) exp(-g/rho)``,
  range rho, peak traction sigma0 = w/rho.

Cell-averaged law (Maugis-Dugdale; ``roughfe.bem.adhesion.solve_adhesive(..., cell_average=True)``, the
default): the traction step at h0 ends the Dugdale zone inside one cell, and sampling
the law at the cell centre puts the whole cell in or out of the zone: a first-order
error in the attractive force that made the pull-off converge slowly with the number of
cells in the zone (+10 / +3.1 / +2.4 % at 2.2 / 4.1 / 7.7 cells, lambda = 2). Each cell
instead carries the average of the law over the cell, with the gap taken linear across
it: uniform over ``g -+ delta``, ``delta = |grad g| dx / 2`` (central differences; in 2D
the uniform spread with the variance of the linear field), which is the ramp above with
the half-width ``max(delta, s h0 / 2)`` (at most h0): w is kept exactly and the zone end
is located inside the cell. delta is taken from the previous state and updated after
each converged solve (at most ``roughfe.bem.adhesive_minimise.MAX_SPREAD_PASSES``
solves; again only when it moved by more than 10 % of the ramp on a cell in the ramp).

Resolution: the law acts over a cohesive (process) zone at the edge of each contact
patch, of length ``(pi/4) E* w / sigma0^2`` at a crack front (the Dugdale-Barenblatt
strip; :meth:`AdhesionLaw.process_zone`). When it is far below the grid spacing each
cell is an independent bistable spring: the pull-off and the hysteresis then depend on
the grid and on the steps of the continuation, and :func:`check_resolution` warns below
the zone the law needs on the grid (:meth:`AdhesionLaw.resolution_cells`: one spacing
for the exponential law on a surface, three for Maugis-Dugdale, more on profiles and
where summits stand off the grid by more than the ramp)
(:class:`~roughfe.errors.ResolutionWarning`). Measured on a rough 32^2 periodic contact
(docs/theory/07_adhesion_persson.md, "The continuation's predictor and the process
zone"): with the zone at 3.4 and 0.42 grid spacings the pull-off does not depend on the
step or on the predictor of the continuation; at 0.068 it scatters by +-5 %, at 7e-4 by
+-40 % (-3.5 to -8.4 MPa) with no convergence down to 1/128 of the step. (Up to round 2,
session 21 the zone was written (pi/8) E* w / sigma0^2 with a threshold of 0.5: half the
length, the same criterion.)
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import (InputError, ResolutionWarning, check_finite_positive,
                      check_in_interval)

LAWS = ("md", "exp")

#: A process zone shorter than this many grid spacings is a ResolutionWarning for the
#: exponential law on a square cell of a surface: below about one spacing (0.88) the
#: elastic stiffness of one cell, E* / (1.12 dx) (its own displacement under a uniform
#: pressure on it), falls below the peak stiffness of the exponential law,
#: sigma0 / rho = (pi/4) E* / zone, so every cell can snap on its own. Other laws and
#: profiles: :meth:`AdhesionLaw.resolution_cells`
PROCESS_ZONE_CELLS = 1.0
#: The centre displacement of a square cell of a surface under a uniform pressure p on
#: it, in units of p dx / E* (the influence operator's diagonal H_ii E* / dx: 1.12 with
#: the Love kernel, 1.10-1.12 with the periodic spectral one)
SQUARE_CELL_COMPLIANCE = 1.12


@dataclass(frozen=True)
class AdhesionLaw:
    """Interface law of adhesion (SI).

    Parameters
    ----------
    kind : {"md", "exp"}
        Maugis-Dugdale or exponential (module docstring).
    work : float
        Work of adhesion w > 0 (J/m^2).
    range : float
        h0 (md) or rho (exp) > 0 (m).
    smoothing : float
        md only: relative width s of the traction ramp about h0, 0 <= s < 1.
    """

    kind: str
    work: float
    range: float
    smoothing: float = 0.05

    def __post_init__(self):
        if self.kind not in LAWS:
            raise InputError(f"adhesion law must be one of {LAWS}, got {self.kind!r}")
        object.__setattr__(self, "work", check_finite_positive(
            "work of adhesion w (J/m^2)", self.work))
        object.__setattr__(self, "range", check_finite_positive(
            "range of adhesion (m)", self.range))
        object.__setattr__(self, "smoothing", check_in_interval(
            "smoothing (the Maugis-Dugdale ramp, a fraction of the range)", self.smoothing,
            0, 1, "left"))
        with np.errstate(over="ignore", under="ignore"):   # the process zone takes sigma0^2
            sigma0 = np.float64(self.work) / np.float64(self.range)
            if not 0.0 < sigma0 * sigma0 < np.inf:         # (range 1e308: ZeroDivisionError)
                raise InputError(f"the law's traction w / range = {float(sigma0):.3g} Pa (w = "
                                 f"{self.work!r} J/m^2, range = {self.range!r} m) is beyond "
                                 f"the floating-point range: give w in J/m^2 and the range "
                                 f"in m")

    @property
    def max_traction(self) -> float:
        """sigma0 = w / range (Pa): the Dugdale stress or the peak exponential traction."""
        return self.work / self.range

    def _ramp(self, spread=None):
        half = 0.5 * self.smoothing * self.range
        if spread is not None:        # ufuncs: np.clip with array bounds is slow here
            half = np.minimum(np.maximum(spread, half), self.range)
        return self.range - half, self.range + half

    def process_zone(self, e_star: float) -> float:
        """Length (m) of the law's cohesive zone at a crack front, ``(pi/4) E* w /
        sigma0^2`` (``e_star`` the pair's E* in Pa): the length over which the traction
        falls from sigma0 to 0 at the edge of an adhesive patch in the JKR-like limit.

        The Dugdale-Barenblatt strip: a uniform traction sigma0 over a length d cancels a
        stress intensity K = sigma0 sqrt(8 d / pi), so d = (pi/8) (K / sigma0)^2; at the
        edge of a contact between a rigid and an elastic body (or two, through E*) the
        energy release rate is G = K^2 / (2 E*), and G = w at the front gives
        d = (pi/4) E* w / sigma0^2. The form (pi/8) E* w / sigma0^2 (used here up to
        round 2, session 21) takes G = K^2 / E*, a crack inside one body of modulus E*:
        half the length. Measured on Johnson's adhesive sinusoid (tests)."""
        return float(np.pi / 4 * e_star * self.work / self.max_traction ** 2)

    def resolution_cells(self, cell_compliance: float, ndim: int,
                         relief: float | None = None) -> float:
        """The least process zone, in grid spacings, that resolves this law on a grid
        whose cell has the self-compliance ``cell_compliance`` (its centre displacement
        under a uniform pressure on it, in p dx / E*: the influence operator's diagonal
        H_ii E*/dx; :data:`SQUARE_CELL_COMPLIANCE` on a surface, 3-7 on a profile,
        growing as log n) in ``ndim`` dimensions; ``relief`` (m, surfaces,
        :func:`cell_relief`; None: smooth) how far the heights stand off their
        neighbours.

        * exponential: c / 1.12 (:data:`PROCESS_ZONE_CELLS` = 1.0 on a square cell of a
          surface). The cell's stiffness E*/(c dx) must exceed the law's peak stiffness
          sigma0/rho = (pi/4) E*/zone: zone >= (pi/4) c dx = 0.79 c dx, with a margin. Measured (round 2, session 22): the pull-off of Maugis'
          sphere 1.25 % off its grid limit at 1.0 cell, branches that retrace (hysteresis
          < 1e-5 of the pull-off); Johnson's sinusoid (a profile, c = 3.3-5.9) +0.5 % at
          2 cells and 2 % hysteresis, +0.1 % and none at 4.
        * Maugis-Dugdale on a surface: 2.7 c (3 cells). Its ramp is 1/s times stiffer
          than the exponential law, but the cell spread of the step (module docstring)
          widens it where the gap varies across a cell: measured on Maugis' sphere
          (lambda 1-3, s = 0.05-0.5), +5.6 % pull-off and 6 % hysteresis at 1.0 cell,
          +0.9-1.0 % and 0.7-1.5 % at 3.1-3.5 cells, the same for every s <= 0.2.
          Where the heights stand off their neighbours by more than half the ramp
          (``relief``, :func:`cell_relief`, above ``max(s, 0.05) h0 / 2``) the cell
          average, linear across a cell, cannot widen the ramp on a summit: there it asks
          ``max(2.7, (pi/4) / max(s, 0.05)) c``, the cell's stiffness E*/(c dx) at least
          the ramp's sigma0/(s h0). Measured (round 2, session 31) on a 192^2 window of
          di-1.di (relief 0.27 nm, h0 = 2 nm, 13.5 zone cells) and its Fourier
          refinements: the approach at which a patch jumps in is 0.32 / 0.21 / 0.15 nm
          late at s = 0.05 / 0.2 / 0.5 on the measured grid, converged on the 2x grid
          (27 cells) for every s; Maugis' sphere (relief < 0.012 h0) jumps in where its
          apex meets the ramp's outer edge at every grid from 1.2 cells.
        * Maugis-Dugdale on a profile: max(3.2, 0.6 / max(s, 0.05)) c. On Johnson's
          sinusoid the hysteresis where the state is unique (positive approach) falls
          below 1 % of the pull-off at about 16, 20-32, 32 and 64 cells for s = 0.5, 0.2,
          0.1, 0.05 (c = 4-5.6 there): the ramp's own stiffness sets it. Below s = 0.05
          the cell spread sets the ramp at these resolutions (s = 0 and 0.05 gave the
          same sweeps at 1024-4096 cells), hence the floor (a reviewer found 0.6 / s
          asking for 3e12 cells at s = 0). With ``cell_average=False`` (the law sampled
          at the cell centres) more cells are needed than this.
        """
        c = float(cell_compliance)
        if self.kind == "exp":
            return PROCESS_ZONE_CELLS / SQUARE_CELL_COMPLIANCE * c
        s = max(self.smoothing, 0.05)
        if ndim >= 2:
            summits = relief is not None and relief > 0.5 * s * self.range
            return max(2.7, np.pi / 4 / s) * c if summits else 2.7 * c
        return max(3.2, 0.6 / s) * c

    def cell_ramp(self, spread):
        """``(g1, width)`` (m, per point): the start and width of the ramp that the
        Dugdale step becomes under the cell spread ``spread`` (:meth:`evaluate`), for a
        caller that evaluates the law many times at one spread."""
        g1, g2 = self._ramp(spread)
        return g1, np.maximum(g2 - g1, 1e-300)

    def evaluate(self, g, spread=None, *, ramp=None):
        """``(phi(g), phi'(g))``: the potential (J/m^2; -w at contact, 0 far away) and
        the magnitude of the attractive traction (Pa, >= 0), in one pass.

        ``spread`` (m, per point, md only): the cell average of the law when the gap
        varies linearly across a cell, uniformly over ``g -+ spread``: the Dugdale step
        at h0 becomes a ramp of half-width ``max(spread, s h0 / 2)`` (at most h0), which
        keeps ``int phi' dg = w`` (module docstring, "Cell-averaged law"). ``ramp``
        (md only): that ramp from :meth:`cell_ramp`, instead of ``spread``."""
        g = np.asarray(g, float)
        w, s0 = self.work, self.max_traction
        if self.kind == "exp":
            e = np.exp(-g / self.range)
            return -w * e, s0 * e
        if ramp is None:
            if spread is None and self.smoothing == 0.0:     # the sharp Dugdale step
                near = g < self.range
                return np.where(near, s0 * g - w, 0.0), np.where(near, s0, 0.0)
            ramp = self.cell_ramp(spread)
        g1, width = ramp
        t = np.subtract(g, g1, out=np.empty(np.broadcast(g, g1).shape))  # clipped to
        # [0, width] in place below (one pass each; also for a scalar g)
        np.maximum(t, 0.0, out=t)
        np.minimum(t, width, out=t)
        r = t / width
        phi = np.minimum(g, g1)
        phi += t
        t *= r
        t *= 0.5
        phi -= t
        phi *= s0
        phi -= w
        r *= -s0
        r += s0
        return phi, r

    def potential(self, g):
        """phi(g) (J/m^2), -w at contact, 0 far away."""
        return self.evaluate(g)[0]

    def traction(self, g):
        """phi'(g) (Pa) >= 0: the magnitude of the attractive traction at gap g."""
        return self.evaluate(g)[1]

    def describe(self) -> dict:
        """JSON-safe parameters (SI)."""
        return {"law": self.kind, "work_of_adhesion": self.work, "range": self.range,
                "max_traction": self.max_traction,
                "smoothing": self.smoothing if self.kind == "md" else None}


def cell_relief(heights) -> float | None:
    """The rms (m) of the heights less the mean of their four neighbours (interior
    points of a surface; None for a profile): how far summits and pits stand off the
    grid around them, the measure of :meth:`AdhesionLaw.resolution_cells` (0.27 nm on
    di-1.di, 0.10 / 0.029 nm on its 2x / 4x Fourier refinements; 0.012 h0 on Maugis'
    sphere at 48^2)."""
    h = np.asarray(heights, float)
    if h.ndim < 2 or min(h.shape) < 3:
        return None
    d = h[1:-1, 1:-1] - 0.25 * (h[2:, 1:-1] + h[:-2, 1:-1] + h[1:-1, 2:] + h[1:-1, :-2])
    return float(np.sqrt(np.mean(d * d)))


def resolution(law: AdhesionLaw, e_star: float, spacing,
               cell_compliance: float | None = None, relief: float | None = None) -> dict:
    """The law's process zone against the grid, JSON-safe (the provenance a result file
    keeps beside the warning of :func:`check_resolution`): ``process_zone`` (m,
    :meth:`AdhesionLaw.process_zone`), ``grid_spacing`` (m, the largest of ``spacing``,
    one per axis), ``process_zone_cells`` (their ratio), ``cell_compliance`` (the
    operator's diagonal H_ii E*/dx; default :data:`SQUARE_CELL_COMPLIANCE` on a surface,
    required for a profile), ``cell_relief`` (m, :func:`cell_relief`, or None),
    ``threshold_cells`` (:meth:`AdhesionLaw.resolution_cells`) and ``resolved``
    (ratio >= threshold)."""
    zone = law.process_zone(e_star)
    spacing = np.atleast_1d(np.asarray(spacing, float))
    dx, ndim = float(np.max(spacing)), spacing.size
    if cell_compliance is None:
        if ndim < 2:
            raise InputError("the resolution of a law on a profile needs the cell's "
                             "compliance (the influence operator's diagonal H_ii E*/dx)")
        cell_compliance = SQUARE_CELL_COMPLIANCE
    relief = None if relief is None else float(relief)
    need = law.resolution_cells(cell_compliance, ndim, relief)
    return {"process_zone": zone, "grid_spacing": dx, "process_zone_cells": zone / dx,
            "cell_compliance": float(cell_compliance), "cell_relief": relief,
            "threshold_cells": need,
            "resolved": bool(zone >= need * dx)}


def check_resolution(law: AdhesionLaw, e_star: float, spacing,
                     cell_compliance: float | None = None,
                     relief: float | None = None) -> bool:
    """Warn (:class:`~roughfe.errors.ResolutionWarning`) when the law's process zone
    (:meth:`AdhesionLaw.process_zone`) spans fewer grid spacings than the law needs
    (:meth:`AdhesionLaw.resolution_cells`, :func:`resolution` for the arguments);
    returns True when it is resolved."""
    r = resolution(law, e_star, spacing, cell_compliance, relief)
    if r["resolved"]:
        return True
    zone, dx, need = r["process_zone"], r["grid_spacing"], r["threshold_cells"]
    # a Maugis-Dugdale law on a profile or on summits is set by its ramp: a wider one
    # resolves sooner
    wider = (AdhesionLaw("md", law.work, law.range, smoothing=0.5)
             if law.kind == "md" and law.smoothing < 0.5 else None)
    easier = (None if wider is None else
              wider.resolution_cells(r["cell_compliance"], np.size(spacing),
                                     r["cell_relief"]))
    hint = (f", or the ramp smoothing 0.5 (smoothing=, roughfe --smoothing; needs "
            f"{easier:.2g} spacings)"
            if easier is not None and easier < 0.9 * need else "")
    warnings.warn(
        f"the {law.kind} adhesion law (w = {law.work:.3g} J/m^2, range {law.range:.3g} m, "
        f"sigma0 = {law.max_traction:.3g} Pa) has a process zone (pi/4) E* w / sigma0^2 = "
        f"{zone:.3g} m, {zone / dx:.2g} of the grid spacing {dx:.3g} m (this law on this "
        f"grid needs at least {need:.2g}): each cell then acts as a bistable spring "
        f"of its own, and the pull-off and the hysteresis depend on the grid and on the "
        f"continuation's steps. Resolve it: a grid spacing <= "
        f"{zone / need:.3g} m, or the same work of adhesion over a longer range{hint}",
        ResolutionWarning, stacklevel=3)
    return False
