"""Figures of roughness genomics I (thesis Fig. 27-39, 41-46). Reads results, never solves.

Units on the axes: x in mm, heights in um, pressure p in MPa (the BEM mean pressure over
the nominal length), K in Pa/m, A = A_r/A_n.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .common import new_figure, save_figure

_MM, _UM = 1e3, 1e6
_ACQ_COLOURS = ("tab:blue", "black", "tab:red", "tab:green", "tab:purple")


def _scale_name(k, n):
    names = ("10x", "20x", "100x") if n == 3 else ("10x", "20x")
    return names[k] if k < len(names) else f"#{k + 1}"


def plot_sequenced_profiles(result, path) -> Path:
    """Measured and sequenced acquisitions (Fig. 34-35, 42-43) and Z_d = Z_1 - Z_2 (Fig. 33, 41)."""
    n = len(result.x)
    fig, axes = new_figure(n + 1, 1, figsize=(8, 2.3 * (n + 1)))
    for k, ax in enumerate(axes[:n]):
        ax.plot(result.x[k] * _MM, result.heights[k] * _UM, color="black", lw=1.0, label="profile")
        ax.plot(result.x[k] * _MM, result.fitted[k] * _UM, "--", color="tab:red", lw=1.0,
                label="sequenced")
        ns, nf = result.ranges[k]
        ax.set_title(f"{_scale_name(k, n)}: L = {result.lengths[k] * _MM:.4g} mm, n = {ns}..{nf}, "
                     f"relative rms error {100 * result.rms_errors[k]:.3g} %", fontsize=9)
        ax.set_ylabel("Z (um)")
        ax.set_xlabel("x (mm)", fontsize=8)     # each acquisition has its own window
        ax.legend(fontsize=8, loc="best", framealpha=0.8)
    ax = axes[n]
    if result.zd.size:
        ax.plot(result.zd_x * _MM, result.zd * _UM, color="tab:red", lw=1.0, label="Z_d = Z_1 - Z_2")
        ax.plot(result.zd_x * _MM, result.zd_fit * _UM, "--", color="black", lw=1.0,
                label="sequenced Z_d")
        ax.legend(fontsize=8, loc="best", framealpha=0.8)
    ax.set_title("Z_d at the nodes shared by the two coarsest acquisitions", fontsize=9)
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("Z_d (um)")
    g = result.genome
    fig.suptitle(f"sequenced genome: A = {g.A:.4g}, H = {g.H:.4g}, gamma = {g.gamma:.6g},\n"
                 f"lambda1 = {g.lambda1 * _MM:.5g} mm, M = {g.M}"
                 + ("" if result.success else "  [NOT WM-like]"), fontsize=10)
    return save_figure(fig, path)


def plot_spectra(result, path) -> Path:
    """PSDs of the acquisitions with hull vertices, detected peaks and the fitted lattice (Fig. 27, 32)."""
    fig, ax = new_figure(figsize=(8, 5))
    n = len(result.spectra)
    shift = 1.0
    for k, sp in enumerate(result.spectra):
        c = _ACQ_COLOURS[k % len(_ACQ_COLOURS)]
        ax.loglog(sp.q, sp.C * shift, color=c, lw=0.8, label=f"{_scale_name(k, n)} PSD (x{shift:g})")
        ax.loglog(sp.q[sp.hull], sp.C[sp.hull] * shift, "o", mfc="none", color=c, ms=5)
        ax.loglog(sp.peak_q, sp.peak_C * shift, "v", color=c, ms=4)
        shift *= 1e-3
    g = result.genome
    q = g.wavenumber(result.n)
    for qq in q:
        ax.axvline(qq, color="tab:green", lw=0.4, alpha=0.6)
    ax.set_xlabel("q (rad/m)")
    ax.set_ylabel("C(q) (m^3), shifted by 1e-3 per acquisition")
    ax.set_title(f"PSD (Hann window): o hull vertices, v peaks, green lines q_n of gamma = "
                 f"{g.gamma:.5g} (PSD comb: {result.gamma_psd:.4g})", fontsize=9)
    ax.legend(fontsize=8)
    return save_figure(fig, path)


def plot_reconstruction(rec, path, max_steps=6) -> Path:
    """Top-down or bottom-up reconstruction (Fig. 30-31): partial sums (red), chromosome (blue)."""
    k = min(int(max_steps), len(rec.indices))
    fig, axes = new_figure(k, 1, figsize=(8, 1.6 * k + 0.6), sharex=True)
    axes = np.atleast_1d(axes)
    x = rec.x * _MM
    for j, ax in enumerate(axes):
        ax.plot(x, rec.complete * _UM, color="black", lw=0.8, label="complete")
        ax.plot(x, rec.partial_sums[j] * _UM, color="tab:red", lw=1.0, label="partial sum")
        ax.plot(x, rec.chromosomes[j] * _UM, color="tab:blue", lw=0.8, label="added chromosome")
        first = rec.indices[0]
        ax.set_ylabel("Z (um)")
        ax.set_title(f"sum of C_{first} .. C_{rec.indices[j]}", fontsize=8)
        if j == 0:
            ax.legend(fontsize=7, loc="upper right", ncol=3)
    axes[-1].set_xlabel("x (mm)")
    fig.suptitle("top-down reconstruction" if rec.order == "td" else "bottom-up reconstruction",
                 fontsize=10)
    return save_figure(fig, path)


def plot_validity(res, path) -> Path:
    """Monte Carlo of Eq. (3.10) (Fig. 29): valid fraction and how often arccos gives the right phase."""
    fig, ax = new_figure(figsize=(10, 4))
    ax.bar(res.M - 0.2, 100 * res.valid_fraction, width=0.4, label="Eq. 3.10 satisfied")
    ax.bar(res.M + 0.2, 100 * res.arccos_fraction, width=0.4,
           label="theta = arccos(...) reproduces C_n (needs g2 >= 0)")
    ax.axhspan(88.5, 98, color="tab:red", alpha=0.15, label="thesis Fig. 29 range (88.5-98 %)")
    ax.set_xlabel("M (ridges)")
    ax.set_ylabel(f"% of {res.n_trials} random phase sets")
    ax.set_ylim(0, 105)
    ax.set_xticks(res.M)
    ax.legend(fontsize=8, loc="center left", bbox_to_anchor=(1.0, 0.5))
    ax.set_title("Eq. 3.10 is an identity (|g1| <= |sum e^{i phi}|); the arccos phase is right half the time",
                 fontsize=9)
    return save_figure(fig, path)


def _curve(ax, curve, quantity, **kw):
    if curve is None:
        return
    ax.plot(curve.pressure / 1e6, curve.values(quantity), **kw)


def _mech_axes(ax, quantity, title):
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("p (MPa)")
    ax.set_ylabel("K (Pa/m)" if quantity == "K" else "A = A_r / A_n")
    ax.set_title(title, fontsize=9)


def plot_chromosome_curves(mech, path, reference=None) -> Path:
    """A(p) and K(p) of the complete profile and of its chromosomes (Fig. 36, 44)."""
    fig, axes = new_figure(1, 2, figsize=(11, 4.5))
    cmap = __import__("matplotlib").colormaps["viridis"]
    m = len(mech.chromosome_curves)
    for ax, q in zip(axes, ("A", "K")):
        _curve(ax, mech.complete, q, color="tab:red", lw=2.5, label="complete")
        if reference is not None:
            _curve(ax, reference, q, color="black", ls="--", lw=1.5, label="sequenced")
        for j, c in enumerate(mech.chromosome_curves):
            _curve(ax, c, q, color=cmap(j / max(m - 1, 1)), lw=0.9, marker=".", ms=3,
                   label=f"C_{mech.indices[j]}")
        _mech_axes(ax, q, f"{q}(p), {mech.kernel} kernel, E = {mech.youngs_modulus / 1e6:.4g} MPa")
    axes[1].legend(fontsize=7, ncol=2)
    return save_figure(fig, path)


def plot_td_bu(mech, path, quantity="A") -> Path:
    """TD (a) and BU (b) partial sums vs the complete profile (Fig. 37 for A, Fig. 38 for K)."""
    fig, axes = new_figure(1, 2, figsize=(11, 4.5), sharey=True)
    cmap = __import__("matplotlib").colormaps["plasma"]
    n_c = len(mech.indices)
    for ax, curves, name in zip(axes, (mech.td_curves, mech.bu_curves), ("TD", "BU")):
        _curve(ax, mech.complete, quantity, color="black", lw=2.5, label="complete")
        idx = mech.indices if name == "TD" else mech.indices[::-1]
        for j, c in enumerate(curves[:-1]):
            _curve(ax, c, quantity, color=cmap(j / max(n_c - 1, 1)), lw=0.9, ls="--",
                   label=f"C_{idx[0]}..C_{idx[j]}")
        _mech_axes(ax, quantity, f"{name} reconstruction, {mech.kernel} kernel")
        ax.legend(fontsize=6, ncol=2)
    return save_figure(fig, path)


def plot_correlations(mech, path) -> Path:
    """Correlation coefficients c_n of TD, BU and single-chromosome curves with the complete one (Fig. 39, 45)."""
    fig, axes = new_figure(1, 3, figsize=(14, 4), sharey=True)
    for ax, (name, c, idx) in zip(axes, (("TD: C_ns..C_n", mech.c_td, mech.indices),
                                         ("BU: C_nf..C_n", mech.c_bu, mech.indices[::-1]),
                                         ("single chromosome C_n", mech.c_chromosome,
                                          mech.indices[:len(mech.chromosome_curves)]))):
        k = len(c["K"])
        pos = np.arange(k)
        ax.bar(pos - 0.2, c["K"], width=0.4, color="black", label="K(p)")
        ax.bar(pos + 0.2, c["A"], width=0.4, color="tab:blue", label="A(p)")
        ax.axhline(0.95, color="tab:red", lw=1, label="0.95")
        ax.set_xticks(pos)
        ax.set_xticklabels([str(i) for i in idx[:k]], fontsize=7)
        ax.set_xlabel("n (chromosome index; for TD/BU the last one added)")
        ax.set_title(name, fontsize=9)
    axes[0].set_ylabel("c_n")
    allc = np.concatenate([v for d in (mech.c_td, mech.c_bu, mech.c_chromosome) for v in d.values()])
    low = np.nanmin(allc) if np.isfinite(allc).any() else 0.0
    axes[0].set_ylim(min(0.8, low - 0.05), 1.01)
    axes[-1].legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.0, 1.0))  # off the bars
    fig.suptitle(f"correlation with the complete profile ({mech.kernel} kernel)", fontsize=10)
    return save_figure(fig, path)


def plot_measured_vs_sequenced(curves, path, title="") -> Path:
    """A(p) and K(p) of the measured and the sequenced profile, per kernel (Fig. 44 black/red)."""
    kernels = list(curves)
    fig, axes = new_figure(len(kernels), 2, figsize=(11, 4 * len(kernels)), squeeze=False)
    for row, k in zip(axes, kernels):
        d = curves[k]["difference"]
        for ax, q in zip(row, ("A", "K")):
            _curve(ax, curves[k]["measured"], q, color="tab:red", lw=2, label="measured")
            _curve(ax, curves[k]["sequenced"], q, color="black", ls="--", marker=".",
                   label="sequenced")
            _mech_axes(ax, q, f"{k} kernel: max |diff| = {100 * d[q]:.3g} % of max {q}")
            ax.legend(fontsize=8)
    if title:
        fig.suptitle(title, fontsize=10)
    return save_figure(fig, path)


def plot_sequenced_surfaces(result, surfaces, path) -> Path:
    """Measured 2D acquisitions, the sequenced genome at the same nodes and their
    difference (issue 15): the fields of
    :func:`~roughfe.genomics.sequencing.surface_result.misfit_fields` (each about its best
    plane, at the acquisitions' own coordinates), so that the difference panel is the
    reported misfit."""
    from ..genomics.sequencing.surface_result import misfit_fields

    fields = misfit_fields(result.genome, surfaces)
    fig, axes = new_figure(len(fields), 3, figsize=(11, 3.4 * len(fields)), squeeze=False)
    for row, (a, z, fit, diff) in enumerate(fields):
        half = 0.5 * (a.x[1] - a.x[0])                  # the pixels centred on the nodes
        ext = [(a.x[0] - half) * _MM, (a.x[-1] + half) * _MM,
               (a.y[0] - half) * _MM, (a.y[-1] + half) * _MM]
        lim = float(np.nanmax(np.abs(z))) * _UM
        # the difference on its own scale: on the heights' scale a misfit of 1e-3 (or of
        # round-off) is one flat colour (a user's review)
        dlim = max(float(np.nanmax(np.abs(diff))) * _UM, 1e-300)
        for col, (data, name) in enumerate(((z, "measured"), (fit, "sequenced genome"),
                                            (diff, "difference"))):
            ax = axes[row, col]
            top = dlim if col == 2 else lim
            im = ax.imshow(data.T * _UM, origin="lower", extent=ext, cmap="RdBu_r",
                           vmin=-top, vmax=top)
            ax.set_title(f"L = {a.length * _MM:.4g} mm: {name}"
                         + (f"\n(own scale; rms {100 * result.rms_errors[row]:.3g} %)"
                            if col == 2 else ""), fontsize=9)
            ax.set_xlabel("x (mm)")
            ax.set_ylabel("y (mm)")
            if col == 1:
                fig.colorbar(im, ax=axes[row, :2], label="z (um), best plane removed",
                             shrink=0.8)
        fig.colorbar(im, ax=axes[row, 2], label="difference (um)", shrink=0.8)
    g = result.genome
    fig.suptitle(f"sequenced surface genome: M = {g.M}, gamma = {g.gamma:.6g}, H = {g.H:.4g}, "
                 f"A = {g.A:.4g}", fontsize=10)
    return save_figure(fig, path)
