"""Figures of BEM contact results: A(p), K(p) curves and a 3D render of the deformed
surface coloured by pressure. Reads results (``SweepResult``/``ContactResult`` or the
step records of ``results.json``); never solves.
"""
from __future__ import annotations

import numpy as np

from .common import (add_triad, block_centres, block_means, block_sums, decimation_note,
                     holds_interrupts, load_pyvista, new_figure, offscreen_plotter,
                     readable_log_ticks, render_blocks, save_figure, save_screenshot,
                     side_bar)

UM = 1e6
MPA = 1e-6


def _column(steps, key):
    return np.array([np.nan if s[key] is None else s[key] for s in steps], float)


def _column_or_zero(steps, key):
    """``key`` of every record, 0 where a record lacks it or holds None."""
    return np.array([s.get(key) or 0.0 for s in steps], float)


def _theory(steps, key):
    """The Persson column ``key`` when the records carry it (else None)."""
    if not any(s.get(key) is not None for s in steps):
        return None
    return np.array([np.nan if s.get(key) is None else s[key] for s in steps], float)


def _along(x, mask):
    """Indices of the points in ``mask`` ordered by ``x``: a branch's line drawn along
    its curve (loads given out of order were joined in solve order, zig-zagging)."""
    idx = np.flatnonzero(mask)
    return idx[np.argsort(x[idx], kind="stable")]


def _branch_note(a, ok, unl):
    """What the log panels say of an unloading branch none of whose steps they draw
    (every step detached, or tensile), else None (until session 25 the branch was listed
    in the legend with no point)."""
    if not unl.any() or (ok & unl).any():
        return None
    if np.all(a[unl] == 0):
        return "unloading: detached at every step"
    return "unloading: no step in compression with contact"


def _legend(ax, note):
    """The panel's legend (if it has labelled lines), ``note`` as its title, or the note
    alone in the lower left corner."""
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=8, title=note, title_fontsize=8)
    elif note:
        ax.text(0.03, 0.03, note, transform=ax.transAxes, fontsize=8)


def plot_area_stiffness(steps, path, title=None, rms_height=None, window_compliance=None,
                        method="BEM"):
    """A*(p), K(p) (exact incremental and central finite differences along p(Delta), each
    branch's lines drawn in order of p whatever the order of the steps) and the mean gap
    u(p), and with ``rms_height`` sigma (m) also V*(d/sigma) (thesis Fig. 8). Records
    with ``persson_area_fraction`` / ``persson_mean_gap`` (:func:`roughfe.theory.beside`)
    get Persson's curves drawn beside the BEM points (and ``persson_stiffness`` its K =
    -dp/du in the K panel; with a hardness ``persson_elastoplastic_area_fraction`` and
    ``persson_plastic_area_fraction`` beside the BEM's A* and ``plastic_area_fraction``); records of one smooth cap get Hertz's A* and K instead
    (``hertz_area_fraction``, ``hertz_stiffness``; :mod:`roughfe.theory.asperity`), and
    with a hardness on a sphere the capped Hertz reference's A*, area at H_p and K
    (``capped_hertz_*``, :mod:`roughfe.theory.capped_hertz`). With the ``window_compliance`` C
    (m/Pa) of a non-periodic window, the K panel marks the window's bulk stiffness 1/C,
    the ceiling K approaches whatever the roughness (:mod:`roughfe.bem.window`).
    ``method`` labels the solver's points ("BEM", or "FEM" for ``contact --method fem``).

    Parameters
    ----------
    steps : list of dict
        Step records (``SweepResult.to_records()`` or ``results.json["steps"]``).
    path : str or Path
        PNG to write.
    rms_height : float, optional
        sigma (m) for the free-volume panel.
    window_compliance : float, optional
        C (m/Pa) of a non-periodic window (``results.json["derived"]``).
    """
    p = _column(steps, "mean_pressure") * MPA
    a = _column(steps, "area_fraction")
    k = _column(steps, "stiffness") * MPA * 1e-6      # MPa/um
    kfd = _column(steps, "stiffness_fd") * MPA * 1e-6
    # the branches apart: an unloading branch drawn as one line with the loading one
    # zig-zagged back over it (hardness, adhesion)
    unl = np.array([bool(s.get("unloading")) for s in steps])
    branches = [(~unl, "o", "", "-")] + ([(unl, "v", " (unloading)", ":")] if unl.any() else [])
    ncol = 3 if rms_height is None else 4
    fig, axes = new_figure(1, ncol, figsize=(5 * ncol, 4))
    ax1, ax2, ax3 = axes[0], axes[1], axes[2]
    if rms_height is not None:
        d = _column(steps, "mean_plane_separation") / rms_height
        v = _column(steps, "free_volume_star")
        for on, mk, tag, ls in branches:
            i = _along(d, on)
            axes[3].plot(d[i], v[i], mk + ls, ms=4, label=method + tag)
        # on a window d = max h - mean h - Delta carries the window's bulk deflection
        # (part of Delta), so it goes below 0 under load (a user's review)
        axes[3].set_xlabel("d / sigma" if not window_compliance else
                           "d / sigma  (d = max h - mean h - Delta: with the window's\n"
                           "bulk deflection in Delta, < 0 under load)")
        axes[3].set_ylabel("V* = V / (A_n sigma)")
        axes[3].set_title("free volume V*(d/sigma), Eq. 2.8")
        axes[3].grid(True, alpha=0.3)
        if unl.any():
            axes[3].legend(fontsize=8)
    # states in compression with contact (a detached or tensile adhesive state has no
    # place on log axes: roughfe contact draws those in adhesion_load_approach.png)
    ok = (p > 0) & (a > 0)
    # an adhesive run that never reaches compression drew three empty panels (a user's
    # review): its states with contact on linear axes instead (p < 0), said in the panels
    tensile = not ok.any() and bool((a > 0).any())
    if tensile:
        ok = np.isfinite(p) & (a > 0)
    loglog = {ax: (ax.plot if tensile else ax.loglog) for ax in (ax1, ax2)}
    a_th = _theory(steps, "persson_area_fraction")
    u_th = _theory(steps, "persson_mean_gap")
    gap = _column(steps, "mean_gap") * UM
    theory = ok & ~unl                 # Persson's theory has no branch: drawn once
    order = np.argsort(p[theory])
    for on, mk, tag, _ in branches:     # a branch with no point gets no legend entry
        if (ok & on).any():
            loglog[ax1](p[ok & on], a[ok & on], mk, ms=4, label=method + tag)
        okg = ok & on & (gap > 0)
        if okg.any():
            (ax3.plot if tensile else ax3.semilogx)(p[okg], gap[okg], mk, ms=4,
                                                    label=method + tag)
    if a_th is not None:
        ax1.loglog(p[theory][order], a_th[theory][order], "-", label="Persson (2001)")
    if u_th is not None:
        ax3.semilogx(p[theory][order], u_th[theory][order] * UM, "-", label="Persson (2007)")
    # with a hardness: Persson's elastoplastic areas (theory.plastic, first loading only)
    # beside the BEM's total and plastic areas (a hardness review: they were written to
    # results.json but drawn nowhere)
    a_ep = _theory(steps, "persson_elastoplastic_area_fraction")
    a_pl = _theory(steps, "persson_plastic_area_fraction")
    if a_ep is not None:
        sel = theory & np.isfinite(a_ep) & (a_ep > 0)
        by_p = np.argsort(p[sel])
        ax1.loglog(p[sel][by_p], a_ep[sel][by_p], "-.", label="Persson, with hardness")
        sel = sel & np.isfinite(a_pl) & (a_pl > 0)
        if sel.any():
            by_p = np.argsort(p[sel])
            ax1.loglog(p[sel][by_p], a_pl[sel][by_p], ":", label="Persson plastic area")
    # the BEM's plastic area beside a theory's (Persson's, or the capped sphere's)
    pl_bem = _column_or_zero(steps, "plastic_area_fraction")
    on = ok & (pl_bem > 0)
    if on.any() and (a_ep is not None or _theory(steps, "capped_hertz_area_fraction")
                     is not None):
        ax1.loglog(p[on], pl_bem[on], "s", ms=4, mfc="none", label=method + " plastic area")
    # one smooth cap (theory.asperity): Hertz's curves in place of Persson's, and with a
    # hardness on a sphere the capped Hertz reference (theory.capped_hertz)
    capped = "Hertz capped at the hardness (rings)"
    for ax, key, style, label in (
            (ax1, "hertz_area_fraction", "--", "Hertz (1882), one smooth asperity"),
            (ax2, "hertz_stiffness", "--", "Hertz (1882), one smooth asperity"),
            (ax1, "capped_hertz_area_fraction", "-.", capped),
            (ax1, "capped_hertz_plastic_area_fraction", ":", capped + ": area at H_p"),
            (ax2, "capped_hertz_stiffness", "-.", capped)):
        curve = _theory(steps, key)
        sel = theory & np.isfinite(curve) & (curve > 0) if curve is not None else None
        if sel is not None and sel.any():
            by_p = np.argsort(p[sel])
            scale = 1.0 if ax is ax1 else MPA * 1e-6
            ax.loglog(p[sel][by_p], curve[sel][by_p] * scale, style, label=label)
    note = (_branch_note(a, ok, unl) if not tensile else
            "no state in compression: the tensile\nstates (p < 0) on linear axes")
    for ax in (ax1, ax3):
        _legend(ax, note)
    ax3.set_xlabel("mean pressure p (MPa)")
    ax3.set_ylabel("mean gap (um)")
    ax3.set_title("mean interfacial separation u(p)")
    ax3.grid(True, which="both", alpha=0.3)
    ax1.set_xlabel("mean pressure p (MPa)")
    ax1.set_ylabel("A* = A_r / A_n")
    ax1.set_title("contact area A(p)")
    ax1.grid(True, which="both", alpha=0.3)
    for on, mk, tag, ls in branches:
        ok2 = _along(p, ok & on & np.isfinite(k) & ((k > 0) | tensile))
        if ok2.size:
            loglog[ax2](p[ok2], k[ok2], mk + ls, ms=4,
                        label="exact (fixed contact set)" + tag)
        ok3 = _along(p, ok & on & np.isfinite(kfd) & ((kfd > 0) | tensile))
        if ok3.size:
            loglog[ax2](p[ok3], kfd[ok3], "x" + ls, ms=5, label="central differences" + tag)
    # with a hardness K is that of the points below it: it jumps as whole grid points
    # yield (a staircase nobody explained; a user's review), so its steps are marked
    flow = ok & np.isfinite(k) & (k > 0) & (_column_or_zero(steps, "plastic_area_fraction") > 0)
    if flow.any():
        ax2.loglog(p[flow], k[flow], "s", ms=7, color="k", mfc="none", mew=0.8,
                   label="plastic flow: K of the points below the hardness\n(it jumps as "
                         "whole grid points yield)")
    k_th = _theory(steps, "persson_stiffness")
    # below full contact only: there K -> inf (the BEM's is inf, not drawn), and a
    # theory point there squashed the panel's range by 6 decades
    if k_th is not None and (theory & np.isfinite(k_th) & (a < 0.999)).any():
        sel = theory & np.isfinite(k_th) & (a < 0.999)
        by_p = np.argsort(p[sel])
        ax2.loglog(p[sel][by_p], k_th[sel][by_p] * MPA * 1e-6, "-",
                   label="Persson, -dp/du" + (" (interface only)" if window_compliance
                                             else ""))
    if window_compliance and ax2.get_legend_handles_labels()[0]:
        ax2.axhline(MPA * 1e-6 / window_compliance, color="0.4", ls="--", lw=1,
                    label="window bulk 1/C (K is in series with it)")
    ax2.set_xlabel("mean pressure p (MPa)")
    ax2.set_ylabel("K = dp/dDelta (MPa/um)")
    ax2.set_title("contact stiffness K(p), Eq. 2.7")
    ax2.grid(True, which="both", alpha=0.3)
    _legend(ax2, note if not tensile or ax2.get_lines() else
            note + "\nK: none of them has one (adhesion)")
    for ax in (ax1, ax2, ax3):
        readable_log_ticks(ax)
        if tensile:               # five labels of p fit beside each other
            ax.locator_params(axis="x", nbins=5)
    if title:
        fig.suptitle(title)
    return save_figure(fig, path)


def plot_adhesion(steps, path, pull_off_force=None, title=None, reference=None):
    """Adhesive contact: load and contact area against the approach, loading and
    unloading branches (the hysteresis loop), the pull-off force marked.

    Parameters
    ----------
    steps : list of dict
        Step records with ``delta`` (m), ``load``, ``area_fraction`` and ``unloading``.
    path : str or Path
        PNG to write.
    pull_off_force : float, optional
        Most tensile load of the unloading branch (same unit as ``load``).
    reference : (float, str), optional
        A theory's pull-off (same unit) and its label, e.g. Maugis' for a sphere.
    """
    d = _column(steps, "delta") * UM
    f = _column(steps, "load")
    a = _column(steps, "area_fraction")
    back = np.array([bool(s.get("unloading")) for s in steps])
    fig, (ax1, ax2) = new_figure(1, 2, figsize=(10, 4))
    for mask, style, label in ((~back, "o-", "loading"), (back, "s--", "unloading")):
        if mask.any():
            ax1.plot(d[mask], f[mask], style, ms=4, label=label)
            ax2.plot(d[mask], a[mask], style, ms=4, label=label)
    if pull_off_force is not None and np.isfinite(pull_off_force):
        ax1.axhline(pull_off_force, color="k", lw=0.8, ls=":",
                    label=f"pull-off {pull_off_force:.3g} (load unit)")
        # a tensile loop orders of magnitude below the compressive loads sat on the zero
        # line: linear within twice the pull-off, logarithmic beyond
        tension = abs(pull_off_force)
        if tension > 0 and np.nanmax(np.abs(f)) > 20 * tension:
            ax1.set_yscale("symlog", linthresh=2 * tension)
            ax1.set_ylim(bottom=-4 * tension)
    if reference is not None and np.isfinite(reference[0]):
        ax1.axhline(reference[0], color="C3", lw=0.8, ls="--",
                    label=f"{reference[1]} {reference[0]:.3g}")
    ax1.axhline(0.0, color="0.5", lw=0.5)
    ax1.set_xlabel("approach Delta (um)")
    ax1.set_ylabel("load (N, or N/m for profiles)")
    ax1.set_title("load-approach, adhesive")
    ax1.legend()
    ax2.set_xlabel("approach Delta (um)")
    ax2.set_ylabel("A* (points at zero gap)")
    ax2.set_title("contact area")
    ax2.legend()
    for ax in (ax1, ax2):
        ax.grid(True, alpha=0.3)
    if title:
        fig.suptitle(title)
    return save_figure(fig, path)


def deformed_heights(heights, result):
    """The rough surface as the deformable body (thesis Fig. 7b), z = h - u - u_pl (m):
    u the elastic displacement, u_pl the plastic one of a state with a hardness (the gap
    is g = u + u_pl + max h - h - Delta, roughfe.bem.contact). Every contact point is
    at z = max h - Delta, elastic or yielded (without u_pl the yielded points of a
    hardness run were drawn over 43 % of the height range; round 2, session 22)."""
    plastic = getattr(result, "plastic_displacement", None)
    z = np.asarray(heights) - result.displacement
    return z if plastic is None else z - plastic


def _state_label(result) -> str:
    """Delta, p and A* of the state shown (and the plastic area with a hardness)."""
    label = (f"Delta = {result.delta * UM:.3g} um, p = {result.mean_pressure * MPA:.3g} MPa, "
             f"A* = {result.area_fraction:.3f}")
    plastic = getattr(result, "plastic_area_fraction", None)
    return label + ("" if plastic is None else f", plastic area {plastic:.3f}")


def plot_profile_state(heights, result, path, title=None):
    """Profile contact: rigid rough profile, deformed elastic flat and pressure."""
    x = np.arange(result.pressure.size) * result.spacing[0] * UM
    h = np.asarray(heights)
    # the elastic flat: max h - Delta + u + u_pl, which touches h where z = max h - Delta
    flat = h.max() - result.delta + (h - deformed_heights(h, result))
    fig, (ax1, ax2) = new_figure(2, 1, figsize=(9, 5), sharex=True)
    ax1.plot(x, h * UM, lw=0.8, label="rough profile")
    ax1.plot(x, flat * UM, lw=0.8, label="deformed elastic surface")
    ax1.set_ylabel("height (um)")
    ax1.legend(loc="best", fontsize=8, framealpha=0.8)
    ax2.plot(x, result.pressure * MPA, lw=0.8)
    ax2.set_xlabel("x (um)")
    ax2.set_ylabel("pressure (MPa)")
    ax1.set_title(((title + ": ") if title else "") + _state_label(result), fontsize=10)
    return save_figure(fig, path)


@holds_interrupts
def render_contact(heights, result, path, title=None, exaggeration=None,
                   window_size=(1000, 800)):
    """Off-screen render of the deformed rough surface z = h - u (- u_pl with a hardness)
    coloured by pressure.

    The thesis treats the rough surface as the deformable body (Fig. 7b): z = h - u puts
    every contact point on the flat at max h - Delta. Contact points are coloured by
    their pressure (MPa), the free (non-contact) area is grey. Grids with more than
    :data:`~roughfe.plotting.common.MAX_RENDER_POINTS` points per side are drawn as block
    means (z; the mean contact pressure where at least half a block is in contact), as
    the label says: contact spots smaller than a block are not seen (A* is in the label).
    """
    pv = load_pyvista()

    h = np.asarray(heights)
    if h.ndim != 2:
        raise ValueError("render_contact needs a surface (2D heights)")
    nx, ny = h.shape
    dx, dy = result.spacing
    blocks = render_blocks(h.shape)
    z = block_means(deformed_heights(h, result), blocks) * UM
    z -= z.mean()
    ptp = float(np.ptp(h)) * UM or 1.0
    if exaggeration is None:
        exaggeration = 0.25 * max(nx * dx, ny * dy) * UM / ptp
    xx, yy = np.meshgrid(*block_centres(blocks, h.shape, (dx * UM, dy * UM)), indexing="ij")
    grid = pv.StructuredGrid(xx, yy, z * exaggeration)
    # mean contact pressure where (most of) a block is in contact, grey (NaN) elsewhere:
    # the grey is the free area; one block = one point unless the grid is decimated
    in_contact = block_means(result.contact, blocks) >= 0.5
    p_sum = block_sums(np.where(result.contact, result.pressure, 0.0), blocks)
    n_contact = np.maximum(block_sums(result.contact, blocks), 1.0)
    pressure = np.where(in_contact, p_sum / n_contact * MPA, np.nan)
    grid["pressure (MPa)"] = pressure.ravel(order="F")
    plotter = offscreen_plotter(window_size=window_size)
    # the colour range ends at the 99th percentile of the contact pressures: contact
    # pressures are heavy-tailed (max / median 16-20 on the measured files), and with the
    # full range 72-77 % of the contact points fell in its lowest tenth, every patch one
    # colour (a user's review). No block in contact: a fixed range (an all-NaN one
    # labelled the bar "nan" and made vtk warn "All-NaN axis encountered").
    shown = pressure[in_contact]
    top = float(np.percentile(shown, 99)) if shown.size else 1.0
    clipped = shown.size and float(shown.max()) > top > 0
    # adhesion: tensile tractions (p < 0) inside the contact, which a range from 0 drew
    # as one flat colour (a user's review): then a diverging map centred on p = 0
    low = float(np.percentile(shown, 1)) if shown.size else 0.0
    if low < 0:
        span = max(-low, top, 1e-300)
        cmap, clim, bar = "coolwarm", (-span, span), "traction (MPa)"
    else:
        cmap, clim, bar = "plasma", (0.0, top if top > 0 else 1.0), "pressure (MPa)"
    plotter.add_mesh(grid, scalars="pressure (MPa)", cmap=cmap, smooth_shading=True,
                     nan_color="lightgrey", clim=clim, scalar_bar_args=side_bar(bar))
    label = (title or "") + (f"\n{_state_label(result)} (free area grey), vertical "
                             f"x{exaggeration:.3g}" + decimation_note(h.shape, z.shape)
                             + (f"; colours to the 99th percentile, {top:.3g} MPa (max "
                                f"{float(shown.max()):.3g})" if clipped else "")
                             + ("; traction < 0 (blue) is tensile" if low < 0 else ""))
    plotter.add_text(label.strip(), position="upper_left", font_size=10)
    plotter.set_background("white")
    plotter.camera_position = "iso"
    add_triad(plotter)
    plotter.camera.zoom(1.0)    # the nearest corner clear of the colour bar
    return save_screenshot(plotter, path)
