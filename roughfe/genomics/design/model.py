"""Designed profiles and surfaces and their JSON (thesis Sec. 4.2; surfaces: issue 15).

A designed profile is a :class:`Design`: a sum of *parts*, each a set of chromosomes
(Eq. 3.2) of one genome, realised at the database length L with N nodes, multiplied by
the part's Eq. (4.2) factor (the amplitude that put its genome on the target pressure
range in Alg. 3) and by one overall factor ``scale`` (Eq. 4.2 applied to the sum).
A single-part design is an ordinary genome with amplitude gene ``scale*weight*A``
(:meth:`Design.as_genome`); cross-overs of genomes with different (gamma, H) are not one
MWM genome, so the design JSON stores every part's versioned genome JSON.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Optional

import numpy as np

from ...errors import InputError
from ...surfaces.surface import Surface
from ..database import THESIS_SETTINGS, DatabaseEntry, DatabaseSettings
from ..genome import Genome, node_coordinates
from ..periodic import check_dim, periodic_heights, realization
from .modulation import modulated_heights

#: genes other than the phases that CCO optimises ("all genes", Sec. 4.2.4)
GENE_VARIABLES = ("H", "gamma", "lambda1", "weight")
DESIGN_FORMAT = "roughfe-design"
#: version 2: a surface design may carry ``modulation`` (written only when it is not 0, so
#: a design without it is still written as version 1, byte for byte as before)
DESIGN_VERSION = 2


def is_amplitude_key(key) -> bool:
    """True for a design variable that is a (positive) amplitude factor: a part weight
    ``(part, "weight")`` or a ridge factor ``(part, "alpha", m)``; False for a phase
    ``(part, m, n)`` or another gene."""
    return isinstance(key[1], str) and key[1] in ("weight", "alpha")


@dataclass(frozen=True, eq=False)
class DesignPart:
    """Chromosomes ``chromosomes`` (indices n) of ``genome`` times ``weight`` (-)."""

    genome: Genome
    chromosomes: tuple
    weight: float = 1.0
    label: str = ""

    def __post_init__(self):
        ch = tuple(sorted({int(n) for n in self.chromosomes}))
        if not ch:
            raise InputError(f"design part {self.label!r} has no chromosomes")
        object.__setattr__(self, "chromosomes", ch)
        if not (np.isfinite(self.weight) and self.weight > 0):
            raise InputError(f"part weight must be finite and > 0, got {self.weight!r}")


@dataclass(frozen=True, eq=False)
class Design:
    """A designed rough profile: ``scale * sum_parts weight * sum_{n in part} C_n(x)``.

    Parameters
    ----------
    parts : tuple of DesignPart
    scale : float
        Overall Eq. (4.2) factor (-).
    length : float
        Observation length L (m).
    n_nodes : int
        Nodes N (spacing L/(N-1), the genome node convention; dim 2: N x N nodes of
        spacing L/N on the torus of period L).
    name : str
        Provenance, e.g. ``"5-1+2-2"``.
    dim : {1, 2}
        1: a profile (thesis); 2: a periodic surface, every part realised by
        :func:`roughfe.genomics.periodic.realize_periodic_surface` (surface database).
    modulation : float
        Surfaces, beyond the thesis and the MWM model: the depth epsilon (-) by which the
        short-wave part of the summed heights is modulated by the long-wave height
        (:func:`~.modulation.modulated_heights`; 0: off, the plain sum of the parts).
        Set by the global stage (``GlobalSearchOptions.modulation``); the exact phase
        sensitivities of the GCMMA stages assume 0.
    """

    parts: tuple
    scale: float = 1.0
    length: float = THESIS_SETTINGS.length
    n_nodes: int = THESIS_SETTINGS.n_nodes
    name: str = ""
    dim: int = 1
    modulation: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "parts", tuple(self.parts))
        if not self.parts:
            raise InputError("a design needs at least one part")
        if not (np.isfinite(self.scale) and self.scale > 0):
            raise InputError(f"design scale must be finite and > 0, got {self.scale!r}")
        object.__setattr__(self, "dim", check_dim(self.dim))
        if not np.isfinite(self.modulation) or (self.modulation and self.dim != 2):
            raise InputError(f"modulation must be finite and needs a surface design (dim 2), "
                             f"got {self.modulation!r} with dim {self.dim}")

    # -- geometry ----------------------------------------------------------------------
    def keys(self, which="all") -> list:
        """Phase variables ``(part, row m, chromosome n)``; ``which`` = "all" or a per-part
        list of chromosome sets."""
        out = []
        for k, part in enumerate(self.parts):
            chosen = part.chromosomes if which == "all" else tuple(which[k])
            for n in chosen:
                if n in part.chromosomes:
                    out.extend((k, m, int(n)) for m in range(part.genome.M))
        return out

    def gene_keys(self) -> list:
        """Gene variables ``(part, name)`` for name in H, gamma, lambda1 and the part weight
        (its amplitude gene relative to the other parts)."""
        return [(k, g) for k in range(len(self.parts)) for g in GENE_VARIABLES]

    def ridge_keys(self) -> list:
        """Per-ridge amplitude variables ``(part, "alpha", m)``: the factor alpha_m of
        ridge m of each part's genome (Eq. 3.17's anisotropy; 1 where the genome has none).
        After :meth:`split_chromosomes` each part is one chromosome, so these are the
        amplitudes of every wave (ridge m, chromosome n) on its own."""
        return [(k, "alpha", m) for k, p in enumerate(self.parts) for m in range(p.genome.M)]

    def phase_values(self, keys) -> np.ndarray:
        """Current values of the variables ``keys``: phases (rad) ``(part, m, n)``, genes
        ``(part, name)`` and ridge factors ``(part, "alpha", m)`` (:meth:`ridge_keys`)."""
        out = []
        for key in keys:
            part = self.parts[key[0]]
            if key[1] == "alpha":
                a = part.genome.anisotropy
                out.append(1.0 if a is None else a[key[2]])
            elif len(key) == 2:
                out.append(part.weight if key[1] == "weight" else getattr(part.genome, key[1]))
            else:
                _, m, n = key
                out.append(part.genome.phases[m, n - part.genome.n_first])
        return np.array(out, dtype=float)

    def with_phases(self, keys, values) -> "Design":
        """A new design with the variables ``keys`` (phases, genes and ridge factors) set
        to ``values``."""
        phases = [np.array(p.genome.phases) for p in self.parts]
        alphas = [None if p.genome.anisotropy is None else np.array(p.genome.anisotropy, float)
                  for p in self.parts]
        genes = [{} for _ in self.parts]
        for key, v in zip(keys, np.asarray(values, dtype=float)):
            if key[1] == "alpha":
                k, _, m = key
                if alphas[k] is None:
                    alphas[k] = np.ones(self.parts[k].genome.M)
                alphas[k][m] = v
            elif len(key) == 2:
                genes[key[0]][key[1]] = float(v)
            else:
                k, m, n = key
                phases[k][m, n - self.parts[k].genome.n_first] = v
        parts = []
        for p, ph, al, g in zip(self.parts, phases, alphas, genes):
            w = g.pop("weight", p.weight)
            if al is not None:
                g["anisotropy"] = al
            parts.append(replace(p, genome=replace(p.genome, phases=ph, **g), weight=w))
        return replace(self, parts=tuple(parts))

    def split_chromosomes(self) -> "Design":
        """The same design with one part per chromosome (weights and the overall scale
        folded into each part's weight), so each chromosome's amplitude is a variable
        ``(part, "weight")`` of its own; the realised heights are unchanged."""
        parts = tuple(replace(p, chromosomes=(n,), weight=p.weight * self.scale)
                      for p in self.parts for n in p.chromosomes)
        return replace(self, parts=parts, scale=1.0)

    def rescaled(self, factor) -> "Design":
        return replace(self, scale=self.scale * float(factor))

    def part_surface(self, k) -> Surface:
        """Part ``k`` alone (with its weight and the overall scale)."""
        part = self.parts[k]
        s = realization(part.genome, self.length, self.n_nodes, self.dim, part.chromosomes)
        return s.scaled(self.scale * part.weight)

    def chromosome_surface(self, k, n) -> Surface:
        part = self.parts[k]
        s = realization(part.genome, self.length, self.n_nodes, self.dim, [n])
        return s.scaled(self.scale * part.weight)

    def phase_derivative(self, k, m, n) -> np.ndarray:
        """d heights / d phi_{m,n} of part ``k`` (m/rad): the wave (m, n) with its phase
        shifted by pi/2, times scale and weight (a[-sin phi + sin(q.x + phi)], Eq. 3.2)."""
        part = self.parts[k]
        g = part.genome
        factor = self.scale * part.weight
        if self.dim == 2:
            return factor * periodic_heights(g, self.length, self.n_nodes, [n], rows=[m],
                                             phase_shift=np.pi / 2)
        x = node_coordinates(self.length, self.n_nodes)
        a = float(g.wave_amplitude(n)) * (1.0 if g.anisotropy is None else g.anisotropy[m])
        phi = g.phases[m, n - g.n_first]
        return factor * a * (np.sin(g.wavenumber(n) * x + phi) - np.sin(phi))

    def surface(self) -> Surface:
        """The designed profile or periodic surface (heights in m) on the nodes: the sum of
        the parts, its short waves modulated by ``modulation`` where that is not 0."""
        surfs = [self.part_surface(k) for k in range(len(self.parts))]
        h = np.sum([s.heights for s in surfs], axis=0)
        if self.modulation:
            h = modulated_heights(h, self.modulation)
        meta = {"generator": "roughfe.design", "name": self.name, "length": self.length,
                "n_nodes": self.n_nodes, "x0": surfs[0].metadata["x0"],
                "parts": [{"label": p.label, "chromosomes": list(p.chromosomes)}
                          for p in self.parts]}
        return Surface(h, surfs[0].size, periodic=self.dim == 2, metadata=meta)

    def spectrum_lines(self) -> list:
        """Discrete spectrum ``(q_n (rad/m), a_n (m))`` of every chromosome of every part:
        a_n = scale * weight * G gamma^((1-n)H) * sqrt(sum_m alpha_m^2) (the rms-equivalent
        amplitude of the M ridges' waves, each scaled by its anisotropy factor alpha_m as
        realised; sqrt(M) without factors). (Until session 25 the factors were left out:
        the markers of a 2D database design with alpha = 0.72, 0.53, 0.59 stood 2.6x
        above the power its waves carry.)"""
        out = []
        for p in self.parts:
            g = p.genome
            ridges = math.sqrt(g.M if g.anisotropy is None else float(np.sum(g.anisotropy ** 2)))
            for n in p.chromosomes:
                a = self.scale * p.weight * float(g.wave_amplitude(n)) * ridges
                out.append((float(g.wavenumber(n)), a))
        return sorted(out)

    def part_genome(self, k) -> Genome:
        """Part ``k`` as a genome: its weight and the overall scale folded into the
        amplitude gene A; the part's chromosomes (realise only those) in metadata."""
        p = self.parts[k]
        g = p.genome
        return replace(g, A=g.A * p.weight * self.scale,
                       metadata={**g.metadata, "design": self.name, "part": k + 1,
                                 "chromosomes": list(p.chromosomes), "dim": self.dim,
                                 "length": self.length, "n_nodes": self.n_nodes})

    def as_genome(self) -> Optional[Genome]:
        """The single genome equal to this design when it has one part (and no
        ``modulation``), else None."""
        return self.part_genome(0) if len(self.parts) == 1 and not self.modulation else None

    # -- JSON --------------------------------------------------------------------------
    def to_dict(self) -> dict:
        return {"format": DESIGN_FORMAT, "version": DESIGN_VERSION if self.modulation else 1,
                "name": self.name, "scale": self.scale, "length": self.length,
                "n_nodes": self.n_nodes, "dim": self.dim,
                **({"modulation": self.modulation} if self.modulation else {}),
                "parts": [{"label": p.label, "weight": p.weight,
                           "chromosomes": list(p.chromosomes), "genome": p.genome.to_dict()}
                          for p in self.parts]}

    @classmethod
    def from_dict(cls, d) -> "Design":
        if d.get("format") != DESIGN_FORMAT or int(d.get("version", 0)) > DESIGN_VERSION:
            raise InputError(f"not a readable {DESIGN_FORMAT} object (format={d.get('format')!r}, "
                             f"version={d.get('version')!r})")
        parts = tuple(DesignPart(Genome.from_dict(p["genome"]), tuple(p["chromosomes"]),
                                 float(p["weight"]), p.get("label", "")) for p in d["parts"])
        return cls(parts, float(d["scale"]), float(d["length"]), int(d["n_nodes"]),
                   d.get("name", ""), int(d.get("dim", 1)), float(d.get("modulation", 0.0)))


def entry_design(entry: DatabaseEntry, settings: DatabaseSettings, weight=1.0,
                 chromosomes=None) -> Design:
    """A database genome (or some of its chromosomes) as a one-part design."""
    g = Genome.from_dict(entry.genome)
    ch = tuple(chromosomes) if chromosomes is not None else tuple(entry.macro) + tuple(entry.micro)
    return Design((DesignPart(g, ch, float(weight), entry.label),), 1.0, settings.length,
                  settings.n_nodes, entry.label, settings.dim)


def combine(a: Design, b: Design) -> Design:
    """Cross-over: the sum of two designs (Algs. 5-7 Step 6); scales folded into weights."""
    parts = tuple(replace(p, weight=p.weight * d.scale) for d in (a, b) for p in d.parts)
    if a.dim != b.dim:
        raise InputError(f"cannot cross a dim-{a.dim} design with a dim-{b.dim} design")
    return Design(parts, 1.0, a.length, a.n_nodes, f"{a.name}+{b.name}", a.dim)

