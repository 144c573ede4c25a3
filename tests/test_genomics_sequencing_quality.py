"""The quality check of profile sequencing (round 2, session 32): misfits against the data
as given, and nodes held out of the fit (roughfe.genomics.sequencing.holdout) to tell a
genome from an overfit."""
import dataclasses
import math
import re

import numpy as np
import pytest

from roughfe.genomics.genome import realize, table1_genome
from roughfe.genomics.sequencing import sequence_profiles
from roughfe.genomics.sequencing.acquisitions import acquisitions_from_surfaces
from roughfe.genomics.sequencing.holdout import (HOLD_OUT_FOLDS, held_out_errors,
                                                 position_folds)
from roughfe.genomics.sequencing.lattice import (design_matrix, lattice_ranges, solve_linear,
                                                 solve_model, tilt_bound)


def _stacked(acqs):
    weights = [1.0 / math.sqrt(float(np.mean(a.z ** 2))) for a in acqs]
    return weights, np.concatenate([a.z * w for a, w in zip(acqs, weights)])


def test_nodes_at_one_position_share_a_fold():
    """The windows of one row share samples: a twin left in the fit would pin the
    held-out height, so every node at one x is held out with it."""
    g = table1_genome(rng=0)
    acqs = acquisitions_from_surfaces([realize(g, scale=s, n_nodes=64)
                                       for s in ("10x", "20x", "100x")])
    fold = position_folds(acqs)
    x = np.concatenate([a.x for a in acqs])
    step = acqs[-1].length / 63
    for i in np.flatnonzero(np.isclose(x[:64, None], x[None, 64:], rtol=0,
                                       atol=1e-9 * step).any(1)):
        twins = np.isclose(x, x[i], rtol=0, atol=1e-9 * step)
        assert twins.sum() >= 2 and np.all(fold[twins] == fold[i])
    assert set(fold.tolist()) == set(range(HOLD_OUT_FOLDS))
    np.testing.assert_array_equal(position_folds(acqs), fold)        # seeded: no drift


def test_held_out_nodes_tell_a_genome_from_an_overfit():
    """A genome's lattice predicts nodes it was not fitted to (exact data: to round-off);
    a lattice of more unknowns than distinct nodes reproduces white noise exactly and
    misses every held-out node by the heights themselves."""
    g = table1_genome(rng=0)
    acqs = acquisitions_from_surfaces([realize(g, scale=s, n_nodes=64) for s in ("10x", "20x")])
    weights, rhs = _stacked(acqs)
    lq1, lg = math.log(2 * math.pi / g.lambda1), math.log(g.gamma)
    ranges = lattice_ranges(lq1, lg, acqs)
    assert np.all(held_out_errors(lq1, lg, acqs, ranges, weights, rhs) < 1e-12)
    rng = np.random.default_rng(0)
    noise = acquisitions_from_surfaces([a.with_heights(rng.standard_normal(64) * 1e-6)
                                        for a in (realize(g, scale=s, n_nodes=64)
                                                  for s in ("10x", "20x"))])
    weights, rhs = _stacked(noise)
    lg = math.log(1.05)                                   # ~85 chromosomes: 170 unknowns
    ranges = lattice_ranges(lq1, lg, noise)
    _, mat = design_matrix(lq1, lg, noise, ranges, weights)
    assert mat.shape[1] > 96                              # 64 + 32 distinct positions
    fit = rhs - mat @ solve_linear(mat, rhs)
    assert math.sqrt(float(np.mean(fit ** 2))) < 1e-6     # reproduced ...
    assert np.all(held_out_errors(lq1, lg, noise, ranges, weights, rhs) > 0.5)  # ... not predicted


def test_a_noisy_genome_predicts_its_held_out_nodes_to_the_noise():
    """Table 1, N = 128, 1 % white noise: held-out errors about the misfit (measured
    1.05-1.25 times it over 6 seeds at 0.1-3 % noise), far below the tolerance."""
    g = table1_genome(rng=2)
    rng = np.random.default_rng(2)
    acq = [realize(g, scale=s, n_nodes=128) for s in ("10x", "20x")]
    noisy = [a.with_heights(a.heights + 1e-2 * a.heights.std() * rng.standard_normal(a.shape))
             for a in acq]
    res = sequence_profiles(noisy)
    assert res.success, res.message
    assert np.all(res.held_out_errors < 1.5 * res.rms_errors)
    assert np.all(res.held_out_errors > res.rms_errors)
    assert res.report()["held_out_errors"] == res.held_out_errors.tolist()


def _row(topographies_dir, name):
    from roughfe.genomics.natural import nested_acquisitions
    from roughfe.surfaces.io import load_surface
    acq = nested_acquisitions(load_surface(topographies_dir / name), n_nodes=128)
    return acq, sequence_profiles(acq, windows=True)


def _line_within_its_bound(acq, res, old_tilt):
    """The line shared by the windows of a measured row (round 2, session 33): it traded
    with the longest chromosomes (``old_tilt`` m/m before); now at most its bound, a rise
    of 13.1 times the largest height over half the row, and a fit that needs it there is
    no genome."""
    bound = tilt_bound(acquisitions_from_surfaces(acq, True))
    assert bound < 0.02 * abs(old_tilt)
    assert np.all(res.tilts == res.tilts[0]) and abs(res.tilts[0]) <= bound * (1 + 1e-12)
    assert ("the line shared by the windows is at its bound" in res.message) == \
        (abs(res.tilts[0]) >= bound * (1 - 1e-9))


def test_the_shared_tilt_is_the_least_squares_within_its_bound():
    """The windows of one row share the line the row lost. On a lattice of many long
    chromosomes (gamma 1.2, 1.1) a line is nearly in their span and the free fit of a
    white-noise row put it at 3e7 and 7e6 times its bound (tilt_bound), the chromosomes
    cancelling it. The fit keeps the free tilt where it is within the bound (gamma 1.5)
    and is otherwise the least misfit of every tilt allowed: the bound."""
    from roughfe.genomics.natural import nested_acquisitions
    from roughfe.surfaces.surface import Surface
    row = Surface(np.random.default_rng(0).standard_normal(256) * 1e-8, 1e-3, periodic=False)
    acqs = acquisitions_from_surfaces(nested_acquisitions(row, n_nodes=256), True)
    weights, rhs = _stacked(acqs)
    bound = tilt_bound(acqs)
    assert bound == pytest.approx(13.1 * max(np.abs(a.z - a.z.mean()).max() for a in acqs)
                                  / (acqs[0].length / 2), rel=1e-12, abs=0)
    lq1 = math.log(2 * math.pi / (1.2 * acqs[0].length))
    for gamma, free_within in ((1.5, True), (1.2, False), (1.1, False)):
        _, mat = design_matrix(lq1, math.log(gamma), acqs,
                               lattice_ranges(lq1, math.log(gamma), acqs), weights)
        free, fit = solve_linear(mat, rhs), solve_model(mat, rhs, acqs)
        assert bool(abs(free[-1]) <= bound) is free_within
        cost = float(np.sum((rhs - mat @ fit) ** 2))
        if free_within:
            np.testing.assert_allclose(fit, free, rtol=1e-9, atol=1e-9 * np.abs(free).max())
            continue
        assert abs(free[-1]) > 1e6 * bound and fit[-1] == pytest.approx(np.sign(free[-1]) * bound, rel=1e-12, abs=0)
        # every allowed tilt, the other unknowns refitted: none fits better (the misfit
        # of these near-singular fits, cond ~1e16, is reproducible to ~1e-7 only)
        for t in np.linspace(-bound, bound, 21):
            rest = solve_linear(mat[:, :-1], rhs - t * mat[:, -1])
            assert cost <= float(np.sum((rhs - mat @ np.append(rest, t)) ** 2)) * (1 + 1e-6)
    # acquisitions that are not windows of one row share no line: nothing is bounded
    assert tilt_bound([dataclasses.replace(a, window=False) for a in acqs]) == math.inf


def test_the_tilts_of_levelled_acquisitions_are_the_least_squares_within_their_bounds():
    """Separately levelled acquisitions (a profilometer's) each get a tilt; on a lattice of
    many long chromosomes the free ones traded against them (measured rows levelled per
    window: -6.1e5 m/m on di-1, -2.1e5 on opd-1, round 2, session 34). Each is now
    bounded as the shared one (the coarsest of its window: 13.1 times the largest height
    over half its own window), by the exact bounded least squares of the tilts: no tilts
    inside the box fit better (a 9 x 9 grid of it, the other unknowns refitted)."""
    from roughfe.surfaces.surface import Surface
    from roughfe.genomics.sequencing.lattice import tilt_bounds
    rng = np.random.default_rng(3)
    surfaces = []
    for length in (1e-3, 0.25e-3):
        x = (np.arange(128) - 64) * length / 127
        z = rng.standard_normal(128) * 1e-8
        z -= np.polyval(np.polyfit(x, z, 1), x)                          # levelled
        surfaces.append(Surface(z, length, periodic=False, metadata={"x0": float(x[0])}))
    acqs = acquisitions_from_surfaces(surfaces, False)
    assert all(a.levelled and not a.window for a in acqs)
    bounds = tilt_bounds(acqs)
    z_scale = max(np.abs(a.z - a.z.mean()).max() for a in acqs)
    np.testing.assert_allclose(bounds, [13.1 * z_scale / (a.length / 2) for a in acqs],
                               rtol=1e-12)
    weights, rhs = _stacked(acqs)
    lq1 = math.log(2 * math.pi / (1.2 * acqs[0].length))
    _, mat = design_matrix(lq1, math.log(1.1), acqs,
                           lattice_ranges(lq1, math.log(1.1), acqs), weights)
    free, fit = solve_linear(mat, rhs), solve_model(mat, rhs, acqs)
    assert np.any(np.abs(free[-2:]) > 1e3 * bounds)
    assert np.all(np.abs(fit[-2:]) <= bounds * (1 + 1e-12))
    cost = float(np.sum((rhs - mat @ fit) ** 2))
    for t in np.array(np.meshgrid(*[np.linspace(-b, b, 9) for b in bounds])).reshape(2, -1).T:
        rest = solve_linear(mat[:, :-2], rhs - mat[:, -2:] @ t)
        assert cost <= float(np.sum((rhs - mat @ np.append(rest, t)) ** 2)) * (1 + 1e-6)
    # raw (unlevelled) acquisitions have no tilt unknown, so no bound
    assert tilt_bounds([dataclasses.replace(a, levelled=False) for a in acqs]).size == 0


def test_misfits_are_measured_against_the_data_as_given(topographies_dir):
    """plu-1's central row (--nodes 128) was "sequenced" with rms errors 1e-4..5e-4,
    H = 2.05: relative to its heights less the fitted tilt (0.18 m/m, traded against
    chromosomes of 2.2e-4 m; 6.5e-5 m rms on a row of 1.8e-8 m rms). Against the data
    the misfit is 0.37-0.39: the row is not WM-like. Its least-squares amplitudes were
    45 times its heights (the line at its bound); damped where the data cannot resolve
    them (round 2, session 34) they are 0.24 times, and the line is inside its bound."""
    acq, res = _row(topographies_dir, "plu-1.plu")
    _line_within_its_bound(acq, res, 0.105)
    for a, h, fit, off, tilt, e in zip(acq, res.heights, res.fitted, res.offsets, res.tilts,
                                       res.rms_errors):
        x = a.metadata["x0"] + np.arange(a.shape[0]) * a.spacing[0]
        np.testing.assert_allclose(h, a.heights - off - tilt * x, rtol=1e-12,
                                   atol=1e-12 * np.abs(h).max())
        assert e == pytest.approx(np.sqrt(np.mean((h - fit) ** 2) / np.mean(a.heights ** 2)),
                                  rel=1e-9)
    assert not res.success
    assert np.all(res.rms_errors > 0.3), res.rms_errors
    z_max = max(float(np.abs(a.heights - a.heights.mean()).max()) for a in acq)
    assert res.amplitudes.max() < 0.5 * z_max
    assert res.message.startswith("not WM-like: relative rms error"), res.message
    assert "waves that cancel" not in res.message


def test_di1_row_damped_predicts_its_held_out_nodes(topographies_dir):
    """di-1's central row (--nodes 128) fits within the tolerance with 84 chromosome
    unknowns on windows of 85-103 nodes. By least squares (1.6 %, 0.9 %, 0.8 %) the nodes
    held out of the fit were missed by 15 % on the coarsest window, with waves of 0.83 m
    that cancel on a row of 15 nm (the design's cond 4e16): an overfit. Damped where the
    data cannot resolve it (round 2, session 34) the fit misses its nodes by 2.1 %, 1.1 %,
    0.9 %, its held-out nodes by 3.7 % at most, and its largest amplitude is 1.3 times the
    heights: the row is sequenced."""
    acq, res = _row(topographies_dir, "di-1.di")
    _line_within_its_bound(acq, res, 4.8e5)
    assert res.success, res.message
    assert np.all(res.rms_errors < 0.025), res.rms_errors
    assert np.all(res.held_out_errors < 0.04), res.held_out_errors
    z_max = max(float(np.abs(a.heights - a.heights.mean()).max()) for a in acq)
    assert res.amplitudes.max() < 1.5 * z_max
    # the same lattice by least squares: the overfit of round 2, session 33
    acqs = acquisitions_from_surfaces(acq, True)
    weights, rhs = _stacked(acqs)
    lq1, lg = math.log(2 * math.pi / res.genome.lambda1), math.log(res.genome.gamma)
    least = held_out_errors(lq1, lg, acqs, res.ranges, weights, rhs, regularise=False)
    assert least[0] > 0.1 > 0.05 > res.held_out_errors[0]
