"""Held-out nodes: does a sequenced lattice predict data it was not fitted to?

A small misfit does not make a genome: the lattice model of the acquisitions (Eq.
3.12-3.16: two unknowns per chromosome, an offset per acquisition, their tilts; in 2D,
Eq. 3.17: two per wave (m, n) and a plane per acquisition) is linear in its wave
coefficients, and with about as many unknowns as distinct nodes it reproduces any
heights, genome or not. The test of a model's degrees of freedom is cross-validation:
the nodes are split into :data:`HOLD_OUT_FOLDS` folds *by position* (every
acquisition's node at one x, or (x, y), is held out together: nested windows share
positions, and a twin left in the fit would pin the held-out height), each fold is
predicted by the linear fit of the others on the same lattice, and the prediction
errors are compared with the tolerance the fit itself must meet. A genome predicts its
held-out nodes to about its misfit (exact WM data: to round-off; noisy data: to the
noise), an overfit misses them by far more than it misses the nodes it was fitted to.

The profile sequencer (:func:`held_out_errors`) and the surface sequencer
(:func:`~.surface.sequence_surfaces`, on the rows of its nonlinear fit) share the
folds (:func:`node_folds`), the predictions (:func:`held_out_residual`) and the verdict
(:func:`overfit_reason`).
"""
from __future__ import annotations

import math

import numpy as np

from .lattice import design_matrix, solve_model

#: folds of the node positions: 1/5 of the positions held out at a time (fewer folds hold
#: out more, and leave a resolvable genome at N = 40 too few nodes per chromosome)
HOLD_OUT_FOLDS = 5
#: seed of the random split of the positions into folds, fixed so that the verdict does
#: not depend on the sequencer's ``seed``; random, as the positions of nested windows
#: interleave periodically (a split by every k-th position can put all nodes of one
#: window into one fold)
HOLD_OUT_SEED = 0


def node_folds(coords, step, folds=HOLD_OUT_FOLDS, seed=HOLD_OUT_SEED) -> np.ndarray:
    """Fold (0..``folds`` - 1) of every node: ``coords`` (rows, d) are the node
    coordinates (m; d = 1 for profiles, 2 for surfaces), nodes whose coordinates all
    agree within 1e-6 ``step`` (m, the finest node spacing) share a position and a fold;
    the distinct positions are dealt to the folds in a random order seeded by ``seed``."""
    coords = np.asarray(coords, dtype=float).reshape(len(coords), -1)
    keys = np.empty(coords.shape, dtype=int)
    for j in range(coords.shape[1]):              # the distinct values along each axis
        order = np.argsort(coords[:, j], kind="stable")
        new = np.concatenate([[True], np.diff(coords[order, j]) > 1e-6 * step])
        keys[order, j] = np.cumsum(new) - 1
    _, group = np.unique(keys, axis=0, return_inverse=True)
    group = group.ravel()
    deal = np.random.default_rng(seed).permutation(int(group.max()) + 1) % folds
    return deal[group]


def position_folds(acqs, folds=HOLD_OUT_FOLDS, seed=HOLD_OUT_SEED) -> np.ndarray:
    """:func:`node_folds` of the stacked nodes of profile acquisitions (their x)."""
    x = np.concatenate([a.x for a in acqs])
    step = min(a.length / (a.z.size - 1) for a in acqs)
    return node_folds(x[:, None], step, folds, seed)


def held_out_residual(rhs, fold, predict) -> np.ndarray:
    """``rhs`` less its prediction, each fold's rows (``fold``, one label per row)
    predicted by ``predict(keep)``: the model's values on every row, fitted to the rows
    ``keep`` (bool per row) only."""
    err = np.zeros_like(rhs)
    for f in np.unique(fold):
        out = fold == f
        if (~out).any():
            err[out] = rhs[out] - predict(~out)[out]
    return err


def held_out_errors(log_q1, log_gamma, acqs, ranges, weights, rhs,
                    folds=HOLD_OUT_FOLDS, regularise=True) -> np.ndarray:
    """Relative rms error of each profile acquisition's nodes predicted by the fits that
    left them out (:func:`position_folds`), the lattice (``log_q1``, ``log_gamma``,
    ``ranges``) fixed: rms(Z_i - Z_i^held-out) / rms(Z_i), as ``rms_errors``
    (``weights`` are 1 / rms(Z_i), ``rhs`` the weighted stacked heights, as in
    :func:`~.lattice.design_matrix`; each fit bounds the shared tilt of the windows of
    one row as the sequencer does, :func:`~.lattice.solve_model`, and, with
    ``regularise``, is damped where its data cannot resolve it as the sequencer's final
    fit is, :mod:`.regularise`)."""
    _, mat = design_matrix(log_q1, log_gamma, acqs, ranges, weights)
    err = held_out_residual(rhs, position_folds(acqs, folds),
                            lambda keep: mat @ solve_model(mat[keep], rhs[keep], acqs,
                                                           regularise=regularise))
    ends = np.cumsum([0] + [a.z.size for a in acqs])
    return np.array([math.sqrt(float(np.mean(err[i:j] ** 2))) for i, j in zip(ends, ends[1:])])


def overfit_reason(held_out, fitted, unknowns, nodes, what="chromosome"):
    """The "an overfit" reason of a fit within the tolerance whose held-out nodes are
    missed by more: for the acquisition ``i`` of largest ``held_out`` error, its
    ``unknowns[i]`` (``what`` unknowns), ``nodes[i]`` and both relative errors."""
    i = int(np.argmax(held_out))
    return (f"an overfit: {unknowns[i]} {what} unknowns on {nodes[i]} nodes (acquisition "
            f"{i + 1}); its nodes held out of the fit ({HOLD_OUT_FOLDS} folds by position) "
            f"are missed by {held_out[i]:.3g} (relative rms), the fitted ones by "
            f"{fitted[i]:.3g}")
