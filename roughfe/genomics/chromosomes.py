"""Chromosomes: the reduced single-cosine form (Eq. 3.7-3.10) and TD/BU reconstructions (Sec. 3.2.2).

Reduced form (Eq. 3.7-3.9), and why Eq. 3.10 always holds
---------------------------------------------------------
For a profile, the M elementary waves of chromosome n share the wavenumber q_n, so by
cos(a + b) = cos a cos b - sin a sin b

    sum_m [cos(phi_m) - cos(q x + phi_m)] = g1 (1 - cos q x) + g2 sin q x
                                          = R [cos(theta) - cos(q x + theta)],

with g1 = sum_m cos(phi_m), g2 = sum_m sin(phi_m) and R e^{i theta} = g1 + i g2. Since
R^2 = g1^2 + g2^2 = M + 2 g3 (g3 = sum_{i<j} cos(phi_j - phi_i), Eq. 3.9), the chromosome
is *exactly* one cosine of amplitude K_n gamma^((1-n)H) with K_n = G sqrt(M + 2 g3)
(Eq. 3.8) and theta_{n,1} = theta_{n,2} = theta_n. The validity condition of Eq. (3.10),
|g1| <= sqrt(M + 2 g3), is |g1| <= sqrt(g1^2 + g2^2): it holds for *every* phase set. The
Monte Carlo of Fig. 29 therefore gives 100 % (up to round-off), not the 88.5-98 % the
thesis reports. What is loose in Eq. (3.8) is the phase: arccos returns theta in [0, pi],
which is right only when g2 >= 0 (about half of the random draws); the correct phase is
theta_n = atan2(g2, g1), used here. :func:`validity_monte_carlo` measures both.

With ridge amplitude factors alpha_m (a genome with ``anisotropy``, Eq. 3.17-3.18) the
waves are weighted and so are the phasors: g1 = sum_m alpha_m cos(phi_m),
g2 = sum_m alpha_m sin(phi_m), K_n e^{i theta_n} = G sum_m alpha_m e^{i phi_m}; the
chromosome is still exactly one cosine.

Consequence for sequencing: a profile determines only K_n and theta_n per chromosome,
never the individual phi_{m,n} nor M (see ``roughfe.genomics.sequencing``).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError, check_memory
from .genome import DEFAULT_NODES, Genome, chromosome_heights, node_coordinates


def reduced_chromosome(genome: Genome, n):
    """K_n (m) and theta_n (rad) of the single-cosine form of chromosome(s) n, Eq. (3.8).

    ``K_n e^{i theta_n} = G sum_m alpha_m e^{i phi_mn}``, i.e. ``K_n = G |g1 + i g2|``
    and ``theta_n = atan2(g2, g1)`` with ``g1 = sum_m alpha_m cos(phi_mn)``,
    ``g2 = sum_m alpha_m sin(phi_mn)``: the ridge amplitude factors alpha_m of the genome
    (``Genome.anisotropy``, Eq. 3.17-3.18; 1 when absent) weight the phasors as they
    weight the waves of :func:`~roughfe.genomics.genome.chromosome_heights`. For alpha = 1
    this is the thesis's ``K_n = G sqrt(M + 2 g3)`` with the sign-correct phase (the thesis
    has ``arccos(g1 / sqrt(M + 2 g3))``). Returns two arrays of len(n).
    """
    phi = genome.phase_columns(np.atleast_1d(n))
    alpha = np.ones(phi.shape[0]) if genome.anisotropy is None else genome.anisotropy
    g1 = alpha @ np.cos(phi)
    g2 = alpha @ np.sin(phi)
    return genome.prefactor * np.hypot(g1, g2), np.arctan2(g2, g1)


def reduced_chromosome_heights(genome: Genome, x, n):
    """C_n(x) from the reduced form Eq. (3.7) with theta_{n,1} = theta_{n,2} (m), shape
    (len(n), P); the ridge factors alpha_m are included (:func:`reduced_chromosome`)."""
    n = np.atleast_1d(np.asarray(n, dtype=int))
    k, theta = reduced_chromosome(genome, n)
    amp = k * genome.gamma ** ((1.0 - n) * genome.H)
    q = genome.wavenumber(n)
    x = np.asarray(x, dtype=float)
    return amp[:, None] * (np.cos(theta)[:, None] - np.cos(np.multiply.outer(q, x) + theta[:, None]))


@dataclass(frozen=True)
class ValidityResult:
    """Monte Carlo of the validity of Eq. (3.10) (Fig. 29).

    Attributes
    ----------
    M : ndarray of int
        Numbers of ridges tested.
    valid_fraction : ndarray
        Fraction of draws with |g1| <= sqrt(M + 2 g3) (Eq. 3.10); 1 up to round-off.
    arccos_fraction : ndarray
        Fraction of draws for which the thesis's theta = arccos(...) reproduces the
        chromosome (i.e. g2 >= 0); about 0.5.
    max_identity_error : float
        max |(M + 2 g3) - (g1^2 + g2^2)| / M over all draws (round-off only).
    n_trials : int
    seed : int or None
    """

    M: np.ndarray
    valid_fraction: np.ndarray
    arccos_fraction: np.ndarray
    max_identity_error: float
    n_trials: int
    seed: object = None
    references: tuple = field(default=("thesis Eq. 3.8-3.10, Fig. 29",))


def _check_validity_memory(m_max: int, n_trials) -> None:
    """The phases and the three pair arrays of the largest M (8 bytes each) fit in memory
    (a million ridges ran for days)."""
    check_memory(f"M = {m_max} ridges x {int(n_trials)} trials",
                 8.0 * int(n_trials) * (m_max + 1.5 * m_max * (m_max - 1)))


def validity_monte_carlo(M_values=tuple(range(2, 21)), n_trials=1000, *, rng) -> ValidityResult:
    """Fraction of random phase sets satisfying Eq. (3.10), per number of ridges M (Fig. 29).

    Phases are drawn uniformly in [0, 2 pi) from ``rng`` (Generator or int seed). g3 is
    computed from its definition (Eq. 3.9, double sum over pairs), independently of g1, g2.
    """
    seed = int(rng) if isinstance(rng, (int, np.integer)) else None
    gen = np.random.default_rng(rng)
    if int(n_trials) < 1:
        raise InputError(f"n_trials must be >= 1, got {n_trials!r}")
    if isinstance(M_values, range) and len(M_values):   # sized before it is listed (a
        _check_validity_memory(max(M_values[0], M_values[-1]), n_trials)  # range to 10^11)
    ms = np.asarray(list(M_values), dtype=int)
    if ms.size == 0 or ms.min() < 1:
        raise InputError(f"M_values must be integers >= 1, got {list(M_values)!r}")
    _check_validity_memory(int(ms.max()), n_trials)
    valid, arccos_ok, worst = [], [], 0.0
    for m in ms:
        phi = gen.uniform(0, 2 * np.pi, size=(int(n_trials), int(m)))
        g1, g2 = np.cos(phi).sum(1), np.sin(phi).sum(1)
        iu, ju = np.triu_indices(int(m), k=1)
        g3 = np.cos(phi[:, ju] - phi[:, iu]).sum(1)
        r2 = m + 2 * g3
        worst = max(worst, float(np.max(np.abs(r2 - (g1 ** 2 + g2 ** 2))) / m))
        root = np.sqrt(np.maximum(r2, 0.0))
        valid.append(np.mean(np.abs(g1) <= root * (1 + 1e-12) + 1e-12))
        theta = np.arccos(np.clip(g1 / np.where(root > 0, root, 1.0), -1, 1))
        arccos_ok.append(np.mean(np.abs(root * np.sin(theta) - g2) <= 1e-9 * m))
    return ValidityResult(ms, np.array(valid), np.array(arccos_ok), worst, int(n_trials), seed)


@dataclass(frozen=True, eq=False)
class Reconstruction:
    """Top-down or bottom-up reconstruction of a realisation (Sec. 3.2.2, Fig. 30-31).

    Attributes
    ----------
    order : {"td", "bu"}
        "td": C_{n_s}, C_{n_s}+C_{n_s+1}, ...; "bu": C_{n_f}, C_{n_f}+C_{n_f-1}, ...
    x : ndarray, shape (P,)
        Node abscissae (m).
    indices : ndarray of int, shape (k,)
        Chromosome added at each step.
    chromosomes : ndarray, shape (k, P)
        C_n(x) of each added chromosome (m), Eq. (3.2).
    partial_sums : ndarray, shape (k, P)
        Profile after each step (m); the last row is the complete profile.
    """

    order: str
    x: np.ndarray
    indices: np.ndarray
    chromosomes: np.ndarray
    partial_sums: np.ndarray

    @property
    def complete(self):
        return self.partial_sums[-1]


def reconstruction(genome: Genome, length, n_nodes=DEFAULT_NODES, order="td") -> Reconstruction:
    """Top-down (``"td"``) or bottom-up (``"bu"``) partial sums of the chromosomes (Eq. 3.3).

    The chromosomes n_s..n_f of Eq. (3.5) at observation length ``length`` (m) that the
    genome holds (:meth:`Genome.held_range`, as :func:`~roughfe.genomics.genome.realize`:
    the complete sum is the realised profile).
    """
    if order not in ("td", "bu"):
        raise InputError(f"order must be 'td' (top-down) or 'bu' (bottom-up), got {order!r}")
    n_s, n_f = genome.held_range(length, n_nodes)
    idx = np.arange(n_s, n_f + 1) if order == "td" else np.arange(n_f, n_s - 1, -1)
    x = node_coordinates(length, n_nodes)
    chrom = chromosome_heights(genome, x, idx)
    return Reconstruction(order, x, idx, chrom, np.cumsum(chrom, axis=0))
