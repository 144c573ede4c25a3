"""Roughness design for a target K(p)/A(p) (thesis Sec. 4.2-4.4, Algs. 3-7).

Modules, by idea (see ``docs/theory/genomics-layout.md``):

* :mod:`.model` -- :class:`Design`/:class:`DesignPart` (a sum of chromosome sets of
  genomes, Eq. 3.2, with the Eq. 4.2 factors) and their JSON;
* :mod:`.objective` -- :class:`Objective` (Eq. 4.1 after Eq. 4.2; f = s_1 s_2 of
  Alg. 7), :func:`combined_score`, the :func:`verdict` on a match and the counted BEM
  :class:`Evaluator`;
* :mod:`.sensitivities` -- exact residual derivatives on the fixed contact sets;
* :mod:`.stages` -- one GCMMA stage (Sec. 4.3.1) through the one driver
  :func:`roughfe.optim.gcmma.gcmma`, its options and the phase box;
* :mod:`.algorithms` -- Alg. 3 (:func:`score_database`), SOG/GCO/CCO/M-CCO (Algs. 4-7),
  :func:`refine` (beyond the thesis) and :func:`run_design`;
* :mod:`.search` -- search stages on the score solved at the target pressures (beyond
  the thesis): :func:`search_at_target_pressures` ((1+1)-ES) and :func:`search_global`
  (IPOP-CMA-ES on batched BEM solves);
* :mod:`.spectrum` -- chromosome amplitudes matched to a target surface's spectrum
  (:func:`match_spectrum`, beyond the thesis, surfaces);
* :mod:`.crest` -- a surface design's highest peak lowered by its phases alone
  (:func:`crest_phases`, multisine crest-factor reduction, beyond the thesis);
* :mod:`.modulation` -- short waves modulated by the long-wave height
  (:func:`modulated_heights`, :attr:`Design.modulation`, beyond the thesis and the MWM
  model) and its measure :func:`crest_roughness`;
* :mod:`.targets` -- the thesis targets y_t1, y_t2, y_t3, targets of a (measured)
  surface in the designs' periodic setting, and independent re-scoring;
* :mod:`.io` -- the result files.

Every public name is importable from ``roughfe.genomics.design``.
"""
from ...optim.gcmma import GcmmaResult, gcmma_maximize, gcmma_minimax
from .algorithms import (METHODS, REFERENCES, Candidate, DesignResult, cco, gco, mcco, refine,
                         run_design, score_database, sog, with_solved_scores)
from .io import heights_name, result_to_dict, write_design_result
from .crest import clipped_phases, crest_phases, wave_modes
from .modulation import MODULATION_CUT, crest_roughness, modulated_heights, wave_split
from .model import (DESIGN_FORMAT, DESIGN_VERSION, GENE_VARIABLES, Design, DesignPart, combine,
                    entry_design)
from .objective import SELECTION, Evaluator, Objective, Verdict, combined_score, verdict
from .search import (AMPLITUDE_VARIABLES, GLOBAL_METHODS, GLOBAL_SCORES, GlobalSearchOptions,
                     search_at_target_pressures, search_global)
from .sensitivities import residual_jacobian
from .spectrum import long_wave_share, match_spectrum, spectrum_matched
from .stages import FORMULATIONS, GcmmaOptions, optimise_phases, phase_bounds
from .targets import (TARGET_BOUNDARIES, Y_T1_GENES, Y_T1_SURFACE_GENES, rescore,
                      rescore_at_target_pressures, score_at_target_pressures, SCORINGS,
                      score_batch, score_batch_at_target_pressures, score_batch_interpolated,
                      surface_targets,
                      target_genome_t1, target_surface, thesis_targets, window_compliance)

__all__ = ["METHODS", "REFERENCES", "Candidate", "DesignResult", "cco", "gco", "mcco", "refine",
           "run_design", "score_database", "search_at_target_pressures", "sog",
           "search_global", "GLOBAL_METHODS", "GlobalSearchOptions",
           "AMPLITUDE_VARIABLES", "score_batch_at_target_pressures", "GLOBAL_SCORES",
           "SCORINGS", "score_batch", "score_batch_interpolated",
           "long_wave_share", "match_spectrum", "spectrum_matched", "target_surface",
           "clipped_phases", "crest_phases", "wave_modes",
           "MODULATION_CUT", "crest_roughness", "modulated_heights", "wave_split",
           "heights_name", "result_to_dict", "write_design_result",
           "DESIGN_FORMAT", "DESIGN_VERSION", "GENE_VARIABLES", "Design", "DesignPart",
           "combine", "entry_design", "Evaluator", "Objective", "combined_score",
           "SELECTION", "Verdict", "verdict", "with_solved_scores",
           "residual_jacobian", "FORMULATIONS", "GcmmaOptions", "optimise_phases",
           "phase_bounds", "Y_T1_GENES", "Y_T1_SURFACE_GENES", "rescore",
           "rescore_at_target_pressures", "score_at_target_pressures", "surface_targets",
           "target_genome_t1", "thesis_targets", "TARGET_BOUNDARIES", "window_compliance", "GcmmaResult", "gcmma_maximize",
           "gcmma_minimax"]
