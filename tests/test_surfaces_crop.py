"""Surface.cropped: a window of a profile or surface by index ranges or physical extents.
What a window must be: the same heights on the same spacing, non-periodic, a plane stays
that plane, windows compose, and a window that is not one is refused saying why."""
import numpy as np
import pytest

from roughfe.errors import InputError
from roughfe.surfaces import Surface, spectral_surface
from roughfe.surfaces.stats import rms_slope


def _plane(shape=(40, 30), size=(4e-5, 6e-5), slopes=(0.02, -0.05)):
    x, y = (c[:, None] if k == 0 else c[None, :]
            for k, c in enumerate(np.arange(n) * (s / n) for n, s in zip(shape, size)))
    return Surface(slopes[0] * x + slopes[1] * y + 1e-6, size), slopes


def test_a_window_of_a_plane_is_the_same_plane():
    plane, slopes = _plane()
    window = plane.cropped(index=((5, 25), (3, 21)))
    coef = window.detrended("plane")
    # the tilt removed from the window is the plane's: nothing is left
    np.testing.assert_allclose(coef.heights, 0, atol=1e-12 * np.ptp(plane.heights))
    dx, dy = window.spacing
    gx = np.diff(window.heights, axis=0) / dx
    gy = np.diff(window.heights, axis=1) / dy
    np.testing.assert_allclose(gx, slopes[0], rtol=1e-9)
    np.testing.assert_allclose(gy, slopes[1], rtol=1e-9)
    assert rms_slope(window) == pytest.approx(np.hypot(*slopes), rel=1e-9)


def test_size_scales_with_the_points_and_the_spacing_is_kept():
    plane, _ = _plane()
    window = plane.cropped(index=((5, 25), None))
    assert window.shape == (20, 30)
    assert window.spacing == pytest.approx(plane.spacing, rel=1e-12, abs=0)
    assert window.size == pytest.approx((20 * plane.spacing[0], plane.size[1]), rel=1e-12, abs=0)
    assert window.nominal_area == pytest.approx(plane.nominal_area * 20 / 40, rel=1e-12, abs=0)


def test_extent_selects_the_cell_centres_inside_it():
    plane, _ = _plane()
    dx, dy = plane.spacing
    by_extent = plane.cropped(extent=((5 * dx, 25 * dx), (3 * dy, 21 * dy)))
    by_index = plane.cropped(index=((5, 25), (3, 21)))
    np.testing.assert_array_equal(by_extent.heights, by_index.heights)
    assert by_extent.size == pytest.approx(by_index.size, rel=1e-12, abs=0)
    # a range between grid points takes the centres inside: [5.5 dx, 9.5 dx) -> 6..9
    part = plane.cropped(extent=((5.5 * dx, 9.5 * dx), None))
    np.testing.assert_array_equal(part.heights, plane.heights[6:10])


def test_a_window_of_a_periodic_surface_is_not_periodic():
    s = spectral_surface(n=32, size=1e-5, hurst=0.8, rms_height=1e-7, rng=1)
    assert s.periodic
    window = s.cropped(index=((0, 16), (0, 16)))
    assert window.periodic is False
    # the whole grid is a window too, and it does not repeat by declaration any more
    assert s.cropped(index=((0, 32), (0, 32))).periodic is False


def test_a_crop_of_a_crop_is_one_crop():
    s = spectral_surface(n=32, size=1e-5, hurst=0.8, rms_height=1e-7, rng=2)
    twice = s.cropped(index=((4, 28), (2, 30))).cropped(index=((3, 10), (5, 20)))
    once = s.cropped(index=((7, 14), (7, 22)))
    np.testing.assert_array_equal(twice.heights, once.heights)
    assert twice.size == pytest.approx(once.size, rel=1e-12, abs=0)
    assert twice.metadata["window"] == once.metadata["window"] == [[7, 14], [7, 22]]
    assert twice.metadata["window_of_shape"] == [32, 32]


def test_a_profile_takes_one_pair():
    p = Surface(np.linspace(0, 1e-6, 10), 1e-5)
    window = p.cropped((2, 7))
    np.testing.assert_array_equal(window.heights, p.heights[2:7])
    assert window.size == pytest.approx((5e-6,), rel=1e-12, abs=0)
    assert p.cropped(extent=(2e-6, 7e-6)).shape == (5,)


@pytest.mark.parametrize("kwargs, words", [
    ({}, "one of them"),
    ({"index": ((0, 10), None), "extent": ((0, 1e-6), None)}, "one of them"),
    ({"index": ((0, 41), None)}, "index\\[0\\] = \\(0, 41\\).*stop <= 40"),
    ({"index": (None, (10, 5))}, "index\\[1\\] = \\(10, 5\\).*start < stop <= 30"),
    ({"index": ((7, 7), None)}, "stop - start >= 2"),
    ({"index": ((7, 8), None)}, "stop - start >= 2"),
    ({"index": ((-3, 8), None)}, "index\\[0\\] start.*integer >= 0, got -3"),
    ({"index": ((1.5, 8), None)}, "integer >= 0, got 1.5"),
    ({"index": (1, 8)}, "must be \\(\\(x_start, x_stop\\), \\(y_start, y_stop\\)\\)"),
    ({"extent": ((0, 5e-5), None)}, "extent\\[0\\].*stop <= 4e-05 m"),
    ({"extent": (None, (3e-5, 1e-5))}, "extent\\[1\\].*0 <= start < stop"),
    ({"extent": ((0, float("nan")), None)}, "extent\\[0\\]"),
    ({"extent": ((0, 1e-6), None)}, "holds 1 point.*needs at least 2"),
])
def test_a_window_that_is_not_one_is_refused_saying_what_is_allowed(kwargs, words):
    plane, _ = _plane()
    with pytest.raises(InputError, match=words):
        plane.cropped(**kwargs)
