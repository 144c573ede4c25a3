"""Sequencing of measured (natural) roughness (thesis Sec. 3.4.2, Fig. 41-46).

The thesis sequenced one steel fracture profile seen through 10x, 20x and 100x lenses
(Table 3). That data is not available; here the nested acquisitions are emulated from
one measured topography: its central row (along x, axis 0) is resampled on N nodes over
the full row, its central half and its central fifth (:func:`nested_acquisitions`).

Resampling: every node takes the mean height of the measured profile over its own cell
``[x - delta/2, x + delta/2]`` (a pixel that integrates, computed from the cumulative
trapezoidal integral of the linearly interpolated row). Coarser than the measurement this
is an anti-aliasing box filter; finer (the central fifth: ~150 measured points on N nodes)
it is a linear interpolation and *adds no information*: the short chromosomes of the
finest acquisitions are then not measured roughness, which is a limit of this emulation
and is reported (``measured_points`` per acquisition).

Each acquisition is detrended by the least-squares line of the *full* row (the WM
function of Eq. 3.1 has no tilt) and shifted so that Z(0) = 0 at the common centre node
(Sec. 3.3.1: Z_d = Z_1 - Z_2 is then a node-by-node difference).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..frozen import freeze_containers
from ..surfaces.surface import Surface
from .genome import DEFAULT_NODES, node_coordinates, realize
from .mechanics import THESIS_YOUNGS_MODULUS, curve_difference, response
from .sequencing import SequencingResult, sequence_profiles

DEFAULT_FRACTIONS = (1.0, 0.5, 0.2)     # full row, central half, central fifth


def central_row(surface: Surface):
    """x (m, centred on the middle of the row) and heights (m) of the central row along x."""
    if surface.ndim == 1:
        z = np.asarray(surface.heights, dtype=float)
    else:
        z = np.asarray(surface.heights[:, surface.shape[1] // 2], dtype=float)
    dx = surface.spacing[0]
    x = (np.arange(z.size) - (z.size - 1) / 2) * dx
    return x, z


def _cell_means(x, z, nodes, delta):
    """Mean of the piecewise-linear profile (x, z) over [node - delta/2, node + delta/2]."""
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (z[1:] + z[:-1]) * np.diff(x))])

    def integral(t):                  # exact integral of the linear interpolant from x[0] to t
        t = np.clip(t, x[0], x[-1])
        k = np.clip(np.searchsorted(x, t, side="right") - 1, 0, x.size - 2)
        dt = t - x[k]
        slope = (z[k + 1] - z[k]) / (x[k + 1] - x[k])
        return cum[k] + z[k] * dt + 0.5 * slope * dt ** 2

    lo, hi = nodes - delta / 2, nodes + delta / 2
    lo_c, hi_c = np.maximum(lo, x[0]), np.minimum(hi, x[-1])
    return (integral(hi_c) - integral(lo_c)) / np.maximum(hi_c - lo_c, 1e-300)


def nested_acquisitions(surface: Surface, fractions=DEFAULT_FRACTIONS, n_nodes=DEFAULT_NODES):
    """Emulated nested acquisitions of the central row of a measured topography.

    Parameters
    ----------
    surface : Surface
        Measured profile or topography (heights in m; the central row along x is used).
    fractions : sequence of float
        Observation lengths as fractions of the usable row length (1, 1/2, 1/5).
    n_nodes : int
        Nodes N per acquisition.

    Returns
    -------
    list of Surface
        Coarsest first, nodes x_j = (j - N//2) L/(N-1) (``metadata["x0"]``), Z(0) = 0;
        ``metadata["measured_points"]`` = measured samples inside the window.
    """
    x, z = central_row(surface)
    if z.size < 16:
        raise InputError(f"too few points: the central row has {z.size} samples, at least 16 are needed")
    fr = sorted((float(f) for f in fractions), reverse=True)
    if not fr or fr[0] > 1 or fr[-1] <= 0:
        raise InputError(f"fractions must lie in (0, 1], got {list(fractions)!r}")
    coef = np.polyfit(x, z, 1)
    z = z - np.polyval(coef, x)
    span = x[-1] - x[0]
    full = span * (n_nodes - 1) / n_nodes      # the shifted node window fits inside the row
    out = []
    for f in fr:
        length = f * full
        nodes = node_coordinates(length, n_nodes)
        delta = length / (n_nodes - 1)
        h = _cell_means(x, z, nodes, delta)
        h = h - h[n_nodes // 2]
        inside = int(np.sum((x >= nodes[0]) & (x <= nodes[-1])))
        meta = {"generator": "nested_acquisitions", "length": length, "x0": float(nodes[0]),
                "fraction": f, "measured_points": inside,
                "source": surface.metadata.get("source"), "detrend": "line of the full row"}
        out.append(Surface(h, n_nodes * delta, periodic=False, metadata=meta))
    return out


@dataclass(frozen=True, eq=False)
class NaturalResult:
    """Sequencing of an emulated nested acquisition set and contact curves measured vs sequenced.

    Attributes
    ----------
    acquisitions : list of Surface
    sequencing : SequencingResult
    curves : dict
        kernel -> {"measured": ResponseCurve, "sequenced": ResponseCurve,
        "difference": {"K": .., "A": ..}} for the coarsest acquisition.
    success, message, nit : report (success of the sequencing quality check).
    """

    acquisitions: list
    sequencing: SequencingResult
    curves: dict
    success: bool
    message: str
    nit: int
    references: tuple = field(default=("thesis Sec. 3.4.2, Table 3, Fig. 41-46",))

    def __post_init__(self):
        freeze_containers(self)

    def report(self) -> dict:
        """JSON-safe report (*_report.json of `genome natural`): the sequencing report
        (with its own ``units``), the measured samples per acquisition and the relative
        A(p), K(p) differences per kernel; ``units`` names the units of this level."""
        out = {"sequencing": self.sequencing.report(),
               "measured_points": [a.metadata.get("measured_points") for a in self.acquisitions],
               "curve_differences": {k: v["difference"] for k, v in self.curves.items()},
               "units": {"measured_points": "1 (samples)",
                         "curve_differences": "1 (relative difference, A and K)",
                         "sequencing": "see sequencing.units"}}
        return out


def sequence_measured(surface: Surface, *, fractions=DEFAULT_FRACTIONS, n_nodes=DEFAULT_NODES,
                      seed=0, kernels=("thesis", "strip"), youngs_modulus=THESIS_YOUNGS_MODULUS,
                      n_steps=20, rms_tolerance=0.05, n_restarts=3) -> NaturalResult:
    """Sequence a measured topography's central row and compare A(p), K(p) (Sec. 3.4.2).

    The measured and sequenced profiles of the coarsest acquisition are loaded with
    ``n_steps`` equal approaches each (E = 210 MPa as the thesis) for every kernel.
    ``n_restarts`` is passed to :func:`~roughfe.genomics.sequencing.sequence_profiles`.
    """
    acq = nested_acquisitions(surface, fractions, n_nodes)
    seq = sequence_profiles(acq, seed=seed, rms_tolerance=rms_tolerance, n_restarts=n_restarts)
    full = acq[0]
    model = realize(seq.genome, length=full.metadata["length"], n_nodes=n_nodes)
    curves = {}
    for k in tuple(kernels):
        m = response(full, kernel=k, youngs_modulus=youngs_modulus, n_steps=n_steps)
        s = response(model, kernel=k, youngs_modulus=youngs_modulus, n_steps=n_steps)
        curves[k] = {"measured": m, "sequenced": s, "difference": curve_difference(m, s)}
    return NaturalResult(acq, seq, curves, seq.success, seq.message, seq.nit)
