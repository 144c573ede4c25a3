"""Is a sequenced genome reproducible? The genes of the two halves of the data.

A genome is a property of the surface (thesis Ch. 3: gamma, H, A and M set the
roughness's statistics and its contact mechanics), so a second sample of the same
surface must give the same genes. A fit within the tolerance that predicts its held-out
nodes (:mod:`.holdout`) need not be one: a dense lattice (gamma 1.1-1.2) with admitted
amplitudes reproduces a rough row and predicts its held-out nodes too, and its genes
depend on how the row was cut (di-1's central row, round 2, session 34: gamma 1.168,
H 0.38 from three nested windows, gamma 1.095, H 1.33 from two levelled ones).

The test (:func:`reproducibility`): every acquisition is cut at x = 0 into its nodes
left of the centre and those right of it (the centre node, Z(0) = 0, in neither): two
disjoint samples of the surface. Each half-set is fitted as the whole was in steps 3-4
(:func:`~.search.fit_profile_model`: variable projection with continuation, the coarser
lattices, the label by BIC; the damped final fit; A and H by
:func:`~.genes.amplitude_genes`), started from the whole's lattice instead of the comb's:
a genome's lattice fits each half (exactly, for exact data) and stays; a lattice that
only reproduces these acquisitions moves to each half's own optimum, and its amplitudes
(H) follow each half's heights. A half models what its whole acquisition models
(:attr:`~.acquisitions.Acquisition.nodes`: the Eq. 3.5 ranges, the label of lambda1 and
the tilt bound of the whole; the PSD of the half's own nodes). Cost: two lattice fits
of half the rows from one start, well under one sequencing.

Why not sequence each half from scratch (comb and restarts): measured in round 2,
session 34 on WM rows, the halves' own search at 25-64 nodes per window failed where
the whole's had not: the natural path on random genomes (rows of 256 samples, 128
nodes), 3 of 6 exact and 4 of 5 noisy (1 %) rows "not reproducible", the halves on
wrong lattices (misfits 2-11 %) or on an overfit (gamma 1.08, misfit 7e-12). That tests
the search at half the nodes, not the genome.

The genes are reproducible when both hold (tolerances fixed from their basis before
any measured row was looked at, round 2, session 34):

* the lattices agree (:data:`LATTICE_TOLERANCE`): every chromosome wavenumber
  ln q_n = ln q_1 + (n - 1) ln gamma of the coarser half's lattice, over its band, lies
  within a quarter of a step of the finer half's lattice (:func:`lattice_offset`).
  Farther, the two place the chromosomes on different spectral lines (a quarter step
  is the midpoint between "on a line" and "half way between two"); this compares gamma
  and lambda1 without their labels, and takes a lattice and its sub-lattices gamma^k
  for one, as the sequencer does. WM data: gamma is identifiable exactly (to 1e-15
  exact, 2e-5 with 1 % noise), i.e. offsets of 1e-14 / 1e-3 steps over 20-40
  chromosomes;
* the H agree (:data:`H_SIGMAS`): |H_left - H_right| <= 3 sqrt(s_left^2 +
  s_right^2), s the standard error of each (:func:`~.genes.amplitude_gene_errors`),
  i.e. the two estimates are not told apart at 3 sigma by the sequencer's own stated
  errors. For independent samples of one genome that fails in 0.27 % of cases; the
  halves of one realisation share its chromosome sums, so they agree far better (exact:
  to round-off).

The rms slope of each half's chromosome sum (:func:`model_slope`) is reported
against the whole's (``slope_ratios``) as information, not as a rule: measured in
round 2, session 35 (docs/theory/05_genomics.md), it reaches 12.6 times the whole's
(halves against each other: 2.16) on noisy WM rows whose genes are reproducible, and
di-1's nested row (3.2 and 1.8; 1.77) lies inside that scatter.

A half that cannot be sequenced (no lattice: an InputError) makes the genes not
reproducible. The test needs :data:`MIN_HALF_NODES` nodes in a half of the coarsest
acquisition; with fewer it is not run (``tested`` False, said in the report).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import InputError
from .acquisitions import Acquisition
from .genes import amplitude_gene_errors, amplitude_genes
from .search import fit_profile_model

#: the largest distance, in lattice steps, of a chromosome wavenumber of one half from
#: the other half's lattice (a quarter step: halfway to "between two lines")
LATTICE_TOLERANCE = 0.25
#: the largest H difference of the halves, in combined standard errors
H_SIGMAS = 3.0
#: the fewest nodes of a half of the coarsest acquisition for which the test is run
MIN_HALF_NODES = 16
SIDES = ("left", "right")


@dataclass(frozen=True)
class HalfGenes:
    """The genes of one half (``side``: "left", x < 0, or "right", x > 0): ``gamma``,
    ``lambda1`` (m), ``H``, ``H_stderr``, ``A`` (m^(1-H)), ``slope`` (the rms slope of
    its chromosome sum, :func:`model_slope`, -), ``misfit`` (the largest
    relative rms error of its acquisitions, -) and ``band`` (first, last chromosome);
    ``message``: why it was not sequenced ("" when it was; then the numbers are NaN)."""

    side: str
    gamma: float = math.nan
    lambda1: float = math.nan
    H: float = math.nan
    H_stderr: float = math.nan
    A: float = math.nan
    slope: float = math.nan
    misfit: float = math.nan
    band: tuple = (0, -1)
    message: str = ""

    def report(self) -> dict:
        return {"side": self.side, "gamma": self.gamma, "lambda1": self.lambda1, "H": self.H,
                "H_stderr": self.H_stderr, "A": self.A, "slope": self.slope,
                "misfit": self.misfit,
                "band": list(self.band), "message": self.message}


@dataclass(frozen=True)
class Reproducibility:
    """The reproducibility test (:func:`reproducibility`): ``tested`` (False: too few
    nodes per half, ``reason`` says so), ``reproducible``, the two :class:`HalfGenes`
    (``halves``), ``lattice_offset`` (the largest distance of a chromosome of one half
    from the other's lattice, lattice steps), ``H_difference`` and ``H_tolerance``
    (:data:`H_SIGMAS` combined standard errors), ``slope_ratios`` (each half's
    :func:`model_slope` over the whole's: information, no verdict), ``angle_difference``
    (surfaces, :mod:`.surface_reproduce`: the largest angle between a ridge of one half
    and the nearest of the other, rad) and ``reason`` (the verdict's words when not
    reproducible)."""

    tested: bool
    reproducible: bool = True
    halves: tuple = ()
    lattice_offset: float = math.nan
    H_difference: float = math.nan
    H_tolerance: float = math.nan
    slope_ratios: tuple = ()
    angle_difference: float = math.nan
    reason: str = ""

    def report(self) -> dict:
        return {"tested": self.tested, "reproducible": self.reproducible,
                "halves": [h.report() for h in self.halves],
                "lattice_offset": self.lattice_offset, "H_difference": self.H_difference,
                "H_tolerance": self.H_tolerance, "slope_ratios": list(self.slope_ratios),
                "angle_difference": self.angle_difference, "reason": self.reason,
                "lattice_tolerance": LATTICE_TOLERANCE, "H_sigmas": H_SIGMAS}


def half_acquisitions(acqs, side) -> list:
    """The nodes of every acquisition left (x < 0) or right (x > 0) of the centre, as
    parts of their acquisition (:attr:`~.acquisitions.Acquisition.nodes`)."""
    if side not in SIDES:
        raise InputError(f"side must be one of {SIDES}, got {side!r}")
    out = []
    for a in acqs:
        tol = 1e-6 * a.length / (a.model_nodes - 1)
        keep = a.x < -tol if side == "left" else a.x > tol
        out.append(Acquisition(a.x[keep], a.z[keep], a.length, a.levelled, a.window,
                               nodes=a.model_nodes))
    return out


def _half_genes(acqs, side, rms_tolerance, starts) -> HalfGenes:
    part = half_acquisitions(acqs, side)
    try:
        fit = fit_profile_model(part, rms_tolerance, 0, starts=starts)
        gamma, lam1 = math.exp(fit.log_gamma), 2 * math.pi / math.exp(fit.log_q1)
        amps = np.abs(fit.cvec)
        A, H = amplitude_genes(fit.n, amps, gamma, lam1)
        H_err = amplitude_gene_errors(fit.n, amps, gamma, lam1)[1]
    except InputError as exc:
        return HalfGenes(side, message=str(exc))
    ends = np.cumsum([0] + [a.z.size for a in part])
    misfit = max(math.sqrt(float(np.mean(fit.residual[i:j] ** 2)))
                 for i, j in zip(ends, ends[1:]))
    return HalfGenes(side, gamma, lam1, H, H_err, A, model_slope(fit), misfit,
                     (int(fit.n[0]), int(fit.n[-1])))


def model_slope(fit) -> float:
    """The rms slope of a fit's chromosome sum (-): sqrt(sum_n c_n^2 q_n^2 / 2), the mean
    square of dZ/dx = sum_n c_n q_n sin(q_n x + theta_n) over a length holding many
    cycles of its chromosomes (of incommensurate q_n: the cross terms average out);
    ``fit``: a :class:`~.search.ProfileModel` (``n``, ``cvec`` in m, ``log_q1``,
    ``log_gamma``)."""
    q = np.exp(fit.log_q1 + (np.asarray(fit.n) - 1) * fit.log_gamma)
    return math.sqrt(0.5 * float(np.sum((np.abs(fit.cvec) * q) ** 2)))


def unfitted_halves(halves, verb: str):
    """The "not reproducible" :class:`Reproducibility` of ``halves`` (two
    :class:`HalfGenes`) when either half could not be ``verb`` ("sequenced", "fitted"), or
    None when both were. One rule for the profile and the surface sequencers."""
    failed = [h for h in halves if h.message]
    if not failed:
        return None
    return Reproducibility(True, False, tuple(halves), reason=(
        "the genes are not reproducible: the " + " and the ".join(
            f"{h.side} half cannot be {verb} ({h.message})" for h in failed)))


def lattice_offset(a: HalfGenes, b: HalfGenes) -> float:
    """The largest distance (in steps of the finer lattice) of a chromosome wavenumber of
    the coarser half's lattice, over its band, from the finer one's lattice (0: the same
    lines; 0.5: on the midpoints). Label-free (the same lines under another n are at 0),
    and a lattice gamma^k whose lines are every k-th line of the other is at 0 too: the
    sequencer takes a lattice and its sub-lattices for one (the coarser lattices of
    ``search._settle``; with noise a half of 1.2-gamma WM data settled on gamma^2)."""
    fine, coarse = sorted((a, b), key=lambda h: h.gamma)
    n = np.arange(coarse.band[0], coarse.band[1] + 1)
    log_q = math.log(2 * math.pi / coarse.lambda1) + (n - 1) * math.log(coarse.gamma)
    steps = (log_q - math.log(2 * math.pi / fine.lambda1)) / math.log(fine.gamma)
    return float(np.max(np.abs(steps - np.round(steps)), initial=0.0))


def reproducibility(acqs, rms_tolerance, lattice, slope=math.nan) -> Reproducibility:
    """Sequence the two halves of ``acqs`` (checked acquisitions, coarsest first) and
    compare their genes (module notes: tolerances and their basis); ``lattice``: the
    whole's (ln q_1, ln gamma), the start of each half's lattice fit; ``slope``: the
    whole's :func:`model_slope` (the halves' are reported over it)."""
    nodes = [int(np.sum(half_acquisitions(acqs[:1], s)[0].z.size)) for s in SIDES]
    if min(nodes) < MIN_HALF_NODES:
        return Reproducibility(False, reason=f"not tested: the halves of the coarsest "
                               f"acquisition have {min(nodes)} nodes, fewer than "
                               f"{MIN_HALF_NODES}")
    halves = tuple(_half_genes(acqs, s, rms_tolerance, (tuple(lattice),)) for s in SIDES)
    failed = unfitted_halves(halves, "sequenced")
    if failed is not None:
        return failed
    a, b = halves
    offset = lattice_offset(a, b)
    dH = abs(a.H - b.H)
    tol_H = H_SIGMAS * math.hypot(a.H_stderr, b.H_stderr)
    ok = offset <= LATTICE_TOLERANCE and dH <= tol_H
    reason = "" if ok else (
        f"the genes are not reproducible (gamma {a.gamma:.4g} vs {b.gamma:.4g}, H "
        f"{a.H:.3g} vs {b.H:.3g} from the left and right halves of the acquisitions; "
        f"lattices {offset:.2f} steps apart (at most {LATTICE_TOLERANCE:g}), H "
        f"{dH:.3g} apart (at most {tol_H:.3g}, {H_SIGMAS:g} standard errors))")
    ratios = tuple(h.slope / slope for h in halves)
    return Reproducibility(True, ok, halves, offset, dH, tol_H, slope_ratios=ratios,
                           reason=reason)
