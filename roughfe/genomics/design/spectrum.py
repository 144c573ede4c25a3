"""Design variables beyond the phases (issue 15 Sec. 3): the chromosome amplitudes of a
design set to the power spectrum of a given target surface, a stage beyond the thesis
between its GCMMA stages and :func:`~.search.search_at_target_pressures`."""
from __future__ import annotations

import math

import time
from dataclasses import replace

import numpy as np

from ...errors import InputError, check_finite_positive
from ...surfaces.stats import angular_wavevectors
from ..bands import wavevector_magnitude
from ..database import DatabaseSettings
from ..periodic import lattice_wavevectors, periodic_heights
from .algorithms import DesignResult, _at_targets, _extended, _finish, score_database
from .model import Design, entry_design
from .objective import Evaluator, combined_score


def spectrum_matched(design: Design, surface, directional: bool = False) -> Design:
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

    ``directional=True`` (beyond the thesis and beyond Eq. 3.17's one amplitude per
    ridge): every *wave* (ridge m, chromosome n) gets the rms of its own cell of the
    target spectrum. Each target mode goes first to the chromosome nearest in log q (as
    above), then, within it, to the ridge whose realised lattice wavevector is nearest in
    direction (angles modulo pi), and wave (m, n) gets the amplitude ``sqrt(2 ms_cell)``
    of a plane wave carrying the cell's mean square (a cosine of amplitude a has mean
    square a^2/2), through the per-ridge factor alpha_m of its one-chromosome part. So
    the design's directional spread of band energy follows the target's, as far as its
    M directions per chromosome allow: a measured surface's band energy is spread over
    all directions, a genome's over M. Waves that round to the same lattice vector share
    their cell; a cell without energy keeps 1e-3 of the largest ratio.
    """
    if not surface.periodic or surface.ndim != 2 or design.dim != 2:
        raise InputError("spectrum_matched needs a surface design (dim 2) and a periodic 2D "
                         "target surface (mirror a measured window first)")
    d = design.split_chromosomes()
    q_parts = np.array([float(p.genome.wavenumber(p.chromosomes[0])) for p in d.parts])
    q, power = _mode_power(surface)
    nearest = np.argmin(np.abs(np.log(q)[:, None] - np.log(q_parts)[None, :]), axis=1)
    target_ms = np.bincount(nearest, weights=power, minlength=len(d.parts))
    if directional:
        return _directions_matched(d, surface, nearest, power)
    ratio = np.array([np.sqrt(target_ms[k]) / d.part_surface(k).heights.std()
                      for k in range(len(d.parts))])
    ratio = np.maximum(ratio, 1e-3 * ratio.max())
    keys = [(k, "weight") for k in range(len(d.parts))]
    return d.with_phases(keys, [p.weight * r for p, r in zip(d.parts, ratio)])


def _mode_power(surface):
    """``|q|`` (rad/m) and mean square ``|h~(q)|^2`` (m^2) of every Fourier mode ``q != 0``
    of a periodic ``surface``, in the FFT's order (Parseval: they sum to the mean square
    about the mean). The one spectrum :func:`spectrum_matched` distributes and
    :func:`long_wave_share` judges."""
    power = np.abs(np.fft.fftn(surface.heights - surface.heights.mean())) ** 2
    power /= surface.heights.size ** 2                   # Parseval: sum = mean square (m^2)
    q = wavevector_magnitude(surface.shape, surface.size, "fft")
    live = q > 0
    return q[live], power[live]


def long_wave_share(surface, length: float) -> float:
    """Share of a periodic target surface's mean square at wavelengths longer than
    ``length``, the design period L (m)::

        s_L = sum_{0 < |q| < 2 pi / L} |h~(q)|^2 / sum_{q != 0} |h~(q)|^2      (-),

    over the Fourier modes of :func:`_mode_power` (the spectrum :func:`spectrum_matched`
    distributes; a mode of wavelength L itself, ``|q| = 2 pi / L`` to 1e-9, is not
    counted: the designs hold it). A design is periodic with period L, so it holds none
    of these modes: :func:`spectrum_matched` gives their mean square to the chromosome
    nearest in log q, the longest, at its own wavelength. A cosine ``a cos(q x)`` adds
    ``a^2 / 2`` to the numerator when ``q < 2 pi / L``. A measured window of side L,
    evenly mirrored (:func:`~.targets.target_surface`), has modes of wavelength 2 L and
    ``sqrt(2) L``: spectral windows carried 0.5-22 % there (H 0.3-0.9), windows of 2 L
    27-84 % (round 2, session 36).

    Returns
    -------
    float
        ``s_L`` in [0, 1]; NaN for a flat surface (no mean square to share).

    Raises
    ------
    InputError
        A non-periodic surface (mirror a measured window first, as
        :func:`spectrum_matched`), or ``length`` not a finite positive number.
    """
    length = check_finite_positive("length (m)", length)
    if not surface.periodic:
        raise InputError("long_wave_share needs a periodic target surface, as "
                         "spectrum_matched (mirror a measured window first)")
    q, power = _mode_power(surface)
    total = float(power.sum())
    if not total > 0:
        return float("nan")
    return float(power[q < 2 * np.pi / length * (1 - 1e-9)].sum() / total)


def _directions_matched(d: Design, surface, part_of, power) -> Design:
    """:func:`spectrum_matched` ``directional=True`` on the one-chromosome parts ``d``:
    ``part_of`` is the part of every live target mode, ``power`` its mean square (m^2)."""
    qx, qy = (np.broadcast_to(q, surface.shape) for q in angular_wavevectors(surface.shape,
                                                                              surface.size))
    live = wavevector_magnitude(surface.shape, surface.size, "fft") > 0
    theta = np.arctan2(qy[live], qx[live]) % np.pi
    amps = []
    for k, part in enumerate(d.parts):
        kk, ll = lattice_wavevectors(part.genome, part.chromosomes, d.length)
        ridge_theta = np.arctan2(ll[:, 0], kk[:, 0]) % np.pi
        mine = part_of == k
        gap = np.abs(theta[mine][:, None] - ridge_theta[None, :])
        ridge = np.argmin(np.minimum(gap, np.pi - gap), axis=1)
        ms = np.bincount(ridge, weights=power[mine], minlength=part.genome.M)
        now = part.weight * np.array([periodic_heights(part.genome, d.length, d.n_nodes,
                                                       part.chromosomes, rows=[m]).std()
                                      for m in range(part.genome.M)])
        amps.append(np.where(now > 0, np.sqrt(ms) / np.where(now > 0, now, 1.0), 0.0))
    floor = 1e-3 * max(float(a.max()) for a in amps)
    parts = []
    for part, a in zip(d.parts, amps):
        alpha = (np.ones(part.genome.M) if part.genome.anisotropy is None
                 else part.genome.anisotropy) * np.maximum(a, floor)
        parts.append(replace(part, genome=replace(part.genome, anisotropy=alpha)))
    return replace(d, parts=tuple(parts))


def match_spectrum(result: DesignResult, surface, settings: DatabaseSettings, *, entries=(),
                   n_entries: int = 0, directional: bool = False,
                   evaluate=None) -> DesignResult:
    """A stage beyond the thesis: every candidate replaced by :func:`spectrum_matched`
    when that raises its strict score (solved at the target pressures), and the
    ``n_entries`` best genomes of ``entries`` by Alg. 3 on the first target, spectrum
    matched, added as candidates of their own (their stages: the genome's Alg. 3 score,
    then NaN for GCMMA 1 and 2, which did not run; stages.csv wrote the matched design's
    score there, under GCMMA headers, until round 2, session 31; its score is the
    candidate's ``scores``). Four
    counted sweeps per candidate (three when it was already scored at the target
    pressures), three per added genome. Run it before :func:`search_at_target_pressures`,
    which then searches the phases and (``amplitudes=True``) the per-chromosome weights
    from there. Measured on x3p-2 (64 x 64): a candidate that GCMMA has tuned keeps its
    phases better than its matched spectrum (SOG 0.694 stays), while a matched database
    genome starts at s_K up to 0.75 against 0.28 unmatched (docs/theory/surface-design.md).
    ``directional``: match every wave, not every chromosome (:func:`spectrum_matched`).
    """
    t0 = time.perf_counter()
    evaluate = evaluate or Evaluator(settings)
    objective = result.objective
    out = []
    for c in result.candidates:
        before = c.at_targets or _at_targets(c.design, objective, settings, evaluate)
        new = _finish(spectrum_matched(c.design, surface, directional), c.stages, objective,
                      evaluate, c.macro, c.micro, c.origin + " (spectrum)")
        new = replace(new, at_targets=_at_targets(new.design, objective, settings, evaluate))
        out.append(new if combined_score(new.at_targets) > combined_score(before)
                   else replace(c, at_targets=before))
    if n_entries > 0:
        s0 = score_database(entries, objective.targets[0])
        for i in np.argsort(-s0, kind="stable")[:int(n_entries)]:
            e = entries[int(i)]
            new = _finish(spectrum_matched(entry_design(e, settings), surface,
                                                    directional), (s0[i],),
                          objective, evaluate, (), (), e.label + " (spectrum)")
            out.append(replace(new, stages=(float(s0[i]), math.nan, math.nan),
                               at_targets=_at_targets(new.design, objective, settings,
                                                      evaluate)))
    out.sort(key=lambda c: -combined_score(c.at_targets))
    f = combined_score(out[0].at_targets)
    kind = "wave" if directional else "chromosome"
    return _extended(result, out, evaluate, t0, f"; {kind} amplitudes matched to the target "
                     f"spectrum (+ {int(n_entries)} matched database genomes): f at p_t = "
                     f"{f:.4f}")
