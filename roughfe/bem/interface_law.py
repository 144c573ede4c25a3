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
each converged solve (at most ``roughfe.bem.adhesion.MAX_SPREAD_PASSES`` solves; again
only when it moved by more than 10 % of the ramp on a cell in the ramp).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError, check_finite_positive

LAWS = ("md", "exp")


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
        s = float(self.smoothing)
        if not 0.0 <= s < 1.0:
            raise InputError(f"smoothing must be in [0, 1), got {self.smoothing!r}")

    @property
    def max_traction(self) -> float:
        """sigma0 = w / range (Pa): the Dugdale stress or the peak exponential traction."""
        return self.work / self.range

    def _ramp(self, spread=None):
        half = 0.5 * self.smoothing * self.range
        if spread is not None:
            half = np.clip(spread, half, self.range)
        return self.range - half, self.range + half

    def evaluate(self, g, spread=None):
        """``(phi(g), phi'(g))``: the potential (J/m^2; -w at contact, 0 far away) and
        the magnitude of the attractive traction (Pa, >= 0), in one pass.

        ``spread`` (m, per point, md only): the cell average of the law when the gap
        varies linearly across a cell, uniformly over ``g -+ spread``: the Dugdale step
        at h0 becomes a ramp of half-width ``max(spread, s h0 / 2)`` (at most h0), which
        keeps ``int phi' dg = w`` (module docstring, "Cell-averaged law")."""
        g = np.asarray(g, float)
        w, s0 = self.work, self.max_traction
        if self.kind == "exp":
            e = np.exp(-g / self.range)
            return -w * e, s0 * e
        g1, g2 = self._ramp(spread)
        if spread is None and g2 <= g1:
            near = g < self.range
            return np.where(near, s0 * g - w, 0.0), np.where(near, s0, 0.0)
        width = np.maximum(g2 - g1, 1e-300)
        t = np.clip(g - g1, 0.0, width)
        phi = s0 * (np.minimum(g, g1) + t - t * t / (2 * width)) - w
        return phi, s0 * (1.0 - t / width)

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
