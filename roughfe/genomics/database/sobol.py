"""The Sobol design of the thesis database (Sec. 4.1.2, Fig. 53) and its task list."""
from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ...errors import InputError, check_in_interval, check_int

_SOBOL_MAX = 2 ** 30    # scipy.stats.qmc.Sobol: at most 2**30 distinct points


@dataclass(frozen=True)
class SobolDesign:
    """The Sobol design of the thesis database (Sec. 4.1.2, Fig. 53).

    ``n_pairs`` (gamma, H) pairs from a 2-D Sobol sequence scaled to ``gamma_range`` x
    ``hurst_range``; ``n_vectors`` phase vectors of ``n_phases`` values in [0, 2 pi),
    taken *sequentially* from a 1-D Sobol sequence (vector k = values k*n_phases ..
    (k+1)*n_phases - 1). Genomes with more chromosomes than ``n_phases`` (small gamma)
    take their extra phases sequentially from the same sequence after the first
    ``n_vectors * n_phases`` values (``n_extra`` per vector), as the thesis adds "a
    larger number of phases for smaller gamma". Both sequences use
    ``scipy.stats.qmc.Sobol(scramble=scramble, seed=seed)`` (pairs: ``seed``, phases:
    ``seed + 1``); the design is stored in the database.

    Surface databases (``dim = 2``, issue 15 Sec. 3): each genome has ``n_ridges`` ridges;
    the genes come from one Sobol point of dimension 2 + 2M (same ``seed``): gamma, H,
    the M ridge angles theta_m in [0, pi) (a ridge at theta + pi is the same wave with
    another phase) and the M anisotropy factors alpha_m, log-uniform in
    ``anisotropy_range``; so each of the ``n_pairs`` points carries its own angles and
    anisotropy. A phase "vector" is then an (M, n_phases + n_extra) matrix taken
    sequentially from the 1-D phase sequence (row by row). ``dim = 1`` is the thesis
    design above, unchanged.

    Integers (:func:`roughfe.errors.check_int`; a bool, text or a float is refused):
    ``n_pairs``, ``n_vectors``, ``n_phases`` >= 1, ``n_extra`` >= 0, ``seed`` >= 0
    (``seed + 1`` seeds the phases), ``n_ridges`` 1..100; the Sobol sequences hold at most
    2**30 points, so ``n_pairs`` and the phase count (``n_vectors`` times
    ``n_phases + n_extra`` times the ridges) are at most 2**30.
    """

    n_pairs: int = 20
    n_vectors: int = 3
    n_phases: int = 30
    n_extra: int = 34
    gamma_range: tuple = (1.2, 2.0)
    hurst_range: tuple = (0.5, 1.5)
    seed: int = 20240
    scramble: bool = True
    dim: int = 1
    n_ridges: int = 3
    anisotropy_range: tuple = (0.5, 2.0)

    def __post_init__(self):
        try:                    # an integer: True and 1.0 passed "in (1, 2)" as 1
            dim = check_int("dim", self.dim, 1)
        except InputError:
            dim = None
        if dim not in (1, 2):
            raise InputError(f"dim must be 1 (profiles) or 2 (surfaces), got {self.dim!r}")
        object.__setattr__(self, "dim", dim)
        # integers (n_ridges: text "3" ran as 3, 2.5 as 2 ridges; the others: a float or
        # text failed later with a bare TypeError, a negative seed with numpy's
        # ValueError, no phases at all with an OverflowError): check_int, upper ends
        for name, what, minimum in (("n_pairs", "(gamma, H) points", 1),
                                    ("n_vectors", "phase vectors", 1),
                                    ("n_phases", "phases per vector", 1),
                                    ("n_extra", "extra phases per vector", 0),
                                    ("seed", "Sobol scrambling seed", 0),
                                    ("n_ridges", "ridges per genome, 1..100", 1)):
            object.__setattr__(self, name, check_int(f"{name} ({what})",
                                                     getattr(self, name), minimum))
        if self.n_ridges > 100:
            raise InputError(f"n_ridges must lie in 1..100, got {self.n_ridges!r}")
        n_phase_values = self.n_vectors * (self.n_phases + self.n_extra) * self.rows
        for name, count in (("n_pairs", self.n_pairs),
                            ("n_vectors * (n_phases + n_extra) * ridges", n_phase_values)):
            if count > _SOBOL_MAX:
                raise InputError(f"{name} must be at most 2**30 = {_SOBOL_MAX} (the points "
                                 f"of a Sobol sequence), got {count}")
        # each end within the Genome's own interval (a gamma or H outside it failed its
        # tasks, and the task's text filled the error line); low == high is one value
        for name, what, low, high, closed in (
                ("gamma_range", "the genome's gamma", 1, 10, "right"),
                ("hurst_range", "the genome's H", 0, 3, "right"),
                ("anisotropy_range", "ridge amplitude factors", 0, float("inf"), "neither")):
            object.__setattr__(self, name, _check_range(name, what, getattr(self, name), low,
                                                        high, closed))

    @property
    def rows(self) -> int:
        """Ridges per genome: 1 for profiles, ``n_ridges`` for surfaces."""
        return 1 if self.dim == 1 else int(self.n_ridges)

    def genes(self) -> np.ndarray:
        """Surfaces: (gamma, H, theta_1..theta_M, alpha_1..alpha_M) per point, shape
        (n_pairs, 2 + 2M)."""
        from scipy.stats import qmc
        m = self.rows
        e = int(np.ceil(np.log2(max(self.n_pairs, 2))))
        u = qmc.Sobol(d=2 + 2 * m, scramble=self.scramble, seed=self.seed).random_base2(e)
        u = u[: self.n_pairs]
        out = np.empty_like(u)
        out[:, 0] = self.gamma_range[0] + u[:, 0] * (self.gamma_range[1] - self.gamma_range[0])
        out[:, 1] = self.hurst_range[0] + u[:, 1] * (self.hurst_range[1] - self.hurst_range[0])
        out[:, 2:2 + m] = np.pi * u[:, 2:2 + m]
        lo, hi = np.log(self.anisotropy_range[0]), np.log(self.anisotropy_range[1])
        out[:, 2 + m:] = np.exp(lo + u[:, 2 + m:] * (hi - lo))
        return out

    def pairs(self) -> np.ndarray:
        """The (gamma, H) pairs, shape (n_pairs, 2)."""
        from scipy.stats import qmc
        m = int(np.ceil(np.log2(max(self.n_pairs, 2))))
        u = qmc.Sobol(d=2, scramble=self.scramble, seed=self.seed).random_base2(m)[: self.n_pairs]
        lo = np.array([self.gamma_range[0], self.hurst_range[0]])
        hi = np.array([self.gamma_range[1], self.hurst_range[1]])
        return u * (hi - lo) + lo     # qmc.scale's formula; it refused low == high (one H)

    def phase_vectors(self) -> np.ndarray:
        """Phase vectors (rad), shape (n_vectors, n_phases + n_extra); for surfaces
        (n_vectors, M, n_phases + n_extra), the M rows of vector k taken one after the
        other (each row as a profile vector is)."""
        from scipy.stats import qmc
        per, extra = self.n_phases * self.rows, self.n_extra * self.rows
        base = self.n_vectors * per
        total = base + self.n_vectors * extra
        m = int(np.ceil(np.log2(total)))
        seq = 2 * np.pi * qmc.Sobol(d=1, scramble=self.scramble,
                                    seed=self.seed + 1).random_base2(m)[:total, 0]
        out = np.empty((self.n_vectors, self.rows, self.n_phases + self.n_extra))
        for k in range(self.n_vectors):
            out[k, :, : self.n_phases] = seq[k * per:(k + 1) * per].reshape(self.rows, -1)
            out[k, :, self.n_phases:] = seq[base + k * extra:
                                            base + (k + 1) * extra].reshape(self.rows, -1)
        return out[:, 0, :] if self.dim == 1 else out

    def check_phases(self, settings) -> None:
        """InputError unless each genome of the design has the phases it realises at
        ``settings`` (a :class:`DatabaseSettings`): a genome of gamma realises
        ``n_f - n_s + 1`` chromosomes (:func:`~roughfe.genomics.database.task.realised_range`,
        more for a smaller gamma), one phase each per ridge, and the design gives
        ``n_phases + n_extra``. Until round 2, session 35 such a genome failed at build
        time, in its task; :func:`roughfe.study.build_genome_db` checks before any runs."""
        from .task import realised_range
        gammas = (self.pairs() if self.dim == 1 else self.genes())[:, 0]
        counts = [n_f - n_s + 1 for n_s, n_f in (realised_range(g, settings) for g in gammas)]
        k = max(range(len(counts)), key=lambda i: (counts[i], -gammas[i]))
        given = self.n_phases + self.n_extra
        if counts[k] > given:
            raise InputError(
                f"gamma = {gammas[k]:.6g} (the design's smallest; gamma_range "
                f"{self.gamma_range[0]:g} .. {self.gamma_range[1]:g}) realises {counts[k]} "
                f"chromosomes at N = {settings.n_nodes}, L = {settings.length:g} m and needs "
                f"{counts[k]} phases per ridge; the design gives n_phases + n_extra = "
                f"{self.n_phases} + {self.n_extra} = {given}: raise n_extra to at least "
                f"{counts[k] - self.n_phases}, or the low end of gamma_range")

    def tasks(self):
        """``(label, gamma, H, phases)`` for every genome (surfaces: ``(label, gamma, H,
        phases, angles, anisotropy)``), labels ``"i-k"`` (1-based)."""
        phases = self.phase_vectors()
        if self.dim == 1:
            return [(f"{i + 1}-{k + 1}", float(g), float(h), phases[k])
                    for i, (g, h) in enumerate(self.pairs()) for k in range(self.n_vectors)]
        m = self.rows
        return [(f"{i + 1}-{k + 1}", float(r[0]), float(r[1]), phases[k], r[2:2 + m], r[2 + m:])
                for i, r in enumerate(self.genes()) for k in range(self.n_vectors)]

    def to_dict(self) -> dict:
        d = asdict(self)
        for key in ("gamma_range", "hurst_range", "anisotropy_range"):
            d[key] = list(getattr(self, key))
        if self.dim == 1:       # the thesis design: stored as before the surface fields
            for key in ("dim", "n_ridges", "anisotropy_range"):
                d.pop(key)
        return d

    @classmethod
    def from_dict(cls, d) -> "SobolDesign":
        d = dict(d)
        for key in ("gamma_range", "hurst_range", "anisotropy_range"):
            if key in d:
                d[key] = tuple(d[key])
        return cls(**d)


def _check_range(name, what, pair, low, high, closed) -> tuple:
    """``(lo, hi)`` as floats, or :class:`~roughfe.errors.InputError`: two numbers, each in
    the interval of ``low`` and ``high`` that ``closed`` names
    (:func:`roughfe.errors.check_in_interval`), ``lo <= hi``."""
    try:
        lo, hi = pair
    except (TypeError, ValueError):
        raise InputError(f"{name} must be two numbers (low, high), got {pair!r}") from None
    lo, hi = (check_in_interval(f"{name} {end} ({what})", v, low, high, closed)
              for end, v in (("low", lo), ("high", hi)))
    if lo > hi:
        raise InputError(f"{name} must have low <= high, got {pair!r}")
    return lo, hi


def sobol_tasks(design: SobolDesign, limit=None) -> list:
    """:func:`genome_entry_task` arguments (label, source, gamma, hurst, phases) per genome.

    ``limit`` keeps the first genomes of the design (a reduced database); an integer >= 1
    (:func:`roughfe.errors.check_int`; 2.5 and "3" are refused).
    """
    if limit is not None:       # int(limit) ran 2.5 as 2 genomes and "3" as 3
        limit = check_int("limit (genomes to build)", limit, 1)
    tasks = []
    for row in design.tasks():
        lab, g, h, phi = row[:4]
        task = {"label": lab, "source": "sobol", "gamma": g, "hurst": h,
                "phases": np.asarray(phi, dtype=float).tolist()}
        if design.dim == 2:
            task["angles"] = [float(v) for v in row[4]]
            task["anisotropy"] = [float(v) for v in row[5]]
        tasks.append(task)
    if limit is not None:
        tasks = tasks[:limit]
    return tasks
