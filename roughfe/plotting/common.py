"""Headless figure helpers shared by every plotting module.

matplotlib is forced onto the non-interactive Agg backend; pyvista renders off-screen
(EGL when ``VTK_DEFAULT_OPENGL_WINDOW`` is unset, as the Makefile does). Every image is
written atomically through :func:`roughfe.writers.atomic_path`.
"""
from __future__ import annotations

import functools
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import numpy as np  # noqa: E402

from .._runtime import headless_environment, interrupts_held  # noqa: E402
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


def readable_log_ticks(ax) -> None:
    """Label at least two ticks on each log axis of ``ax`` (call it when the data are
    drawn): an axis spanning less than two powers of ten showed a single label (a K
    panel from 35 to 725 MPa/um: "10^2" alone; a user's review). Such an axis is
    labelled at 1, 2, 5 x 10^k, or at every integer multiple when that still gives fewer
    than two, as plain numbers (3 significant digits)."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    for axis, (lo, hi) in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
        if axis.get_scale() != "log" or not 0 < min(lo, hi):
            continue
        lo, hi = sorted((lo, hi))
        if np.floor(np.log10(hi)) - np.ceil(np.log10(lo)) >= 1:
            continue                          # two powers of ten or more: labelled
        for subs in ((1.0, 2.0, 5.0), np.arange(1.0, 10.0)):
            ticks = LogLocator(base=10, subs=subs).tick_values(lo, hi)
            if np.count_nonzero((ticks >= lo) & (ticks <= hi)) >= 2:
                break
        axis.set_major_locator(LogLocator(base=10, subs=subs))
        axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:.3g}"))
        axis.set_minor_formatter(NullFormatter())


def offscreen_plotter(window_size=(1000, 800), **kwargs):
    """A ``pyvista.Plotter`` that renders off-screen (no display needed).

    Sets the headless defaults (:func:`roughfe._runtime.headless_environment`) before
    pyvista is imported (:func:`load_pyvista`).
    """
    pv = load_pyvista()
    pv.OFF_SCREEN = True
    return pv.Plotter(off_screen=True, window_size=list(window_size), **kwargs)


def load_pyvista():
    """pyvista, headless (:func:`roughfe._runtime.headless_environment`), imported with
    Ctrl-C held (:func:`roughfe._runtime.interrupts_held`; see :func:`holds_interrupts`)."""
    headless_environment()
    with interrupts_held():
        import pyvista as pv
        import pyvista.plotting  # noqa: F401
    return pv


def holds_interrupts(render):
    """Decorator of a function that renders with pyvista: Ctrl-C (and SIGTERM) is held
    until it returns, then delivered (:func:`roughfe._runtime.interrupts_held`). A
    KeyboardInterrupt inside vtk was an ImportError traceback (its lazy module loading),
    an empty mesh and a ValueError in add_mesh (raised in a vtkPythonAlgorithm callback,
    which vtk logs and swallows) or a segmentation fault (``generate rmd --m 11``
    interrupted at 1.5-1.75 s; round 2, session 33). A render takes seconds (block means
    above MAX_RENDER_POINTS)."""
    @functools.wraps(render)
    def held(*args, **kwargs):
        with interrupts_held():
            return render(*args, **kwargs)
    return held


def side_bar(title, x=0.88, y=0.15):
    """``scalar_bar_args`` of a vertical colour bar at the right edge of a render, its
    lower end at ``y`` (window fraction), labels to 3 significant digits."""
    return {"title": title, "vertical": True, "position_x": x, "position_y": y,
            "height": 0.7, "fmt": "%.3g"}


def add_triad(plotter):
    """The x, y, z orientation marker in the lower-left corner of a 3D render (an axes
    actor with captions; unlike the cube axes' tick labels it is safe beside dolfinx)."""
    plotter.add_axes(xlabel="x", ylabel="y", zlabel="z", line_width=2, color="black")


def save_screenshot(plotter, path) -> Path:
    """Render ``plotter`` to a PNG atomically and close it; return the path."""
    path = Path(path)
    try:
        with atomic_path(path, suffix=".png") as tmp:
            plotter.screenshot(str(tmp))
    finally:
        plotter.close()
    return path


#: Most points per side a 3D render draws: a larger grid is shown as block means (a
#: 1000 x 800 window cannot show more; vtk's time grows with the points: a 2048^2 contact
#: render took 29-36 s, 7-8 s CPU, on the shared 2-core machine).
MAX_RENDER_POINTS = 512


def render_blocks(shape, max_points=MAX_RENDER_POINTS) -> tuple:
    """Start index of every display block per axis: square blocks of ceil(n / max_points)
    points of the longest axis, the same on every axis (the last one may be shorter); one
    point per block when every axis fits. (Until round 2, session 28 each axis had its
    own factor: 640 x 480 points were drawn as 320 x 480 blocks of 2 x 1 points.)"""
    step = max(-(-n // max_points) for n in shape)
    return tuple(np.arange(0, n, step) for n in shape)


def block_sums(a, blocks) -> np.ndarray:
    """Sums of ``a`` over the blocks of :func:`render_blocks` (vectorised reduceat)."""
    a = np.asarray(a, dtype=float)
    return np.add.reduceat(np.add.reduceat(a, blocks[0], axis=0), blocks[1], axis=1)


def block_means(a, blocks) -> np.ndarray:
    """Means of ``a`` over the blocks of :func:`render_blocks`."""
    counts = [np.diff(np.append(b, n)) for b, n in zip(blocks, np.shape(a))]
    return block_sums(a, blocks) / np.outer(*counts)


def block_centres(blocks, shape, spacing) -> tuple:
    """Coordinates of the block centres per axis, in the units of ``spacing``."""
    return tuple((b + (np.diff(np.append(b, n)) - 1) / 2.0) * d
                 for b, n, d in zip(blocks, shape, spacing))


def decimation_note(shape, shown) -> str:
    """``", shown as 512 x 512 block means of 2048 x 2048"`` when decimated, else ``""``."""
    if tuple(shape) == tuple(shown):
        return ""
    return (f", shown as {' x '.join(map(str, shown))} block means of "
            f"{' x '.join(map(str, shape))} points")
