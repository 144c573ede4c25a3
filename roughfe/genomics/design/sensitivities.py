"""Exact sensitivities of the design residuals on the fixed contact sets (Sec. 4.3.1,
beyond the thesis' finite differences)."""
from __future__ import annotations

import numpy as np

from ...bem import contact_set_pressure_rate
from ...errors import InputError
from ..database import DatabaseSettings
from ..macro_micro import (periodic_approach, profile_response, profile_sweep, sweep_curve,
                           top_approach)
from ..similarity import read_curve
from .model import Design
from .objective import Objective


def residual_jacobian(design: Design, keys, objective: Objective, settings: DatabaseSettings,
                      evaluate=None):
    """Residuals r = (y_t - y)/y_t (as :meth:`Objective.residuals`) and their exact
    derivatives with respect to the phase variables ``keys`` on the fixed contact sets.

    At step j the contact set c_j is fixed and ``H_cc p_c = h_c - max h + Delta_j``
    (gap definition of :mod:`roughfe.bem.contact`), so with ``H_cc x_j = 1`` (H is
    symmetric; x_j from :func:`roughfe.bem.contact_set_pressure_rate`, the solve behind
    the exact stiffness K) the mean pressure varies as

        d p_j = (1/N) [x_j . dh_c + sum(x_j) (dDelta_j - d max h)],
        Delta_j = (j/n_t) f (max h - min h)

    (f = ``top_fraction``; a periodic surface, dim 2: ``f (max h - mean h)``,
    :func:`~roughfe.genomics.macro_micro.top_approach`).

    The heights vary with a phase phi_{m,n} of a part as
    ``dh/dphi = scale * weight * a_{m,n} (sin(q_n x + phi) - sin(phi))`` (Eq. 3.2;
    :meth:`Design.phase_derivative`, on a surface with the lattice wavevector).
    K by differences over the steps (``stiffness="fd"``) is ``D p / delta`` with a fixed
    difference matrix D and ``delta = (max h - min h)/n_t``; the exact per-step K and
    A(p) depend only on the contact sets, so their derivatives vanish. The chain then
    goes through the Eq. (4.2) rescaling ``eta = p_max^t / p_n`` and the linear
    interpolation at the target pressures (below the first rescaled pressure the first
    value held: :func:`~roughfe.genomics.similarity.read_curve`). Gene
    variables (``(part, name)`` keys) get forward differences. One BEM sweep plus n_t
    solves with H_cc replace the n + 1 sweeps of finite differences; each gene variable costs one more sweep (its forward
    difference). ``evaluate`` (an :class:`~.objective.Evaluator`), when given, counts
    every sweep run here on its ``n_sweeps``. The derivative ignores contact-set
    changes, as any derivative of this piecewise-smooth map must.

    Checked against central differences (issue 14; tests in
    ``tests/test_design_algorithms.py`` and ``tests/test_surface_database.py``): on the
    M-CCO design of the 60-genome database (N = 512, y_t1/y_t3, 10 phases) exact and
    central differences agree to 3e-10 (K rows) and 5e-10 (A rows) relative at steps
    1e-5 and 1e-6 rad. At 1e-4 rad and above a grazing node enters or leaves a contact
    set inside the step and the A rows of the differences jump (a node is 1/512 of A:
    differences up to 59 against an exact 0.15 at 1e-4 rad, "100 %" mismatch): that is
    the staircase of the node count, not an error of J. A second, unrelated source of
    apparent mismatch: a target pressure that coincides with a rescaled step of the
    design sits on a kink of the linear interpolation, where J is the one-sided
    derivative (of the segment below) and central differences average both sides
    (the 12 % seen on a surface test whose targets were the design's own pressures).
    So ``dA/dphi`` here is only the shift of the staircase along p (Eq. 4.2 and the
    interpolation): it is exact, and it says nothing about which phase adds a node.

    Returns
    -------
    (r, J) : ndarray (n_r,), ndarray (n_r, len(keys))
    """
    if design.modulation:
        raise InputError("exact sensitivities of a modulated design are not derived (the "
                         "modulation is set by the global stage, after the GCMMA stages)")
    surf = design.surface()
    h = surf.heights.ravel()
    n_nodes = h.size
    opts = settings.response_options()
    sweep = profile_sweep(surf, **opts)
    _count(evaluate)
    p = np.asarray(sweep.mean_pressure, float)
    if np.any(p <= 0):
        raise InputError("a loading step without contact: no sensitivities (use finite "
                         "differences)")
    curve = sweep_curve(sweep, settings.stiffness)
    k_vals = curve.stiffness
    i_max, i_min = int(np.argmax(h)), int(np.argmin(h))
    n_t = p.size
    frac = np.arange(1, n_t + 1) / n_t
    # dh/dvariable, shape (N, n_var): phases exactly, genes by differences below
    dh = np.zeros((n_nodes, len(keys)))
    gene_cols = []
    for col, key in enumerate(keys):
        if len(key) == 2:
            gene_cols.append(col)
            continue
        dh[:, col] = design.phase_derivative(*key).ravel()
    # the top approach (profile_sweep): fraction * (max h - min h), periodic: max h - mean h
    top = top_approach(surf, opts["kernel"], opts["top_fraction"])
    d_low = dh.mean(axis=0) if periodic_approach(surf, opts["kernel"]) else dh[i_min]
    d_ptp = opts["top_fraction"] * (dh[i_max] - d_low)
    dp = np.empty((n_t, len(keys)))
    for j, res in enumerate(sweep.results):
        xj = contact_set_pressure_rate(res).ravel()
        dp[j] = (xj @ dh + xj.sum() * (frac[j] * d_ptp - dh[i_max])) / n_nodes
    if settings.stiffness == "exact":
        dk = np.zeros_like(dp)
    else:
        delta = top / n_t
        d1 = np.gradient(np.eye(n_t), axis=0, edge_order=1)       # K = d1 @ p / delta
        dk = d1 @ dp / delta - np.outer(k_vals, d_ptp / n_t / delta)
    eta = objective.p_max / p[-1]
    pr = eta * p
    dpr = eta * (dp - np.outer(p, dp[-1] / p[-1]))
    r_out, j_out = [], []
    for t in objective.targets:
        sel = (t.pressure >= objective.p_range[0]) & (t.pressure <= objective.p_range[1])
        pt, yt = t.pressure[sel], t.values[sel]
        # the curve read as Objective.residuals reads it (read_curve: below p_1 the
        # first value held, its derivative that of y_1)
        y, dy = read_curve(pt, pr, curve.values(t.quantity), dpr,
                           dk if t.quantity == "K" else np.zeros_like(dp))
        r_out.append((yt - y) / yt)
        j_out.append(-dy / yt[:, None])
    r, jac = np.concatenate(r_out), np.vstack(j_out)
    if gene_cols:
        vals = design.phase_values(keys)
        for col in gene_cols:
            step = 1e-6 * max(abs(vals[col]), 1e-12)
            v = vals.copy()
            v[col] += step
            c2 = profile_response(design.with_phases(keys, v).surface(),
                                  **settings.response_options())
            _count(evaluate)
            jac[:, col] = (objective.residuals(c2) - r) / step
    return r, jac


def _count(evaluate):
    """One BEM sweep more on ``evaluate.n_sweeps`` (nothing without an evaluator)."""
    if evaluate is not None:
        evaluate.n_sweeps += 1
