"""Headless figure helpers shared by every plotting module.

matplotlib is forced onto the non-interactive Agg backend; pyvista renders off-screen
(EGL when ``VTK_DEFAULT_OPENGL_WINDOW`` is unset, as the Makefile does). Every image is
written atomically through :func:`roughfe.writers.atomic_path`.
"""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from .._runtime import headless_environment  # noqa: E402
from ..writers import atomic_path  # noqa: E402


def new_figure(*args, **kwargs):
    """``plt.subplots`` with constrained layout (Agg backend)."""
    kwargs.setdefault("layout", "constrained")
    return plt.subplots(*args, **kwargs)


def save_figure(fig, path, dpi=150) -> Path:
    """Save a matplotlib figure atomically, close it, return the path."""
    path = Path(path)
    try:
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=dpi, format=path.suffix.lstrip(".") or "png")
    finally:
        plt.close(fig)
    return path


def offscreen_plotter(window_size=(1000, 800), **kwargs):
    """A ``pyvista.Plotter`` that renders off-screen (no display needed).

    Sets the headless defaults (:func:`roughfe._runtime.headless_environment`) before
    pyvista is imported.
    """
    headless_environment()
    import pyvista as pv
    pv.OFF_SCREEN = True
    return pv.Plotter(off_screen=True, window_size=list(window_size), **kwargs)


def save_screenshot(plotter, path) -> Path:
    """Render ``plotter`` to a PNG atomically and close it; return the path."""
    path = Path(path)
    try:
        with atomic_path(path, suffix=".png") as tmp:
            plotter.screenshot(str(tmp))
    finally:
        plotter.close()
    return path
