"""Surface genome database and surface design (issue 15 Sec. 3): periodic realisation of a
surface genome, 2D database rows, design on a 2D database, bad input."""
from dataclasses import replace

import numpy as np
import pytest

from roughfe.errors import InputError
from roughfe.genomics import database as db
from roughfe.genomics.design import (Design, DesignPart, Evaluator, Objective, rescore,
                                     rescore_at_target_pressures, run_design)
from roughfe.genomics.design.sensitivities import residual_jacobian
from roughfe.genomics.genome import Genome, random_genome
from roughfe.genomics.periodic import (lattice_wavevectors, periodic_chromosome_range,
                                       periodic_heights, realize_periodic_surface)
from roughfe.genomics.similarity import Target

L = 1e-4
SETTINGS = db.DatabaseSettings(length=L, n_nodes=32, dim=2, top_fraction=0.8,
                               youngs_modulus=1e6, n_steps=8)


def _genome():
    return random_genome(1.0, 0.8, 1.5, L, 3, 12, rng=1, angles=[0.3, 1.2, 2.5],
                         anisotropy=[1.0, 0.7, 1.3])


def test_periodic_realisation_is_the_lattice_plane_wave_sum():
    """Eq. 3.17 on the torus: the FFT build equals the brute-force sum of the rounded
    plane waves to round-off, Z(0) = 0, and every wavevector moved by <= (2 pi/L)/sqrt 2."""
    g, n = _genome(), 32
    s = realize_periodic_surface(g, L, n)
    idx = np.array(s.metadata["chromosomes"])
    assert (idx[0], idx[-1]) == periodic_chromosome_range(g.gamma, g.lambda1, L, n)
    k, l_ = lattice_wavevectors(g, idx, L)
    x = np.arange(n) * L / n
    X, Y = np.meshgrid(x, x, indexing="ij")
    a = g.wave_amplitude(idx)[None, :] * g.anisotropy[:, None]
    phi = g.phase_columns(idx)
    z = sum(a[m, j] * (np.cos(phi[m, j]) - np.cos(2 * np.pi * (k[m, j] * X + l_[m, j] * Y) / L
                                                   + phi[m, j]))
            for m in range(g.M) for j in range(idx.size))
    assert np.max(np.abs(s.heights - z)) <= 1e-12 * np.max(np.abs(z))
    assert s.heights[0, 0] == pytest.approx(0.0, abs=1e-12 * np.max(np.abs(z)))
    q = g.wavenumber(idx) * L / (2 * np.pi)
    moved = np.hypot(k - q * np.cos(g.angles)[:, None], l_ - q * np.sin(g.angles)[:, None])
    assert moved.max() <= 2 ** -0.5 + 1e-12
    assert s.periodic and s.size == (L, L)


def test_phase_shift_translates_the_periodic_surface():
    """Translating by one node along x equals adding 2 pi k / N to every phase (the
    phases carry position: the symmetry the design variables rely on)."""
    g, n = _genome(), 32
    idx = np.arange(*np.add(periodic_chromosome_range(g.gamma, g.lambda1, L, n), (0, 1)))
    k, _ = lattice_wavevectors(g, idx, L)
    ph = np.array(g.phases)
    ph[:, idx - g.n_first] += 2 * np.pi * k / n
    z0 = periodic_heights(g, L, n)
    z1 = periodic_heights(replace(g, phases=ph), L, n)
    # Z has the offset sum a cos(phi) that makes Z(0) = 0: compare without the mean
    assert np.allclose(z1 - z1.mean(), np.roll(z0, -1, axis=0) - z0.mean(), atol=1e-12 * np.ptp(z0))


def test_phase_derivative_matches_differences():
    g = _genome()
    d = Design((DesignPart(g, (3, 4, 5), 2.0, "g"),), 1.5, L, 32, "g", 2)
    dz = d.phase_derivative(0, 1, 4)
    eps = 1e-6
    d2 = d.with_phases([(0, 1, 4)], [g.phases[1, 3] + eps])
    fd = (d2.surface().heights - d.surface().heights) / eps
    assert np.max(np.abs(fd - dz)) <= 1e-5 * np.max(np.abs(dz))


def test_sobol_surface_design_has_angles_and_anisotropy():
    sd = db.SobolDesign(dim=2, n_pairs=4, n_vectors=2, n_ridges=3, anisotropy_range=(0.5, 2.0))
    tasks = db.sobol_tasks(sd)
    assert len(tasks) == 8
    for t in tasks:
        assert len(t["angles"]) == 3 and all(0 <= a < np.pi for a in t["angles"])
        assert all(0.5 <= a <= 2.0 for a in t["anisotropy"])
        assert np.shape(t["phases"]) == (3, sd.n_phases + sd.n_extra)
    # profile design unchanged: no surface keys in its stored JSON
    assert "dim" not in db.SobolDesign().to_dict()
    assert db.SobolDesign.from_dict(sd.to_dict()) == sd


@pytest.fixture(scope="module")
def surface_db(tmp_path_factory):
    sd = db.SobolDesign(dim=2, n_pairs=4, n_vectors=1, n_ridges=2)
    records = [db.genome_entry_task(**t, **SETTINGS.to_dict()) for t in db.sobol_tasks(sd)]
    path = tmp_path_factory.mktemp("sdb") / "db.sqlite"
    con = db.connect(path, create=True)
    db.write_settings(con, SETTINGS)
    db.write_design(con, sd)
    db.insert_records(con, records)
    con.close()
    return path, records


def test_surface_db_rows(surface_db):
    """Each row: M ridges with angles, one chromosome curve per chromosome of the periodic
    range, the realisation loaded to 0.8 of full contact (A* < 1); the settings record
    dim = 2; p scales with the amplitude gene (Eq. 4.2) while K(p/A), A*(p/A) do not change."""
    path, records = surface_db
    assert db.read_settings(path).dim == 2
    entries = db.load_entries(path)
    for e in entries:
        g = Genome.from_dict(e.genome)
        n_s, n_f = periodic_chromosome_range(g.gamma, g.lambda1, L, 32)
        assert g.M == 2 and g.angles is not None
        assert (g.n_first, g.n_last) == (n_s, n_f)
        assert len(e.chromosome_curves) == n_f - n_s + 1
        assert 0 < e.curve.area_fraction[-1] < 1
    t = db.sobol_tasks(db.SobolDesign(dim=2, n_pairs=4, n_vectors=1, n_ridges=2))[0]
    twice = db.genome_entry_task(**{**t, "label": "x"}, amplitude=2.0, **SETTINGS.to_dict())
    assert twice["p_max"] == pytest.approx(2 * records[0]["p_max"], rel=1e-7)
    assert np.allclose(twice["curve"]["stiffness"], records[0]["curve"]["stiffness"], rtol=1e-6)


def test_exact_sensitivities_of_a_surface_design_agree_with_differences(surface_db):
    """The fixed-contact-set Jacobian (periodic approach: f (max h - mean h)) of the K and
    A residuals against central differences: the same derivative to 1e-4 of its scale at
    one of the steps 1e-5, 1e-4, 1e-6 rad (tried in that order). A central difference
    errs by the solver's rounding over the step (~1e-12/h of the scale) plus, when a
    contact set changes inside the step, by a kink of O(1). Measured on rows 1-3 of this
    database: <= 2.5e-6 at 1e-6 rad, <= 1.8e-7 at 1e-5 except 2.8e-5 on row 3 (a contact
    set changing within 1e-5 rad), O(1) from 1e-3 on. A wrong sensitivity fails at every
    step; rounding or a kink at one step does not fail the test. The target pressures lie
    between the design's rescaled steps: at a step the linear interpolation has a kink
    (one-sided derivatives), which is what an earlier version of this test, with targets
    on the steps, measured as a 12 % "mismatch"."""
    path, _ = surface_db
    e = db.load_entries(path)[1]
    d = Design((DesignPart(Genome.from_dict(e.genome), e.macro + e.micro, 1e-6, e.label),),
               1.0, L, 32, e.label, 2)
    c = Evaluator(SETTINGS)(d)
    pt = np.append(0.5 * (c.pressure[1:] + c.pressure[:-1]), 1.001 * c.pressure[-1])
    obj = Objective((Target(pt, 1.01 * np.interp(pt, c.pressure, c.stiffness), "K", "t", {}),
                     Target(pt[:-1], 0.99 * np.interp(pt[:-1], c.pressure, c.area_fraction),
                            "A", "a", {})))
    keys = d.keys("all")[:4]
    r, jac = residual_jacobian(d, keys, obj, SETTINGS)
    x0 = d.phase_values(keys)
    ev = Evaluator(SETTINGS)
    for i in range(len(keys)):
        errors = []
        for h in (1e-5, 1e-4, 1e-6):
            x = [x0.copy(), x0.copy()]
            x[0][i] += h
            x[1][i] -= h
            fd = np.subtract(*(obj.residuals(ev(d.with_phases(keys, v))) for v in x)) / (2 * h)
            errors.append(np.max(np.abs(fd - jac[:, i])) / np.max(np.abs(jac)))
            if errors[-1] <= 1e-4:
                break
        assert min(errors) <= 1e-4, f"phase {keys[i]}: relative errors {errors}"
    assert np.abs(jac[pt.size:]).max() > 1e-2        # the A rows are not trivially zero


def test_sog_recovers_a_surface_genome_near_the_database(surface_db):
    """Target: a database genome with every phase moved by N(0, 0.3 rad) and amplitude x3
    (a genome outside the database). SOG starts from its parent among others and GCMMA
    raises s on K(p) to >= 0.95; a fresh BEM run of the saved design reproduces the
    reported score. (Since session 26 the curves are read from (0, 0) below their first
    pressure, and the target's first point lies below the parent's: its GCMMA reaches
    0.944 and genome 1-1's 0.961, where the parent's reached 0.971 with the first value
    held.)"""
    entries, tk, _ = _perturbed_target(surface_db, 0.3)
    res = run_design("sog", entries, [tk], SETTINGS)
    best = res.best
    assert entries[1].label in [c.origin for c in res.candidates]
    assert best.stages[1] > best.stages[0] and best.scores[0] >= 0.95
    assert rescore(best.design, [tk], SETTINGS)[0] == pytest.approx(best.scores[0], abs=1e-9)
    assert best.design.surface().periodic
    # the design JSON keeps dim
    assert Design.from_dict(best.design.to_dict()).dim == 2
    strict = rescore_at_target_pressures(best.design, [tk], SETTINGS)[0]
    assert abs(strict - best.scores[0]) < 0.05


def test_surface_database_bad_input():
    with pytest.raises(InputError, match="dim"):
        db.DatabaseSettings(dim=3)
    with pytest.raises(InputError, match="top_fraction"):
        db.DatabaseSettings(dim=2, top_fraction=1.5)
    with pytest.raises(InputError, match="angles"):
        db.make_genome(1.5, 0.8, 1, SETTINGS)
    with pytest.raises(InputError, match="2 x"):
        db.make_genome(1.5, 0.8, np.zeros((1, 40)), SETTINGS, angles=[0.1, 0.2])
    with pytest.raises(InputError, match="n_ridges"):
        db.SobolDesign(dim=2, n_ridges=0)
    g = _genome()
    one = Design((DesignPart(g, (3,), 1.0, "a"),), 1.0, L, 32, "a", 1)
    two = Design((DesignPart(g, (3,), 1.0, "b"),), 1.0, L, 32, "b", 2)
    from roughfe.genomics.design import combine
    with pytest.raises(InputError, match="dim"):
        combine(one, two)


def test_surface_db_and_design_commands(tmp_path, capsys, monkeypatch):
    """db build --dim 2 through the study runner, design-targets of a surface file (its own
    BEM sweep), design on the surface database; the saved periodic heights re-scored by a
    fresh BEM run give the reported scores. A surface design is saved as surface.npz and
    surface.png (they were profile.*), and psd.png draws the --match-spectrum target's
    spectrum beside the design's (it drew the design's alone)."""
    import json

    import roughfe.plotting.design as design_plots
    from roughfe.cli import main

    drawn = {}                                   # figure file -> its panels' legend labels
    save = design_plots.save_figure

    def recording_save(fig, path, *args, **kwargs):
        drawn[path.name] = [[t.get_text() for t in ax.get_legend().get_texts()]
                            for ax in fig.axes if ax.get_legend() is not None]
        return save(fig, path, *args, **kwargs)
    monkeypatch.setattr(design_plots, "save_figure", recording_save)
    from roughfe.surfaces import Surface
    from roughfe.surfaces.io import load_surface, save_surface

    path = tmp_path / "s.sqlite"
    assert main(["db", "build", str(path), "--dim", "2", "--nodes", "16", "--steps", "5",
                 "--ridges", "2", "--limit", "2", "--length", "1e-4", "--quiet",
                 "--workers", "1", "--hurst-range", "0.2", "0.45"]) == 0
    settings = db.read_settings(path)
    assert all(0.2 <= e.hurst <= 0.45 for e in db.load_entries(path))
    assert (settings.dim, settings.n_nodes, settings.top_fraction) == (2, 16, 0.8)
    g = Genome.from_dict(db.load_entries(path)[0].genome)
    tsurf = realize_periodic_surface(replace(g, A=2e-6, phases=g.phases + 0.2), 1e-4, 16)
    save_surface(Surface(tsurf.heights, tsurf.size, periodic=True), tmp_path / "t.npz")
    assert main(["design-targets", "--db", str(path), "--surface", str(tmp_path / "t.npz"),
                 "--detrend", "mean", "-o", str(tmp_path / "t")]) == 0
    # a plain matrix of the same heights with --size and --periodic (a review found no
    # way to give its size: the message named a --size the command did not have)
    np.save(tmp_path / "t.npy", tsurf.heights)
    assert main(["design-targets", "--db", str(path), "--surface", str(tmp_path / "t.npy"),
                 "--size", "1e-4", "--periodic", "--detrend", "mean", "-o",
                 str(tmp_path / "t_npy")]) == 0
    for name in ("t_K.csv", "t_A.csv"):
        assert (tmp_path / "t_npy" / name).read_text() == (tmp_path / "t" / name).read_text()
    out = tmp_path / "d"
    assert main(["design", "--db", str(path), "--target", str(tmp_path / "t" / "t_K.csv"),
                 "--second-target", str(tmp_path / "t" / "t_A.csv"), "--method", "mcco",
                 "--iterations", "1", "--match-spectrum", str(tmp_path / "t.npz"),
                 "--spectrum-starts", "1", "--match-directions", "--search", "3",
                 "--search-amplitudes", "wave", "--global", "cmaes", "--global-eval", "6",
                 "--global-amplitudes", "0.5", "--global-waves",
                 "-o", str(out)]) == 0
    report = json.loads((out / "result.json").read_text())
    assert "wave amplitudes matched to the target spectrum" in report["message"]
    assert "wave weights" in report["message"] and "wave amplitudes x exp" in report["message"]
    design = Design.from_dict(json.loads((out / "design.json").read_text()))
    assert design.dim == 2
    heights = load_surface(out / "surface.npz")
    assert heights.periodic and heights.shape == (16, 16)
    assert (out / "surface.png").is_file() and (out / "psd.png").is_file()
    assert not (out / "profile.npz").exists() and not (out / "profile.png").exists()
    assert drawn["psd.png"] == [["FFT (no window, annulus mean)",
                                 "target t.npz (--match-spectrum)", "chromosomes",
                                 "Nyquist pi/dx"]]
    np.testing.assert_allclose(heights.heights, design.surface().heights, rtol=1e-12)
    targets = [Target.from_dict(t) for t in report["targets"]]
    assert rescore_at_target_pressures(design, targets, settings) == pytest.approx(
        report["candidates"][0]["scores_at_target_pressures"], abs=1e-7)
    assert main(["design", "--db", str(path), "--target", str(tmp_path / "t" / "t_K.csv"),
                 "--method", "sog", "--match-directions", "-o", str(tmp_path / "e")]) == 2
    assert "--match-directions needs --match-spectrum" in capsys.readouterr().err
    assert main(["db", "build", str(tmp_path / "x.sqlite"), "--dim", "2",
                 "--top-fraction", "1.5"]) == 2
    assert "top_fraction" in capsys.readouterr().err
    assert main(["db", "build", str(tmp_path / "x.sqlite"), "--dim", "2",
                 "--hurst-range", "1.0", "0.2"]) == 2
    assert "hurst_range must have low <= high, got (1.0, 0.2)" in capsys.readouterr().err


def test_match_spectrum_restores_a_genome_whose_hurst_exponent_moved(surface_db):
    """Target: a database genome with H lowered by 0.3 (same phases, every chromosome's
    amplitude changed: outside the database, and Eq. 4.2 cannot undo it). SOG without
    GCMMA iterations keeps the parent; matching the chromosome amplitudes to the target
    surface's band rms (match_spectrum) restores the target itself, so the strict score
    goes to 1 (round-off), and a fresh BEM run of the saved design reproduces it."""
    from roughfe.genomics.design import GcmmaOptions, match_spectrum

    path, _ = surface_db
    entries = db.load_entries(path)
    g = Genome.from_dict(entries[1].genome)
    g = replace(g, H=g.H - 0.3, A=2.0)
    target = Design((DesignPart(g, tuple(range(g.n_first, g.n_last + 1)), 1.0, "t"),), 1.0, L,
                    32, "t", 2)
    c = Evaluator(SETTINGS)(target)
    tk = Target(c.pressure, c.stiffness, "K", "tK", {})
    res = run_design("sog", [entries[1]], [tk], SETTINGS,
                     options=GcmmaOptions(n_it_sog=0, n_it_micro=0))
    before = rescore_at_target_pressures(res.best.design, [tk], SETTINGS)[0]
    matched = match_spectrum(res, target.surface(), SETTINGS)
    assert before < 0.9 and matched.best.at_targets[0] == pytest.approx(1.0, abs=1e-6)
    assert matched.success and matched.nit == res.nit + 4     # strict before, 2 in _finish, after
    assert rescore_at_target_pressures(matched.best.design, [tk], SETTINGS)[0] == \
        matched.best.at_targets[0]
    # a matched database genome added as a candidate ran no GCMMA stage: its stages say so
    # (NaN; stages.csv wrote the matched score under the GCMMA 1 and 2 headers)
    added = match_spectrum(res, target.surface(), SETTINGS, entries=entries, n_entries=1)
    new = [c for c in added.candidates if len(c.stages) == 3 and np.isnan(c.stages[1])]
    assert len(new) == 1 and np.isnan(new[0].stages[2]) and np.isfinite(new[0].stages[0])
    assert new[0].origin.endswith("(spectrum)") and 0 < new[0].scores[0] <= 1


def test_design_match_spectrum_warns_of_its_file_as_design_targets(surface_db, tmp_path,
                                                                    capsys, monkeypatch,
                                                                    computed_once):
    """`design --match-spectrum FILE` read its file without the warnings of info, contact,
    leak and design-targets (round 2, session 36): a map with offset scan lines gave a
    matched design without a word, and the design had no --detrend to follow the advice.
    It now warns through the same path (surface_warnings.plausible_surface), before the
    design runs; --detrend lines levels the lines (no warning, another target spectrum),
    --scan-axis y reads the rows as the lines (not offset: no warning)."""
    import roughfe.genomics.design as design
    from roughfe.cli import main
    from roughfe.genomics.design import target_surface
    from roughfe.genomics.target_csv import write_target_csv
    from roughfe.surfaces import Surface, load_surface, save_surface, spectral_surface

    # the three runs design for the same target and database; the default and --scan-axis
    # y match the same detrended file (the axis is read by the warnings before the design
    # and kept in the surface's metadata; match_spectrum reads the heights, size and
    # periodicity): each design and match is computed once per distinct arguments
    monkeypatch.setattr(design, "run_design", computed_once(design.run_design))
    matched = []                                 # the surfaces the stage matched
    match = computed_once(design.match_spectrum, lambda res, surface, *a, **k: (
        res, surface.heights, surface.size, surface.periodic, a, k))
    monkeypatch.setattr(design, "match_spectrum",
                        lambda res, surface, *a, **k: matched.append(surface) or match(
                            res, surface, *a, **k))

    path, _ = surface_db
    g = Genome.from_dict(db.load_entries(path)[0].genome)
    c = Evaluator(SETTINGS)(Design((DesignPart(g, tuple(range(g.n_first, g.n_last + 1)), 1.0,
                                               "t"),), 1.0, L, 32, "t", 2))
    write_target_csv(tmp_path / "tK.csv", Target(c.pressure, c.stiffness, "K", "tK", {}))
    size = (L, 2 * L / 3)
    h = spectral_surface((48, 32), size, 0.7, rms_height=2e-7, rng=1).heights
    h = h + 6e-8 * np.random.default_rng(3).standard_normal(32)[None, :]    # line offsets
    save_surface(Surface(h, size, False), tmp_path / "lines.npz")

    def run(*extra):
        out = tmp_path / f"d{len(list((tmp_path).glob('d*')))}"
        capsys.readouterr()
        assert main(["design", "--db", str(path), "--target", str(tmp_path / "tK.csv"),
                     "--method", "sog", "--iterations", "1", "--match-spectrum",
                     str(tmp_path / "lines.npz"), *extra, "--no-figures", "--quiet",
                     "-o", str(out)]) in (0, 1)
        return capsys.readouterr().err

    offset = "roughfe design: warning: the scan lines along x (heights[:, j]) look offset"
    said = run()                                                 # default --detrend plane
    assert offset in said and "--detrend lines" in said
    assert "scan lines" not in run("--detrend", "lines")
    assert "scan lines" not in run("--scan-axis", "y")           # rows i: no offsets
    read = load_surface(tmp_path / "lines.npz")
    assert len(matched) == 3 and not np.array_equal(matched[0].heights, matched[1].heights)
    np.testing.assert_array_equal(matched[2].heights, matched[0].heights)
    for got, mode in zip(matched, ("plane", "lines")):           # the file detrended so
        np.testing.assert_array_equal(got.heights, target_surface(read, SETTINGS,
                                                                  detrend=mode).heights)


def test_ridge_keys_scale_every_wave_on_its_own():
    """Per-wave amplitude variables (Design.ridge_keys on one-chromosome parts): the
    surface is linear in every wave's factor alpha_m (Eq. 3.17), so setting the factors
    gives exactly the sum of the waves times their factors; phase_values reads them back."""
    g = _genome()
    d = Design((DesignPart(g, (3, 4, 5), 2.0, "g"),), 1.5, L, 32, "g", 2).split_chromosomes()
    keys = d.ridge_keys()
    assert len(keys) == 3 * 3 and all(k[1] == "alpha" for k in keys)
    x0 = d.phase_values(keys)
    np.testing.assert_array_equal(x0, np.tile(g.anisotropy, 3))
    f = np.random.default_rng(2).uniform(0.3, 2.0, x0.size)
    new = d.with_phases(keys, x0 * f)
    np.testing.assert_array_equal(new.phase_values(keys), x0 * f)
    waves = sum(f[3 * k + m] * d.parts[k].weight
                * periodic_heights(p.genome, L, 32, p.chromosomes, rows=[m])
                for k, p in enumerate(d.parts) for m in range(3))
    h = new.surface().heights
    assert np.max(np.abs(h - waves)) <= 1e-12 * np.ptp(h)


def _perturbed_target(surface_db, spread=0.6):
    """Database genome 1 with amplitude x3 and every phase moved by N(0, spread) (rad):
    (entries, K target, A target) of its own BEM sweep."""
    path, _ = surface_db
    entries = db.load_entries(path)
    g = Genome.from_dict(entries[1].genome)
    g = replace(g, A=3.0, phases=g.phases + np.random.default_rng(5).normal(0, spread,
                                                                          g.phases.shape))
    target = Design((DesignPart(g, tuple(range(g.n_first, g.n_last + 1)), 1.0, "t"),), 1.0, L,
                    32, "t", 2)
    c = Evaluator(SETTINGS)(target)
    return entries, Target(c.pressure, c.stiffness, "K", "tK", {}), \
        Target(c.pressure, c.area_fraction, "A", "tA", {})


def test_batched_surface_scores_equal_the_single_strict_scores(surface_db):
    """score_batch_at_target_pressures on periodic surfaces (batched Polonsky-Keer CG at
    the target pressures) gives the scores of the single load-controlled BEM
    (rescore_at_target_pressures) to the CG tolerance, for several different designs."""
    from roughfe.genomics.design import score_batch_at_target_pressures
    from roughfe.genomics.design.targets import batch_scoring

    entries, tk, ta = _perturbed_target(surface_db)
    assert batch_scoring(SETTINGS)
    rng = np.random.default_rng(3)
    designs = []
    for e in entries[:3]:
        d = Design((DesignPart(Genome.from_dict(e.genome), e.macro + e.micro, 1.0, e.label),),
                   1.0, L, 32, e.label, 2)
        keys = d.keys("all")
        designs.append(d.with_phases(keys, d.phase_values(keys) + rng.normal(0, 0.5, len(keys))))
    batch = score_batch_at_target_pressures(designs, [tk, ta], SETTINGS)
    single = np.array([rescore_at_target_pressures(d, [tk, ta], SETTINGS) for d in designs])
    assert np.ptp(single) > 0.05                       # the designs differ
    np.testing.assert_allclose(batch, single, rtol=0, atol=1e-8)


def test_global_stage_objective_moves_with_every_variable_and_not_with_its_symmetries(
        surface_db):
    """The global stage's variables on a split surface design (every phase and every
    chromosome amplitude, as search_global with amplitudes > 0) all reach the strict
    score: one step in any single variable changes it. It is flat only along the exact
    symmetries of the objective: one overall height factor (Eq. 4.2 rescales it out) and
    a translation by one node (every phase + 2 pi k / N, k the wave's lattice index)."""
    from roughfe.genomics.design import score_batch_at_target_pressures

    entries, tk, _ = _perturbed_target(surface_db)
    e = entries[2]
    d = Design((DesignPart(Genome.from_dict(e.genome), e.macro + e.micro, 1.0, e.label),),
               1.0, L, 32, e.label, 2).split_chromosomes()
    keys = d.keys("all") + [(k, "weight") for k in range(len(d.parts))]
    x0 = d.phase_values(keys)
    is_w = np.array([k[1] == "weight" for k in keys])
    step = np.where(is_w, x0 * (np.exp(0.05) - 1), 0.05)
    shift = np.concatenate([2 * np.pi * lattice_wavevectors(p.genome, p.chromosomes, L)[0][:, 0]
                            / 32 for p in d.parts] + [np.zeros(is_w.sum())])
    rows = [x0 + np.diag(step)[i] for i in range(len(keys))] + \
        [x0, np.where(is_w, 1.7 * x0, x0), x0 + shift]
    f = score_batch_at_target_pressures([d.with_phases(keys, x) for x in rows], [tk],
                                        SETTINGS)[:, 0]
    f0 = f[len(keys)]
    assert np.isfinite(f).all() and 0 < f0 < 1
    assert np.abs(f[:len(keys)] - f0).min() > 1e-6       # no frozen variable
    np.testing.assert_allclose(f[-2:], f0, rtol=0, atol=1e-8)   # CG tolerance


def test_global_search_of_a_surface_design_with_wave_amplitudes(surface_db):
    """search_global (IPOP-CMA-ES on batched strict scores) on a surface design, every
    wave's amplitude a variable: f at the target pressures never falls, the searched
    design is re-scored by one single BEM run (at_targets), which an independent run of
    its heights reproduces; an unknown amplitude kind is one clear error."""
    from roughfe.genomics.design import (GcmmaOptions, combined_score,
                                         score_at_target_pressures,
                                         search_at_target_pressures, search_global)

    entries, tk, ta = _perturbed_target(surface_db)
    res = run_design("mcco", entries, [tk, ta], SETTINGS,
                     options=GcmmaOptions(n_it_sog=0, n_it_cross=0, n_it_micro=0))
    out = search_global(res, SETTINGS, n_eval=40, amplitudes=0.5, waves=True, seed=1)
    f0 = max(combined_score(rescore_at_target_pressures(c.design, [tk, ta], SETTINGS))
             for c in res.candidates)
    best = out.best
    assert combined_score(best.at_targets) > f0      # 40 evaluations from a poor start
    # the searched design: one part per chromosome, its waves' factors moved on their own
    assert all(len(p.chromosomes) == 1 for p in best.design.parts)
    alphas = np.array([p.genome.anisotropy / p.genome.anisotropy[0] for p in best.design.parts])
    assert np.ptp(alphas, axis=0).max() > 1e-3
    again = score_at_target_pressures(best.design.surface(), [tk, ta], SETTINGS)
    np.testing.assert_allclose(again, best.at_targets, rtol=0, atol=1e-12)
    assert "wave amplitudes x exp(+-0.5)" in out.message
    with pytest.raises(InputError, match="waves=True needs amplitudes > 0"):
        search_global(res, SETTINGS, n_eval=4, waves=True)
    with pytest.raises(InputError, match="amplitudes must be one of"):
        search_at_target_pressures(res, SETTINGS, n_eval=4, amplitudes="ridge")


def test_global_search_with_the_modulation_variable(surface_db):
    """search_global with ``modulation`` > 0: one more variable, the depth of the short
    waves' modulation by the long-wave height; the searched design carries it (within
    +-0.5 of the start's 0), its strict score is reproduced by an independent BEM run of
    its heights and by its JSON read back."""
    from roughfe.genomics.design import (GcmmaOptions, combined_score,
                                         score_at_target_pressures, search_global)

    entries, tk, ta = _perturbed_target(surface_db)
    res = run_design("mcco", entries, [tk, ta], SETTINGS,
                     options=GcmmaOptions(n_it_sog=0, n_it_cross=0, n_it_micro=0))
    out = search_global(res, SETTINGS, n_eval=40, amplitudes=0.5, modulation=0.5, seed=1)
    f0 = max(combined_score(rescore_at_target_pressures(c.design, [tk, ta], SETTINGS))
             for c in res.candidates)
    best = out.best
    assert combined_score(best.at_targets) > f0
    assert 0 < abs(best.design.modulation) <= 0.5
    again = score_at_target_pressures(best.design.surface(), [tk, ta], SETTINGS)
    np.testing.assert_allclose(again, best.at_targets, rtol=0, atol=1e-12)
    read = Design.from_dict(best.design.to_dict())
    np.testing.assert_array_equal(read.surface().heights, best.design.surface().heights)
    assert "short-wave modulation +-0.5" in out.message
    with pytest.raises(InputError, match="modulation <= 2"):
        search_global(res, SETTINGS, n_eval=4, modulation=3.0)


def test_a_wave_at_the_nyquist_wavenumber_is_its_node_sampling():
    """Documented, not changed (roughfe.genomics.periodic): the periodic range keeps
    q_n = pi/delta, and a wave on the lattice vector (N/2, 0) is (-1)^i a cos(phi) on the
    nodes (amplitude a |cos phi|: rms 5e-24 m at phi = pi/2, not a/sqrt 2); every wave,
    on Nyquist-row vectors or not, is its exact node sampling."""
    L, N = 1e-3, 32
    g = Genome(A=1e-3, H=0.8, gamma=2.0, lambda1=L, phases=np.full((1, 6), np.pi / 2),
               angles=[0.0])
    assert periodic_chromosome_range(2.0, L, L, N) == (1, 5)      # q_5 = pi / delta
    assert np.std(periodic_heights(g, L, N, [5])) < 1e-20
    rng = np.random.default_rng(0)
    g = Genome(A=1e-3, H=0.8, gamma=2.0, lambda1=L, phases=rng.uniform(0, 2 * np.pi, (4, 6)),
               angles=[0.0, np.pi / 2, 0.3, 1.2], anisotropy=[1.0, 0.8, 1.1, 1 / 0.88])
    n = np.arange(1, 6)
    k, l_ = lattice_wavevectors(g, n, L)
    assert (16, 0) in zip(k[:, -1], l_[:, -1]) and (0, 16) in zip(k[:, -1], l_[:, -1])
    i, j = np.meshgrid(np.arange(N), np.arange(N), indexing="ij")
    a = g.wave_amplitude(n)[None, :] * g.anisotropy[:, None]
    phi = g.phase_columns(n)
    direct = sum(a[m, c] * (np.cos(phi[m, c]) - np.cos(2 * np.pi * (k[m, c] * i + l_[m, c] * j)
                                                         / N + phi[m, c]))
                 for m in range(4) for c in range(n.size))
    np.testing.assert_allclose(periodic_heights(g, L, N), direct, atol=1e-12 * np.abs(direct).max())
