"""Figures of band chromosomes of a surface (issue 15 §2). Reads results, never solves.

* :func:`render_band_sums` -- pyvista renders of chromosomes or TD/BU partial sums (2D);
  line plots for profiles.
* :func:`plot_band_energy` -- the variance budget per band against wavelength.
* :func:`plot_band_curves` -- A(p) and K(p) of every TD and BU partial sum.
* :func:`plot_band_correlations` -- c_n bars (chromosomes, TD, BU) with the Alg. 2 threshold.

Units: lengths in um, heights in um, pressure in MPa, K in Pa/m.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .common import (holds_interrupts, load_pyvista, new_figure, offscreen_plotter,
                     save_figure, save_screenshot)

_UM, _MPA = 1e6, 1e-6
#: largest number of grid points per axis drawn in a render (larger grids are strided)
RENDER_MAX_POINTS = 256


def _panels(bands, which):
    if which == "chromosomes":
        return bands.chromosomes, [f"C_{n}" for n in bands.indices]
    sums = bands.partial_sums(which)
    idx = bands.indices if which == "td" else bands.indices[::-1]
    first = idx[0]
    return sums, [f"{which.upper()} C_{first}..C_{n}" for n in idx]


def _pick(n, max_panels):
    if n <= max_panels:
        return np.arange(n)
    return np.unique(np.round(np.linspace(0, n - 1, max_panels)).astype(int))


@holds_interrupts
def render_band_sums(bands, path, which: str = "td", max_panels: int = 6) -> Path:
    """Renders (2D) or line plots (profiles) of ``which`` in {"td", "bu", "chromosomes"}.

    At most ``max_panels`` panels, evenly spread over the bands (the last one is the
    complete surface for partial sums); grids above ``RENDER_MAX_POINTS`` per axis are
    strided for the render (the heights are not changed).
    """
    from ..genomics.macro_micro import is_flat
    fields, labels = _panels(bands, which)
    pick = _pick(len(fields), int(max_panels))
    surf = bands.surface
    scale = float(np.max(np.abs(surf.heights)))
    # a band that is round-off of the surface (is_flat, as Alg. 2 treats it) is said to
    # be empty, not stretched to a full-height comb of noise
    flat = [is_flat(fields[k], scale) for k in range(len(fields))]
    labels = [lab + (" (empty: round-off)" if f else "") for lab, f in zip(labels, flat)]
    if surf.ndim == 1:
        fig, axes = new_figure(len(pick), 1, figsize=(8, 1.5 * len(pick) + 0.6), sharex=True)
        x = surf.coordinates()[0] * _UM
        for ax, k in zip(np.atleast_1d(axes), pick):
            ax.plot(x, fields[k] * _UM, lw=0.8, color="tab:blue")
            ax.set_ylabel("z (um)")
            ax.set_title(labels[k], fontsize=9)
        np.atleast_1d(axes)[-1].set_xlabel("x (um)")
        return save_figure(fig, path)
    pv = load_pyvista()
    stride = [max(1, int(np.ceil(n / RENDER_MAX_POINTS))) for n in surf.shape]
    x, y = (c[::s] * _UM for c, s in zip(surf.coordinates(), stride))
    xx, yy = np.meshgrid(x, y, indexing="ij")
    cols = min(3, len(pick))
    rows = int(np.ceil(len(pick) / cols))
    plotter = offscreen_plotter(window_size=(420 * cols, 380 * rows), shape=(rows, cols))
    lateral = max(surf.size) * _UM
    for j, k in enumerate(pick):
        plotter.subplot(j // cols, j % cols)
        h = fields[k][::stride[0], ::stride[1]] * _UM
        if flat[k]:
            h = np.zeros_like(h)
        ptp = float(np.ptp(h)) or 1.0
        grid = pv.StructuredGrid(xx, yy, h * 0.25 * lateral / ptp)
        grid["z (um)"] = h.ravel(order="F")
        plotter.add_mesh(grid, scalars="z (um)", cmap="viridis", show_scalar_bar=False)
        shown = "" if flat[k] else f", z shown x{0.25 * lateral / ptp:.3g}"
        plotter.add_text(f"{labels[k]}\nrms {np.std(fields[k]) * _UM:.3g} um{shown}",
                         font_size=9)
        plotter.set_background("white")
        plotter.camera_position = "iso"
    return save_screenshot(plotter, path)


def plot_band_energy(bands, path) -> Path:
    """Mean-square height of each band (the Parseval budget) against its centre wavelength."""
    fig, ax = new_figure(figsize=(7, 4))
    lam = bands.wavelengths()
    centre = np.sqrt(lam[:-1] * lam[1:]) * _UM
    share = bands.energy / bands.energy.sum()
    ax.bar(np.arange(bands.n_chromosomes), 100 * share, color="tab:blue")
    ax.set_xticks(np.arange(bands.n_chromosomes))
    # rotated, 2 significant digits: 19 bands of di-1 ran together as "0.009290.00657..."
    ax.set_xticklabels([f"{n}: {c:.2g}" for n, c in zip(bands.indices, centre)], fontsize=7,
                       rotation=60, ha="right", rotation_mode="anchor")
    ax.set_xlabel("band n / centre wavelength (um)")
    ax.set_ylabel("share of <h^2> (%)")
    ax.set_title(f"variance budget of {bands.n_chromosomes} bands (gamma = {bands.gamma:.4g}, "
                 f"{bands.transform.upper()}, detrend {bands.detrend})", fontsize=9)
    return save_figure(fig, path)


def plot_band_curves(mech, path) -> Path:
    """A(p) and K(p) of the TD (top row) and BU (bottom row) partial sums; the complete
    surface in black."""
    fig, axes = new_figure(2, 2, figsize=(10, 7))
    n_c = len(mech.indices)
    cmap = __import__("matplotlib").colormaps["viridis"]
    for row, (name, curves, idx) in enumerate((("TD", mech.td_curves, mech.indices),
                                               ("BU", mech.bu_curves, mech.indices[::-1]))):
        for k, (c, n) in enumerate(zip(curves, idx)):
            if c is None or c is mech.complete:
                continue
            colour = cmap(k / max(n_c - 1, 1))
            axes[row, 0].plot(c.pressure * _MPA, c.area_fraction, color=colour, lw=0.9,
                              label=f"..C_{n}" if k % max(1, n_c // 6) == 0 else None)
            axes[row, 1].plot(c.pressure * _MPA, c.stiffness, color=colour, lw=0.9)
        for col, q in enumerate(("area_fraction", "stiffness")):
            ax = axes[row, col]
            ax.plot(mech.complete.pressure * _MPA, getattr(mech.complete, q), color="black",
                    lw=2, label="complete" if col == 0 else None)
            ax.set_xscale("log")
            if col == 1:          # K spans decades over the pressures (as roughfe contact)
                ax.set_yscale("log")
            ax.set_xlabel("p (MPa)")
            ax.set_ylabel("A*" if col == 0 else "K (Pa/m)")
            ax.set_title(f"{name} partial sums: {'A(p)' if col == 0 else 'K(p)'}", fontsize=9)
        axes[row, 0].legend(fontsize=7)
    return save_figure(fig, path)


def plot_band_correlations(mech, path, macro_micro=None) -> Path:
    """c_n of K(p) for chromosomes, TD and BU sums; macro bands of Alg. 2 highlighted."""
    fig, ax = new_figure(figsize=(8, 4))
    n = np.asarray(mech.indices)
    w = 0.27
    ax.bar(n - w, np.nan_to_num(mech.c_chromosome["K"]), w, label="C_n alone", color="tab:blue")
    ax.bar(n, np.nan_to_num(mech.c_td["K"]), w, label="TD sum to n", color="tab:orange")
    ax.bar(n + w, np.nan_to_num(mech.c_bu["K"][::-1]), w, label="BU sum from n", color="tab:green")
    if macro_micro is not None:
        ax.axhline(macro_micro.threshold, color="tab:red", ls="--", lw=1,
                   label=f"threshold {macro_micro.threshold:g}")
        for m in macro_micro.macro:
            ax.axvspan(m - 0.5, m + 0.5, color="tab:red", alpha=0.08)
    ax.set_xlabel("band n")
    ax.set_ylabel("c_n of K(p)")
    ax.set_xticks(n)
    # the range of the bars (and the threshold): c_n near 1 are told apart
    shown = np.concatenate([np.asarray(mech.c_chromosome["K"], float),
                            np.asarray(mech.c_td["K"], float), np.asarray(mech.c_bu["K"], float),
                            [macro_micro.threshold] if macro_micro is not None else []])
    low = float(np.nanmin(shown)) if np.isfinite(shown).any() else 0.0
    ax.set_ylim(min(low - 0.05 * (1.0 - low) - 0.01, 0.95), 1.005)
    ax.set_title("correlation with the complete K(p) (Alg. 2); shaded: macro bands", fontsize=9)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.0, 1.0), framealpha=0.9)
    return save_figure(fig, path)
