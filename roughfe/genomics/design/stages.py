"""One GCMMA stage of Sec. 4.3.1 on the phases (and genes) of a design.

GCMMA itself is :func:`roughfe.optim.gcmma.gcmma` (the one driver loop). Variables are
the phases, bounded to +-10 % of their start (thesis) or, with ``bound="period"``, to
+-10 % of 2 pi (a relative bound on an angle depends on its arbitrary origin and freezes
phases near 0: the thesis choice is kept as the default because it is what the thesis
reports); gradients by forward differences as in the thesis, or exact on the fixed
contact sets (:mod:`.sensitivities`). Eq. (4.2) is re-applied at every evaluation.
"""
from __future__ import annotations

import numbers
from dataclasses import dataclass

import numpy as np

from ...errors import InputError, check_finite_positive, check_int
from ...optim.gcmma import gcmma
from .model import Design
from .objective import Evaluator, Objective, combined_score
from .sensitivities import residual_jacobian

#: GCMMA subproblems of a stage: "minimax" (Svanberg's min-max form, the default) or
#: "thesis" (minimise (1 - s)^2), see :mod:`roughfe.optim.gcmma`
FORMULATIONS = ("minimax", "thesis")
BOUNDS = ("start", "period")
GRADIENTS = ("exact", "fd")


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
    ``formulation``: ``"minimax"`` (Svanberg's min-max form with the finite-difference
    Jacobian of every residual, same cost per iteration) or ``"thesis"`` (minimise
    (1 - s)^2 with the finite-difference gradient of s), both by
    :func:`roughfe.optim.gcmma.gcmma`;
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

    def __post_init__(self):
        """Every option checked when the options are made, before any database or BEM
        work (they were read only when a stage reached them)."""
        for name in ("n_it_sog", "n_it_cross", "n_it_micro", "n_micro"):
            check_int(f"GcmmaOptions.{name}", getattr(self, name), 0)
        f = self.fraction
        if isinstance(f, bool) or not isinstance(f, numbers.Real) or not 0 < f <= 1:
            raise InputError(f"GcmmaOptions.fraction must be in (0, 1], got {f!r}")
        check_finite_positive("GcmmaOptions.eps (forward-difference step, unit box)", self.eps)
        for name, allowed in (("bound", BOUNDS), ("formulation", FORMULATIONS),
                              ("gradient", GRADIENTS)):
            if getattr(self, name) not in allowed:
                raise InputError(f"GcmmaOptions.{name} must be one of {allowed}, "
                                 f"got {getattr(self, name)!r}")
        if not isinstance(self.cco_genes, bool):
            raise InputError(f"GcmmaOptions.cco_genes must be True or False, "
                             f"got {self.cco_genes!r}")


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

    def designed(x):
        return evaluate(design.with_phases(keys, x))

    if options.formulation == "thesis":
        res = gcmma(lambda x: [objective(designed(x))], phi0, lo, hi, form="square", n_it=n_it,
                    eps=options.eps, y0=None if f0 is None else [f0])
        return design.with_phases(keys, res.x), float(res.fun), res
    sizes = [int(np.sum((t.pressure >= objective.p_range[0])
                        & (t.pressure <= objective.p_range[1]))) for t in objective.targets]

    def score(r):
        parts = np.split(np.abs(r), np.cumsum(sizes)[:-1])
        return combined_score([1.0 - p.max() for p in parts])

    jacobian = None
    if options.gradient == "exact":
        def jacobian(x):
            return residual_jacobian(design.with_phases(keys, x), keys, objective,
                                     evaluate.settings, evaluate)[1]
    res = gcmma(lambda x: objective.residuals(designed(x)), phi0, lo, hi, form="minimax",
                score=score, n_it=n_it, eps=options.eps, jacobian=jacobian,
                label="GCMMA min-max")
    return design.with_phases(keys, res.x), float(res.fun), res

