"""Reproducibility of a sequenced surface genome (round 2, session 35): the lattice and the
ridges of the two halves of the data (roughfe.genomics.sequencing.surface_reproduce) must
agree, as a genome is a property of the surface."""
import json
import math

import numpy as np
import pytest

from roughfe.genomics.sequencing import sequence_surfaces
from roughfe.genomics.sequencing.reproduce import LATTICE_TOLERANCE
from roughfe.genomics.sequencing.surface_data import (resolvable_surface_genome,
                                                      surface_acquisitions)
from roughfe.genomics.sequencing.surface_reproduce import (ANGLE_TOLERANCE, angle_offset,
                                                           half_surface_acquisitions)


def _pair(seed, noise):
    g, acq, rng = resolvable_surface_genome(seed, length=1e-3, n_nodes=48)
    return g, [a.with_heights(a.heights + noise * a.heights.std() * rng.normal(size=a.shape))
               for a in acq]


def test_the_halves_are_disjoint_and_keep_their_acquisition():
    """Left and right halves share no node, leave out only the column x = 0, and keep the
    acquisition's coordinates and length (so its Eq. 3.5 band); angles compare mod pi."""
    _, acq = _pair(0, 0.0)
    acqs = surface_acquisitions(acq)
    left, right = (half_surface_acquisitions(acqs, s) for s in ("left", "right"))
    for whole, a, b in zip(acqs, left, right):
        assert not np.any(a.valid & b.valid)
        assert np.all(a.x[np.any(a.valid, axis=1)] < 0) and np.all(b.x[np.any(b.valid, axis=1)] > 0)
        assert a.valid.sum() + b.valid.sum() == whole.valid.sum() - whole.z.shape[1]
        assert a.length == whole.length and np.array_equal(a.x, whole.x)
    assert angle_offset([0.1, 1.0], [1.0 + math.pi, 0.1 - math.pi]) == pytest.approx(0, abs=1e-12)
    assert angle_offset([0.1], [0.1 + math.radians(2)]) == pytest.approx(math.radians(2))


@pytest.mark.parametrize("noise", [0.0, 0.01])
def test_a_surface_genome_is_reproduced_by_its_halves(noise):
    """3-ridge MWM pair (N = 48): exact, both halves give the whole's lattice, ridges and H
    to round-off; with 1 % noise (seeds 0-9 measured: lattices within 1.1e-3 steps,
    ridges within 0.027 deg, H within 0.012) it stays sequenced and says so."""
    g, acq = _pair(4, noise)
    r = sequence_surfaces(acq)
    rep = r.reproducibility
    assert r.success, r.message
    assert rep.tested and rep.reproducible
    assert "the lattice and ridges of the two halves agree" in r.message
    report = json.loads(json.dumps(r.report()))["reproducibility"]
    assert report["reproducible"] and len(report["halves"]) == 2
    if noise == 0:
        assert rep.lattice_offset < 1e-12 and rep.angle_difference < 1e-12
        assert all(h.H == pytest.approx(g.H, abs=1e-10) for h in rep.halves)
    else:
        assert rep.lattice_offset < 0.01 * LATTICE_TOLERANCE
        assert rep.angle_difference < 0.05 * ANGLE_TOLERANCE


def test_a_whole_with_a_ridge_the_data_do_not_hold_is_not_reproduced():
    """3 % noise, seed 3: the whole came back with 4 ridges for 3 (A 65 % low) within the
    tolerance and said success; its halves, fitted from its lattice and angles, put their
    ridges 1.9 deg apart (at most 1.5) and H at 0.80 / 0.00: not a genome."""
    _, acq = _pair(3, 0.03)
    r = sequence_surfaces(acq)
    rep = r.reproducibility
    assert r.genome.M == 4
    assert not r.success and rep.tested and not rep.reproducible
    assert r.message.startswith("not a genome: the genes are not reproducible (gamma "), r.message
    assert rep.angle_difference > ANGLE_TOLERANCE
