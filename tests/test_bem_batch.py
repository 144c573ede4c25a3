"""The batched contact solvers (roughfe.bem.batch) against the single solver, an analytic
solution and themselves: exact pivoting gives the single dense solver's contact states
to round-off (load and displacement control, warm-started sweeps), the batched CG agrees
to its tolerance, a row does not depend on the rows beside it, and a cylinder's contact
half-width follows plane-strain Hertz."""
import numpy as np
import pytest

from roughfe.bem import contact_sweep, influence_operator, solve_contact
from roughfe.bem.batch import solve_batch
from roughfe.bem.batch_exact import batch_sweep, solve_batch_exact
from roughfe.errors import InputError
from roughfe.model import Material, central_differences
from roughfe.surfaces import Surface

N, L = 256, 1e-3
MAT = Material(1e6, 0.0)


def profiles(B, seed=0):
    """B random profiles: a few cosines of random phases (rough, contact on a few peaks)."""
    rng = np.random.default_rng(seed)
    x = np.arange(N) * L / N
    k = np.arange(1, 9)
    amp = 1e-6 * k ** -1.6
    ph = rng.uniform(0, 2 * np.pi, (B, k.size))
    return np.einsum("k,bkx->bx", amp, np.cos(2 * np.pi * k[None, :, None] * x / L + ph[..., None]))


def op():
    return influence_operator((N,), (L,), MAT.E_star, "strip")


def surface(h):
    return Surface(h, (L,), periodic=False)


@pytest.mark.parametrize("kernel, shape", [("strip", (48,)), ("spectral", (40,)),
                                           ("spectral", (16, 12)), ("love", (10, 8))])
def test_stacked_products_are_the_single_field_products(kernel, shape):
    """The batched operator is the single-field convolution over the trailing axes: a
    stack of B fields gives each field's own product (to rounding: the same transforms,
    one thread) and H equals its dense matrix; the preconditioner is M = the inverse
    spectrum's circular convolution, row by row as on one field."""
    from roughfe.bem.batch import BatchOperator
    rng = np.random.default_rng(5)
    o = influence_operator(shape, [1e-3] * len(shape), 1e9, kernel)
    bop = BatchOperator(o)
    p = rng.random((3,) + shape)
    u, z = bop.apply(p), bop.precondition(p)
    assert u.shape == z.shape == p.shape
    dense = o.dense()
    for b in range(3):
        np.testing.assert_allclose(u[b], o.apply(p[b]), rtol=0, atol=1e-14 * np.abs(u).max())
        np.testing.assert_allclose(u[b].reshape(-1), dense @ p[b].reshape(-1), rtol=0,
                                   atol=1e-12 * np.abs(u).max())
        np.testing.assert_allclose(z[b], o.precondition(p[b], bop.inverse), rtol=0,
                                   atol=1e-14 * np.abs(z).max())
    if o.periodic:     # M inverts H exactly off the zero mode
        np.testing.assert_allclose(bop.precondition(u), p - p.mean(axis=tuple(
            range(1, p.ndim)), keepdims=True), rtol=0, atol=1e-12)


@pytest.mark.parametrize("control", ["delta", "mean_pressure"])
def test_exact_batch_equals_the_single_dense_solver(control):
    h = profiles(6)
    value = 0.3 * np.ptp(h, axis=1) if control == "delta" else np.full(6, 2e3)
    st = solve_batch_exact(op(), h, **{control: value})
    for b in range(6):
        r = solve_contact(surface(h[b]), MAT, kernel="strip", solver="dense",
                          compute_stiffness=False, **{control: float(value[b])})
        assert st.n_contact[b] == r.n_contact > 0
        np.testing.assert_allclose(st.pressure[b], r.pressure, rtol=0,
                                   atol=1e-9 * r.pressure.max())
        assert st.delta[b] == pytest.approx(r.delta, rel=1e-10, abs=0)
        assert st.mean_pressure[b] == pytest.approx(r.mean_pressure, rel=1e-10)
    assert np.all(st.residual < 1e-10)


def test_batched_cg_agrees_to_its_tolerance_and_rows_are_independent():
    h = profiles(5, seed=1)
    pk = solve_batch(op(), h, mean_pressure=np.linspace(1e3, 4e3, 5), tol=1e-10)
    ex = solve_batch_exact(op(), h, mean_pressure=np.linspace(1e3, 4e3, 5))
    np.testing.assert_array_equal(pk.n_contact, ex.n_contact)
    np.testing.assert_allclose(pk.delta, ex.delta, rtol=1e-8)
    assert np.all(pk.residual <= 1e-10)
    alone = solve_batch_exact(op(), h[2:3], mean_pressure=2.5e3)
    np.testing.assert_array_equal(alone.pressure[0], ex.pressure[2])       # same arithmetic
    d = solve_batch(op(), h, delta=0.2 * np.ptp(h, axis=1))
    r = solve_contact(surface(h[3]), MAT, kernel="strip", solver="dense",
                      delta=0.2 * float(np.ptp(h[3])), compute_stiffness=False)
    assert d.n_contact[3] == r.n_contact and d.mean_pressure[3] == pytest.approx(
        r.mean_pressure, rel=1e-7)


@pytest.mark.parametrize("method", ["exact", "pk"])
def test_sweep_equals_contact_sweep_area_and_stiffness(method):
    h = profiles(4, seed=2)
    p = np.geomspace(3e2, 2e4, 8)
    pr = p[None, :] * np.array([1.0, 0.7, 1.3, 1.1])[:, None]
    sw = batch_sweep(op(), h, pr, method=method)
    for b in range(4):
        ref = contact_sweep(surface(h[b]), MAT, pressures=tuple(pr[b]), kernel="strip",
                            compute_stiffness=False)
        np.testing.assert_array_equal(np.round(sw.area_fraction[b] * N),
                                      np.round(np.asarray(ref.area_fraction) * N))
        tol = 1e-10 if method == "exact" else 1e-7
        np.testing.assert_allclose(sw.delta[b], ref.delta, rtol=tol)
        np.testing.assert_allclose(sw.stiffness[b], central_differences(ref.delta, ref.mean_pressure),
                                   rtol=100 * tol)


@pytest.mark.parametrize("method", ["exact", "pk"])
def test_displacement_sweep_equals_contact_sweep(method):
    """batch_sweep(deltas=) (displacement control, each row at its own increasing
    approaches; exact: from the top state's contact sets by Schur complements) gives
    contact_sweep's contact counts, mean pressures and K = dp/dDelta at those approaches."""
    h = profiles(4, seed=3)
    dl = np.ptp(h, axis=1)[:, None] * np.arange(1, 9) / 8
    top = solve_batch_exact(op(), h, delta=np.ptp(h, axis=1)) if method == "exact" else None
    sw = batch_sweep(op(), h, deltas=dl, method=method, top=top)
    tol = 1e-10 if method == "exact" else 1e-7
    for b in range(4):
        ref = contact_sweep(surface(h[b]), MAT, deltas=tuple(dl[b]), kernel="strip",
                            compute_stiffness=False)
        np.testing.assert_array_equal(np.round(sw.area_fraction[b] * N),
                                      np.round(np.asarray(ref.area_fraction) * N))
        np.testing.assert_allclose(sw.delta[b], dl[b], rtol=1e-14)
        np.testing.assert_allclose(sw.mean_pressure[b], ref.mean_pressure, rtol=tol)
        np.testing.assert_allclose(sw.stiffness[b], ref.stiffness_fd, rtol=100 * tol)
    with pytest.raises(InputError, match="exactly one"):
        batch_sweep(op(), h, dl, deltas=dl)
    with pytest.raises(InputError, match="deltas must be"):
        batch_sweep(op(), h, deltas=dl[:, ::-1])


def test_cylinder_follows_plane_strain_hertz():
    """A parabolic profile h = -x^2/(2R) under a line load P': a = sqrt(4 R P'/(pi E*))
    (Johnson 1985, Eq. 4.43); the node count 2a/dx within two nodes, in every row of a
    batch of different loads."""
    x = (np.arange(N) - N / 2 + 0.5) * L / N
    R = 5e-3
    h = np.tile(-x ** 2 / (2 * R), (3, 1))
    pm = np.array([0.5, 1.0, 2.0]) * 1e3                 # mean pressure over L (Pa)
    st = solve_batch_exact(op(), h, mean_pressure=pm)
    a = np.sqrt(4 * R * pm * L / (np.pi * MAT.E_star))
    assert np.all(np.abs(st.n_contact - 2 * a / (L / N)) <= 2)
    assert np.all(np.diff(st.n_contact) > 0)


def test_bad_input_is_refused():
    h = profiles(2)
    with pytest.raises(InputError, match="exactly one"):
        solve_batch_exact(op(), h)
    with pytest.raises(InputError, match="shape"):
        solve_batch(op(), h[:, :10], delta=1e-7)
    with pytest.raises(InputError, match="flat"):
        solve_batch_exact(op(), np.zeros((2, N)), delta=1e-7)
    with pytest.raises(InputError, match="increasing"):
        batch_sweep(op(), h, np.array([[2.0, 1.0], [1.0, 2.0]]))
    bad = h.copy()
    bad[1, 7] = np.inf
    for call in (lambda: solve_batch(op(), bad, delta=1e-7),
                 lambda: solve_batch_exact(op(), bad, delta=1e-7),
                 lambda: batch_sweep(op(), bad, np.array([[1.0, 2.0], [1.0, 2.0]]))):
        with pytest.raises(InputError, match=r"heights must be finite: 1 non-finite"):
            call()
    with pytest.raises(InputError, match="pressures must be a numeric array"):
        batch_sweep(op(), h, "light")
    with pytest.raises(InputError, match="profile operator"):
        solve_batch_exact(influence_operator((N,), (L,), 1e6, "spectral"), h, delta=1e-7)
    with pytest.raises(InputError, match="mean_pressure"):
        solve_batch(op(), h, mean_pressure=np.array([1.0, -1.0]))


def test_schur_complement_on_the_top_set_equals_the_direct_solves():
    """set_inverse of the p_max state and the Schur complement of its subsets give the
    direct solutions of H_FF x = [c_F, 1] to round-off; a sweep warm-started with that
    basis equals the sweep without it (the same exact contact states)."""
    from roughfe.bem.batch_exact import _set_solutions, set_inverse
    h = profiles(4, seed=5)
    o = op()
    top = solve_batch_exact(o, h, delta=np.ptp(h, axis=1))
    basis = set_inverse(o, top)
    c = h - h.max(axis=1, keepdims=True)
    F = top.pressure > 0
    for b in range(4):                                   # leave some points of U out
        F[b, np.flatnonzero(F[b])[: 2 + b]] = False
    direct = _set_solutions(o.dense(), c, F)
    schur = _set_solutions(o.dense(), c, F, basis, np.arange(4))

    def scatter(idx, valid, x):
        out = np.zeros((4, N, 2))
        r, s = np.nonzero(valid)
        out[r, idx[r, s]] = x[r, s]
        return out
    a, b = scatter(*direct), scatter(*schur)
    assert np.abs(a - b).max() <= 1e-12 * np.abs(a).max()
    pr = np.geomspace(0.05, 1.0, 8)[None, :] * top.mean_pressure[:, None]
    s1, s2 = batch_sweep(o, h, pr), batch_sweep(o, h, pr, top=top)
    np.testing.assert_array_equal(s1.area_fraction, s2.area_fraction)
    np.testing.assert_allclose(s2.delta, s1.delta, rtol=1e-12)


def test_batched_and_single_field_cg_are_one_algorithm():
    """solve_batch (masked full rows) and pk.polonsky_keer (gathered free set) share the
    CG's pieces (solvers.pr_beta, step_length, relative_residual): on one periodic
    field they take the same iterations to the same state. The pieces give the same
    numbers as scalars (pk) and per row (batch); tau is the exact minimiser of the
    quadratic energy along t; beta restarts (0) without a previous iteration."""
    import functools
    from roughfe.bem.contact import _cg_preconditioner
    from roughfe.bem.pk import polonsky_keer
    from roughfe.bem.solvers import pr_beta, relative_residual, step_length
    from roughfe.surfaces.spectral import spectral_surface
    s = spectral_surface(128, 1e-3, 0.8, rms_slope=1.0, rng=3)
    h = s.heights
    o = influence_operator(h.shape, s.size, MAT.E_star)
    pm = 0.05 * MAT.E_star
    st = solve_batch(o, h[None], mean_pressure=pm, tol=1e-10)
    pk = polonsky_keer(o.apply, h, float(np.ptp(h)), mean_pressure=pm, offset=-h.max(),
                       precond=_cg_preconditioner(o),
                       apply_single=functools.partial(o.apply, single=True))
    assert abs(int(st.nit[0]) - pk.nit) <= 1
    np.testing.assert_array_equal(st.pressure[0] > 0, pk.pressure > 0)
    np.testing.assert_allclose(st.pressure[0], pk.pressure, rtol=0, atol=1e-8 * pk.pressure.max())
    # the pieces, scalar and per row
    num, den = np.array([3.0, -2.0, 1.0, 5.0]), np.array([2.0, 4.0, 0.0, -1.0])
    rows = pr_beta(num, den), step_length(num, den), relative_residual(num, den, den, 2.0)
    for i in range(4):
        assert pr_beta(num[i], den[i]) == rows[0][i] and step_length(num[i], den[i]) == rows[1][i]
        assert relative_residual(num[i], den[i], den[i], 2.0) == rows[2][i]
    np.testing.assert_array_equal(rows[0], [1.5, 0.0, 0.0, 0.0])
    rng = np.random.default_rng(0)
    a = rng.standard_normal((6, 6))
    A, b, x, t = a @ a.T + 6 * np.eye(6), *rng.standard_normal((3, 6))
    g = A @ x - b                                       # gradient of 1/2 x'Ax - b'x
    tau = step_length(g @ t, t @ A @ t)
    energy = [0.5 * y @ A @ y - b @ y for y in (x - (tau + e) * t for e in (-1e-4, 0, 1e-4))]
    assert energy[1] < min(energy[0], energy[2])
