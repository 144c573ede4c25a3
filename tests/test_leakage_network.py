"""Free-volume network of Algorithm 1 (thesis Sec. 2.4.1, Fig. 10-13, Eq. 2.8, 2.15-2.16).

Hand-made gap patterns with known percolating (U_p) and trapped (U_np) cells, the
saddle-point rule of Fig. 13, identities (V_p + V_np = V, symmetry under transposition)
and agreement with the BEM free volume. Arrays are printed with axis 0 downwards: for
``direction="x"`` the inlet is the first row and the outlet the last row.
"""
import numpy as np
import pytest

from roughfe.errors import InputError
from roughfe.leakage import directional_network, free_volume_network

UM = 1e-6
SP = (1e-6, 1e-6)


def cells(text):
    """'#' open (gap 1 um), '.' contact."""
    return np.array([[c == "#" for c in row.split()[0]] for row in text.strip().splitlines()])


def test_saddle_point_connects_diagonal_cells_fig13a():
    # the two blocks touch only across the corner of the central element; equal gaps:
    # d_zc = (1 + 1)/4 = 0.5 um lies below both open corners -> saddle -> connection
    g = np.array([[1, 1, 0, 0],
                  [1, 1, 0, 0],
                  [0, 0, 1, 1],
                  [0, 0, 1, 1.]]) * UM
    r = free_volume_network(g, None, SP, directions=("x",))
    net = r.directions["x"]
    assert r.percolates("x") is True
    assert net.saddle.sum() == 1 and net.n_rejected_diagonals == 0
    assert np.array_equal(r.percolating, g > 0)
    assert not r.trapped.any()
    # D_h of the saddle channel: sqrt(2)/2 * d_zc (length; see the module docstring)
    assert net.hydraulic_diameter[net.saddle][0] == pytest.approx(np.sqrt(2) / 2 * 0.5 * UM,
                                                                  rel=1e-6, abs=0)


def test_no_saddle_no_connection_fig13b():
    # corner 4 of the element has a gap 4x the other open corner: d_zc = 1.25 um > 1 um,
    # the centre is not a saddle point -> the diagonal does not conduct; all is trapped
    g = np.array([[1, 1, 0, 0],
                  [1, 1, 0, 0],
                  [0, 0, 4, 4],
                  [0, 0, 1, 1.]]) * UM
    r = free_volume_network(g, None, SP, directions=("x",), sigma=UM)
    assert r.percolates("x") is False
    assert r.directions["x"].n_rejected_diagonals == 1
    assert not r.percolating.any()
    assert np.array_equal(r.trapped, g > 0)
    assert r.trapped_volume == pytest.approx(r.volume, rel=1e-6, abs=0)
    assert r.trapped_volume_star == pytest.approx(r.volume / (16 * SP[0] * SP[1] * UM))


def test_dead_ends_are_trapped_5x5():
    # inlet row 0, outlet row 4. The cell (1,4) hangs on the row-2 cross-section by one
    # channel only (a dead end, like connection 6-7 of Fig. 11): it is non-percolating;
    # the isolated cell (3,3) is trapped too. The side arm (2,2..4) belongs to the same
    # cross-section as the path and percolates (cross-section granularity of Alg. 1).
    o = cells("""
        ###..
        .#..#
        .####
        .#.#.
        ##...""")
    r = free_volume_network(o * UM, None, SP, directions=("x",))
    expected_p = cells("""
        ###..
        .#...
        .####
        .#...
        ##...""")
    assert r.percolates("x")
    assert np.array_equal(r.percolating, expected_p)
    assert np.array_equal(r.trapped, o & ~expected_p)
    assert r.directions["x"].n_backbone_sections == 5


def test_pockets_open_only_to_the_inlet_do_not_percolate():
    # a U-shaped pocket with both mouths on the inlet row (row 0) carries no through
    # flow: it is not on an open inlet-outlet path (the thesis' recursion would keep it,
    # because each of its cross-sections has two connections)
    o = cells("""
        #.#.#
        ###.#
        ....#
        ....#""")
    r = free_volume_network(o * UM, None, SP, directions=("x",))
    assert r.percolates("x")
    assert np.array_equal(r.percolating, cells("....#\n....#\n....#\n....#"))
    assert r.trapped.sum() == 5


def test_union_over_directions_and_blocked_direction():
    # a horizontal channel (row 1) percolates along y only; a closed vertical pocket
    o = cells("""
        ....
        ####
        ....
        .#..""")
    r = free_volume_network(o * UM, None, SP, directions=("x", "y"))
    assert r.percolates("x") is False and r.percolates("y") is True
    assert np.array_equal(r.percolating, r.directions["y"].percolating)
    assert np.array_equal(r.percolating, cells("....\n####\n....\n...."))
    assert r.trapped.sum() == 1
    rx = free_volume_network(o * UM, None, SP, directions=("x",))
    assert not rx.percolating.any() and rx.trapped.sum() == 5


def test_periodic_side_walls_join_wrapping_sections():
    # flow along x; the path steps from column 0 to column 3 across the periodic edge
    o = cells("""
        #...
        #...
        ...#
        ...#""")
    g = o * UM
    assert free_volume_network(g, None, SP, directions=("x",)).percolates("x") is False
    rp = free_volume_network(g, None, SP, directions=("x",), periodic=True)
    # across the edge the cells (1,0) and (2,3) touch only at a corner: saddle (equal gaps)
    assert rp.percolates("x") is True
    assert np.array_equal(rp.percolating, o)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_volume_identities_and_transpose_symmetry(seed):
    rng = np.random.default_rng(seed)
    g = np.maximum(rng.standard_normal((24, 17)), 0) * UM      # ~50 % contact
    r = free_volume_network(g, None, SP, directions="xy", sigma=UM)
    # Eq. 2.15 + 2.16: the two domains partition U
    assert r.percolating_volume + r.trapped_volume == pytest.approx(r.volume, rel=1e-13, abs=0)
    assert not (r.percolating & r.trapped).any()
    assert np.array_equal(r.percolating | r.trapped, g > 0)
    assert r.volume == pytest.approx(g.sum() * SP[0] * SP[1], rel=1e-13, abs=0)   # Eq. 2.8
    # flow along y of g is flow along x of g.T
    nx = directional_network(g.T > 0, g.T, SP, "x")
    ny = directional_network(g > 0, g, SP, "y")
    assert nx.percolates == ny.percolates
    assert np.array_equal(nx.percolating.T, ny.percolating)


def test_limits_fully_open_and_fully_closed():
    g = np.full((6, 5), 2 * UM)
    r = free_volume_network(g, None, SP)
    assert r.percolates("x") and r.percolates("y") and r.percolating.all()
    assert r.trapped_volume == 0.0
    z = free_volume_network(np.zeros((6, 5)), None, SP, sigma=UM)
    assert z.volume == 0.0 and z.percolates("x") is False and z.free_volume_star == 0.0


def test_q1_corner_conduction_vs_saddle_rule():
    # Fig. 13b pattern: the network says "no" but Q1 corner conduction connects the
    # blocks through the shared vertex (the disagreement reported by leak studies)
    from roughfe.fem.reynolds import vertex_components
    g = np.array([[1, 1, 0, 0],
                  [1, 1, 0, 0],
                  [0, 0, 4, 4],
                  [0, 0, 1, 1.]]) * UM
    lab = vertex_components(g > 0)
    assert np.intersect1d(lab[0], lab[-1]).size > 0
    assert free_volume_network(g, None, SP, directions=("x",)).percolates("x") is False


def test_free_volume_matches_bem_contact():
    from roughfe.bem import Material, solve_contact
    from roughfe.leakage import leakage_of_contact
    from roughfe.surfaces.rmd import rmd_surface
    s = rmd_surface(4, 2.3, 1e-4, rng=3)
    c = solve_contact(s, Material(1e9, 0.3), delta=0.5 * np.ptp(s.heights))
    r = leakage_of_contact(c, reynolds=False)
    assert r.network.volume == pytest.approx(c.free_volume, rel=1e-12, abs=0)
    assert r.network.free_volume_star == pytest.approx(c.free_volume_star, rel=1e-12, abs=0)
    assert not r.network.open[c.contact].any()


def test_bad_input_is_named():
    with pytest.raises(InputError, match="direction"):
        free_volume_network(np.ones((3, 3)), None, SP, directions=("z",))
    with pytest.raises(InputError, match="gap"):
        free_volume_network(-np.ones((3, 3)), None, SP)
    with pytest.raises(InputError, match="contact mask"):
        free_volume_network(np.ones((3, 3)), np.zeros((2, 3), bool), SP)
    with pytest.raises(InputError, match=r"spacing must be the cell size \(dx, dy\)"):
        free_volume_network(np.ones((3, 3)), None, 1e-6)          # was a TypeError
    for name in ("gap_tol", "min_hydraulic_diameter"):                # were accepted
        with pytest.raises(InputError, match=name):
            free_volume_network(np.ones((3, 3)), None, SP, **{name: -1e-9})


@pytest.mark.parametrize("periodic", [False, True])
def test_trapped_volume_splits_into_sealed_pockets_and_open_dead_ends(periodic):
    """The thesis' trapped domain U_np is everything off the inlet-outlet backbone: it
    holds open dead ends beside the flow as well as pockets sealed by contact (a user's
    review found 39-72 % of V_np in dead ends, drawn red as "trapped"). ``sealed`` is the
    part that no face-connected open path joins to inlet or outlet: here the pocket, not
    the dead end, whatever the side walls."""
    g = np.zeros((10, 9))
    g[:, 1] = 1 * UM                 # a straight channel from inlet (row 0) to outlet
    g[5, 2:5] = 2 * UM               # a side arm (in the channel's cross-section) ...
    g[6:8, 4] = 2 * UM               # ... and a blind branch off it, along the flow
    g[2:4, 6:8] = 3 * UM             # a pocket ringed by contact
    r = free_volume_network(g, None, SP, directions=("x",), periodic=periodic,
                            sigma=1 * UM, corner_rule="closed")
    dead, pocket = np.zeros(g.shape, bool), np.zeros(g.shape, bool)
    dead[6:8, 4], pocket[2:4, 6:8] = True, True
    assert np.array_equal(r.trapped, dead | pocket)
    assert np.array_equal(r.sealed, pocket)
    cell = SP[0] * SP[1]
    assert r.trapped_volume == pytest.approx((2 * 2 + 4 * 3) * UM * cell, rel=1e-12, abs=0)
    assert r.sealed_volume == pytest.approx(4 * 3 * UM * cell, rel=1e-12, abs=0)
    assert r.sealed_volume_star == pytest.approx(r.sealed_volume / (90 * cell * UM),
                                                 rel=1e-12, abs=0)
    # a pocket that reaches the outlet row is open to the flow there: not sealed
    g[2:10, 7] = 3 * UM
    assert not free_volume_network(g, None, SP, directions=("x",), periodic=periodic,
                                   corner_rule="closed").sealed[2:4, 6:8].any()
