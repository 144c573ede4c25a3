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
    sequencer fits the line back (:func:`~.lattice.design_matrix`); ``window``: a window
    of the coarsest acquisition's own profile (its sampled nodes, not a realisation of its
    own), so it also holds the coarsest one's long chromosomes
    (:func:`~.lattice.lattice_ranges`); ``nodes``: 0, or the N of the acquisition of
    length ``length`` whose nodes these are a part of (a half of them, :mod:`.reproduce`):
    the model (Eq. 3.5 ranges, the label of lambda1, the tilt bound) is then that
    acquisition's, the PSD that of the nodes given (:attr:`span`)."""

    x: np.ndarray
    z: np.ndarray
    length: float
    levelled: bool = False
    window: bool = False
    nodes: int = 0

    @property
    def model_nodes(self) -> int:
        """N of Eq. 3.5 (the nodes of the whole acquisition)."""
        return self.nodes or self.z.size

    @property
    def span(self) -> float:
        """Length (m) spanned by the nodes given: ``length``, or (their number - 1) times
        their spacing for a part of an acquisition."""
        return self.length if not self.nodes else (self.z.size - 1) * float(self.x[1] - self.x[0])


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


#: what to do with data a sequencer does not take, named in its InputError
PROFILE_PATH = ("2 or more nested profiles (1D) go to sequence_profiles (CLI `roughfe genome "
                "sequence P1.npz P2.npz`, e.g. realised by `roughfe genome realize GENOME.json "
                "--scale 10x` and `--scale 20x`)")
SURFACE_PATH = ("square N x N windows (2D) of equal spacings go to sequence_surfaces (a "
                "surface genome's `roughfe genome realize`; CLI `roughfe genome sequence "
                "S1.npz [S2.npz ...]`)")
ROWS_PATH = ("a measured surface or profile is sequenced as nested windows of its central "
             "row (roughfe.genomics.natural.sequence_measured, CLI `roughfe genome natural "
             "FILE`), or take a row yourself as a profile (Surface(s.heights[:, j], "
             "s.size[0]), a column: s.heights[i, :]); the band chromosomes of any surface "
             "or profile: `roughfe genome chromosomes FILE`")


def check_kind(surfaces, ndim: int) -> list:
    """The acquisitions as a list of Surfaces of ``ndim`` dimensions (1: the profile
    sequencer, 2: the surface sequencer), non-periodic; else an InputError that says what
    was given, what the sequencer takes and what to do instead.

    A periodic flag marks heights that are not a window of Eq. 3.1/3.17 with the node
    convention the sequencers model: a generated periodic surface (Fourier filtering,
    resampling) or the periodic realisation of a surface database or design
    (:mod:`roughfe.genomics.periodic`, wavevectors rounded to the torus lattice). Such a
    realisation of a resolvable surface genome failed after 3.6 s with "not a WM surface"
    (48^2, measured in round 2, session 32)."""
    surfaces = list(surfaces)
    for k, s in enumerate(surfaces):
        check_instance(f"acquisition {k}", s, Surface, "a roughfe Surface")
    dims = [s.ndim for s in surfaces]
    if any(d != ndim for d in dims):
        k = next(k for k, d in enumerate(dims) if d != ndim)
        given = (f"acquisition {k} is a {surfaces[k].shape[0]} x {surfaces[k].shape[1]} "
                 f"surface (2D)" if dims[k] == 2 else
                 f"acquisition {k} is a profile (1D) of {surfaces[k].shape[0]} nodes")
        mix = " (a mix of profiles and surfaces)" if len(set(dims)) > 1 else ""
        kind = "profiles (1D)" if ndim == 1 else "2D surfaces"
        raise InputError(f"{given}{mix}: the {'profile' if ndim == 1 else 'surface'} "
                         f"sequencer takes {kind} only. {PROFILE_PATH}; {SURFACE_PATH}; "
                         f"{ROWS_PATH}")
    for k, s in enumerate(surfaces):
        if s.periodic:
            raise InputError(
                f"acquisition {k} is periodic: the sequencers take non-periodic windows of "
                f"Eq. 3.1 (profiles) or Eq. 3.17 (surfaces), node N//2 at the origin, "
                f"spacing L/(N-1). A periodic surface of a genome database or design "
                f"(`db build --dim 2`, `design`) rounds its wavevectors onto the period's "
                f"lattice and is no such window: its genome is the design's genome.json "
                f"(genome_partK.json per part) or the database's. A generated periodic "
                f"surface has "
                f"no genome; {ROWS_PATH}. If the heights are a non-periodic window after "
                f"all, save them as a non-periodic Surface (Surface(heights, size, periodic=False))")
    return surfaces


def is_row_window(surface) -> bool:
    """True for an acquisition of :func:`roughfe.genomics.natural.nested_acquisitions`
    (``metadata["window_of_row"]``): nodes taken from one measured row."""
    return bool(surface.metadata.get("window_of_row", False))


def acquisitions_from_surfaces(surfaces, windows=None) -> list:
    """Check nested acquisitions and return them sorted from coarsest to finest.

    ``windows`` True: the acquisitions are windows of one sampled profile (the nested
    acquisitions of a measured row, :func:`roughfe.genomics.natural.nested_acquisitions`):
    each may have its own N, and every one holds the long chromosomes of the coarsest
    (:attr:`Acquisition.window`). None: True when every acquisition says so
    (:func:`is_row_window`), so that `genome sequence` on the saved acquisitions of
    `genome natural` sequences them as `natural` did.

    Raises InputError for: fewer than 2 profiles, 2D or periodic data (:func:`check_kind`),
    different N (unless ``windows``), fewer than ``MIN_NODES`` nodes, a flat profile, equal
    lengths, windows that are not nested around x = 0, or scales that do not overlap (the
    finer window shorter than two coarse spacings).
    """
    surfaces = check_kind(surfaces, 1)
    if len(surfaces) < 2:
        raise InputError(f"profile sequencing needs at least 2 nested acquisitions (Sec. "
                         f"3.3.1: gamma is read from the overlap of two scales), got "
                         f"{len(surfaces)}. Realise a genome at two scales (`roughfe genome "
                         f"realize GENOME.json --scale 10x`, `--scale 20x`); {ROWS_PATH}")
    if windows is None:
        windows = all(is_row_window(s) for s in surfaces)
    sizes = {s.shape[0] for s in surfaces}
    if len(sizes) != 1 and not windows:
        raise InputError(f"all acquisitions must have the same number of nodes N (Sec. 3.2: N = 512 "
                         f"at every scale), got N = {[s.shape[0] for s in surfaces]}")
    if min(sizes) < MIN_NODES:
        raise InputError(f"too few points: N = {min(sizes)} nodes per acquisition, at least "
                         f"{MIN_NODES} are needed")
    acq = []
    for k, s in enumerate(surfaces):
        if np.ptp(s.heights) == 0:
            raise InputError(f"acquisition {k} is flat (all heights equal {float(s.heights[0])!r} m): "
                             f"there is no roughness to sequence")
        x = observation_coordinates(s)
        z = np.asarray(s.heights, dtype=float)
        acq.append(Acquisition(x, z, float((z.size - 1) * s.spacing[0]), is_levelled(x, z),
                               bool(windows)))
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
        dx = a.length / (a.z.size - 1)
        if b.length <= 2 * dx:
            raise InputError(f"non-overlapping scales: the finer window {b.length:.4g} m is not longer than "
                             f"two spacings {2 * dx:.4g} m of the coarser acquisition, so they share no "
                             f"wavelength")
    return acq
