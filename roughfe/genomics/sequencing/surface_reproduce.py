"""Is a sequenced surface genome reproducible? The genes of the two halves of its data:
the 2D counterpart of :mod:`.reproduce` (round 2, session 35).

As for profiles, a genome is a property of the surface, so a second sample of it must
give its genes again. Every acquisition is cut at x = 0 into the nodes with x < 0 and
those with x > 0 (the column x = 0 in neither; the other half left out as undefined
nodes are): two disjoint samples. Each is fitted as the whole's last step was, from the
whole's lattice and ridge angles (:func:`~.surface_fit.fit_model`, direct, over the
whole's band of chromosomes; the final solve damped, :meth:`~.surface_grid.GridModel.
solve`, on the nonlinear fit's nodes: every node up to ~16384 in all, else its tensor
sub-grid, as the held-out fits), and its genes read by
:func:`~.surface_result.genes_from_fit`. A half models
what its whole models (the acquisition's length and nodes: the Eq. 3.5 ranges).

The genes are reproducible when both hold:

* the lattices agree (:data:`~.reproduce.LATTICE_TOLERANCE`, :func:`~.reproduce.
  lattice_offset`: every line of the coarser half's lattice within a quarter of a step
  of the finer one's), the profile test's rule;
* the ridges agree: every ridge angle of one half lies within :data:`ANGLE_TOLERANCE`
  (mod pi) of a ridge of the other, the angular resolution at which the sequencer
  takes two directions for one ridge (:data:`~.surface_data.ANGLE_TOL`, 1.5 deg). On a
  surface the angles are genes the heights identify directly (a profile has none).

H is reported, not judged: the profile test's tolerance is 3 standard errors of
:func:`~.genes.amplitude_gene_errors`, whose model (each chromosome amplitude a random
sum of M phasors) is the profile's; on a surface every wave is seen and an MWM genome's
H is exact, its error only that of the noise, which the surface sequencer does not
state. Measured (round 2, session 35) before the rule was wired: 3-ridge pairs of
``resolvable_surface_genome`` (N = 48, seeds 0-4): exact, halves = whole (H to 1e-10);
1 % noise, gamma within 1.1e-4, angles within 0.02 deg, H within 0.017 of each other.
The measured crops whose fits reach the genes (they fail earlier: "not a WM surface" or
their misfit), fitted for information: di-1 128^2 halves at ridges 57.7 / 91.8 and
44.3 / 90.4 deg, H -0.25 and -0.58; plu-1 128^2 H 0.67 and 10.1.
"""
from __future__ import annotations

import math

import numpy as np

from ...errors import InputError
from .reproduce import (LATTICE_TOLERANCE, SIDES, HalfGenes, Reproducibility, lattice_offset,
                        unfitted_halves)
from .surface_data import ANGLE_TOL, SurfaceAcquisition
from .surface_fit import fit_model
from .surface_grid import GridModel
from .surface_result import genes_from_fit, plane_free_misfits

#: the largest angle (rad) between a ridge of one half and the nearest ridge of the other
ANGLE_TOLERANCE = ANGLE_TOL


def half_surface_acquisitions(acqs, side) -> list:
    """The acquisitions with only their nodes left (x < 0) or right (x > 0) of the centre
    defined, the others undefined (NaN)."""
    if side not in SIDES:
        raise InputError(f"side must be one of {SIDES}, got {side!r}")
    out = []
    for a in acqs:
        tol = 1e-6 * a.length / (a.z.shape[0] - 1)
        keep = a.x < -tol if side == "left" else a.x > tol
        out.append(SurfaceAcquisition(a.x, a.y, np.where(keep[:, None], a.z, np.nan),
                                      a.length))
    return out


def _half_genes(acqs, n_nodes, side, p, band, axis_nodes):
    """(HalfGenes, angles) of one half fitted from the whole's ``p`` over ``band``."""
    part = half_surface_acquisitions(acqs, side)
    model = GridModel(part, n_nodes, axis_nodes=axis_nodes)
    try:
        q, ranges, _ = fit_model(model, np.asarray(p, float), continuation=False, band=band)
        sol = model.solve(q, ranges, exact=True, regularise=True)
        g = genes_from_fit(q, sol, ranges)
    except (np.linalg.LinAlgError, ValueError, InputError) as exc:
        return HalfGenes(side, message=str(exc) or type(exc).__name__), np.array([])
    misfit = float(np.max(plane_free_misfits(model, sol["resid"])[0]))
    return (HalfGenes(side, g["gamma"], g["lambda1"], g["H"], math.nan, g["A"],
                      misfit=misfit, band=(int(sol["nn"].min()), int(sol["nn"].max()))),
            np.asarray(g["angles"], float))


def angle_offset(a, b) -> float:
    """The largest angle (rad, mod pi) from a ridge of either set to the nearest of the
    other (0: the same directions; inf when one set is empty)."""
    if not (len(a) and len(b)):
        return math.inf
    d = np.abs(np.angle(np.exp(2j * (np.subtract.outer(a, b))))) / 2
    return float(max(d.min(axis=1).max(), d.min(axis=0).max()))


def surface_reproducibility(acqs, n_nodes, p, ranges, axis_nodes=None) -> Reproducibility:
    """Fit the two halves of ``acqs`` (checked :class:`~.surface_data.SurfaceAcquisition`,
    coarsest first, ``n_nodes`` per axis) from the whole's ``p`` = (ln q1, ln gamma,
    angles) over the band of its ``ranges``, and compare their lattices and ridges
    (module notes); ``axis_nodes``: the nonlinear fit's sub-grid, as the whole's."""
    band = (min(r[0] for r in ranges), max(r[1] for r in ranges))
    fits = [_half_genes(acqs, n_nodes, s, p, band, axis_nodes) for s in SIDES]
    halves = tuple(f[0] for f in fits)
    failed = unfitted_halves(halves, "fitted")
    if failed is not None:
        return failed
    a, b = halves
    offset = lattice_offset(a, b)
    turn = angle_offset(fits[0][1], fits[1][1])
    ok = offset <= LATTICE_TOLERANCE and turn <= ANGLE_TOLERANCE
    reason = "" if ok else (
        f"the genes are not reproducible (gamma {a.gamma:.4g} vs {b.gamma:.4g}, ridges at "
        + " / ".join(f"{np.degrees(t):.1f}" for t in fits[0][1]) + " vs "
        + " / ".join(f"{np.degrees(t):.1f}" for t in fits[1][1])
        + f" deg from the left and right halves of the acquisitions; lattices {offset:.2f} "
        f"steps apart (at most {LATTICE_TOLERANCE:g}), ridges {np.degrees(turn):.2f} deg "
        f"apart (at most {np.degrees(ANGLE_TOLERANCE):g} deg))")
    return Reproducibility(True, ok, halves, offset, abs(a.H - b.H), math.nan,
                           angle_difference=turn, reason=reason)
