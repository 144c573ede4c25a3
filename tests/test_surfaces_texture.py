"""The texture aspect ratio Str (ISO 25178-2) of :mod:`roughfe.surfaces.texture`, checked
on surfaces whose autocorrelation is known in closed form."""
import numpy as np
import pytest

from roughfe.errors import InputError
from roughfe.surfaces.surface import Surface
from roughfe.surfaces.texture import ACF_LEVEL, texture_aspect_ratio


def _bump(n, size, width):
    """A periodic Gaussian bump exp(-(x/wx)^2 - (y/wy)^2): its autocorrelation is the
    Gaussian of widths sqrt(2) w, which falls to ACF_LEVEL at r = sqrt(2 ln(1/0.2)) w
    along each axis, so Str = min(w) / max(w) and the lay lies along the wider axis."""
    x = (np.arange(n[0]) - n[0] / 2) * size[0] / n[0]
    y = (np.arange(n[1]) - n[1] / 2) * size[1] / n[1]
    h = np.exp(-(x[:, None] / width[0]) ** 2 - (y[None, :] / width[1]) ** 2)
    return Surface(h * 1e-6, size, periodic=True)


def test_str_of_a_gaussian_bump_is_its_width_ratio():
    """Round bump: Str 1; a bump 4x as wide along y: Str 1/4, lay along y (90 deg), the
    lengths sqrt(2 ln 5) w. The same bump on rectangular cells (dx 2.5x dy) gives the same
    numbers: Str is taken in metres, not in cells. Tolerances: the ray is sampled every
    half cell with linear interpolation (w = 8 cells: 1 %); the heights' mean is removed
    (the wide bump's is 1.1 % of its peak), which shortens the wide axis' length by 2.7 %
    (both by about as much: Str within 0.01)."""
    r0 = np.sqrt(2 * np.log(1 / ACF_LEVEL))
    round_ = texture_aspect_ratio(_bump((256, 256), (1e-4, 1e-4), (3e-6, 3e-6)))
    assert round_.ratio == pytest.approx(1.0, abs=0.02)
    assert round_.shortest == pytest.approx(r0 * 3e-6, rel=0.02, abs=0)
    lay = texture_aspect_ratio(_bump((256, 256), (1e-4, 1e-4), (3e-6, 12e-6)))
    assert lay.ratio == pytest.approx(0.25, abs=0.01)
    assert lay.lay_angle == pytest.approx(90.0, abs=1.0) and not lay.bounded
    assert lay.longest == pytest.approx(r0 * 12e-6, rel=0.04, abs=0)
    cells = texture_aspect_ratio(_bump((256, 102), (1e-4, 1e-4), (3e-6, 12e-6)))
    assert cells.ratio == pytest.approx(lay.ratio, abs=0.01)
    assert cells.lay_angle == pytest.approx(90.0, abs=1.0)


def test_grooves_along_x_have_their_lay_along_x_and_transposing_turns_it():
    """Grooves h = sin(2 pi y / lambda) (constant along x) on a window: the heights stay
    correlated along x up to the window's end (the zero-padded estimate falls linearly,
    to 0.2 at 0.8 L), across them cos(2 pi r / lambda) reaches 0.2 at acos(0.2) lambda /
    (2 pi). Their transpose is the same lay along y."""
    n, L, lam = 128, 1e-4, 1e-5
    y = np.arange(n) * L / n
    h = np.broadcast_to(np.sin(2 * np.pi * y / lam), (n, n)) * 1e-7
    tex = texture_aspect_ratio(Surface(np.array(h), (L, L), periodic=False))
    assert tex.lay_angle == pytest.approx(0.0, abs=1.0)
    assert tex.shortest == pytest.approx(np.arccos(0.2) * lam / (2 * np.pi), rel=0.03, abs=0)
    assert tex.longest == pytest.approx(0.8 * L, rel=0.02, abs=0)
    turned = texture_aspect_ratio(Surface(np.array(h).T.copy(), (L, L), periodic=False))
    assert turned.lay_angle == pytest.approx(90.0, abs=1.0)
    assert turned.ratio == pytest.approx(tex.ratio, rel=1e-6, abs=0)


def test_str_needs_a_rough_2d_surface():
    with pytest.raises(InputError, match="2D"):
        texture_aspect_ratio(Surface(np.arange(8.0) * 1e-9, (1e-6,), periodic=False))
    with pytest.raises(InputError, match="flat"):
        texture_aspect_ratio(Surface(np.zeros((8, 8)), (1e-6, 1e-6), periodic=False))
