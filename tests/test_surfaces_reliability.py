"""The trace/retrace reliability cutoff (roughfe.surfaces.reliability): synthetic sweeps of
one self-affine surface with independent white noise of known level, shifted by a known
lag; the noise-free and the pure-noise limits; the estimator's null distribution; the
trace/retrace pairing of an instrument file's channels; di-1 (trace vs retrace). The share
of the mean-square slope above a cutoff (slope_share_above): sums of sinusoids (exact),
white noise (the fraction of q^2 above the cutoff), bad cutoffs."""
import numpy as np
import pytest

from roughfe.errors import InputError
from roughfe.surfaces import Surface
from roughfe.surfaces.channels import trace_retrace_partner
from roughfe.surfaces.io import load_surface
from roughfe.surfaces.reliability import (FALSE_ALARM, THRESHOLD, minimum_lines,
                                          slope_share_above, trace_retrace_coherence)
from roughfe.surfaces.spectral import self_affine_psd, spectral_surface

NX, NY, DX = 256, 512, 1e-9          # points per line (fast axis x), lines, spacing (m)


def _surface(hurst, seed):
    """A periodic self-affine map whose PSD is exactly C0 times the shape (fixed
    amplitudes), 1 nm rms, 256 nm x 512 nm."""
    return spectral_surface((NX, NY), (NX * DX, NY * DX), hurst, rms_height=1e-9,
                            amplitudes="fixed", rng=seed)


def _line_psd(surface, hurst):
    """The map's mean line PSD along x from its 2D PSD, C_x(q_x) = sum_qy C(q) dq_y (m^3,
    Persson's normalisation; exact on the grid for fixed amplitudes, line_psd's
    docstring), at q_x = k 2 pi / L_x, k = 1 .. NX/2 - 1 (the generator drops Nyquist)."""
    lx, ly = surface.size
    qx = 2 * np.pi * np.arange(1, NX // 2) / lx
    ky = np.fft.fftfreq(NY, 1.0 / NY)
    qy = 2 * np.pi * ky[np.abs(ky) < NY // 2] / ly
    shape = self_affine_psd(np.hypot(qx[:, None], qy[None, :]), hurst,
                            2 * np.pi / max(lx, ly), np.pi / DX)
    return qx, surface.metadata["C0"] * shape.sum(axis=1) * (2 * np.pi / ly)


def _noisy_pair(hurst, seed, k_star=40, lag=7):
    """Two sweeps of one surface, ``second[i + lag] = first[i]``, each with independent
    white noise whose line PSD, sigma^2 dx / (2 pi), equals the surface's at
    q_x = k_star 2 pi / L_x. Returns (first, second, the crossing q* (rad/m) interpolated
    in log-log, the log-slope beta of surface-over-noise PSD there)."""
    surface = _surface(hurst, seed)
    qx, cx = _line_psd(surface, hurst)
    sigma = np.sqrt(cx[k_star - 1] * 2 * np.pi / DX)
    log_ratio = np.log(cx / (sigma ** 2 * DX / (2 * np.pi)))
    i = int(np.flatnonzero(log_ratio < 0)[0])
    step = np.log(qx[i]) - np.log(qx[i - 1])
    q_star = np.exp(np.log(qx[i - 1]) + log_ratio[i - 1] / (log_ratio[i - 1] - log_ratio[i])
                    * step)
    beta = (log_ratio[i - 1] - log_ratio[i]) / step
    rng = np.random.default_rng(1000 + seed)
    h = surface.heights
    first = Surface(h + sigma * rng.standard_normal(h.shape), surface.size, periodic=False)
    second = Surface(np.roll(h, lag, axis=0) + sigma * rng.standard_normal(h.shape),
                     surface.size, periodic=False)
    return first, second, q_star, beta


def _crossing_tolerance(lines, beta, threshold=THRESHOLD):
    """4 standard deviations of the crossing in ln q: the coherence estimate's standard
    deviation over ``lines`` independent lines, sqrt(2 g (1 - g)^2 / K) (Carter, Knapp &
    Nuttall 1973) at g = 1/4, over the curve's slope there, d g / d ln q = -beta / 4
    (g = 1 / (1 + (q / q*)^beta)^2). 0.14 for K = 512, beta = 2.6; 20 seeds at H = 0.8
    gave ln(q_c / q*) 0.008 +- 0.030 (largest 0.060)."""
    sd = np.sqrt(2 * threshold * (1 - threshold) ** 2 / lines)
    return 4 * sd / (beta / 4)


@pytest.mark.parametrize("hurst, seeds", [(0.8, (0, 1, 2)), (0.3, (3, 4))])
def test_cutoff_is_where_the_surface_psd_equals_the_noise_psd(hurst, seeds):
    for seed in seeds:
        first, second, q_star, beta = _noisy_pair(hurst, seed)
        result = trace_retrace_coherence(first, second)
        assert result.integer_lag == 7 and result.lines == NY and result.points == NX - 7
        tol = _crossing_tolerance(NY, beta)
        assert abs(np.log(result.q_cutoff / q_star)) < tol, (seed, result.q_cutoff, q_star)
        # gamma^2 = 1/2 is P_S / P_N = 2.41, not 1: ln(2.41) / beta = 0.33 below q* at H
        # 0.8, outside the tolerance (the threshold's derivation is what is tested)
        half = trace_retrace_coherence(first, second, threshold=0.5).q_cutoff
        assert np.log(half / q_star) < -tol
        assert np.log(half / q_star) == pytest.approx(-np.log(1 / (np.sqrt(2) - 1)) / beta,
                                                      abs=tol)
        # P_S / P_N from the coherence: 1 at q_c within the same scatter
        at = np.argmin(abs(result.q - q_star))
        assert abs(np.log(result.snr[at - 3: at + 4].mean())) < 0.5


@pytest.mark.parametrize("lag", [7, -5, 0])
def test_without_noise_the_sweeps_agree_up_to_nyquist(lag):
    surface = _surface(0.8, 3)
    second = Surface(np.roll(surface.heights, lag, axis=0), surface.size, periodic=False)
    result = trace_retrace_coherence(surface, second)
    assert result.integer_lag == lag and result.lag == pytest.approx(lag, abs=1e-6)
    assert result.q_cutoff is None and result.coherence.min() > 1 - 1e-9
    n = NX - abs(lag)                  # the aligned lines' points; their last wavenumber
    assert result.points == n and result.q[-1] == pytest.approx(
        (n // 2) * 2 * np.pi / (n * DX), rel=1e-12, abs=0)      # Nyquist (odd n: below)


@pytest.mark.parametrize("lag", [6.4, -5.3])
def test_a_sub_sample_lag_is_recovered_from_the_phase(lag):
    """A Fourier shift by a fraction of a sample: the coherence does not depend on a delay
    common to all lines (>= 0.999 except the last wavenumber, where the surface has no
    power: the generator drops Nyquist), the lag comes from the cross-spectrum's phase."""
    surface = _surface(0.8, 3)
    k = np.fft.fftfreq(NX, 1.0 / NX)[:, None]
    shifted = np.fft.ifft(np.fft.fft(surface.heights, axis=0)
                          * np.exp(-2j * np.pi * k * lag / NX), axis=0).real
    result = trace_retrace_coherence(surface, Surface(shifted, surface.size, periodic=False))
    assert result.integer_lag == round(lag)
    assert result.lag == pytest.approx(lag, abs=0.01)
    assert result.lag_length == pytest.approx(lag * DX, abs=0.01 * DX)
    assert result.coherence[:-1].min() > 0.999


def test_pure_noise_is_reliable_nowhere_and_its_coherence_is_the_estimator_bias():
    rng = np.random.default_rng(5)
    size = (NX * DX, NY * DX)
    first = Surface(rng.standard_normal((NX, NY)) * 1e-9, size, periodic=False)
    second = Surface(rng.standard_normal((NX, NY)) * 1e-9, size, periodic=False)
    result = trace_retrace_coherence(first, second)
    assert result.q_cutoff == result.q[0] and not result.reliable_anywhere
    assert result.coherence.max() < THRESHOLD
    # E[gamma^2] = 1 / K for K independent lines without shared signal
    assert result.coherence.mean() * NY == pytest.approx(1.0, rel=0.3)


def test_null_distribution_of_the_coherence():
    """P(gamma^2 >= t) = (1 - t)^(K - 1) for K independent noise lines: the basis of
    minimum_lines. K = 64, t = 0.05: 0.0395; 8 maps of 127 wavenumbers."""
    rng = np.random.default_rng(11)
    lines, t = 64, 0.05
    values = []
    for _ in range(8):
        maps = [Surface(rng.standard_normal((NX, lines)), (NX * DX, lines * DX),
                        periodic=False) for _ in range(2)]
        values.append(trace_retrace_coherence(*maps, max_lag=2).coherence)
    share = np.mean(np.concatenate(values) >= t)
    assert share == pytest.approx((1 - t) ** (lines - 1), rel=0.35)
    assert minimum_lines(512) == 37          # 256 (3/4)^36 <= 0.01 < 256 (3/4)^35
    assert 256 * 0.75 ** 36 <= FALSE_ALARM < 256 * 0.75 ** 35


def test_levelling_windowing_and_order_of_the_sweeps():
    """Each sweep's own line offsets and tilts (and a plane) are removed exactly: the
    curve does not change; swapping the sweeps negates the lag; lines along y are the
    transposed map."""
    first, second, _, _ = _noisy_pair(0.8, 1)
    base = trace_retrace_coherence(first, second)
    rng = np.random.default_rng(2)
    x = np.arange(NX)[:, None] * DX
    offsets = rng.normal(0, 3e-9, NY) + rng.normal(0, 0.02, NY) * x
    moved = Surface(second.heights + offsets + 0.05 * x, second.size, periodic=False)
    again = trace_retrace_coherence(first, moved)
    assert again.integer_lag == base.integer_lag
    np.testing.assert_allclose(again.coherence, base.coherence, rtol=1e-7, atol=1e-12)
    swapped = trace_retrace_coherence(second, first)
    assert swapped.lag == pytest.approx(-base.lag, abs=1e-9)
    assert swapped.q_cutoff == pytest.approx(base.q_cutoff, rel=1e-9, abs=0)
    transposed = trace_retrace_coherence(
        Surface(first.heights.T, first.size[::-1], periodic=False),
        Surface(second.heights.T, second.size[::-1], periodic=False), axis="y")
    assert transposed.axis == "y" and transposed.lag == pytest.approx(base.lag, abs=1e-9)
    np.testing.assert_allclose(transposed.coherence, base.coherence, rtol=1e-9, atol=1e-15)


def test_bad_input_is_refused():
    surface = _surface(0.8, 0)
    flat = Surface(surface.heights, surface.size, periodic=False)
    with pytest.raises(InputError, match="same grid"):
        trace_retrace_coherence(flat, Surface(flat.heights[:, :-1], flat.size))
    with pytest.raises(InputError, match="same physical size"):
        trace_retrace_coherence(flat, Surface(flat.heights, (1e-6, 1e-6)))
    with pytest.raises(InputError, match="profile"):
        trace_retrace_coherence(Surface(flat.heights[:, 0], 2e-7), flat)
    with pytest.raises(InputError, match="Surface"):
        trace_retrace_coherence(flat.heights, flat)
    for bad in (0.0, 1.0, "0.25"):
        with pytest.raises(InputError, match="threshold"):
            trace_retrace_coherence(flat, flat, threshold=bad)
    with pytest.raises(InputError, match="max_lag"):
        trace_retrace_coherence(flat, flat, max_lag=NX - 8)
    few = Surface(flat.heights[:, :30], (NX * DX, 30 * DX), periodic=False)
    with pytest.raises(InputError, match="30 lines along x are too few: with fewer than 3"):
        trace_retrace_coherence(few, few)


def _entries(*channels):
    """``metadata["channel_table"]`` of (index, name, direction) triples."""
    return [{"index": i, "name": n, "direction": d} for i, n, d in channels]


def test_trace_and_retrace_are_paired_by_name_and_direction():
    """From the directions stored as data on reading (metadata["channel_table"]), not
    from the labels shown: a name with parentheses, quotes or a direction-like word in
    it is only a name."""
    table = _entries((0, "Height", "Trace"), (1, "Height", "Retrace"), (2, "Phase", "Trace"),
                     (3, "AmplitudeError", "Trace"))

    def partner(index, channels=table):
        read = next(c for c in channels if c["index"] == index)
        return trace_retrace_partner({"channel": read, "channel_table": channels})
    assert partner(0) == 1 and partner(1) == 0
    assert partner(2) is None and partner(3) is None          # no retrace of the Phase
    assert partner(0, _entries((0, "Height", "Trace"), (1, "Height", None))) is None
    assert partner(0, table + _entries((4, "Height", "Retrace"))) is None   # ambiguous
    assert partner(0, _entries((0, "Height (x)", "Trace"), (1, "Height (x)", "retrace"))) == 1
    assert partner(0, _entries((0, "Height' (Trace)", None), (1, "Height' (Retrace)", None))) \
        is None                                   # directions only in the names: none
    assert partner(1, _entries((0, "Height", "Forward"), (1, "Height", "Backward"))) is None
    assert trace_retrace_partner({}) is None
    assert trace_retrace_partner({"channel": {"index": 0, "name": "Raw"},
                                  "channels": ["0 'Raw'"]}) is None   # one channel: none


def test_labels_without_the_directions_as_data_are_refused_with_the_reason(
        topographies_dir, tmp_path):
    """A .npz saved from di-1 by a roughfe before session 37 has only the labels
    (metadata["channels"]) and a channel read without "direction": its partner is not
    parsed back from the text; the error says why and what to do. Saved now, it keeps
    the table and finds the partner."""
    from roughfe.surfaces.channels import read_channel_label
    from roughfe.surfaces.io import save_surface
    trace = load_surface(topographies_dir / "di-1.di", channel=0)
    assert trace_retrace_partner(load_surface(save_surface(trace, tmp_path / "new.npz"))
                                 .metadata) == 1
    old = {k: v for k, v in trace.metadata.items() if k != "channel_table"}
    old["channel"] = {"index": 0, "name": "Height"}
    saved = save_surface(Surface(trace.heights, trace.size, False, old), tmp_path / "old.npz")
    meta = load_surface(saved).metadata
    assert meta["channels"][:2] == ["0 'Height' (Trace)", "1 'Height' (Retrace)"]
    # what info prints of the channel read: the direction from the data, or else the label
    assert read_channel_label(meta) == read_channel_label(trace.metadata) == \
        "0 'Height' (Trace)"
    with pytest.raises(InputError, match=r"di-1.di' by a roughfe before round 2, session "
                                         r"37\) lists the file's channels as text only "
                                         r"\(0 'Height' \(Trace\), 1 'Height' \(Retrace\).*"
                                         r"read the instrument file again"):
        trace_retrace_partner(meta)


def test_di1_trace_and_retrace(topographies_dir):
    """Measured (round 2, session 36): lag -6.79 samples (retrace = trace shifted by
    -6.79 nm along x; integer -6, correlation 0.9984) and q_c = 5.93e8 rad/m (10.6 nm), 1.48
    times session 35's 4e8 rad/m (where C_y / C_x rises; docs/theory/01_surfaces.md)."""
    path = topographies_dir / "di-1.di"
    trace, retrace = load_surface(path, channel=0), load_surface(path, channel=1)
    result = trace_retrace_coherence(trace, retrace)
    assert result.integer_lag == -6 and -7.0 < result.lag < -6.5
    assert result.correlation > 0.998
    assert result.q_cutoff == pytest.approx(5.927e8, rel=2e-3, abs=0)
    assert result.wavelength_cutoff == pytest.approx(10.60e-9, rel=2e-3, abs=0)
    # the whole fast-axis band up to q_c agrees, nothing beyond 1e9 rad/m does
    assert result.coherence[result.q < 3e8].min() > 0.5
    assert result.coherence[result.q > 1e9].max() < 0.1


def _waves(n=64, length=64e-9):
    """A periodic map of two waves along x (amplitudes 3 and 0.5 nm, k = 3 and 20) and two
    along y (1 and 2 nm, k = 5 and 12) on n x n points; (surface, the waves by axis as
    (amplitude m, q rad/m))."""
    x = np.arange(n) * length / n
    q = 2 * np.pi / length
    waves = {"x": ((3e-9, 3 * q), (0.5e-9, 20 * q)), "y": ((1e-9, 5 * q), (2e-9, 12 * q))}
    (a1, q1), (a2, q2) = waves["x"]
    (b1, p1), (b2, p2) = waves["y"]
    h = (a1 * np.sin(q1 * x)[:, None] + a2 * np.cos(q2 * x + 0.4)[:, None]
         + b1 * np.cos(p1 * x)[None, :] + b2 * np.sin(p2 * x + 1.1)[None, :])
    return Surface(h, (length, length), periodic=True), waves


def test_slope_share_of_sinusoids_is_exact():
    """A wave a sin(q x) carries a^2 q^2 / 2 of the mean-square slope along its axis and
    none across it: the share above a cutoff between two waves is the upper wave's."""
    surface, waves = _waves()
    q = 2 * np.pi / surface.size[0]
    for axis, ((a1, q1), (a2, q2)) in waves.items():
        upper = (a2 * q2) ** 2 / ((a1 * q1) ** 2 + (a2 * q2) ** 2)
        for q_c in (q1 * 1.01, 0.5 * (q1 + q2), q2 * 0.99):
            assert slope_share_above(surface, q_c, axis) == pytest.approx(
                upper, rel=1e-12, abs=0), (axis, q_c)
        assert slope_share_above(surface, 0.5 * q1, axis) == pytest.approx(1.0, rel=1e-12,
                                                                           abs=0)
        assert slope_share_above(surface, q2 * 1.01, axis) == pytest.approx(0.0, abs=1e-15)
    # x: 0.5 nm at k 20 against 3 nm at k 3 (100 / 181); y: 2 nm at k 12 against 1 at k 5
    exact = {"x": 100 / 181, "y": 576 / 601}
    for axis in "xy":
        assert slope_share_above(surface, 10 * q, axis) == pytest.approx(exact[axis],
                                                                         rel=1e-12, abs=0)
    # a profile is its x lines; a map flat along y has no slope there
    profile = Surface(surface.heights[:, 0], surface.size[0], periodic=True)
    assert slope_share_above(profile, 10 * q, "x") == pytest.approx(exact["x"], rel=1e-12,
                                                                    abs=0)
    flat_y = Surface(np.repeat(surface.heights[:, :1], 64, axis=1), surface.size,
                     periodic=True)
    assert np.isnan(slope_share_above(flat_y, 10 * q, "y"))


@pytest.mark.parametrize("periodic", [True, False])
def test_slope_share_of_white_noise_is_the_share_of_q2(periodic):
    """White noise has a flat line PSD (also Hann-windowed, for a non-periodic map), so its
    share above q_c is that of q^2 over the line PSD's wavenumbers; continuous:
    1 - (q_c / q_N)^3 (0.875 at q_N / 2; the share of the heights would be 0.5)."""
    n, dx = 256, 1e-9
    rng = np.random.default_rng(7)
    surface = Surface(rng.standard_normal((n, 2 * n)) * 1e-9, (n * dx, 2 * n * dx),
                      periodic=periodic)
    q_n = np.pi / dx
    k = np.arange(1, n // 2 + 1)
    q, w = 2 * np.pi * k / (n * dx), np.where(k == n // 2, 1.0, 2.0)
    for f in (0.25, 0.5, 0.8):
        expected = np.sum((q ** 2 * w)[q > f * q_n]) / np.sum(q ** 2 * w)
        assert abs(expected - (1 - f ** 3)) < 0.005
        share = slope_share_above(surface, f * q_n, "x")
        assert share == pytest.approx(expected, abs=0.01), f
    # across the lines the same (the y lines are 512 points long: a finer q grid)
    assert slope_share_above(surface, 0.5 * q_n, "y") == pytest.approx(0.875, abs=0.01)


def test_slope_share_refuses_a_bad_cutoff():
    surface, _ = _waves()
    for bad in (0.0, -1e8, np.nan, np.inf, "5e8", None):
        with pytest.raises(InputError, match="q_cutoff"):
            slope_share_above(surface, bad, "x")
    with pytest.raises(InputError, match="direction"):
        slope_share_above(surface, 1e8, "z")
