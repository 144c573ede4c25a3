"""The 1D PSD along x / along y of a map (contact.engineering's line PSD) and the ISO
7-point rms slope (Rdq / Sdq): Parseval per line, the 2D PSD summed over the other
component, waves along one direction, isotropy, analytic slopes of waves, and
SurfaceTopography's own numbers on a measured file."""
import numpy as np
import pytest

from roughfe.errors import InputError
from roughfe.surfaces import Surface, power_spectrum, spectral_surface
from roughfe.surfaces.iso_slope import ISO_WEIGHTS, rms_slope_iso
from roughfe.surfaces.line_psd import line_power_spectrum, line_spectra
from roughfe.surfaces.stats import rms_slope


def _hann(n):
    w = 0.5 - 0.5 * np.cos(2 * np.pi * np.arange(n) / (n - 1))
    return w / np.sqrt(np.mean(w ** 2))


@pytest.mark.parametrize("periodic", [True, False])
@pytest.mark.parametrize("direction", ["x", "y"])
def test_parseval_per_line(periodic, direction):
    """sum(C weight) of the line PSD is the mean over the lines of each line's variance
    (of the windowed line with the Hann window, built here from its definition), i.e.
    the map's variance less the variance of the line means; odd and even line lengths."""
    shape, size = (37, 52), (1e-4, 1.3e-4)
    h = np.random.default_rng(11).standard_normal(shape) * 1e-8 + 3e-8
    h += np.linspace(0, 4e-8, shape[1])[None, :]            # line means that differ
    s = Surface(h, size, periodic=periodic)
    lines = h if direction == "x" else h.T                   # lines along axis 0
    psd = line_power_spectrum(s, direction, window="none")
    assert psd.ndim == 1 and psd.window == "none"
    assert psd.mean_square == pytest.approx(np.mean(np.var(lines, axis=0)), rel=1e-12, abs=0)
    assert psd.mean_square < np.var(h)                       # the line means are not in it
    w = _hann(lines.shape[0])[:, None]
    windowed = (lines - lines.mean(axis=0)) * w
    hann = line_power_spectrum(s, direction, window="hann")
    assert hann.mean_square == pytest.approx(np.mean(np.var(windowed, axis=0)), rel=1e-12, abs=0)
    auto = line_power_spectrum(s, direction)
    assert auto.window == ("none" if periodic else "hann")


def test_line_psd_is_the_2d_psd_summed_over_the_other_component():
    """Without a window, C_x(q_x) = sum_{q_y} C(q_x, q_y) dq_y over the full 2D
    periodogram (C = |h~|^2 / (dqx dqy), as in stats): an independent route through the
    2D FFT of the whole map."""
    shape, size = (48, 30), (2e-4, 1e-4)
    h = np.random.default_rng(2).standard_normal(shape) * 1e-8
    s = Surface(h, size, periodic=True)
    dqx, dqy = 2 * np.pi / size[0], 2 * np.pi / size[1]
    c2 = np.abs(np.fft.fft2(h - h.mean()) / h.size) ** 2 / (dqx * dqy)
    cx = c2.sum(axis=1) * dqy                                # sum over q_y at each q_x
    cy = c2.sum(axis=0) * dqx
    px, py = line_power_spectrum(s, "x"), line_power_spectrum(s, "y")
    np.testing.assert_allclose(px.C, cx[1: shape[0] // 2 + 1], rtol=1e-10)
    np.testing.assert_allclose(py.C, cy[1: shape[1] // 2 + 1], rtol=1e-10)
    np.testing.assert_allclose(px.q, dqx * np.arange(1, shape[0] // 2 + 1), rtol=1e-14)


def test_waves_along_x_have_no_power_along_y():
    """h = sum a_k cos(q_k x + phi): every line along y is flat, every line along x is
    the same profile (its analytic PSD: a^2 L / (8 pi) at q_k, Persson's; 2 pi times
    that in C_jacobs)."""
    shape, size = (64, 40), (1e-4, 6e-5)
    x = (np.arange(shape[0]) * size[0] / shape[0])[:, None]
    h = 2e-8 * np.cos(2 * np.pi * 5 * x / size[0] + 0.3) + 5e-9 * np.cos(
        2 * np.pi * 11 * x / size[0] + 1.0) + np.zeros(shape)
    s = Surface(h, size, periodic=True)
    py = line_power_spectrum(s, "y")
    assert np.max(py.C) < 1e-28 * np.max(line_power_spectrum(s, "x").C) + 1e-300
    px = line_power_spectrum(s, "x")
    peaks = {int(round(q * size[0] / (2 * np.pi))): c for q, c in zip(px.q, px.C)
             if c > 1e-6 * px.C.max()}
    assert set(peaks) == {5, 11}
    assert peaks[5] == pytest.approx(2e-8 ** 2 * size[0] / (8 * np.pi), rel=1e-10, abs=0)
    assert px.C_jacobs[4] == pytest.approx(2e-8 ** 2 * size[0] / 4, rel=1e-10, abs=0)
    # non-periodic with the default Hann window: still no power along y
    assert np.max(line_power_spectrum(Surface(h, size), "y").C) < 1e-20 * peaks[5]


def _z_scores(s, scatter_of=None):
    """(C_x - C_y) / its standard deviation at q_x = q_y. C_x(q) = sum over q_y of 2D
    periodogram values c_i dq_y (test above), independent exponential variables for a
    Gaussian surface: var = sum mu_i^2 dq^2, estimated by sum c_i^2 / 2 (E c^2 = 2 mu^2)
    on ``scatter_of`` (default ``s``)."""
    cx = line_power_spectrum(s, "x").C[:-1]
    cy = line_power_spectrum(s, "y").C[:-1]
    s = s if scatter_of is None else scatter_of
    n, length = s.shape[0], s.size[0]
    dq = 2 * np.pi / length
    c2 = np.abs(np.fft.fft2(s.heights) / s.heights.size) ** 2 / dq ** 2
    k = np.arange(1, n // 2)                   # the Nyquist value left out
    var = ((c2[k, :] ** 2).sum(axis=1) + (c2[:, k] ** 2).sum(axis=0)) / 2 * dq ** 2
    return (cx - cy) / np.sqrt(var)


def test_isotropic_surface_has_equal_x_and_y_psds_within_their_scatter():
    """A Gaussian isotropic spectral surface (square, periodic): C_x - C_y is within its
    statistical scatter at each q (z-scores of rms 0.6-1.5, mean within 4 standard errors
    of 0); a lay (cosine grooves across x, 3 Sq) is beyond 30 of those standard
    deviations at its wavenumber and nowhere else."""
    s = spectral_surface(256, 1e-4, hurst=0.8, rms_height=1e-7, rng=4)
    z = _z_scores(s)
    assert 0.6 < np.sqrt(np.mean(z ** 2)) < 1.5, z
    assert abs(np.mean(z)) < 4 / np.sqrt(z.size), z
    groove = 3e-7 * np.cos(2 * np.pi * 20 * np.arange(256) / 256)[:, None]
    zg = _z_scores(Surface(s.heights + groove, s.size, periodic=True), scatter_of=s)
    assert zg[19] > 30, zg[19]
    np.testing.assert_allclose(np.delete(zg, 19), np.delete(z, 19), rtol=1e-8)


def test_profiles_and_bad_directions():
    """A profile's x PSD is its PSD; a profile has no y; a direction is x or y."""
    prof = Surface(np.random.default_rng(0).standard_normal(100) * 1e-8, 1e-4)
    a, b = line_power_spectrum(prof, "x"), power_spectrum(prof)
    np.testing.assert_array_equal(a.C, b.C)
    assert line_spectra(prof) == {}
    with pytest.raises(InputError, match="direction 'y' needs a 2D surface"):
        line_power_spectrum(prof, "y")
    with pytest.raises(InputError, match="direction must be 'x' or 'y', got 'z'"):
        line_power_spectrum(Surface(np.zeros((8, 8)), 1e-5), "z")


def test_line_psd_equals_surface_topography_on_a_measured_file(topographies_dir):
    """x3p-2.x3p (grooved, non-periodic, 650 x 650): SurfaceTopography's
    power_spectrum_from_profile of the map (along x) and of its transpose (along y) is
    2 pi times roughfe's C. Without a window to 1e-10 at every q it reports. With the
    Hann window along the lines (its window("hann", direction="x")) per value within 2 %
    (measured 0.989-1.003) and in the median within 0.3 % from q = 2 dq on: its Hann is
    scipy's periodic one (n in the cosine's period, ours n - 1) and it keeps each line's
    mean, whose product with the window has power at q = dq (1.07x and 1.64x ours)."""
    st = pytest.importorskip("SurfaceTopography")
    from roughfe.surfaces.io import load_surface
    path = topographies_dir / "x3p-2.x3p"
    theirs = st.open_topography(str(path)).topography(channel_index=0)
    to_m = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "nm": 1e-9}[theirs.unit]
    ours = load_surface(path)
    for direction, topo in (("x", theirs), ("y", theirs.transpose())):
        q, c = topo.power_spectrum_from_profile(window="None", reliable=False,
                                                resampling_method=None)
        psd = line_power_spectrum(ours, direction, window="none")
        n = q.size                         # q = 0 .. (n - 1) dq: no Nyquist value
        np.testing.assert_allclose(q[1:] / to_m, psd.q[: n - 1], rtol=1e-12)
        np.testing.assert_allclose(c[1:] * to_m ** 3, psd.C_jacobs[: n - 1], rtol=1e-10)
        q, c = topo.window("hann", direction="x").power_spectrum_from_profile(
            window="None", reliable=False, resampling_method=None)
        ratio = c[2:] * to_m ** 3 / line_power_spectrum(ours, direction).C_jacobs[1: n - 1]
        assert np.all(np.abs(ratio - 1) < 0.02), (ratio.min(), ratio.max())
        assert abs(np.median(ratio) - 1) < 3e-3


# -- ISO 7-point rms slope -------------------------------------------------------------
def _stencil_gain(theta):
    """The 7-point stencil on cos(k x): -sin(k x) times this / dx (theta = k dx)."""
    return (45 * np.sin(theta) - 9 * np.sin(2 * theta) + np.sin(3 * theta)) / 30


def test_iso_weights_are_iso_4287s_formula():
    """(1/60 dx)(h[i+3] - 9 h[i+2] + 45 h[i+1] - 45 h[i-1] + 9 h[i-2] - h[i-3]): exact
    on polynomials up to degree 6 (the derivative of x^7 is the first it misses)."""
    np.testing.assert_array_equal(ISO_WEIGHTS * 60, [-1, 9, -45, 0, 45, -9, 1])
    x = np.arange(40) * 0.25
    for p in range(7):
        s = Surface(x ** p, 10.0, periodic=False)        # spacing 0.25
        exact = np.sqrt(np.mean((p * x[3:-3] ** max(p - 1, 0)) ** 2)) if p else 0.0
        assert rms_slope_iso(s) == pytest.approx(exact, rel=1e-9, abs=1e-9)


def _wave_slope_errors(points_per_wave):
    """Relative errors of rms_slope (forward differences) and rms_slope_iso on
    h = a cos(k x) over 40 periods, non-periodic, against the rms of the analytic slope
    a k sin(k x) at the points where each is evaluated (forward: the midpoints)."""
    a, n_per = 1e-7, points_per_wave
    n, dx = 40 * n_per, 1e-6
    k = 2 * np.pi / (n_per * dx)
    x = np.arange(n) * dx
    s = Surface(a * np.cos(k * x), n * dx, periodic=False)
    fwd_exact = a * k * np.sqrt(np.mean(np.sin(k * (x[:-1] + dx / 2)) ** 2))
    iso_exact = a * k * np.sqrt(np.mean(np.sin(k * x[3:-3]) ** 2))
    return rms_slope(s) / fwd_exact - 1, rms_slope_iso(s) / iso_exact - 1, k * dx


@pytest.mark.parametrize("points_per_wave", [6, 8, 12, 16, 24])
def test_slopes_of_a_wave_have_the_stencils_analytic_errors(points_per_wave):
    """Forward differences are off by sin(k dx/2)/(k dx/2) - 1 (-4.5 % at 6 points per
    wave), the ISO stencil by its gain / (k dx) - 1 (-0.76 %; ~(k dx)^6 / 140)."""
    fwd_err, iso_err, theta = _wave_slope_errors(points_per_wave)
    assert fwd_err == pytest.approx(np.sin(theta / 2) / (theta / 2) - 1, rel=1e-6, abs=0)
    assert iso_err == pytest.approx(_stencil_gain(theta) / theta - 1, rel=1e-6, abs=0)
    assert abs(iso_err) == pytest.approx(theta ** 6 / 140, rel=0.35, abs=0)
    assert abs(iso_err) < abs(fwd_err) / 5
    if points_per_wave >= 16:        # the ISO slope within 1e-4, the forward one not
        assert abs(iso_err) < 1e-4 < abs(fwd_err)


def test_both_slopes_converge_the_iso_one_at_sixth_order():
    """Observed orders between 8, 16 and 32 points per wave: 2 (forward) and 6 (ISO)."""
    errs = np.array([_wave_slope_errors(n)[:2] for n in (8, 16, 32)])
    orders = np.log2(np.abs(errs[:-1] / errs[1:]))
    np.testing.assert_allclose(orders[:, 0], 2.0, atol=0.05)
    np.testing.assert_allclose(orders[:, 1], 6.0, atol=0.15)


def test_iso_slope_of_periodic_waves_and_a_surface():
    """Periodic data wrap: on a surface of waves, Sdq^2 is the sum over waves and axes
    of (a q_i gain(q_i dx_i) / (q_i dx_i))^2 / 2, and the spectral slope is the exact
    one; short grids (fewer than 7 points, non-periodic) give NaN."""
    shape, size = (64, 48), (1e-4, 6e-5)
    dx = [sz / n for sz, n in zip(size, shape)]
    g = np.meshgrid(*[np.arange(n) * d for n, d in zip(shape, dx)], indexing="ij")
    waves = [(3e-8, (3, 2)), (1e-8, (9, -5))]
    h = sum(a * np.cos(2 * np.pi * (kx * g[0] / size[0] + ky * g[1] / size[1]) + 0.7)
            for a, (kx, ky) in waves)
    expect = 0.0
    exact = 0.0
    for a, ks in waves:
        for kk, sz, d in zip(ks, size, dx):
            q = 2 * np.pi * kk / sz
            expect += (a * _stencil_gain(abs(q) * d) / d) ** 2 / 2
            exact += (a * q) ** 2 / 2
    s = Surface(h, size, periodic=True)
    assert rms_slope_iso(s) == pytest.approx(np.sqrt(expect), rel=1e-10, abs=0)
    assert rms_slope(s) == pytest.approx(np.sqrt(exact), rel=1e-10, abs=0)
    # below the spectral slope by the 9.6-points-per-wave component's stencil error
    assert 0.999 < rms_slope_iso(s) / rms_slope(s) < 1
    assert np.isnan(rms_slope_iso(Surface(np.zeros((6, 10)), (1e-5, 1e-5))))


def test_iso_slope_equals_surface_topography_with_the_iso_stencil(topographies_dir):
    """SurfaceTopography's derivative with the ISO stencil as a muFFT operator (its
    own operators are first-order; it offers custom stencils) on x3p-2.x3p, each axis'
    mean square over the points its stencil reaches: equal to roughfe's Sdq to 1e-9."""
    st = pytest.importorskip("SurfaceTopography")
    muFFT = pytest.importorskip("muFFT")
    from roughfe.surfaces.io import load_surface
    path = topographies_dir / "x3p-2.x3p"
    theirs = st.open_topography(str(path)).topography(channel_index=0)
    w = list(ISO_WEIGHTS)
    ops = (muFFT.DiscreteDerivative([-3, 0], [[c] for c in w]),
           muFFT.DiscreteDerivative([0, -3], [w]))
    dx, dy = theirs.derivative(1, operator=ops)
    to_m = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "nm": 1e-9}[theirs.unit]
    ours = load_surface(path)
    sdq = np.sqrt(np.mean(dx ** 2) + np.mean(dy ** 2))
    assert rms_slope_iso(ours) == pytest.approx(sdq, rel=1e-9, abs=0)
    assert dx.shape == (ours.shape[0] - 6, ours.shape[1]) and to_m > 0


# -- CLI and figure ----------------------------------------------------------------------
def test_info_psd_writes_the_line_psds_as_csv_and_png(tmp_path, capsys):
    """roughfe info --psd FILE.csv: the radial PSD and the x and y line PSDs, each row
    equal to the library's (C and C_jacobs = 2 pi C or (2 pi)^2 C); an existing file
    needs --overwrite; .png draws the line PSDs in a second panel."""
    from roughfe.cli import main
    from roughfe.surfaces import save_surface
    x = np.arange(40)[:, None] * 1e-6
    h = 1e-8 * np.cos(2 * np.pi * 4 * x / 40e-6) + 1e-9 * np.random.default_rng(1) \
        .standard_normal((40, 30))
    s = Surface(h, (40e-6, 30e-6))
    path, csv = tmp_path / "s.npz", tmp_path / "psd.csv"
    save_surface(s, path)
    assert main(["info", str(path), "--detrend", "none", "--psd", str(csv)]) == 0
    rows = [r.split(",") for r in csv.read_text().splitlines()[1:]]
    for kind, ref in (("x", line_power_spectrum(s, "x")), ("y", line_power_spectrum(s, "y")),
                      ("radial", power_spectrum(s))):
        got = np.array([[float(v) for v in r[1:5]] for r in rows if r[0] == kind])
        np.testing.assert_allclose(got[:, 0], ref.q, rtol=1e-9)
        np.testing.assert_allclose(got[:, 1], ref.C, rtol=1e-9)
        np.testing.assert_allclose(got[:, 2], ref.C_jacobs, rtol=1e-9)
        assert {r[5] for r in rows if r[0] == kind} == {"hann"}
    assert main(["info", str(path), "--psd", str(csv)]) == 2
    assert "pass --overwrite" in capsys.readouterr().err
    assert main(["info", str(path), "--psd", str(tmp_path / "p.txt")]) == 2
    assert main(["info", str(path), "--psd", str(tmp_path / "p.png")]) == 0
    assert (tmp_path / "p.png").stat().st_size > 0


def test_psd_figure_draws_the_line_psds_in_a_second_panel(monkeypatch, tmp_path):
    from roughfe.plotting import surfaces as surface_plot
    kept = []
    monkeypatch.setattr(surface_plot, "save_figure", lambda fig, path, dpi=150:
                        kept.append(fig) or path)
    s = spectral_surface(32, 1e-5, hurst=0.8, rms_height=1e-8, rng=0)
    surface_plot.plot_psd({"s": power_spectrum(s)}, tmp_path / "f.png",
                          lines=line_spectra(s))
    ax0, ax1 = kept[-1].axes
    drawn = {ln.get_label(): ln for ln in ax1.get_lines()}
    assert set(drawn) == {"along x", "along y"}
    np.testing.assert_array_equal(drawn["along y"].get_ydata(),
                                  line_power_spectrum(s, "y").C)
    assert "m$^3$" in ax1.get_ylabel() and "m$^4$" in ax0.get_ylabel()
    surface_plot.plot_psd({"s": power_spectrum(s)}, tmp_path / "f.png")
    assert len(kept[-1].axes) == 1
