"""The thesis's Eq. (3.12)-(3.15) on Z_d = Z_1 - Z_2, for the record (Sec. 3.3.1)."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from ...errors import InputError
from .genes import M_VALUES, variance_amplitude
from .result import SequencingResult


@dataclass(frozen=True)
class ZdRidgeFit:
    """Eq. (3.15) solved for each M: cost f_m and the probability P_m = f_m / sum f_m.

    Attributes: M (ridges tried), cost (f_m, the mean squared misfit of Z_d normalised by
    its peak-valley dZ), P (P_m), alpha (fitted A / A0 per M), A0 (Eq. 3.13 estimate),
    chromosomes (indices in Z_d with their sign +1 / -1), nit (Jacobian evaluations).
    """

    M: np.ndarray
    cost: np.ndarray
    P: np.ndarray
    alpha: np.ndarray
    A0: float
    chromosomes: tuple
    nit: int


def thesis_zd_fit(result: SequencingResult, M_values=M_VALUES, *, seed=0,
                  n_starts=3) -> ZdRidgeFit:
    """Fit Z_d = Z_1 - Z_2 with the ridge model of Eq. (3.12)-(3.15) for each M (angles directly).

    Z_r(x) = alpha A0 sum_{n in U} s_n sum_m G_n(M) gamma^((1-n)H) [cos phi_mn - cos(q_n x + phi_mn)]
    with U the chromosomes of the coarsest acquisition missing from the second (s_n = +1)
    and those of the second missing from the first (s_n = -1), gamma, lambda1, H from the
    sequencing and A0 from Eq. (3.13). The unknowns alpha and phi_mn are fitted by scipy
    ``least_squares`` with the analytic Jacobian (angles directly: the constraint
    eta^2 + xi^2 = 1 of Eq. 3.12 disappears), from ``n_starts`` seeded random starts. The
    cost f_m is the same for every M >= 2 up to the optimiser (any resultant of modulus
    <= M is reachable and alpha absorbs the scale): P_m does not identify M.
    """
    if result.zd.size < 4:
        raise InputError("Z_d needs at least 4 shared nodes of the two coarsest acquisitions")
    g = result.genome
    (s1, f1), (s2, f2) = result.ranges[0], result.ranges[1]
    only1 = [n for n in range(s1, f1 + 1) if not s2 <= n <= f2]
    only2 = [n for n in range(s2, f2 + 1) if not s1 <= n <= f1]
    idx = np.array(only1 + only2, dtype=int)
    sign = np.array([1.0] * len(only1) + [-1.0] * len(only2))
    if idx.size == 0:
        raise InputError("the two coarsest acquisitions have the same chromosomes: Z_d = 0")
    x, zd = result.zd_x, result.zd
    dz = float(np.ptp(zd)) or 1.0
    A0 = variance_amplitude(result.heights[0], np.arange(s1, f1 + 1), g.gamma, g.lambda1, g.H)
    q = g.wavenumber(idx)
    qx = np.multiply.outer(x, q)                                     # (P, k)
    rng = np.random.default_rng(seed)
    costs, alphas, nit = [], [], 0
    for M in M_values:
        base = sign * A0 * math.sqrt(math.log(g.gamma) / M) * (2 * math.pi / g.lambda1) ** (-g.H) \
            * g.gamma ** ((1.0 - idx) * g.H)                         # (k,)

        def resid(p):
            phi = p[1:].reshape(M, idx.size)
            wave = (np.cos(phi)[None] - np.cos(qx[:, None, :] + phi[None])).sum(1)  # (P, k)
            return (p[0] * wave @ base - zd) / dz

        def jac(p):
            phi = p[1:].reshape(M, idx.size)
            wave = (np.cos(phi)[None] - np.cos(qx[:, None, :] + phi[None]))          # (P, M, k)
            dphi = p[0] * base[None, None, :] * (-np.sin(phi)[None] + np.sin(qx[:, None, :] + phi[None]))
            return np.column_stack([wave.sum(1) @ base, dphi.reshape(x.size, -1)]) / dz

        best = math.inf
        best_alpha = float("nan")
        for _ in range(int(n_starts)):
            p0 = np.concatenate([[1.0], rng.uniform(0, 2 * np.pi, M * idx.size)])
            r = least_squares(resid, p0, jac=jac, method="lm", max_nfev=200 * (1 + M * idx.size))
            nit += int(r.njev or 0)
            c = float(np.mean(r.fun ** 2))
            if c < best:
                best, best_alpha = c, float(r.x[0])
        costs.append(best)
        alphas.append(best_alpha)
    costs = np.array(costs)
    total = costs.sum()
    return ZdRidgeFit(np.array(M_values), costs, costs / total if total > 0 else np.full(costs.size, np.nan),
                      np.array(alphas), A0, tuple(zip(idx.tolist(), sign.tolist())), nit)
