"""Search stages beyond the thesis on the score solved at the target's own pressures
(issue 14): :func:`search_at_target_pressures` (a (1+1)-ES, one design per BEM sweep)
and :func:`search_global` (IPOP-CMA-ES, a generation of designs solved together by the
batched BEM of :mod:`roughfe.bem.batch_exact`). Both take a :class:`DesignResult` of Algs.
4-7 and return it with the searched candidates."""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

import numpy as np

from ...errors import InputError, check_int
from ...optim.cmaes import ipop_cmaes
from ...optim.es import one_plus_one_es
from ..database import DatabaseSettings
from .algorithms import Candidate, DesignResult, _at_targets, _extended, _finish
from .crest import peak_height
from .model import Design, is_amplitude_key
from .objective import Evaluator, combined_score
from .targets import SCORINGS, score_batch


#: amplitude variables of a search stage (``amplitudes=``, CLI ``--search-amplitudes``):
#: "part" (each part's weight), "chromosome" (each chromosome's,
#: :meth:`Design.split_chromosomes`) or "wave" (each ridge m of each chromosome n: the
#: factor alpha_m of a one-chromosome part, :meth:`Design.ridge_keys`; surfaces, beyond
#: Eq. 3.17's one amplitude per ridge)
AMPLITUDE_VARIABLES = ("part", "chromosome", "wave")


def _amplitude_kind(amplitudes) -> str:
    """``amplitudes`` as one of :data:`AMPLITUDE_VARIABLES` (False -> "part", True ->
    "chromosome", the older boolean spelling)."""
    kind = {False: "part", True: "chromosome"}[amplitudes] if isinstance(amplitudes, bool) \
        else amplitudes
    if kind not in AMPLITUDE_VARIABLES:
        raise InputError(f"amplitudes must be one of {AMPLITUDE_VARIABLES}, got {amplitudes!r}")
    return kind


#: genes of every part that :attr:`GlobalSearchOptions.genes` makes variables
SEARCH_GENES = ("gamma", "H", "lambda1")


def _search_variables(design: Design, amplitudes, genes: bool = False):
    """The variables of a search stage: every phase and the amplitudes of
    :data:`AMPLITUDE_VARIABLES` ``amplitudes`` (with ``genes`` also every part's
    :data:`SEARCH_GENES`). Returns the design they act on, their keys, start values and
    a mask of the variables that are not phases (amplitudes and genes)."""
    kind = _amplitude_kind(amplitudes)
    d0 = design if kind == "part" else design.split_chromosomes()
    amps = d0.ridge_keys() if kind == "wave" else [(k, "weight") for k in range(len(d0.parts))]
    keys = d0.keys("all") + amps
    if genes:
        keys += [(k, g) for k in range(len(d0.parts)) for g in SEARCH_GENES]
    return d0, keys, d0.phase_values(keys), np.array([is_amplitude_key(k) or k[1] in
                                                      SEARCH_GENES for k in keys])


def _searched(c: Candidate, design: Design, objective, settings, evaluate) -> Candidate:
    """Candidate ``c`` with the design a search stage found: its thesis stages kept, its
    scores re-evaluated on the n_t approaches (:func:`_finish`) and ``at_targets`` the
    strict scores of one single (unbatched) solve at the target pressures."""
    new = _finish(design, c.stages, objective, evaluate, c.macro, c.micro, c.origin)
    return replace(new, at_targets=_at_targets(new.design, objective, settings, evaluate))


def search_at_target_pressures(result: DesignResult, settings: DatabaseSettings, *,
                               n_eval: int = 400, width: float = math.pi,
                               weight_fraction: float = 0.3, sigma: float = 0.3, seed: int = 0,
                               starts: int = 1, amplitudes="part",
                               evaluate=None) -> DesignResult:
    """An optional stage beyond the thesis: a derivative-free search of every phase and
    part weight on the score solved *at the target's own pressures*.

    The thesis stages (and :func:`refine`) maximise Eq. (4.1) on the design's n_t equal
    approaches interpolated at the target pressures, by GCMMA within +-10 % boxes. Two
    things stop them on a multi-target design (Alg. 7): A(p) is a count of contact nodes,
    so s_A is a staircase whose derivative on the fixed contact sets is zero, and the
    boxes keep the phases near a local optimum. Here the objective is f of
    :func:`rescore_at_target_pressures` (load-controlled BEM steps at the pressures
    ``p_t / eta``, Eq. 4.2; A is the exact node fraction, K central differences), i.e.
    the strict score itself. Variables: all phases (box +-``width`` around their current
    values; the default is the whole period) and each part's weight (the macro/micro
    amplitude ratio, +-``weight_fraction``), mapped to the unit box. Optimiser: a (1+1)
    evolution strategy (Rechenberg's 1/5 success rule, step ``sigma`` in the unit box,
    ``default_rng(seed)``, :func:`roughfe.optim.es.one_plus_one_es`) that accepts equal
    scores, so it walks across the plateaus of the staircase; ``n_eval`` sweeps per run.
    (Measured on y_t1/y_t3, N = 512: Powell's method stops on the first plateau it meets.)

    ``starts``: a deterministic multi-start, ``starts`` independent runs from each
    candidate's design (one generator, drawn on in order), the best strict f kept.
    Measured on y_t1/y_t3, N = 512, from the thesis-stage M-CCO result: 4 x 400 sweeps
    give f at p_t = 0.843 against 0.820 with one start (4890 against 1284 sweeps).
    ``amplitudes`` (:data:`AMPLITUDE_VARIABLES`; ``True`` is "chromosome"): "chromosome"
    makes the amplitude of every chromosome a variable too (the design is split into one
    part per chromosome, :meth:`Design.split_chromosomes`, the same profile), each within
    +-``weight_fraction`` of its start: the spectrum, which sets K(p) at the higher
    loads, moves with the phases, which set the first contacts. "wave" (surfaces) makes
    every wave's amplitude (ridge m of chromosome n, :meth:`Design.ridge_keys`) a
    variable instead: the directional spread of each band's energy moves too (measured
    on x3p-2 SOG, 300 sweeps: 0.946 against 0.955 per chromosome, the larger search
    space costs more than it gains at this budget; ``docs/theory/surface-design.md``).

    Each candidate keeps its thesis stages; its design is replaced only when the strict
    f improves, its ``scores``/``curve`` are re-evaluated on the n_t approaches (as
    everywhere, so :func:`rescore` reproduces them) and ``at_targets`` holds the strict
    scores. Candidates are re-sorted by the strict f.
    """
    if n_eval < 1 or not width > 0 or not 0 < weight_fraction < 1 or not sigma > 0 \
            or int(starts) < 1:
        raise InputError(f"n_eval >= 1, width > 0, 0 < weight_fraction < 1, sigma > 0 and "
                         f"starts >= 1 needed, got {n_eval!r}, {width!r}, {weight_fraction!r}, "
                         f"{sigma!r}, {starts!r}")
    t0 = time.perf_counter()
    evaluate = evaluate or Evaluator(settings)
    objective = result.objective
    rng = np.random.default_rng(seed)
    out = []
    for c in result.candidates:
        d0, keys, x0, is_w = _search_variables(c.design, amplitudes)
        lo = np.where(is_w, x0 * (1 - weight_fraction), x0 - width)
        hi = np.where(is_w, x0 * (1 + weight_fraction), x0 + width)

        def strict(u):
            d = d0.with_phases(keys, lo + (hi - lo) * u)
            return combined_score(_at_targets(d, objective, settings, evaluate))

        runs = [one_plus_one_es(strict, (x0 - lo) / (hi - lo), n_eval, sigma=sigma, rng=rng)
                for _ in range(int(starts))]
        best = max(runs, key=lambda r: r.fun)          # the first of equals: deterministic
        d_best = d0.with_phases(keys, lo + (hi - lo) * best.x) if best.fun > best.fun0 else \
            c.design
        out.append(_searched(c, d_best, objective, settings, evaluate))
    out.sort(key=lambda c: -combined_score(c.at_targets))
    f = combined_score(out[0].at_targets)
    return _extended(result, out, evaluate, t0, f"; search at the target pressures ((1+1)-ES, "
                     f"all phases +-{width:.3g} rad, "
                     f"{_amplitude_kind(amplitudes)} weights +-{weight_fraction:.0%}, "
                     f"{starts} x {n_eval} sweeps per candidate): f at p_t = {f:.4f}")


#: global search stages (``GlobalSearchOptions.method``, CLI ``--global``)
GLOBAL_METHODS = ("cmaes",)
#: what the global stage maximises (``GlobalSearchOptions.score``, CLI ``--global-score``):
#: "strict" (f solved at the target pressures) or "min" (the smaller of the strict f and
#: the interpolated f, Eq. 4.1 on the design's own n_t approaches)
GLOBAL_SCORES = ("strict", "min")


@dataclass(frozen=True)
class GlobalSearchOptions:
    """Settings of :func:`search_global` (CLI ``design --global cmaes`` and its
    ``--global-*`` flags).

    Attributes
    ----------
    method : str
        ``"cmaes"``: IPOP-CMA-ES, :func:`roughfe.optim.cmaes.ipop_cmaes`.
    n_eval : int
        Strict evaluations per searched candidate (one evaluation: a profile solved at
        its p_max approach and at the target pressures ``p_t / eta``, Eq. 4.2), >= 2.
    sigma : float
        First CMA-ES step (rad for the phases; the weight variables are mapped through
        tanh, so the same number is a fraction of their range), > 0.
    popsize : int
        Population of the first run (0: ``4 + 3 ln n``), doubled at each restart.
    weight_fraction : float
        Part weights (the macro/micro mixing of a cross-over) vary as
        ``w = w_0 (1 + weight_fraction tanh v)`` (-), 0 < weight_fraction < 1; used when
        ``amplitudes`` is 0.
    amplitudes : float
        0: off. > 0: the design is split into one part per chromosome
        (:meth:`Design.split_chromosomes`, the same heights) and every chromosome's
        amplitude (Eq. 3.2's ``a_n``, with its part's weight and the Eq. 4.2 scale
        folded in) is a variable on a log scale, ``a_n = a_n0 exp(amplitudes tanh v)``,
        so within ``[a_n0 e^-amplitudes, a_n0 e^amplitudes]`` (strictly); replaces the
        part weights (each chromosome carries its own). At most 2.
    waves : bool
        With ``amplitudes > 0``: every *wave* (ridge m of chromosome n, the factor
        alpha_m of a one-chromosome part, :meth:`Design.ridge_keys`) is a log-scale
        amplitude variable instead of every chromosome (surfaces; beyond Eq. 3.17's one
        amplitude per ridge).
    genes : float
        0: off. > 0: every part's genes gamma, H and lambda1 (Eq. 3.2: the wavenumbers
        ``q_n = 2 pi gamma^(n-1) / lambda1`` and amplitudes ``G gamma^((1-n) H)`` of its
        chromosomes) are variables too, ``g = g_0 (1 + genes tanh v)`` (-), 0 <= genes
        < 1; not with ``amplitudes`` (a split design would give every chromosome its own
        gamma).
    seed : int
        Every IPOP-CMA-ES run draws from ``numpy.random.default_rng(seed)``: the search
        is deterministic (rounds differ by their start, candidates by their design).
    n_candidates : int
        The best candidates (by strict f) searched, one after the other, >= 1.
    rounds : int
        IPOP-CMA-ES runs one after the other, each from the best design of the round
        before (population back to ``popsize``, step back to ``sigma``), ``n_eval``
        evaluations each, >= 1. Measured (``docs/theory/06_design.md``): the restarts
        of IPOP return to the start design, and the basin of the best design found is
        explored only by a run that starts there.
    score : str
        What is maximised (:data:`GLOBAL_SCORES`): ``"strict"``, f solved at the target
        pressures (:func:`~.targets.score_batch` "strict"), or ``"min"``, the smaller of
        that and the interpolated f (Eq. 4.1 on the design's own n_t equal approaches
        after Eq. 4.2, "interpolated": the thesis scoring, reproduced by
        :func:`~.targets.rescore`), so that a design found meets a goal under both
        scorings; one evaluation then costs about 1.8 strict ones (the two sweeps share
        the p_max solve; measured in ``docs/theory/06_design.md``).
    peak : float
        0: off. > 0 (surfaces): the maximised value is lowered by ``peak_weight x max(0,
        z_max - peak)``, ``z_max = (max Z - mean Z) / rms Z`` the design's highest node
        in rms heights (-), e.g. the target's own z_max (Eq. 4.2 scales p by the
        design's p_max, reached at ``top_fraction x (max Z - mean Z)``; :mod:`.crest`).
        Measured in session 8 on x3p-2 M-CCO: it lowers z_max but not the level of A(p)
        (``docs/theory/surface-design.md``), so the study leaves it off. The reported
        scores stay the strict ones.
    peak_weight : float
        Penalty per rms height of ``z_max`` above ``peak`` (-), > 0.
    modulation : float
        0: off. > 0 (surfaces): one more variable, the depth of the short waves'
        modulation by the long-wave height (:attr:`Design.modulation`,
        :func:`~.modulation.modulated_heights`), ``epsilon = epsilon_0 + modulation tanh
        v`` (-), epsilon_0 the start design's (0 after the thesis stages). Measured in
        session 9 on x3p-2 M-CCO (from the study's 300-sweep search, f 0.7773, seed 0):
        0.5 gives f 0.8732 at 2000 evaluations (0.8477 without) and 0.9085 at 6000
        (0.8607 without; ``docs/theory/surface-design.md``).
    """

    method: str = "cmaes"
    n_eval: int = 20000
    sigma: float = 0.5
    popsize: int = 0
    weight_fraction: float = 0.3
    amplitudes: float = 0.0
    waves: bool = False
    genes: float = 0.0
    seed: int = 0
    n_candidates: int = 1
    rounds: int = 1
    score: str = "strict"
    peak: float = 0.0
    peak_weight: float = 1.0
    modulation: float = 0.0

    def __post_init__(self):
        if self.method not in GLOBAL_METHODS:
            raise InputError(f"method must be one of {GLOBAL_METHODS}, got {self.method!r}")
        if self.score not in GLOBAL_SCORES:
            raise InputError(f"global search: score must be one of {GLOBAL_SCORES}, got "
                             f"{self.score!r}")
        for name, low in (("n_eval", 2), ("popsize", 0), ("n_candidates", 1), ("rounds", 1),
                          ("seed", 0)):
            check_int(f"global search: {name}", getattr(self, name), low)
        checks = (("sigma > 0", self.sigma > 0 and math.isfinite(self.sigma), self.sigma),
                  ("0 < weight_fraction < 1", 0 < self.weight_fraction < 1,
                   self.weight_fraction),
                  ("0 <= amplitudes <= 2 (log half-range)", 0 <= self.amplitudes <= 2,
                   self.amplitudes),
                  ("0 <= genes < 1", 0 <= self.genes < 1, self.genes),
                  ("genes = 0 with amplitudes", not (self.genes and self.amplitudes),
                   self.genes),
                  ("peak >= 0", self.peak >= 0 and math.isfinite(self.peak), self.peak),
                  ("peak_weight > 0", self.peak_weight > 0 and math.isfinite(self.peak_weight),
                   self.peak_weight),
                  ("0 <= modulation <= 2", 0 <= self.modulation <= 2, self.modulation))
        for what, ok, value in checks:
            if not ok:
                raise InputError(f"global search: {what} needed, got {value!r}")
        if self.waves and not self.amplitudes > 0:
            raise InputError("global search: waves=True needs amplitudes > 0 (the log "
                             "half-range of the wave amplitudes)")

    @property
    def kind(self) -> str:
        """The amplitude variables, one of :data:`AMPLITUDE_VARIABLES`."""
        return "part" if not self.amplitudes > 0 else "wave" if self.waves else "chromosome"

    def values(self, keys, x0, X) -> np.ndarray:
        """The design variables ``keys`` (start values ``x0``) of the CMA-ES points ``X``
        (rows): phases as they are (rad), weights and genes mapped into their bounds."""
        is_gene = np.array([len(k) == 2 and k[1] in SEARCH_GENES for k in keys])
        is_w = np.array([is_amplitude_key(k) for k in keys])
        if self.amplitudes > 0:
            w = x0 * np.exp(self.amplitudes * np.tanh(X))
        else:
            w = x0 * (1 + self.weight_fraction * np.tanh(X))
        return np.where(is_w, w, np.where(is_gene, x0 * (1 + self.genes * np.tanh(X)), X))

    def describe(self) -> str:
        what = (f"{self.kind} amplitudes x exp(+-{self.amplitudes:g})" if self.amplitudes > 0
                else f"part weights +-{self.weight_fraction:.0%}")
        return what + (f", genes {'/'.join(SEARCH_GENES)} +-{self.genes:.0%}"
                       if self.genes > 0 else "") + (
            f", z_max above {self.peak:g} rms penalised x {self.peak_weight:g}"
            if self.peak > 0 else "") + (
            f", short-wave modulation +-{self.modulation:g}" if self.modulation > 0 else "")

    @property
    def scorings(self) -> tuple:
        """The kinds of :func:`~.targets.score_batch` an evaluation needs."""
        return ("strict",) if self.score == "strict" else SCORINGS

    def objective_values(self, scores: dict) -> np.ndarray:
        """The maximised value of each row of :func:`~.targets.score_batch`'s ``scores``:
        f (:func:`combined_score`) of the strict scores, or the smaller of the strict and
        the interpolated f (``score="min"``)."""
        return np.min([[combined_score(r) for r in scores[k]] for k in self.scorings], axis=0)

    def peak_penalty(self, designs) -> np.ndarray:
        """``peak_weight x max(0, z_max - peak)`` of every design (0 with ``peak`` off),
        ``z_max = (max Z - mean Z) / rms Z`` of its realised heights (-)."""
        if not self.peak > 0:
            return np.zeros(len(designs))
        z_max = np.array([peak_height(d.surface().heights) for d in designs])
        return self.peak_weight * np.maximum(0.0, z_max - self.peak)


def search_global(result: DesignResult, settings: DatabaseSettings,
                  options: GlobalSearchOptions = GlobalSearchOptions(), **overrides
                  ) -> DesignResult:
    """An optional global stage beyond the thesis: IPOP-CMA-ES on the score solved at
    the target's own pressures, with the designs of a population solved together.

    ``options`` (:class:`GlobalSearchOptions`); keyword ``overrides`` replace its fields
    (``search_global(r, s, n_eval=60)``).

    Objective (``score="strict"``): f (:func:`combined_score`, Alg. 7 Step 10) of
    :func:`~.targets.score_batch_at_target_pressures`, the strict score of
    :func:`rescore_at_target_pressures` (load-controlled exact BEM at ``p_t / eta``,
    Eq. 4.2; A the exact node count, K central differences, Eq. 4.1) for a whole CMA-ES
    generation at once (:mod:`roughfe.bem.batch_exact`); ``score="min"``: the smaller of
    that f and the interpolated f (the thesis scoring, Eq. 4.1 on the design's own n_t
    approaches), from the same batched solves. Variables: every phase (rad,
    unbounded: a phase is periodic) and either every part weight, ``w = w_0 (1 +
    weight_fraction tanh v)``, or (``amplitudes > 0``) every chromosome's amplitude on a
    log scale, ``a_n = a_n0 exp(amplitudes tanh v)``. Optimiser:
    :func:`roughfe.optim.cmaes.ipop_cmaes` from the candidate's design with step
    ``sigma``, population ``popsize`` (default 4 + 3 ln n), doubled at each restart,
    ``n_eval`` strict evaluations per candidate and round, ``default_rng(seed)``; with
    ``rounds`` > 1 the next run starts from the best design found; the ``n_candidates``
    best candidates (by strict f) are searched, the others kept.

    Why: the thesis stages and the (1+1)-ES of :func:`search_at_target_pressures`
    stop at f <= 0.843 at p_t on y_t1/y_t3, while the set f >= 0.9 around the target
    genome is a few hundredths of a radian wide in 15 phases (measured); a search that
    can afford 10^4-10^5 evaluations and learns the correlations of the phases (the
    covariance) is the measured alternative (``docs/theory/06_design.md``).

    The best design found is re-scored by one single, unbatched solve (``at_targets``)
    and replaces the candidate's design only when its strict f rose; candidates are
    re-sorted by the strict f. ``nit`` counts every strict evaluation as one sweep.
    """
    opts = replace(options, **overrides) if overrides else options
    t0 = time.perf_counter()
    evaluate = Evaluator(settings)
    objective = result.objective
    cands = list(result.candidates)
    strict0 = [combined_score(c.at_targets) if c.at_targets else
               combined_score(_at_targets(c.design, objective, settings, evaluate))
               for c in cands]
    order = np.argsort(strict0, kind="stable")[::-1]
    out, runs, curves = [], [], []
    for rank, i in enumerate(order):
        c = cands[i]
        if rank >= int(opts.n_candidates):
            out.append(c if c.at_targets else replace(c, at_targets=_at_targets(
                c.design, objective, settings, evaluate)))
            continue
        c, c_runs = _global_rounds(c, opts, objective, settings, evaluate)
        out.append(c)
        runs += c_runs
        curves.append(_joined_history([r.history for r in c_runs]))
    out.sort(key=lambda c: -combined_score(c.at_targets))
    f = combined_score(out[0].at_targets)
    interp = (f", interpolated f = {combined_score(out[0].scores):.4f}" if opts.score == "min"
              else "")
    hist = "; ".join(f"{r.nfev} evaluations in {r.n_runs} runs (populations "
                     f"{', '.join(map(str, r.popsizes))}): f {r.fun0:.4f} -> {r.fun:.4f}"
                     for r in runs)
    rounds = f"{opts.rounds} rounds from the best, " if opts.rounds > 1 else ""
    what = "at the target pressures" if opts.score == "strict" else \
        "on min(f at the target pressures, interpolated f)"
    res = _extended(result, out, evaluate, t0, f"; global search {what} "
                    f"(IPOP-CMA-ES, sigma {opts.sigma:g}, phases and {opts.describe()}, "
                    f"{rounds}{hist}): f at p_t = {f:.4f}{interp}")
    return replace(res, search_history=tuple(curves))


def _global_rounds(c: Candidate, opts: GlobalSearchOptions, objective, settings, evaluate):
    """``opts.rounds`` IPOP-CMA-ES runs of :func:`search_global` on candidate ``c``, each
    from the best design of the round before (re-scored by one single solve in between,
    :func:`_searched`); stops early when a round finds nothing better (the next would
    repeat it). Returns the candidate and the :class:`~roughfe.optim.cmaes.CmaResult`
    of each round."""
    runs = []
    for _ in range(int(opts.rounds)):
        d0, keys, x0, is_w = _search_variables(c.design, opts.kind, opts.genes > 0)
        designs = _designs_of(d0, keys, x0, opts)

        def fun(X, designs=designs):
            ds = designs(X)
            sc = score_batch(ds, objective.targets, settings, opts.scorings)
            evaluate.n_sweeps += len(X)
            return opts.objective_values(sc) - opts.peak_penalty(ds)

        start = np.where(is_w, 0.0, x0)
        if opts.modulation > 0:                    # the modulation depth: one more variable
            start = np.append(start, 0.0)
        run = ipop_cmaes(fun, start, opts.sigma, int(opts.n_eval),
                         popsize=int(opts.popsize), rng=np.random.default_rng(opts.seed))
        runs.append(run)
        improved = run.fun > run.fun0
        c = _searched(c, designs(run.x[None, :])[0] if improved else c.design, objective,
                      settings, evaluate)
        if not improved:
            break
    return c, runs


def _designs_of(d0: Design, keys, x0, opts: GlobalSearchOptions):
    """The map from CMA-ES points (rows) to designs of :func:`_global_rounds`: the
    variables ``keys`` of ``d0`` (start values ``x0``) by :meth:`GlobalSearchOptions.values`,
    and with ``opts.modulation`` > 0 the last column the modulation depth,
    ``epsilon_0 + modulation tanh v``."""
    def designs(X):
        X = np.asarray(X, dtype=float)
        if not opts.modulation > 0:
            return [d0.with_phases(keys, v) for v in opts.values(keys, x0, X)]
        eps = d0.modulation + opts.modulation * np.tanh(X[:, -1])
        return [replace(d0.with_phases(keys, v), modulation=float(e))
                for v, e in zip(opts.values(keys, x0, X[:, :-1]), eps)]
    return designs


def _joined_history(histories) -> np.ndarray:
    """Rows (strict evaluations spent, best f so far) of consecutive rounds as one curve."""
    spent, rows = 0, []
    for h in histories:
        h = np.array(h, dtype=float)
        h[:, 0] += spent
        spent = h[-1, 0]
        rows.append(h)
    h = np.concatenate(rows)
    h[:, 1] = np.maximum.accumulate(h[:, 1])
    return h
