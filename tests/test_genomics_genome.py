"""Genome, Eq. 3.1-3.5: index ranges of Table 1, Z(0) = 0, chromosome sum, JSON round trip."""
import numpy as np
import pytest

from roughfe.errors import FileFormatError, InputError
from roughfe.genomics.genome import (Genome, chromosome_heights, chromosome_range, load_genome,
                                     node_coordinates, observation_coordinates, profile_heights,
                                     random_genome, realize, save_genome, table1_genome)
from roughfe.genomics.periodic import realization


def test_table1_index_ranges_from_eq_3_5():
    # Table 1: lambda1 = L_10x = 1 mm, gamma = 1.5, N = 512.
    assert chromosome_range(1.5, 1e-3, 1e-3, 512) == (1, 16)
    assert chromosome_range(1.5, 1e-3, 5e-4, 512) == (2, 18)
    assert chromosome_range(1.5, 1e-3, 1e-4, 512) == (6, 22)
    g = table1_genome(rng=3)
    assert [g.chromosome_range(g.length_of(s)) for s in ("10x", "20x", "100x")] == \
        [(1, 16), (2, 18), (6, 22)]


def test_the_eq_3_5_count_is_not_eq_3_4s_n_c():
    """As chromosome_range's notes say: Eq. 3.4's n_c = floor(log_gamma(N - 1)) is 15 for
    Table 1, Eq. 3.5 holds 16 / 17 / 17 chromosomes at 10x / 20x / 100x (floor + 1 or + 2),
    so n_c is not "the same at any realization"."""
    import math
    assert math.floor(math.log(511) / math.log(1.5)) == 15
    counts = [n_f - n_s + 1 for n_s, n_f in (chromosome_range(1.5, 1e-3, L, 512)
                                            for L in (1e-3, 5e-4, 1e-4))]
    assert counts == [16, 17, 17]


def test_realisation_is_sum_of_chromosomes_and_vanishes_at_origin():
    g = table1_genome(rng=1)
    s = realize(g, scale="20x")
    x = node_coordinates(5e-4, 512)
    assert s.shape == (512,)
    assert np.isclose(s.spacing[0], 5e-4 / 511, rtol=1e-14, atol=0)     # delta = L/(N-1)
    assert np.isclose(s.size[0], 512 * 5e-4 / 511, rtol=1e-14, atol=0)  # Surface cell convention
    # Z(0) = 0: the node sits exactly at x = 0, and its height is zero to the round-off
    # of the sums (0.0 with the reference BLAS, 3.3e-19 = 2e-16 of max |Z| with OpenBLAS)
    assert x[256] == 0.0 and abs(s.heights[256]) <= 1e-13 * np.abs(s.heights).max()
    chrom = chromosome_heights(g, x, np.arange(2, 19))            # Eq. 3.2
    np.testing.assert_allclose(chrom.sum(axis=0), s.heights, atol=1e-15 * np.abs(chrom).max() * 50)
    # Eq. 3.1 written out directly for chromosome n = 5, ridge by ridge
    n = 5
    G = 1.0 * np.sqrt(np.log(1.5) / 8) * (2 * np.pi / 1e-3) ** -0.75
    q = 2 * np.pi / 1e-3 * 1.5 ** (n - 1)
    phi = g.phases[:, n - 1]
    direct = G * 1.5 ** ((1 - n) * 0.75) * (np.cos(phi)[:, None] - np.cos(q * x + phi[:, None])).sum(0)
    np.testing.assert_allclose(chrom[n - 2], direct, rtol=0, atol=1e-12 * np.abs(direct).max())


def test_nested_realisations_share_nodes():
    g = table1_genome(rng=2)
    z10, z20 = realize(g, scale="10x"), realize(g, scale="20x")
    x10, x20 = node_coordinates(1e-3, 512), node_coordinates(5e-4, 512)
    d = 5e-4 / 511
    common = np.isin(np.round(x10 / d).astype(int), np.round(x20 / d).astype(int))
    np.testing.assert_allclose(x10[common], x20[np.isin(np.round(x20 / d), np.round(x10 / d))], rtol=1e-12)
    assert common.sum() == 256
    assert z10.metadata["n_s"] == 1 and z20.metadata["n_f"] == 18


def test_json_round_trip_and_errors(tmp_path):
    g = table1_genome(rng=4)
    path = save_genome(g, tmp_path / "g.json")
    back = load_genome(path)
    assert (back.A, back.H, back.gamma, back.lambda1, back.M) == (g.A, g.H, g.gamma, g.lambda1, 8)
    np.testing.assert_array_equal(back.phases, g.phases)
    with pytest.raises(InputError, match="gamma"):
        Genome(A=1, H=0.7, gamma=1.0, lambda1=1e-3, phases=np.zeros((2, 3)))
    with pytest.raises(InputError, match="H"):
        Genome(A=1, H=-0.1, gamma=1.5, lambda1=1e-3, phases=np.zeros((2, 3)))
    # a band-limited genome (issue 15): a window that shows chromosomes beyond the phase
    # matrix (n = 1..22) sums those it holds and invents none; a window that shows none
    # of them is an error
    fine = realize(g, length=1e-5)
    assert fine.metadata["chromosomes"][-1] == 22 < fine.metadata["n_f"]
    np.testing.assert_allclose(
        fine.heights, profile_heights(g, observation_coordinates(fine),
                                      np.arange(fine.metadata["n_s"], 23)))
    with pytest.raises(InputError, match="holds only"):
        realize(g, length=1e-9)
    bad = g.to_dict() | {"version": 99}
    with pytest.raises(FileFormatError, match="version"):
        Genome.from_dict(bad)


@pytest.mark.parametrize("kwargs, words", [
    ({"n_max": 2.5}, ["n_max", "integer", "2.5"]),     # used to be truncated to 2
    ({"n_max": 0}, ["n_max", ">= 1", "0"]),
    ({"rng": -1}, ["rng", "-1"]),
    ({"rng": "seed"}, ["rng", "'seed'"]),
])
def test_random_genome_refuses_what_it_would_truncate(kwargs, words):
    with pytest.raises(InputError) as info:
        table1_genome(**{"rng": 0, **kwargs})
    for w in words:
        assert w in str(info.value)
    # the same seed still gives the same phases (the seed is kept in the metadata)
    a, b = table1_genome(rng=7), table1_genome(rng=7)
    np.testing.assert_array_equal(a.phases, b.phases)
    assert a.metadata["seed"] == 7


def test_surface_realisation_with_ridges_along_x_repeats_the_profile():
    from roughfe.genomics.genome import Genome, realize_surface
    g = table1_genome(rng=5)
    g2 = Genome(A=g.A, H=g.H, gamma=g.gamma, lambda1=g.lambda1, phases=g.phases, angles=np.zeros(8))
    surf = realize_surface(g2, 1e-3, 64)
    prof = realize(g2, length=1e-3, n_nodes=64).heights
    np.testing.assert_allclose(surf.heights, np.repeat(prof[:, None], 64, axis=1),
                               atol=1e-12 * np.abs(prof).max())


@pytest.mark.parametrize("chromosomes, words", [
    ([1.5], ["chromosomes[0]", "integer", "1.5"]),      # used to be truncated to chromosome 1
    ([2, 3.0], ["chromosomes[1]", "3.0"]),
    ([0, 2], ["chromosomes[0]", ">= 1", "0"]),
    ([], ["at least one"]),
])
def test_realize_refuses_chromosome_indices_it_would_truncate(chromosomes, words):
    g = table1_genome(rng=0)
    with pytest.raises(InputError) as info:
        realize(g, scale="10x", n_nodes=64, chromosomes=chromosomes)
    for w in words:
        assert w in str(info.value)
    # the periodic surface realisation checks them the same way
    g2 = random_genome(1, .75, 1.5, 1e-3, 4, 22, rng=0, angles=[0, .5, 1, 2])
    with pytest.raises(InputError) as info:
        realization(g2, 1e-3, 64, dim=2, chromosomes=chromosomes)
    for w in words:
        assert w in str(info.value)
    # integer indices (Python or numpy) still select exactly those chromosomes
    s = realize(g, scale="10x", n_nodes=64, chromosomes=np.array([3, 1]))
    assert s.metadata["chromosomes"] == [1, 3]
    assert realization(g2, 1e-3, 64, dim=2, chromosomes=[3, 1]).metadata["chromosomes"] == [1, 3]
