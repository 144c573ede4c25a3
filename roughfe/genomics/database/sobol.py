"""The Sobol design of the thesis database (Sec. 4.1.2, Fig. 53) and its task list."""
from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ...errors import InputError


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
    """

    n_pairs: int = 20
    n_vectors: int = 3
    n_phases: int = 30
    n_extra: int = 34
    gamma_range: tuple = (1.2, 2.0)
    hurst_range: tuple = (0.5, 1.5)
    seed: int = 20240
    scramble: bool = True

    def pairs(self) -> np.ndarray:
        """The (gamma, H) pairs, shape (n_pairs, 2)."""
        from scipy.stats import qmc
        m = int(np.ceil(np.log2(max(self.n_pairs, 2))))
        u = qmc.Sobol(d=2, scramble=self.scramble, seed=self.seed).random_base2(m)[: self.n_pairs]
        return qmc.scale(u, [self.gamma_range[0], self.hurst_range[0]],
                         [self.gamma_range[1], self.hurst_range[1]])

    def phase_vectors(self) -> np.ndarray:
        """Phase vectors (rad), shape (n_vectors, n_phases + n_extra)."""
        from scipy.stats import qmc
        base = self.n_vectors * self.n_phases
        total = base + self.n_vectors * self.n_extra
        m = int(np.ceil(np.log2(total)))
        seq = 2 * np.pi * qmc.Sobol(d=1, scramble=self.scramble,
                                    seed=self.seed + 1).random_base2(m)[:total, 0]
        out = np.empty((self.n_vectors, self.n_phases + self.n_extra))
        for k in range(self.n_vectors):
            out[k, : self.n_phases] = seq[k * self.n_phases:(k + 1) * self.n_phases]
            out[k, self.n_phases:] = seq[base + k * self.n_extra: base + (k + 1) * self.n_extra]
        return out

    def tasks(self):
        """``(label, gamma, H, phases)`` for every genome, labels ``"i-k"`` (1-based)."""
        pairs, phases = self.pairs(), self.phase_vectors()
        return [(f"{i + 1}-{k + 1}", float(g), float(h), phases[k])
                for i, (g, h) in enumerate(pairs) for k in range(self.n_vectors)]

    def to_dict(self) -> dict:
        d = asdict(self)
        d["gamma_range"], d["hurst_range"] = list(self.gamma_range), list(self.hurst_range)
        return d

    @classmethod
    def from_dict(cls, d) -> "SobolDesign":
        d = dict(d)
        d["gamma_range"], d["hurst_range"] = tuple(d["gamma_range"]), tuple(d["hurst_range"])
        return cls(**d)


def sobol_tasks(design: SobolDesign, limit=None) -> list:
    """:func:`genome_entry_task` arguments (label, source, gamma, hurst, phases) per genome.

    ``limit`` keeps the first genomes of the design (a reduced database); it must be >= 1.
    """
    tasks = [{"label": lab, "source": "sobol", "gamma": g, "hurst": h,
              "phases": [float(v) for v in phi]} for lab, g, h, phi in design.tasks()]
    if limit is not None:
        if int(limit) < 1:
            raise InputError(f"limit must be >= 1 genome, got {limit!r}")
        tasks = tasks[: int(limit)]
    return tasks
