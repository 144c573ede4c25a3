"""Figures of the leakage analysis (thesis Fig. 14-24): maps and study curves.

Reads arrays and JSON-safe records only; never solves. Maps are pyvista off-screen
renders seen from above (x to the right, y up, lengths in micrometres); curves are
matplotlib figures. Every file is written atomically (roughfe.plotting.common).
"""
from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np

from .._runtime import load_render_backend, render_in_fresh_process
from .common import (holds_interrupts, load_pyvista, new_figure, offscreen_plotter,
                     save_figure, save_screenshot, side_bar)

UM = 1e6


def _render_elsewhere(name, arrays, **kwargs) -> Path:
    """Call ``roughfe.plotting.leakage.<name>(**arrays, **kwargs)`` in a fresh interpreter
    (this process loaded dolfinx before vtk: see :mod:`roughfe._runtime`)."""
    render_in_fresh_process(__name__, name, arrays, **kwargs)
    return Path(kwargs["path"])


def _image(shape, size):
    pv = load_pyvista()
    nx, ny = shape
    return pv.ImageData(dimensions=(nx + 1, ny + 1, 1),
                        spacing=(size[0] / nx * UM, size[1] / ny * UM, 1.0))


def _cells(a):
    """(nx, ny) array -> VTK cell order (x fastest)."""
    a = np.asarray(a)
    return a.reshape(a.shape[0] * a.shape[1], *a.shape[2:], order="F") if a.ndim == 2 else \
        a.transpose(1, 0, *range(2, a.ndim)).reshape(a.shape[0] * a.shape[1], *a.shape[2:])


#: Caption font (pixels) and the margin (pixels) kept around the caption and the map.
_CAPTION_PX, _MARGIN_PX = 20, 12
#: Left edge of a map's colour bar (window fraction); the map is fitted left of it.
_BAR_X = 0.85


def _caption(plotter, text):
    """``text`` centred at the top edge of the window; returns its height (pixels),
    measured by vtk's text renderer."""
    from vtkmodules.vtkRenderingCore import vtkTextRenderer
    width, height = plotter.window_size
    actor = plotter.add_text(text, position=(width / 2, height - _MARGIN_PX), font_size=10)
    prop = actor.GetTextProperty()
    prop.SetFontSize(_CAPTION_PX)
    prop.SetJustificationToCentered()
    prop.SetVerticalJustificationToTop()
    box = [0, 0, 0, 0]
    vtkTextRenderer().GetBoundingBox(prop, text, box, plotter.render_window.GetDPI())
    return box[3] - box[2] + 1


def _fit_below(plotter, size, top, right):
    """Parallel view from above that shows the map (``size`` m) whole in the window below
    its top ``top`` pixels and left of the fraction ``right`` of its width (the colour
    bar), centred there with a margin."""
    width, height = plotter.window_size
    lx, ly = size[0] * UM, size[1] * UM
    free_w, free_h = right * width - 2 * _MARGIN_PX, height - top - 2 * _MARGIN_PX
    px = min(free_w / lx, free_h / ly)                    # pixels per um
    # the map's centre at the centre of the free box; the focal point is the window's
    fx = lx / 2 - (right * width / 2 - width / 2) / px
    fy = ly / 2 - ((height - top) / 2 - height / 2) / px
    plotter.enable_parallel_projection()
    cam = plotter.camera
    cam.focal_point = (fx, fy, 0.0)
    cam.position = (fx, fy, max(lx, ly) * 4.0)
    cam.up = (0.0, 1.0, 0.0)
    cam.parallel_scale = height / (2 * px)
    plotter.renderer.reset_camera_clipping_range()


def _finish(plotter, title, path, size, right=1.0):
    """Caption, view and screenshot of a map. The caption (the title wrapped, the
    orientation and the size) has its own band at the top and the map is fitted below
    it, left of ``right`` (the colour bar's left edge, a fraction of the width): on a
    tall map (64 x 256 um) the caption covered the top rows until session 25."""
    # no cube-axes labels: vtk's label formatting aborts (std::bad_alloc in its regex)
    # in processes that also loaded dolfinx; the size goes into the caption instead
    # long titles (a coupled step's tag) wrapped: centred text is clipped at both ends
    text = "\n".join(textwrap.fill(line, 80) for line in title.split("\n"))
    top = _caption(plotter, f"{text}\nx to the right, y up; {size[0] * UM:.4g} x "
                            f"{size[1] * UM:.4g} um")
    _fit_below(plotter, size, top + 2 * _MARGIN_PX, right)
    return save_screenshot(plotter, path)


@holds_interrupts
def network_map(gap, percolating, trapped, size, path, *, title="free-volume network",
                widest_path=None, junctions=None, sealed=None):
    """Gap map with contact black, percolating cells white to blue (by gap) and trapped
    cells red, like thesis Fig. 16-17; with ``sealed`` the trapped cells are split into
    sealed (red: no open path to inlet or outlet) and dead ends open to the flow (pink);
    optionally the widest path (orange) and the critical junctions (yellow discs).

    Parameters
    ----------
    gap : ndarray, shape (nx, ny)
        Gap in m.
    percolating, trapped : ndarray of bool
        ``U_p`` and ``U_np``; every other cell is drawn as contact.
    size : (float, float)
        Physical size in m.
    path : path-like
        PNG file.
    widest_path : ndarray of bool, optional
        Cells of the widest inlet-outlet path(s) (:mod:`roughfe.leakage.junction`).
    junctions : sequence of (x, y), optional
        Junction centres in m.
    sealed : ndarray of bool, optional
        The sealed part of ``trapped`` (:attr:`roughfe.leakage.network.NetworkResult.sealed`).
    """
    if not load_render_backend():
        arrays = {"gap": gap, "percolating": percolating, "trapped": trapped}
        for key, value in (("widest_path", widest_path), ("sealed", sealed)):
            if value is not None:
                arrays[key] = value
        return _render_elsewhere("network_map", arrays, size=list(size), path=str(path),
                                 title=title,
                                 junctions=None if junctions is None else
                                 [list(map(float, j)) for j in junctions])
    g = np.asarray(gap, float)
    rgb = np.zeros(g.shape + (3,))
    gmax = g[percolating].max() if np.any(percolating) else 1.0
    t = np.clip(g / gmax, 0.0, 1.0) if gmax > 0 else np.zeros_like(g)
    blue = np.stack([1.0 - 0.85 * t, 1.0 - 0.6 * t, np.ones_like(t)], axis=-1)
    rgb[percolating] = blue[percolating]
    trapped = np.asarray(trapped, bool)
    split = sealed is not None
    sealed = trapped if sealed is None else trapped & np.asarray(sealed, bool)
    rgb[trapped] = (1.0, 0.62, 0.72)            # dead ends open to the flow
    rgb[sealed] = (0.85, 0.1, 0.1)
    legend = ""
    if widest_path is not None and np.any(widest_path):
        rgb[np.asarray(widest_path, bool)] = (1.0, 0.55, 0.0)
        legend = "\norange: widest path"
    img = _image(g.shape, size)
    img.cell_data["colour"] = (_cells(rgb) * 255).astype(np.uint8)
    pl = offscreen_plotter(window_size=(900, 900))
    pl.add_mesh(img, scalars="colour", rgb=True, show_scalar_bar=False, lighting=False)
    if junctions:
        # cell centres from 0 (Surface.coordinates) on an image whose cells start at 0
        half = (0.5 * size[0] / g.shape[0], 0.5 * size[1] / g.shape[1])
        pts = np.array([[(x + half[0]) * UM, (y + half[1]) * UM, 0.5] for x, y in junctions])
        pl.add_points(pts, color="yellow", point_size=22, render_points_as_spheres=True)
        legend += ("  " if legend else "\n") + "yellow: critical junction"
    n_p, n_t = int(np.sum(percolating)), int(np.sum(trapped))
    key = network_key(g.size - n_p - n_t, n_p, n_t, int(np.sum(sealed)) if split else None)
    return _finish(pl, f"{title}\n{key}{legend}", path, size)


def network_key(n_contact, n_percolating, n_trapped, n_sealed=None) -> str:
    """The colour key of :func:`network_map` (cell counts): red means one thing on every
    map. With ``n_sealed`` (the map splits the trapped cells) red is sealed and pink the
    dead ends, zeros included; without it red is every trapped cell, and the key says
    they are not split. Until round 2, session 31 a map whose trapped cells were all
    sealed said "red: trapped" and the others "red: sealed" (a seals review)."""
    head = f"black: contact ({n_contact})  white-blue: percolating ({n_percolating})"
    if n_sealed is None:
        return f"{head}\nred: trapped ({n_trapped}; sealed and dead ends not told apart)"
    return (f"{head}\nred: sealed ({n_sealed})  pink: dead end, open to the flow "
            f"({n_trapped - n_sealed})")


@holds_interrupts
def pressure_map(pressure, size, path, *, title="Reynolds pressure (Pa)", at="cells",
                 clim=None):
    """Fluid pressure per cell (``at="cells"``, FV) or at the cell corners (``"nodes"``,
    Q1 FE); NaN where undetermined is grey. ``clim`` (Pa, low and high): the colour range,
    with pressures above it in magenta (the sealed pockets of a coupled solve, whose
    pressure can be many times the inlet's and set the whole scale)."""
    if not load_render_backend():
        return _render_elsewhere("pressure_map", {"pressure": pressure}, size=list(size),
                                 path=str(path), title=title, at=at,
                                 clim=None if clim is None else [float(c) for c in clim])
    p = np.asarray(pressure, float)
    if at == "cells":
        img = _image(p.shape, size)
        img.cell_data["p (Pa)"] = _cells(p)
    else:
        img = _image((p.shape[0] - 1, p.shape[1] - 1), size)
        img.point_data["p (Pa)"] = p.ravel(order="F")
    pl = offscreen_plotter(window_size=(900, 900))
    extra = {}
    if not np.isfinite(p).any():      # no open cell with a pressure: all grey, said, and
        extra = {"clim": [0.0, 1.0]}  # no "All-NaN axis" warning from the colour range
        title += "\nno pressure: no open cell reaches the inlet or the outlet"
    elif clim is not None and np.nanmax(p) > clim[1]:
        extra = {"clim": [float(c) for c in clim], "above_color": "magenta"}
        title += f"\nmagenta: above {clim[1]:.3g} Pa (sealed pockets, up to {np.nanmax(p):.3g} Pa)"
    pl.add_mesh(img, scalars="p (Pa)", cmap="viridis", nan_color="grey", lighting=False,
                scalar_bar_args=side_bar("p (Pa)", x=_BAR_X, y=0.1),
                **extra)
    return _finish(pl, title, path, size, right=_BAR_X - 0.01)


@holds_interrupts
def flux_map(flux_magnitude, size, path, *, title="flux magnitude (m^2/s)"):
    """Cell flux magnitude on a log colour scale (cells without flow: black)."""
    if not load_render_backend():
        return _render_elsewhere("flux_map", {"flux_magnitude": flux_magnitude},
                                 size=list(size), path=str(path), title=title)
    q = np.asarray(flux_magnitude, float)
    pos = q[q > 0]
    if not pos.size:       # a sealed step: say so, not a black square with "0.00" ticks
        title += "\nno flow: no percolating path in this direction (sealed)"
    floor = pos.max() * 1e-8 if pos.size else 1.0
    img = _image(q.shape, size)
    img.cell_data["log10 |q|"] = _cells(np.log10(np.maximum(q, floor)))
    pl = offscreen_plotter(window_size=(900, 900))
    pl.add_mesh(img, scalars="log10 |q|", cmap="inferno", lighting=False,
                scalar_bar_args=side_bar("log10 q, m^2/s", x=_BAR_X, y=0.1))
    return _finish(pl, title, path, size, right=_BAR_X - 0.01)


def steps_figure(steps, path):
    """Leak rate and volumes over the load steps of ``roughfe leak`` (results.json steps);
    with ``persson_leak_rate_<d>`` in the records also Lorenz & Persson's critical-junction
    estimate beside the Reynolds leak rate of each direction, and with
    ``leak_rate_one_way`` (``--fsi``) the one-way leak rate beside the coupled one and a
    third panel of load shares. Steps without a contact area (a coupled lift-off) are
    named below the leak rates.

    The leak-rate panel (a seals review, round 2, session 31): each direction has one
    colour, Reynolds solid with markers, Persson dotted (its x and y differ only by the
    window's W/L: the theory is isotropic); a step sealed along a direction (Q = 0, no
    point on the log axis) gets a down triangle of that direction's colour at the
    bottom, so that a step sealed along x alone is not drawn as sealed."""
    from matplotlib.transforms import blended_transform_factory

    skipped = [s.get("external_pressure", np.nan) for s in steps
               if s.get("area_fraction") is None]
    steps = [s for s in steps if s.get("area_fraction") is not None]
    a = np.array([s["area_fraction"] for s in steps], float)
    coupled = any(s.get("leak_rate_one_way") is not None for s in steps)
    fig, axes = new_figure(1, 3 if coupled else 2, figsize=(15 if coupled else 10, 4))
    ax1, ax2 = axes[0], axes[1]
    bottom = blended_transform_factory(ax1.transData, ax1.transAxes)
    reynolds = "Reynolds, two-way coupled" if coupled else "Reynolds"
    drawn = []
    # the sealed triangles of x below those of y: a step sealed along both shows both
    for d, colour, marker, low in (("x", "C0", "o", 0.03), ("y", "C1", "s", 0.08)):
        q = [s.get(f"leak_rate_{d}") for s in steps]
        if all(v is None for v in q):
            continue
        drawn += _positive(q)
        ax1.semilogy(a, _positive(q), f"{marker}-", color=colour, label=f"{reynolds}, {d}")
        zero = np.array([v is not None and v <= 0 for v in q])
        if zero.any():
            ax1.plot(a[zero], np.full(zero.sum(), low), "v", color=colour, ms=9,
                     transform=bottom, clip_on=False, label=f"sealed along {d} (Q$_{d}$ = 0)")
        p = [s.get(f"persson_leak_rate_{d}") for s in steps]
        if any(v is not None for v in p):
            drawn += _positive(p)
            ax1.semilogy(a, _positive(p), ":", color=colour, lw=1.8,
                         label=f"Persson (critical junction), {d}")
    if not any(f"persson_leak_rate_{d}" in s for s in steps for d in "xy"):
        p = [s.get("persson_leak_rate") for s in steps]   # records without the directions
        if any(v is not None for v in p):
            drawn += _positive(p)
            ax1.semilogy(a, _positive(p), "k:", label="Persson (critical junction), "
                                                      "mean over directions")
    if coupled:
        q = [s.get("leak_rate_one_way") for s in steps]
        drawn += _positive(q)
        ax1.semilogy(a, _positive(q), "^-.", color="0.45", label="one-way (rigid gap)")
    if not np.isfinite(drawn).any():               # no positive rate: an empty log axis
        ax1.text(0.5, 0.5, "every step sealed: Q = 0", transform=ax1.transAxes,
                 ha="center", va="center")
        ax1.set_yticks([])
    if skipped:
        ax1.annotate(f"lift-off (not shown, no contact): p_ext = "
                     f"{', '.join(f'{p:.3g}' for p in skipped)} Pa", (0.01, 0.01),
                     xycoords="axes fraction", fontsize=7, color="0.3")
    ax1.set_xlabel("A* = A_r / A_n")
    ax1.set_ylabel("leak rate Q (m$^3$/s)")
    persson = {d: any(s.get(f"persson_leak_rate{d}") is not None for s in steps)
               for d in ("", "_x", "_y")}
    ax1.set_title("leak rate" + (": Reynolds solid, Persson dotted" if any(persson.values())
                                 else "") + ("\n(Persson is isotropic: its x and y differ by "
                                             "the window's W/L only)"
                                             if persson["_x"] and persson["_y"] else ""),
                  fontsize=9)
    ax1.legend(title="flow", fontsize=7, title_fontsize=8)
    vols = {}
    for key, label in (("free_volume_star", "V*"), ("percolating_volume_star", "V$_p$*"),
                       ("trapped_volume_star", "$\\bar V_p$*")):
        vals = [s.get(key) for s in steps]
        if all(v is not None for v in vals):
            vols[label] = np.array(vals, float)
    positive = [v[v > 0] for v in vols.values() if np.any(v > 0)]
    log = bool(positive) and max(v.max() for v in positive) > 100 * min(v.min()
                                                                      for v in positive)
    for k, (label, vals) in enumerate(vols.items()):   # V* wide below: V* = V_p* + trapped
        zero = vals <= 0
        line, = ax2.plot(a, np.where(zero, np.nan, vals) if log else vals, "o-", label=label,
                         **({"lw": 4, "ms": 9, "alpha": 0.45} if k == 0 else {}))
        if log and zero.any():  # no logarithm: a volume of 0 (sealed) as a mark at the foot
            ax2.plot(np.asarray(a)[zero], np.zeros(int(zero.sum())), "v", ms=7, clip_on=False,
                     color=line.get_color(), transform=ax2.get_xaxis_transform(),
                     label=f"{label} = 0")
    if log:
        ax2.set_yscale("log")      # the trapped volume is decades below the free one
    ax2.set_xlabel("A* = A_r / A_n")
    ax2.set_ylabel("dimensionless volume")
    ax2.set_title("free, percolating and trapped volume", fontsize=10)
    ax2.legend(fontsize=8)
    if coupled:
        for key, label in (("contact_load_fraction", "solid contact"),
                           ("fluid_load_fraction", "fluid film"),
                           ("trapped_load_fraction", "trapped fluid")):
            vals = [s.get(key) for s in steps]
            if any(v is not None for v in vals):
                axes[2].plot(a, [np.nan if v is None else v for v in vals], "o-", label=label)
        axes[2].set_xlabel("A* = A_r / A_n")
        axes[2].set_ylabel("share of the external load")
        axes[2].set_title("load shares (two-way coupled)", fontsize=10)
        axes[2].legend(fontsize=8)
    return save_figure(fig, path)


def _positive(values):
    """Leak rates for a log axis: None and Q <= 0 (sealed) as NaN, no point."""
    return [np.nan if v is None or v <= 0 else float(v) for v in values]


def _by(curves, key):
    out = {}
    for c in curves:
        out.setdefault(c[key], []).append(c)
    return out


def _series(rows, x, y):
    xs = np.array([r[x] if r[x] is not None else np.nan for r in rows], float)
    ys = np.array([r[y] if r[y] is not None else np.nan for r in rows], float)
    return xs, ys


def study_figures(summary, outdir) -> list:
    """Figures of the Sec. 2.4 study from :func:`roughfe.leakage.study.summarise`.

    Writes (PNG): ``vp_vs_separation`` (Fig. 14a,b), ``vnp_vs_separation`` (Fig. 15),
    ``moments`` (Fig. 19), ``vp_vs_moments`` (Fig. 20-21), ``volumes_vs_vstar`` (Fig. 22),
    ``fits_g_beta`` (Fig. 24), ``leak_rate_vs_area`` (Q vs A*). Curves use the finest
    resolution m present unless stated. Returns the paths.
    """
    outdir = Path(outdir)
    curves = summary["curves"]
    m_max = max(c["m"] for c in curves)
    fine = [c for c in curves if c["m"] == m_max]
    byD = _by(fine, "D")
    paths = []

    def per_d(ax, x, y, logy=False, err=None):
        for D, rows in sorted(byD.items()):
            xs, ys = _series(rows, x, y)
            if logy:
                ys = np.where(ys > 0, ys, np.nan)      # zero volumes have no logarithm
            if err:
                _, es = _series(rows, x, err)
                ax.errorbar(xs, ys, yerr=es, marker="o", capsize=2, label=f"D={D:g}")
            else:
                ax.plot(xs, ys, "o-", label=f"D={D:g}")
        if logy:
            ax.set_yscale("log")
        ax.legend(fontsize=8)

    for name, key, label in (("vp_vs_separation", "percolating_volume_star", "V$_p$*"),
                             ("vnp_vs_separation", "trapped_volume_star", "$\\bar V_p$*")):
        fig, (a1, a2) = new_figure(1, 2, figsize=(10, 4))
        per_d(a1, "separation_star_mean", f"{key}_mean", logy=(key == "trapped_volume_star"))
        a1.set_xlabel("d/$\\sigma$")
        a1.set_ylabel(f"{label} (mean, m={m_max})")
        per_d(a2, "separation_star_mean", f"{key}_std")
        a2.set_xlabel("d/$\\sigma$")
        a2.set_ylabel(f"std of {label}")
        fig.suptitle(f"{label} against the mean-plane separation, mean and scatter over the "
                     f"surfaces (m = {m_max}; thesis Fig. {14 if name == 'vp_vs_separation' else 15})",
                     fontsize=10)
        paths.append(save_figure(fig, outdir / f"{name}.png"))

    fig, (a1, a2) = new_figure(1, 2, figsize=(10, 4))
    per_d(a1, "separation_star_mean", "m0_star_mean")
    per_d(a2, "separation_star_mean", "m2_star_mean")
    a1.set_xlabel("d/$\\sigma$"), a1.set_ylabel("m$_0$* = m$_0$/m$_{00}$")
    a2.set_xlabel("d/$\\sigma$"), a2.set_ylabel("m$_2$* = m$_2$/m$_{20}$")
    fig.suptitle(f"spectral moments of the gap against the separation (m = {m_max}; "
                 f"thesis Fig. 19)", fontsize=10)
    paths.append(save_figure(fig, outdir / "moments.png"))

    fig, axes = new_figure(2, 2, figsize=(10, 8))
    per_d(axes[0, 0], "m0_star_mean", "percolating_volume_star_mean")
    per_d(axes[0, 1], "m2_star_mean", "percolating_volume_star_mean")
    per_d(axes[1, 0], "m0_star_mean", "trapped_volume_star_mean", logy=True)
    per_d(axes[1, 1], "m2_star_mean", "trapped_volume_star_mean", logy=True)
    for ax, xl, yl in ((axes[0, 0], "m$_0$*", "V$_p$*"), (axes[0, 1], "m$_2$*", "V$_p$*"),
                       (axes[1, 0], "m$_0$*", "$\\bar V_p$*"), (axes[1, 1], "m$_2$*", "$\\bar V_p$*")):
        ax.set_xlabel(xl), ax.set_ylabel(yl)
    fig.suptitle(f"percolating and trapped volume against the gap's moments (m = {m_max}; "
                 f"thesis Fig. 20-21)", fontsize=10)
    paths.append(save_figure(fig, outdir / "vp_vs_moments.png"))

    ds = sorted({c["D"] for c in curves})
    fig, axes = new_figure(2, len(ds), figsize=(3.2 * len(ds), 6), squeeze=False)
    for j, D in enumerate(ds):
        for m, rows in sorted(_by([c for c in curves if c["D"] == D], "m").items()):
            xs, ys = _series(rows, "free_volume_star_mean", "percolating_volume_star_mean")
            axes[0, j].plot(xs, ys, "o-", label=f"m={m}")
            xs, ys = _series(rows, "free_volume_star_mean", "trapped_volume_star_mean")
            axes[1, j].plot(xs, np.where(ys > 0, ys, np.nan), "o-", label=f"m={m}")
        axes[0, j].set_title(f"D={D:g}")
        axes[1, j].set_yscale("log")
        axes[1, j].set_xlabel("V*")
        axes[0, j].legend(fontsize=7)
    axes[0, 0].set_ylabel("V$_p$*")
    axes[1, 0].set_ylabel("$\\bar V_p$*")
    fig.suptitle("percolating and trapped volume against the free volume, per D and "
                 "resolution m (thesis Fig. 22)", fontsize=10)
    paths.append(save_figure(fig, outdir / "volumes_vs_vstar.png"))

    fig, (a1, a2) = new_figure(1, 2, figsize=(10, 4))
    for D, rows in sorted(_by(summary["fits"], "D").items()):
        ms = [r["m"] for r in rows]
        a1.plot(ms, [np.nan if r["g"] is None else r["g"] for r in rows], "o-", label=f"D={D:g}")
        a2.plot(ms, [np.nan if r["beta"] is None else r["beta"] for r in rows], "o-",
                label=f"D={D:g}")
    a1.set_xlabel("m"), a1.set_ylabel("g = dV$_p$*/dV*  (Eq. 2.17)")
    a2.set_xlabel("m"), a2.set_ylabel("$\\beta$:  $\\bar V_p$* = (V*)$^\\beta$")
    a1.legend(fontsize=8), a2.legend(fontsize=8)
    from matplotlib.ticker import MaxNLocator
    for ax in (a1, a2):                # m is an integer
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    fig.suptitle("fits of Eq. 2.17 per D against the resolution m (thesis Fig. 24)",
                 fontsize=10)
    paths.append(save_figure(fig, outdir / "fits_g_beta.png"))

    fig, ax = new_figure(figsize=(6, 4.5))
    for D, rows in sorted(byD.items()):
        xs, ys = _series(rows, "area_fraction_mean", "leak_rate_mean")
        ax.plot(xs, np.where(ys > 0, ys, np.nan), "o-", label=f"D={D:g}")
    ax.set_yscale("log")
    ax.set_xlabel("A* = A$_r$/A$_n$")
    given = summary.get("settings") or {}
    at = (f"\nat $\\Delta P$ = {given['pressure_drop']:.3g} Pa, "
          f"$\\mu$ = {given['mu']:.3g} Pa s" if "pressure_drop" in given and "mu" in given
          else "")
    ax.set_ylabel(f"leak rate Q (m$^3$/s), mean, m={m_max}{at}")
    ax.legend(fontsize=8)
    paths.append(save_figure(fig, outdir / "leak_rate_vs_area.png"))
    return paths
