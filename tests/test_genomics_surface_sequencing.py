"""Sequencing of 2D MWM surfaces (issue 15 §1): exact recovery, prediction, noise, bad input."""
import numpy as np
import pytest

from roughfe.errors import InputError
from roughfe.genomics.genome import realize, realize_surface
from roughfe.genomics.sequencing import sequence_surfaces
from roughfe.genomics.sequencing.surface_data import (SurfaceAcquisition, cluster_angles,
                                                      resolvable_surface_genome,
                                                      surface_peaks)
from roughfe.surfaces.spectral import spectral_surface
from roughfe.surfaces.surface import Surface

N = 48
L1 = 1e-3


def _genome(seed, M=3, gamma=1.8, H=0.8):
    """A genome in the sequencer's gauge: lambda1 in [L1, gamma L1) (n_s = 1 at L1),
    anisotropy of geometric mean 1, ridges at least 0.4 pi / M apart (resolvable)."""
    return resolvable_surface_genome(seed, length=L1, n_nodes=N, n_ridges=M, gamma=gamma,
                                     hurst=H)


def _wrapped(a):
    return np.abs(np.angle(np.exp(1j * a)))


def test_noise_free_mwm_surface_is_sequenced_exactly():
    """Every gene, angle, anisotropy factor and phase to 1e-8; the acquisitions to 1e-10;
    the genome holds exactly the chromosomes of the data (band-limited)."""
    g, acq, _ = _genome(5)
    r = sequence_surfaces(acq)
    s = r.genome
    assert r.success, r.message
    assert s.M == g.M
    assert s.gamma == pytest.approx(g.gamma, rel=1e-10)
    assert s.lambda1 == pytest.approx(g.lambda1, rel=1e-10, abs=0)
    assert s.A == pytest.approx(g.A, rel=1e-8)
    assert s.H == pytest.approx(g.H, abs=1e-8)
    np.testing.assert_allclose(s.angles, g.angles, atol=1e-9)
    np.testing.assert_allclose(s.anisotropy, g.anisotropy, rtol=1e-8)
    assert (s.n_first, s.n_last) == (1, max(a.metadata["n_f"] for a in acq))
    truth = g.phase_columns(np.arange(s.n_first, s.n_last + 1))
    assert _wrapped(s.phases - truth).max() < 1e-8
    assert np.all(r.rms_errors < 1e-10)


def test_sequenced_genome_predicts_other_windows():
    """A window between the two acquisitions is predicted to round-off; a finer grid that
    shows chromosomes above the data's band gets only the held ones (none invented)."""
    g, acq, _ = _genome(7)
    s = sequence_surfaces(acq).genome
    mid = realize_surface(s, 0.6 * L1, N).heights
    np.testing.assert_allclose(mid, realize_surface(g, 0.6 * L1, N).heights,
                               atol=1e-10 * np.abs(mid).max())
    fine = realize_surface(s, L1 / 2.5, 2 * N)
    assert fine.metadata["n_f"] > s.n_last == fine.metadata["chromosomes"][-1]
    band = g.__class__(A=g.A, H=g.H, gamma=g.gamma, lambda1=g.lambda1,
                       phases=g.phase_columns(np.arange(1, s.n_last + 1)),
                       angles=g.angles, anisotropy=g.anisotropy)
    ref = realize_surface(band, L1 / 2.5, 2 * N).heights
    np.testing.assert_allclose(fine.heights, ref, atol=1e-10 * np.abs(ref).max())


@pytest.mark.parametrize("seed", [11, 1])
def test_one_percent_white_noise(seed):
    """Issue 15 targets: M exact, angles within 0.5 deg, gamma within 0.5 %, the
    reconstruction misfit at the noise level (1 % rms). Seed 1: the lattice gamma^(1/3)
    nests the true one and fits the noise with 3x the waves; chosen by the residual alone
    it gave gamma 32 % low with success True (now by the information criterion)."""
    g, acq, rng = _genome(seed)
    noisy = [a.with_heights(a.heights + 0.01 * a.heights.std() * rng.normal(size=a.shape))
             for a in acq]
    r = sequence_surfaces(noisy)
    s = r.genome
    assert s.M == g.M
    assert np.degrees(np.abs(s.angles - g.angles)).max() < 0.5
    assert s.gamma == pytest.approx(g.gamma, rel=5e-3)
    # the misfit is over the heights about their plane (the model's plane takes the rest):
    # the noise, 1 % of the rms about the mean, is that share of signal_rms; both the fit
    # (every wave its own amplitude) and the genome (amplitudes on its power law)
    noise = np.array([0.01 * a.heights.std() for a in acq]) / r.signal_rms
    for e in (r.fit_rms_errors, r.rms_errors):
        assert np.all((e > 0.8 * noise) & (e < 1.2 * noise)), e
    assert r.success


def test_undefined_points_and_a_removed_mean_plane():
    g, (a1, a2), rng = _genome(5)
    bad = rng.random(a1.shape) < 0.03
    x, y = np.meshgrid(np.arange(N), np.arange(N), indexing="ij")
    h = np.where(bad, 0.0, a1.heights + 1e-7 * x - 2e-7 * y)   # garbage at undefined points
    r = sequence_surfaces([a1.with_heights(h), a2], valid=[~bad, None])
    assert r.genome.M == g.M and r.genome.gamma == pytest.approx(g.gamma, rel=1e-10)
    assert r.genome.A == pytest.approx(g.A, rel=1e-8)
    np.testing.assert_allclose(r.genome.angles, g.angles, atol=1e-9)


def test_a_surface_without_wm_lattice_is_reported_not_sequenced():
    s = spectral_surface(N, 1e-3, 0.8, rms_height=1e-6, rng=1)
    r = sequence_surfaces([Surface(s.heights, N * 1e-3 / (N - 1))])
    assert not r.success
    assert "not" in r.message


def test_angle_clusters_wrap_around_pi():
    centres, labels, sizes = cluster_angles([0.005, np.pi - 0.005, 1.0, 1.01], [1, 1, 1, 1])
    assert sorted(sizes.tolist()) == [2, 2]
    assert labels[0] == labels[1] != labels[2] == labels[3]
    assert min(centres[labels[0]], np.pi - centres[labels[0]]) < 1e-9


def test_bad_acquisitions_name_the_mismatch():
    g, (a1, a2), _ = _genome(5)
    prof = realize(g, length=L1, n_nodes=N)
    with pytest.raises(InputError, match="surface sequencer takes 2D surfaces only"):
        sequence_surfaces([a1, prof])
    with pytest.raises(InputError, match="same N x N"):
        sequence_surfaces([a1, realize_surface(g, L1 / 2, N + 8)])
    shifted = Surface(a2.heights, a2.size, metadata={**a2.metadata, "x0": 0.9 * L1})
    with pytest.raises(InputError, match="nested"):
        sequence_surfaces([a1, shifted])
    with pytest.raises(InputError, match="different observation lengths"):
        sequence_surfaces([a1, a1])
    with pytest.raises(InputError, match="one mask per acquisition"):
        sequence_surfaces([a1, a2], valid=[None])
    with pytest.raises(InputError, match="n_restarts"):           # was truncated to 2
        sequence_surfaces([a1, a2], n_restarts=2.5)
    with pytest.raises(InputError, match="rms_tolerance"):
        sequence_surfaces([a1, a2], rms_tolerance=0.0)


def test_genome_sequence_command_on_surfaces(tmp_path, capsys):
    """`roughfe genome sequence` takes 2D acquisitions (angles and anisotropy in the genome
    JSON) and refuses a mix of profiles and surfaces in one line."""
    from roughfe.cli import main
    from roughfe.genomics.genome import load_genome
    from roughfe.surfaces.io import save_surface
    g, (a1, a2), _ = _genome(7)
    p1, p2 = save_surface(a1, tmp_path / "a1.npz"), save_surface(a2, tmp_path / "a2.npz")
    assert main(["genome", "sequence", str(p2), str(p1), "--no-figures",
                 "-o", str(tmp_path / "seq")]) == 0
    s = load_genome(tmp_path / "seq" / "genome.json")
    np.testing.assert_allclose(s.angles, g.angles, atol=1e-8)
    np.testing.assert_allclose(s.anisotropy, g.anisotropy, rtol=1e-7)
    assert "ridge angles" in capsys.readouterr().out
    prof = save_surface(realize(g, length=L1, n_nodes=N), tmp_path / "p.npz")
    assert main(["genome", "sequence", str(p1), str(prof), "-o", str(tmp_path / "mix")]) == 2
    assert "mix profiles (1D) and surfaces (2D)" in capsys.readouterr().err


def test_separable_grid_model_equals_the_dense_design():
    """The separable Gram/projection solve on a tensor sub-grid with undefined nodes gives
    the coefficients of a dense least-squares fit of the explicit cos/sin/plane design, and
    its variable-projection Jacobian at the true lattice (zero residual, where Kaufman's
    form is exact) equals central finite differences of the residual."""
    from roughfe.genomics.sequencing.surface_data import surface_acquisitions
    from roughfe.genomics.sequencing.surface_grid import GridModel
    g, (a1, a2), rng = _genome(5)
    bad = rng.random(a1.shape) < 0.05
    acqs = surface_acquisitions([a1, a2], valid=[~bad, None])
    noisy = [type(a)(a.x, a.y, a.z + 1e-3 * np.nanstd(a.z) * rng.normal(size=a.z.shape),
                     a.length) for a in acqs]
    model = GridModel(noisy, N, axis_nodes=40)
    p = np.r_[np.log(2 * np.pi / g.lambda1), np.log(g.gamma), g.angles]
    ranges = model.ranges(p[0], p[1])
    sol = model.solve(p, ranges, exact=True)
    cols = []
    for k, grid in enumerate(model.grids):
        xx, yy = np.meshgrid(grid["x"], grid["y"], indexing="ij")
        xx, yy = xx[grid["ok"]], yy[grid["ok"]]
        arg = np.multiply.outer(xx, np.cos(sol["theta_w"])) + np.multiply.outer(
            yy, np.sin(sol["theta_w"]))
        on = (sol["nn"] >= ranges[k][0]) & (sol["nn"] <= ranges[k][1])
        plane = np.zeros((xx.size, 3 * len(acqs)))
        plane[:, 3 * k:3 * k + 3] = np.column_stack([np.ones_like(xx), xx / acqs[k].length,
                                                     yy / acqs[k].length])
        cols.append(np.hstack([np.cos(arg * sol["q"]) * on, np.sin(arg * sol["q"]) * on, plane]))
    dense = np.vstack(cols)
    coef = np.linalg.lstsq(dense, model.z, rcond=None)[0]
    np.testing.assert_allclose(sol["coef"], coef, rtol=0, atol=1e-9 * np.abs(coef).max())
    np.testing.assert_allclose(sol["resid"], model.z - dense @ coef, atol=1e-12 * model.scale)
    clean = GridModel(acqs, N, axis_nodes=40)
    jac = clean.jacobian(p, clean.solve(p, ranges, exact=True))
    for j, h in enumerate([1e-7, 1e-7] + [1e-6] * g.M):
        dp = np.zeros_like(p)
        dp[j] = h
        fd = (clean.solve(p + dp, ranges, exact=True)["resid"]
              - clean.solve(p - dp, ranges, exact=True)["resid"]) / (2 * h)
        np.testing.assert_allclose(jac[:, j], fd, atol=1e-5 * np.abs(fd).max())



def test_an_exact_sub_lattice_is_told_from_the_lattice():
    """On noise-free data the sub-lattice gamma^(1/3) also reproduces the data (its extra
    chromosomes come out empty); the sequencer stops at the first exact candidate only
    when every chromosome carries a wave, which tells the lattice from a sub-lattice."""
    from roughfe.genomics.sequencing.surface import _every_chromosome_present
    from roughfe.genomics.sequencing.surface_data import surface_acquisitions
    from roughfe.genomics.sequencing.surface_grid import GridModel
    g, acq, _ = _genome(5)
    model = GridModel(surface_acquisitions(acq), N)
    true = model.ranges(np.log(2 * np.pi / g.lambda1), np.log(g.gamma))
    for k, present in [(1, True), (3, False)]:
        # chromosome n of the lattice is chromosome 1 + k (n - 1) of the sub-lattice
        p = np.r_[np.log(2 * np.pi / g.lambda1), np.log(g.gamma) / k, g.angles]
        sol = model.solve(p, [(1 + k * (a - 1), 1 + k * (b - 1)) for a, b in true], exact=True)
        # both reproduce the data (the sub-lattice to 1e-7 rms: 3x the waves, closer in q)
        assert float(sol["resid"] @ sol["resid"]) < 1e-12 * float(model.z @ model.z)
        assert _every_chromosome_present(sol) is present


def test_noise_variance_from_the_periodogram_plateau():
    """The white-noise variance read from the high-q plateau of the periodogram: within
    20 % of the added noise at 128^2 (measured 3-17 % high there, 2 % at 512^2), and at
    the side-lobe level (1e-9 of the variance) on noise-free data."""
    from roughfe.genomics.sequencing.surface_data import surface_acquisitions, surface_peaks
    g, acq, rng = resolvable_surface_genome(0, length=L1, n_nodes=128, n_ridges=4, gamma=1.6)
    for a in surface_acquisitions(acq):
        assert surface_peaks(a).noise_variance < 1e-9 * np.nanvar(a.z)
    sigma = [0.01 * a.heights.std() for a in acq]
    noisy = [a.with_heights(a.heights + s * rng.normal(size=a.shape)) for a, s in zip(acq, sigma)]
    for a, s in zip(surface_acquisitions(noisy), sigma):
        assert surface_peaks(a).noise_variance == pytest.approx(s ** 2, rel=0.2, abs=0)


@pytest.mark.parametrize("seed", range(5))
def test_the_noise_floor_ends_the_search(seed, monkeypatch):
    """1 % white noise, seeds 0-4: the search stops at the first gamma candidate whose fit
    is down to the noise floor with every chromosome above the noise (no continuation):
    M exact, angles within 0.5 deg, gamma within 0.5 %, the misfit at the noise level.
    Seeds 0-1 (seed 1: the sub-lattice gamma^(1/3) competes): the full search, without
    the rule, finds the same genome with 5-20x the residual evaluations."""
    import roughfe.genomics.sequencing.surface as seq
    g, acq, rng = _genome(seed)
    noisy = [a.with_heights(a.heights + 0.01 * a.heights.std() * rng.normal(size=a.shape))
             for a in acq]
    r = sequence_surfaces(noisy)
    s = r.genome
    assert r.success and s.M == g.M
    assert np.degrees(np.abs(s.angles - g.angles)).max() < 0.5
    assert s.gamma == pytest.approx(g.gamma, rel=5e-3)
    noise = np.array([0.01 * a.heights.std() for a in acq]) / r.signal_rms
    for e in (r.fit_rms_errors, r.rms_errors):
        assert np.all((e > 0.8 * noise) & (e < 1.2 * noise)), e
    if seed < 2:
        monkeypatch.setattr(seq, "NOISE_FLOOR_FACTOR", 0.0)
        full = sequence_surfaces(noisy)
        assert full.genome.gamma == pytest.approx(s.gamma, rel=1e-9)
        np.testing.assert_allclose(full.genome.angles, s.angles, atol=1e-9)
        assert full.nit > 3 * r.nit


def test_a_noisy_sub_lattice_holds_noise_only_in_its_extra_chromosomes():
    """With 1 % noise both the lattice and its sub-lattice gamma^(1/3) fit down to the
    noise floor; the extra chromosomes of the sub-lattice hold noise-sized waves only,
    which the presence test measured against the noise floor tells apart."""
    from roughfe.genomics.sequencing.surface import (NOISE_FLOOR_FACTOR, _every_chromosome_present,
                                                     _noise_floor)
    from roughfe.genomics.sequencing.surface_data import surface_acquisitions, surface_peaks
    from roughfe.genomics.sequencing.surface_grid import GridModel
    g, acq, rng = _genome(5)
    noisy = surface_acquisitions(
        [a.with_heights(a.heights + 0.01 * a.heights.std() * rng.normal(size=a.shape))
         for a in acq])
    model = GridModel(noisy, N)
    cost, amplitude = _noise_floor(model, [surface_peaks(a).noise_variance for a in noisy])
    true = model.ranges(np.log(2 * np.pi / g.lambda1), np.log(g.gamma))
    for k, present in [(1, True), (3, False)]:
        p = np.r_[np.log(2 * np.pi / g.lambda1), np.log(g.gamma) / k, g.angles]
        sol = model.solve(p, [(1 + k * (a - 1), 1 + k * (b - 1)) for a, b in true])
        assert float(sol["resid"] @ sol["resid"]) <= NOISE_FLOOR_FACTOR * cost
        assert _every_chromosome_present(sol) is True          # noise passes 1e-6
        assert _every_chromosome_present(sol, noise=amplitude) is present


def test_a_tilt_does_not_make_a_poor_fit_pass():
    """The model fits a plane per acquisition; the misfit was over the variance about the
    mean, so a tilt of 100 rms added to 10 %-noisy acquisitions read 0.34 % (success)
    where the same data without it read 9.9 % (FAILED; here: 0.34 % / 0.36 %, success,
    against 28 % / 65 % without the tilt). Over the heights about their plane neither
    passes."""
    g, acq, rng = _genome(5)
    noisy = [a.with_heights(a.heights + 0.1 * a.heights.std() * rng.normal(size=a.shape))
             for a in acq]
    tilted = []
    for a in noisy:
        x = np.arange(a.shape[0])[:, None] / a.shape[0]
        tilted.append(a.with_heights(a.heights + 100 * a.heights.std() * x))
    r, t = sequence_surfaces(noisy), sequence_surfaces(tilted)
    assert not r.success and not t.success
    assert r.rms_errors.min() > 0.05 and t.rms_errors.min() > 0.05


def test_a_fit_with_an_impossible_exponent_is_a_failed_sequencing(topographies_dir,
                                                                  monkeypatch):
    """di-1.di on every fourth point (128^2): the lattice fit's amplitudes grow towards
    short waves (H = -0.45); the Genome refused it with an InputError about an H the user
    never gave (exit 2, no report). Now a failed sequencing that says why.

    Its final fit (gamma 1.106, 2 ridges, 203 unknowns on 16384 nodes) is singular to
    working precision: least squares put waves of 292 times the largest height into the
    directions the heights do not resolve (round 2, session 35). Damped as the profile
    fit is (:mod:`roughfe.genomics.sequencing.regularise`), the largest wave is 1.01
    times it, for a residual sum of squares 0.06 % higher (the bound of the rule:
    1 + p / (4 (m - p)) = 1.3 %); H -0.436 for -0.454, still impossible."""
    import roughfe.genomics.sequencing.surface as surface
    from roughfe.surfaces import Surface
    from roughfe.surfaces.io import load_surface
    s = load_surface(topographies_dir / "di-1.di")
    h = s.heights[::4, ::4]
    crop = Surface(h, (h.shape[0] * 4 * s.spacing[0], h.shape[1] * 4 * s.spacing[1]))
    final = {}
    real = surface.genes_from_fit
    monkeypatch.setattr(surface, "genes_from_fit",
                        lambda p, sol, ranges: final.update(p=p, sol=sol, ranges=ranges)
                        or real(p, sol, ranges))
    r = sequence_surfaces([crop])
    assert not r.success and r.genome is None
    assert "H = -0.437, outside (0, 3]" in r.message
    acqs = surface.surface_acquisitions([crop])
    ls = surface.GridModel(acqs, 128).solve(final["p"], final["ranges"], exact=True)
    damped, w = final["sol"], ls["nn"].size
    largest = float(np.abs(crop.heights - crop.heights.mean()).max())
    assert damped["damping"] > 0
    assert np.hypot(*ls["coef"][:2 * w].reshape(2, w)).max() > 100 * largest
    assert np.hypot(*damped["coef"][:2 * w].reshape(2, w)).max() < 1.1 * largest
    rows, unknowns = damped["resid"].size, damped["coef"].size
    assert damped["resid"] @ damped["resid"] <= (1 + unknowns / (4 * (rows - unknowns))) \
        * (ls["resid"] @ ls["resid"])
    # its two halves (x < 0, x > 0), fitted from that lattice, find other ridges (57.7 /
    # 91.8 and 44.3 / 90.4 deg) and H (-0.25, -0.58): no genome of the surface either
    # (the verdict fails it earlier, on H)
    from roughfe.genomics.sequencing.surface_reproduce import surface_reproducibility
    rep = surface_reproducibility(acqs, 128, final["p"], final["ranges"], 128)
    assert not rep.reproducible and "the genes are not reproducible" in rep.reason


@pytest.mark.slow
def test_an_overfit_of_a_measured_profile_is_not_a_genome(topographies_dir):
    """di-1.di's nested acquisitions (genome natural): the lattice fit reproduced them to
    0.1-0.3 % with 145 chromosomes, H at the end of its search interval (3) and waves of
    2.9 m on a profile of 15 nm rms, and said success; off by 1e8 on windows it was not
    fitted to. A fit at the end of the H interval, or with waves far larger than the data,
    is not a genome.

    Since round 2, session 34 (damped fit, halves compared) the fit passes every other
    test and its halves refuse it: at the default 512 nodes by their lattices alone (0.40
    steps apart, at most 0.25; 69 s of the suite's 8.5 min), here at 256 nodes (misfits
    0.8 / 0.4 / 0.4 %; lattices 0.40 steps apart and H 0.956 vs 0.069, 0.886 apart, at
    most 0.219; ~15 s); the lattice criterion alone: test_genomics_sequencing_reproduce.
    Without the halves' test the 256-node fit is "sequenced" (measured)."""
    from roughfe.genomics.natural import nested_acquisitions
    from roughfe.genomics.sequencing import sequence_profiles
    from roughfe.surfaces.io import load_surface
    acq = nested_acquisitions(load_surface(topographies_dir / "di-1.di"), n_nodes=256)
    r = sequence_profiles(acq)
    assert not r.success and "not a genome" in r.message
    assert np.all(r.rms_errors < 0.05)            # the overfit itself: a tiny misfit


def _own_misfits(genome, acq):
    """Relative rms misfit of ``realize_surface(genome)`` on each acquisition, both about
    their best plane (the sequencer fits a plane per acquisition)."""
    out = []
    for a in acq:
        n = a.shape[0]
        xx, yy = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
        plane = np.column_stack([np.ones(n * n), xx.ravel(), yy.ravel()])

        def about_plane(f):
            return f.ravel() - plane @ np.linalg.lstsq(plane, f.ravel(), rcond=None)[0]
        d = a.heights - realize_surface(genome, a.metadata["length"], n).heights
        out.append(np.sqrt(np.mean(about_plane(d) ** 2) / np.mean(about_plane(a.heights) ** 2)))
    return np.array(out)


def _sub_lattice_case():
    from roughfe.genomics.genome import random_genome
    g = random_genome(1e-3, 0.8, 1.8, 1.3e-3, 3, 30, rng=np.random.default_rng(3),
                      angles=[0, np.pi / 2, 2.2], anisotropy=[1.2, 0.9, 1 / 1.08])
    return g, [realize_surface(g, 1e-3, N), realize_surface(g, 4e-4, N)]


@pytest.mark.parametrize("case", ["pair", "one window"])
def test_a_sub_lattice_fit_is_refitted_on_its_lattice(case):
    """The direct fits settled on gamma^(1/2) (pair) and gamma^(1/4) (one window of seed
    1), which reproduce the data to 1e-11 and 1e-6 with k - 1 of every k chromosomes
    empty; the genome on that lattice (amplitudes on its power law: A x1.41 and x36)
    misfits its own windows by 94 % and 45 %, and success was True. Now the lattice the
    fit stands for is found: the true genome, and the reported misfit is the genome's."""
    if case == "pair":
        g, acq = _sub_lattice_case()
    else:
        g, acq, _ = resolvable_surface_genome(1, length=L1, n_nodes=N)
        acq = acq[:1]
    r = sequence_surfaces(acq)
    assert r.success, r.message
    assert r.genome.gamma == pytest.approx(g.gamma, rel=1e-10)
    assert r.genome.A == pytest.approx(g.A, rel=1e-8)
    np.testing.assert_allclose(r.rms_errors, _own_misfits(r.genome, acq), rtol=0.05,
                               atol=1e-13)
    assert np.all(r.rms_errors < 1e-10)


@pytest.mark.parametrize("perturbation", [10, 21, 22, 28])
def test_the_one_window_genome_does_not_depend_on_round_off(perturbation):
    """The one window above with its heights perturbed at 1e-15 (relative, seeded): the
    search path of a poor start is chaotic in round-off (unperturbed, its continuation
    fit ends at gamma 1.156698 or 1.156630 on the two BLAS), and one path ends on
    gamma^(2/9) (misfit 2.4 %, empty chromosomes), whose coarser lattices hold
    gamma^(1/2) but not gamma. Settled once,
    the genome came back on gamma^(1/2) (misfit 32 %, success False) for perturbations
    22, 24, 28 of 0-29 with the reference BLAS and 10, 16, 21, 25 (and the unperturbed
    data) with OpenBLAS; a winning coarser fit above its floor is now settled again: the
    true genome from all 30, on both."""
    g, acq, _ = resolvable_surface_genome(1, length=L1, n_nodes=N)
    a = acq[0]
    rng = np.random.default_rng(perturbation)
    r = sequence_surfaces([a.with_heights(a.heights
                                          * (1 + 1e-15 * rng.standard_normal(a.shape)))])
    assert r.success, r.message
    assert r.genome.gamma == pytest.approx(g.gamma, rel=1e-10)
    assert r.genome.A == pytest.approx(g.A, rel=1e-8)
    assert np.all(r.rms_errors < 1e-10)


def test_the_zero_wavevector_is_no_peak():
    """The periodogram's zero bin (the window-weighted mean of the heights about their
    mean: a bowl's) is its largest value; its mirror neighbours are equal up to the last
    bits, which the sub-bin parabola turned into an offset of 1e-14 bins when they
    survive the logarithm: a "peak" at |q| = 1.5e-14 / L in a direction set by
    round-off (4 of these 40 perturbations at 1e-15; on a fit's residual it took 92 % of
    the power and became a ridge at angle 0, OpenBLAS). Now the zero bin is no
    candidate: the same one wave from every perturbation."""
    n, length = 48, 1e-3
    x = (np.arange(n) - n // 2) * length / (n - 1)
    X, Y = np.meshgrid(x, x, indexing="ij")
    z = 1e-3 * (X / length) ** 2 + 1e-4 * Y / length + 1e-4 * np.cos(
        2 * np.pi * 7.3 * (X * np.cos(0.8) + Y * np.sin(0.8)) / length + 0.3)
    rng = np.random.default_rng(0)
    for _ in range(40):
        zp = z * (1 + 1e-15 * rng.standard_normal(z.shape))
        pk = surface_peaks(SurfaceAcquisition(x, x, zp, length))
        q = np.hypot(pk.qx, pk.qy)
        assert q.size == 1 and q[0] * length / (2 * np.pi) == pytest.approx(7.3, rel=1e-4)
        assert np.mod(np.arctan2(pk.qy, pk.qx), np.pi)[0] == pytest.approx(0.8, abs=1e-4)


def test_the_reported_misfit_is_the_returned_genomes(monkeypatch):
    """Without the refit on the coarser lattice the sub-lattice genome comes back: its
    rms_errors (and success) are those of the genome realised on the acquisitions (94 %,
    82 %; 47 %, 50 % with the genes of least height misfit), not of the fit with every
    wave its own amplitude (1e-11, kept as fit_rms_errors)."""
    import roughfe.genomics.sequencing.surface as seq
    monkeypatch.setattr(seq, "coarser_lattices", lambda *args, **kw: [])
    g, acq = _sub_lattice_case()
    r = sequence_surfaces(acq)
    assert r.genome.gamma == pytest.approx(np.sqrt(g.gamma), rel=1e-6)
    assert np.all(r.fit_rms_errors < 1e-9)
    np.testing.assert_allclose(r.rms_errors, _own_misfits(r.genome, acq), rtol=1e-6)
    assert r.rms_errors.min() > 0.3 and not r.success
    assert f"misfit of the genome {r.rms_errors[0]:.3g}, {r.rms_errors[1]:.3g}" in r.message


@pytest.mark.parametrize("seed, n_nodes, gamma, n_ridges, windows",
                         [(4, 32, 1.6, 2, 2), (10, 48, 1.8, 3, 1)])
def test_a_ridge_left_empty_by_the_completion_is_dropped(seed, n_nodes, gamma, n_ridges,
                                                         windows):
    """A ridge added from the residual takes over the waves of a ridge fitted at a wrong
    angle (44.2 deg next to the true 45.6; 127.1 next to 137.4), which then holds none.
    It was kept: M = 3 for 2 (4 for 3), its alpha 1e-9 and, as the alphas have a product
    of 1, the others x 1e4, A x 4.5e-5 (x 6e-4), success True. Now dropped: the genes."""
    g, acq, _ = resolvable_surface_genome(seed, length=L1, n_nodes=n_nodes, gamma=gamma,
                                          n_ridges=n_ridges)
    r = sequence_surfaces(acq[:windows])
    s = r.genome
    assert r.success, r.message
    assert s.M == g.M
    np.testing.assert_allclose(s.angles, g.angles, atol=1e-9)
    np.testing.assert_allclose(s.anisotropy, g.anisotropy, rtol=1e-8)
    assert s.A == pytest.approx(g.A, rel=1e-8)


def test_the_genes_minimise_the_genomes_height_misfit():
    """1 % noise, seed 4: the genes from the fit of ln b_mn (weighted by b_mn^2) gave A
    6.5 % and H 0.0072 off and a genome misfitting its windows by 1.31 / 1.40 x the noise
    (the long waves, nearly collinear with each other and the plane near the window
    length, are poorly set by the heights and weighed most); refined to the least height
    misfit with the fitted phases: A 1.5 %, H 0.0017, 1.05 / 1.03 x."""
    g, acq, rng = _genome(4)
    noisy = [a.with_heights(a.heights + 0.01 * a.heights.std() * rng.normal(size=a.shape))
             for a in acq]
    r = sequence_surfaces(noisy)
    noise = np.array([0.01 * a.heights.std() for a in acq]) / r.signal_rms
    assert np.all(r.rms_errors < 1.1 * noise), r.rms_errors / noise
    assert r.genome.A == pytest.approx(g.A, rel=0.03)
    assert r.genome.H == pytest.approx(g.H, abs=0.003)


def test_the_refit_on_a_coarser_lattice_is_not_refitted_again(monkeypatch):
    """The refit from a coarser start can converge back to the finer lattice, which was
    then offered its coarser lattices again, without end (RecursionError: N = 64, seed 1,
    3 % undefined points and a plane). Here every fit is taken for a sub-lattice and its
    "coarser" start is its own lattice: one refit each, the genome as without."""
    import roughfe.genomics.sequencing.surface as seq
    monkeypatch.setattr(seq, "_every_chromosome_present", lambda *args, **kw: False)
    monkeypatch.setattr(seq, "coarser_lattices", lambda p, *args, **kw: [p.copy()])
    g, acq, _ = _genome(5)
    r = sequence_surfaces(acq)
    assert r.success and r.genome.M == g.M
    assert r.genome.gamma == pytest.approx(g.gamma, rel=1e-10)


def test_a_few_undefined_points_do_not_hide_the_peaks():
    """Undefined nodes were set to zero before the periodogram: impulsive noise of about
    sqrt(3 %) = 17 % of the rms height, which lifted the median power, and the threshold
    (30 x median) dropped the peaks: "only 1 spectral peaks" for seed 1 (14 of seeds
    0-49 at N = 48 failed). Filled by the harmonic interpolation for the periodogram
    only, the surface is sequenced exactly."""
    g, acq, rng = _genome(1)
    masks = [rng.random(a.shape) > 0.03 for a in acq]
    r = sequence_surfaces(acq, valid=masks)
    assert r.success, r.message
    assert r.genome.M == g.M and r.genome.gamma == pytest.approx(g.gamma, rel=1e-10)
    assert r.genome.A == pytest.approx(g.A, rel=1e-8)
    assert np.all(r.rms_errors < 1e-10)
    from roughfe.genomics.sequencing.surface_data import harmonic_fill
    z = np.arange(25.0).reshape(5, 5) ** 2 / 10
    holes = z.copy()
    holes[2, 2] = holes[0, 0] = holes[3, 1] = holes[3, 2] = np.nan
    filled = harmonic_fill(holes)
    assert filled[2, 2] == pytest.approx((z[1, 2] + filled[3, 2] + z[2, 1] + z[2, 3]) / 4)
    assert filled[0, 0] == pytest.approx((z[0, 1] + z[1, 0]) / 2)
    assert filled[3, 1] == pytest.approx((z[2, 1] + z[4, 1] + z[3, 0] + filled[3, 2]) / 4)


def test_the_fill_error_is_not_taken_for_noise():
    """Seed 22, 3 % undefined, noise-free: the periodogram's plateau held the error of the
    harmonic fill (white, like noise), and the search stopped at a fit with a 3 % misfit
    as if at the noise floor (success True, gamma 4e-4 and A 4 % off). The floor is now
    read again with the undefined nodes filled by the fit's own heights: exact."""
    g, acq, rng = _genome(22)
    r = sequence_surfaces(acq, valid=[rng.random(a.shape) > 0.03 for a in acq])
    assert r.success and r.genome.M == g.M
    assert r.genome.gamma == pytest.approx(g.gamma, rel=1e-10)
    assert r.genome.A == pytest.approx(g.A, rel=1e-8)
    assert np.all(r.rms_errors < 1e-10)


def test_a_sequenced_surface_genome_realises_as_its_surface(tmp_path, capsys):
    """`genome realize` on a sequenced 2D genome wrote a 512-point profile by Eq. 3.1 that
    ignored the ridge angles, and the sequencer stored no n_nodes for --nodes' default.
    Now the N x N window of Eq. 3.17 the sequencer models, N of the acquisitions: the
    acquisition itself."""
    from roughfe.cli import main
    from roughfe.surfaces.io import load_surface, save_surface
    g, (a1, a2), _ = _genome(7)
    p1, p2 = save_surface(a1, tmp_path / "a1.npz"), save_surface(a2, tmp_path / "a2.npz")
    assert main(["genome", "sequence", str(p1), str(p2), "--no-figures",
                 "-o", str(tmp_path / "seq")]) == 0
    genome = str(tmp_path / "seq" / "genome.json")
    assert main(["genome", "realize", genome, "--length", str(L1),
                 "-o", str(tmp_path / "r.npz")]) == 0
    assert "realised surface L = 0.001 m, N = 48" in capsys.readouterr().out
    r = load_surface(tmp_path / "r.npz")
    assert r.shape == (N, N) and not r.periodic
    np.testing.assert_allclose(r.heights, a1.heights, atol=1e-10 * np.abs(a1.heights).max())
    assert main(["genome", "realize", genome, "--length", str(L1), "--chromosomes", "2",
                 "-o", str(tmp_path / "c.npz")]) == 2
    assert "a surface genome (ridge angles) is realised with the Eq. 3.5" in \
        capsys.readouterr().err


@pytest.mark.parametrize("gamma, n_ridges, seed", [(2.5, 1, 3), (3.0, 1, 8), (2.2, 2, 11)])
def test_two_exact_lattices_tie_at_round_off(gamma, n_ridges, seed):
    """Noise-free data fit exactly on their lattice gamma and on its sub-lattice
    sqrt(gamma); the BIC floored the cost at 1e-32 z.z, below the ~1e-29 the solve
    reaches, so round-off chose between the two: gamma = sqrt(gamma), relative misfit
    0.65-0.84, success False (3 of 136 random genomes at N = 48). With the sequencers'
    one round-off floor (1e-24 z.z) the exact fits tie and the lattice wins."""
    g, acq, _ = resolvable_surface_genome(seed, length=L1, n_nodes=N, n_ridges=n_ridges,
                                          gamma=gamma, hurst=0.7)
    r = sequence_surfaces(acq)
    assert r.success, r.message
    assert r.genome.gamma == pytest.approx(gamma, rel=1e-12, abs=0)
    assert r.rms_errors.max() < 1e-12


def test_the_figure_draws_the_genome_at_the_acquisitions_own_nodes(tmp_path, monkeypatch):
    """Windows off the origin (metadata x0, y0, honoured by the sequencer): the figure
    drew the genome centred on the origin, so a sequencing exact to 5e-15 showed a
    difference 96-97 % of the surface. Now it draws the fields of ``misfit_fields`` (the
    genome at each acquisition's own nodes, best planes removed as by the misfit): the
    difference's rms is the reported misfit."""
    from roughfe.genomics.genome import random_genome, surface_heights
    from roughfe.genomics.sequencing.surface_result import misfit_fields
    import roughfe.plotting.genomics as plots

    g = random_genome(1e-3, 0.8, 1.8, 1.3e-3, 3, 30, rng=1, angles=[0.3, 1.2, 2.4])
    acq = []
    for length, frac in ((L1, 0.3), (L1 / 2.5, 0.4)):
        d = length / (N - 1)
        x = np.round(-frac * length / d) * d + np.arange(N) * d
        z, _ = surface_heights(g, length, N, x, x)
        acq.append(Surface(z, N * d, periodic=False,
                           metadata={"x0": float(x[0]), "y0": float(x[0])}))
    r = sequence_surfaces(acq)
    assert r.success and r.rms_errors.max() < 1e-12, r.message
    fields = misfit_fields(r.genome, acq)
    for (a, measured, sequenced, diff), err in zip(fields, r.rms_errors):
        assert a.x[0] < -0.2 * a.length and a.y[0] == a.x[0]      # off the centre
        rel = np.sqrt(np.mean(diff ** 2)) / np.sqrt(np.mean(measured ** 2))
        assert rel == pytest.approx(err, rel=1e-3, abs=1e-15)
        np.testing.assert_array_equal(diff, measured - sequenced)
    drawn = []
    monkeypatch.setattr(plots, "save_figure", lambda fig, path: drawn.append(fig) or path)
    plots.plot_sequenced_surfaces(r, acq, tmp_path / "s.png")
    panels = drawn[0].axes
    for row, (_, measured, _, _) in enumerate(fields):
        z = np.asarray(panels[3 * row].images[0].get_array())
        diff = np.asarray(panels[3 * row + 2].images[0].get_array())
        assert np.sqrt(np.mean(diff ** 2)) < 1e-12 * np.sqrt(np.mean(z ** 2))
        # the difference on its own colour scale (on the heights' it was one flat colour)
        assert panels[3 * row + 2].images[0].get_clim()[1] == pytest.approx(
            np.abs(diff).max(), rel=1e-9, abs=0)
        assert panels[3 * row].images[0].get_clim()[1] == pytest.approx(
            np.abs(z).max(), rel=1e-9, abs=0)


@pytest.mark.parametrize("hurst, seed", [(0.3, 1), (0.8, 2)])
def test_a_continuous_spectrum_fails_before_any_fit(hurst, seed):
    """A periodic self-affine 256^2 surface: its periodogram has ~100 local maxima in
    17-31 directions, and the lattice fit of all of them ran for more than 12 minutes
    before it failed (a user's review). Its peaks lie on no geometric lattice (comb
    coherence ~0.2, an MWM's is > 0.7): the failure is now told before any fit."""
    s = spectral_surface(256, 1e-4, hurst, rms_height=1e-6, rng=seed)
    r = sequence_surfaces([Surface(s.heights, 256 * 1e-4 / 255)])
    assert not r.success and r.genome is None and r.nit == 0
    assert "no geometric lattice" in r.message and "comb coherence 0." in r.message


def test_a_surface_genome_predicts_its_held_out_nodes():
    """The 5-fold held-out nodes of the profile sequencer (sequencing.holdout, round 2,
    session 33 for surfaces): each fold of (x, y) positions predicted by the fit of the
    others on the sequenced lattice (the model's own solve, the fold left out as
    undefined nodes are). An exact MWM surface predicts them to round-off (measured
    2e-15..7e-15, seeds 1, 5, 7, 11), a 1 %-noisy one to about its misfit (1.01-1.03
    times it): both are genomes."""
    from roughfe.genomics.sequencing.holdout import node_folds
    g, acq, rng = _genome(5)
    r = sequence_surfaces(acq)
    assert r.success and np.all(r.held_out_errors < 1e-12), r.held_out_errors
    assert r.report()["held_out_errors"] == r.held_out_errors.tolist()
    g, acq, rng = _genome(11)
    r = sequence_surfaces([a.with_heights(a.heights + 0.01 * a.heights.std()
                                          * rng.normal(size=a.shape)) for a in acq])
    assert r.success, r.message
    assert np.all((r.held_out_errors > r.fit_rms_errors)
                  & (r.held_out_errors < 1.2 * r.fit_rms_errors)), r.held_out_errors
    # nodes at one (x, y) share a fold, nodes that share x (or y) only need not
    coords = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]] * 2)
    fold = node_folds(coords + 1e-9 * np.arange(8)[:, None], step=1.0, folds=4)
    np.testing.assert_array_equal(fold[:4], fold[4:])
    assert sorted(fold[:4].tolist()) == [0, 1, 2, 3]


@pytest.mark.slow
def test_a_surface_fit_of_more_waves_than_nodes_misses_its_held_out_nodes():
    """Noise (32^2, band-limited to half the Nyquist wavenumber, inside the disk the
    waves cover) on a lattice of 20 ridges, gamma 1.1: 1483 unknowns on 1024 nodes. The
    fit reproduces it within the tolerance (0.4 %), and its held-out nodes are missed by
    65 %: an overfit, which a genome is not (the test above)."""
    from roughfe.genomics.sequencing.surface_data import surface_acquisitions
    from roughfe.genomics.sequencing.surface_grid import GridModel
    from roughfe.genomics.sequencing.surface_result import held_out_misfits, plane_free_misfits
    white = np.fft.fft2(np.random.default_rng(0).standard_normal((32, 32)))
    k = np.hypot(*np.meshgrid(*2 * [2 * np.fft.fftfreq(32)], indexing="ij"))
    noise = np.fft.ifft2(np.where(k < 0.5, white, 0)).real * 1e-6
    model = GridModel(surface_acquisitions([Surface(noise, 1e-3, periodic=False)]), 32)
    p = np.r_[np.log(2 * np.pi / 1.2e-3), np.log(1.1), np.linspace(0, np.pi, 20, endpoint=False)]
    ranges = model.ranges(p[0], p[1])
    sol = model.solve(p, ranges, exact=True)
    assert sol["coef"].size > 1024
    assert plane_free_misfits(model, sol["resid"])[0][0] < 0.01
    assert held_out_misfits(model, p, ranges)[0] > 0.3


def test_a_surface_fit_whose_held_out_nodes_are_missed_is_not_a_genome(monkeypatch):
    """The verdict of a fit within the tolerance whose held-out nodes are missed by more
    (here made so): not a genome, the message naming the wave unknowns and nodes of the
    acquisition, both misfits, and the report holding the held-out misfits."""
    import re

    import roughfe.genomics.sequencing.surface as surface
    real = surface.held_out_misfits
    monkeypatch.setattr(surface, "held_out_misfits",
                        lambda *a, **k: real(*a, **k) + [0.1, 0.2])
    g, acq, _ = _genome(5)
    r = sequence_surfaces(acq)
    assert not r.success and np.all(r.rms_errors < 1e-10)
    waves = 2 * g.M * (r.ranges[1][1] - r.ranges[1][0] + 1)
    assert re.match(rf"not a genome: an overfit: {waves} wave unknowns on {N * N} nodes "
                    rf"\(acquisition 2\); its nodes held out of the fit \(5 folds by "
                    rf"position\) are missed by 0\.2 \(relative rms\), the fitted ones by "
                    rf"\d\.\d+e-1\d; M = 3 ridges", r.message), r.message
    assert r.report()["held_out_errors"][1] == pytest.approx(0.2, rel=1e-9, abs=0)
