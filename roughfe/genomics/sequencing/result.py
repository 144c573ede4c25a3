"""The result of sequencing (scipy OptimizeResult-like)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from ...writers import to_jsonable
from ...frozen import compact_repr, freeze_containers
from ..genome import Genome
from .genes import M_VALUES
from .lattice import round_off_cost


#: Units of :meth:`SequencingResult.report` (report.json of `genome sequence`, the
#: ``sequencing`` part of `genome natural`'s *_report.json); "1": dimensionless
REPORT_UNITS = {"A": "m^(1-H)", "H": "1", "gamma": "1", "lambda1": "m",
                "M": "1 (number of ridges)", "lengths": "m",
                "ranges": "1 (chromosome numbers n_s, n_f)",
                "rms_errors": "1 (relative: rms(Z - Z_seq) / rms(Z))",
                "held_out_errors": "1 (relative: rms(Z - Z_held-out) / rms(Z))", "offsets": "m",
                "reproducibility": ("genes of the two halves (gamma, H, H_stderr: 1; A: "
                                    "m^(1-H); lambda1: m; misfit: 1, relative); "
                                    "lattice_offset: 1 (lattice steps)"),
                "tilts": "1 (m/m)",
                "zd_rms": "m", "zd_rms_error": "1 (relative)", "gamma_psd": "1",
                "H_psd": "1", "A0_variance": "m^(1-H)", "M_loglik": "1 (log-likelihood, one per M_values)",
                "M_values": "1 (number of ridges M of each M_loglik)",
                "lnA_stderr": "1 (standard error of ln A)", "H_stderr": "1",
                "M_support": "1 (smallest and largest M within 1.92 of the best log-likelihood)",
                "nit": "1 (residual evaluations)", "elapsed_s": "s"}


@dataclass(frozen=True, eq=False)
class SequencingResult:
    """Sequenced genome and its quality report (scipy OptimizeResult-like).

    Attributes
    ----------
    genome : Genome
        Sequenced genome (phases: one set consistent with the fitted chromosome sums).
    success : bool
        True when every acquisition is reproduced within ``rms_tolerance``.
    message : str
    nit : int
        Residual evaluations of the nonlinear (lattice) fit.
    n : ndarray of int
        Chromosome indices fitted (union over acquisitions).
    amplitudes, phases : ndarray
        c_n (m) and theta_n (rad) of the reduced chromosomes (Eq. 3.7-3.8), of the fit
        damped where the data cannot resolve it (:mod:`.regularise`).
    ranges : list of (int, int)
        (n_s, n_f) per acquisition, coarsest first (Eq. 3.5).
    lengths : ndarray
        Observation lengths (m), coarsest first.
    rms_errors : ndarray
        rms(Z_i - Z_i^seq) / rms(Z_i) per acquisition (relative, -), Z_i the heights as
        given (the fitted offset and tilt are part of the model, not of the yardstick).
    held_out_errors : ndarray
        The same for each node predicted by the (damped) linear fit on the sequenced
        lattice that left its position out (:func:`~.holdout.held_out_errors`, 5 folds): about
        ``rms_errors`` for a genome, far more for an overfit (a fit within the tolerance
        whose held-out errors exceed it is "not a genome: an overfit").
    x, heights, fitted : list of ndarray
        Nodes (m), measured heights less their fitted offset and sequenced heights (m)
        per acquisition.
    zd_x, zd, zd_fit : ndarray
        Z_d = Z_1 - Z_2 at the common nodes of the two coarsest acquisitions and its
        sequenced counterpart (m); empty when they share no node. Their relative misfit,
        :meth:`zd_rms_error`, is None when Z_d is round-off.
    spectra : list of SpectrumPeaks
    gamma_psd, H_psd : float
        gamma from the PSD peaks alone (comb, step 2) and H from the slope of the PSD
        peaks on the lattice (ln C ~ -2H ln q, Eq. 3.11): the thesis's estimates, for
        comparison with the fit and the maximum-likelihood H.
    M_loglik : ndarray
        Log-likelihood of M = 2..20 (flat-ish: M is weakly identifiable).
    offsets : ndarray
        Height offset of each acquisition (m, coarsest first): the constant fitted with
        the chromosomes, its height at x = 0 off the genome's zero (Eq. 3.1: Z(0) = 0),
        e.g. the mean a mean-removed profile lost; ``heights`` are the data less it.
    tilts : ndarray
        Slope of each acquisition's fitted line (m/m, coarsest first): the line a
        levelled profile lost (``heights`` are the data less it too; round 2, session 29);
        for the windows of one row one shared tilt; each within
        :func:`~.lattice.tilt_bounds` (the shared one since round 2, session 33, a
        levelled profile's since session 34).
    lnA_stderr, H_stderr : float
        Standard errors (1 sigma) of ln A and H from the Fisher information of their
        likelihood (:func:`~.genes.amplitude_gene_errors`; NaN when not computed).
    M_support : tuple of int or None
        The range of M within 1.92 of the best log-likelihood (about 95 %,
        :func:`~.genes.ridge_support`): M is weakly identifiable.
    reproducibility : Reproducibility or None
        The genes of the left and right halves of the data, each sequenced from scratch,
        and whether they agree (:mod:`.reproduce`; "not a genome: the genes are not
        reproducible" when not; round 2, session 34). None: not run (the fit failed an
        earlier test).
    A0 : float
        Amplitude from the height variance of the coarsest acquisition as given (Eq.
        3.13), for comparison with the maximum-likelihood A. The fitted offset and tilt
        are unknowns of the model, not data: they are not put back (until round 2,
        session 33 the variance was of the heights less the fitted tilt, on measured
        rows a line of 3e3-5e5 m/m: A0 up to 9e13).
    seed : int or None
    elapsed : float
        Wall time (s).
    """

    genome: Genome
    success: bool
    message: str
    nit: int
    n: np.ndarray
    amplitudes: np.ndarray
    phases: np.ndarray
    ranges: list
    lengths: np.ndarray
    rms_errors: np.ndarray
    x: list
    heights: list
    fitted: list
    zd_x: np.ndarray
    zd: np.ndarray
    zd_fit: np.ndarray
    spectra: list
    gamma_psd: float
    H_psd: float
    M_loglik: np.ndarray
    offsets: np.ndarray = field(default_factory=lambda: np.zeros(0))
    tilts: np.ndarray = field(default_factory=lambda: np.zeros(0))
    held_out_errors: np.ndarray = field(default_factory=lambda: np.zeros(0))
    reproducibility: Optional[object] = None
    A0: float = float("nan")
    lnA_stderr: float = float("nan")
    H_stderr: float = float("nan")
    M_support: Optional[tuple] = None
    seed: Optional[int] = None
    elapsed: float = 0.0
    references: tuple = field(default=("thesis Sec. 3.3.1, Eq. 3.5-3.16",))

    __repr__ = compact_repr          # one line (the full arrays ran to ~80k characters)

    def __post_init__(self):
        freeze_containers(self)

    def zd_rms_error(self) -> Optional[float]:
        """rms(Z_d - Z_d^seq) / rms(Z_d) (relative, -), the report's ``zd_rms_error``; None
        when there is no Z_d (no common nodes) or when Z_d is round-off of the heights
        (mean Z_d^2 <= :func:`~.lattice.round_off_cost` of the coarsest acquisition's mean
        square height: two windows that show the same chromosomes, e.g. L and L/1.1 at
        N = 256, have Z_d ~ 2e-19 m on heights of 7e-4 m, and a ratio of two round-offs,
        2.66, is no error)."""
        if not self.zd.size:
            return None
        zd2 = float(np.mean(self.zd ** 2))
        if zd2 <= round_off_cost(np.mean(self.heights[0] ** 2)):
            return None
        return float(np.sqrt(np.mean((self.zd - self.zd_fit) ** 2) / zd2))

    def report(self) -> dict:
        """JSON-safe summary (genes, rms errors, ranges, diagnostics), with ``units`` (the
        unit of every number, :data:`REPORT_UNITS`)."""
        g = self.genome
        return {"success": bool(self.success), "message": self.message, "nit": int(self.nit),
                "genes": {"A": g.A, "H": g.H, "gamma": g.gamma, "lambda1": g.lambda1, "M": g.M},
                "lengths": self.lengths.tolist(), "ranges": [list(r) for r in self.ranges],
                "rms_errors": self.rms_errors.tolist(), "offsets": self.offsets.tolist(),
                "tilts": self.tilts.tolist(), "held_out_errors": self.held_out_errors.tolist(),
                "reproducibility": (None if self.reproducibility is None
                                    else self.reproducibility.report()),
                "zd_rms": float(np.sqrt(np.mean(self.zd ** 2))) if self.zd.size else None,
                "zd_rms_error": self.zd_rms_error(),
                "gamma_psd": self.gamma_psd, "H_psd": self.H_psd, "A0_variance": self.A0,
                "M_loglik": to_jsonable(self.M_loglik),
                "M_values": list(M_VALUES[:len(self.M_loglik)]),
                "lnA_stderr": self.lnA_stderr, "H_stderr": self.H_stderr,
                "M_support": None if self.M_support is None else list(self.M_support),
                "seed": self.seed, "elapsed_s": self.elapsed, "units": dict(REPORT_UNITS)}
