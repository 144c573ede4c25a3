"""`genome natural` (roughfe.genomics.natural): a profile realised from a genome is
sequenced back (round 2, session 32), the line is chosen by --row/--axis, a time estimate
is printed first, and the warnings of every genome subcommand name it."""
from __future__ import annotations

import math

import numpy as np
import pytest

from roughfe.errors import InputError
from roughfe.genomics.chromosomes import reduced_chromosome
from roughfe.genomics.genome import realize, table1_genome
from roughfe.genomics.natural import measured_row, nested_acquisitions, sequence_measured
from roughfe.genomics.sequencing import variance_amplitude
from roughfe.surfaces.surface import Surface


@pytest.mark.parametrize("seed", [0, 1])
def test_a_realised_table1_profile_is_sequenced_back_by_the_natural_path(seed):
    """realise -> natural -> the genome. The box-filter resampling put the nodes between
    the samples over (N-1)/N of the row, interpolated the finer windows and left their
    long chromosomes out of the model: gamma 1.145, H 1.81, "an overfit" (seed 0)."""
    g = table1_genome(rng=seed)
    profile = realize(g, length=1e-3, n_nodes=256)
    res = sequence_measured(profile, n_nodes=256, kernels=())
    seq = res.sequencing
    assert res.success, res.message
    # every node is a sample of the profile: the windows hold its heights exactly, less
    # the row's least-squares line (and Z(0))
    for a in res.acquisitions:
        x = a.metadata["x0"] + np.arange(a.shape[0]) * a.spacing[0]
        k = np.round(x / profile.spacing[0]).astype(int) + 128
        d = a.heights - (profile.heights[k] - profile.heights[128])
        np.testing.assert_allclose(d, np.polyval(np.polyfit(x, d, 1), x), rtol=0,
                                   atol=1e-12 * np.abs(profile.heights).max())
    assert seq.genome.gamma == pytest.approx(g.gamma, rel=1e-9)
    assert seq.genome.lambda1 == pytest.approx(g.lambda1, rel=1e-9)
    assert np.all(seq.rms_errors < 1e-9)
    # the chromosomes are the genome's own (Eq. 3.7-3.8), the statistical genes within
    # three of their reported errors
    assert list(seq.n) == list(range(*np.add(g.chromosome_range(1e-3, 256), (0, 1))))
    true = reduced_chromosome(g, seq.n)[0] * g.gamma ** ((1.0 - seq.n) * g.H)
    np.testing.assert_allclose(seq.amplitudes, true, rtol=1e-7)
    assert abs(seq.genome.H - g.H) < 3 * seq.H_stderr
    assert abs(math.log(seq.genome.A / g.A)) < 3 * seq.lnA_stderr
    # the row's line is fitted back within its bound, far inside it (a WM row)
    assert "at its bound" not in res.message
    # A0 (Eq. 3.13) of the coarsest window as given, the yardstick of the misfits; it was
    # taken of the heights less the fitted tilt, i.e. with the row's line put back, which
    # is no data (round 2, session 33)
    n0 = np.arange(seq.ranges[0][0], seq.ranges[0][1] + 1)
    given = variance_amplitude(res.acquisitions[0].heights, n0, seq.genome.gamma,
                               seq.genome.lambda1, seq.genome.H)
    assert seq.A0 == pytest.approx(given, rel=1e-12, abs=0)
    assert seq.A0 < variance_amplitude(seq.heights[0], n0, seq.genome.gamma,
                                       seq.genome.lambda1, seq.genome.H)


def test_the_row_and_axis_pick_the_line():
    h = np.arange(6 * 5, dtype=float).reshape(6, 5) ** 1.5
    s = Surface(h, (6e-3, 5e-3), periodic=False)
    np.testing.assert_array_equal(measured_row(s)[1], h[:, 2])                 # central, x
    np.testing.assert_array_equal(measured_row(s, 4)[1], h[:, 4])
    np.testing.assert_array_equal(measured_row(s, 1, "y")[1], h[1, :])
    assert np.diff(measured_row(s, axis="y")[0])[0] == pytest.approx(1e-3)      # y spacing
    for row, axis in ((5, "x"), (6, "y"), (-1, "x"), (1, "z")):
        with pytest.raises(InputError, match="row|axis"):
            measured_row(s, row, axis)
    with pytest.raises(InputError, match="profile"):
        measured_row(Surface(h[:, 0], 6e-3, periodic=False), 1)
    g = table1_genome(rng=0)
    rows = np.stack([realize(g, length=1e-3, n_nodes=64).heights * (k + 1) for k in range(3)])
    grid = Surface(rows, (3e-3, 64e-3 / 63), periodic=False)
    a = nested_acquisitions(grid, n_nodes=64, row=2, axis="y")[0]
    assert a.metadata["row"] == 2 and a.metadata["axis"] == "y"
    np.testing.assert_allclose(a.heights[-1] / nested_acquisitions(grid, n_nodes=64, row=0,
                                                                   axis="y")[0].heights[-1], 3.0)


def test_genome_natural_options_and_time_estimate(tmp_path, capsys):
    from roughfe.cli import main
    from roughfe.surfaces.io import save_surface
    g = table1_genome(rng=0)
    save_surface(realize(g, length=1e-3, n_nodes=256), tmp_path / "p.npz")
    grid = Surface(np.random.default_rng(0).standard_normal((40, 30)) * 1e-6, 1e-3,
                   periodic=False)
    save_surface(grid, tmp_path / "s.npz")
    base = ["genome", "natural", "--kernels", "--no-figures"]
    assert main(base + [str(tmp_path / "p.npz"), "--nodes", "256", "-o",
                        str(tmp_path / "a")]) == 0
    out = capsys.readouterr().out
    # the estimate comes before the run's report, the realised profile is sequenced back
    assert out.index("the lattice fit takes up to ~") < out.index("sequenced genome:")
    assert "gamma = 1.5 " in out and "success" in out
    assert main(base + [str(tmp_path / "p.npz"), "--row", "1", "-o", str(tmp_path / "b")]) == 2
    assert "profile" in capsys.readouterr().err
    assert main(base + [str(tmp_path / "s.npz"), "--row", "30", "-o", str(tmp_path / "c")]) == 2
    err = capsys.readouterr().err
    assert "--row 30" in err and "0..29" in err
    assert main(base + [str(tmp_path / "s.npz"), "--axis", "y", "--row", "40", "-o",
                        str(tmp_path / "d")]) == 2
    assert "0..39" in capsys.readouterr().err
    assert not (tmp_path / "c").exists() and not (tmp_path / "d").exists()


def test_warnings_name_the_genome_subcommand(tmp_path, capsys):
    """`genome chromosomes` warned as "roughfe genome: warning" (options.warn named
    args.command only); other commands keep their own name."""
    from roughfe.cli import main
    from roughfe.surfaces.io import save_surface
    s = Surface(np.random.default_rng(1).standard_normal((32, 32)) * 1e-6, 1e-3,
                periodic=False)
    save_surface(s, tmp_path / "s.npz")
    assert main(["genome", "chromosomes", str(tmp_path / "s.npz"), "--steps", "3",
                 "--no-figures", "--quiet", "-o", str(tmp_path / "o")]) in (0, 1)
    err = capsys.readouterr().err
    assert "roughfe genome chromosomes: warning:" in err
    assert "roughfe genome: warning" not in err
    tilted = s.with_heights(s.heights + np.linspace(0, 1e-4, 32)[:, None])   # warns: a tilt
    save_surface(tilted, tmp_path / "t.npz")
    assert main(["info", str(tmp_path / "t.npz")]) == 0
    assert "roughfe info: warning:" in capsys.readouterr().err


@pytest.mark.parametrize("seed", [1, 3])
def test_windows_at_a_stride_hold_the_rows_short_chromosomes(seed):
    """A Table 1 row of 256 samples sequenced with 128 nodes: the full window is sampled
    at stride 3 (85 nodes) and holds the row's chromosomes shorter than 3 spacings aliased
    on its nodes. Modelled to its own Eq. 3.5 range they were misfit (seed 1: 5.5 %, 'not
    WM-like'); every window now goes to the row's finest chromosome: exact."""
    g = table1_genome(rng=seed)
    profile = realize(g, length=1e-3, n_nodes=256)
    res = sequence_measured(profile, n_nodes=128, kernels=())
    assert res.acquisitions[0].metadata["stride"] > 1
    assert res.success, res.message
    assert np.all(res.sequencing.rms_errors < 1e-9)
    assert res.sequencing.genome.gamma == pytest.approx(g.gamma, rel=1e-9)
