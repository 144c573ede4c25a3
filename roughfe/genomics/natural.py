"""Sequencing of measured (natural) roughness (thesis Sec. 3.4.2, Fig. 41-46).

The thesis sequenced one steel fracture profile seen through 10x, 20x and 100x lenses
(Table 3). That data is not available; here the nested acquisitions are emulated from
one line of a measured topography (:func:`measured_row`: by default its central row
along x) as its windows over the full row, its central half and its central fifth
(:func:`nested_acquisitions`).

Sampling: the nodes of every acquisition are the row's own samples, at an integer stride
(1 unless the window holds more than N samples), node N//2 on the row's sample P//2
(the genome node convention: a realised profile's node N//2 is at x = 0). Nothing is
interpolated or averaged, so a profile realised from a genome (Eq. 3.1 at its nodes) is
sequenced back exactly: every acquisition holds the genome's heights at its nodes. Each
acquisition is a window of the *same* profile, so it also holds the long chromosomes of
the coarsest one: the acquisitions are marked ``window_of_row`` and the sequencer models
them from the coarsest one's n_s on (:func:`~roughfe.genomics.sequencing.lattice.
lattice_ranges`), and each has its own N (the samples in its window, up to N).

Until round 2, session 32 every acquisition had N nodes at the thesis spacing L/(N-1) over
``(N-1)/N`` of the row, each the mean of the linearly interpolated row over its cell (a
box filter). Those nodes sat between the samples and the finer windows were
interpolations of 256 and 102 samples on 512 nodes: a realised Table 1 profile came back
with gamma = 1.145, H = 1.81, 59 chromosomes and "not a genome: ... an overfit" (0.45-0.52 %
misfit), where it is now exact. A stride above 1 takes every s-th sample without an
anti-aliasing filter, as Eq. 3.1 is evaluated at the nodes (its short chromosomes alias);
the sequencer models every window of the row up to the row's finest chromosome, so the
aliased ones are fitted where they are, not left as misfit (a Table 1 row of 256 samples
sequenced with 128 nodes: misfits 1-5.5 % -> 1e-13, round 2, session 32).

Each acquisition is detrended by the least-squares line of the *full* row (the WM
function of Eq. 3.1 has no tilt) and shifted so that Z(0) = 0 at the common centre node
(Sec. 3.3.1: Z_d = Z_1 - Z_2 is then a node-by-node difference). The line is removed
once, before windowing, and fitted back as one tilt shared by the windows: a WM row
has a line of its own over the row (that of its long chromosomes), which the data lost
with the instrument's. That tilt is bounded
(:func:`~roughfe.genomics.sequencing.lattice.tilt_bound`: a rise over half the row of at
most 13.1 times the largest height, the steepest line a chromosome the amplitude guard
admits can carry). Unbounded it
reached 3e3-5e5 m/m on measured rows (di-1, x3p-2, opd-1, ``--nodes 128``), traded
against the long chromosomes of the fine lattices these fits end on; WM rows stay far
inside the bound (at most 3.9 of 13.1, 2700 rows) and are sequenced as before. Fitting
no tilt is no exact model: realised Table 1 rows then came back as gamma^(1/3) or with
gamma 1.22 (round 2, session 33).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import progress
from ..errors import InputError
from ..frozen import freeze_containers
from ..surfaces.surface import Surface
from .genome import DEFAULT_NODES, realize
from .mechanics import THESIS_YOUNGS_MODULUS, curve_difference, response
from .sequencing import MIN_NODES, SequencingResult, sequence_profiles

DEFAULT_FRACTIONS = (1.0, 0.5, 0.2)     # full row, central half, central fifth
AXES = ("x", "y")


def measured_row(surface: Surface, row=None, axis="x"):
    """One line of a topography: x (m, zero at sample P//2) and heights (m).

    Parameters
    ----------
    surface : Surface
        A profile (1D: the profile itself; ``row`` None, ``axis`` "x") or a topography.
    row : int, optional
        Index of the line across ``axis`` (a topography's heights[:, row] along x,
        heights[row, :] along y); default the central one (shape // 2).
    axis : {"x", "y"}
        Direction of the line (axis 0 or 1 of the heights).
    """
    if axis not in AXES:
        raise InputError(f"axis must be 'x' or 'y', got {axis!r}")
    if surface.ndim == 1:
        if axis != "x" or row is not None:
            raise InputError(f"this is a profile (1D, {surface.shape[0]} samples): it is its "
                             f"only line; a row index and axis 'y' are for topographies (2D)")
        z, dx = np.asarray(surface.heights, dtype=float), surface.spacing[0]
    else:
        k = AXES.index(axis)
        rows = surface.shape[1 - k]            # the lines along x are indexed by y, and back
        j = rows // 2 if row is None else row
        if isinstance(j, bool) or not isinstance(j, (int, np.integer)) or not 0 <= j < rows:
            raise InputError(f"row {j!r} along {axis}: this topography "
                             f"({surface.shape[0]} x {surface.shape[1]}) has rows 0..{rows - 1} "
                             f"along {axis}")
        z = np.asarray(surface.heights[:, j] if k == 0 else surface.heights[j, :], dtype=float)
        dx = surface.spacing[k]
    x = (np.arange(z.size) - z.size // 2) * dx
    return x, z


def central_row(surface: Surface):
    """x (m) and heights (m) of the central row along x (:func:`measured_row`)."""
    return measured_row(surface)


def _window_nodes(left, right, n_nodes):
    """(stride, nodes left of the centre, nodes right of it) of a window of ``left`` and
    ``right`` samples beside its centre: at most ``n_nodes`` nodes, node N//2 central."""
    stride = max(1, -(-(left + right) // (n_nodes - 1)))
    a, b = left // stride, right // stride
    n = min(n_nodes, a + b + 1)
    while n // 2 > a or n - 1 - n // 2 > b:
        n -= 1
    return stride, n // 2, n - 1 - n // 2


def nested_acquisitions(surface: Surface, fractions=DEFAULT_FRACTIONS, n_nodes=DEFAULT_NODES,
                        *, row=None, axis="x"):
    """Emulated nested acquisitions of one line of a measured topography.

    Parameters
    ----------
    surface : Surface
        Measured profile or topography (heights in m).
    fractions : sequence of float
        Observation lengths as fractions of the row (1, 1/2, 1/5), in (0, 1].
    n_nodes : int
        Largest number of nodes per acquisition (a window of more samples takes every
        s-th one).
    row, axis :
        The line (:func:`measured_row`; default the central row along x).

    Returns
    -------
    list of Surface
        Coarsest first; nodes are row samples, node N//2 at x = 0 (``metadata["x0"]``),
        Z(0) = 0; ``metadata``: ``stride`` (samples per node spacing),
        ``measured_points`` (samples inside the window), ``window_of_row`` True.
    """
    x, z = measured_row(surface, row, axis)
    if z.size < 16:
        raise InputError(f"too few points: the row has {z.size} samples, at least 16 are needed")
    if n_nodes < 2:
        raise InputError(f"n_nodes must be >= 2, got {n_nodes!r}")
    fr = sorted((float(f) for f in fractions), reverse=True)
    if not fr or fr[0] > 1 or fr[-1] <= 0:
        raise InputError(f"fractions must lie in (0, 1], got {list(fractions)!r}")
    if len(set(fr)) < len(fr):   # was the sequencer's "different observation lengths"
        raise InputError(f"fractions must differ (one acquisition each), got "
                         f"{list(fractions)!r}")
    coef = np.polyfit(x, z, 1)
    z = z - np.polyval(coef, x)
    dx = x[1] - x[0]
    c = z.size // 2
    out = []
    for f in fr:
        stride, a, b = _window_nodes(int(f * c + 1e-9), int(f * (z.size - 1 - c) + 1e-9),
                                     n_nodes)
        idx = c + stride * np.arange(-a, b + 1)
        h = z[idx] - z[c]
        delta = stride * dx
        meta = {"generator": "nested_acquisitions", "length": float((a + b) * delta),
                "x0": float(x[idx[0]]), "fraction": f, "stride": int(stride),
                "measured_points": int(idx[-1] - idx[0] + 1), "window_of_row": True,
                "row": row, "axis": axis,
                "source": surface.metadata.get("source"), "detrend": "line of the full row"}
        out.append(Surface(h, (a + b + 1) * delta, periodic=False, metadata=meta))
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
                      n_steps=20, rms_tolerance=0.05, n_restarts=3, row=None,
                      axis="x") -> NaturalResult:
    """Sequence one line of a measured topography and compare A(p), K(p) (Sec. 3.4.2).

    The line is :func:`measured_row` (``row``, ``axis``; default the central row along x).
    The measured and sequenced profiles of the coarsest acquisition are loaded with
    ``n_steps`` equal approaches each (E = 210 MPa as the thesis) for every kernel
    (progress: "A(p), K(p) curves"). ``n_restarts`` is passed to
    :func:`~roughfe.genomics.sequencing.sequence_profiles`.
    """
    acq = nested_acquisitions(surface, fractions, n_nodes, row=row, axis=axis)
    short = [a for a in acq if a.shape[0] < MIN_NODES]
    if short:    # sequence_profiles said "N = 7 nodes", naming no fraction (session 37)
        a = short[-1]
        points = a.metadata["measured_points"]
        raise InputError(
            f"the acquisition of fraction {a.metadata['fraction']:g} has {a.shape[0]} nodes "
            f"({points} of the row's {measured_row(surface, row, axis)[1].size} samples, at "
            f"most n_nodes = {n_nodes}); sequencing needs at least {MIN_NODES} per "
            f"acquisition: give " + (f"n_nodes >= {MIN_NODES}" if points >= MIN_NODES else
                                     "larger fractions or a row of more samples"))
    seq = sequence_profiles(acq, seed=seed, rms_tolerance=rms_tolerance, n_restarts=n_restarts,
                            windows=True)
    full = acq[0]
    model = realize(seq.genome, length=full.metadata["length"], n_nodes=full.shape[0])
    curves = {}
    for k in progress.iterate(tuple(kernels), "A(p), K(p) curves"):
        m = response(full, kernel=k, youngs_modulus=youngs_modulus, n_steps=n_steps)
        s = response(model, kernel=k, youngs_modulus=youngs_modulus, n_steps=n_steps)
        curves[k] = {"measured": m, "sequenced": s, "difference": curve_difference(m, s)}
    return NaturalResult(acq, seq, curves, seq.success, seq.message, seq.nit)


#: residual evaluations (linear solves) of one lattice start on a measured row that is not
#: WM-like: 3845 over 3 starts on sur-2's central row (281 + 281 + 113 nodes, 65 s), 2500-4000
#: in round 2, session 32; an exact WM profile needs a few dozen
SOLVES_PER_START = 1300
#: comb ratio whose chromosome count sizes the timed solve (the fits of measured rows end on
#: fine lattices: gamma 1.05-1.2)
_TIMED_GAMMA = 1.1


def sequencing_time_estimate(acquisitions, n_restarts=3) -> float:
    """Rough upper estimate (s) of :func:`sequence_profiles` on ``acquisitions`` of a row
    that is not WM-like: one linear solve of the stacked nodes on a lattice of ratio 1.1
    is timed here and multiplied by :data:`SOLVES_PER_START` per lattice start. An
    exact WM profile takes a small fraction of it."""
    import time

    from .sequencing.lattice import solve_linear
    rows = sum(a.shape[0] for a in acquisitions)
    n = max(a.shape[0] for a in acquisitions)
    cols = 2 * int(np.ceil(np.log(n) / np.log(_TIMED_GAMMA))) + 2 * len(acquisitions)
    mat = np.random.default_rng(0).standard_normal((rows, cols))
    rhs = mat @ np.ones(cols)
    solve_linear(mat, rhs)                        # warm-up (LAPACK, caches)
    t0 = time.perf_counter()
    for _ in range(3):
        solve_linear(mat, rhs)
    per_solve = (time.perf_counter() - t0) / 3
    return per_solve * SOLVES_PER_START * int(n_restarts)
