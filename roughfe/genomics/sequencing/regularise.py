"""The linear chromosome fit damped where the data cannot resolve it (Tikhonov, with the
damping set by the fit's own misfit).

With the lattice known the chromosome fit is linear (Eq. 3.12-3.16, :func:`~.lattice.
design_matrix`): A x = b, the columns a_j of A the chromosomes' ``1 - cos(q_n x)`` and
``sin(q_n x)`` on the stacked weighted nodes (each acquisition weighted to unit rms), then
an offset per acquisition and the tilts. On the fine lattices that fits of measured rows
end on (gamma 1.17-1.19) the long chromosomes run a few cycles or fewer over the row and,
with the line, are nearly collinear: the column-scaled design has cond 1e14-1e17 at the
sequenced lattices of di-1, x3p-2 and opd-1 (``--nodes 128``). Least squares then moves
along those directions by whatever the data put into them, noise or a shape that is no
WM profile: waves of 0.4-7 m that cancel on rows of 20-200 nm, which miss the nodes held
out of the fit by 7-29 times the heights.

The rule. With D = diag ||a_j|| and the SVD A D^-1 = U S V^T, a coefficient along the
right singular vector v_i puts s_i times itself into the data. The largest coefficient
admitted is the one whose height is :data:`PRIOR_SCALE` times the data's (weighted norm
kappa ||b||, kappa = :data:`PRIOR_SCALE` = 1: no unknown alone carries more height than
the data); the data's noise level is that of
the least-squares fit, sigma = ||A x_LS - b|| / sqrt(m - p) (m rows, p unknowns). A
direction is resolved when an admitted coefficient along it shows above the noise,
s_i kappa ||b|| > sigma, that is s_i > lambda with

    lambda = sigma / (kappa ||b||),

and the fit is Tikhonov's at that lambda (the most probable coefficients with Gaussian
noise of level sigma and a Gaussian prior of scale kappa ||b|| on each column's height):

    minimise ||A x - b||^2 + lambda^2 sum_j ||a_j||^2 x_j^2,
    x = D^-1 V diag(s_i / (s_i^2 + lambda^2)) U^T b.

Resolved directions (s_i >> lambda) keep their least-squares coefficient; unresolved
ones (s_i << lambda) are damped to s_i beta_i / lambda^2 (beta = U^T b). It is solved as
the least squares of the stacked system [A; lambda D] x = [b; 0] (:func:`damped_system`),
of condition number at most s_1 / lambda, so that the bounds of
:func:`~.lattice.solve_model` apply to it unchanged.

What it costs: for data whose least-squares coefficient along each v_i is admitted
(|beta_i| / s_i <= kappa ||b||), damping v_i raises ||A x - b||^2 by
lambda^4 beta_i^2 / (s_i^2 + lambda^2)^2 <= sigma^2 / 4, so the misfit^2 rises by at
most the factor 1 + p / (4 (m - p)). Exact data (WM genomes) have sigma at round-off and
keep their exact fit. What least squares fits along unresolved directions is no part of
any genome with admitted amplitudes; the misfit rises by its share (measured, round 2,
session 34: docs/theory/05_genomics.md).
"""
from __future__ import annotations

import math

import numpy as np

#: kappa: the prior scale of one unknown's column height, in units of the data's (weighted
#: norms): a chromosome of a WM profile carries no more height than the profile (WM fits
#: stay below the largest height; the amplitude guard, :data:`~.lattice.OVERFIT_FACTOR`,
#: judges fits whose data demand more). Measured (round 2, session 34, ``--nodes 128``):
#: kappa 1 leaves the largest amplitude of di-1's row at 1.3 times its heights (kappa
#: 10: 7.7 times, misfit 2.07 % for 2.10 %); Table 1 with 1 % noise moves by at most
#: 5.5e-5 of its largest amplitude (kappa 10: 5.5e-7), exact data not at all
PRIOR_SCALE = 1.0


def resolution_damping(mat, rhs, coef, prior=PRIOR_SCALE) -> float:
    """lambda = sigma / (``prior`` ||rhs||) of the least-squares coefficients ``coef`` of
    ``mat`` x = ``rhs`` (module notes), sigma^2 = ||mat coef - rhs||^2 / (m - p); 0 (no
    damping) when the fit has no rows to spare (p >= m: no misfit measures the noise)
    or the data are zero."""
    m, p = mat.shape
    r = rhs - mat @ coef
    return noise_damping(float(r @ r), m, p, math.sqrt(float(rhs @ rhs)), prior)


def noise_damping(rss, rows, unknowns, rhs_norm, prior=PRIOR_SCALE) -> float:
    """lambda = sigma / (``prior`` ``rhs_norm``) with sigma^2 = ``rss`` / (``rows`` -
    ``unknowns``): the damping of a least-squares fit of ``unknowns`` coefficients to
    ``rows`` data of norm ``rhs_norm`` that left the residual sum of squares ``rss``
    (module notes; the profile fit, :func:`resolution_damping`, and the surface fit,
    :meth:`~.surface_grid.GridModel.solve`). 0 (no damping) when the fit has no rows to
    spare (``unknowns`` >= ``rows``: no misfit measures the noise) or the data are zero."""
    if rows <= unknowns or rhs_norm == 0.0:
        return 0.0
    return math.sqrt(rss / (rows - unknowns)) / (prior * rhs_norm)


def damped_system(mat, rhs, damping):
    """The stacked least-squares system [mat; lambda D] x = [rhs; 0] of Tikhonov's fit at
    lambda = ``damping`` (D = diag of the column norms of ``mat``): (matrix, rhs)."""
    scale = np.linalg.norm(mat, axis=0)
    return (np.vstack([mat, np.diag(damping * scale)]),
            np.concatenate([rhs, np.zeros(mat.shape[1])]))
