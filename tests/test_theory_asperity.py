"""One smooth asperity (roughfe.theory.asperity): Persson's random-roughness theory is
not drawn beside a sphere; Hertz's is (round 2, session 32)."""
import numpy as np
import pytest

from roughfe.bem import contact_sweep
from roughfe.model import Material
from roughfe.surfaces.shapes import sphere_cap
from roughfe.surfaces.spectral import spectral_surface
from roughfe.surfaces.surface import Surface
from roughfe.theory import beside
from roughfe.theory.asperity import single_asperity


def test_a_sphere_is_one_asperity_and_a_rough_or_tilted_window_is_not():
    cap = single_asperity(sphere_cap(32, 0.2, 2.5))
    assert cap["shape"] == "sphere"
    assert cap["radius"] == pytest.approx(2.5, rel=1e-9, abs=0)
    rough = spectral_surface(n=64, size=1e-4, hurst=0.8, rms_height=1e-6, rng=0)
    window = Surface(rough.heights, rough.size, periodic=False)
    assert single_asperity(window) is None
    assert single_asperity(rough) is None              # periodic: no cap
    # a measured file is mostly its tilt (plu-1.plu: 99.996 % of the variance a
    # quadric, 1 % of what its plane leaves): rough heights on a steep plane
    x = np.arange(64) * rough.spacing[0]
    tilted = Surface(window.heights + 0.5 * x[:, None], rough.size, periodic=False)
    assert single_asperity(tilted) is None
    # a cylinder profile
    xs = (np.arange(101) - 50) * 1e-3
    assert single_asperity(Surface(-xs ** 2 / 2.0, 0.101, periodic=False))["radius"] == \
        pytest.approx(1.0, rel=1e-9, abs=0)


def test_beside_a_sphere_is_hertz_not_persson():
    """Until round 2, session 32 the step records of a sphere carried Persson's A*(p)
    (0.10-0.47 of the BEM's on this case) and the figures drew it as the theory."""
    surface = sphere_cap(64, 0.21, 1.0)
    mat = Material(0.91, 0.3)
    sweep = contact_sweep(surface, mat, deltas=np.array([0.5, 1.0, 2.0]) * 1e-3)
    out = beside(surface, mat.E_star, sweep.to_records())
    assert "single_asperity" in out["persson"] and "Persson" in out["persson"]["note"]
    for step, r in zip(out["steps"], sweep.results):
        assert not any(k.startswith("persson_") for k in step)
        # Hertz's area within the cell count of the BEM's contact (a few %), K within 2 %
        assert step["hertz_area_fraction"] == pytest.approx(r.area_fraction, rel=0.05, abs=0)
        assert step["hertz_stiffness"] == pytest.approx(r.stiffness, rel=0.02, abs=0)
    adhesive = beside(surface, mat.E_star, sweep.to_records(), adhesive=True)
    assert adhesive["persson"]["single_asperity"]["shape"] == "sphere"
    assert not any(k.startswith(("persson_", "hertz_")) for s in adhesive["steps"] for k in s)
