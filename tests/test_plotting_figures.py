"""What the matplotlib figures draw: the lines and labels of the saved figure, read back
from the Figure before it is written (``save_figure`` patched in the plotting module)."""
import numpy as np
import pytest

from roughfe.plotting import contact as contact_plot


@pytest.fixture
def drawn(monkeypatch, tmp_path):
    """Call ``plot(module, *args)`` and get the Figure it would have saved."""
    figures = []

    def keep(fig, path, dpi=150):
        figures.append(fig)
        return path

    def plot(module, func, *args, **kwargs):
        monkeypatch.setattr(module, "save_figure", keep)
        getattr(module, func)(*args, tmp_path / "fig.png", **kwargs)
        return figures[-1]
    return plot


def _lines(ax):
    return {ln.get_label(): ln for ln in ax.get_lines()}


def _records(p, delta, k, unloading=None):
    recs = []
    for i, (pi, di, ki) in enumerate(zip(p, delta, k)):
        r = {"mean_pressure": pi, "delta": di, "area_fraction": 0.01 * pi / p.max(),
             "stiffness": ki, "stiffness_fd": ki, "mean_gap": 1e-6 / (1 + pi / p.max()),
             "mean_plane_separation": 1e-6, "free_volume_star": 1.0}
        if unloading is not None:
            r["unloading"] = bool(unloading[i])
        recs.append(r)
    return recs


def test_stiffness_lines_follow_the_curve_when_loads_come_out_of_order(drawn):
    """``--pressure 3e5 1e4 1e5 3e4 2e5``: the K panel joined the points in solve order,
    a zig-zag; each branch's line is drawn in order of p."""
    p = np.array([3e5, 1e4, 1e5, 3e4, 2e5])
    fig = drawn(contact_plot, "plot_area_stiffness", _records(p, p * 1e-12, p * 1e6))
    for label in ("exact (fixed contact set)", "central differences"):
        x = _lines(fig.axes[1])[label].get_xdata()
        assert sorted(x) == list(x) and len(x) == 5



def test_an_unloading_branch_detached_at_every_step_is_a_note_not_an_empty_entry(drawn):
    """``roughfe contact ns.npz --hardness 2e6 --unload``: every unloading step detaches
    (p = 0, A* = 0), none is drawn on the log axes; the A(p) and u(p) legends listed
    'BEM (unloading)' with no point. Now the panels say so; a branch with points keeps
    its entry."""
    p = np.array([1e5, 2e5, 4e5, 0.0, 0.0, 0.0])
    recs = _records(p, np.linspace(1, 6, 6) * 1e-7, p * 1e6, unloading=[0, 0, 0, 1, 1, 1])
    for r in recs[3:]:
        r.update(area_fraction=0.0, stiffness=0.0, stiffness_fd=None)
    fig = drawn(contact_plot, "plot_area_stiffness", recs, rms_height=1e-7)
    for ax in fig.axes[:3]:
        legend = ax.get_legend()
        assert [t.get_text() for t in legend.get_texts()][:1] in (["BEM"], ["exact (fixed contact set)"])
        assert not any("unloading" in t.get_text() for t in legend.get_texts())
        assert legend.get_title().get_text() == "unloading: detached at every step"
    # the V* panel draws every step, detached ones too: both branches, no note
    assert "BEM (unloading)" in _lines(fig.axes[3])
    back = _records(np.array([1e5, 2e5, 4e5, 2e5]), np.array([1, 2, 3, 2.5]) * 1e-7,
                    np.full(4, 1e11), unloading=[0, 0, 0, 1])
    fig = drawn(contact_plot, "plot_area_stiffness", back)
    assert "BEM (unloading)" in _lines(fig.axes[0])
    assert not fig.axes[0].get_legend().get_title().get_text()

def _labelled_ticks(fig, axis):
    """The tick labels with text that lie inside the axis' view (after a draw)."""
    fig.canvas.draw()
    lo, hi = sorted(axis.get_view_interval())
    return [t.get_text() for t, v in zip(axis.get_ticklabels(), axis.get_ticklocs())
            if t.get_text() and lo <= v <= hi]


def test_a_log_axis_within_a_decade_has_two_labels_or_more(drawn):
    """A K panel from 0.55 to 1.8 MPa/um (a sphere with a hardness) showed "10^0" alone:
    each log axis of the contact figure labels two ticks or more, as plain numbers."""
    p = np.array([1e5, 2e5, 4e5, 8e5])
    k = np.array([0.55, 0.9, 1.4, 1.8]) * 1e12
    fig = drawn(contact_plot, "plot_area_stiffness", _records(p, p * 1e-12, k))
    for ax in fig.axes[:3]:
        for axis in (ax.xaxis, ax.yaxis):
            if axis.get_scale() == "log":
                labels = _labelled_ticks(fig, axis)
                assert len(labels) >= 2, (ax.get_title(), labels)
    k_labels = _labelled_ticks(fig, fig.axes[1].yaxis)
    assert "1" in k_labels and all(float(t) > 0 for t in k_labels)     # plain numbers


def test_a_tensile_only_adhesive_run_draws_its_states(drawn):
    """An adhesive run that never reaches compression (p < 0 at every step) drew three
    empty log panels; its states are drawn on linear axes, and the panels say why."""
    p = -np.array([5e4, 4.7e4, 4.3e4])
    recs = _records(p, np.array([1, 2, 4]) * 5e-9, np.full(3, np.nan))
    for r, a, kfd in zip(recs, (0.096, 0.1, 0.11), (5.7e11, 4.6e11, 4.0e11)):
        r.update(area_fraction=a, stiffness=None, stiffness_fd=kfd)
    fig = drawn(contact_plot, "plot_area_stiffness", recs)
    for ax in fig.axes[:3]:
        assert ax.get_xscale() == ax.get_yscale() == "linear"
        assert len(ax.get_lines()[0].get_xdata()) == 3
        assert "no state in compression" in ax.get_legend().get_title().get_text()
    np.testing.assert_allclose(_lines(fig.axes[0])["BEM"].get_ydata(), [0.096, 0.1, 0.11])


def test_the_plastic_stiffness_steps_are_labelled(drawn):
    """With a hardness K is that of the points below it and jumps as grid points yield:
    the steps with plastic flow are marked and the legend says why K steps there."""
    p = np.array([1e5, 2e5, 4e5, 8e5])
    recs = _records(p, p * 1e-12, np.array([1.0, 1.2, 1.2, 0.9]) * 1e12)
    for r, f in zip(recs, (0.0, 0.0, 0.05, 0.2)):
        r["plastic_area_fraction"] = f
    fig = drawn(contact_plot, "plot_area_stiffness", recs)
    flow = [ln for ln in fig.axes[1].get_lines() if ln.get_label().startswith("plastic flow")]
    assert len(flow) == 1 and "grid points yield" in flow[0].get_label()
    np.testing.assert_allclose(flow[0].get_xdata(), [0.4, 0.8])


def test_persson_elastoplastic_areas_are_drawn_beside_the_plastic_area(drawn):
    """With a hardness, Persson's elastoplastic total and plastic areas (theory.plastic,
    first loading only) are drawn in the A* panel beside the BEM's plastic area, in order
    of p; the unloading step carries none and adds no point to the theory lines."""
    p = np.array([1e5, 4e5, 2e5, 1e6])
    recs = _records(p, p * 1e-12, np.full(4, 1e12), unloading=[0, 0, 0, 1])
    for r, ep, pl, bem in zip(recs, (0.02, 0.05, 0.03, None), (0.01, 0.04, 0.02, None),
                              (0.0, 0.03, 0.01, 0.03)):
        r.update(persson_elastoplastic_area_fraction=ep, persson_plastic_area_fraction=pl,
                 plastic_area_fraction=bem)
    fig = drawn(contact_plot, "plot_area_stiffness", recs)
    lines = _lines(fig.axes[0])
    np.testing.assert_allclose(lines["Persson, with hardness"].get_xdata(), [0.1, 0.2, 0.4])
    np.testing.assert_allclose(lines["Persson, with hardness"].get_ydata(), [0.02, 0.03, 0.05])
    np.testing.assert_allclose(lines["Persson plastic area"].get_ydata(), [0.01, 0.02, 0.04])
    np.testing.assert_allclose(sorted(lines["BEM plastic area"].get_ydata()), [0.01, 0.03, 0.03])


# -- design PSD figure ---------------------------------------------------------------------
def _three_ridge_design():
    """A periodic 2D design (64 x 64, L = 100 um) of one genome with three ridges at 0, 90
    and 45 deg and anisotropy factors 0.5, 1, 2: chromosomes n = 1..3 at q_n L / 2 pi = 4,
    8, 16, each wave on its own lattice vector, no two in one annulus of another n."""
    from roughfe.genomics.design.model import Design, DesignPart
    from roughfe.genomics.genome import random_genome
    L = 1e-4
    g = random_genome(1e-6, 0.8, 2.0, L / 4, 3, 3, rng=1,
                      angles=[0.0, np.pi / 2, np.pi / 4], anisotropy=[0.5, 1.0, 2.0])
    return Design((DesignPart(g, (1, 2, 3), 1.0, "a"),), 1.0, L, 64, dim=2)


def test_spectrum_lines_carry_the_mean_square_each_chromosome_realises():
    """a_n is the rms-equivalent amplitude of the ridges' waves: a_n^2 / 2 is the mean
    square chromosome n adds to the surface, each ridge scaled by its anisotropy factor
    (left out until session 25: sqrt(M), 1.7x here)."""
    d = _three_ridge_design()
    for n, (q, a) in zip((1, 2, 3), d.spectrum_lines()):
        var = d.chromosome_surface(0, n).heights.var()
        assert a ** 2 / 2 / var == pytest.approx(1.0, rel=1e-9)    # (m^2 ~ 1e-21: ratios)


def test_surface_psd_figure_markers_sit_on_the_annulus_averaged_fft_psd(drawn):
    """A surface design's PSD is a density per d^2q (m^4): a chromosome's mean square
    a^2/2 is spread over its annulus 2 pi q dq, which is what the annulus average of the
    FFT PSD reports. The markers took the profile formula a^2/(4 dq) (m^3), 1e4-1e5
    above the line, the axis read m^3 and the legend 'Hann' for an unwindowed periodic
    surface."""
    from roughfe.plotting import design as design_plot
    from roughfe.surfaces.stats import power_spectrum
    d = _three_ridge_design()
    s = d.surface()
    fig = drawn(design_plot, "plot_psds", {"sog": (s, d.spectrum_lines())})
    ax = fig.axes[0]
    lines = _lines(ax)
    ps = power_spectrum(s)
    assert ps.window == "none" and ax.get_ylabel() == "C (m^4)"
    assert "Hann" not in " ".join(lines) and "FFT (no window, annulus mean)" in lines
    q, marker = lines["chromosomes"].get_xdata(), lines["chromosomes"].get_ydata()
    fft = ps.C[[int(np.argmin(np.abs(ps.q - qi))) for qi in q]]
    # the annulus holds N_bin lattice points of area (2 pi / L)^2, about 2 pi q dq; the
    # counts differ (measured marker / FFT 1.27, 0.95, 1.11: 20 points at k = 4, not 25)
    assert np.all(np.abs(np.log(marker / fft)) < np.log(1.4))
    # empty annuli (round-off, ~1e-48) are gaps: the axis spans the data, not 30 decades
    line = lines["FFT (no window, annulus mean)"].get_ydata()
    assert np.nanmin(line) > 1e-20 * np.nanmax(line) and np.isnan(line).any()
    assert ax.get_ylim()[0] > 1e-20 * np.nanmax(line)


def test_the_psd_figure_draws_the_target_spectrum_of_a_matched_design(drawn):
    """`design --match-spectrum`: psd.png drew the design's spectrum alone. With
    ``target`` the target surface's annulus-averaged PSD (the same estimator, m^4) is a
    line of its own on every panel; a target of another dimension is refused (C(q) of a
    profile, m^3, is not comparable)."""
    from roughfe.errors import InputError
    from roughfe.plotting import design as design_plot
    from roughfe.surfaces import Surface
    from roughfe.surfaces.stats import power_spectrum
    d = _three_ridge_design()
    s = d.surface()
    target = s.scaled(2.0)
    fig = drawn(design_plot, "plot_psds", {"a": (s, d.spectrum_lines()), "b": (s, [])},
                target=target, target_label="target t.npz")
    ps = power_spectrum(target)
    for ax in fig.axes:
        line = _lines(ax)["target t.npz"]
        keep = ps.C > design_plot.ROUND_OFF * ps.C.max()   # empty annuli: gaps, as the design's
        np.testing.assert_array_equal(line.get_xdata(), ps.q)
        np.testing.assert_allclose(line.get_ydata()[keep], ps.C[keep], rtol=1e-12, atol=0)
        assert np.isnan(line.get_ydata()[~keep]).all()
    profile = Surface(target.heights[:, 0], target.size[0], periodic=True)
    with pytest.raises(InputError, match="dimension"):
        drawn(design_plot, "plot_psds", {"a": (s, [])}, target=profile)


def test_profile_psd_figure_markers_equal_the_psd_of_one_cosine(drawn):
    """A profile's C is per dq, two-sided: a cosine of amplitude a on the lattice puts
    a^2/4 on +-q, C = a^2 / (4 dq) (m^3); a non-periodic profile's PSD is Hann-windowed."""
    from roughfe.plotting import design as design_plot
    from roughfe.surfaces import Surface
    L, n, k, a = 1e-4, 256, 12, 2e-7
    x = np.arange(n) * L / n
    cos = Surface(a * np.cos(2 * np.pi * k * x / L), L, periodic=True)
    q = 2 * np.pi * k / L
    fig = drawn(design_plot, "plot_psds", {"periodic": (cos, [(q, a)]),
                                           "window": (Surface(cos.heights, L), [(q, a)])})
    (ax1, ax2) = fig.axes
    fft = _lines(ax1)["FFT (no window)"]
    at_q = fft.get_ydata()[int(np.argmin(np.abs(fft.get_xdata() - q)))]
    assert _lines(ax1)["chromosomes"].get_ydata()[0] / at_q == pytest.approx(1.0, rel=1e-9)
    assert at_q / (a ** 2 / (4 * 2 * np.pi / L)) == pytest.approx(1.0, rel=1e-9)
    assert ax1.get_ylabel() == ax2.get_ylabel() == "C (m^3)"
    assert "FFT (Hann)" in _lines(ax2)


# -- leakage maps -------------------------------------------------------------------------
def test_the_caption_of_a_tall_leakage_map_leaves_its_top_rows_visible(tmp_path):
    """A 64 x 256 um map fills the square window's height: the four-line caption of a
    network map (title, colour key, legend, orientation) covered its top rows. The
    caption now has its own band: every dark (text) pixel lies above the map's top row.
    One gap everywhere, all cells percolating: the map is one colour."""
    from matplotlib.image import imread
    from roughfe.plotting.leakage import network_map
    shape = (64, 256)
    path = network_map(np.full(shape, 1e-6), np.ones(shape, bool), np.zeros(shape, bool),
                       (64e-6, 256e-6), tmp_path / "net.png",
                       title="free-volume network, step 1: A*=0.056, p=3.45e+05 Pa",
                       widest_path=np.arange(np.prod(shape)).reshape(shape) == 0)
    rgb = imread(path)[..., :3]
    colour = rgb[rgb.shape[0] // 2, rgb.shape[1] // 2]          # the map, mid-window
    in_map = np.flatnonzero(np.all(np.abs(rgb - colour) < 0.02, axis=-1).any(axis=1))
    text = np.flatnonzero(np.all(rgb < 0.35, axis=-1).any(axis=1))
    assert text.size and in_map.size and text.max() < in_map.min()
    # the map is shown whole: its height 4x its width, as the domain
    cols = np.flatnonzero(np.all(np.abs(rgb - colour) < 0.02, axis=-1).any(axis=0))
    height, width = in_map.max() - in_map.min() + 1, cols.max() - cols.min() + 1
    assert height / width == pytest.approx(4.0, rel=0.02)


# -- design curves title -------------------------------------------------------------------
def _design_result(score, success=True, solved=()):
    """The parts of a DesignResult the curves figure reads (one K target; ``solved``:
    the best design's scores at the target pressures)."""
    from types import SimpleNamespace
    from roughfe.genomics.similarity import ResponseCurve, Target
    p = np.geomspace(2e6, 2.5e8, 8)
    target = Target(p, 1e3 * p, "K", "y_t1")
    curve = ResponseCurve(p, 1.1e3 * p, p / 3e8)
    best = SimpleNamespace(origin="2-1", scores=(score,), curve=curve, at_targets=solved)
    message = (f"sog: best 2-1 s = {score:.4f} (stages -0.2848, 0.6208, 0.6208); the target "
               f"is NOT matched (s = {score:.4f} <= 0.95, the selection value of Alg. 3)")
    return SimpleNamespace(method="sog", best=best, success=success, message=message,
                           objective=SimpleNamespace(targets=(target,)))


def _inside(fig, text):
    fig.canvas.draw()
    box, frame = text.get_window_extent(), fig.bbox
    return frame.x0 <= box.x0 and box.x1 <= frame.x1 and frame.y0 <= box.y0 and box.y1 <= frame.y1


def test_design_curves_title_is_whole_and_keeps_the_verdict(drawn):
    """``roughfe design`` titled curves.png with the 136-character result.message, centred
    on an 11 in figure and clipped at both ends: the verdict ('NOT matched') was lost.
    The title is now one short line (method, origin, s, verdict) and a long title wraps."""
    from roughfe.plotting import design as design_plot
    result = _design_result(0.6208)
    title = design_plot.design_title(result)
    assert title == ("sog: best 2-1; target NOT matched: s = 0.6208 <= 0.95 (interpolated "
                     "from the design's own n_t approaches)")
    assert "; target matched: s = 0.97 > 0.95" in design_plot.design_title(
        _design_result(0.97))
    assert "NOT a success" in design_plot.design_title(_design_result(0.97, success=False))
    # solved at the target pressures (roughfe design always, the search stages): those
    # scores decide, as in the message (a title said NOT matched by the interpolated s)
    assert design_plot.design_title(_design_result(0.908, solved=(0.9634,))).endswith(
        "target matched: s = 0.9634 > 0.95 (solved at the target pressures)")
    for t in (title, result.message):
        fig = drawn(design_plot, "plot_design_curves", [result], title=t)
        assert _inside(fig, fig._suptitle) and "NOT matched" in fig._suptitle.get_text()


# -- surface PSD figure (roughfe demo) -------------------------------------------------------
def _laid_surface(lay):
    """A Gaussian H = 0.8 spectral surface (128^2, L = 100 um, rms 0.1 um) plus a cosine
    lay of amplitude ``lay`` (m) at q = 10 (2 pi / L): the lay's annulus sits far above the
    power law, as the grooves of x3p-2.x3p."""
    from roughfe.surfaces import Surface, spectral_surface
    s = spectral_surface(128, 1e-4, 0.8, rms_height=1e-7, rng=0)
    x = np.arange(128) * 1e-4 / 128
    return Surface(s.heights + lay * np.cos(2 * np.pi * 10 * x / 1e-4)[:, None], s.size,
                   periodic=True)


@pytest.mark.parametrize("lay", [0.0, 5e-8])
def test_the_psd_fit_line_lies_on_its_data(drawn, lay):
    """The demo's measured PSD drew the fitted line 3.5x above its data: the Whittle level
    is a mean that the lay's annuli set (not a normalisation: the fit and the figure read
    one PowerSpectrum). On a power law the line is the fit's own; with a lay it is the
    fitted slope at the data's median, and the values that set the Whittle level are
    ringed."""
    from roughfe.plotting import surfaces as surface_plot
    from roughfe.surfaces import fit_hurst, power_spectrum
    from roughfe.surfaces.psd_fit import fit_points
    s = _laid_surface(lay)
    psd, fit = power_spectrum(s), fit_hurst(s)
    fig = drawn(surface_plot, "plot_psd", {"s": psd}, fits={"s": fit})
    line = next(ln for ln in fig.axes[0].get_lines() if ln.get_label().startswith("fit:"))
    q, c = line.get_xdata(), line.get_ydata()
    slope = np.polyfit(np.log(q), np.log(c), 1)[0]
    assert slope == pytest.approx(fit.slope, abs=1e-9)
    sel, _ = fit_points(psd, fit.q_range)
    drawn_level = np.median(psd.C[sel] / (c[0] * (psd.q[sel] / q[0]) ** slope))
    whittle_level = np.median(psd.C[sel] / (fit.prefactor * psd.q[sel] ** fit.slope))
    rings = [ln for ln in fig.axes[0].get_lines() if "Whittle level" in ln.get_label()
             and not ln.get_label().startswith("fit:")]
    if lay == 0.0:          # a power law: the Whittle line itself, through the data
        assert whittle_level == pytest.approx(1.0, abs=0.1)
        assert drawn_level == pytest.approx(whittle_level, abs=1e-9) and not rings
    else:                   # the lay: Whittle 2.2x above the data, the drawn line on it
        assert whittle_level < 0.5
        assert drawn_level == pytest.approx(1.0, abs=1e-9)
        # the lay's annulus (its mean |q|: 1 % above 2 pi 10 / L)
        assert rings and rings[0].get_xdata()[0] == pytest.approx(2 * np.pi * 10 / 1e-4,
                                                                  rel=0.02, abs=0)


# -- FEM mesh render ---------------------------------------------------------------------------
def test_the_fem_mesh_render_is_cut_along_a_straight_line(tmp_path):
    """The render kept whole cells by their centres: a saw-tooth lower edge the mesh does
    not have (a user's review). The shown mesh ends on the straight line y = -0.33 W,
    across the whole width, in mm, and the picture has axes (it renders)."""
    from roughfe.plotting.fem import render_deformed_mesh, shown_mesh
    nx, ny, w = 21, 41, 1e-3                      # a 1 mm x 2 mm body of triangles
    x, y = np.meshgrid(np.linspace(0, w, nx), np.linspace(-2 * w, 0, ny), indexing="ij")
    pts = np.column_stack([x.ravel(), y.ravel()])
    i, j = np.meshgrid(np.arange(nx - 1), np.arange(ny - 1), indexing="ij")
    a = (i * ny + j).ravel()
    cells = np.vstack([np.column_stack([a, a + ny, a + 1]),
                       np.column_stack([a + ny, a + ny + 1, a + 1])])
    disp = np.zeros_like(pts)
    disp[:, 1] = -1e-8 * np.exp(pts[:, 1] / w)
    fields = {"points": pts, "cells": cells, "displacement": disp,
              "stress_yy": -1e6 * np.ones(len(cells))}
    # the cut between two rows of nodes (-0.30 and -0.35 mm)
    grid, unit, scale, mag, y_cut = shown_mesh(fields, top_fraction=0.33)
    assert unit == "mm" and scale == 1e3 and y_cut == pytest.approx(-0.33, abs=1e-12)
    ys, xs = grid.points[:, 1], grid.points[:, 0]
    assert ys.min() == pytest.approx(y_cut, abs=1e-9)            # nothing below the cut
    edge = np.abs(ys - y_cut) < 1e-9
    assert xs[edge].min() == pytest.approx(0, abs=1e-9) and xs[edge].max() == pytest.approx(
        1.0, abs=1e-9)
    assert render_deformed_mesh(fields, tmp_path / "m.png",
                                window_size=(400, 300)).stat().st_size > 5000


def _leak_steps():
    """Five one-way steps as x3p-2 (a 256^2 crop, steel) gave them: a lay along y, so x
    seals first (A* 0.41) while y still flows; both sealed at A* 0.57. Persson's
    per-direction estimates differ 6x (the window's W/L only)."""
    a = [0.018, 0.059, 0.187, 0.406, 0.572]
    qx = [1.27e-19, 1.64e-20, 7.85e-24, 0.0, 0.0]
    qy = [1.74e-19, 7.65e-20, 2.37e-20, 2.01e-21, 0.0]
    px = [3.2e-19, 7.3e-20, 2.6e-21, 8.8e-27, 0.0]
    return [{"area_fraction": ai, "leak_rate_x": x, "leak_rate_y": y,
             "persson_leak_rate_x": p, "persson_leak_rate_y": p / 6.07,
             "persson_leak_rate": p * (1 + 1 / 6.07) / 2, "free_volume_star": 1.0 - ai,
             "percolating_volume_star": 0.9 - ai, "trapped_volume_star": 0.1}
            for ai, x, y, p in zip(a, qx, qy, px)]


def test_steps_figure_draws_sealing_and_persson_per_direction(drawn):
    """A seals review of ``roughfe leak``'s steps.png: the y curve was dashed under a title
    "dashed lines: sealed steps"; a grey vertical line marked A* 0.41 "sealed" where only
    x was (y flowed); and one Persson line, the mean of x and y, which differ 6x. Now
    both Reynolds curves are solid, each direction's Persson estimate is dotted in its
    colour, and a step sealed along a direction gets a triangle in that direction's
    colour: x at 0.41 and 0.57, y at 0.57 only; no vertical line, no averaged Persson."""
    from roughfe.plotting import leakage
    fig = drawn(leakage, "steps_figure", _leak_steps())
    ax = fig.axes[0]
    lines = _lines(ax)
    rx, ry = lines["Reynolds, x"], lines["Reynolds, y"]
    assert rx.get_linestyle() == ry.get_linestyle() == "-"
    assert rx.get_color() != ry.get_color()
    for d, reynolds in (("x", rx), ("y", ry)):
        persson = lines[f"Persson (critical junction), {d}"]
        assert persson.get_linestyle() == ":" and persson.get_color() == reynolds.get_color()
    assert lines["Persson (critical junction), y"].get_ydata()[0] == pytest.approx(
        3.2e-19 / 6.07, rel=1e-12, abs=0)
    assert list(lines["sealed along x (Q$_x$ = 0)"].get_xdata()) == [0.406, 0.572]
    assert list(lines["sealed along y (Q$_y$ = 0)"].get_xdata()) == [0.572]
    assert lines["sealed along x (Q$_x$ = 0)"].get_color() == rx.get_color()
    assert not any("mean" in label for label in lines)
    # no vertical marker lines: every line but the sealed marks has one point per step
    assert all(len(ln.get_xdata()) == 5 for label, ln in lines.items()
               if not label.startswith("sealed"))
    assert "dashed" not in ax.get_title() and "W/L" in ax.get_title()


def test_network_key_says_red_is_sealed_on_every_map():
    """The network map's key said "red: trapped" when every trapped cell was sealed and
    "red: sealed ... pink: dead end" otherwise: red is now "sealed" whenever the map
    splits the trapped cells (zero dead ends included), and "trapped" only on a map that
    does not split them, which says so."""
    from roughfe.plotting.leakage import network_key
    all_sealed = network_key(10, 80, 10, 10)
    some = network_key(10, 80, 10, 4)
    for key in (all_sealed, some):
        assert "red: sealed" in key and "red: trapped" not in key
    assert "pink: dead end, open to the flow (0)" in all_sealed
    assert "red: sealed (4)" in some and "pink: dead end, open to the flow (6)" in some
    unsplit = network_key(10, 80, 10)
    assert "red: trapped (10; sealed and dead ends not told apart)" in unsplit
    assert "pink" not in unsplit


def test_a_volume_of_zero_is_marked_not_dropped_on_the_log_axis(drawn):
    """steps.png's volume panel is logarithmic when the trapped volume is decades below
    the free one; a percolating volume of 0 (sealed) was drawn as a line diving to the
    axis' foot. It is now left out of its line and marked at the foot in its colour."""
    from roughfe.plotting import leakage
    steps = _leak_steps()
    for s, vp in zip(steps, (0.5, 0.2, 0.05, 0.0, 0.0)):
        s.update(percolating_volume_star=vp, trapped_volume_star=1e-4)
    ax = drawn(leakage, "steps_figure", steps).axes[1]
    assert ax.get_yscale() == "log"
    lines = _lines(ax)
    vp = lines["V$_p$*"].get_ydata()
    assert np.all(np.isnan(vp[3:])) and np.all(vp[:3] > 0)
    mark = lines["V$_p$* = 0"]
    assert list(mark.get_xdata()) == [0.406, 0.572]
    assert mark.get_color() == lines["V$_p$*"].get_color()
