"""How long :func:`~roughfe.genomics.band_mechanics.band_mechanics` will take, said before
it starts: its BEM sweeps counted exactly, their wall time extrapolated from one timed
sweep on a small crop of the surface (``roughfe genome chromosomes`` prints it: 55 sweeps
on a 512^2 window ran 2.5 min without a word of warning, a user's review).

The cost model is rough, and said to be: one sweep of ``n_steps`` steps on a central crop
of at most :data:`CALIBRATION_SIDE` ^2 points (:data:`CALIBRATION_SIDE` ^2 points of a
profile) is timed after a warm-up solve, its seconds per point and step are multiplied by
the points, steps and sweeps of the run and divided by the sweeps run at once. The BEM
iterations per step grow with the grid and differ between the complete surface, a smooth
single band and a rough partial sum, and two threads do not halve the time, so the
estimate is quoted as a range a factor :data:`SPREAD` either way. Measured against whole
runs on the 2-core development machine (20 steps, 2 workers, other jobs running; the
calibration took 0.4-0.9 s), estimate / actual wall time was 1.23 (di-1.di cut to 128^2,
30 s / 24 s), 1.29 (x3p-2, 128^2), 1.10 (di-1, 256^2), 0.62 (x3p-2, 256^2, 116 s /
188 s), 0.81 (plu-1, 256^2) and 0.94 (di-1, 512^2, 55 sweeps: 689 s / 732 s).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np

from ..errors import RoughfeError
from ..surfaces.surface import Surface
from .band_mechanics import band_fields
from .bands import BandChromosomes
from .macro_micro import profile_response
from .mechanics import distinct_fields
from .similarity import ResponseCurve

#: side of the square crop the calibration sweep runs on (profiles: its square, in points)
CALIBRATION_SIDE = 64
#: the estimate is quoted as [t / SPREAD, t * SPREAD]
SPREAD = 2.0


def _duration(seconds: float) -> str:
    if seconds < 90:
        return f"{max(seconds, 1):.0f} s"
    if seconds < 90 * 60:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


@dataclass(frozen=True)
class SweepPlan:
    """The sweeps of a :func:`band_mechanics` run and a rough estimate of its wall time.

    Attributes
    ----------
    n_sweeps : int
        BEM sweeps to run (flat and repeated fields are not swept).
    n_steps : int
        Approaches per sweep.
    shape : tuple of int
        Grid of each sweep.
    workers : int
        Sweeps run at once.
    seconds_per_point_step : float
        Wall time (s) per grid point and step of the calibration sweep; NaN when it could
        not run (a flat crop, a sweep that did not converge).
    calibration_shape : tuple of int
        Grid of the calibration crop.
    """

    n_sweeps: int
    n_steps: int
    shape: tuple
    workers: int
    seconds_per_point_step: float
    calibration_shape: tuple

    @property
    def seconds(self) -> float:
        """Estimated wall time of the sweeps (s; NaN when not estimated)."""
        at_once = max(1, min(self.workers, self.n_sweeps))
        return (self.seconds_per_point_step * math.prod(self.shape) * self.n_steps
                * self.n_sweeps / at_once)

    def summary(self) -> str:
        """One line: what will run, and for roughly how long."""
        grid = " x ".join(map(str, self.shape))
        head = (f"{self.n_sweeps} BEM sweeps of {self.n_steps} steps on {grid} points "
                f"({self.workers} at a time)")
        t = self.seconds
        if not np.isfinite(t):
            return f"{head}: time not estimated (the calibration sweep did not run)"
        crop = " x ".join(map(str, self.calibration_shape))
        lo, hi = _duration(t / SPREAD), _duration(t * SPREAD)
        span = f"about {lo}" if lo == hi else f"roughly {lo} to {hi}"
        return (f"{head}: {span} (a rough guess, extrapolated from one timed sweep of a "
                f"{crop} crop by the number of points)")


def _crop(surface: Surface, side: int) -> Surface:
    """The central crop of at most ``side`` x ``side`` points (a profile: ``side^2``
    points), with the same spacing."""
    side = side if surface.heights.ndim == 2 else side ** 2
    h = surface.heights
    cut = tuple(slice((n - min(n, side)) // 2, (n - min(n, side)) // 2 + min(n, side))
                for n in h.shape)
    size = tuple(L * min(n, side) / n for L, n in zip(surface.size, h.shape))
    return Surface(h[cut], size, surface.periodic)


def plan_band_sweeps(bands: BandChromosomes, *, youngs_modulus: float, poisson: float = 0.0,
                     n_steps: int = 20, kernel: str = "auto", workers: int = 2,
                     response: Optional[Callable[[Surface], ResponseCurve]] = None
                     ) -> SweepPlan:
    """Count the sweeps of :func:`~roughfe.genomics.band_mechanics.band_mechanics` with
    the same arguments and time one sweep on a crop (see the module notes; ~0.1-0.5 s).

    Parameters as :func:`~roughfe.genomics.band_mechanics.band_mechanics`.

    Returns
    -------
    SweepPlan
    """
    flat, same = distinct_fields(band_fields(bands))
    n_sweeps = sum(1 for key, first in same.items() if key == first)
    if response is None:
        def response(s):
            return profile_response(s, youngs_modulus=youngs_modulus, poisson=poisson,
                                    n_steps=int(n_steps), kernel=kernel)
    crop = _crop(bands.surface, CALIBRATION_SIDE)
    per_point_step = float("nan")
    for calibration in (_crop(bands.surface, 8), crop):   # a warm-up (FFT plans), the run
        try:
            t0 = time.perf_counter()
            response(calibration)
            per_point_step = ((time.perf_counter() - t0)
                              / (calibration.heights.size * int(n_steps)))
        except (RoughfeError, ArithmeticError, ValueError):  # a flat crop, no convergence
            per_point_step = float("nan")
    return SweepPlan(n_sweeps=n_sweeps, n_steps=int(n_steps), shape=tuple(bands.surface.shape),
                     workers=int(workers), seconds_per_point_step=per_point_step,
                     calibration_shape=tuple(crop.shape))
