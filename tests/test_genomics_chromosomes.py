"""Reduced chromosome form (Eq. 3.7-3.10) and TD/BU reconstructions (Sec. 3.2.2)."""
import numpy as np

from roughfe.genomics.chromosomes import (reconstruction, reduced_chromosome_heights,
                                          validity_monte_carlo)
from roughfe.genomics.genome import (chromosome_heights, node_coordinates, random_genome, realize,
                                     table1_genome)


def test_reduced_form_equals_eq_3_2():
    g = table1_genome(rng=7)
    x = node_coordinates(1e-3, 512)
    n = np.arange(1, 17)
    full = chromosome_heights(g, x, n)
    red = reduced_chromosome_heights(g, x, n)
    np.testing.assert_allclose(red, full, rtol=0, atol=1e-12 * np.abs(full).max())


def test_eq_3_10_is_an_identity_and_arccos_phase_is_right_half_the_time():
    res = validity_monte_carlo(range(2, 21), 1000, rng=0)
    assert np.all(res.valid_fraction == 1.0)          # |g1| <= |R| always (thesis: 88.5-98 %)
    assert res.max_identity_error < 1e-12             # M + 2 g3 == g1^2 + g2^2
    assert np.all(np.abs(res.arccos_fraction - 0.5) < 0.07)   # arccos only right when g2 >= 0


def test_td_and_bu_end_at_the_complete_profile():
    g = table1_genome(rng=8)
    z = realize(g, scale="10x").heights
    td, bu = reconstruction(g, 1e-3, order="td"), reconstruction(g, 1e-3, order="bu")
    assert td.indices[0] == 1 and bu.indices[0] == 16 and len(td.indices) == 16
    tol = 1e-12 * np.abs(z).max()
    np.testing.assert_allclose(td.complete, z, atol=tol)
    np.testing.assert_allclose(bu.complete, z, atol=tol)
    np.testing.assert_allclose(td.partial_sums[0], td.chromosomes[0])   # TD step 1 is C_1
    # TD step k + BU step (n_c - k) = complete profile
    np.testing.assert_allclose(td.partial_sums[4] + bu.partial_sums[10], z, atol=tol)


def test_reduced_form_weights_the_ridges_by_their_anisotropy_factors():
    # K_n e^{i theta_n} = G sum_m alpha_m e^{i phi_mn}: the reduced cosine must equal the
    # sum of the weighted waves of Eq. (3.2) (unweighted it was off by 65 % of max |C_n|)
    g = random_genome(1, .75, 1.5, 1e-3, 2, 16, rng=0, anisotropy=[2.0, 0.5])
    x = node_coordinates(1e-3, 512)
    n = np.arange(1, 17)
    full = chromosome_heights(g, x, n)
    red = reduced_chromosome_heights(g, x, n)
    np.testing.assert_allclose(red, full, rtol=0, atol=1e-12 * np.abs(full).max())
