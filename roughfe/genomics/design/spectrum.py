"""Design variables beyond the phases (issue 15 Sec. 3): the chromosome amplitudes of a
design set to the power spectrum of a given target surface, a stage beyond the thesis
between its GCMMA stages and :func:`~.algorithms.search_at_target_pressures`."""
from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from ...errors import InputError
from ..bands import wavevector_magnitude
from ..database import DatabaseSettings
from .algorithms import DesignResult, _at_targets, _extended, _finish, score_database
from .model import Design, entry_design
from .objective import Evaluator, combined_score


def spectrum_matched(design: Design, surface) -> Design:
    """``design`` with the amplitude of every chromosome set to the rms height the target
    surface carries in that chromosome's band (a stage beyond the thesis, issue 15 Sec. 3).

    The design is split into one part per chromosome (:meth:`Design.split_chromosomes`)
    and every Fourier mode of ``surface`` (periodic, e.g. the mirrored measured window of
    :func:`target_surface`) is assigned to the chromosome whose wavenumber q_n is nearest
    in log q (so the bands of all parts, of any gamma, partition the spectrum once); part
    ``k``'s weight is multiplied by ``rms_t,k / rms_k`` (Parseval: the rms of the modes of
    the band over that of the chromosome realised). A chromosome whose band holds no
    energy keeps 1e-3 of the largest ratio (weights stay > 0). Phases, angles and the
    lattice stay those of the design; the overall scale is left to Eq. (4.2). Why: for a
    randomly phased (Gaussian) surface K(p) and A(p) are functionals of the power
    spectrum (Persson's theory), and Eq. (4.2) can only stretch p, so a design whose
    band amplitudes follow the target's starts on the right K level (x3p-2, 64 x 64, six
    best genomes: s_K 0.16-0.28 -> 0.35-0.75).
    """
    if not surface.periodic or surface.ndim != 2 or design.dim != 2:
        raise InputError("spectrum_matched needs a surface design (dim 2) and a periodic 2D "
                         "target surface (mirror a measured window first)")
    d = design.split_chromosomes()
    q_parts = np.array([float(p.genome.wavenumber(p.chromosomes[0])) for p in d.parts])
    power = np.abs(np.fft.fftn(surface.heights - surface.heights.mean())) ** 2
    power /= surface.heights.size ** 2                   # Parseval: sum = mean square (m^2)
    q = wavevector_magnitude(surface.shape, surface.size, "fft")
    live = q > 0
    nearest = np.argmin(np.abs(np.log(q[live])[:, None] - np.log(q_parts)[None, :]), axis=1)
    target_ms = np.bincount(nearest, weights=power[live], minlength=len(d.parts))
    ratio = np.array([np.sqrt(target_ms[k]) / d.part_surface(k).heights.std()
                      for k in range(len(d.parts))])
    ratio = np.maximum(ratio, 1e-3 * ratio.max())
    keys = [(k, "weight") for k in range(len(d.parts))]
    return d.with_phases(keys, [p.weight * r for p, r in zip(d.parts, ratio)])


def match_spectrum(result: DesignResult, surface, settings: DatabaseSettings, *, entries=(),
                   n_entries: int = 0, evaluate=None) -> DesignResult:
    """A stage beyond the thesis: every candidate replaced by :func:`spectrum_matched`
    when that raises its strict score (solved at the target pressures), and the
    ``n_entries`` best genomes of ``entries`` by Alg. 3 on the first target, spectrum
    matched, added as candidates of their own (their stages: the genome's Alg. 3 score,
    then twice the matched design's score, no GCMMA stage having run). Four
    counted sweeps per candidate (three when it was already scored at the target
    pressures), three per added genome. Run it before :func:`search_at_target_pressures`,
    which then searches the phases and (``amplitudes=True``) the per-chromosome weights
    from there. Measured on x3p-2 (64 x 64): a candidate that GCMMA has tuned keeps its
    phases better than its matched spectrum (SOG 0.694 stays), while a matched database
    genome starts at s_K up to 0.75 against 0.28 unmatched (docs/theory/surface-design.md).
    """
    t0 = time.perf_counter()
    evaluate = evaluate or Evaluator(settings)
    objective = result.objective
    out = []
    for c in result.candidates:
        before = c.at_targets or _at_targets(c.design, objective, settings, evaluate)
        new = _finish(spectrum_matched(c.design, surface), c.stages, objective, evaluate,
                      c.macro, c.micro, c.origin + " (spectrum)")
        new = replace(new, at_targets=_at_targets(new.design, objective, settings, evaluate))
        out.append(new if combined_score(new.at_targets) > combined_score(before)
                   else replace(c, at_targets=before))
    if n_entries > 0:
        s0 = score_database(entries, objective.targets[0])
        for i in np.argsort(-s0, kind="stable")[:int(n_entries)]:
            e = entries[int(i)]
            new = _finish(spectrum_matched(entry_design(e, settings), surface), (s0[i],),
                          objective, evaluate, (), (), e.label + " (spectrum)")
            s1 = combined_score(new.scores)
            out.append(replace(new, stages=(float(s0[i]), s1, s1),
                               at_targets=_at_targets(new.design, objective, settings,
                                                      evaluate)))
    out.sort(key=lambda c: -combined_score(c.at_targets))
    f = combined_score(out[0].at_targets)
    return _extended(result, out, evaluate, t0, f"; chromosome amplitudes matched to the target "
                     f"spectrum (+ {int(n_entries)} matched database genomes): f at p_t = "
                     f"{f:.4f}")
