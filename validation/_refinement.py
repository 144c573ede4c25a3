"""The refinement levels of the convergence studies (``validation/fem_convergence.py``,
``validation/richardson_calibration.py``): a profile's polyline sampled r times finer, the
study loads and their +-5 % window, and the windowed quantities (A* with sub-element edges,
window and tangent K, mean gap) of a sweep solved at that window. SI units (m, Pa). A
helper module of the studies, not a study of its own.
"""
from __future__ import annotations

import numpy as np

from _fem_cases import MATERIAL, subcell_area

from roughfe.bem import contact_sweep
from roughfe.fem import mirrored_profile
from roughfe.surfaces import Surface

FRACTIONS = (0.5, 0.7, 0.9)    # loads: native-BEM mean pressure at these Delta / (max h - mean h)
K_WINDOW = 0.05                # K: secant over the mean pressures p (1 -+ K_WINDOW)


def refined(surface: Surface, r: int) -> Surface:
    """The polyline through the samples of ``surface``, sampled r times finer."""
    n = surface.shape[0]
    dx = surface.spacing[0]
    xf = np.arange((n - 1) * r + 1) * dx / r
    h = np.interp(xf, np.arange(n) * dx, surface.heights)
    return Surface(h, xf.size * dx / r, metadata={**surface.metadata, "refined": r})


def study_pressures(surface: Surface) -> np.ndarray:
    """The compared mean pressures (Pa): native BEM at Delta = FRACTIONS of the top."""
    mirrored = mirrored_profile(surface)
    top = float(surface.heights.max() - mirrored.heights.mean())
    bem = contact_sweep(mirrored, MATERIAL, deltas=top * np.asarray(FRACTIONS),
                        kernel="spectral", compute_stiffness=False)
    return bem.mean_pressure


def load_window(pressures) -> np.ndarray:
    """The solved mean pressures (Pa): every compared p and p (1 -+ K_WINDOW), increasing."""
    p = np.asarray(pressures, float)
    return np.sort(np.concatenate([p * (1 - K_WINDOW), p, p * (1 + K_WINDOW)]))


def window_quantities(sweep, n: int) -> dict:
    """A*, K (window secant and tangent) and mean gap at the compared loads of a sweep
    solved at :func:`load_window`: the middle load of every consecutive triple.

    The window stiffness is K = -(p+ - p-) / (g+ - g-) with the mean gaps g (Eq. 2.8) at
    the window's ends p+- = p (1 +- K_WINDOW): the tangent dp/dDelta (Eq. 2.7) averaged
    over the window (in load control Delta = const - mean gap in both methods).
    """
    p = sweep.mean_pressure.reshape(-1, 3)
    g = sweep.mean_gap.reshape(-1, 3)
    mid = slice(1, None, 3)
    return {"area": [subcell_area(x, n) for x in sweep.results[mid]],
            "area_count": sweep.area_fraction[mid].tolist(),
            "stiffness": ((p[:, 2] - p[:, 0]) / (g[:, 0] - g[:, 2])).tolist(),
            "stiffness_tangent": sweep.stiffness[mid].tolist(),
            "mean_gap": g[:, 1].tolist(), "mean_pressure": p[:, 1].tolist(),
            "window_mean_pressure": sweep.mean_pressure.tolist(),
            "window_mean_gap": sweep.mean_gap.tolist(),
            "window_stiffness_tangent": sweep.stiffness.tolist()}
