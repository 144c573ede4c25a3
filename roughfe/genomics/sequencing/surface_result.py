"""Step 5 and the report of 2D MWM sequencing: the genes from the fitted wave
coefficients, the misfit per acquisition and the result.

See :mod:`roughfe.genomics.sequencing.surface` for the model and the conventions. Beyond
the thesis: its sequencing (Sec. 3.3.1) is of profiles, whose amplitudes it never checks
against the genome's power law; here the misfit reported is the returned genome's.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Optional

import numpy as np
from scipy.optimize import least_squares

from ..genome import Genome, surface_heights
from .holdout import held_out_residual, node_folds
from .result import REPORT_UNITS
from .surface_data import surface_acquisitions


def _wave_gram(gram, n_waves):
    """The Gram matrix of the 2 W wave columns with the plane columns projected out (Schur
    complement): the height misfit of wave coefficients c - c_fit, with each
    acquisition's plane refitted, is (c - c_fit)^T S (c - c_fit)."""
    k = 2 * n_waves
    return gram[:k, :k] - gram[:k, k:] @ np.linalg.solve(gram[k:, k:], gram[k:, :k])


def _height_genes(x0, nn, mm, phi, ln_gamma, n_ridges, gram, coef):
    """(ln G, H, ln alpha_1..alpha_{M-1}) minimising the height misfit of the genome's
    waves b_mn = G gamma^((1-n)H) alpha_m (alpha_M = 1 / prod of the others) with the
    fitted phases, (c(x) - c_fit)^T S (c(x) - c_fit) (:func:`_wave_gram`), from ``x0``
    (the fit of ln b_mn). Beyond the thesis (whose profile genes come from the amplitude
    trend alone): the log fit weighs the long waves by their size, while near the window
    length they are nearly collinear with each other and the plane and poorly determined
    by the heights (1 % noise: the genome misfit 1.40 x the noise, 1.0-1.1 x with these)."""
    evals, evecs = np.linalg.eigh(0.5 * (gram + gram.T))
    root = np.sqrt(np.clip(evals, 0.0, None))[:, None] * evecs.T
    trig = np.r_[-np.cos(phi), np.sin(phi)]
    mm2, nn2 = np.r_[mm, mm], np.r_[nn, nn]
    last = mm2 == n_ridges - 1

    def coefs(x):
        ln_alpha = np.append(x[2:], -np.sum(x[2:]))
        return np.exp(x[0] + (1.0 - nn2) * x[1] * ln_gamma + ln_alpha[mm2]) * trig

    def jac(x):
        c = coefs(x)
        cols = [c, (1.0 - nn2) * ln_gamma * c]
        cols += [c * ((mm2 == j).astype(float) - last) for j in range(n_ridges - 1)]
        return root @ np.column_stack(cols)

    res = least_squares(lambda x: root @ (coefs(x) - coef), np.asarray(x0, float), jac=jac,
                        method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15)
    return res.x


def genes_from_fit(p, sol, ranges):
    """Genome genes from the fitted coefficients (see the module notes): a fit of ln b_mn
    weighted by b_mn^2, refined to the least height misfit (:func:`_height_genes`)."""
    nn, mm = sol["nn"], sol["mm"]
    w = nn.size
    u, v = sol["coef"][:w], sol["coef"][w:2 * w]
    theta = np.asarray(p[2:], float)
    flip = np.floor(theta / np.pi).astype(int) % 2 == 1     # theta in [pi, 2 pi) mod 2 pi
    theta = np.mod(theta, np.pi)
    v = np.where(flip[mm], -v, v)
    order = np.argsort(theta)                     # ridges listed by angle in [0, pi)
    rank = np.empty_like(order)
    rank[order] = np.arange(order.size)
    theta, mm = theta[order], rank[mm]
    b = np.hypot(u, v)
    phi = np.arctan2(v, -u)
    n = np.unique(nn)
    M = theta.size
    phases = np.zeros((M, n.size))
    phases[mm, nn - n[0]] = phi
    amp = np.zeros((M, n.size))
    amp[mm, nn - n[0]] = b
    gamma = math.exp(p[1])
    lam1 = 2 * math.pi / math.exp(p[0])
    # ln b = ln G + (1 - n) H ln gamma + ln alpha_m, sum ln alpha_m = 0, weights b^2
    good = b > 0
    rows = np.flatnonzero(good)
    mat = np.zeros((rows.size, 2 + M))
    mat[:, 0] = 1.0
    mat[:, 1] = (1.0 - nn[rows]) * math.log(gamma)
    mat[np.arange(rows.size), 2 + mm[rows]] = 1.0
    rhs = np.log(b[rows])
    wts = b[rows] / b[rows].max()
    # gauge: replace ln alpha_M by -sum of the others
    red = mat[:, :2 + M - 1].copy()
    red[:, 2:] -= mat[:, [2 + M - 1]]
    sol_g, *_ = np.linalg.lstsq(red * wts[:, None], rhs * wts, rcond=None)
    if 0.0 < sol_g[1] <= 3.0:
        # then the genes whose genome misfits the heights least (phases as fitted); an
        # amplitude trend outside the WM range is left as it is (the caller fails on it)
        sign = np.r_[np.ones(w), np.where(flip[sol["mm"]], -1.0, 1.0)]   # v was flipped
        sol_g = _height_genes(sol_g, nn, mm, phi, math.log(gamma), M,
                              _wave_gram(sol["gram"], w) * np.outer(sign, sign), np.r_[u, v])
    ln_g, hurst = sol_g[0], sol_g[1]
    ln_alpha = np.append(sol_g[2:], -np.sum(sol_g[2:]))
    prefactor = math.exp(ln_g)
    a_gene = prefactor / (math.sqrt(math.log(gamma) / M) * (2 * math.pi / lam1) ** (-hurst))
    return dict(A=a_gene, H=float(hurst), gamma=gamma, lambda1=lam1, phases=phases,
                n_first=int(n[0]), angles=theta, anisotropy=np.exp(ln_alpha), amplitudes=amp)


@dataclass(frozen=True, eq=False)
class SurfaceSequencingResult:
    """Sequenced surface genome and its quality report (OptimizeResult-like).

    Attributes
    ----------
    genome : Genome or None
        The band-limited genome (None when no WM lattice was found).
    success : bool
        True when the genome reproduces every acquisition within ``rms_tolerance``.
    message : str
    nit : int
        Residual evaluations of the nonlinear fit.
    ranges : list of (int, int)
        Chromosome range per acquisition, coarsest first: Eq. 3.5's, less the empty
        chromosomes at either end of the band (:func:`~.surface_fit.present_band`).
    lengths, rms_errors : ndarray
        Observation lengths (m) and relative rms misfits per acquisition of the returned
        genome realised on the acquisition's nodes (about the best plane, as the fit
        takes a plane per acquisition) over ``signal_rms``.
    amplitudes : ndarray (M, n_c)
        Fitted wave amplitudes b_mn (m).
    peaks : list of SurfacePeaks
    elapsed : float
    signal_rms : ndarray or None
        Rms height of each acquisition about its best plane (m), the part the waves must
        reproduce (the model's plane per acquisition takes the rest); None without a fit.
    fit_rms_errors : ndarray or None
        The same misfits of the fit, every wave (m, n) with its own amplitude b_mn; the
        genome's ``rms_errors`` are larger where the amplitudes are off the power law
        G gamma^((1-n)H) alpha_m the genome imposes.
    held_out_errors : ndarray or None
        The same misfits of the fit's rows (:func:`held_out_misfits`: all nodes up to
        ~16384, else the tensor sub-grid of the nonlinear fit) each predicted by the fit
        that left its position out (5 folds): about ``fit_rms_errors`` for a genome, far
        more for an overfit (a fit within the tolerance whose held-out misfit exceeds it
        is "not a genome: an overfit"; round 2, session 33).
    reproducibility : Reproducibility or None
        The lattice and ridges of the two halves of the data
        (:mod:`~roughfe.genomics.sequencing.surface_reproduce`; a fit that fails an
        earlier test is not tested: None).
    """

    genome: Optional[Genome]
    success: bool
    message: str
    nit: int
    ranges: list
    lengths: np.ndarray
    rms_errors: np.ndarray
    amplitudes: np.ndarray
    peaks: list
    elapsed: float = 0.0
    references: tuple = field(default=("thesis Sec. 3.3.2, Eq. 3.17 (projected form)",))
    signal_rms: Optional[np.ndarray] = None
    fit_rms_errors: Optional[np.ndarray] = None
    held_out_errors: Optional[np.ndarray] = None
    reproducibility: Optional[object] = None

    def report(self) -> dict:
        """JSON-safe summary (report.json of `genome sequence` on surfaces), with
        ``units`` for the keys it holds."""
        g = self.genome
        genes = None if g is None else {
            "A": g.A, "H": g.H, "gamma": g.gamma, "lambda1": g.lambda1, "M": g.M,
            "angles_deg": np.degrees(g.angles).tolist(), "anisotropy": g.anisotropy.tolist(),
            "n_first": g.n_first, "n_last": g.n_last}
        out = {"success": bool(self.success), "message": self.message, "nit": int(self.nit),
               "genes": genes, "lengths": self.lengths.tolist(),
               "ranges": [list(r) for r in self.ranges],
               "rms_errors": [float(e) for e in self.rms_errors],
               "signal_rms_m": (None if self.signal_rms is None
                                else [float(v) for v in self.signal_rms]),
               "fit_rms_errors": (None if self.fit_rms_errors is None
                                  else [float(e) for e in self.fit_rms_errors]),
               "held_out_errors": (None if self.held_out_errors is None
                                   else [float(e) for e in self.held_out_errors]),
               "reproducibility": (None if self.reproducibility is None
                                   else self.reproducibility.report()),
               "elapsed_s": self.elapsed}
        units = {**REPORT_UNITS, "angles_deg": "deg", "anisotropy": "1",
                 "n_first": "1 (chromosome number)", "n_last": "1 (chromosome number)",
                 "signal_rms_m": "m", "fit_rms_errors": "1 (relative)"}
        out["units"] = {k: u for k, u in units.items() if k in out or k in (genes or {})}
        return out


def failure(message, acqs, peaks, t0):
    return SurfaceSequencingResult(
        genome=None, success=False, message=message, nit=0, ranges=[],
        lengths=np.array([a.length for a in acqs]), rms_errors=np.full(len(acqs), np.inf),
        amplitudes=np.zeros((0, 0)), peaks=peaks, elapsed=time.perf_counter() - t0)


def genome_residual(genome, full):
    """Heights minus the genome's realisation on the valid nodes of every acquisition of
    ``full`` (a GridModel of all nodes), in its row order: the chromosomes of Eq. 3.5 at
    each acquisition that the genome holds, as :func:`~roughfe.genomics.genome.realize_surface`
    sums them, at the acquisition's own node coordinates."""
    out = []
    for k, (a, grid) in enumerate(zip(full.acqs, full.grids)):
        z, _ = surface_heights(genome, a.length, full.n_nodes, grid["x"], grid["y"])
        out.append(full.z[full.block == k] - z[grid["ok"]])
    return np.concatenate(out)


def about_plane(x, y, ok, f):
    """``f`` (m, the values on the nodes ``ok`` of the grid ``x`` by ``y``, in the order of
    ``z[ok]``) minus its least-squares plane a + b x + c y: the part of a height field or
    residual that a plane per acquisition (the fit's, or a removed mean plane) cannot
    absorb."""
    xx, yy = np.meshgrid(x, y, indexing="ij")
    plane = np.column_stack([np.ones(int(ok.sum())), xx[ok], yy[ok]])
    return f - plane @ np.linalg.lstsq(plane, f, rcond=None)[0]


def plane_free_misfits(full, resid):
    """Relative rms misfits and signal rms per acquisition of ``full`` (a GridModel of all
    nodes) for the residual ``resid`` on its rows: the rms of the residual about its best
    plane over the rms height about the acquisition's best plane (the model fits a plane
    per acquisition, so a fit's residual has none and a genome's is taken without its
    plane). Relative to the heights without their best plane: a misfit over the variance
    about the mean let a tilt pass a fit that explained nothing else (10 % noise read
    9.9 %, with a tilt of 100 rms 0.34 %)."""
    errs, signal = [], []
    for k in range(len(full.acqs)):
        rows = full.block == k
        grid = full.grids[k]
        fields = [about_plane(grid["x"], grid["y"], grid["ok"], f)
                  for f in (full.z[rows], resid[rows])]
        signal.append(float(np.sqrt(np.mean(fields[0] ** 2))))
        errs.append(float(np.sqrt(np.mean(fields[1] ** 2))) / max(signal[-1], 1e-300))
    return np.array(errs), np.array(signal)


def held_out_misfits(model, p, ranges, regularise=False):
    """Relative rms misfit of each acquisition's rows of ``model`` (the GridModel of the
    nonlinear fit: every node up to ~16384 in all, else a tensor sub-grid) predicted by
    the linear fit (every wave its own amplitude, a plane per acquisition; the model's
    own solve, the other rows left out as undefined nodes) of the other folds at the
    lattice ``p``, ``ranges`` (:mod:`.holdout`: 5 folds by (x, y)), taken as
    :func:`plane_free_misfits` (about the best plane, over the signal about it); inf
    when the other folds do not determine the waves (a singular fit). ``regularise``:
    each fold's fit damped as the final fit is (:meth:`~.surface_grid.GridModel.solve`)."""
    def predict(keep):
        coef = model.solve(p, ranges, exact=True, keep=keep, regularise=regularise)["coef"]
        return np.concatenate([h[g["ok"]] for h, g in
                               zip(model.heights(p, ranges, coef), model.grids)])

    step = min(a.length / (a.z.shape[0] - 1) for a in model.acqs)
    try:
        err = held_out_residual(model.z, node_folds(model.node_coordinates(), step), predict)
    except np.linalg.LinAlgError:
        return np.full(len(model.acqs), np.inf)
    return plane_free_misfits(model, err)[0]


def misfit_fields(genome, surfaces, valid=None):
    """What the misfit of :func:`plane_free_misfits` compares, per acquisition (coarsest
    first): ``(acquisition, measured, sequenced, difference)``, the measured heights and
    the genome's (:func:`~roughfe.genomics.genome.surface_heights` at the acquisition's
    own node coordinates, ``metadata["x0"]``/``"y0"`` honoured as by the sequencer), each
    about its best plane, and ``measured - sequenced`` (the residual about its best
    plane), in m on the N x N grid, NaN where undefined. The rms of ``difference`` over
    that of ``measured`` is the relative misfit ``rms_errors`` of the sequencing."""
    out = []
    for a in surface_acquisitions(surfaces, valid):
        model, _ = surface_heights(genome, a.length, a.z.shape[0], a.x, a.y)
        fields = []
        for f in (a.z, model):
            g = np.full(a.z.shape, np.nan)
            g[a.valid] = about_plane(a.x, a.y, a.valid, f[a.valid])
            fields.append(g)
        out.append((a, fields[0], fields[1], fields[0] - fields[1]))
    return out
