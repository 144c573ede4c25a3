"""Display decimation of large renders (issue 16 sec. 3): block means that conserve sums
and are exact on linear fields at the block centres; a 520^2 contact render is drawn
from 260^2 blocks."""
import numpy as np
import pytest

from roughfe.plotting.common import (MAX_RENDER_POINTS, block_centres, block_means, block_sums,
                                     render_blocks)


@pytest.mark.parametrize("shape", [(2048, 2048), (1030, 700), (300, 5000), (17, 9),
                                   (640, 480)])
def test_blocks_conserve_sums_and_are_exact_on_planes(shape):
    rng = np.random.default_rng(0)
    a = rng.normal(size=shape)
    blocks = render_blocks(shape)
    assert all(len(b) <= MAX_RENDER_POINTS for b in blocks)
    assert block_sums(a, blocks).sum() == pytest.approx(a.sum(), rel=1e-12, abs=1e-9)
    # a linear field's block mean is its value at the block centre (also for the shorter
    # last block of a non-divisible axis)
    dx, dy = 0.5e-6, 2e-6
    x, y = np.arange(shape[0]) * dx, np.arange(shape[1]) * dy
    plane = 3.0 + 2.0 * x[:, None] - 5.0 * y[None, :]
    cx, cy = block_centres(blocks, shape, (dx, dy))
    np.testing.assert_allclose(block_means(plane, blocks), 3.0 + 2.0 * cx[:, None] - 5.0 * cy[None, :],
                               rtol=1e-12, atol=1e-12)
    if max(shape) <= MAX_RENDER_POINTS:           # small grids are drawn point by point
        np.testing.assert_array_equal(block_means(a, blocks), a)
    # square blocks: one step on every axis (640 x 480 was drawn as 2 x 1 blocks)
    steps = {int(b[1] - b[0]) for b in blocks if len(b) > 1}
    assert len(steps) <= 1


def test_a_large_contact_render_is_drawn_from_blocks(tmp_path):
    from roughfe.bem import Material, solve_contact
    from roughfe.plotting.contact import render_contact
    from roughfe.surfaces import Surface

    n = 520                                        # > MAX_RENDER_POINTS: blocks of 2 x 2
    x = np.arange(n) / n
    h = 1e-6 * np.cos(2 * np.pi * x)[:, None] * np.cos(2 * np.pi * x)[None, :]
    s = Surface(h, 1e-4, periodic=True)
    r = solve_contact(s, Material(1e9, 0.0), mean_pressure=2e6, tol=1e-4)
    path = render_contact(s.heights, r, tmp_path / "r.png", title="t", window_size=(400, 300))
    assert path.stat().st_size > 5000


def test_the_deformed_surface_puts_every_contact_point_on_the_flat():
    # with a hardness, yielded points carry a plastic displacement: z = h - u - u_pl is
    # max h - Delta on the whole contact set (without u_pl the render spread the yielded
    # points over 43 % of the height range)
    from roughfe.bem import Material, contact_sweep
    from roughfe.cli.contact_cmd import _shown_step
    from roughfe.plotting.contact import deformed_heights
    from roughfe.surfaces.spectral import spectral_surface
    s = spectral_surface(32, 1e-4, 0.8, rms_height=1e-6, rng=3)
    top = s.heights.max() - s.heights.mean()
    sw = contact_sweep(s, Material(1e9, 0.3), deltas=[0.3 * top, 0.6 * top], hardness=5e7,
                       unload=True)
    assert max(r.plastic_area_fraction for r in sw.results) > 0.05
    for r in (r for r in sw.results if r.n_contact):
        z = deformed_heights(s.heights, r)[r.contact]
        assert np.ptp(z) < 1e-6 * np.ptp(s.heights)
        assert z.mean() == pytest.approx(s.heights.max() - r.delta, abs=1e-6 * np.ptp(s.heights))
    # the state figure shows the largest contact below full contact (full contact is a
    # blank plane), the last such step; full contact only when every step is
    assert _shown_step([0.1, 0.4, 1.0]) == 1
    assert _shown_step([0.1, 0.4, 0.4, 0.2, 0.0]) == 2
    assert _shown_step([1.0, 1.0]) == 1


def test_a_render_without_contact_has_a_finite_colour_range(tmp_path):
    # delta = 0 on a surface touching at one point: no block in contact; the all-NaN
    # pressure gave a colour bar labelled "nan" and vtk's "All-NaN axis" warning
    import warnings

    from roughfe.bem import Material, solve_contact
    from roughfe.plotting.contact import render_contact
    from roughfe.surfaces.spectral import spectral_surface
    s = spectral_surface(32, 1e-4, 0.8, rms_height=1e-6, rng=3)
    r = solve_contact(s, Material(1e9, 0.0), delta=0.0)
    assert r.n_contact <= 1
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        path = render_contact(s.heights, r, tmp_path / "r.png", title="t", window_size=(400, 300))
    assert path.stat().st_size > 5000


def test_tensile_tractions_get_a_diverging_colour_range(tmp_path, monkeypatch):
    """Adhesive contact carries tensile tractions (p < 0) inside the contact; the render's
    range from 0 drew all of them as one flat colour (a user's review). A contact with
    p < 0 gets a range symmetric about 0 on a diverging map; a compressive one keeps
    (0, 99th percentile)."""
    import dataclasses

    import roughfe.plotting.contact as pc
    from roughfe.bem import Material, solve_contact
    from roughfe.surfaces.spectral import spectral_surface
    s = spectral_surface(32, 1e-4, 0.8, rms_height=1e-6, rng=3)
    r = solve_contact(s, Material(1e9, 0.0), mean_pressure=5e6)
    seen = []
    make = pc.offscreen_plotter

    def recording(**kw):
        plotter = make(**kw)
        add = plotter.add_mesh
        plotter.add_mesh = lambda *a, **k: seen.append(k) or add(*a, **k)
        return plotter
    monkeypatch.setattr(pc, "offscreen_plotter", recording)
    pc.render_contact(s.heights, r, tmp_path / "c.png", window_size=(300, 200))
    tensile = dataclasses.replace(r, pressure=np.where(r.contact, r.pressure - 3e6, 0.0))
    pc.render_contact(s.heights, tensile, tmp_path / "t.png", window_size=(300, 200))
    (lo_c, hi_c), (lo_t, hi_t) = seen[0]["clim"], seen[1]["clim"]
    assert lo_c == 0.0 and hi_c > 0 and seen[0]["cmap"] == "plasma"
    assert lo_t == -hi_t and lo_t < 0 and seen[1]["cmap"] == "coolwarm"
    assert -lo_t * 1e6 >= -np.percentile(tensile.pressure[tensile.contact], 1) * (1 - 1e-9)
