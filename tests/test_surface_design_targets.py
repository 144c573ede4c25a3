"""Targets of a measured (non-periodic) window for surface design (issue 15 Sec. 3): the
evenly mirrored window is the periodic interface the designs are; the window alone on a
half-space adds its own bulk compliance in series (1/K_window ~ 1/K_periodic + C)."""
import re
from dataclasses import replace

import numpy as np
import pytest

from roughfe.errors import InputError
from roughfe.genomics import database as db
from roughfe.genomics.design import surface_targets, window_compliance
from roughfe.surfaces import Surface
from roughfe.surfaces.io import load_surface

E = 210e6


def _settings_only_db(tmp_path, settings):
    """A database file holding only ``settings`` (what design-targets reads of it)."""
    from roughfe.genomics.database.store import connect, write_settings
    path = tmp_path / "s.sqlite"
    con = connect(path, create=True)
    write_settings(con, settings)
    con.commit()
    con.close()
    return path


def test_mirrored_window_is_the_even_periodic_extension():
    rng = np.random.default_rng(3)
    h = rng.normal(size=(5, 7))
    s = Surface(h, (5e-6, 14e-6))
    m = s.mirrored()
    assert m.periodic and m.shape == (8, 12) and m.spacing == pytest.approx(s.spacing)
    np.testing.assert_array_equal(m.heights[:5, :7], h)
    # even about both edges of the window: h(i) = h(-i) = h(2(n-1) - i)
    np.testing.assert_array_equal(m.heights, np.roll(m.heights[::-1, ::-1], (1, 1), (0, 1)))
    assert Surface(np.arange(4.0), 4.0).mirrored().heights.tolist() == [0, 1, 2, 3, 2, 1]


def test_resampled_is_the_band_limited_interpolant():
    """Waves both grids resolve are evaluated exactly on the new nodes; a wave beyond the
    new Nyquist wavenumber is removed (thinning would alias it); the mean is kept;
    resampling onto the same grid is the identity."""
    x = np.arange(40) / 40
    keep = 1.0 + np.cos(2 * np.pi * 3 * x)[:, None] + 0.5 * np.sin(2 * np.pi * (2 * x[:, None]
                                                                              + 5 * x[None, :]))
    s = Surface(keep + np.cos(2 * np.pi * 15 * x)[None, :], (1e-5, 1e-5), periodic=True)
    r = s.resampled((16, 12))
    xr, yr = np.arange(16) / 16, np.arange(12) / 12
    exact = 1.0 + np.cos(2 * np.pi * 3 * xr)[:, None] + 0.5 * np.sin(
        2 * np.pi * (2 * xr[:, None] + 5 * yr[None, :]))
    np.testing.assert_allclose(r.heights, exact, atol=1e-13)
    assert r.size == s.size and r.periodic
    np.testing.assert_allclose(s.resampled((40, 40)).heights, s.heights, atol=1e-13)
    with pytest.raises(InputError, match="periodic"):
        Surface(keep, (1e-5, 1e-5)).resampled((8, 8))
    with pytest.raises(InputError, match="shape"):
        s.resampled((8,))
    with pytest.raises(InputError, match=r"shape\[1\].*integer >= 2, got 12.5"):
        s.resampled((16, 12.5))                 # was truncated to 12 points


def test_window_compliance_of_a_square_is_loves_mean_deflection():
    """Mean deflection of a uniformly loaded square of side a on a half-space: 0.946 p a/E*
    (the tabulated influence factors of a flexible square footing: centre 1.122, corner
    2 ln(1 + sqrt 2)/pi = 0.561 (Love), mean 0.946); the grid sum converges to it."""
    a = 1e-4
    c = [window_compliance(Surface(np.zeros((n, n)), (a, a)), E) * E / a for n in (16, 32)]
    assert abs(c[1] - 0.9462) < abs(c[0] - 0.9462) < 0.01
    assert c[1] == pytest.approx(0.9462, rel=2e-3)


def test_window_target_is_the_periodic_interface_in_series_with_the_window(topographies_dir):
    """x3p-2 (thinned to 55 x 55 over its 83 x 204 um): the window alone on the half-space
    (non-periodic kernel) is stiffer than nothing but saturates at 1/C, its bulk compliance
    in series with the rough interface of the mirrored (periodic) window:
    1/K_window = 1/K_periodic + C within 7 % beyond the first step (whose K is a one-sided
    difference), and K_window < 1/C everywhere while K_periodic exceeds 1/C tenfold."""
    x = load_surface(topographies_dir / "x3p-2.x3p")
    h = x.heights[::12, ::12]
    s = Surface(h, (h.shape[0] * x.spacing[0] * 12, h.shape[1] * x.spacing[1] * 12))
    settings = db.DatabaseSettings(length=1e-4, n_nodes=32, dim=2, top_fraction=0.8,
                                   youngs_modulus=E, n_steps=8)
    kw, _, win = surface_targets(s, settings, boundary="window")
    fine = db.DatabaseSettings(**{**settings.to_dict(), "top_fraction": 0.95, "n_steps": 24})
    kp, ap, per = surface_targets(s, fine, resolution="full")
    assert kp.metadata["boundary"] == "periodic" and kp.metadata["resolution"] == "full"
    assert kp.metadata["solved_shape"] == [2 * (n - 1) for n in s.shape]
    c = window_compliance(s.detrended("plane"), E)
    assert c == pytest.approx(0.9 * np.sqrt(np.prod(s.size)) / E, rel=0.03, abs=0)
    k_per = np.exp(np.interp(np.log(win.pressure), np.log(per.pressure),
                             np.log(per.stiffness)))
    predicted = 1.0 / (1.0 / k_per + c)
    assert np.all(win.stiffness < 1.0 / c)
    assert per.stiffness.max() > 10.0 / c
    np.testing.assert_allclose(predicted[1:], win.stiffness[1:], rtol=0.07)
    # the default: resampled onto the database spacing L/N (same band as the designs)
    kd, _, _ = surface_targets(s, settings)
    spacing = settings.length / settings.n_nodes
    assert kd.metadata["solved_shape"] == [round(2 * (n - 1) * d / spacing)
                                           for n, d in zip(s.shape, s.spacing)]
    with pytest.raises(InputError, match="boundary"):
        surface_targets(s, settings, boundary="free")
    with pytest.raises(InputError, match="resolution"):
        surface_targets(s, settings, resolution="fine")


def test_spectrum_matched_recovers_the_chromosome_amplitudes_of_a_reweighted_design():
    """A target that is the design with every chromosome's amplitude changed (same phases,
    lattice waves on the axes): matching the band rms restores it exactly; a profile
    design or a non-periodic target is refused."""
    from roughfe.genomics.design import Design, DesignPart, spectrum_matched
    from roughfe.genomics.genome import random_genome

    length, n = 1e-4, 32
    g = random_genome(1e-6, 0.8, 2.0, length, 2, 5, rng=4, angles=[0.0, np.pi / 2],
                      anisotropy=[1.0, 0.6])
    d = Design((DesignPart(g, (1, 2, 3, 4, 5), 1.0, "g"),), 1.0, length, n, "g", 2)
    split = d.split_chromosomes()
    w = np.random.default_rng(5).uniform(0.2, 3.0, len(split.parts))
    target = split.with_phases([(k, "weight") for k in range(len(w))], w).surface()
    matched = spectrum_matched(d, target).surface().heights
    ref = target.heights - target.heights.mean()
    np.testing.assert_allclose(matched - matched.mean(), ref, atol=1e-12 * np.ptp(ref))
    with pytest.raises(InputError, match="periodic"):
        spectrum_matched(d, Surface(target.heights, target.size))


def test_directional_spectrum_matching_recovers_every_wave_amplitude():
    """A target that is the design with every *wave* (ridge, chromosome) re-weighted on its
    own (per-ridge factors of one-chromosome parts: not an MWM genome, nor reachable by
    chromosome weights): directional matching restores it exactly, chromosome matching
    does not (it keeps the design's ratio between the ridges of a chromosome). Angles and
    chromosomes are chosen so that no rounded lattice wave lies half-way (in log q)
    between two chromosomes (the longest wave rounded to the diagonal would)."""
    from roughfe.genomics.design import Design, DesignPart, spectrum_matched
    from roughfe.genomics.genome import random_genome

    length, n = 1e-4, 32
    g = random_genome(1e-6, 0.8, 2.0, length, 3, 5, rng=4, angles=[0.0, 1.0, 2.0],
                      anisotropy=[1.0, 0.6, 1.4])
    d = Design((DesignPart(g, (2, 3, 4, 5), 1.0, "g"),), 2.0, length, n, "g", 2)
    split = d.split_chromosomes()
    rng = np.random.default_rng(5)
    parts = tuple(replace(p, genome=replace(p.genome, anisotropy=rng.uniform(0.2, 3.0, 3)))
                  for p in split.parts)
    target = replace(split, parts=parts).surface()
    ref = target.heights - target.heights.mean()
    for directional, ok in ((True, True), (False, False)):
        matched = spectrum_matched(d, target, directional).surface().heights
        err = np.abs(matched - matched.mean() - ref).max() / np.ptp(ref)
        assert (err < 1e-12) == ok, (directional, err)


def test_profile_target_defaults_to_the_profile_databases_own_setting(tmp_path):
    """On a profile database the designs are non-periodic profiles on the strip kernel:
    the default boundary of a profile target is then the window itself, and a design's
    own profile is its own target exactly. The old default ("periodic": the mirrored
    profile with the periodic BEM) scored a database genome against its own profile
    s = 0.009 (K 130x off at p_max)."""
    from roughfe.genomics.database import make_genome
    from roughfe.genomics.macro_micro import profile_response
    from roughfe.genomics.periodic import realization
    settings = db.DatabaseSettings(n_nodes=128, n_steps=6)
    genome = make_genome(1.5, 0.8, 3, settings)                  # seeded phases
    profile = realization(genome, settings.length, settings.n_nodes, settings.dim)
    own = profile_response(profile, **settings.response_options())
    tk, ta, curve = surface_targets(profile, settings, detrend="none")
    assert tk.metadata["boundary"] == "window"
    np.testing.assert_allclose(curve.pressure, own.pressure, rtol=1e-12)
    np.testing.assert_allclose(curve.stiffness, own.stiffness, rtol=1e-12)
    _, _, mirrored = surface_targets(profile, settings, detrend="none", boundary="periodic")
    assert mirrored.stiffness[-1] > 10 * own.stiffness[-1]
    # the CSV says how the target was made (K 10x apart between the two boundaries, and
    # the file said neither) and still reads back with its quantity
    from roughfe.genomics.target_csv import read_target_csv, write_target_csv
    path = write_target_csv(tmp_path / "tk.csv", tk)
    assert "# solved with boundary window, resolution design, detrend none" in path.read_text()
    back = read_target_csv(path)
    assert back.quantity == "K" and np.array_equal(back.values, tk.values)


def test_a_surface_database_refuses_a_profile_target(tmp_path, capsys):
    """`design-targets --db <dim-2 db> --surface profile.npz` wrote targets of a 1D profile
    (a line contact) for periodic 2D designs, with no error; `design --match-spectrum`
    refused the same file. Both now say so (target_surface, which both read)."""
    from roughfe.cli import main
    from roughfe.genomics.design.targets import target_surface
    from roughfe.surfaces.io import save_surface
    settings = db.DatabaseSettings(length=1e-4, n_nodes=16, dim=2)
    path = _settings_only_db(tmp_path, settings)
    x = np.linspace(0.0, 1e-4, 64)
    profile = save_surface(Surface(1e-7 * np.sin(2 * np.pi * 3 * x / 1e-4), 1e-4),
                           tmp_path / "profile.npz")
    message = "surface database \\(dim 2, designs are periodic 2D surfaces\\): its target " \
              "must be a 2D surface, got a profile of 64 points"
    assert main(["design-targets", "--db", str(path), "--surface", str(profile),
                 "-o", str(tmp_path / "t")]) == 2
    assert re.search(message, capsys.readouterr().err)
    with pytest.raises(InputError, match=message):
        target_surface(Surface(np.ones(64), 1e-4), settings)


def test_design_targets_scan_axis_y_gives_the_transposed_maps_targets(tmp_path):
    """`design-targets --surface` levelled scan lines along x only (no --scan-axis until
    round 2, session 35, as info, contact, leak and genome chromosomes had): a map scanned
    along y, given with --scan-axis y, now gives the targets of its transpose along x."""
    from roughfe.cli import main
    from roughfe.genomics.target_csv import read_target_csv
    from roughfe.surfaces import spectral_surface
    from roughfe.surfaces.io import save_surface
    path = _settings_only_db(tmp_path, db.DatabaseSettings(length=1e-6, n_nodes=16, dim=2,
                                                          n_steps=5, top_fraction=0.8))
    rng = np.random.default_rng(3)
    h = spectral_surface((48, 32), (1e-6, 2e-6 / 3), 0.7, rms_height=1e-8, rng=1).heights
    h = h + 3e-9 * rng.standard_normal(32)[None, :]               # offsets of lines along x
    save_surface(Surface(h, (1e-6, 2e-6 / 3), False), tmp_path / "x.npz")
    save_surface(Surface(h.T, (2e-6 / 3, 1e-6), False), tmp_path / "y.npz")

    def targets(name, *extra):
        out = tmp_path / f"t_{name}_{len(extra)}"
        assert main(["design-targets", "--db", str(path), "--surface", str(tmp_path / name),
                     "--detrend", "lines", *extra, "-o", str(out)]) == 0
        return [read_target_csv(out / f"{name[0]}_{q}.csv") for q in "KA"]

    along_x = targets("x.npz")
    for a, b in zip(along_x, targets("y.npz", "--scan-axis", "y")):
        assert np.allclose(b.pressure, a.pressure, rtol=1e-9, atol=0)
        assert np.allclose(b.values, a.values, rtol=1e-9, atol=0)
    wrong = targets("y.npz")                      # the lines levelled across the scan
    assert not np.allclose(wrong[1].values, along_x[1].values, rtol=1e-3, atol=0)


def test_design_targets_warns_of_offset_scan_lines_and_a_kept_tilt(tmp_path, capsys):
    """`design-targets --surface` read its file without the warnings of info, contact and
    leak (round 2, session 35): a measured map with offset scan lines, or with an
    instrument tilt kept by --detrend mean, gave targets without a word. Both now warn
    (the one path, surface_warnings.plausible_surface); levelled lines and a removed plane
    do not."""
    from roughfe.cli import main
    from roughfe.surfaces import spectral_surface
    from roughfe.surfaces.io import save_surface
    path = _settings_only_db(tmp_path, db.DatabaseSettings(length=1e-6, n_nodes=16, dim=2,
                                                          n_steps=4, top_fraction=0.8))
    size = (1e-6, 2e-6 / 3)
    h = spectral_surface((48, 32), size, 0.7, rms_height=1e-8, rng=1).heights
    lines = h + 3e-9 * np.random.default_rng(3).standard_normal(32)[None, :]
    x, y = np.meshgrid(np.arange(48), np.arange(32), indexing="ij")
    tilted = h + 3e-9 * (x + 0.5 * y)                     # rms of the plane ~ 4 um x Sq
    save_surface(Surface(lines, size, False), tmp_path / "lines.npz")
    save_surface(Surface(tilted, size, False), tmp_path / "tilted.npz")

    def err(name, *extra):
        capsys.readouterr()
        assert main(["design-targets", "--db", str(path), "--surface", str(tmp_path / name),
                     *extra, "-o", str(tmp_path / f"t_{name}_{len(extra)}")]) == 0
        return capsys.readouterr().err

    offset = "warning: the scan lines along x (heights[:, j]) look offset"
    assert offset in err("lines.npz")                          # default --detrend plane
    assert offset not in err("lines.npz", "--detrend", "lines")
    assert "scan lines" not in err("lines.npz", "--scan-axis", "y")  # rows i: no offsets
    kept = "warning: --detrend mean keeps the tilt of this non-periodic surface"
    assert kept in err("tilted.npz", "--detrend", "mean")
    assert kept not in err("tilted.npz")                       # the plane removed
