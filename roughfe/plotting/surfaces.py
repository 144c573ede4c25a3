"""Figures of rough surfaces: 3D render (pyvista, off-screen), profiles and PSDs (matplotlib).

Plotting reads surfaces and statistics computed elsewhere; it never generates or solves.
Lengths are shown in micrometres.
"""
from __future__ import annotations

import numpy as np

from .common import (add_triad, block_centres, block_means, decimation_note,
                     holds_interrupts, load_pyvista, new_figure, offscreen_plotter,
                     render_blocks, save_figure, save_screenshot, side_bar)

UM = 1e6   # metres -> micrometres


@holds_interrupts
def render_surface(surface, path, title=None, exaggeration=None, cmap="viridis",
                   window_size=(1000, 800)):
    """Off-screen 3D render of a surface warped by its height, with a colour bar in um.

    Parameters
    ----------
    surface : Surface
        A 2D surface (m).
    path : str or Path
        PNG file to write (atomically).
    title : str, optional
        Text in the upper-left corner.
    exaggeration : float, optional
        Vertical exaggeration of the heights; default: peak-to-valley shown as 25 % of
        the larger lateral size. The colour bar shows the true heights about their mean
        in um (block means when the grid has more than ``MAX_RENDER_POINTS`` points per
        side).

    Returns
    -------
    Path
    """
    pv = load_pyvista()

    if surface.ndim != 2:
        raise ValueError(f"render_surface needs a 2D surface, got a profile {surface.shape}")
    blocks = render_blocks(surface.shape)
    h = block_means(surface.heights - surface.heights.mean(), blocks) * UM
    ptp = float(np.ptp(surface.heights)) * UM or 1.0
    if exaggeration is None:
        exaggeration = 0.25 * max(surface.size) * UM / ptp
    spacing = [d * UM for d in surface.spacing]
    xx, yy = np.meshgrid(*block_centres(blocks, surface.shape, spacing), indexing="ij")
    grid = pv.StructuredGrid(xx, yy, h * exaggeration)
    grid["h - mean h (um)"] = h.ravel(order="F")
    plotter = offscreen_plotter(window_size=window_size)
    plotter.add_mesh(grid, scalars="h - mean h (um)", cmap=cmap, smooth_shading=True,
                     scalar_bar_args=side_bar("h - mean h (um)"))
    label = title or ""
    label += (f"\n{surface.size[0] * UM:.4g} um x {surface.size[1] * UM:.4g} um, "
              f"vertical exaggeration x{exaggeration:.3g}" + decimation_note(surface.shape, h.shape))
    plotter.add_text(label.strip(), position="upper_left", font_size=11)
    plotter.set_background("white")
    plotter.camera_position = "iso"
    add_triad(plotter)
    # the corner nearest the colour bar clear of it (1.35 put it under the bar; a long
    # surface lies along the view's diagonal and fits at the same zoom)
    plotter.camera.zoom(1.0)
    return save_screenshot(plotter, path)


def plot_profile(surface, path, title=None, axis=0):
    """Line plot of a profile, or of the middle row (``axis=0``: along x) of a surface.

    Heights are plotted as stored (um), so e.g. ``W(0) = 0`` of a WM profile is visible.
    """
    if surface.ndim == 1:
        x, h = surface.coordinates()[0], surface.heights
    else:
        mid = surface.shape[1 - axis] // 2
        h = surface.heights[:, mid] if axis == 0 else surface.heights[mid, :]
        x = surface.coordinates()[axis]
    fig, ax = new_figure(figsize=(7, 3))
    ax.plot(x * UM, h * UM, lw=0.8)
    ax.set_xlabel(f"{'xy'[axis]} (um)")
    ax.set_ylabel("height (um)")
    ax.set_title(title or ("profile" if surface.ndim == 1 else f"profile through the middle, along {'xy'[axis]}"))
    ax.grid(alpha=0.3)
    return save_figure(fig, path)


def _fit_line(ax, psd, fit):
    """The fitted power law over its ``q_range``, dashed. Where the data are not one power
    law (median data/line outside [0.5, 2]: :func:`roughfe.surfaces.psd_fit.fit_level`)
    the fitted slope is drawn at the data's median level, and the values that set the
    Whittle level are ringed (x3p-2.x3p: the line lay 3.5x above its data, set by three
    annuli of the grooves; a user's review)."""
    from ..surfaces.psd_fit import fit_level
    level = fit_level(psd, fit)
    shift = level.median_ratio if not 0.5 <= level.median_ratio <= 2.0 else 1.0
    qf = np.geomspace(*fit.q_range, 20)
    label = f"fit: H = {fit.hurst:.3f}, D = {fit.fractal_dimension:.3f}"
    if shift != 1.0:
        label += (f"\ndrawn at the data's median: the Whittle level is {1 / shift:.2g}x "
                  f"that\n(not one power law)")
    ax.loglog(qf, shift * fit.prefactor * qf ** fit.slope, "k--", lw=1, label=label)
    if shift != 1.0 and level.peak_q.size:
        waves = 2 * np.pi / level.peak_q * UM
        ax.loglog(level.peak_q, level.peak_C, "o", mfc="none", mec="C3", ms=8,
                  label=f"{level.peak_q.size} values carry {level.peak_share:.0%} of the "
                        f"Whittle level\n(wavelengths {waves.min():.2g}-{waves.max():.2g} um)")


def plot_psd(spectra, path, title=None, fits=None, lines=None, coherence=None):
    """Log-log plot of power spectra.

    Parameters
    ----------
    spectra : mapping of label -> PowerSpectrum
        Computed with :func:`roughfe.surfaces.stats.power_spectrum`.
    path : str or Path
        PNG file.
    fits : mapping of label -> HurstFit, optional
        Drawn as dashed power laws over their ``q_range`` with the fitted H (at the
        data's median level when they are not one power law: :func:`_fit_line`).
    lines : mapping of label -> PowerSpectrum, optional
        1D PSDs along x and y of a map
        (:func:`roughfe.surfaces.line_psd.line_power_spectrum`), drawn in a second
        panel (m^3: not on the 2D PSD's axis).
    coherence : TraceRetraceCoherence, optional
        The trace/retrace coherence of the map
        (:func:`roughfe.surfaces.reliability.trace_retrace_coherence`): drawn in a last
        panel with its threshold, and its cutoff ``q_c`` marked in every panel.
    """
    panels = 1 + bool(lines) + (coherence is not None)
    fig, axes = new_figure(1, panels, figsize=(5.5 * panels, 4.5) if panels > 1 else (6, 4.5),
                           squeeze=False)
    ax = axes[0, 0]
    units = set()
    for label, psd in spectra.items():
        units.add(psd.ndim)
        ax.loglog(psd.q, psd.C, ".", ms=3, label=label)
        fit = (fits or {}).get(label)
        if fit is not None and fit.success:
            _fit_line(ax, psd, fit)
    unit = "m$^4$" if units == {2} else ("m$^3$" if units == {1} else "m$^3$ or m$^4$")
    _psd_axes(ax, f"PSD C(q) ({unit}, Persson's normalisation)",   # (2 pi)^-d x ST's
              title or "power spectral density")
    if lines:
        for label, psd in lines.items():
            axes[0, 1].loglog(psd.q, psd.C, ".", ms=3, label=label)
        _psd_axes(axes[0, 1], "1D PSD C(q) (m$^3$, Persson's normalisation)",
                  "mean PSD of the lines along x and along y")
    if coherence is not None:
        _coherence_panel(axes[0, -1], coherence)
        if coherence.q_cutoff is not None:
            for a in axes[0, :-1]:
                a.axvline(coherence.q_cutoff, color="0.4", ls=":", lw=1,
                          label=f"trace/retrace q_c = {coherence.q_cutoff:.3g} rad/m")
                a.legend(fontsize=8)
    return save_figure(fig, path)


def _coherence_panel(ax, c):
    """The trace/retrace coherence gamma^2(q) along the fast axis, its threshold and
    cutoff (:class:`~roughfe.surfaces.reliability.TraceRetraceCoherence`)."""
    ax.semilogx(c.q, c.coherence, ".", ms=3, label=f"gamma^2 along {c.axis} (fast axis)")
    ax.axhline(c.threshold, color="0.4", ls="--", lw=1,
               label=f"{c.threshold:g}: surface power = noise power")
    if c.q_cutoff is not None:
        ax.axvline(c.q_cutoff, color="0.4", ls=":", lw=1,
                   label=f"q_c = {c.q_cutoff:.3g} rad/m ({c.wavelength_cutoff:.3g} m)")
    ax.set_ylim(0, 1.02)
    ax.set_xlabel("wavenumber q (rad/m)")
    ax.set_ylabel("coherence gamma^2 (-)")
    ax.set_title("trace/retrace coherence")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)


def _psd_axes(ax, ylabel, title):
    ax.set_xlabel("wavenumber q (rad/m)")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
