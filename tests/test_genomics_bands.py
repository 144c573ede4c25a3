"""Band chromosomes of any surface (issue 15 §2): exactness, orthogonality, WM recovery, mechanics."""
import numpy as np
import pytest

from roughfe import progress
from roughfe.errors import InputError, NoConvergenceError
from roughfe.genomics.macro_micro import profile_response
from roughfe.genomics.band_mechanics import band_macro_micro, band_mechanics
from roughfe.genomics.bands import band_chromosomes, band_leakage, genome_q1
from roughfe.genomics.genome import node_coordinates, random_genome, realize_surface
from roughfe.genomics.mechanics import ChromosomeMechanics, curve_difference
from roughfe.surfaces.io import load_surface
from roughfe.surfaces.spectral import spectral_profile, spectral_surface
from roughfe.surfaces.surface import Surface
from roughfe.surfaces.wm import wm_series

MEASURED = ("di-1.di", "opd-1.opd", "plu-1.plu", "sur-2.sur", "x3p-2.x3p")


@pytest.mark.parametrize("name", MEASURED)
def test_measured_bands_sum_exactly_and_split_the_variance(topographies_dir, name):
    """Every measured file: the chromosomes add up to the detrended surface (linearity)
    and their mean squares to its mean square (orthogonal bands, Parseval)."""
    s = load_surface(topographies_dir / name)
    b = band_chromosomes(s)
    h = b.surface.heights
    assert b.transform == "dct"                      # measured windows are not periodic
    assert np.abs(b.chromosomes.sum(axis=0) - h).max() <= 1e-12 * np.abs(h).max()
    assert b.energy.sum() == pytest.approx(np.mean(h ** 2), rel=1e-12, abs=0)
    assert np.all(np.diff(b.q_bounds) > 0)
    assert b.q_bounds[1] / b.q_bounds[0] == pytest.approx(np.sqrt(2.0))
    assert b.n_bins.sum() == h.size - 1               # every bin but q = 0 in one band
    # TD and BU partial sums end on the complete surface and are complementary
    td, bu = b.partial_sums("td"), b.partial_sums("bu")
    assert np.allclose(td[-1], h, atol=1e-12 * np.abs(h).max())
    k = b.n_chromosomes // 2
    assert np.allclose(td[k - 1] + bu[b.n_chromosomes - k - 1], h, atol=1e-12 * np.abs(h).max())


def test_periodic_on_grid_wm_chromosomes_are_recovered_exactly():
    """A periodic surface whose WM wavevectors sit on the FFT grid (gamma = 2, lambda1 = L,
    ridges along the axes and diagonals): each band holds exactly its WM chromosome."""
    n, length, gamma = 128, 1e-3, 2.0
    x = np.arange(n) * length / n
    rng = np.random.default_rng(7)
    idx = np.arange(1, 7)                      # q_n = 2 pi 2^(n-1) / L: on the grid
    q = 2 * np.pi * gamma ** (idx - 1) / length
    angles = np.array([0.0, np.pi / 2, np.pi / 4])
    # a diagonal plane wave with |q| = q_n is on the grid only if q_n / sqrt(2) is: use
    # axis-aligned ridges for all chromosomes and the diagonal ridge only where it fits
    amps = np.outer([1.0, 0.7, 0.0], gamma ** (-0.8 * idx)) * 1e-6
    phases = rng.uniform(0, 2 * np.pi, (3, idx.size))
    coords = (x[:, None], x[None, :])
    ref = np.array([wm_series(coords, amps[:, [j]], q[[j]], phases[:, [j]], angles)
                    for j in range(idx.size)])
    ref -= ref.mean(axis=(1, 2), keepdims=True)
    surf = Surface(ref.sum(axis=0), length, periodic=True)
    b = band_chromosomes(surf, gamma, q1=genome_q1(gamma, length), detrend="mean")
    assert b.transform == "fft"
    assert b.n_chromosomes >= idx.size
    lead = b.chromosomes[: idx.size]
    assert np.abs(lead - ref).max() <= 1e-10 * np.abs(ref).max()
    assert np.abs(b.chromosomes[idx.size:]).max() <= 1e-10 * np.abs(ref).max()


def _wm_reference(genome, surf, bands):
    """True WM chromosomes of a realisation, placed in the band holding their q_n."""
    length = surf.metadata["length"]
    x = node_coordinates(length, surf.shape[0])
    ref = np.zeros_like(bands.chromosomes)
    for n in range(surf.metadata["n_s"], surf.metadata["n_f"] + 1):
        q = genome.wavenumber(np.array([n]))
        k = np.searchsorted(bands.q_bounds, q[0], side="right") - 1
        ph = genome.phase_columns(np.array([n]))
        amp = np.broadcast_to(genome.wave_amplitude(np.array([n])), ph.shape)
        z = wm_series((x[:, None], x[None, :]), amp, q, ph, genome.angles)
        if 0 <= k < ref.shape[0]:
            ref[k] += z - z.mean()
    return ref


def test_mwm_window_leakage_is_measured_and_the_mirror_transform_cuts_it():
    """A non-periodic MWM window: the bands hold the WM chromosomes up to leakage. The DCT
    (mirrored window) leaks less than the FFT (periodic extension) in the inner bands,
    where it stays below 0.6 (measured 0.18-0.55; FFT 0.55-1.5)."""
    rng = np.random.default_rng(3)
    g = random_genome(1e-4, 0.8, 2.0, 32e-3, 5, 40, rng=rng, angles=rng.uniform(0, np.pi, 5))
    s = realize_surface(g, 16e-3, 129)
    q1 = genome_q1(2.0, g.lambda1)
    leak = {}
    for tr in ("fft", "dct"):
        b = band_chromosomes(s, 2.0, q1=q1, detrend="mean", transform=tr)
        leak[tr] = band_leakage(b, _wm_reference(g, s, b))
    inner_dct = leak["dct"][2:-1]
    inner_fft = leak["fft"][1:-1]
    assert np.all(inner_dct < 0.6)
    assert np.median(inner_dct) < 0.6 * np.median(inner_fft)


def test_profiles_decompose_too():
    s = spectral_profile(256, 1e-3, 0.8, rms_height=1e-6, rng=1)
    b = band_chromosomes(s, 1.5)
    assert b.transform == "fft" and b.chromosomes.shape[1:] == s.shape
    assert np.abs(b.chromosomes.sum(0) - b.surface.heights).max() < 1e-12 * np.abs(s.heights).max()


@pytest.mark.parametrize("kwargs, match", [
    (dict(gamma=1.0), "gamma"), (dict(gamma="x"), "gamma"), (dict(detrend="cubic"), "detrend"),
    (dict(transform="wavelet"), "transform"), (dict(q1=-1.0), "q1"),
    # 1.0001 made 1000s of (mostly empty) bands before any check
    (dict(gamma=1.0001), "more than the .* distinct wavenumbers"),
])
def test_bad_band_input(kwargs, match):
    s = Surface(np.random.default_rng(0).normal(size=(16, 16)), 1e-3)
    with pytest.raises(InputError, match=match):
        band_chromosomes(s, **kwargs)


def test_flat_or_offset_surfaces_are_refused():
    with pytest.raises(InputError, match="flat"):
        band_chromosomes(Surface(np.ones((16, 16)), 1e-3))
    z = np.random.default_rng(0).normal(size=(16, 16)) + 5.0
    with pytest.raises(InputError, match="mean"):
        band_chromosomes(Surface(z, 1e-3), detrend="none")


def test_band_mechanics_in_two_threads_equals_one():
    """The sweeps run two at a time (issue 15 §4 speed on 2 cores): every curve is the
    same deterministic computation, so the result equals the serial one exactly."""
    s = spectral_surface(32, 1e-3, 0.8, rms_height=1e-6, rng=5)
    b = band_chromosomes(Surface(s.heights, s.size), 2.0)      # non-periodic window
    one = band_mechanics(b, youngs_modulus=1e9, n_steps=5, workers=1)
    two = band_mechanics(b, youngs_modulus=1e9, n_steps=5, workers=2)
    assert one.nit == two.nit > 3 and one.success and two.success
    for a, c in zip((one.complete,) + one.chromosome_curves + one.td_curves + one.bu_curves,
                    (two.complete,) + two.chromosome_curves + two.td_curves + two.bu_curves):
        assert (a is None) == (c is None)
        if a is not None:
            for q in ("pressure", "stiffness", "area_fraction"):
                assert np.array_equal(getattr(a, q), getattr(c, q))
    with pytest.raises(InputError, match="workers"):
        band_mechanics(b, youngs_modulus=1e9, n_steps=5, workers=0)


def test_band_mechanics_of_a_periodic_surface():
    """TD/BU sums end on the sum of all bands, swept as its own surface and agreeing with
    the complete curve, and the macro/micro split partitions the bands."""
    s = spectral_surface(32, 1e-3, 0.8, rms_height=1e-6, rng=2)
    b = band_chromosomes(s, 2.0, detrend="mean")
    calls = []
    with progress.listening(lambda desc, d, t: calls.append((d, t)) if desc == "band sweeps" else None):
        m = band_mechanics(b, youngs_modulus=1e9, n_steps=6)
    n_c = b.n_chromosomes
    assert len(m.td_curves) == len(m.bu_curves) == len(m.chromosome_curves) == n_c
    assert m.td_curves[0] is m.chromosome_curves[0]
    # the sum of all bands has its own sweep: it was the complete surface's curve object,
    # so its c_n = 1 correlated the complete curve with itself and could not fail
    every = b.partial_sums("td")[-1]
    assert not np.array_equal(every, b.surface.heights)          # a second height field
    last = m.td_curves[-1]
    assert last is not m.complete and m.bu_curves[-1] is last
    own = profile_response(b.as_surface(every), youngs_modulus=1e9, n_steps=6)
    for q in ("pressure", "stiffness", "area_fraction"):
        assert np.array_equal(getattr(last, q), getattr(own, q))
    # it agrees: the heights differ by the reconstruction round-off (2e-16 of the
    # peak-valley), the curves by the solve's round-off (1.3e-14 in K, 0 in A measured)
    assert np.max(np.abs(b.chromosomes.sum(0) - b.surface.heights)) < 1e-15 * np.ptp(every)
    diff = curve_difference(m.complete, last)
    assert diff["K"] < 1e-9 and diff["A"] < 1e-9
    assert 1.0 - m.c_td["K"][-1] <= 1e-12 and 1.0 - m.c_bu["A"][-1] <= 1e-12
    # the last band holds round-off only (ptp 9e-22 m on a 3e-6 m surface): flat against
    # the complete surface, no sweep (it was swept, judged against its own round-off)
    assert np.ptp(b.chromosomes[-1]) < 1e-15 and m.chromosome_curves[-1] is None
    assert m.nit == calls[-1][0] == calls[-1][1] == n_c + 2 * max(n_c - 2, 0) + 1
    # the longest-wave TD sums carry most of the stiffness shape of the complete surface
    assert m.c_td["K"][n_c - 2] > 0.9
    mm = band_macro_micro(m, threshold=0.95)
    assert sorted(mm.macro + mm.micro) == list(b.indices)
    d = m.to_dict()
    assert len(d["td"]) == n_c and d["complete"]["pressure"]
    assert m.success and "NOT" not in m.message
    # a band sweep that does not converge: no curve, c_n NaN, success False, named
    def flaky(surf):
        if np.array_equal(surf.heights, b.chromosomes[1]):
            raise NoConvergenceError("KKT residual 1e-3 > tol")
        return profile_response(surf, youngs_modulus=1e9, n_steps=6)
    bad = band_mechanics(b, youngs_modulus=1e9, n_steps=6, response=flaky)
    assert not bad.success and f"c {int(b.indices[1])}" in bad.message
    assert bad.chromosome_curves[1] is None and np.isnan(bad.c_chromosome["K"][1])
    # Alg. 2 does not count the failed band as a flat micro one (it holds energy)
    assert bad.failed_chromosomes == (int(b.indices[1]),) and b.energy[1] > 0
    split = band_macro_micro(bad, threshold=0.95)
    assert int(b.indices[1]) not in split.micro + split.macro and not split.success
    assert "NOT classified" in split.message
    assert ChromosomeMechanics.from_dict(bad.to_dict()).failed_chromosomes == bad.failed_chromosomes
    # a failed bottom-up sum is named by the band it ends at (bu key k ends at
    # indices[-1 - k]; it was labelled indices[k])
    bu = b.partial_sums("bu")

    def flaky_bu(surf):
        if np.array_equal(surf.heights, bu[2]):
            raise NoConvergenceError("KKT residual 1e-3 > tol")
        return profile_response(surf, youngs_modulus=1e9, n_steps=6)
    bad_bu = band_mechanics(b, youngs_modulus=1e9, n_steps=6, response=flaky_bu)
    assert f"(bu {int(b.indices[-3])})" in bad_bu.message
    # the material under the one vocabulary E/nu; files with the old keys still read
    assert (d["E"], d["nu"]) == (1e9, 0.0) and "youngs_modulus" not in d
    import json
    old = json.loads(json.dumps(d))
    old["youngs_modulus"], old["poisson"] = old.pop("E"), old.pop("nu")
    for data in (d, old):
        back = ChromosomeMechanics.from_dict(json.loads(json.dumps(data)))
        assert back.youngs_modulus == 1e9 and back.to_dict()["complete"] == d["complete"]
        np.testing.assert_array_equal(back.c_td["K"], m.c_td["K"])
    from roughfe.errors import FileFormatError
    with pytest.raises(FileFormatError, match="E"):
        ChromosomeMechanics.from_dict({k: v for k, v in d.items() if k != "E"})


def test_genome_chromosomes_command(tmp_path, capsys):
    """`roughfe genome chromosomes`: the documented files, bands summing to the surface,
    TD/BU curves ending on the complete one, figures; a bad gamma is a one-line error."""
    import json

    from roughfe.cli import main
    from roughfe.surfaces.io import save_surface
    s = spectral_surface(32, 1e-3, 0.8, rms_height=1e-6, rng=4)
    path = save_surface(s, tmp_path / "s.npz")
    out = tmp_path / "out"
    assert main(["genome", "chromosomes", str(path), "--gamma", "2", "--steps", "4",
                 "--E", "1e9", "-o", str(out)]) == 0
    data = np.load(out / "chromosomes.npz")
    assert np.allclose(data["chromosomes"].sum(0), data["surface"], atol=1e-12 * 1e-6)
    assert data["q_bounds"].size == data["chromosomes"].shape[0] + 1
    mech = json.loads((out / "mechanics.json").read_text())
    # the sum of all bands is swept on its own: it agrees with the complete surface
    assert mech["td"][-1] == mech["bu"][-1]
    for q in ("pressure", "stiffness", "area_fraction"):
        ref = np.asarray(mech["complete"][q])
        assert np.allclose(mech["td"][-1][q], ref, rtol=1e-9, atol=1e-9 * np.abs(ref).max())
    # units in the files (none until round 2, session 24), as leak's fields/step_NNN.npz
    units = json.loads(str(data["units"]))
    assert set(units) == set(data.files) - {"units"}
    assert units["chromosomes"] == units["surface"] == "m" and units["q_bounds"] == "rad/m"
    assert mech["units"]["E"] == "Pa" and mech["units"]["length"] == "m"
    assert mech["units"]["pressure"].startswith("Pa ") and mech["units"]["stiffness"].startswith(
        "Pa/m")
    numbers = {k for k, v in mech.items() if isinstance(v, (int, float, list, dict))
               and not isinstance(v, bool)} - {"complete", "chromosomes", "td", "bu",
                                               "failed_chromosomes", "units"}
    assert numbers <= set(mech["units"])
    assert set(mech["complete"]) <= set(mech["units"])
    mm = json.loads((out / "macro_micro.json").read_text())
    assert sorted(mm["macro"] + mm["micro"]) == mech["indices"]
    for fig in ("td", "bu", "chromosomes", "energy", "curves", "correlations"):
        assert (out / f"{fig}.png").stat().st_size > 5_000
    assert "band chromosomes" in capsys.readouterr().out
    assert main(["genome", "chromosomes", str(path), "--gamma", "20", "-o",
                 str(tmp_path / "bad")]) == 2
    assert "gamma" in capsys.readouterr().err
    # two steps difference K(p) into one secant: every curve flat, every c_n 0, all bands
    # "micro" and a success (a user's review); refused before the decomposition
    for steps in ("1", "2"):
        assert main(["genome", "chromosomes", str(path), "--steps", steps, "--E", "1e9",
                     "-o", str(tmp_path / "two")]) == 2
        assert "--steps must be 0 (the decomposition only) or >= 3" in capsys.readouterr().err
    assert not (tmp_path / "two").exists()
    with pytest.raises(InputError, match="n_steps must be >= 3"):
        band_mechanics(band_chromosomes(s, 2.0), youngs_modulus=1e9, n_steps=2)
    assert not (tmp_path / "bad").exists()
    # a band sweep that does not converge: exit 1 (it exited 0 with the band counted as
    # a flat micro band) and macro_micro.json says success false
    import roughfe.genomics.band_mechanics as bm
    real, seen = bm.profile_response, []

    def flaky(surf, **kw):
        seen.append(1)
        if len(seen) == 3:
            raise NoConvergenceError("simulated")
        return real(surf, **kw)
    bm.profile_response = flaky
    try:
        assert main(["genome", "chromosomes", str(path), "--gamma", "2", "--steps", "4",
                     "--E", "1e9", "--no-figures", "-o", str(tmp_path / "fail")]) == 1
    finally:
        bm.profile_response = real
    mm = json.loads((tmp_path / "fail" / "macro_micro.json").read_text())
    assert mm["success"] is False and "NOT classified" in mm["message"]


def test_band_edges_checks_its_range():
    # (10, 1) returned [] silently; NaN raised "cannot convert float NaN to integer"; 0 a
    # ZeroDivisionError
    from roughfe.genomics.bands import band_edges
    for q_min, q_max, match in [(10.0, 1.0, "below q_min"), (float("nan"), 1.0, "q_min"),
                                (0.0, 1.0, "q_min")]:
        with pytest.raises(InputError, match=match):
            band_edges(q_min, q_max, 2.0)
    e = band_edges(1.0, 8.0, 2.0)
    assert e[0] == 1.0 and e[-1] >= 8.0


def test_genome_chromosomes_window_mirror_and_undiscriminating_split(tmp_path, capsys):
    """On a non-periodic window every band's K(p) is mostly the window's bulk stiffness
    (a user's review: all bands macro or all micro with --steps): the command says so and
    offers --mirror, which decomposes and solves the evenly mirrored window; a split with
    every band on one side is warned of with the c_n range."""
    import json

    from roughfe.cli import main
    from roughfe.surfaces.io import save_surface
    from roughfe.surfaces.surface import Surface
    s = spectral_surface(32, 1e-3, 0.8, rms_height=1e-6, rng=4)
    window = Surface(s.heights[:17, :17], (1e-3 * 17 / 32,) * 2, periodic=False)
    path = save_surface(window, tmp_path / "w.npz")
    args = ["genome", "chromosomes", str(path), "--gamma", "2", "--steps", "3", "--E", "1e9",
            "--no-figures"]
    assert main(args + ["-o", str(tmp_path / "plain")]) in (0, 1)
    err = capsys.readouterr().err
    assert "is mostly the window's flat-punch bulk stiffness" in err and "--mirror" in err
    assert main(args + ["--mirror", "-o", str(tmp_path / "mirrored")]) in (0, 1)
    err = capsys.readouterr().err
    assert "flat-punch" not in err
    data = np.load(tmp_path / "mirrored" / "chromosomes.npz")
    assert data["surface"].shape == (32, 32)                     # 2 (n - 1) per side
    mm = json.loads((tmp_path / "mirrored" / "macro_micro.json").read_text())
    one_side = not mm["macro"] or not mm["micro"]
    assert ("the split does not discriminate here" in err) is one_side
    periodic = save_surface(s, tmp_path / "p.npz")
    assert main(["genome", "chromosomes", str(periodic), "--mirror", "--steps", "0",
                 "-o", str(tmp_path / "bad")]) == 2
    assert "--mirror mirrors a non-periodic window" in capsys.readouterr().err
