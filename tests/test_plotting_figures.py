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
    for label in ("exact, H_cc x = 1", "finite differences"):
        x = _lines(fig.axes[1])[label].get_xdata()
        assert sorted(x) == list(x) and len(x) == 5
