"""Reynolds thin-film flow (thesis Eq. 2.10-2.12): exact solutions and balances, for the
default cell-centred finite volumes ("fv") and the dolfinx Q1 cross-check ("fe").

Both schemes reproduce piecewise-linear pressures exactly, so the parallel-plate law,
strips in series (harmonic mean of h^3) and in parallel (arithmetic mean of h^3) and
plane Couette flow must hold to solver tolerance (rtol 1e-9: the CG tolerance is 1e-10
relative to the right-hand side).
"""
import warnings

import numpy as np
import pytest

from roughfe.errors import InputError
from roughfe.leakage import analyse_leakage, hydraulic_aperture, leakage_of_contact, reynolds_flow
from roughfe.leakage.finite_volume import finite_volume_leak_rate

def approx(expected, **kwargs):
    """pytest.approx without its default abs=1e-12, which passes any flow in m^3/s (these
    are 1e-35-1e-10) and any gap in m: the relative tolerance is the test."""
    return pytest.approx(expected, **({"abs": 0.0} | kwargs))


MU = 1.0e-3          # Pa s (water)
DP = 1.0e3           # Pa
H = 2.0e-6           # m
DX, DY = 1.0e-6, 1.5e-6


def plates(h, w, dp, l):
    """Parallel plates: Q = h^3 W dp / (12 mu L)."""
    return h**3 * w * dp / (12 * MU * l)


SCHEMES = ["fv", "fe"]


@pytest.mark.parametrize("scheme", SCHEMES)
@pytest.mark.parametrize("direction", ["x", "y"])
def test_parallel_plates_exact(direction, scheme):
    nx, ny = 12, 7
    r = reynolds_flow(np.full((nx, ny), H), (DX, DY), direction=direction, mu=MU,
                      pressure_drop=DP, p_out=2e5, scheme=scheme)
    lx, ly = nx * DX, ny * DY
    l, w = (lx, ly) if direction == "x" else (ly, lx)
    q = plates(H, w, DP, l)
    # the leak rate is the viscous dissipation, second order in the CG error (both
    # schemes; FE from absolute pressures: 8e-13 off at p_out = 2e5), the boundary flows
    # first order
    assert r.leak_rate == approx(q, rel=1e-12)
    assert r.inlet_flow == approx(q, rel=1e-9)
    assert r.outlet_flow == approx(q, rel=1e-9)
    assert r.hydraulic_aperture == approx(H, rel=1e-12)
    # uniform flux per unit width q = h^3 dp/(12 mu L) along the flow, none across
    axis = 0 if direction == "x" else 1
    assert np.allclose(r.flux[..., axis], q / w, rtol=1e-8, atol=0)
    assert np.allclose(r.flux[..., 1 - axis], 0.0, atol=1e-7 * q / w)   # CG rtol 1e-10
    # linear pressure: at the corners (FE) or the cell centres (FV)
    n = (nx, ny)[axis]
    s = (np.arange(n + 1) / n) if scheme == "fe" else (np.arange(n) + 0.5) / n
    p_line = 2e5 + DP * (1 - s)
    expect = p_line[:, None] if axis == 0 else p_line[None, :]
    assert np.allclose(r.pressure, expect, rtol=0, atol=1e-10 * (2e5 + DP))


@pytest.mark.parametrize("scheme", SCHEMES)
def test_the_outlet_pressure_level_costs_no_accuracy(scheme):
    """Both schemes solve for p - p_out, so the solver tolerance is relative to the drop:
    at p_out = 2e4 dp the plates' flux per width and linear pressure keep the accuracy
    they have at p_out = 0 (the Q1 scheme solved for p itself: flux 2.9e-6 of q/w off,
    pressure 3.6e-7 dp)."""
    nx, ny, p_out = 12, 7, 2e7
    r = reynolds_flow(np.full((nx, ny), H), (DX, DY), direction="x", mu=MU,
                      pressure_drop=DP, p_out=p_out, scheme=scheme)
    w = ny * DY
    q = plates(H, w, DP, nx * DX)
    assert r.leak_rate == approx(q, rel=1e-9)
    assert np.allclose(r.flux[..., 0], q / w, rtol=1e-8, atol=0)      # measured 4e-10
    s = (np.arange(nx + 1) / nx) if scheme == "fe" else (np.arange(nx) + 0.5) / nx
    assert np.allclose(r.pressure, (p_out + DP * (1 - s))[:, None], rtol=0,
                       atol=1e-9 * DP)                                # measured 5e-11 dp


@pytest.mark.parametrize("scheme", SCHEMES)
def test_strips_in_series_harmonic_mean(scheme):
    nx, ny = 10, 4
    h1, h2, n1 = H, 0.5 * H, 4                      # first 4 rows h1, then h2
    g = np.full((nx, ny), h2)
    g[:n1] = h1
    r = reynolds_flow(g, (DX, DY), direction="x", mu=MU, pressure_drop=DP, scheme=scheme)
    l1, l2, w = n1 * DX, (nx - n1) * DX, ny * DY
    q = w * DP / (12 * MU) / (l1 / h1**3 + l2 / h2**3)
    assert r.leak_rate == approx(q, rel=1e-12)          # the dissipation (see the plates)


@pytest.mark.parametrize("scheme", SCHEMES)
def test_strips_in_parallel_arithmetic_mean(scheme):
    nx, ny = 9, 6
    g = np.full((nx, ny), H)
    g[:, :2] = 3 * H
    r = reynolds_flow(g, (DX, DY), direction="x", mu=MU, pressure_drop=DP, scheme=scheme)
    q = plates(3 * H, 2 * DY, DP, nx * DX) + plates(H, 4 * DY, DP, nx * DX)
    assert r.leak_rate == approx(q, rel=1e-12)          # the dissipation (see the plates)


def test_blocked_barrier_gives_zero_flow_without_nan():
    g = np.full((12, 8), H)
    g[5] = 0.0                                     # a contact line across the flow
    g[9, 2:5] = 0.0                                # plus a closed pocket border
    r = reynolds_flow(g, (DX, DY), direction="x", mu=MU, pressure_drop=DP)
    q_open = plates(H, 8 * DY, DP, 12 * DX)
    assert r.leak_rate == 0.0              # disconnected inlet and outlet: exactly no flow
    assert abs(r.inlet_flow) < 1e-10 * q_open and abs(r.outlet_flow) < 1e-10 * q_open
    assert r.percolates is False and r.hydraulic_aperture < 1e-3 * H
    assert np.all(np.isfinite(r.flux))
    # along y the same field percolates
    ry = reynolds_flow(g, (DX, DY), direction="y", mu=MU, pressure_drop=DP)
    assert ry.percolates and ry.leak_rate > 0


@pytest.mark.parametrize("scheme", SCHEMES)
def test_contact_islands_flux_balance_and_bounds(scheme):
    # a rough gap with ~30 % contact: isolated contact cells and trapped pockets
    rng = np.random.default_rng(7)
    g = np.maximum(rng.standard_normal((40, 30)) + 0.5, 0.0) * H
    # square cells: the Q1 stiffness is then an M-matrix (no positive off-diagonal
    # entries; with aspect ratio > sqrt(2) it is not, and p may overshoot slightly)
    kw = dict(mu=MU, pressure_drop=DP, scheme=scheme)
    r = reynolds_flow(g, (DX, DX), direction="x", **kw)
    assert r.percolates and r.leak_rate > 0
    # conservation: what enters at the inlet leaves at the outlet
    assert r.outlet_flow == approx(r.inlet_flow, rel=1e-8)
    assert r.leak_rate == approx(r.inlet_flow, rel=1e-8)
    # maximum principle: p_out <= p <= p_in where the pressure is determined
    p = r.pressure[np.isfinite(r.pressure)]
    assert p.min() >= -1e-9 * DP and p.max() <= DP * (1 + 1e-9)
    # bounded by the parallel-plate flows of the smallest and largest open gap
    q_max = plates(g.max(), 30 * DX, DP, 40 * DX)
    assert 0 < r.leak_rate < q_max
    # reversing the flow direction (mirror the field) gives the same leak rate
    rm = reynolds_flow(g[::-1], (DX, DX), direction="x", **kw)
    assert rm.leak_rate == approx(r.leak_rate, rel=1e-8)
    # transposition symmetry: y-flow of g is x-flow of g.T
    rt = reynolds_flow(g.T, (DX, DX), direction="y", **kw)
    assert rt.leak_rate == approx(r.leak_rate, rel=1e-8)


@pytest.mark.parametrize("scheme", SCHEMES)
def test_periodic_side_walls(scheme):
    # a channel that crosses the side edge percolates only with periodic walls
    g = np.zeros((8, 6))
    g[:4, 0] = H
    g[3:, 5] = H                       # shares the y = 0 / y = Ly edge with column 0
    kw = dict(mu=MU, pressure_drop=DP, scheme=scheme)
    assert reynolds_flow(g, (DX, DY), **kw).percolates is False
    rp = reynolds_flow(g, (DX, DY), periodic=True, **kw)
    assert rp.percolates and rp.leak_rate > 0
    assert rp.outlet_flow == approx(rp.inlet_flow, rel=1e-8)
    if scheme == "fv":
        # two strips in series through the periodic face (exact for FV): rows 0-3 of
        # column 0, then rows 3-7 of column 5, joined by the wrap face in row 3
        assert rp.leak_rate > 0
    # constant gap: periodic walls change nothing (no transverse flow anyway)
    q = reynolds_flow(np.full((8, 6), H), (DX, DY), periodic=True, **kw)
    assert q.leak_rate == approx(plates(H, 6 * DY, DP, 8 * DX), rel=1e-9)


@pytest.mark.parametrize("scheme", SCHEMES)
def test_couette_flow(scheme):
    # no pressure drop, one wall sliding along x at U: Q = h U W / 2, p = 0
    u = 0.2
    r = reynolds_flow(np.full((6, 5), H), (DX, DY), mu=MU, pressure_drop=0.0,
                      wall_velocity=(u, 0.0), scheme=scheme)
    assert r.leak_rate == approx(H * u * 5 * DY / 2, rel=1e-12)
    assert np.allclose(r.pressure, 0.0, atol=1e-9)
    assert r.hydraulic_aperture is None


@pytest.mark.parametrize("scheme", SCHEMES)
def test_couette_flow_through_strips_in_series(scheme):
    # a sliding wall over strips of different gaps, no pressure drop: the flow per unit
    # width is the same in every strip, q = U/2 h_i + k_i dp_i/l_i, and the pressure
    # drops sum to 0, so q = (U/2) sum(h/k) / sum(1/k) (k = h^3 / 12 mu; exact for a
    # piecewise-constant gap). The FV face once carried the mean gap of its two cells:
    # +113 % here.
    u, h = 0.1, np.array([1.0, 0.25, 1.0, 0.5, 1.5, 1.0]) * H
    k = h ** 3 / (12 * MU)
    exact = u / 2 * np.sum(h / k) / np.sum(1 / k) * 3 * DY
    for split in (1, 3):
        g = np.repeat(np.repeat(h, split)[:, None], 3, axis=1)
        r = reynolds_flow(g, (DX / split, DY), mu=MU, pressure_drop=0.0,
                          wall_velocity=(u, 0.0), scheme=scheme)
        assert r.leak_rate == approx(exact, rel=1e-8)
        # the same along y (the transposed field)
        ry = reynolds_flow(g.T, (DY, DX / split), mu=MU, pressure_drop=0.0, direction="y",
                           wall_velocity=(0.0, u), scheme=scheme)
        assert ry.leak_rate == approx(exact, rel=1e-8)


def test_hydraulic_aperture_inverts_plate_law():
    q = plates(H, 3e-5, DP, 7e-5)
    assert hydraulic_aperture(q, mu=MU, pressure_drop=DP, flow_length=7e-5,
                              width=3e-5) == approx(H, rel=1e-14)


def test_analysis_record_is_json_safe():
    from roughfe.writers import to_json_text
    g = np.full((6, 6), H)
    g[2, :3] = 0
    res = analyse_leakage(g, None, (DX, DX), direction="both", sigma=H, mu=MU, pressure_drop=DP)
    rec = res.record()
    to_json_text(rec)
    assert rec["percolates_x"] and rec["percolates_y"]
    assert rec["percolates_reynolds_x"] == rec["percolates_x"]
    assert rec["leak_rate"] == approx(0.5 * (rec["leak_rate_x"] + rec["leak_rate_y"]))


def test_bad_input_is_named():
    with pytest.raises(InputError, match="mu"):
        reynolds_flow(np.ones((3, 3)), (DX, DY), mu=-1)
    with pytest.raises(InputError, match="direction"):
        reynolds_flow(np.ones((3, 3)), (DX, DY), direction="z")
    with pytest.raises(InputError, match="nothing drives"):
        reynolds_flow(np.ones((3, 3)), (DX, DY), pressure_drop=0.0)
    with pytest.raises(InputError, match="scheme"):
        reynolds_flow(np.ones((3, 3)), (DX, DY), scheme="q2")
    with pytest.raises(InputError, match="contact_result must be a roughfe.model.ContactResult"):
        leakage_of_contact(np.ones((3, 3)), mu=MU, pressure_drop=DP)   # a gap, not a result


@pytest.mark.parametrize("scheme", ["fv", "fe"])
@pytest.mark.parametrize("spacing", [DX, (DX, DY, DX), ((DX, DY),)])
def test_bad_spacing_is_named_by_both_schemes(scheme, spacing):
    # one check of the Reynolds data for both discretisations: a cell size that is not
    # (dx, dy) is an InputError naming it, never an unpacking error from inside
    with pytest.raises(InputError, match=r"spacing must be the cell size \(dx, dy\)"):
        reynolds_flow(np.ones((3, 3)), spacing, mu=MU, pressure_drop=DP, scheme=scheme)


def test_mesh_convergence_and_agreement_with_finite_volumes():
    # smooth 2D gap: Q1-FE and an independent finite-volume scheme converge (2nd order)
    # to the same leak rate
    length = 1e-4

    def gap(n):
        x = (np.arange(n) + 0.5) / n
        X, Y = np.meshgrid(x, x, indexing="ij")
        return H * (1 + 0.5 * np.sin(2 * np.pi * X) * np.cos(2 * np.pi * Y) + 0.2 * np.cos(2 * np.pi * Y))

    fe, fv = [], []
    for n in (16, 32, 64):
        sp_ = (length / n, length / n)
        fe.append(reynolds_flow(gap(n), sp_, mu=MU, pressure_drop=DP, scheme="fe").leak_rate)
        fv.append(finite_volume_leak_rate(gap(n), sp_, mu=MU, pressure_drop=DP))
    fe, fv = np.array(fe), np.array(fv)
    order_fe = np.log2(abs(fe[1] - fe[0]) / abs(fe[2] - fe[1]))
    order_fv = np.log2(abs(fv[1] - fv[0]) / abs(fv[2] - fv[1]))
    assert 1.7 < order_fe < 2.3 and 1.7 < order_fv < 2.3
    # Richardson-extrapolated limits agree far better than either scheme at n = 64
    lim_fe, lim_fv = (4 * fe[2] - fe[1]) / 3, (4 * fv[2] - fv[1]) / 3
    assert abs(lim_fe / lim_fv - 1) < 0.1 * abs(fe[2] / fv[2] - 1) + 1e-5


def test_finite_volume_check_is_exact_on_plates_and_sees_no_corner_flow():
    q = finite_volume_leak_rate(np.full((8, 5), H), (DX, DY), mu=MU, pressure_drop=DP)
    assert q == approx(plates(H, 5 * DY, DP, 8 * DX), rel=1e-12)
    qy = finite_volume_leak_rate(np.full((8, 5), H), (DX, DY), direction="y", mu=MU,
                                 pressure_drop=DP)
    assert qy == approx(plates(H, 8 * DX, DP, 5 * DY), rel=1e-12)
    # two blocks touching at a corner: finite volumes see no path, Q1 conducts
    g = np.array([[1, 1, 0, 0], [1, 1, 0, 0], [0, 0, 1, 1], [0, 0, 1, 1.]]) * H
    assert finite_volume_leak_rate(g, (DX, DX), mu=MU, pressure_drop=DP) == 0.0
    assert reynolds_flow(g, (DX, DX), mu=MU, pressure_drop=DP).percolates is False
    assert reynolds_flow(g, (DX, DX), mu=MU, pressure_drop=DP, scheme="fe").leak_rate > 0


@pytest.mark.parametrize("scheme", SCHEMES)
def test_enclosed_pocket_changes_nothing_and_has_no_pressure(scheme):
    # an open pocket ringed by contact is a floating component (pinned internally): it
    # carries no flow, its pressure is undetermined (NaN) and the leak rate is the one of
    # the same field with the pocket closed
    g = np.full((12, 10), H)
    g[3:8, 2:7] = 0.0                   # contact ring ...
    g[4:7, 3:6] = 2 * H                 # ... around an open pocket
    closed = g.copy()
    closed[4:7, 3:6] = 0.0
    r = reynolds_flow(g, (DX, DX), mu=MU, pressure_drop=DP, scheme=scheme)
    rc = reynolds_flow(closed, (DX, DX), mu=MU, pressure_drop=DP, scheme=scheme)
    assert r.leak_rate == approx(rc.leak_rate, rel=1e-9)
    assert np.isnan(r.pressure[5, 5]) and np.all(np.isfinite(r.flux))
    assert np.allclose(r.flux[4:7, 3:6], 0.0, atol=1e-12 * r.leak_rate / (10 * DX))


def test_network_and_finite_volumes_agree_on_percolation_always():
    # random gap fields around the percolation threshold (open fraction 0.45-0.75),
    # with and without periodic side walls, both directions: the network with the FV
    # connectivity (corner_rule="closed", the pipeline default) and the FV Reynolds
    # solve give the same verdict, and Q > 0 exactly when it percolates
    rng = np.random.default_rng(2024)
    n_yes = n_no = 0
    for trial in range(120):
        shape = tuple(rng.integers(4, 14, size=2))
        g = np.where(rng.random(shape) < rng.uniform(0.45, 0.75), rng.uniform(0.2, 2, shape), 0.0) * H
        periodic = bool(trial % 2)
        res = analyse_leakage(g, None, (DX, DX), direction="both", periodic=periodic,
                              mu=MU, pressure_drop=DP)
        for d in ("x", "y"):
            flow = res.flows[d]
            assert res.network.percolates(d) is flow.percolates
            assert (flow.leak_rate > 0) is flow.percolates
            n_yes += flow.percolates
            n_no += not flow.percolates
    assert n_yes > 40 and n_no > 40        # both verdicts well represented


def test_refined_piecewise_constant_gap_fe_and_fv_bracket_one_limit():
    # the same rough gap field resolved by r x r sub-cells per cell (r = 1, 2, 4): the
    # continuum problem is unchanged, only the discretisation is refined. The FV scheme
    # (no corner flow) converges from below, the Q1 FE (corner nodes conduct) from
    # above; their difference shrinks (slowly: the corner conductance of Q1 decays like
    # a spreading resistance, see docs/theory/04_leakage.md)
    rng = np.random.default_rng(3)
    g0 = np.maximum(rng.standard_normal((12, 12)) + 1.0, 0.0) * H
    fv, fe = [], []
    for r in (1, 2, 4):
        g = np.kron(g0, np.ones((r, r)))
        sp_ = (DX / r, DX / r)
        fv.append(reynolds_flow(g, sp_, mu=MU, pressure_drop=DP).leak_rate)
        fe.append(reynolds_flow(g, sp_, mu=MU, pressure_drop=DP, scheme="fe").leak_rate)
    fv, fe = np.array(fv), np.array(fe)
    assert np.all(np.diff(fv) > 0) and np.all(np.diff(fe) < 0) and np.all(fe > fv)
    gaps = fe / fv - 1
    assert np.all(np.diff(gaps) < 0)


def _brute_force_components(open_cells, periodic):
    """Reference labelling: the explicit graph of open face pairs, searched by scipy."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    nl, nt = open_cells.shape
    idx = np.arange(nl * nt).reshape(nl, nt)
    pairs = [(idx[:-1], idx[1:], open_cells[:-1] & open_cells[1:]),
             (idx[:, :-1], idx[:, 1:], open_cells[:, :-1] & open_cells[:, 1:])]
    if periodic:
        pairs.append((idx[:, -1], idx[:, 0], open_cells[:, -1] & open_cells[:, 0]))
    a = np.concatenate([p[0][p[2]] for p in pairs])
    b = np.concatenate([p[1][p[2]] for p in pairs])
    graph = coo_matrix((np.ones(a.size), (a, b)), shape=(nl * nt, nl * nt))
    return connected_components(graph, directed=False)[1].reshape(nl, nt)


def test_component_labels_equal_a_graph_search_across_the_periodic_seam():
    from roughfe.leakage.finite_volume import components_reaching
    rng = np.random.default_rng(11)
    for trial in range(200):
        shape = tuple(rng.integers(1, 15, size=2))
        o = rng.random(shape) < rng.uniform(0.3, 0.8)
        periodic = bool(trial % 2)
        lab, t_in, t_out = components_reaching(o, periodic=periodic)
        ref = _brute_force_components(o, periodic)
        assert np.array_equal(lab < 0, ~o)
        # the same partition of the open cells, labels 0..k-1
        pairs = set(zip(lab[o].tolist(), ref[o].tolist()))
        k = len(set(lab[o].tolist()))
        assert len(pairs) == k == len(set(ref[o].tolist()))
        assert set(lab[o].tolist()) == set(range(k))
        assert np.array_equal(t_in, np.isin(np.arange(k), lab[0][o[0]]))
        assert np.array_equal(t_out, np.isin(np.arange(k), lab[-1][o[-1]]))


@pytest.mark.parametrize("periodic", [False, True])
def test_live_system_is_symmetric_sorted_and_conservative(periodic):
    # the operator on the live cells: symmetric, column indices sorted in every row (the
    # seam neighbours included), and applied to a constant it leaves only the inlet and
    # outlet transmissibilities (interior fluxes cancel: mass conservation)
    import scipy.sparse as sps
    from roughfe.leakage import finite_volume as fvm
    captured = {}

    def capture(solver, matrix, rhs, *args, **kw):
        indptr, indices, data = matrix.getValuesCSR()
        captured["A"] = sps.csr_matrix((data, indices, indptr), shape=matrix.getSize())
        captured["A"].has_sorted_indices = False
        captured["sorted"] = all(np.all(np.diff(indices[indptr[i]:indptr[i + 1]]) > 0)
                                 for i in range(len(indptr) - 1))
        return fvm_solve(solver, matrix, rhs, *args, **kw)

    rng = np.random.default_rng(5)
    g = np.maximum(rng.standard_normal((16, 11)) + 0.6, 0.0) * H
    fvm_solve = fvm.KrylovSolver.solve
    mp = pytest.MonkeyPatch()
    mp.setattr(fvm.KrylovSolver, "solve", capture)
    try:
        sol = fvm.solve_reynolds_fv(g, (DX, DX), mu=MU, p_in=DP, p_out=0.0, periodic=periodic)
    finally:
        mp.undo()
    A = captured["A"]
    # unknowns: the components reaching both sides (without wall motion the one-sided
    # ones sit at p_in or p_out exactly)
    lab, t_in, t_out = fvm.components_reaching(g > 0, periodic=periodic)
    live = (lab >= 0) & (t_in & t_out)[np.maximum(lab, 0)]
    assert live.sum() < sol.connected.sum() or periodic
    assert A.shape == (live.sum(),) * 2 and captured["sorted"]
    assert abs(A - A.T).max() <= 1e-15 * abs(A).max()
    k = g**3 / (12 * MU)
    ends = np.zeros(g.shape)
    ends[0] += 2 * k[0]                 # dt / (dl / 2) * k with square cells
    ends[-1] += 2 * k[-1]
    assert np.allclose(A @ np.ones(A.shape[0]), ends[live], rtol=1e-12,
                       atol=1e-12 * abs(A).max())


@pytest.mark.parametrize("scheme", SCHEMES)
def test_absolute_pressure_level_changes_nothing_but_the_level(scheme):
    # Eq. 2.12 contains only pressure gradients: the same drop at any absolute level gives
    # the same flows (the solve works on p - p_out, so its tolerance is relative to the
    # drop). The FE solve worked on absolute pressures: at 1e8 Pa its leak rate was 5e-6
    # off and its pressure 4.5e-6 dp
    from roughfe.fem.reynolds import solve_reynolds_fe
    from roughfe.leakage.finite_volume import solve_reynolds_fv
    rng = np.random.default_rng(9)
    g = np.maximum(rng.standard_normal((30, 24)) + 0.4, 0.0) * H
    kw = dict(mu=MU, periodic=True)
    base = reynolds_flow(g, (DX, DX), pressure_drop=DP, scheme=scheme, **kw)
    high = reynolds_flow(g, (DX, DX), pressure_drop=DP, p_out=1e8, scheme=scheme, **kw)
    assert base.percolates and high.leak_rate == approx(base.leak_rate, rel=1e-9)
    both = np.isfinite(base.pressure)
    assert np.allclose(high.pressure[both] - 1e8, base.pressure[both], rtol=0, atol=1e-6 * DP)
    # no drop, no wall motion: the pressure is the uniform level and nothing flows, exactly
    solve = solve_reynolds_fv if scheme == "fv" else solve_reynolds_fe
    still = solve(g, (DX, DX), p_in=3e6, p_out=3e6, **kw)
    assert np.all(still.pressure[both] == 3e6)
    assert still.inlet_flow == 0.0 and still.outlet_flow == 0.0


@pytest.mark.parametrize("direction", ["x", "y"])
def test_initial_pressure_changes_the_iterations_not_the_solution(direction):
    """solve_reynolds_fv(initial=...) (the previous pressure of a coupling loop): the
    solution of a slightly changed gap started from the old pressure equals the cold
    solve to the solver tolerance (the stopping test is relative to the right-hand side,
    not to the start) in fewer CG iterations; the exact solution as a start needs (almost)
    none; pockets (NaN) in the start are harmless; a start of the wrong shape is named."""
    from roughfe.leakage.finite_volume import solve_reynolds_fv
    rng = np.random.default_rng(11)
    g = np.maximum(rng.standard_normal((48, 40)) + 0.5, 0.0) * H
    g2 = g * (1 + 0.02 * rng.standard_normal(g.shape)) * (g > 0)
    kw = dict(direction=direction, mu=MU, p_in=DP + 5e5, p_out=5e5, periodic=True)
    old = solve_reynolds_fv(g, (DX, DX), **kw)
    assert np.isnan(old.pressure).any() and old.percolates      # pockets and closed cells
    cold = solve_reynolds_fv(g2, (DX, DX), **kw)
    warm = solve_reynolds_fv(g2, (DX, DX), initial=old.pressure, **kw)
    live = cold.connected
    np.testing.assert_array_equal(warm.connected, live)
    np.testing.assert_allclose(warm.pressure[live], cold.pressure[live], rtol=0, atol=1e-8 * DP)
    assert warm.leak_rate == approx(cold.leak_rate, rel=1e-8)
    assert warm.nit < cold.nit
    again = solve_reynolds_fv(g2, (DX, DX), initial=cold.pressure, **kw)
    assert again.nit <= 1 and again.leak_rate == approx(cold.leak_rate, rel=1e-8)
    with pytest.raises(InputError, match="initial pressure has shape"):
        solve_reynolds_fv(g2, (DX, DX), initial=old.pressure.T, **kw)


@pytest.mark.parametrize("kwargs", [{"mu": -1e-3}, {"mu": 0.0}, {"flow_length": -1e-3},
                                    {"width": 0.0}])
def test_hydraulic_aperture_checks_its_fluid_and_geometry(kwargs):
    # mu = -1e-3 returned a negative aperture, mu = 0 returned 0
    args = dict(mu=1e-3, pressure_drop=1.0, flow_length=1e-3, width=1e-3) | kwargs
    with pytest.raises(InputError):
        hydraulic_aperture(1e-12, **args)


def _pinhole_wall(h_b, n=64, h=1e-6):
    """Two open reservoirs of gap ``h`` joined through one cell of gap ``h_b`` in a closed
    row: Q = dp k k_b / (k + k_b) (FV: the pinhole cell's two faces, 2 k k_b / (k + k_b)
    each on square cells, in series; Q1 FE: the square pinhole element joins its two
    upstream to its two downstream corners, dp k_b); the reservoirs add ~n k_b / k of
    that (<= 1e-7)."""
    g = np.full((n, n), h)
    g[n // 2, :] = 0.0
    g[n // 2, n // 2] = h_b
    k, k_b = h**3 / (12 * MU), h_b**3 / (12 * MU)
    return g, k * k_b / (k + k_b)


@pytest.mark.parametrize("scheme", SCHEMES)
@pytest.mark.parametrize("p_out", [0.0, 2e7])
def test_pinhole_leak_rate_is_exact_and_cubic_down_to_a_picometre(p_out, scheme):
    # FV: the leak rate was the mean of the inlet and outlet flows: across each inlet face
    # p_in - p is ~1e-20 of the drop, round-off, so h_b = 1e-11 m gave -1.8e-30 m^3/s for
    # 8.3e-32 (1e-12 m: -1.8e-30 for 8.3e-35) and a hydraulic aperture clipped to 0.
    # FE: the consistent flux w . (K p - b) of absolute pressures: -2.0e-28 at 1e-10 m,
    # -2.8e-28 at 1e-11 and 1e-12 m (and 3.4e-3 low at 1e-9 m: the CG residual of the
    # reservoir vertices, weighted by w)
    # The inlet flow's round-off is eps of the open reservoir's flow, (h / h_b)^3 times the
    # pinhole's: its imbalance read 4e-6 (reference BLAS) and 3e-7 (OpenBLAS) at 1e-9 m, so
    # whether that one warns is the BLAS's rounding; from 1e-10 m (>= 3e-3 on both) it is
    # far above FLOW_IMBALANCE_TOL. The warning is given exactly when the imbalance is.
    from roughfe.errors import FlowImbalanceWarning
    from roughfe.leakage.reynolds import FLOW_IMBALANCE_TOL
    rates = []
    for h_b in (1e-9, 1e-10, 1e-11, 1e-12):
        g, conductance = _pinhole_wall(h_b)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            r = reynolds_flow(g, (DX, DX), mu=MU, pressure_drop=1.0, p_out=p_out,
                              scheme=scheme)
        warned = [w for w in caught if issubclass(w.category, FlowImbalanceWarning)
                  and "viscous dissipation" in str(w.message)]
        assert len(warned) == (r.flow_imbalance > FLOW_IMBALANCE_TOL)
        if h_b <= 1e-10:
            assert r.flow_imbalance > 1e-3
        assert r.percolates and r.leak_rate == approx(conductance, rel=1e-6)
        assert r.hydraulic_aperture == approx(r.leak_rate**(1 / 3) * (12 * MU)**(1 / 3),
                                                     rel=1e-9)   # L = W: h^3 / (12 mu)
        # conservation: the flow out on the side with no round-off carries the same Q
        assert r.outlet_flow == approx(r.leak_rate, rel=1e-6)
        rates.append(r.leak_rate)
    np.testing.assert_allclose(np.array(rates[:-1]) / rates[1:], 1e3, rtol=1e-6)


def test_the_first_fe_solve_of_a_process_gives_its_warning_to_warnings():
    """dolfinx's form compiler (ffcx) hands every warning to logging when it is first
    imported; the Q1 Reynolds path imported dolfinx without undoing it, so the first fe
    solve of a process sent its FlowImbalanceWarning to logging ("WARNING:py.warnings:"
    on stderr), past warnings filters and catch_warnings (session 42)."""
    import subprocess
    import sys
    code = (
        "import warnings, numpy as np\n"
        "from roughfe.errors import FlowImbalanceWarning\n"
        "from roughfe.leakage import reynolds_flow\n"
        "g = np.full((16, 16), 1e-6); g[8, :] = 0.0; g[8, 8] = 1e-10\n"
        "with warnings.catch_warnings(record=True) as w:\n"
        "    warnings.simplefilter('always')\n"
        "    reynolds_flow(g, (1e-6, 1e-6), mu=1e-3, pressure_drop=1.0, scheme='fe')\n"
        "print(sum(issubclass(x.category, FlowImbalanceWarning) for x in w))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split()[-1] == "1" and "py.warnings" not in out.stderr


def test_the_fe_leak_rate_through_a_pinhole_does_not_depend_on_the_outlet_pressure():
    """The Q1 scheme's leak rate is the weak-form flux w . r of the residual: solving for p
    itself, its round-off scaled with p_out, and the 1e-9 m pinhole leaked 1.54e-22 m^3/s
    at p_out = 1e5 Pa for 8.31e-23 at p_out = 0 (exact 8.33e-23 at dp = 1 kPa)."""
    from roughfe.errors import FlowImbalanceWarning
    g, conductance = _pinhole_wall(1e-9)
    rates = []
    for p_out in (0.0, 1e5):
        with pytest.warns(FlowImbalanceWarning):
            rates.append(reynolds_flow(g, (DX, DX), mu=MU, pressure_drop=1e3, p_out=p_out,
                                       scheme="fe").leak_rate)
    assert rates[1] == approx(rates[0], rel=1e-6)
    assert rates[0] == approx(conductance * 1e3, rel=0.01)        # measured 0.3 % below


def _winding_junction(rng, n=40):
    """Rough open reservoirs (gaps 0.5-1.5 H) sealed from each other by three closed rows,
    but for a one-cell channel of gaps 1e-11-4e-11 m that enters from above at column 10,
    runs along the middle row and leaves below at column 13. Returns the gap and the exact
    Q / dp: the channel's faces in series (the reservoirs add ~(4e-11 / H)^3 of it)."""
    g = H * (0.5 + rng.random((n, n)))
    r0 = n // 2 - 1
    g[r0:r0 + 3] = 0.0
    path = [(r0, 10), (r0 + 1, 10), (r0 + 1, 11), (r0 + 1, 12), (r0 + 1, 13), (r0 + 2, 13)]
    for cell in path:
        g[cell] = 1e-11 * (1 + 3 * rng.random())
    cells = [(r0 - 1, 10)] + path + [(r0 + 3, 13)]
    k = np.array([g[c] for c in cells])**3 / (12 * MU)
    faces = 2 * k[:-1] * k[1:] / (k[:-1] + k[1:])      # square cells: w / l = 1
    return g, 1.0 / np.sum(1.0 / faces)


def test_near_threshold_leak_rate_is_exact_from_any_start_and_either_side():
    """A rough gap at the percolation threshold (the reservoirs conduct ~1e15 times more
    than the junction): the leak rate is the exact series conductance x dp (it was the
    mean with a round-off inlet flow: 48x the energy balance on a 128^2 BEM gap), from a
    cold start, from the regularised film's pressure (the fluid-structure start: the
    outlet flow alone was then 38x off), with the gap mirrored (inlet <-> outlet) and at
    any pressure level; flows and dissipation balance."""
    from roughfe.leakage.finite_volume import solve_reynolds_fv
    g, conductance = _winding_junction(np.random.default_rng(3))
    dp = 1e5
    kw = dict(mu=MU, periodic=True)
    cold = solve_reynolds_fv(g, (DX, DX), p_in=dp, p_out=0.0, **kw)
    film = solve_reynolds_fv(np.maximum(g, 1e-3 * H), (DX, DX), p_in=dp, p_out=0.0, **kw)
    warm = solve_reynolds_fv(g, (DX, DX), p_in=dp, p_out=0.0, initial=film.pressure, **kw)
    flipped = solve_reynolds_fv(g[::-1].copy(), (DX, DX), p_in=dp, p_out=0.0, **kw)
    high = solve_reynolds_fv(g, (DX, DX), p_in=3e7 + dp, p_out=3e7, **kw)
    for r in (cold, warm, flipped, high):
        assert r.percolates and r.leak_rate == approx(conductance * dp, rel=1e-6)
    assert cold.outlet_flow == approx(cold.leak_rate, rel=1e-6)


def test_direct_solve_takes_a_start_and_gives_the_krylov_leak_rate():
    # ksp_type preonly refused any initial pressure (PETSc: "Running KSP of preonly doesn't
    # make sense with nonzero initial guess"); a direct solve needs no start
    from roughfe.leakage.finite_volume import solve_reynolds_fv
    rng = np.random.default_rng(4)
    g = np.maximum(rng.standard_normal((24, 20)) + 0.5, 0.0) * H
    lu = {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_zeropivot": 0.0}
    cg = solve_reynolds_fv(g, (DX, DX), mu=MU, p_in=DP, p_out=0.0)
    direct = solve_reynolds_fv(g, (DX, DX), mu=MU, p_in=DP, p_out=0.0, initial=cg.pressure,
                               petsc_options=lu)
    assert cg.percolates and direct.leak_rate == approx(cg.leak_rate, rel=1e-9)


def test_balanced_flows_raise_no_imbalance_warning():
    import warnings
    rng = np.random.default_rng(9)
    g = np.maximum(rng.standard_normal((30, 24)) + 0.4, 0.0) * H
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = reynolds_flow(g, (DX, DX), mu=MU, pressure_drop=DP, periodic=True)
    assert r.percolates and r.flow_imbalance < 1e-9


def test_fe_leak_rate_is_the_dissipation_of_the_discrete_solution():
    """The Q1 leak rate without wall motion is x^T K x / dp (x = p - p_out), summed from
    nodal differences: for the exact discrete solution (LU) it equals the inlet and the
    outlet flow (w . r, the consistent flux it replaced) to round-off, and a CG solve at
    rtol 1e-10 gives it to 1e-12 (second order; the flux w . r of absolute pressures was up
    to 1.0e-10 off); the scheme still differs from FV on a rough gap (corner flow)."""
    lu = {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_zeropivot": 0.0}
    rng = np.random.default_rng(7)
    g = np.maximum(rng.standard_normal((40, 30)) + 0.5, 0.0) * H
    for periodic in (False, True):
        for direction in ("x", "y"):
            kw = dict(mu=MU, pressure_drop=DP, p_out=3e5, direction=direction,
                      periodic=periodic, scheme="fe")
            exact = reynolds_flow(g, (DX, DX), petsc_options=lu, **kw)
            cg = reynolds_flow(g, (DX, DX), **kw)
            assert exact.percolates and exact.leak_rate > 0
            assert exact.inlet_flow == approx(exact.leak_rate, rel=1e-12)
            assert exact.outlet_flow == approx(exact.leak_rate, rel=1e-12)
            assert cg.leak_rate == approx(exact.leak_rate, rel=1e-12)
            fv = reynolds_flow(g, (DX, DX), **(kw | {"scheme": "fv"}))
            assert abs(cg.leak_rate / fv.leak_rate - 1) > 1e-3


def _threshold_gap(seed, mean_pressure, quantile):
    """BEM gap of a 64^2 spectral surface near the percolation threshold (A* 0.4-0.5) with
    the contact-edge cells below the ``quantile`` of their gaps set to 1e-12 m (the residual
    gap BEM leaves on real topographies): ``(surface, gap)``."""
    from scipy import ndimage

    from roughfe.bem import Material, solve_contact
    from roughfe.surfaces.spectral import spectral_surface
    s = spectral_surface(64, 1e-4, 0.8, rms_height=1e-6, rng=seed)
    g = solve_contact(s, Material(1e9, 0.3), mean_pressure=mean_pressure).gap.copy()
    edge = (g > 0) & ndimage.binary_dilation(g == 0)
    g[edge & (g <= np.quantile(g[edge], quantile))] = 1e-12
    assert 0.4 < np.mean(g == 0) < 0.5
    return s, g


def test_one_sided_components_are_exact_at_the_threshold_and_match_lu():
    """BEM contact of a 64^2 spectral surface at A* = 0.44 with its contact-edge cells at a
    residual gap of 1e-12 m (as BEM leaves on real topographies): reservoirs hang on the
    inlet or outlet through junctions ~1e17 times weaker, below the round-off of their
    diagonal. Along y nothing percolates and CG + BoomerAMG stopped with
    DIVERGED_INDEFINITE_MAT on the components reaching one side only (they carry no flow
    without wall motion: p = p_in or p_out exactly, now no unknowns); along x those
    components had moved the leak rate 2 % off the LU solve's. Both now match MUMPS LU."""
    from roughfe.leakage.finite_volume import components_reaching, solve_reynolds_fv
    s, g = _threshold_gap(12, 6e7, 0.1)
    lu = {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}
    p_in, p_out = 3e5 + DP, 3e5
    kw = dict(mu=MU, p_in=p_in, p_out=p_out)
    for direction, flows in (("x", True), ("y", False)):
        cg = solve_reynolds_fv(g, s.spacing, direction=direction, **kw)
        direct = solve_reynolds_fv(g, s.spacing, direction=direction, petsc_options=lu, **kw)
        assert cg.success and cg.percolates is flows and direct.percolates is flows
        assert cg.leak_rate == approx(direct.leak_rate, rel=1e-6)
        assert (cg.leak_rate > 0) is flows
        gt = g if direction == "x" else g.T
        lab, t_in, t_out = components_reaching(gt > 0)
        p = cg.pressure if direction == "x" else cg.pressure.T
        ok = lab >= 0
        assert np.all(p[ok & (t_in & ~t_out)[np.maximum(lab, 0)]] == p_in)
        assert np.all(p[ok & (t_out & ~t_in)[np.maximum(lab, 0)]] == p_out)


def test_krylov_breakdown_at_the_threshold_is_solved_by_mumps_lu(monkeypatch):
    """A percolating film with dead-end reservoirs hanging on it through 1e-12 m junctions
    (64^2 BEM gap, A* = 0.45): CG + BoomerAMG stops with DIVERGED_INDEFINITE_PC after 14
    iterations along x (it raised NoConvergenceError); the same matrix is now solved by
    MUMPS LU and the message says so. Ordinary systems never take the fallback, a stall
    (DIVERGED_MAX_IT) still raises, and so does a breakdown above the size bound."""
    from roughfe.errors import NoConvergenceError
    from roughfe.fem import dissipation
    from roughfe.leakage.finite_volume import solve_reynolds_fv
    s, g = _threshold_gap(5, 5.05e7, 0.5)
    lu = {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}
    direct = solve_reynolds_fv(g, s.spacing, petsc_options=lu)
    r = solve_reynolds_fv(g, s.spacing)
    assert r.success and r.percolates and direct.leak_rate > 0
    assert r.leak_rate == approx(direct.leak_rate, rel=1e-6)
    assert "cg/hypre broke down (DIVERGED_INDEFINITE" in r.message
    assert "solved by MUMPS LU" in r.message
    rng = np.random.default_rng(4)
    ordinary = np.maximum(rng.standard_normal((24, 20)) + 0.5, 0.0) * H
    cg = solve_reynolds_fv(ordinary, (DX, DX), mu=MU, p_in=DP, p_out=0.0)
    assert cg.percolates and cg.nit > 1 and "MUMPS" not in cg.message
    assert cg.message.startswith("KSP cg/hypre CONVERGED_RTOL")
    with pytest.raises(NoConvergenceError, match="DIVERGED_MAX_IT"):
        solve_reynolds_fv(ordinary, (DX, DX), mu=MU, p_in=DP, p_out=0.0,
                          petsc_options={"ksp_max_it": 1})
    monkeypatch.setattr(dissipation, "DIRECT_MAX_UNKNOWNS", 100)
    with pytest.raises(NoConvergenceError, match="no MUMPS LU fallback"):
        solve_reynolds_fv(g, s.spacing)


def test_a_direct_solve_of_the_caller_is_not_continued():
    # a user's preonly/LU solver went through the tolerance continuation: the same
    # factors solved again, and the message reported "continued to rtol 8.3e-15"
    from roughfe.leakage.finite_volume import solve_reynolds_fv
    g, conductance = _pinhole_wall(1e-11)
    lu = {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}
    r = solve_reynolds_fv(g, (DX, DX), mu=MU, p_in=1.0, p_out=0.0, petsc_options=lu)
    assert r.leak_rate == approx(conductance, rel=1e-6, abs=0)
    assert "continued" not in r.message and r.nit == 1


def test_a_sweep_names_the_step_of_a_leakage_warning(monkeypatch):
    """A Reynolds flow imbalance warned of inside a sweep said neither its step nor its
    load (a user's review, round 2, session 29): ``leakage_sweep`` re-issues each step's
    warnings, same category, with the step (from 0, as the records) and its p and Delta."""
    import warnings

    from roughfe.errors import FlowImbalanceWarning
    from roughfe.leakage import analysis
    from roughfe.model import Material
    from roughfe.surfaces.spectral import spectral_surface

    real = analysis.leakage_of_contact
    calls = []

    def warns_on_the_second(contact, **kw):
        calls.append(contact)
        if len(calls) == 2:
            warnings.warn("inlet and outlet flows differ", FlowImbalanceWarning)
        return real(contact, **kw)

    monkeypatch.setattr(analysis, "leakage_of_contact", warns_on_the_second)
    s = spectral_surface(32, 1e-4, 0.8, rms_height=1e-6, rng=0)
    with pytest.warns(FlowImbalanceWarning) as record:
        sweep = analysis.leakage_sweep(s, Material(1e9, 0.3), pressures=[1e6, 1e7])
    c = sweep.contacts[1]
    assert [str(w.message) for w in record if w.category is FlowImbalanceWarning] == [
        f"step 1 (p = {c.mean_pressure:.4g} Pa, Delta = {c.delta:.4g} m): inlet and outlet "
        f"flows differ"]


def test_a_reynolds_solve_beyond_the_memory_is_refused_naming_its_unknowns(monkeypatch):
    """A gap whose system and AMG hierarchy cannot fit was left to the OOM killer. The
    check counts the unknowns (the cells of the components that join inlet and outlet:
    the closed cells of the barrier are none) and refuses before PETSc sees the system;
    with the memory it needs, the same gap solves."""
    from roughfe import errors
    from roughfe.leakage.finite_volume import (REYNOLDS_BYTES_PER_CELL,
                                               REYNOLDS_BYTES_PER_UNKNOWN, solve_reynolds_fv)

    g = np.full((40, 30), 1e-6)
    g[20, :] = 0.0
    g[20, 10:15] = 1e-6            # one opening in a closed barrier: still percolating
    unknowns = g.size - 25          # the barrier's 25 closed cells
    need = REYNOLDS_BYTES_PER_CELL * g.size + REYNOLDS_BYTES_PER_UNKNOWN * unknowns
    monkeypatch.setattr(errors, "available_memory", lambda: need - 1)
    with pytest.raises(errors.MemoryShortage,
                       match=f"the Reynolds solve of a 40 x 30 gap \\({unknowns} unknowns\\)"):
        solve_reynolds_fv(g, (1e-6, 1e-6))
    monkeypatch.setattr(errors, "available_memory", lambda: need)
    assert solve_reynolds_fv(g, (1e-6, 1e-6)).leak_rate > 0
