"""The critical constriction (thesis Ch. 5): bottleneck gap, junction, width, parent channel.

Checked against brute force (every threshold), against its defining property (the
junction is a cut cell of {gap >= u_c}), on hand-built channels with known sizes, and
against the Reynolds solve: the leak rate of a field dominated by one narrow channel is
the junction formula's.
"""
import numpy as np
import pytest

from roughfe.errors import InputError
from roughfe.leakage import analyse_leakage, critical_constriction, reynolds_flow
from roughfe.leakage.finite_volume import components_reaching

UM = 1e-6


def _perc(open_cells, periodic=False):
    _, a, b = components_reaching(open_cells, periodic=periodic)
    return bool((a & b).any())


@pytest.mark.parametrize("periodic", [False, True])
def test_critical_gap_is_the_brute_force_bottleneck(periodic):
    rng = np.random.default_rng(5)
    n_perc = 0
    for _ in range(25):
        g = np.maximum(rng.standard_normal((10, 8)) + 0.3, 0.0) * UM
        for d, gf in (("x", g), ("y", g.T)):
            c = critical_constriction(g, (UM, UM), direction=d, periodic=periodic)
            vals = np.unique(gf[gf > 0])
            ok = [u for u in vals if _perc(gf >= u, periodic)]
            assert c.percolates is bool(ok)
            if not ok:
                continue
            n_perc += 1
            assert c.critical_gap == max(ok)
            # the junction is a cut cell: without it {gap >= u_c} no longer percolates
            i, j = c.junction
            assert g[i, j] == c.critical_gap
            cut = g.copy()
            cut[i, j] = 0.0
            cf = cut if d == "x" else cut.T
            assert not _perc(cf >= c.critical_gap, periodic)
            # the path is face-connected, inlet to outlet, its minimum gap is u_c
            p = c.path
            axis = 0 if d == "x" else 1
            assert p[0, axis] == 0 and p[-1, axis] == g.shape[axis] - 1
            steps = np.abs(np.diff(p, axis=0))
            if periodic:
                steps[:, 1 - axis] = np.minimum(steps[:, 1 - axis],
                                                g.shape[1 - axis] - steps[:, 1 - axis])
            assert np.all(steps.sum(axis=1) == 1)
            assert g[p[:, 0], p[:, 1]].min() == c.critical_gap
    assert n_perc > 15


def test_channel_sizes_and_junction_leak_rate():
    # wide open inlet and outlet reservoirs (gap 10 um) joined by one straight channel
    # 3 cells wide, 6 cells long, gap 1 um, with a 0.6 um throat in its middle
    nx, ny = 20, 15
    g = np.zeros((nx, ny))
    g[:7], g[13:] = 10 * UM, 10 * UM
    g[7:13, 6:9] = 1 * UM
    g[10, 6:9] = 0.6 * UM
    c = critical_constriction(g, (UM, 2 * UM))
    assert c.critical_gap == 0.6 * UM and c.junction[0] == 10
    assert c.width == pytest.approx(3 * 2 * UM)                 # 3 cells of dy = 2 um
    assert c.parent_channel_length == pytest.approx(6 * UM)     # 6 cells of dx = 1 um
    assert c.position[0] == pytest.approx(10 * UM)   # cell centres from 0 (was 10.5 um)
    # the same point as Surface.coordinates() gives that cell
    from roughfe.surfaces import Surface
    x, y = Surface(g, (nx * UM, ny * 2 * UM), periodic=False).coordinates()
    assert c.position == pytest.approx((x[c.junction[0]], y[c.junction[1]]))
    # the same in y (transposed field)
    cy = critical_constriction(g.T, (2 * UM, UM), direction="y")
    assert cy.junction == c.junction[::-1] and cy.width == pytest.approx(c.width)
    assert cy.parent_channel_length == pytest.approx(c.parent_channel_length)
    # the channel carries all the flow; its resistance is the throat row plus five 1 um
    # rows (strips in series, 3 cells wide): Reynolds equals that up to the spreading
    # resistance of the reservoirs (< 1 %), and the junction formula with the channel's
    # own aspect (width/length) bounds it from above (it ignores the 1 um rows)
    q = reynolds_flow(g, (UM, 2 * UM), mu=1e-3, pressure_drop=1e3).leak_rate
    w = 3 * 2 * UM
    q_series = w * 1e3 / (12e-3) / (UM / (0.6 * UM) ** 3 + 5 * UM / UM ** 3)
    assert q == pytest.approx(q_series, rel=0.05, abs=0) and q < q_series
    q_j = c.leak_rate_junction(mu=1e-3, pressure_drop=1e3, length=UM, width=w)
    assert q_j > q


def test_sealed_field_and_record():
    g = np.full((6, 6), UM)
    g[3] = 0.0
    c = critical_constriction(g, (UM, UM))
    assert not c.percolates and c.critical_gap is None and c.path.shape == (0, 2)
    assert c.leak_rate_junction(mu=1e-3, pressure_drop=1.0, length=1, width=1) == 0.0
    res = analyse_leakage(g, None, (UM, UM), direction="both", mu=1e-3, pressure_drop=1.0)
    rec = res.record()
    assert rec["critical_gap_x"] is None and rec["critical_gap_y"] == UM
    assert rec["critical_gap"] is None                    # first direction: x
    assert rec["leak_rate_critical_junction_y"] == pytest.approx(UM ** 3 / 12e-3, rel=1e-6, abs=0)
    with pytest.raises(InputError, match="channel_factor"):
        critical_constriction(g, (UM, UM), channel_factor=0.5)
    with pytest.raises(InputError, match="spacing must be the cell size"):
        critical_constriction(g, UM)                              # was a TypeError


def test_the_unsuffixed_junction_leak_rate_is_the_mean_over_directions():
    """A gap that is open along y only (a closed row across x): the unsuffixed junction
    leak rate was the x direction's, 0 ('sealed'), beside leak_rate = the mean of 0 and
    a positive Q_y. It is now the mean over the directions, as leak_rate."""
    g = np.full((16, 12), 1e-6)
    g[8, :] = 0.0                        # a closed row: no flow along x, open along y
    r = analyse_leakage(g, g == 0, (1e-6, 1e-6), mu=1e-3, pressure_drop=1e3).record()
    assert r["leak_rate_critical_junction_x"] == 0.0 and r["leak_rate_critical_junction_y"] > 0
    assert r["leak_rate_critical_junction"] == pytest.approx(
        0.5 * r["leak_rate_critical_junction_y"], rel=1e-12, abs=0)
    assert r["leak_rate"] == pytest.approx(0.5 * r["leak_rate_y"], rel=1e-12, abs=0)
    # the junction formula counts the whole width (L_x / L_y) u_c^3 dp / (12 mu); Reynolds
    # sees the 15 open lanes of 16 (this compared 1.111e-13 with 1.042e-13 at rel 1e-6 and
    # passed only through pytest.approx's default abs = 1e-12)
    assert r["leak_rate_critical_junction_y"] / r["leak_rate_y"] == pytest.approx(16 / 15,
                                                                               rel=1e-9)
    # parallel plates without the closed row: the junction formula is exact, as is Reynolds
    p = analyse_leakage(np.full((16, 12), 1e-6), None, (1e-6, 1e-6), mu=1e-3,
                        pressure_drop=1e3).record()
    plates = 1e-18 * 16e-6 * 1e3 / (12e-3 * 12e-6)
    for key in ("leak_rate_critical_junction_y", "leak_rate_y"):
        assert p[key] == pytest.approx(plates, rel=1e-9, abs=0)


@pytest.mark.parametrize("kwargs, words", [
    ({"mu": 0.0, "reynolds": False}, "mu"), ({"pressure_drop": -5.0, "reynolds": False}, "pressure_drop"),
    ({"pressure_drop": float("nan"), "reynolds": False}, "pressure_drop")])
def test_fluid_data_are_checked_without_reynolds_too(kwargs, words):
    # mu = 0 was a ZeroDivisionError in record(); a negative drop a negative junction
    # leak rate (the study path wrote it)
    g = np.full((8, 8), 1e-6)
    with pytest.raises(InputError, match=words):
        analyse_leakage(g, None, (1e-6, 1e-6), **kwargs)


def test_empty_and_clipped_negative_gaps_are_refused():
    with pytest.raises(InputError, match="shape"):
        critical_constriction(np.zeros((0, 5)), (1e-6, 1e-6))
    from roughfe.leakage.network import free_volume_network
    with pytest.raises(InputError, match="shape"):
        free_volume_network(np.zeros((0, 5)), None, (1e-6, 1e-6))
    g = np.full((6, 6), 1e-6)
    g[3, :] = -5e-6                      # interpenetrating: became a 1 nm film with h_min
    with pytest.raises(InputError, match="finite and >= 0"):
        reynolds_flow(g, (1e-6, 1e-6), h_min=1e-9)


def _channel_with_neck(row, col=(5, 8), shape=(20, 12)):
    """A straight 3-cell channel along x (columns ``col``) of 1 um in contact, closing to
    10-12 nm across row ``row``: the junction is (row, col[1] - 1), u_c = 12 nm."""
    g = np.zeros(shape)
    g[:, col[0]:col[1]] = UM
    g[row, col[0]:col[1]] = np.linspace(0.010, 0.012, col[1] - col[0]) * UM
    return g


@pytest.mark.parametrize("row, at_edge", [(0, True), (1, True), (2, False), (10, False),
                                          (17, False), (18, True), (19, True)])
def test_a_junction_at_the_cut_of_a_window_is_flagged(row, at_edge):
    # the neck closing at the inlet or outlet row (or the next) of a non-periodic window
    # may be the cut's; the same neck inside the window is the surface's
    g = _channel_with_neck(row)
    c = critical_constriction(g, (UM, UM), direction="x", periodic=False)
    assert c.junction == (row, 7) and c.critical_gap == pytest.approx(0.012 * UM, abs=0)
    assert c.at_edge is at_edge and c.record()["critical_at_edge"] is at_edge
    # a periodic window has no cut: never flagged, the same junction
    p = critical_constriction(g, (UM, UM), direction="x", periodic=True)
    assert p.junction == (row, 7) and p.at_edge is False


@pytest.mark.parametrize("col, at_edge", [((0, 3), True), ((1, 4), True), ((2, 5), False),
                                          ((9, 12), True), ((8, 11), True), ((7, 10), False)])
def test_a_junction_against_a_side_wall_is_flagged(col, at_edge):
    # the neck in the middle row, its widest cell (the junction) on the wall side of a
    # channel along a non-periodic side wall (the real surface may go round it beyond the
    # wall); the transposed field along y agrees
    g = _channel_with_neck(10, col=col)
    jc = col[0] if col[0] < 6 else col[1] - 1          # the cell nearest the wall
    g[10, col[0]:col[1]] = 0.010 * UM
    g[10, jc] = 0.012 * UM
    c = critical_constriction(g, (UM, UM), direction="x", periodic=False)
    assert c.junction == (10, jc) and c.at_edge is at_edge
    t = critical_constriction(g.T, (UM, UM), direction="y", periodic=False)
    assert t.junction == (jc, 10) and t.at_edge is at_edge
    assert not critical_constriction(g, (UM, UM), direction="x", periodic=True).at_edge


def test_at_edge_reaches_the_records_per_direction():
    g = _channel_with_neck(19)
    rec = analyse_leakage(g, None, (UM, UM), direction="x", reynolds=False).record()
    assert rec["critical_at_edge_x"] is True and rec["critical_at_edge"] is True
    assert rec["critical_at_edge_y"] is None        # not analysed (no junction: None)
    sealed = np.zeros((8, 8))
    sealed[:, 3] = UM
    sealed[4, 3] = 0.0
    rec = analyse_leakage(sealed, None, (UM, UM), direction="x", reynolds=False).record()
    assert rec["critical_at_edge_x"] is None        # no percolation, no junction
