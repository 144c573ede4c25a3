"""Figures of the BEM/FEM cross-validation (reads results, never solves).

* :func:`plot_area_stiffness` -- A*(p) and K(p) curves of several methods overlaid.
* :func:`plot_pressures` -- pressure along the profile at a few loads, BEM vs FEM.
* :func:`plot_westergaard` -- contact half-width error and pressure vs Westergaard.
* :func:`render_deformed_mesh` -- pyvista off-screen picture of the deformed FEM mesh
  coloured by sigma_yy (from the FEM ``ContactResult.fields``), with x and y axes in mm
  or um; :func:`shown_mesh` is the part it draws.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .._runtime import load_render_backend, render_in_fresh_process
from .common import (holds_interrupts, load_pyvista, new_figure, offscreen_plotter,
                     readable_log_ticks, save_figure, save_screenshot, side_bar)

_STYLES = ("-", "--", ":", "-.", (0, (5, 1)), (0, (1, 3)))


def plot_area_stiffness(curves, path, title="") -> Path:
    """Overlay A*(p) and K(p) of several methods.

    Parameters
    ----------
    curves : sequence of dict
        Each with ``label``, ``mean_pressure`` (Pa), ``area_fraction`` and ``stiffness``
        (Pa/m) arrays; optional ``marker``.
    path : path
        PNG file.
    """
    fig, (ax1, ax2) = new_figure(1, 2, figsize=(10, 4))
    for k, c in enumerate(curves):
        p = np.asarray(c["mean_pressure"]) / 1e6
        kw = dict(ls=_STYLES[k % len(_STYLES)], marker=c.get("marker", "o"), ms=3,
                  label=c["label"])
        ax1.plot(p, c["area_fraction"], **kw)
        ax2.plot(p, np.asarray(c["stiffness"]) / 1e12, **kw)
    ax1.set(xlabel="mean pressure p (MPa)", ylabel="A* = A_r / A_n", title="A*(p)",
            xscale="log", yscale="log")
    ax2.set(xlabel="mean pressure p (MPa)", ylabel="K = dp/dDelta (MPa/um)", title="K(p)",
            xscale="log", yscale="log")
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
        readable_log_ticks(ax)
    if title:
        fig.suptitle(title)
    return save_figure(fig, path)


def plot_pressures(x, series, path, title="") -> Path:
    """Pressure along the profile.

    Parameters
    ----------
    x : ndarray
        Positions (m).
    series : sequence of dict
        Each with ``label``, ``pressure`` (Pa, same length as x) and optional ``color``
        and ``style`` (``"line"`` or ``"points"``).
    """
    fig, ax = new_figure(figsize=(10, 4))
    for s in series:
        kw = {"color": s.get("color"), "label": s["label"]}
        if s.get("style", "line") == "points":           # only the loaded points
            p = np.asarray(s["pressure"], float)
            on = p > 0
            ax.plot(np.asarray(x)[on] * 1e3, p[on] / 1e6, "o", ms=3, mfc="none", **kw)
        else:
            ax.plot(np.asarray(x) * 1e3, np.asarray(s["pressure"]) / 1e6, "-", lw=1, **kw)
    ax.set(xlabel="x (mm)", ylabel="pressure (MPa)", title=title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, ncol=2)
    return save_figure(fig, path)


def plot_westergaard(p_star_ratio, width_errors, x, pressure_pairs, path) -> Path:
    """Westergaard check: half-width error vs p/p* and the pressure profiles.

    Parameters
    ----------
    p_star_ratio : ndarray
        p / p* of the load steps.
    width_errors : dict label -> ndarray
        Relative half-width errors (a_num / a_ref - 1) per step.
    x : ndarray
        Positions (m).
    pressure_pairs : sequence of (label, numerical pressure, analytic pressure)
    """
    fig, (ax1, ax2) = new_figure(1, 2, figsize=(10, 4))
    for k, (label, err) in enumerate(width_errors.items()):
        ax1.plot(p_star_ratio, 100 * np.asarray(err), marker="os^"[k % 3], ls=_STYLES[k],
                 label=label)
    ax1.axhspan(-0.5, 0.5, color="g", alpha=0.1, label="target +-0.5 %")
    ax1.set(xlabel="p / p*", ylabel="a / a_Westergaard - 1 (%)", title="contact half-width")
    for k, (label, num, ref) in enumerate(pressure_pairs):
        line, = ax2.plot(np.asarray(x) * 1e3, np.asarray(ref) / 1e6, "-", lw=1)
        ax2.plot(np.asarray(x) * 1e3, np.asarray(num) / 1e6, "o", ms=2.5, mfc="none",
                 color=line.get_color(), label=label)
    ax2.set(xlabel="x (mm)", ylabel="pressure (MPa)",
            title="pressure: FEM (points), Westergaard (lines)")
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    return save_figure(fig, path)


def render_deformed_mesh(fields, path, *, magnification=None, top_fraction=0.35,
                         window_size=(1400, 700), title=None) -> Path:
    """pyvista off-screen picture of the deformed FEM mesh coloured by sigma_yy.

    Parameters
    ----------
    fields : mapping
        ``ContactResult.fields`` (FEM): ``points`` (m), ``cells``, ``displacement`` (m),
        ``stress_yy`` (Pa, per cell).
    path : path
        PNG file.
    magnification : float, optional
        Displacement magnification; default makes the largest displacement 3 % of the
        body width.
    top_fraction : float
        The mesh is shown down to ``top_fraction * W`` below the top, cut along a
        straight line (the stresses of a rough contact are confined near the surface);
        the caption says so, with the body's depth.
    title : str, optional
        First caption line (e.g. the load of the state shown).

    Debian's dolfinx and the vtk wheel cannot render in one process when dolfinx was
    loaded first (vtk aborts in its std::regex): then the picture is rendered by a fresh
    interpreter (:mod:`roughfe._runtime`).
    """
    path = Path(path)
    arrays = {k: np.asarray(fields[k]) for k in ("points", "cells", "displacement", "stress_yy")}
    if load_render_backend():
        return _render(arrays, path, magnification, top_fraction, window_size, title)
    render_in_fresh_process(__name__, "_render_arrays", arrays, path=str(path),
                            magnification=magnification, top_fraction=top_fraction,
                            window_size=list(window_size), title=title)
    return path


def _render_arrays(*, path, magnification, top_fraction, window_size, title=None,
                   **fields) -> Path:
    """:func:`_render` with the fields as keyword arrays (the fresh-process entry point)."""
    return _render(fields, Path(path), magnification, top_fraction, tuple(window_size), title)


def shown_mesh(fields, magnification=None, top_fraction=0.35):
    """The part of the deformed FEM mesh :func:`render_deformed_mesh` draws, as a pyvista
    grid in display units: points ``(x + m u_x, y + m u_y)`` in mm (um for a body
    narrower than 1 mm), ``sigma_yy (MPa)`` per cell, clipped along the straight line
    ``y = top - top_fraction W`` (cells kept whole by their centres drew a saw-tooth
    lower edge the mesh does not have; a user's review). Returns ``(grid, unit, scale,
    magnification, y_cut)``, ``y_cut`` in display units."""
    pv = load_pyvista()

    pts = np.asarray(fields["points"], float)
    disp = np.asarray(fields["displacement"], float)
    cells = np.asarray(fields["cells"], np.int64).reshape(-1, 3)
    width = np.ptp(pts[:, 0])
    if magnification is None:
        umax = np.abs(disp).max()
        magnification = 0.03 * width / umax if umax > 0 else 1.0
    unit, scale = ("mm", 1e3) if width >= 1e-3 else ("um", 1e6)
    pts3 = np.zeros((pts.shape[0], 3))
    pts3[:, :2] = (pts + magnification * disp) * scale
    conn = np.hstack([np.full((cells.shape[0], 1), 3), cells]).ravel()
    grid = pv.UnstructuredGrid(conn, np.full(cells.shape[0], pv.CellType.TRIANGLE, np.uint8),
                               pts3)
    grid.cell_data["sigma_yy (MPa)"] = np.asarray(fields["stress_yy"]) / 1e6
    y_cut = (pts[:, 1].max() - top_fraction * width) * scale
    return (grid.clip(normal="y", origin=(0.0, y_cut, 0.0), invert=False), unit, scale,
            magnification, y_cut)


@holds_interrupts
def _render(fields, path, magnification, top_fraction, window_size, title=None) -> Path:
    plotter = offscreen_plotter(window_size=window_size)
    shown, unit, scale, magnification, y_cut = shown_mesh(fields, magnification, top_fraction)
    pts = np.asarray(fields["points"], float)
    width = np.ptp(pts[:, 0])
    name = "sigma_yy (MPa)"
    lo = float(np.percentile(shown.cell_data[name], 1))
    plotter.add_mesh(shown, scalars=name, cmap="viridis", clim=(lo, 0.0),
                     show_edges=shown.n_cells < 6000,                 # edges hide fine meshes
                     edge_color="grey", line_width=0.2, scalar_bar_args=side_bar(name))
    # axes from the body's left edge and its undeformed top to the cut
    x0 = pts[:, 0].min() * scale
    plotter.show_bounds(bounds=(x0, x0 + width * scale, y_cut, pts[:, 1].max() * scale, 0, 0),
                        xtitle=f"x ({unit})", ytitle=f"y ({unit})",
                        ticks="outside", location="front", show_zaxis=False,
                        show_zlabels=False, n_xlabels=6, n_ylabels=3, fmt="%.3g",
                        color="black", font_size=10)
    caption = (f"deformed mesh (displacements x{magnification:.3g}), cut at y = "
               f"{y_cut:.3g} {unit}: the top {top_fraction:g} W of a body "
               f"{np.ptp(pts[:, 1]) * scale:.3g} {unit} deep, W = {width * scale:.3g} "
               f"{unit}; y = 0 is the undeformed top")
    plotter.add_text(caption if not title else f"{title}\n{caption}", font_size=10)
    plotter.set_background("white")
    plotter.view_xy()
    plotter.reset_camera()
    plotter.camera.zoom(1.3)
    return save_screenshot(plotter, path)
