"""The discretisation error at a fixed surface (round 2, session 33): the band-limited
refinement of a surface (``Surface.refined``, roughfe.surfaces.resample) and the grid
check that solves a sweep again on it (roughfe.bem.grid_check, ``roughfe contact
--grid-check``). Measured: docs/theory/02, "Discretisation error at a fixed surface"."""
import json

import numpy as np
import pytest

from roughfe.bem import Material, contact_sweep, solve_contact
from roughfe.bem.grid_check import GRID_CHANGE_LIMIT, grid_check
from roughfe.errors import InputError
from roughfe.reference import westergaard
from roughfe.surfaces import Surface, power_spectrum, spectral_surface

MAT = Material(E=1e9, nu=0.3)
LAM, G = 1e-3, 1e-6


def test_refined_periodic_keeps_samples_and_spectrum():
    """The interpolant passes through the samples; its DFT is the original's on the
    modes both grids carry, the Nyquist coefficient split between +-n/2 (a cosine:
    half the sampled power, the continuous one), zero beyond the original's modes."""
    rng = np.random.default_rng(1)
    s = Surface(rng.normal(size=(16, 11)) * 1e-9, (2e-6, 1e-6), periodic=True)
    r = s.refined(3)
    assert r.shape == (48, 33) and r.size == s.size and r.periodic
    assert r.metadata["refined_from"] == [16, 11] and r.metadata["refined_factor"] == 3
    np.testing.assert_allclose(r.heights[::3, ::3], s.heights, rtol=0, atol=1e-22)
    a, b = np.fft.fft2(s.heights) / s.heights.size, np.fft.fft2(r.heights) / r.heights.size
    kx, ky = np.arange(-7, 8), np.arange(-5, 6)
    np.testing.assert_allclose(b[np.ix_(kx, ky)], a[np.ix_(kx, ky)], rtol=0, atol=1e-24)
    np.testing.assert_allclose(b[8, ky], a[8, ky] / 2, rtol=0, atol=1e-24)
    np.testing.assert_allclose(b[-8, ky], a[8, ky] / 2, rtol=0, atol=1e-24)
    keep = np.zeros(b.shape, bool)
    keep[np.ix_(np.r_[kx, 8, -8], ky)] = True
    assert np.abs(b[~keep]).max() < 1e-12 * np.abs(a).max()
    # a profile, odd factor
    p = Surface(rng.normal(size=17), 1.0, periodic=True)
    np.testing.assert_allclose(p.refined(4).heights[::4], p.heights, rtol=0, atol=1e-14)
    assert s.refined(1) is s


def test_refined_surface_has_the_psd_below_nyquist_and_none_above():
    """Radially averaged PSD (roughfe.surfaces.stats): the same in every annulus below
    the original Nyquist wavenumber, zero beyond the original's largest |q| (its
    corner modes, sqrt 2 q_N)."""
    s = spectral_surface(32, 1e-6, 0.8, rms_height=1e-9, rng=4)
    fine = s.refined(4)
    a, b = power_spectrum(s), power_spectrum(fine)
    dq, q_n = 2 * np.pi / 1e-6, np.pi * 32 / 1e-6
    below = np.arange(a.q.size)[(np.arange(a.q.size) + 1.5) * dq < q_n]
    np.testing.assert_allclose(b.C[below], a.C[below], rtol=1e-10, atol=0)
    beyond = b.q > np.sqrt(2) * q_n + dq
    assert beyond.sum() > 20 and np.all(b.C[beyond] < 1e-20 * a.C.max())
    assert np.sqrt(np.mean(fine.heights ** 2)) == pytest.approx(
        np.sqrt(np.mean(s.heights ** 2)), rel=1e-12, abs=0)   # no Nyquist power: same rms


def test_refined_window_keeps_its_footprint_and_mirror_band_limited_heights():
    """A non-periodic window is refined through its even mirror image (period
    2 (n - 1) dx), sampled at the centres of the sub-cells: heights that are themselves
    even about the end samples and band-limited come back exactly; a tilted plane (the
    worst case: the mirror's kink is its whole slope) is off by 0.34 slope dx in the edge
    sub-cells, 0.10 one cell in and < 0.03 from four cells in (decaying like 1 /
    distance: the band-limited interpolant rounds the kink)."""
    n, m = 24, 19
    i, j = np.meshgrid(np.arange(n), np.arange(m), indexing="ij")

    def f(x, y):
        return np.cos(3 * np.pi * x / (n - 1)) + 0.3 * np.cos(7 * np.pi * y / (m - 1))

    s = Surface(f(i, j) * 1e-9, (n * 1e-7, m * 1e-7))
    for factor in (2, 3):
        r = s.refined(factor)
        assert r.shape == (n * factor, m * factor) and r.size == s.size and not r.periodic
        xs = (np.arange(n * factor) + 0.5) / factor - 0.5
        ys = (np.arange(m * factor) + 0.5) / factor - 0.5
        np.testing.assert_allclose(r.heights, f(*np.meshgrid(xs, ys, indexing="ij")) * 1e-9,
                                   rtol=0, atol=1e-21)
    plane = Surface(0.1 * i.astype(float), (n, m))
    centres = (np.arange(2 * n) + 0.5) / 2 - 0.5
    err = np.abs(plane.refined(2).heights - 0.1 * centres[:, None])
    assert err[0].max() == pytest.approx(0.0335, rel=0.01, abs=0)
    assert err[2].max() == pytest.approx(0.0104, rel=0.01, abs=0)
    assert err[8:-8].max() < 0.03 * 0.1
    with pytest.raises(InputError, match="refinement factor"):
        s.refined(0)
    with pytest.raises(InputError, match="refinement factor"):
        s.refined(1.5)


@pytest.mark.parametrize("s", [0.1, 0.3])
def test_refining_westergaards_sinusoid_converges_to_his_answer(s):
    """A cosine sampled at 8 points per wavelength is band-limited: its refinements are
    the same cosine on finer grids, and the BEM converges to Westergaard. Measured:
    mean gap off by -5.7 % / +4.3 % on 8 points (s = 0.1 / 0.3), within 1e-4 from 256;
    A* by counting points within two points at every grid (it jumps by one)."""
    x = np.arange(8) * LAM / 8
    cosine = Surface(G * np.cos(2 * np.pi * x / LAM), LAM, periodic=True)
    p = s * np.pi * MAT.E_star * G / LAM
    ref = westergaard(G, LAM, MAT.E_star, p)
    gaps = []
    for f in (1, 2, 4, 8, 16, 32):
        r = solve_contact(cosine.refined(f), MAT, mean_pressure=p)
        assert abs(r.area_fraction - ref.area_fraction) <= 2.0 / (8 * f)
        gaps.append(abs(r.mean_gap / ref.mean_gap - 1))
    assert gaps[0] > 0.04 and gaps[-1] < 1e-4 and max(gaps[3:]) < gaps[0] / 20


def _rough(n=32):
    return spectral_surface(n, 1e-5, 0.8, rms_slope=0.5, rng=1)


def test_grid_check_change_shrinks_with_refinement():
    """A surface rough to the grid scale: the check's A* change (fine / coarse - 1) is
    large on the grid as given and shrinks on the refined grids (measured, the larger
    of two loads: -9.6 %, -4.0 %, -2.2 % at 64^2, 128^2, 256^2 of the same surface);
    flagged above the 5 % limit: the first only, with K and the mean gap beside it
    (< 1.2 %, < 0.21 %)."""
    base = _rough(64)
    pressures = [0.02 * MAT.E_star * 0.5, 0.06 * MAT.E_star * 0.5]
    changes = []
    for f in (1, 2, 4):
        s = base.refined(f)
        check = grid_check(s, MAT, contact_sweep(s, MAT, pressures=pressures))
        assert check.shape == (128 * f, 128 * f) and set(check.coarse) == {
            "area_fraction", "stiffness", "mean_gap"}
        np.testing.assert_allclose(check.mean_pressure, pressures, rtol=1e-12, atol=0)
        changes.append(np.abs(check.change("area_fraction")).max())
        if f == 1:
            assert check.flagged and "A*" in check.note()
            doc = json.loads(json.dumps(check.describe()))
            assert doc["flagged"] and doc["steps"][0]["area_fraction_change"] < -GRID_CHANGE_LIMIT
            assert np.abs(check.change("stiffness")).max() < 0.02
            assert np.abs(check.change("mean_gap")).max() < 0.005
        else:
            assert not check.flagged and check.note() is None
    assert changes[0] > 0.08 and changes[1] < 0.6 * changes[0] and changes[2] < 0.6 * changes[1]


def test_grid_check_of_an_adhesive_sweep_compares_the_pull_off():
    """The adhesive sweep is solved again at the same rigid planes (approaches shifted
    by the rise of the highest point), with the pull-off of the unloading branch."""
    from roughfe.bem.adhesion import AdhesionLaw, adhesive_sweep
    rough = _rough(32)
    k = 1e-9 / rough.spacing[0]                   # the same shape at dx = 1 nm, as di-1.di
    s = Surface(rough.heights * k, 32e-9, periodic=True)
    h = s.heights
    law = AdhesionLaw("exp", 0.05, 2e-9)          # di-1's law: 13 zone cells
    mat = Material(2.1e8, 0.0)
    planes = [h.max() - x * np.ptp(h) for x in (0.15, 0.3)]
    deltas = [h.max() - p for p in planes]
    sweep = adhesive_sweep(s, mat, law, deltas, unload=True)
    check = grid_check(s, mat, sweep.sweep, adhesion=law, unload=True)
    assert set(check.coarse) == {"area_fraction", "mean_pressure", "pull_off_pressure"}
    fine = s.refined(2)
    direct = adhesive_sweep(fine, mat, law, [d + fine.heights.max() - h.max() for d in deltas],
                            unload=True)
    # the same solves (to the solver's tolerance: the approaches differ in round-off)
    assert check.fine["pull_off_pressure"][0] == pytest.approx(direct.pull_off_pressure,
                                                               rel=1e-6, abs=0)
    assert check.fine["area_fraction"][1] == pytest.approx(
        direct.sweep.results[1].area_fraction, rel=1e-3, abs=0)
    assert np.isfinite(check.change("pull_off_pressure")[0])
    p0, p1 = check.coarse["mean_pressure"], check.fine["mean_pressure"]     # tensile, both
    np.testing.assert_allclose(check.change("mean_pressure"), (p1 - p0) / np.abs(p0).max(),
                               rtol=1e-12, atol=0)
    assert check.describe()["pull_off_pressure_change"] == pytest.approx(
        direct.pull_off_pressure / sweep.pull_off_pressure - 1, rel=1e-3, abs=1e-6)


def test_grid_check_refuses_what_it_cannot_compare():
    s = _rough(16)
    with pytest.raises(InputError, match="factor"):
        grid_check(s, MAT, contact_sweep(s, MAT, n_steps=2), factor=1)
    with pytest.raises(InputError, match="SweepResult"):
        grid_check(s, MAT, solve_contact(s, MAT, delta=1e-9))
    full = contact_sweep(s, MAT, deltas=[float(s.heights.max() - s.heights.mean())])
    with pytest.raises(InputError, match="partial contact"):
        grid_check(s, MAT, full)


@pytest.mark.slow
def test_contact_cli_grid_check(tmp_path, capsys):
    """``roughfe contact --grid-check``: derived.grid_check in results.json, the table
    and the warning above the limit; refused with --method fem."""
    from roughfe.cli import main
    from roughfe.surfaces.io import save_surface
    path = save_surface(_rough(), tmp_path / "rough.npz")
    out = tmp_path / "out"
    assert main(["contact", str(path), "--E", "1e9", "--nu", "0.3", "--steps", "3",
                 "--grid-check", "--no-figures", "-o", str(out)]) == 0
    doc = json.loads((out / "results.json").read_text())
    check = doc["derived"]["grid_check"]
    assert doc["inputs"]["grid_check"] and check["factor"] == 2 and check["shape"] == [64, 64]
    assert check["flagged"] and check["largest_change"]["area_fraction"]["change"] < -0.05
    assert [s["step"] for s in check["steps"]] == [0, 1]     # step 2: full contact
    profile = save_surface(Surface(np.cos(np.arange(32) / 5.0) * 1e-6, 1e-4), tmp_path / "p.npz")
    printed = capsys.readouterr()
    assert "grid check: the same surface 2x finer (64 x 64 points" in printed.out
    assert "warning: the same surface 2x finer (band-limited) changes A*" in printed.err
    assert main(["contact", str(profile), "--E", "1e9", "--nu", "0.3", "--steps", "2",
                 "--method", "fem", "--grid-check", "-o", str(tmp_path / "fem")]) == 2
    assert "--method fem does not take --grid-check" in capsys.readouterr().err
