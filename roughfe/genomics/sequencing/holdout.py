"""Held-out nodes: does a sequenced lattice predict data it was not fitted to?

A small misfit does not make a genome: the lattice model of the acquisitions (Eq.
3.12-3.16: two unknowns per chromosome, an offset per acquisition, their tilts) is
linear in its chromosome sums, and with about as many unknowns as distinct nodes it
reproduces any heights, genome or not. The test of a model's degrees of freedom is
cross-validation: the nodes are split into :data:`HOLD_OUT_FOLDS` folds *by position*
(every acquisition's node at one x is held out together: the windows of one row share
samples, and a twin left in the fit would pin the held-out height), each fold is
predicted by the linear fit of the others on the same lattice, and the prediction
errors are compared with the tolerance the fit itself must meet. A genome predicts its
held-out nodes to about its misfit (exact WM data: to round-off; noisy data: to the
noise), an overfit misses them by far more than it misses the nodes it was fitted to.
"""
from __future__ import annotations

import math

import numpy as np

from .lattice import design_matrix, solve_linear

#: folds of the node positions: 1/5 of the positions held out at a time (fewer folds hold
#: out more, and leave a resolvable genome at N = 40 too few nodes per chromosome)
HOLD_OUT_FOLDS = 5
#: seed of the random split of the positions into folds, fixed so that the verdict does
#: not depend on the sequencer's ``seed``; random, as the positions of nested windows
#: interleave periodically (a split by every k-th position can put all nodes of one
#: window into one fold)
HOLD_OUT_SEED = 0


def position_folds(acqs, folds=HOLD_OUT_FOLDS, seed=HOLD_OUT_SEED) -> np.ndarray:
    """Fold (0..``folds`` - 1) of every node of the stacked acquisitions: nodes at one x
    (within 1e-6 of the finest spacing) share a fold; the distinct positions are dealt
    to the folds in a random order seeded by ``seed``."""
    x = np.concatenate([a.x for a in acqs])
    step = min(a.length / (a.z.size - 1) for a in acqs)
    order = np.argsort(x, kind="stable")
    new = np.concatenate([[True], np.diff(x[order]) > 1e-6 * step])
    group = np.empty(x.size, dtype=int)
    group[order] = np.cumsum(new) - 1
    deal = np.random.default_rng(seed).permutation(int(group.max()) + 1) % folds
    return deal[group]


def held_out_errors(log_q1, log_gamma, acqs, ranges, weights, rhs,
                    folds=HOLD_OUT_FOLDS) -> np.ndarray:
    """Relative rms error of each acquisition's nodes predicted by the fits that left
    them out (:func:`position_folds`), the lattice (``log_q1``, ``log_gamma``, ``ranges``)
    fixed: rms(Z_i - Z_i^held-out) / rms(Z_i), as ``rms_errors`` (``weights`` are
    1 / rms(Z_i), ``rhs`` the weighted stacked heights, as in
    :func:`~.lattice.design_matrix`)."""
    _, mat = design_matrix(log_q1, log_gamma, acqs, ranges, weights)
    fold = position_folds(acqs, folds)
    err = np.zeros_like(rhs)
    for f in range(folds):
        out = fold == f
        if out.any() and (~out).any():
            err[out] = rhs[out] - mat[out] @ solve_linear(mat[~out], rhs[~out])
    ends = np.cumsum([0] + [a.z.size for a in acqs])
    return np.array([math.sqrt(float(np.mean(err[i:j] ** 2))) for i, j in zip(ends, ends[1:])])
