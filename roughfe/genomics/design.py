"""Roughness design for a target K(p)/A(p) (thesis Sec. 4.2-4.4, Algs. 3-7).

A designed profile is a :class:`Design`: a sum of *parts*, each a set of chromosomes
(Eq. 3.2) of one genome, realised at the database length L with N nodes, multiplied by
the part's Eq. (4.2) factor (the amplitude that put its genome on the target pressure
range in Alg. 3) and by one overall factor ``scale`` (Eq. 4.2 applied to the sum).
A single-part design is an ordinary genome with amplitude gene ``scale*weight*A``
(:meth:`Design.as_genome`); cross-overs of genomes with different (gamma, H) are not one
MWM genome, so the design JSON stores every part's versioned genome JSON.

Algorithms
----------
* :func:`score_database` -- Alg. 3. The database curves are stored at A = 1; Eq. (4.2)
  rescales a curve exactly by stretching its pressure axis (see
  :mod:`roughfe.genomics.similarity`), so scoring needs no new BEM solution.
* :func:`sog` (Alg. 4), :func:`gco` (Alg. 5), :func:`cco` (Alg. 6), :func:`mcco` (Alg. 7),
  each with the stages of Sec. 4.3.1: "GCMMA 0" (selection/cross-over), "GCMMA 1"
  (GCMMA on the macro-scale phases; all phases for CCO) and "GCMMA 2" (GCMMA on the
  micro-scale phases; CCO repeats stage 1).
* Alg. 2 on a cross-over (Alg. 5 Step 13) needs the K_n(p) of every chromosome of the
  new genome: a chromosome of a part is the parent's chromosome times a positive factor,
  whose curve is the parent's stretched in p (Eq. 4.2), and c_n rescales it anyway, so
  the stored chromosome curves of the parents are reused with the new complete curve.

GCMMA (Svanberg 2002) is mmapy's ``gcmmasub`` with the usual outer/inner loop
(:func:`gcmma_maximize`): variables are the phases, bounded to +-10 % of their start
(thesis) or, with ``bound="period"``, to +-10 % of 2 pi (a relative bound on an angle
depends on its arbitrary origin and freezes phases near 0: the thesis choice is kept as
the default because it is what the thesis reports); gradients by forward finite
differences as in the thesis. The objective is written as minimising ``(1 - s)^2``:
for ``s`` in (0, 1] that is maximising ``s^2`` (thesis), and unlike ``-s^2`` it stays
right when a poor start has ``s < 0``. Eq. (4.2) is re-applied at every evaluation.
The best point ever evaluated is returned (GCMMA is not monotone on this non-smooth
infinity-norm objective).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from typing import Callable, Optional, Sequence

import numpy as np

from ..errors import InputError
from ..surfaces.surface import Surface
from .database import DatabaseEntry, DatabaseSettings
from .genome import Genome, realize, save_genome
from .macro_micro import classify, profile_response
from .similarity import ResponseCurve, Target, similarity, split_ranges

#: genes other than the phases that CCO optimises ("all genes", Sec. 4.2.4)
GENE_VARIABLES = ("H", "gamma", "lambda1", "weight")
DESIGN_FORMAT = "roughfe-design"
DESIGN_VERSION = 1
METHODS = ("sog", "gco", "cco", "mcco")
REFERENCES = ("Borri C. (2019) Surface roughness genomics, PhD thesis, IMT Lucca, Ch. 4",
              "Svanberg K. (2002) SIAM J. Optim. 12(2):555-573 (GCMMA)")


# ---------------------------------------------------------------------------------------
# designed genomes
# ---------------------------------------------------------------------------------------
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
        Nodes N (spacing L/(N-1), the genome node convention).
    name : str
        Provenance, e.g. ``"5-1+2-2"``.
    """

    parts: tuple
    scale: float = 1.0
    length: float = 849.42e-6
    n_nodes: int = 512
    name: str = ""

    def __post_init__(self):
        object.__setattr__(self, "parts", tuple(self.parts))
        if not self.parts:
            raise InputError("a design needs at least one part")
        if not (np.isfinite(self.scale) and self.scale > 0):
            raise InputError(f"design scale must be finite and > 0, got {self.scale!r}")

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

    def phase_values(self, keys) -> np.ndarray:
        """Current values of the variables ``keys``: phases (rad) ``(part, m, n)`` and
        genes ``(part, name)``."""
        out = []
        for key in keys:
            part = self.parts[key[0]]
            if len(key) == 2:
                out.append(part.weight if key[1] == "weight" else getattr(part.genome, key[1]))
            else:
                _, m, n = key
                out.append(part.genome.phases[m, n - part.genome.n_first])
        return np.array(out, dtype=float)

    def with_phases(self, keys, values) -> "Design":
        """A new design with the variables ``keys`` (phases and genes) set to ``values``."""
        phases = [np.array(p.genome.phases) for p in self.parts]
        genes = [{} for _ in self.parts]
        for key, v in zip(keys, np.asarray(values, dtype=float)):
            if len(key) == 2:
                genes[key[0]][key[1]] = float(v)
            else:
                k, m, n = key
                phases[k][m, n - self.parts[k].genome.n_first] = v
        parts = []
        for p, ph, g in zip(self.parts, phases, genes):
            w = g.pop("weight", p.weight)
            parts.append(replace(p, genome=replace(p.genome, phases=ph, **g), weight=w))
        return replace(self, parts=tuple(parts))

    def rescaled(self, factor) -> "Design":
        return replace(self, scale=self.scale * float(factor))

    def part_surface(self, k) -> Surface:
        """Part ``k`` alone (with its weight and the overall scale)."""
        part = self.parts[k]
        s = realize(part.genome, self.length, self.n_nodes, chromosomes=part.chromosomes)
        return s.scaled(self.scale * part.weight)

    def chromosome_surface(self, k, n) -> Surface:
        part = self.parts[k]
        s = realize(part.genome, self.length, self.n_nodes, chromosomes=[n])
        return s.scaled(self.scale * part.weight)

    def surface(self) -> Surface:
        """The designed profile (heights in m) on the genome nodes."""
        surfs = [self.part_surface(k) for k in range(len(self.parts))]
        h = np.sum([s.heights for s in surfs], axis=0)
        meta = {"generator": "roughfe.design", "name": self.name, "length": self.length,
                "n_nodes": self.n_nodes, "x0": surfs[0].metadata["x0"],
                "parts": [{"label": p.label, "chromosomes": list(p.chromosomes)}
                          for p in self.parts]}
        return Surface(h, surfs[0].size, periodic=False, metadata=meta)

    def spectrum_lines(self) -> list:
        """Discrete spectrum ``(q_n (rad/m), a_n (m))`` of every chromosome of every part:
        a_n = scale * weight * G gamma^((1-n)H) * sqrt(M) (the rms-equivalent amplitude of
        the M ridges' waves)."""
        out = []
        for p in self.parts:
            for n in p.chromosomes:
                a = self.scale * p.weight * float(p.genome.wave_amplitude(n)) * math.sqrt(p.genome.M)
                out.append((float(p.genome.wavenumber(n)), a))
        return sorted(out)

    def part_genome(self, k) -> Genome:
        """Part ``k`` as a genome: its weight and the overall scale folded into the
        amplitude gene A; the part's chromosomes (realise only those) in metadata."""
        p = self.parts[k]
        g = p.genome
        return replace(g, A=g.A * p.weight * self.scale,
                       metadata={**g.metadata, "design": self.name, "part": k + 1,
                                 "chromosomes": list(p.chromosomes)})

    def as_genome(self) -> Optional[Genome]:
        """The single genome equal to this design when it has one part, else None."""
        return self.part_genome(0) if len(self.parts) == 1 else None

    # -- JSON --------------------------------------------------------------------------
    def to_dict(self) -> dict:
        return {"format": DESIGN_FORMAT, "version": DESIGN_VERSION, "name": self.name,
                "scale": self.scale, "length": self.length, "n_nodes": self.n_nodes,
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
                   d.get("name", ""))


def entry_design(entry: DatabaseEntry, settings: DatabaseSettings, weight=1.0,
                 chromosomes=None) -> Design:
    """A database genome (or some of its chromosomes) as a one-part design."""
    g = Genome.from_dict(entry.genome)
    ch = tuple(chromosomes) if chromosomes is not None else tuple(entry.macro) + tuple(entry.micro)
    return Design((DesignPart(g, ch, float(weight), entry.label),), 1.0, settings.length,
                  settings.n_nodes, entry.label)


def combine(a: Design, b: Design) -> Design:
    """Cross-over: the sum of two designs (Algs. 5-7 Step 6); scales folded into weights."""
    parts = tuple(replace(p, weight=p.weight * d.scale) for d in (a, b) for p in d.parts)
    return Design(parts, 1.0, a.length, a.n_nodes, f"{a.name}+{b.name}")


# ---------------------------------------------------------------------------------------
# objective: Eq. 4.1 after Eq. 4.2, one or two targets
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class Objective:
    """What a design is scored against.

    ``targets[0]`` sets p_max^t (Eq. 4.2). With two targets (M-CCO) the score is the
    product f = s(y_t1, .) * s(y_t3, .) (Alg. 7 Step 10); the second target is read on
    the same rescaled curve, so it must not extend beyond p_max^t of the first.
    """

    targets: tuple
    p_range: tuple = (0.0, math.inf)

    def __post_init__(self):
        t = tuple(self.targets)
        if not 1 <= len(t) <= 2:
            raise InputError(f"one or two targets, got {len(t)}")
        if len(t) == 2 and t[1].p_max > t[0].p_max * (1 + 1e-6):
            raise InputError(f"the second target reaches p = {t[1].p_max:.6g} Pa beyond the "
                             f"first target's p_max = {t[0].p_max:.6g} Pa (Eq. 4.2 matches one "
                             f"p_max)")
        object.__setattr__(self, "targets", t)

    @property
    def p_max(self) -> float:
        return self.targets[0].p_max

    def scores(self, curve: ResponseCurve) -> tuple:
        """Similarity per target (Eq. 4.1) after Eq. (4.2)."""
        c = curve.to_target_range(self.p_max)
        return tuple(similarity(t, c, self.p_range, rescale=False) for t in self.targets)

    def __call__(self, curve: ResponseCurve) -> float:
        """s (one target) or f = s_1 s_2 (Alg. 7); with a negative score f is the smallest
        score instead, since a product of two negative scores would look good."""
        return combined_score(self.scores(curve))

    def residuals(self, curve: ResponseCurve) -> np.ndarray:
        """Relative errors (y_t - y_i)/y_t at every target point in ``p_range`` (all
        targets stacked); ``s = 1 - max |r|`` for one target (Eq. 4.1)."""
        c = curve.to_target_range(self.p_max)
        out = []
        for t in self.targets:
            sel = (t.pressure >= self.p_range[0]) & (t.pressure <= self.p_range[1])
            yi = np.interp(t.pressure[sel], c.pressure, c.values(t.quantity))
            out.append((t.values[sel] - yi) / t.values[sel])
        return np.concatenate(out)


def combined_score(scores) -> float:
    """Product of the similarity scores (Alg. 7 Step 10) when all are >= 0, else the
    smallest (negative) one."""
    scores = np.asarray(scores, dtype=float)
    return float(np.prod(scores)) if np.all(scores >= 0) else float(scores.min())


class Evaluator:
    """Counts and runs the BEM response of designs (``Surface -> ResponseCurve``)."""

    def __init__(self, settings: DatabaseSettings, response=None):
        self.settings = settings
        self.response = response or (lambda s: profile_response(
            s, youngs_modulus=settings.youngs_modulus, poisson=settings.poisson,
            n_steps=settings.n_steps, kernel=settings.kernel, stiffness=settings.stiffness))
        self.n_sweeps = 0

    def __call__(self, design: Design) -> ResponseCurve:
        self.n_sweeps += 1
        return self.response(design.surface())


# ---------------------------------------------------------------------------------------
# exact sensitivities on the fixed contact sets
# ---------------------------------------------------------------------------------------
def residual_jacobian(design: Design, keys, objective: Objective, settings: DatabaseSettings):
    """Residuals r = (y_t - y)/y_t (as :meth:`Objective.residuals`) and their exact
    derivatives with respect to the phase variables ``keys`` on the fixed contact sets.

    At step j the contact set c_j is fixed and ``H_cc p_c = h_c - max h + Delta_j``
    (gap definition of :mod:`roughfe.bem.contact`), so with ``H_cc x_j = 1`` (H is
    symmetric) the mean pressure varies as

        d p_j = (1/N) [x_j . dh_c + sum(x_j) (dDelta_j - d max h)],
        Delta_j = (j/n_t) (max h - min h).

    The heights vary with a phase phi_{m,n} of a part as
    ``dh/dphi = scale * weight * a_{m,n} (sin(q_n x + phi) - sin(phi))`` (Eq. 3.2).
    K by differences over the steps (``stiffness="fd"``) is ``D p / delta`` with a fixed
    difference matrix D and ``delta = (max h - min h)/n_t``; the exact per-step K and
    A(p) depend only on the contact sets, so their derivatives vanish. The chain then
    goes through the Eq. (4.2) rescaling ``eta = p_max^t / p_n`` and the linear
    interpolation at the target pressures. Gene variables (``(part, name)`` keys) get
    forward differences. One BEM sweep plus n_t solves with H_cc replace the n + 1
    sweeps of finite differences; the derivative ignores contact-set changes, as any
    derivative of this piecewise-smooth map must (measured in
    ``validation/design_study.py``: GCMMA reaches the same scores as with finite
    differences).

    Returns
    -------
    (r, J) : ndarray (n_r,), ndarray (n_r, len(keys))
    """
    from ..bem import Material, contact_sweep, influence_operator
    from .genome import node_coordinates
    surf = design.surface()
    h = surf.heights
    n_nodes = h.size
    sweep = contact_sweep(surf, Material(settings.youngs_modulus, settings.poisson),
                          n_steps=settings.n_steps, kernel=settings.kernel,
                          compute_stiffness=settings.stiffness == "exact")
    p = np.asarray(sweep.mean_pressure, float)
    if np.any(p <= 0):
        raise InputError("a loading step without contact: no sensitivities (use finite differences)")
    k_vals = np.asarray(sweep.stiffness if settings.stiffness == "exact" else sweep.stiffness_fd)
    curve = ResponseCurve(p, k_vals, sweep.area_fraction)
    op = influence_operator(surf.shape, surf.size, sweep.e_star, sweep.results[0].kernel)
    hmat = op.dense()
    i_max, i_min = int(np.argmax(h)), int(np.argmin(h))
    n_t = p.size
    frac = np.arange(1, n_t + 1) / n_t
    # dh/dvariable, shape (N, n_var): phases exactly, genes by differences below
    x = node_coordinates(design.length, design.n_nodes)
    dh = np.zeros((n_nodes, len(keys)))
    gene_cols = []
    for col, key in enumerate(keys):
        if len(key) == 2:
            gene_cols.append(col)
            continue
        k, m, n = key
        part = design.parts[k]
        g = part.genome
        a = float(g.wave_amplitude(n)) * (1.0 if g.anisotropy is None else g.anisotropy[m])
        phi = g.phases[m, n - g.n_first]
        dh[:, col] = design.scale * part.weight * a * (np.sin(g.wavenumber(n) * x + phi) - np.sin(phi))
    d_ptp = dh[i_max] - dh[i_min]
    dp = np.empty((n_t, len(keys)))
    for j, res in enumerate(sweep.results):
        c = np.flatnonzero(res.contact.ravel())
        xj = np.linalg.solve(hmat[np.ix_(c, c)], np.ones(c.size))
        dp[j] = (xj @ dh[c] + xj.sum() * (frac[j] * d_ptp - dh[i_max])) / n_nodes
    if settings.stiffness == "exact":
        dk = np.zeros_like(dp)
    else:
        delta = float(np.ptp(h)) / n_t
        d1 = np.gradient(np.eye(n_t), axis=0, edge_order=1)       # K = d1 @ p / delta
        dk = d1 @ dp / delta - np.outer(k_vals, d_ptp / n_t / delta)
    eta = objective.p_max / p[-1]
    pr = eta * p
    dpr = eta * (dp - np.outer(p, dp[-1] / p[-1]))
    r_out, j_out = [], []
    for t in objective.targets:
        sel = (t.pressure >= objective.p_range[0]) & (t.pressure <= objective.p_range[1])
        pt, yt = t.pressure[sel], t.values[sel]
        yv = curve.values(t.quantity)
        dyv = dk if t.quantity == "K" else np.zeros_like(dp)
        y = np.interp(pt, pr, yv)
        dy = np.empty((pt.size, len(keys)))
        b = np.clip(np.searchsorted(pr, pt), 1, n_t - 1)
        a_ = b - 1
        for i, (ia, ib, q) in enumerate(zip(a_, b, pt)):
            if q <= pr[0]:
                dy[i] = dyv[0]
            elif q >= pr[-1]:
                dy[i] = dyv[-1]
            else:
                span = pr[ib] - pr[ia]
                w = (q - pr[ia]) / span
                dw = (-dpr[ia] * span - (q - pr[ia]) * (dpr[ib] - dpr[ia])) / span ** 2
                dy[i] = (1 - w) * dyv[ia] + w * dyv[ib] + (yv[ib] - yv[ia]) * dw
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
                                  youngs_modulus=settings.youngs_modulus, poisson=settings.poisson,
                                  n_steps=settings.n_steps, kernel=settings.kernel,
                                  stiffness=settings.stiffness)
            jac[:, col] = (objective.residuals(c2) - r) / step
    return r, jac


# ---------------------------------------------------------------------------------------
# GCMMA
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class GcmmaResult:
    """Best point of a GCMMA run (scipy-like report)."""

    x: np.ndarray
    fun: float
    x0: np.ndarray
    fun0: float
    history: tuple
    nit: int
    nfev: int
    success: bool
    message: str


def _inside(u):
    """Keep a GCMMA iterate in the unit box (the subproblem can return round-off or, on a
    degenerate subproblem, non-finite values outside it)."""
    return np.clip(np.nan_to_num(u, nan=0.5, posinf=1.0, neginf=0.0), 0.0, 1.0)


def gcmma_maximize(fun: Callable[[np.ndarray], float], x0, lower, upper, *, n_it: int = 5,
                   eps: float = 0.02, grad: Optional[Callable] = None, f0=None,
                   max_inner: int = 5) -> GcmmaResult:
    """Maximise a score ``s = fun(x) <= 1`` in a box with GCMMA (mmapy ``gcmmasub``).

    Minimises ``(1 - s)^2`` with ``n_it`` outer iterations; variables are mapped to the
    unit box; gradients by forward differences of step ``eps`` (unit-box units) unless
    ``grad(x) -> ds/dx`` is given. Returns the best evaluated point.
    """
    from mmapy import asymp, concheck, gcmmasub, raaupdate
    x0 = np.asarray(x0, float)
    lo, hi = np.asarray(lower, float), np.asarray(upper, float)
    width = hi - lo
    if np.any(width <= 0):
        raise InputError("GCMMA bounds need upper > lower for every variable")
    n, m = x0.size, 1
    nfev = [0]

    def s_of(u):
        nfev[0] += 1
        return float(fun(lo + u.ravel() * width))

    def obj(s):
        return (1.0 - s) ** 2

    def f_and_grad(u, s):
        if grad is not None:
            ds = np.asarray(grad(lo + u.ravel() * width), float) * width
        else:
            ds = np.empty(n)
            for j in range(n):
                up = u.copy()
                step = eps if up[j, 0] + eps <= 1.0 else -eps
                up[j, 0] += step
                ds[j] = (s_of(up) - s) / step
        return np.array([[obj(s)]]), (-2.0 * (1.0 - s) * ds).reshape(n, 1)

    u = ((x0 - lo) / width).reshape(n, 1)
    s0 = float(f0) if f0 is not None else s_of(u)
    best_u, best_s = u.copy(), s0
    history = [s0]
    xmin, xmax = np.zeros((n, 1)), np.ones((n, 1))
    low, upp = xmin.copy(), xmax.copy()
    xold1, xold2 = u.copy(), u.copy()
    a0, a, c, d = 1.0, np.zeros((m, 1)), 1000.0 * np.ones((m, 1)), np.ones((m, 1))
    raa0, raa, raa0eps, raaeps, epsimin = 0.01, 0.01 * np.ones((m, 1)), 1e-6, 1e-6 * np.ones((m, 1)), 1e-7
    fval, dfdx = -np.ones((m, 1)), np.zeros((m, n))
    s = s0
    f0val, df0dx = f_and_grad(u, s)
    it = 0
    for it in range(1, int(n_it) + 1):
        low, upp, raa0, raa = asymp(it, n, u, xold1, xold2, xmin, xmax, low, upp, raa0, raa,
                                    raa0eps, raaeps, df0dx, dfdx)
        xmma, *_, f0app, fapp = gcmmasub(m, n, it, epsimin, u, xmin, xmax, low, upp, raa0, raa,
                                         f0val, df0dx, fval, dfdx, a0, a, c, d)
        xmma = _inside(xmma)
        s_new = s_of(xmma)
        f0new = np.array([[obj(s_new)]])
        conserv = concheck(m, epsimin, f0app, f0new, fapp, fval)
        inner = 0
        while conserv == 0 and inner < max_inner:
            inner += 1
            raa0, raa = raaupdate(xmma, u, xmin, xmax, low, upp, f0new, fval, f0app, fapp, raa0,
                                  raa, raa0eps, raaeps, epsimin)
            xmma, *_, f0app, fapp = gcmmasub(m, n, it, epsimin, u, xmin, xmax, low, upp, raa0,
                                             raa, f0val, df0dx, fval, dfdx, a0, a, c, d)
            xmma = _inside(xmma)
            s_new = s_of(xmma)
            f0new = np.array([[obj(s_new)]])
            conserv = concheck(m, epsimin, f0app, f0new, fapp, fval)
        xold2, xold1, u, s = xold1, u, np.clip(xmma, 0.0, 1.0), s_new
        history.append(s)
        if s > best_s:
            best_u, best_s = u.copy(), s
        if it < n_it:
            f0val, df0dx = f_and_grad(u, s)
    return GcmmaResult(lo + best_u.ravel() * width, best_s, x0, s0, tuple(history), it,
                       nfev[0], True, f"GCMMA: {it} outer iterations, best s = {best_s:.6f} "
                       f"(start {s0:.6f})")


def gcmma_minimax(residuals: Callable[[np.ndarray], np.ndarray], score: Callable, x0, lower,
                  upper, *, n_it: int = 5, eps: float = 0.02, max_inner: int = 5,
                  jacobian: Optional[Callable] = None) -> GcmmaResult:
    """Minimise ``max_j |r_j(x)|`` in a box with GCMMA in Svanberg's min-max form.

    The infinity norm of Eq. (4.1) is not differentiable; Svanberg (2002, Sec. 6) writes
    ``min max_j f_j`` as ``min z  s.t.  f_j(x) - z <= 0`` (``f0 = 0``, ``a0 = a_j = 1``,
    large ``c_j``), here with ``f_j = +-r_j``. Every residual gets its own
    forward-difference derivative from the same ``n + 1`` BEM sweeps that the gradient
    of ``s^2`` costs. ``score(r) -> s`` reports the score of a residual vector.
    ``jacobian(x) -> (r, dr/dx)`` replaces the finite differences when given.
    """
    from mmapy import asymp, concheck, gcmmasub, raaupdate
    x0 = np.asarray(x0, float)
    lo, hi = np.asarray(lower, float), np.asarray(upper, float)
    width = hi - lo
    if np.any(width <= 0):
        raise InputError("GCMMA bounds need upper > lower for every variable")
    n = x0.size
    nfev = [0]

    def r_of(u):
        nfev[0] += 1
        return np.asarray(residuals(lo + u.ravel() * width), float)

    def cons(r):
        return np.concatenate([r, -r]).reshape(-1, 1)

    def jac(u, r):
        if jacobian is not None:
            nfev[0] += 1
            J = np.asarray(jacobian(lo + u.ravel() * width)[1], float) * width[None, :]
            return np.vstack([J, -J])
        J = np.empty((r.size, n))
        for j in range(n):
            up = u.copy()
            step = eps if up[j, 0] + eps <= 1.0 else -eps
            up[j, 0] += step
            J[:, j] = (r_of(up) - r) / step
        return np.vstack([J, -J])

    u = ((x0 - lo) / width).reshape(n, 1)
    r = r_of(u)
    m = 2 * r.size
    s0 = float(score(r))
    best_u, best_s, history = u.copy(), s0, [s0]
    xmin, xmax = np.zeros((n, 1)), np.ones((n, 1))
    low, upp = xmin.copy(), xmax.copy()
    xold1, xold2 = u.copy(), u.copy()
    a0, a, c, d = 1.0, np.ones((m, 1)), 1000.0 * np.ones((m, 1)), np.zeros((m, 1))
    raa0, raa, raa0eps, raaeps, epsimin = 0.01, 0.01 * np.ones((m, 1)), 1e-6, 1e-6 * np.ones((m, 1)), 1e-7
    f0val, df0dx = np.zeros((1, 1)), np.zeros((n, 1))
    fval, dfdx = cons(r), jac(u, r)
    it = 0
    for it in range(1, int(n_it) + 1):
        low, upp, raa0, raa = asymp(it, n, u, xold1, xold2, xmin, xmax, low, upp, raa0, raa,
                                    raa0eps, raaeps, df0dx, dfdx)
        xmma, *_, f0app, fapp = gcmmasub(m, n, it, epsimin, u, xmin, xmax, low, upp, raa0, raa,
                                         f0val, df0dx, fval, dfdx, a0, a, c, d)
        xmma = _inside(xmma)
        r_new = r_of(xmma)
        fnew = cons(r_new)
        conserv = concheck(m, epsimin, f0app, np.zeros((1, 1)), fapp, fnew)
        inner = 0
        while conserv == 0 and inner < max_inner:
            inner += 1
            raa0, raa = raaupdate(xmma, u, xmin, xmax, low, upp, np.zeros((1, 1)), fnew, f0app,
                                  fapp, raa0, raa, raa0eps, raaeps, epsimin)
            xmma, *_, f0app, fapp = gcmmasub(m, n, it, epsimin, u, xmin, xmax, low, upp, raa0,
                                             raa, f0val, df0dx, fval, dfdx, a0, a, c, d)
            xmma = _inside(xmma)
            r_new = r_of(xmma)
            fnew = cons(r_new)
            conserv = concheck(m, epsimin, f0app, np.zeros((1, 1)), fapp, fnew)
        xold2, xold1, u, r = xold1, u, np.clip(xmma, 0.0, 1.0), r_new
        s = float(score(r))
        history.append(s)
        if s > best_s:
            best_u, best_s = u.copy(), s
        if it < n_it:
            fval, dfdx = cons(r), jac(u, r)
    return GcmmaResult(lo + best_u.ravel() * width, best_s, x0, s0, tuple(history), it,
                       nfev[0], True, f"GCMMA min-max: {it} outer iterations, best s = "
                       f"{best_s:.6f} (start {s0:.6f})")


def phase_bounds(phi0, fraction: float = 0.1, bound: str = "start"):
    """Box for the phases: +-fraction*|phi0| ("start", thesis) or +-fraction*2 pi ("period").

    A floor of 1e-3 rad keeps the box open for phases that start at 0.
    """
    phi0 = np.asarray(phi0, float)
    if bound == "start":
        half = np.maximum(fraction * np.abs(phi0), 1e-3)
    elif bound == "period":
        half = np.full(phi0.shape, fraction * 2 * np.pi)
    else:
        raise InputError(f"bound must be 'start' or 'period', got {bound!r}")
    return phi0 - half, phi0 + half


@dataclass(frozen=True)
class GcmmaOptions:
    """Numerical options of the GCMMA stages (Sec. 4.3.1).

    ``n_it``: outer iterations per stage (thesis: SOG 5, GCO/CCO 3, stage 2: 1);
    ``fraction``/``bound``: phase box (see :func:`phase_bounds`); ``eps``: forward
    difference step in unit-box units; ``n_micro``: at most this many micro-scale
    chromosomes per part (the longest wavelengths, largest amplitudes) enter stage 2;
    ``formulation``: ``"minimax"`` (:func:`gcmma_minimax`, Svanberg's min-max form with
    the finite-difference Jacobian of every residual, same cost per iteration) or
    ``"thesis"`` (minimise (1 - s)^2 with the finite-difference gradient of s);
    ``cco_genes``: CCO's stage 1 optimises "all genes of the new genome" (Sec. 4.2.4):
    besides the phases, H, gamma, lambda and the relative amplitude of each part, each
    within +-fraction of its start (SOG and GCO keep H, gamma, lambda fixed, Sec. 4.2.2);
    ``gradient``: ``"exact"`` (:func:`residual_jacobian`, min-max only) or ``"fd"``
    (forward differences, thesis).
    """

    n_it_sog: int = 5
    n_it_cross: int = 3
    n_it_micro: int = 1
    fraction: float = 0.1
    bound: str = "start"
    eps: float = 0.02
    n_micro: int = 6
    formulation: str = "minimax"
    cco_genes: bool = True
    gradient: str = "exact"


def optimise_phases(design: Design, keys, objective: Objective, evaluate: Evaluator, n_it: int,
                    options: GcmmaOptions, f0=None):
    """One GCMMA stage on the phases ``keys`` of ``design``; returns (design, s, GcmmaResult)."""
    if not keys or n_it <= 0:
        s = f0 if f0 is not None else objective(evaluate(design))
        return design, float(s), None
    phi0 = design.phase_values(keys)
    lo, hi = phase_bounds(phi0, options.fraction, options.bound)
    is_gene = np.array([len(k) == 2 for k in keys])
    if is_gene.any():                       # genes (> 0): +-fraction of their start value
        lo[is_gene] = phi0[is_gene] * (1.0 - options.fraction)
        hi[is_gene] = phi0[is_gene] * (1.0 + options.fraction)
    if options.formulation == "minimax":
        def score(r):
            k = [int(np.sum((t.pressure >= objective.p_range[0]) & (t.pressure <= objective.p_range[1])))
                 for t in objective.targets]
            parts = np.split(np.abs(r), np.cumsum(k)[:-1])
            return combined_score([1.0 - p.max() for p in parts])
        jacobian = None
        if options.gradient == "exact":
            def jacobian(x):
                evaluate.n_sweeps += 1
                return residual_jacobian(design.with_phases(keys, x), keys, objective,
                                         evaluate.settings)
        elif options.gradient != "fd":
            raise InputError(f"gradient must be 'exact' or 'fd', got {options.gradient!r}")
        res = gcmma_minimax(lambda x: objective.residuals(evaluate(design.with_phases(keys, x))),
                            score, phi0, lo, hi, n_it=n_it, eps=options.eps, jacobian=jacobian)
    elif options.formulation == "thesis":
        res = gcmma_maximize(lambda x: objective(evaluate(design.with_phases(keys, x))), phi0,
                             lo, hi, n_it=n_it, eps=options.eps, f0=f0)
    else:
        raise InputError(f"formulation must be 'minimax' or 'thesis', got {options.formulation!r}")
    return design.with_phases(keys, res.x), float(res.fun), res


# ---------------------------------------------------------------------------------------
# Alg. 3 and the selections
# ---------------------------------------------------------------------------------------
def score_database(entries: Sequence[DatabaseEntry], target: Target, p_range=(0.0, math.inf)
                   ) -> np.ndarray:
    """Alg. 3: s_i of every database genome after Eq. (4.2), in ``p_range`` (Pa)."""
    if not entries:
        raise InputError("the genome database is empty: build it first ('roughfe db build')")
    return np.array([similarity(target, e.curve, p_range) for e in entries])


def _select(scores, threshold, fallback):
    """Indices with score > threshold, best first; the ``fallback`` best if none pass."""
    order = np.argsort(-scores, kind="stable")
    chosen = [int(i) for i in order if scores[i] > threshold]
    return (chosen if chosen else [int(i) for i in order[:fallback]]), bool(chosen)


@dataclass(frozen=True, eq=False)
class Candidate:
    """One of the (up to three) final designs of a method, with its score per stage."""

    design: Design
    stages: tuple           # scores at GCMMA 0, 1, 2 (and 3 after :func:`refine`)
    scores: tuple           # final similarity per target
    curve: ResponseCurve    # final response on the target range (Eq. 4.2 applied)
    macro: tuple            # variables of stage 1, per part
    micro: tuple            # variables of stage 2, per part
    origin: str


@dataclass(frozen=True, eq=False)
class DesignResult:
    """Output of SOG / GCO / CCO / M-CCO (scipy-like: success, message, nit = BEM sweeps)."""

    method: str
    candidates: tuple
    objective: Objective
    pbar: Optional[float]
    database_scores: dict
    n_cross: int
    n_cross_above: int
    selection_passed: bool
    success: bool
    message: str
    nit: int
    elapsed: float
    references: tuple = REFERENCES

    @property
    def best(self) -> Candidate:
        return self.candidates[0]


def _macro_micro_of(design: Design, curve: ResponseCurve, entries_by_label, threshold,
                    axis="steps"):
    """Alg. 2 on a (cross-over) design from the parents' stored chromosome curves."""
    chroms, curves = [], []
    for k, part in enumerate(design.parts):
        e = entries_by_label[part.label]
        n_s = int(e.genome.get("n_first", 1))
        for n in part.chromosomes:
            chroms.append((k, n))
            curves.append(e.chromosome_curves[n - n_s])
    res = classify(curve, curves, np.arange(len(chroms)), threshold, axis)
    macro = [[] for _ in design.parts]
    micro = [[] for _ in design.parts]
    for j, c in enumerate(res.corr_k):
        k, n = chroms[j]
        (macro if c > threshold else micro)[k].append(n)
    return tuple(tuple(x) for x in macro), tuple(tuple(x) for x in micro)


def _limit_micro(micro, n_micro):
    return tuple(tuple(sorted(m)[:n_micro]) for m in micro)


def _finish(design, s_stages, objective, evaluate, macro, micro, origin):
    curve = evaluate(design)
    eta = objective.p_max / curve.p_max
    design = design.rescaled(eta)
    curve = curve.rescaled(eta)
    return Candidate(design, tuple(float(s) for s in s_stages), objective.scores(curve), curve,
                     macro, micro, origin)


def _optimise_candidates(starts, objective, evaluate, options, n_it1, n_it2, entries_by_label,
                         settings, stage1="macro"):
    """GCMMA 1 and 2 for each start ``(design, s0, curve0, origin)``; best first."""
    out = []
    for design, s0, curve0, origin in starts:
        macro, micro = _macro_micro_of(design, curve0, entries_by_label, settings.threshold,
                                       settings.correlation)
        if stage1 == "all":
            keys1 = design.keys("all") + (design.gene_keys() if options.cco_genes else [])
        else:
            keys1 = design.keys(macro)
        d1, s1, _ = optimise_phases(design, keys1, objective, evaluate, n_it1, options, f0=s0)
        if s1 < s0:
            d1, s1 = design, s0
        if stage1 == "all" or n_it2 <= 0:
            d2, s2 = d1, s1
        else:
            keys2 = d1.keys(_limit_micro(micro, options.n_micro))
            d2, s2, _ = optimise_phases(d1, keys2, objective, evaluate, n_it2, options, f0=s1)
            if s2 < s1:
                d2, s2 = d1, s1
        out.append(_finish(d2, (s0, s1, s2), objective, evaluate, macro, micro, origin))
    out.sort(key=lambda c: -combined_score(c.scores))
    return tuple(out)


def _result(method, cands, objective, pbar, dbs, n_cross, n_above, passed, evaluate, t0):
    best = cands[0]
    msg = (f"{method}: best {best.origin} s = {combined_score(best.scores):.4f} "
           f"(stages {', '.join(f'{s:.4f}' for s in best.stages)})"
           + ("" if passed else "; no genome passed the 0.95 selection, the best ones were used"))
    return DesignResult(method, cands, objective, pbar, dbs, n_cross, n_above, passed, True, msg,
                        evaluate.n_sweeps, time.perf_counter() - t0)


def _check_entries(entries):
    if not entries:
        raise InputError("the genome database is empty: build it first ('roughfe db build')")
    return list(entries), {e.label: e for e in entries}


def sog(entries, target: Target, settings: DatabaseSettings, *, evaluate=None,
        options: GcmmaOptions = GcmmaOptions(), n_best: int = 3) -> DesignResult:
    """Simple Optimisation of Genes (Alg. 4).

    The ``n_best`` genomes with the largest s (Alg. 3) are optimised with GCMMA on the
    phases of their macro-scale chromosomes (Alg. 2, stored in the database; stage 1,
    ``n_it_sog`` iterations), then on their micro-scale phases (stage 2).
    """
    t0 = time.perf_counter()
    entries, by_label = _check_entries(entries)
    evaluate = evaluate or Evaluator(settings)
    objective = Objective((target,))
    s = score_database(entries, target)
    starts = []
    for i in np.argsort(-s, kind="stable")[:n_best]:
        e = entries[int(i)]
        d = entry_design(e, settings, weight=target.p_max / e.p_max)
        starts.append((d, float(s[i]), e.curve.rescaled(target.p_max / e.p_max), e.label))
    cands = _optimise_candidates(starts, objective, evaluate, options, options.n_it_sog,
                                 options.n_it_micro, by_label, settings)
    return _result("sog", cands, objective, None, {"s": s.tolist()}, 0, 0, True, evaluate, t0)


def _cross(entries, by_label, objective, settings, evaluate, sets, parts_of, n_best, max_set):
    """Steps 5-12 of Algs. 5-7: every pair of U1 x U2, rescaled (Eq. 4.2), scored."""
    u1, u2 = (s[:max_set] if max_set else s for s in sets)
    pool = []
    for i1 in u1:
        for i2 in u2:
            e1, e2 = entries[i1], entries[i2]
            d1 = entry_design(e1, settings, objective.p_max / e1.p_max, parts_of[0](e1))
            d2 = entry_design(e2, settings, objective.p_max / e2.p_max, parts_of[1](e2))
            d = combine(d1, d2)
            curve = evaluate(d)
            pool.append((objective(curve), d, curve, f"{e1.label}+{e2.label}"))
    pool.sort(key=lambda t: -t[0])
    starts = [(d, s, c, o) for s, d, c, o in pool[:n_best]]
    return starts, len(pool), sum(1 for t in pool if t[0] > 0.95)


def _two_range_sets(entries, target, pbar, threshold=0.95, fallback=3):
    r1, r2 = split_ranges(target, pbar)
    s1, s2 = score_database(entries, target, r1), score_database(entries, target, r2)
    u1, ok1 = _select(s1, threshold, fallback)
    u2, ok2 = _select(s2, threshold, fallback)
    return (s1, s2), (u1, u2), ok1 and ok2


def gco(entries, target: Target, pbar: float, settings: DatabaseSettings, *, evaluate=None,
        options: GcmmaOptions = GcmmaOptions(), n_best: int = 3, max_set: Optional[int] = 8
        ) -> DesignResult:
    """Genome Cross-Over (Alg. 5).

    U1/U2: genomes with s > 0.95 on [0, pbar] / [pbar, p_max^t] (the 3 best of a range
    if none passes; at most ``max_set`` per set, None = all as in the thesis); every
    pair U1 x U2 is summed (each at its Eq. 4.2 amplitude), rescaled and scored; the
    ``n_best`` best go through GCMMA on their macro phases (Alg. 2 on the new genome),
    then their micro phases.
    """
    t0 = time.perf_counter()
    entries, by_label = _check_entries(entries)
    pbar = target.check_pbar(pbar)
    evaluate = evaluate or Evaluator(settings)
    objective = Objective((target,))
    (s1, s2), sets, passed = _two_range_sets(entries, target, pbar)
    every = (lambda e: None, lambda e: None)
    starts, n_cross, n_above = _cross(entries, by_label, objective, settings, evaluate, sets,
                                      every, n_best, max_set)
    cands = _optimise_candidates(starts, objective, evaluate, options, options.n_it_cross,
                                 options.n_it_micro, by_label, settings)
    return _result("gco", cands, objective, pbar, {"s1": s1.tolist(), "s2": s2.tolist()},
                   n_cross, n_above, passed, evaluate, t0)


def cco(entries, target: Target, pbar: float, settings: DatabaseSettings, *, evaluate=None,
        options: GcmmaOptions = GcmmaOptions(), n_best: int = 3, max_set: Optional[int] = 8
        ) -> DesignResult:
    """Chromosomes Cross-Over (Alg. 6): as GCO with the macro-scale chromosomes only;
    GCMMA on all genes of the new genome (phases, and with ``options.cco_genes`` also H,
    gamma, lambda and the part amplitudes; stage 1); stage 2 repeats stage 1 (Sec. 4.3.1)."""
    t0 = time.perf_counter()
    entries, by_label = _check_entries(entries)
    pbar = target.check_pbar(pbar)
    evaluate = evaluate or Evaluator(settings)
    objective = Objective((target,))
    (s1, s2), sets, passed = _two_range_sets(entries, target, pbar)
    macro = (lambda e: e.macro or e.micro[:1], lambda e: e.macro or e.micro[:1])
    starts, n_cross, n_above = _cross(entries, by_label, objective, settings, evaluate, sets,
                                      macro, n_best, max_set)
    cands = _optimise_candidates(starts, objective, evaluate, options, options.n_it_cross, 0,
                                 by_label, settings, stage1="all")
    return _result("cco", cands, objective, pbar, {"s1": s1.tolist(), "s2": s2.tolist()},
                   n_cross, n_above, passed, evaluate, t0)


def mcco(entries, target_k: Target, target_a: Target, settings: DatabaseSettings, *,
         evaluate=None, options: GcmmaOptions = GcmmaOptions(), n_best: int = 3,
         max_set: Optional[int] = 8, pool: int = 0, swap: bool = False,
         weights: Sequence[float] = (1.0,)) -> DesignResult:
    """Mixed Chromosomes Cross-Over (Alg. 7) for a K(p) target and an A(p) target.

    U1: macro chromosomes of genomes with s(y_t1, K) > 0.95; U2: micro chromosomes of
    genomes with s(y_t3, A) > 0.95 (the 3 best if none passes); every pair summed,
    rescaled, scored with f = s_K * s_A; the ``n_best`` best get GCMMA on their macro
    phases, then on their micro phases, objective f.

    Wider start pool (beyond the thesis; the defaults are the thesis'): ``pool = k``
    puts the k best genomes of each Alg. 3 ranking in U1/U2 (besides those > 0.95, at
    most ``max_set``); ``swap`` also crosses the macro chromosomes of the A-ranked
    genomes with the micro chromosomes of the K-ranked ones; ``weights`` multiplies the
    micro part's Eq. (4.2) amplitude by each factor before the pair is rescaled, so
    the macro/micro amplitude ratio is scanned too. Every start is one BEM sweep.
    """
    t0 = time.perf_counter()
    if target_k.quantity != "K" or target_a.quantity != "A":
        raise InputError(f"M-CCO needs a K(p) target and an A(p) target, got "
                         f"{target_k.quantity!r} and {target_a.quantity!r}")
    entries, by_label = _check_entries(entries)
    evaluate = evaluate or Evaluator(settings)
    objective = Objective((target_k, target_a))
    s1, s2 = score_database(entries, target_k), score_database(entries, target_a)
    fallback = max(3, int(pool))
    u1, ok1 = _select(s1, 0.95, fallback)
    u2, ok2 = _select(s2, 0.95, fallback)
    if pool:
        u1 = list(dict.fromkeys(u1 + [int(i) for i in np.argsort(-s1, kind="stable")[:pool]]))
        u2 = list(dict.fromkeys(u2 + [int(i) for i in np.argsort(-s2, kind="stable")[:pool]]))
    u1, u2 = (u[:max_set] if max_set else u for u in (u1, u2))
    pairs = [(i1, i2) for i1 in u1 for i2 in u2]
    if swap:
        pairs += [(i2, i1) for i2 in u2 for i1 in u1 if (i2, i1) not in pairs]
    ws = tuple(float(w) for w in weights)
    if not ws or any(not (np.isfinite(w) and w > 0) for w in ws):
        raise InputError(f"weights must be finite and > 0, got {weights!r}")
    found = []
    for i1, i2 in pairs:
        if i1 == i2:
            continue
        e1, e2 = entries[i1], entries[i2]
        d1 = entry_design(e1, settings, objective.p_max / e1.p_max, e1.macro or e1.micro[:1])
        for w in ws:
            d2 = entry_design(e2, settings, w * objective.p_max / e2.p_max,
                              e2.micro or e2.macro[-1:])
            d = combine(d1, d2)
            curve = evaluate(d)
            tag = f"{e1.label}+{e2.label}" + ("" if w == 1.0 else f" (micro x{w:g})")
            found.append((objective(curve), d, curve, tag))
    found.sort(key=lambda t: -t[0])
    starts = [(d, s, c, o) for s, d, c, o in found[:n_best]]
    cands = _optimise_candidates(starts, objective, evaluate, options, options.n_it_cross,
                                 options.n_it_micro, by_label, settings)
    return _result("mcco", cands, objective, None, {"s1": s1.tolist(), "s2": s2.tolist()},
                   len(found), sum(1 for t in found if t[0] > 0.95), ok1 and ok2, evaluate, t0)


def refine(result: DesignResult, settings: DatabaseSettings, *, rounds: int = 3, n_it: int = 15,
           options: GcmmaOptions = GcmmaOptions(bound="period"), evaluate=None) -> DesignResult:
    """An optional stage beyond the thesis ("GCMMA 3"): GCMMA on *all* phases of every
    candidate (macro and micro together), ``rounds`` times ``n_it`` iterations, the
    +-``options.fraction`` box re-centred on the current phases at every round.

    Re-centring lets the phases drift beyond +-10 % of their database values, which the
    thesis stages do not allow; the result keeps the thesis stages and appends the
    refined score as a fourth stage, so both are reported. Candidates are re-sorted.
    """
    t0 = time.perf_counter()
    evaluate = evaluate or Evaluator(settings)
    objective = result.objective
    out = []
    for c in result.candidates:
        d, sc = c.design, combined_score(c.scores)
        for _ in range(int(rounds)):
            d_new, s_new, _ = optimise_phases(d, d.keys("all"), objective, evaluate, n_it, options,
                                              f0=sc)
            if s_new <= sc + 1e-12:
                break
            d, sc = d_new, s_new
        new = _finish(d, (*c.stages[:3], sc), objective, evaluate, c.macro, c.micro, c.origin)
        out.append(new)
    out.sort(key=lambda c: -combined_score(c.scores))
    return replace(result, candidates=tuple(out), nit=result.nit + evaluate.n_sweeps,
                   elapsed=result.elapsed + time.perf_counter() - t0,
                   message=result.message + f"; refined (GCMMA 3, {rounds} x {n_it} it., all "
                   f"phases): s = {combined_score(out[0].scores):.4f}")


def run_design(method: str, entries, targets, settings: DatabaseSettings, *, pbar=None,
               evaluate=None, options: GcmmaOptions = GcmmaOptions(), **kw) -> DesignResult:
    """Dispatch to :func:`sog`, :func:`gco`, :func:`cco` or :func:`mcco` (the CLI entry)."""
    targets = list(targets)
    if method not in METHODS:
        raise InputError(f"method must be one of {METHODS}, got {method!r}")
    if method == "mcco":
        if len(targets) != 2:
            raise InputError("mcco needs two targets: K(p) (--target) and A(p) (--second-target)")
        return mcco(entries, targets[0], targets[1], settings, evaluate=evaluate,
                    options=options, **kw)
    if len(targets) != 1:
        raise InputError(f"{method} takes one target, got {len(targets)}")
    if method == "sog":
        return sog(entries, targets[0], settings, evaluate=evaluate, options=options, **kw)
    if pbar is None:
        raise InputError(f"{method} needs the threshold pressure pbar (Pa)")
    fn = gco if method == "gco" else cco
    return fn(entries, targets[0], pbar, settings, evaluate=evaluate, options=options, **kw)


# ---------------------------------------------------------------------------------------
# reproducibility and the thesis targets
# ---------------------------------------------------------------------------------------
def rescore(design: Design, targets, settings: DatabaseSettings, response=None) -> tuple:
    """Independent check: realise a saved design, run a fresh BEM sweep *without* any
    rescaling and return the similarity per target (must equal the reported scores)."""
    evaluate = Evaluator(settings, response)
    curve = evaluate(design)
    return tuple(similarity(t, curve, rescale=False) for t in targets)


def rescore_at_target_pressures(design: Design, targets, settings: DatabaseSettings) -> tuple:
    """Stricter independent check: Eq. (4.1) with the design solved *at the target's
    pressures* (load-controlled BEM steps), so nothing is interpolated.

    :func:`rescore` (and every optimiser) samples the design at its own n_t equal
    approaches and interpolates linearly at the target pressures. A(p) of a profile is
    a count of contact nodes (a staircase in p), so the interpolated value can be a
    fraction of a node that the design never has at that pressure. Here one
    displacement solve at Delta = peak-valley gives p_max (Eq. 4.2 factor
    ``eta = p_max^t / p_max``); then the design is solved at the pressures ``p_j / eta``
    of all targets; A is the exact node fraction there and K = dp/dDelta by the same
    central differences over those steps as the target's K over its own steps. An
    independent BEM run of the target genome itself scores 1 to round-off.
    """
    from ..bem import Material, contact_sweep
    from ..bem.sweep import central_differences
    targets = list(targets)
    surf = design.surface()
    mat = Material(settings.youngs_modulus, settings.poisson)
    top = contact_sweep(surf, mat, deltas=[float(np.ptp(surf.heights))], kernel=settings.kernel,
                        compute_stiffness=False)
    eta = targets[0].p_max / float(top.mean_pressure[-1])
    p = np.unique(np.concatenate([t.pressure for t in targets]))
    sw = contact_sweep(surf, mat, pressures=p / eta, kernel=settings.kernel,
                       compute_stiffness=False)
    k = central_differences(sw.delta, sw.mean_pressure)
    curve = ResponseCurve(np.asarray(sw.mean_pressure) * eta, k, sw.area_fraction)
    return tuple(similarity(t, curve, rescale=False) for t in targets)


#: the genome behind target y_t1 (not in the Sobol database: gamma, H off the Sobol points,
#: phases from a different generator), fixed here and recorded in every report.
Y_T1_GENES = {"gamma": 1.55, "H": 0.8, "A": 1.0, "phase_seed": 20190}


def target_genome_t1(settings: DatabaseSettings) -> Genome:
    """Genome of y_t1: M = 1, lambda = L, phases ``default_rng(20190).uniform(0, 2 pi)``."""
    from .database import make_genome
    g = make_genome(Y_T1_GENES["gamma"], Y_T1_GENES["H"], Y_T1_GENES["phase_seed"], settings,
                    amplitude=Y_T1_GENES["A"])
    return replace(g, metadata={"role": "target y_t1", **Y_T1_GENES})


def thesis_targets(settings: DatabaseSettings, response=None, *, pbar2_fraction=0.53 / 1.6):
    """Targets of Sec. 4.3-4.4: y_t1 (K of :func:`target_genome_t1`), y_t3 (its A(p)) and
    y_t2 (K linear in p up to pbar, flat after, on the same pressure range).

    The thesis gives p in its own units and no p_max^t; reading p_max^t ~ 1.6e-4 off
    Figs. 57-59, ``pbar2_fraction = 0.53/1.6`` places pbar = 0.53e-4 at the same fraction
    of p_max^t. y_t2 starts at y_t1's first value (K at first contact is finite), rises
    linearly to y_t1's value at pbar and stays there. Returns ``(t1, t2, t3, curve)``.
    """

    evaluate = Evaluator(settings, response)
    g = target_genome_t1(settings)
    d = Design((DesignPart(g, tuple(range(g.n_first, g.n_last + 1)), 1.0, "y_t1"),), 1.0,
               settings.length, settings.n_nodes, "y_t1")
    curve = evaluate(d)
    meta = {"genome": g.to_dict(), "settings": settings.to_dict()}
    t1 = Target(curve.pressure, curve.stiffness, "K", "y_t1", meta)
    t3 = Target(curve.pressure, curve.area_fraction, "A", "y_t3", meta)
    pbar = pbar2_fraction * curve.p_max
    plateau = float(np.interp(pbar, curve.pressure, curve.stiffness))
    from .similarity import linear_then_flat_target as ltf
    t2 = ltf(curve.p_max, pbar, plateau, n_points=settings.n_steps, name="y_t2",
             start=float(curve.stiffness[0]))
    return t1, t2, t3, curve


# ---------------------------------------------------------------------------------------
# result files
# ---------------------------------------------------------------------------------------
def result_to_dict(result: DesignResult, settings: DatabaseSettings) -> dict:
    """JSON-safe report of a design run: candidates, scores per stage, targets, settings."""
    return {
        "format": "roughfe-design-result", "version": 1, "method": result.method,
        "message": result.message, "success": result.success, "nit_bem_sweeps": result.nit,
        "elapsed_s": result.elapsed, "pbar": result.pbar, "n_cross": result.n_cross,
        "n_cross_above_0.95": result.n_cross_above,
        "selection_passed": result.selection_passed,
        "targets": [t.to_dict() for t in result.objective.targets],
        "settings": settings.to_dict(), "database_scores": result.database_scores,
        "candidates": [{"origin": c.origin, "stages": list(c.stages), "scores": list(c.scores),
                        "score": combined_score(c.scores), "macro": [list(m) for m in c.macro],
                        "micro": [list(m) for m in c.micro], "curve": c.curve.to_dict(),
                        "design": c.design.to_dict()} for c in result.candidates],
        "references": list(result.references)}


def write_design_result(result: DesignResult, settings: DatabaseSettings, outdir) -> dict:
    """Write the best design and the report to ``outdir`` (atomically).

    Files: ``result.json`` (:func:`result_to_dict`), ``design.json`` (the best design,
    reloadable with :meth:`Design.from_dict`), ``genome.json`` (the roughfe-genome when
    the design is one genome; for several, ``genome_partK.json``: part K as a genome with
    its weight and the overall scale in A), ``profile.npz`` (native
    surface file of the designed profile), ``curves.csv`` (p, targets, K, A) and
    ``stages.csv`` (similarity per candidate and GCMMA stage).
    """
    from pathlib import Path
    from ..surfaces.io import save_surface
    from ..writers import write_json, write_text
    out = Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    best = result.best
    paths = {"result": write_json(out / "result.json", result_to_dict(result, settings)),
             "design": write_json(out / "design.json", best.design.to_dict())}
    g = best.design.as_genome()
    if g is not None:  # one genome: realisable with 'roughfe genome realize'
        paths["genome"] = save_genome(g, out / "genome.json")
    else:  # several genomes cannot be one genome: each part is one (its chromosomes in metadata)
        for k in range(len(best.design.parts)):
            paths[f"genome_part{k + 1}"] = save_genome(best.design.part_genome(k),
                                                       out / f"genome_part{k + 1}.json")
    paths["profile"] = save_surface(best.design.surface(), out / "profile.npz")
    c = best.curve
    cols = ["pressure_Pa", "K_Pa_per_m", "A"]
    data = [c.pressure, c.stiffness, c.area_fraction]
    for t in result.objective.targets:
        cols.append(f"target_{t.name}_{t.quantity}")
        data.append(np.interp(c.pressure, t.pressure, t.values, left=np.nan, right=np.nan))
    lines = [",".join(cols)] + [",".join(f"{v:.10g}" for v in row) for row in zip(*data)]
    paths["curves"] = write_text(out / "curves.csv", "\n".join(lines) + "\n")
    rows = ["method,candidate,origin,gcmma0,gcmma1,gcmma2,gcmma3_refined,final"]
    rows += [f"{result.method},{k + 1},{cand.origin},{cand.stages[0]:.6f},{cand.stages[1]:.6f},"
             f"{cand.stages[2]:.6f},"
             f"{cand.stages[3] if len(cand.stages) > 3 else float('nan'):.6f},"
             f"{combined_score(cand.scores):.6f}"
             for k, cand in enumerate(result.candidates)]
    paths["stages"] = write_text(out / "stages.csv", "\n".join(rows) + "\n")
    return paths
