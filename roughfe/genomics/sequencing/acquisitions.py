"""Nested acquisitions of a profile and their checks (thesis Sec. 3.2-3.3.1)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import InputError, check_finite_positive, check_instance, check_int
from ...surfaces.surface import Surface
from ..genome import observation_coordinates

MIN_NODES = 32
#: a profile is levelled when its own least-squares line (mean, and slope times L/2) is
#: below this fraction of its rms height: zero to the round-off of float32 files, while
#: a raw WM or measured window has a line of order its rms
LEVELLED_TOLERANCE = 1e-6


# -- data checks -------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class Acquisition:
    """One acquisition: node abscissae x (m), heights z (m), observation length L = (N-1) dx;
    ``levelled``: its least-squares line was removed (:func:`is_levelled`), so the
    sequencer fits the line back (:func:`~.lattice.design_matrix`)."""

    x: np.ndarray
    z: np.ndarray
    length: float
    levelled: bool = False


def is_levelled(x, z) -> bool:
    """True when the heights ``z`` (m) at ``x`` (m) have a least-squares line of zero to
    round-off (:data:`LEVELLED_TOLERANCE` of their rms): the mark a profilometer's
    levelling leaves."""
    xc = x - x.mean()
    rms = float(np.sqrt(np.mean(z ** 2)))
    slope = float(xc @ z) / float(xc @ xc)
    return bool(abs(float(z.mean())) <= LEVELLED_TOLERANCE * rms
                and abs(slope) * 0.5 * float(np.ptp(x)) <= LEVELLED_TOLERANCE * rms)


def check_controls(rms_tolerance, n_restarts):
    """The controls both sequencers take, checked: ``rms_tolerance`` (relative rms
    error, > 0) and ``n_restarts`` (comb periods tried, an integer >= 1). Returns them
    as float and int. Used by
    :func:`~roughfe.genomics.sequencing.profile.sequence_profiles` and
    :func:`~roughfe.genomics.sequencing.surface.sequence_surfaces`."""
    return (check_finite_positive("rms_tolerance (relative rms error)", rms_tolerance),
            check_int("n_restarts (comb periods tried)", n_restarts, 1))


def acquisitions_from_surfaces(surfaces) -> list:
    """Check nested acquisitions and return them sorted from coarsest to finest.

    Raises InputError for: fewer than 2 profiles, 2D data, different N, fewer than
    ``MIN_NODES`` nodes, a flat profile, equal lengths, windows that are not nested around x = 0, or
    scales that do not overlap (the finer window shorter than two coarse spacings).
    """
    surfaces = list(surfaces)
    if len(surfaces) < 2:
        raise InputError(f"sequencing needs at least 2 nested acquisitions, got {len(surfaces)}")
    for k, s in enumerate(surfaces):
        check_instance(f"acquisition {k}", s, Surface, "a roughfe Surface")
        if s.ndim != 1:
            raise InputError(f"acquisition {k} must be a profile (1D heights), got shape {s.shape}")
    sizes = {s.shape[0] for s in surfaces}
    if len(sizes) != 1:
        raise InputError(f"all acquisitions must have the same number of nodes N (Sec. 3.2: N = 512 "
                         f"at every scale), got N = {[s.shape[0] for s in surfaces]}")
    n = sizes.pop()
    if n < MIN_NODES:
        raise InputError(f"too few points: N = {n} nodes per acquisition, at least {MIN_NODES} are needed")
    acq = []
    for k, s in enumerate(surfaces):
        if np.ptp(s.heights) == 0:
            raise InputError(f"acquisition {k} is flat (all heights equal {float(s.heights[0])!r} m): "
                             f"there is no roughness to sequence")
        x = observation_coordinates(s)
        z = np.asarray(s.heights, dtype=float)
        acq.append(Acquisition(x, z, float((n - 1) * s.spacing[0]), is_levelled(x, z)))
    acq.sort(key=lambda a: -a.length)
    for a, b in zip(acq, acq[1:]):
        if not b.length < a.length * (1 - 1e-9):
            raise InputError(f"acquisitions must have different observation lengths, got two of "
                             f"{a.length:.6g} m")
        tol = 1e-6 * a.length
        if b.x[0] < a.x[0] - tol or b.x[-1] > a.x[-1] + tol:
            raise InputError(f"acquisition of length {b.length:.6g} m ([{b.x[0]:.4g}, {b.x[-1]:.4g}] m) is "
                             f"not nested inside the one of length {a.length:.6g} m "
                             f"([{a.x[0]:.4g}, {a.x[-1]:.4g}] m)")
        dx = a.length / (n - 1)
        if b.length <= 2 * dx:
            raise InputError(f"non-overlapping scales: the finer window {b.length:.4g} m is not longer than "
                             f"two spacings {2 * dx:.4g} m of the coarser acquisition, so they share no "
                             f"wavelength")
    return acq
