"""What a design is scored against: Eq. (4.1) after Eq. (4.2), one or two targets
(Alg. 7 Step 10), and the counted BEM evaluation of designs."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import InputError, check_instance
from ..database import DatabaseSettings
from ..macro_micro import profile_response
from ..similarity import ResponseCurve, Target, similarity
from .model import Design


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
        for k, target in enumerate(t):
            check_instance(f"targets[{k}]", target, Target,
                           "a roughfe.genomics.similarity.Target")
        try:
            lo, hi = (float(v) for v in self.p_range)
        except (TypeError, ValueError):
            lo = hi = math.nan
        if not 0 <= lo < hi:
            raise InputError(f"p_range must be (p_low, p_high) in Pa with 0 <= p_low < p_high, "
                             f"got {self.p_range!r}")
        object.__setattr__(self, "p_range", (lo, hi))
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
        targets stacked); ``s = 1 - max |r|`` for one target (Eq. 4.1). The curve is
        read as :func:`similarity` reads it (:meth:`ResponseCurve.at`: from (0, 0) below
        its first pressure)."""
        c = curve.to_target_range(self.p_max)
        out = []
        for t in self.targets:
            sel = (t.pressure >= self.p_range[0]) & (t.pressure <= self.p_range[1])
            yi = c.at(t.pressure[sel], t.quantity)
            out.append((t.values[sel] - yi) / t.values[sel])
        return np.concatenate(out)


#: similarity above which a database genome (Algs. 5-7 Step 2-3) or a cross-over counts
#: as a match (thesis: 0.95), and a design matches its target (:func:`verdict`)
SELECTION = 0.95


def _beside(s: float) -> str:
    """``s`` with 4 significant digits, or as many as it takes to tell it from the
    selection value (0.95004 is not printed "0.95 > 0.95")."""
    for digits in (4, 6, 8, 12, 17):
        text = f"{s:.{digits}g}"
        if float(text) == s or float(text) != SELECTION and (float(text) > SELECTION) == (s > SELECTION):
            return text
    return text


@dataclass(frozen=True)
class Verdict:
    """Whether a design matches its targets (:func:`verdict`), with the scores that
    decided it, per target (``names``), and where they come from: ``solved`` True when
    the design was solved at the target pressures
    (:func:`~.targets.rescore_at_target_pressures`), False when its curve on its own n_t
    approaches was interpolated there (Eq. 4.1 after Eq. 4.2)."""

    matched: bool
    scores: tuple
    names: tuple
    solved: bool

    @property
    def source(self) -> str:
        return ("solved at the target pressures" if self.solved else
                "interpolated from the design's own n_t approaches")

    def _each(self) -> str:
        """``s = 0.97 > 0.95`` (one target) or ``s(y_t1) = 0.97 > 0.95, s(y_t3) = ...``."""
        return ", ".join(f"s{f'({n})' if len(self.names) > 1 else ''} = {_beside(s)} "
                         f"{'>' if s > SELECTION else '<='} {SELECTION}"
                         for n, s in zip(self.names, self.scores))

    def note(self) -> str:
        """The verdict as the design message states it."""
        if len(self.scores) == 1:
            return (f"the target is {'' if self.matched else 'NOT '}matched ({self._each()}, "
                    f"the selection value of Alg. 3; decided by the score {self.source})")
        return (f"the targets are {'' if self.matched else 'NOT '}matched ({self._each()}: "
                f"each target's s must exceed {SELECTION}, the selection value of Alg. 3; "
                f"decided by the scores {self.source})")

    def short(self) -> str:
        """The verdict in a figure title."""
        return (f"target{'s' if len(self.scores) > 1 else ''} "
                f"{'' if self.matched else 'NOT '}matched: {self._each()} ({self.source})")


def verdict(candidate, targets) -> Verdict:
    """The one verdict on a design candidate's match to ``targets``, for the message,
    result.json and the figure title alike: decided by its scores solved at the target
    pressures (``candidate.at_targets``) when it has them -- the search stages and
    ``roughfe design`` solve the best design there -- else by its interpolated
    ``scores``; matched when every target's s is above :data:`SELECTION` (Alg. 3's
    single-target value; the product f = s_K s_A of M-CCO, Alg. 7, is what is maximised,
    and two targets at 0.9709 each are matched although f = 0.9427)."""
    solved = len(candidate.at_targets) > 0
    scores = tuple(float(s) for s in (candidate.at_targets if solved else candidate.scores))
    return Verdict(all(s > SELECTION for s in scores), scores,
                   tuple(t.name for t in targets), solved)


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
            s, **settings.response_options()))
        self.n_sweeps = 0

    def __call__(self, design: Design) -> ResponseCurve:
        self.n_sweeps += 1
        return self.response(design.surface())

