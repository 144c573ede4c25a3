"""Genome sequencing of rough profiles from nested acquisitions (thesis Sec. 3.3.1, Eq. 3.5-3.16).

Input: two or more acquisitions of the same profile at observation lengths
L_1 > L_2 > ... (e.g. 10x, 20x, 100x), each with the same number of nodes N, centred on
the same point x = 0 (node coordinates from ``metadata["x0"]`` or the genome node
convention of :mod:`roughfe.genomics.genome`).

What a profile can and cannot tell (the thesis is loose here)
-------------------------------------------------------------
By the reduced form (Eq. 3.7-3.8, :mod:`roughfe.genomics.chromosomes`) every chromosome
of a *profile* is exactly one cosine,

    C_n(x) = c_n [cos(theta_n) - cos(q_n x + theta_n)],
    c_n e^{i theta_n} = G gamma^{(1-n) H} sum_m e^{i phi_{m,n}},

so the heights depend on (A, M, Phi) only through the complex amplitudes c_n e^{i theta_n}.
Consequences, stated once:

* gamma and lambda1 (the wavenumber lattice) and every c_n, theta_n are identifiable,
  exactly for WM data. With the lattice known the fit is *linear*: Eq. (3.12)-(3.16) with
  the phasor sums as unknowns, (eta, xi) -> c_n (cos theta_n, sin theta_n), needs no
  constraint eta^2 + xi^2 = 1, no fmincon, no (eta, xi) vs angle choice, and uses all
  nodes of all acquisitions (the thesis's low-pass behaviour came from 128 fitting nodes).
  Only (ln q_1, ln gamma) are nonlinear: they are refined by variable projection
  (scipy ``least_squares`` on the residual of the linear solve).
* M and the individual phi_{m,n} are *not* identifiable from profiles: any M phasors
  with the same sum give the same heights (the thesis's P_m(alpha) is flat in M up to
  optimiser noise). A and H enter only through the mean trend of |c_n|: with random phases
  |sum_m e^{i phi}|^2 / M is ~ exponentially distributed with mean 1 (independent of M), so
  A and H are *statistical* estimates with an error set by the number of chromosomes
  (standard deviation ~4.4 % on H over 20 phase seeds of Table 1, 22 chromosomes),
  whatever the fitting method.
  They are estimated here by maximum likelihood (:func:`amplitude_genes`); M by
  maximum likelihood over 2..20 using the distribution of the resultant of M random unit
  phasors (weak: M = 8 and M = 12 are nearly indistinguishable); the phases are then
  *one* set of M phasors per chromosome with the fitted sum (drawn from a seeded rng),
  so the sequenced genome reproduces the acquisitions exactly and has the fitted genes.

Steps (:func:`sequence_profiles`)
---------------------------------
1. PSD of each acquisition (Hann window, ``roughfe.surfaces.stats.power_spectrum``) and
   its peaks: the vertices of the upper convex hull of the log-log PSD (quickhull,
   ``scipy.spatial.ConvexHull``, as the thesis) plus the prominent local maxima,
   located to sub-bin precision by a parabola in log PSD.
2. gamma (Eq. 3.6): the peaks of all acquisitions lie on one lattice
   ln q_n = ln q_1 + (n-1) ln gamma; ln gamma is the period of a comb fitted to the peak
   abscissae (largest period with near-maximal coherence), refined by regression. Fewer
   than 3 peaks over all acquisitions: an InputError (no lattice can be read from them;
   more nodes or acquisitions are needed).
3. lambda1 so that n_s = 1 for the coarsest acquisition (Eq. 3.5): lambda1 in [L_1, gamma L_1).
4. Variable projection with continuation in the highest chromosome index (the basin of
   ln gamma shrinks like 1/n), restarts from the best comb periods; the lattice label is
   finally chosen among the shifts compatible with step 3 by the Bayesian information
   criterion (BIC). A lattice gamma^(1/k) holds the data's lattice as every k-th
   chromosome and fits as well (the others empty, or holding noise), and with noise the
   comb offers only such sub-lattices: a fit within ``rms_tolerance`` is therefore also
   tried on its coarser lattices gamma^k (k = 2..24, as the 2D sequencer does) and the
   lower BIC wins.
   The final fit on the chosen lattice (and the fits of the held-out nodes) is damped
   where the data cannot resolve it (:mod:`.regularise`: Tikhonov at lambda = the
   least-squares noise level over the data's height), so that nearly collinear long
   chromosomes do not carry waves that cancel; least squares ranks the lattices.
5. Genes A, H (maximum likelihood on c_n, M-free), M, phases; Z_d = Z_1 - Z_2 at the
   common nodes; relative rms errors of the realisations of the sequenced genome; a
   quality report (success is False, with a message, when the relative rms error of any
   acquisition exceeds ``rms_tolerance``: the profile is not WM-like; when the nodes held
   out of the fit are missed by more, :mod:`.holdout`: an overfit; or when the two
   halves of the data give other genes, :mod:`.reproduce`: not reproducible).

Modules: :mod:`.acquisitions` (checks), :mod:`.peaks` (step 1), :mod:`.lattice` (steps
2-4), :mod:`.search` (steps 1-4 and the final fit, as one call), :mod:`.regularise` (the
damped final fit), :mod:`.holdout` (held-out nodes), :mod:`.reproduce` (the genes of the
two halves), :mod:`.genes` (step 5), :mod:`.result`, :mod:`.profile` (the driver,
:func:`sequence_profiles`) and :mod:`.zd` (the thesis's Z_d fit, for the record).
Surfaces (2D MWM, issue 15): :mod:`.surface_data` (acquisitions, peaks, ridge directions),
:mod:`.surface_grid` (the grid model of the fit; its final solve damped as the profile
fit's, :mod:`.regularise`), :mod:`.surface_fit` (the nonlinear fit and the band of
chromosomes the data hold), :mod:`.surface` (:func:`sequence_surfaces`),
:mod:`.surface_result` (genes, misfits, result) and :mod:`.surface_reproduce` (the
lattice and ridges of the two halves).
"""
from .acquisitions import MIN_NODES, Acquisition, acquisitions_from_surfaces
from .genes import (amplitude_gene_errors, amplitude_genes, peak_slope_H, phases_with_sums,
                    ridge_likelihood, ridge_support, variance_amplitude)
from .lattice import comb_periods, label_q1, lattice_from_period
from .peaks import SpectrumPeaks, refine_peaks, spectrum_peaks, upper_hull
from .profile import sequence_profiles
from .result import SequencingResult
from .surface import SurfaceSequencingResult, sequence_surfaces
from .surface_data import SurfaceAcquisition, SurfacePeaks, surface_acquisitions, surface_peaks
from .zd import ZdRidgeFit, thesis_zd_fit

__all__ = ["MIN_NODES", "Acquisition", "acquisitions_from_surfaces", "amplitude_genes",
           "amplitude_gene_errors", "ridge_support",
           "peak_slope_H", "phases_with_sums", "ridge_likelihood", "variance_amplitude",
           "comb_periods", "label_q1", "lattice_from_period", "SpectrumPeaks", "refine_peaks",
           "spectrum_peaks", "upper_hull",
           "sequence_profiles", "SequencingResult", "ZdRidgeFit", "thesis_zd_fit",
           "sequence_surfaces", "SurfaceSequencingResult", "SurfaceAcquisition", "SurfacePeaks",
           "surface_acquisitions", "surface_peaks"]
