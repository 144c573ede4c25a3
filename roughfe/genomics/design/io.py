"""Result files of a design run (written atomically through :mod:`roughfe.writers`)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ...surfaces.io import save_surface
from ...writers import write_json, write_text
from ..database import DatabaseSettings
from ..genome import save_genome
from .algorithms import DesignResult
from .objective import combined_score, verdict


def heights_name(dim: int) -> str:
    """The stem of a design's heights file and figure: ``"profile"`` for a profile design
    (dim 1: ``profile.npz``, ``profile.png``), ``"surface"`` for a surface design (dim 2:
    ``surface.npz``, ``surface.png``; earlier versions named both ``profile.*``)."""
    return "surface" if int(dim) == 2 else "profile"


def result_to_dict(result: DesignResult, settings: DatabaseSettings) -> dict:
    """JSON-safe report of a design run: candidates, scores per stage, targets, settings,
    and the verdict on the best design's match (:func:`~.objective.verdict`, as the
    message states it): ``matched`` and ``matched_by`` (which scores decided it)."""
    v = verdict(result.best, result.objective.targets)
    by = ", ".join(f"{n} {sc!r}" for n, sc in zip(v.names, v.scores))
    return {
        "format": "roughfe-design-result", "version": 1, "method": result.method,
        "message": result.message, "success": result.success,
        "matched": v.matched, "matched_by": f"scores {v.source}: {by}",
        "nit_bem_sweeps": result.nit,
        "elapsed_s": result.elapsed, "pbar": result.pbar, "n_cross": result.n_cross,
        "n_cross_above_0.95": result.n_cross_above,
        "selection_passed": result.selection_passed,
        "targets": [t.to_dict() for t in result.objective.targets],
        "settings": settings.to_dict(), "database_scores": result.database_scores,
        "candidates": [{"origin": c.origin, "stages": list(c.stages), "scores": list(c.scores),
                        "score": combined_score(c.scores),
                        "scores_at_target_pressures": list(c.at_targets),
                        "rescore_error": c.rescore_error,
                        "macro": [list(m) for m in c.macro],
                        "micro": [list(m) for m in c.micro], "curve": c.curve.to_dict(),
                        "design": c.design.to_dict()} for c in result.candidates],
        "references": list(result.references)}


def write_design_result(result: DesignResult, settings: DatabaseSettings, outdir) -> dict:
    """Write the best design and the report to ``outdir`` (atomically).

    Files: ``result.json`` (:func:`result_to_dict`), ``design.json`` (the best design,
    reloadable with :meth:`Design.from_dict`), ``genome.json`` (the roughfe-genome when
    the design is one genome; for several, ``genome_partK.json``: part K as a genome with
    its weight and the overall scale in A), ``profile.npz`` (native surface file of the
    designed profile; ``surface.npz`` for a surface design, :func:`heights_name`),
    ``curves.csv`` (p, targets, K, A; the K column says how K was taken,
    ``K_fd_Pa_per_m`` (differences over the sweep's steps) or ``K_exact_Pa_per_m`` (the
    tangent at a fixed contact set), as ``settings.stiffness``) and ``stages.csv`` (similarity per candidate and
    GCMMA stage). The returned paths are keyed by file stem (``"profile"`` or
    ``"surface"`` for the heights).
    """
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
    kind = heights_name(best.design.dim)
    paths[kind] = save_surface(best.design.surface(), out / f"{kind}.npz")
    c = best.curve
    cols = ["pressure_Pa", f"K_{settings.stiffness}_Pa_per_m", "A"]
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

