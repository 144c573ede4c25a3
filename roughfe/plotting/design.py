"""Figures of roughness design (thesis Figs. 47-70): macro/micro roughness, the genetic
map and its summary, database curves vs targets, similarity per GCMMA stage, sensitivity
to pbar, designed profiles, their K(p)/A(p) and PSDs. Reads results; never solves."""
from __future__ import annotations

import numpy as np

import textwrap

from ..errors import InputError
from ..genomics.design import combined_score, verdict
from ..surfaces.stats import power_spectrum
from .common import new_figure, save_figure

_MACRO, _MICRO = "#d62728", "#1f77b4"


def plot_macro_micro(mm, path, title="") -> "Path":
    """Fig. 47/50: c_n of K(p) and A(p) per chromosome with the threshold."""
    fig, ax = new_figure(figsize=(6.4, 3.6))
    n = np.asarray(mm.chromosomes)
    ax.plot(n, mm.corr_k, "ko-", label="K(p)")
    ax.plot(n, mm.corr_a, "b^-", label="A(p)")
    ax.axhline(mm.threshold, color="r", ls="--", label=f"threshold {mm.threshold:g}")
    ax.set_xlabel("chromosome n")
    ax.set_ylabel("correlation c_n")
    ax.set_title(title or f"macro: n = {list(mm.macro)}")
    ax.legend()
    return save_figure(fig, path)


def plot_macro_micro_profiles(x, total, macro, micro, curves, path, title="") -> "Path":
    """Figs. 48-49: Z, Z_L, Z_S and their K(p), A(p) (``curves``: name -> ResponseCurve)."""
    fig, axes = new_figure(1, 3, figsize=(13, 3.6))
    for h, lab, c in ((total, "Z", "k"), (macro, "Z_L (macro)", _MACRO), (micro, "Z_S (micro)", _MICRO)):
        axes[0].plot(np.asarray(x) * 1e6, np.asarray(h) * 1e6, color=c, lw=1, label=lab)
    axes[0].set_xlabel("x (um)")
    axes[0].set_ylabel("height (um)")
    axes[0].legend()
    for (name, cur), c in zip(curves.items(), ("k", _MACRO, _MICRO)):
        axes[1].plot(cur.pressure, cur.stiffness, "o-", ms=3, color=c, label=name)
        axes[2].plot(cur.pressure, cur.area_fraction, "o-", ms=3, color=c, label=name)
    axes[1].set_xlabel("p (Pa)")
    axes[1].set_ylabel("K (Pa/m)")
    axes[2].set_xlabel("p (Pa)")
    axes[2].set_ylabel("A = A_r/A_n")
    axes[1].legend()
    fig.suptitle(title)
    return save_figure(fig, path)


def plot_genetic_map(rows, path, n_max=None) -> "Path":
    """Fig. 54: one column per genome, one row per chromosome n; red macro, blue micro.

    ``rows``: dicts with ``label``, ``n_c`` and ``macro`` (as :func:`summary_table`).
    """
    n_max = n_max or max(r["n_c"] for r in rows)
    grid = np.full((n_max, len(rows)), np.nan)
    for j, r in enumerate(rows):
        grid[: min(r["n_c"], n_max), j] = 0.0
        for n in r["macro"]:
            if n <= n_max:
                grid[n - 1, j] = 1.0
    from matplotlib.colors import ListedColormap
    fig, ax = new_figure(figsize=(max(6, 0.22 * len(rows) + 2), 0.2 * n_max + 2))
    ax.imshow(grid, cmap=ListedColormap([_MICRO, _MACRO]), vmin=0, vmax=1, aspect="auto",
              origin="lower", extent=(-0.5, len(rows) - 0.5, 0.5, n_max + 0.5),
              interpolation="nearest")
    ax.set_xticks(range(len(rows)))
    ax.set_xticklabels([r["label"] for r in rows], rotation=90, fontsize=7)
    ax.set_xlabel("genome")
    ax.set_ylabel("chromosome n")
    ax.set_title("genetic map: macro (red) / micro (blue) chromosomes")
    return save_figure(fig, path)


def plot_map_summary(rows, path, n_max=None) -> "Path":
    """Fig. 55: share of genomes in which chromosome n (1..n_max) is macro or micro;
    ``n_max`` defaults to the largest n_c of the rows (the thesis' figure stops at 10;
    a fixed 10 dropped the chromosomes beyond it without a note)."""
    if n_max is None:
        n_max = max([int(r["n_c"]) for r in rows] or [1])
    n = np.arange(1, n_max + 1)
    macro = np.array([sum(1 for r in rows if k in r["macro"]) for k in n])
    present = np.array([sum(1 for r in rows if k <= r["n_c"]) for k in n])
    fig, ax = new_figure(figsize=(6.4, 3.6))
    ax.bar(n, macro / np.maximum(present, 1), color=_MACRO, label="macro")
    ax.bar(n, (present - macro) / np.maximum(present, 1), bottom=macro / np.maximum(present, 1),
           color=_MICRO, label="micro")
    for k, m in zip(n, present):          # how many genomes hold chromosome n
        ax.text(k, 1.01, str(int(m)), ha="center", va="bottom", fontsize=7)
    ax.set_xlabel("chromosome n")
    ax.set_ylabel("fraction of genomes")
    ax.set_ylim(0, 1.1)
    ax.set_xticks(n)
    ax.set_title(f"macro / micro share over {len(rows)} genomes (number holding n above)",
                 fontsize=10)
    ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=8)
    return save_figure(fig, path)


def plot_database_curves(entries, targets, path) -> "Path":
    """Fig. 57/67: K(p), A(p) of every database genome rescaled (Eq. 4.2) and the targets;
    each curve drawn from (0, 0), as the score reads it (:meth:`ResponseCurve.points`)."""
    p_max = targets[0].p_max
    fig, axes = new_figure(1, 2, figsize=(11, 4))
    for e in entries:
        c = e.curve.to_target_range(p_max)
        axes[0].plot(*c.points("K"), color="0.7", lw=0.7)
        axes[1].plot(*c.points("A"), color="0.7", lw=0.7)
    colors = ("r", "k", "m")
    for t, col in zip(targets, colors):
        ax = axes[0] if t.quantity == "K" else axes[1]
        ax.plot(t.pressure, t.values, "-", color=col, lw=2, label=t.name)
    axes[0].set_xlabel("p (Pa)")
    axes[0].set_ylabel("K (Pa/m)")
    axes[1].set_xlabel("p (Pa)")
    axes[1].set_ylabel("A = A_r/A_n")
    for ax in axes:
        if ax.get_legend_handles_labels()[0]:
            ax.legend()
    return save_figure(fig, path)


def design_title(result) -> str:
    """A figure title a line long: method, best origin and the verdict on the match with
    the scores that decided it (:func:`~roughfe.genomics.design.verdict`, the message's
    own), and NOT a success when the result's criterion failed. The full
    ``result.message`` (136 characters and more, clipped at both ends as a title until
    session 25) is in result.json and printed."""
    v = verdict(result.best, result.objective.targets)
    return (f"{result.method}: best {result.best.origin}; {v.short()}"
            + ("" if result.success else "; NOT a success (see result.json)"))


def plot_design_curves(results, path, title="") -> "Path":
    """Figs. 60/64/68: K(p) and A(p) of the best design of each result vs the targets;
    ``title`` (e.g. :func:`design_title`) wrapped to the figure's width. A design's
    curve is drawn as the score reads it (:meth:`ResponseCurve.points`): its computed
    steps (marked) and, below the first, the line from (0, 0). The legend's s is that
    reading (Eq. 4.1 on the design's own steps); the title's verdict may be decided by the
    score solved at the target pressures and says so."""
    results = list(results)
    fig, axes = new_figure(1, 2, figsize=(11, 4))
    for t in results[0].objective.targets:
        ax = axes[0] if t.quantity == "K" else axes[1]   # the targets' own panels
        ax.plot(t.pressure, t.values, "r-", lw=2.5, label=f"target {t.name}")
    targets = results[0].objective.targets
    for r, m in zip(results, ("o", "s", "^", "x")):
        c = r.best.curve
        labels = []
        for quantity in ("K", "A"):      # each panel: the scores of its own targets
            own = [f"{sc:.3f}" for t, sc in zip(targets, r.best.scores)
                   if t.quantity == quantity]
            labels.append(f"{r.method} s={', '.join(own)} on its steps" if own else r.method)
        if len(targets) > 1:
            labels[0] += f" (product {combined_score(r.best.scores):.3f})"
        for ax, quantity, label in zip(axes, ("K", "A"), labels):  # from (0, 0), unmarked
            ax.plot(*c.points(quantity), "--" + m, ms=4, markevery=slice(1, None),
                    label=label)
    axes[0].set_xlabel("p (Pa)")
    axes[0].set_ylabel("K (Pa/m)")
    axes[1].set_xlabel("p (Pa)")
    axes[1].set_ylabel("A = A_r/A_n")
    axes[0].legend(fontsize=8)
    axes[1].legend(fontsize=8)
    fig.suptitle(textwrap.fill(title, 100))
    return save_figure(fig, path)


def plot_stages(results, path, title="") -> "Path":
    """Figs. 58/63: similarity of every candidate at GCMMA 0, 1, 2 (and the optional
    refinement stage 3), per method."""
    from ..genomics.design.objective import SELECTION

    fig, ax = new_figure(figsize=(6.4, 4))
    styles = {"sog": "k--", "gco": "r-", "cco": "b-.", "mcco": "m-"}
    for r in results:
        for k, (c, mk) in enumerate(zip(r.candidates, ("^", "o", "x"))):
            ax.plot(range(len(c.stages)), c.stages, styles.get(r.method, "g-"), marker=mk,
                    label=f"{r.method.upper()} ({k + 1}: {c.origin})")
    n = max(len(c.stages) for r in results for c in r.candidates)
    ax.axhline(SELECTION, color="0.5", lw=1, ls=":", label=f"match: s > {SELECTION:g}")
    ax.set_xticks(range(n))
    ax.set_xticklabels(["GCMMA 0", "GCMMA 1", "GCMMA 2", "GCMMA 3\n(refined)"][:n])
    ax.set_ylabel("similarity score s (interpolated, Eq. 4.1)")
    ax.set_title(title or "similarity of each candidate after each GCMMA stage")
    ax.legend(fontsize=7, ncol=2)
    return save_figure(fig, path)


def plot_pbar_sensitivity(pbars, best, n_cross, n_above, path) -> "Path":
    """Fig. 59: best s vs pbar per method (a) and |U3| with the part above 0.95 (b).

    ``best``, ``n_cross``, ``n_above``: dict method -> list aligned with ``pbars``.
    """
    fig, axes = new_figure(1, 2, figsize=(11, 4))
    pbars = np.asarray(pbars)
    for m, st in (("gco", "ro-"), ("cco", "bs-.")):
        if m in best:
            axes[0].plot(pbars, best[m], st, label=m.upper())
    axes[0].set_xlabel("pbar (Pa)")
    axes[0].set_ylabel("best similarity s")
    axes[0].legend()
    w = 0.35 * (pbars[1] - pbars[0] if pbars.size > 1 else 1.0)
    for k, (m, col) in enumerate((("gco", "r"), ("cco", "b"))):
        if m in n_cross:
            axes[1].bar(pbars + (k - 0.5) * w, n_cross[m], w, color=col, label=f"|U3| {m.upper()}")
            axes[1].bar(pbars + (k - 0.5) * w, n_above[m], w, color="w", edgecolor=col)
    axes[1].set_xlabel("pbar (Pa)")
    axes[1].set_ylabel("cardinality of U3 (white: s > 0.95)")
    axes[1].legend()
    return save_figure(fig, path)


def plot_profiles(named_surfaces, path, title="") -> "Path":
    """Figs. 61/65/69: topographies of designed profiles (``name -> Surface``); designed
    surfaces (2D) as height maps, one panel each."""
    if any(s.ndim == 2 for s in named_surfaces.values()):
        fig, axes = new_figure(1, len(named_surfaces), figsize=(4.5 * len(named_surfaces), 4),
                               squeeze=False)
        for ax, (name, s) in zip(axes[0], named_surfaces.items()):
            im = ax.imshow(s.heights.T * 1e6, origin="lower", cmap="viridis",
                           extent=(0, s.size[0] * 1e6, 0, s.size[1] * 1e6))
            fig.colorbar(im, ax=ax, label="height (um)")
            ax.set_xlabel("x (um)")
            ax.set_ylabel("y (um)")
            ax.set_title(name)
        fig.suptitle(title)
        return save_figure(fig, path)
    fig, ax = new_figure(figsize=(8, 3.6))
    for name, s in named_surfaces.items():
        x = s.metadata.get("x0", 0.0) + np.arange(s.shape[0]) * s.spacing[0]
        ax.plot(x * 1e6, s.heights * 1e6, lw=1, label=name)
    ax.set_xlabel("x (um)")
    ax.set_ylabel("height (um)")
    ax.set_title(title)
    ax.legend(fontsize=8)
    return save_figure(fig, path)


def chromosome_psd(surface, q, a):
    """C (two-sided, the convention of :mod:`roughfe.surfaces.stats`) at which the
    chromosomes of rms-equivalent amplitude ``a`` (m) at ``q`` (rad/m) stand beside the
    FFT PSD of ``surface``: the mean square a^2/2 of one chromosome spread over the
    q-space its PSD value stands for (the ``weight`` of :func:`power_spectrum`): a
    profile's 2 dq (C = a^2 / (4 dq), m^3), a surface's annulus 2 pi q dq (C = a^2 /
    (4 pi q dq), m^4; the isotropic density, matched by the annulus average of the FFT
    PSD), dq = 2 pi / L with L the longest side (the annulus width). (Until session 25
    a surface's markers took the profile formula, in m^3: 1e4-1e5 above its PSD.)"""
    q, a = np.asarray(q, float), np.asarray(a, float)
    dq = 2 * np.pi / max(surface.size)
    return a ** 2 / (4 * dq) if surface.ndim == 1 else a ** 2 / (4 * np.pi * q * dq)


#: PSD values below this fraction of the largest are round-off (float64 power of an exact
#: zero): left out of the PSD figure
ROUND_OFF = 1e-20


def _drawn_psd(surf):
    """``(q, C, window name)`` of :func:`power_spectrum`; bins without power (empty
    annuli of a band-limited design: round-off ~1e-48) are NaN, gaps rather than points
    that stretch the log axis over 30 decades."""
    ps = power_spectrum(surf)
    how = "no window" if ps.window == "none" else ps.window.capitalize()
    return ps.q, np.where(ps.C > ROUND_OFF * np.max(ps.C), ps.C, np.nan), how


def plot_psds(named, path, title="", target=None, target_label="target") -> "Path":
    """Figs. 62/66/70: log10 PSD of each designed profile or surface (FFT, line: a
    surface's annulus average; Hann-windowed for non-periodic data, as
    :func:`power_spectrum` reports) and the discrete spectrum of its chromosomes
    (markers at q_n, :func:`chromosome_psd`).

    ``named``: name -> (Surface, list of (q_n (rad/m), a_n (m))). ``target``: a Surface
    whose spectrum the design was matched to (``design --match-spectrum``: the target
    surface as :func:`~roughfe.genomics.design.target_surface` prepares it), drawn on
    every panel by the same estimator (C in m^4 for a surface), labelled
    ``target_label``.
    """
    if target is not None and any(s.ndim != target.ndim for s, _ in named.values()):
        raise InputError(f"the target spectrum is of a {target.ndim}D height field, a design "
                         f"here of another dimension: their C(q) have different units")
    drawn_target = None if target is None else _drawn_psd(target)
    fig, axes = new_figure(1, len(named), figsize=(4.5 * len(named), 3.6), squeeze=False)
    for ax, (name, (surf, lines)) in zip(axes[0], named.items()):
        q, c, how = _drawn_psd(surf)
        ax.loglog(q, c, "k-", lw=0.8,
                  label=f"FFT ({how}{', annulus mean' if surf.ndim == 2 else ''})")
        if drawn_target is not None:
            ax.loglog(*drawn_target[:2], "-", color="tab:blue", lw=1.2, alpha=0.8,
                      label=target_label)
        if lines:
            q, a = np.asarray(lines, float).T
            ax.loglog(q, chromosome_psd(surf, q, a), "rs", ms=4, label="chromosomes")
        # Eq. 3.5 takes wavelengths down to one node spacing: the last chromosomes lie
        # beyond the nodes' Nyquist wavenumber and are aliased on them (docs/theory/05)
        ax.axvline(np.pi / max(surf.spacing), color="0.5", ls=":", lw=1,
                   label="Nyquist pi/dx")
        ax.set_xlabel("q (rad/m)")
        ax.set_ylabel(f"C (m^{surf.ndim + 2})")
        ax.set_title(name)
        ax.legend(fontsize=7)
    fig.suptitle(title)
    return save_figure(fig, path)


def plot_search_history(named, path, goal=None, title="") -> "Path":
    """Best strict f against the strict evaluations spent (``name -> (k, 2) array`` of
    :attr:`DesignResult.search_history` rows), log abscissa; ``goal`` a horizontal line."""
    fig, ax = new_figure()
    for name, h in named.items():
        h = np.asarray(h, dtype=float)
        ax.step(h[:, 0], h[:, 1], where="post", label=name)
    if goal is not None:
        ax.axhline(goal, color="k", ls=":", label=f"goal {goal:g}")
    ax.set_xscale("log")
    ax.set_xlabel("strict evaluations (profiles solved at the target pressures)")
    ax.set_ylabel("best f at the target pressures")
    ax.set_title(title)
    ax.legend()
    return save_figure(fig, path)
