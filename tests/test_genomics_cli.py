"""`roughfe genome ...` end to end on small grids: files, figures, exit codes, clear errors."""
import json

import numpy as np
import pytest

from roughfe.cli import main
from roughfe.genomics.genome import load_genome
from roughfe.surfaces.io import load_surface


@pytest.mark.slow
def test_genome_commands_end_to_end(tmp_path, capsys):
    g = tmp_path / "g.json"
    assert main(["genome", "example", "-o", str(g), "--seed", "3"]) == 0
    for s in ("10x", "20x"):
        assert main(["genome", "realize", str(g), "--scale", s, "--nodes", "128",
                     "-o", str(tmp_path / f"{s}.npz")]) == 0
    z = load_surface(tmp_path / "10x.npz")
    # Z(0) = 0 at node N//2, to the round-off of the sums (roughfe.genomics.genome)
    assert z.shape == (128,) and abs(z.heights[64]) <= 1e-13 * np.abs(z.heights).max()
    seqdir = tmp_path / "seq"
    assert main(["genome", "sequence", str(tmp_path / "20x.npz"), str(tmp_path / "10x.npz"),
                 "-o", str(seqdir)]) == 0
    text = capsys.readouterr().out
    assert "gamma = 1.5" in text and "relative rms error" in text
    out = seqdir / "genome.json"
    seq = load_genome(out)
    assert abs(seq.gamma - 1.5) < 1e-9
    rep = json.loads((seqdir / "report.json").read_text())
    assert rep["success"] and max(rep["rms_errors"]) < 1e-9
    for fig in ("profiles", "psd", "td", "bu"):
        assert (seqdir / f"{fig}.png").stat().st_size > 10_000
    mech = tmp_path / "mech"
    assert main(["genome", "mechanics", str(out), "--nodes", "32", "--kernels", "strip",
                 "--steps", "5", "--max-chromosomes", "1", "-o", str(mech)]) == 0
    data = json.loads((mech / "mechanics_strip.json").read_text())
    assert np.isclose(data["c_td"]["K"][-1], 1.0)
    assert (mech / "correlations_strip.png").is_file()
    assert main(["genome", "validity", "--trials", "50", "-o", str(tmp_path / "v.png")]) == 0


def test_genome_cli_reports_bad_input(tmp_path, capsys):
    g = tmp_path / "g.json"
    main(["genome", "example", "-o", str(g)])
    main(["genome", "realize", str(g), "--scale", "10x", "--nodes", "128", "-o", str(tmp_path / "a.npz")])
    main(["genome", "realize", str(g), "--scale", "20x", "--nodes", "64", "-o", str(tmp_path / "b.npz")])
    assert main(["genome", "sequence", str(tmp_path / "a.npz"), str(tmp_path / "b.npz"),
                 "-o", str(tmp_path / "s")]) == 2
    assert "same number of nodes" in capsys.readouterr().err


@pytest.mark.parametrize("dim, n_nodes", [(1, 128), (2, 16)])
def test_parts_of_a_design_realise_their_share_by_default(tmp_path, dim, n_nodes):
    """genome_partK.json of a design of several genomes carries its chromosomes, the
    design's L, N and dimension: `genome realize` without options gives its share, and
    the shares sum to the design (a profile, or a periodic surface for dim 2). Before,
    every chromosome of the genome was realised (a relative error of 1.5-2.7 against the
    design) and a 2D part came out as a 1D profile."""
    from roughfe.genomics import database as db
    from roughfe.genomics.design.model import Design, DesignPart
    from roughfe.genomics.genome import save_genome
    from roughfe.surfaces.io import load_surface
    settings = db.DatabaseSettings(n_nodes=n_nodes, dim=dim)
    kw = {"angles": [0.3, 1.4]} if dim == 2 else {}
    g1 = db.make_genome(1.5, 0.8, 1, settings, **kw)
    g2 = db.make_genome(1.7, 0.6, 2, settings, **kw)
    n1 = sorted(int(n) for n in range(g1.n_first, g1.n_first + g1.phases.shape[1]))
    n2 = sorted(int(n) for n in range(g2.n_first, g2.n_first + g2.phases.shape[1]))
    design = Design((DesignPart(g1, tuple(n1[:2])), DesignPart(g2, tuple(n2[2:]), 0.7)),
                    scale=2.0, length=settings.length, n_nodes=n_nodes, dim=dim)
    total = 0.0
    for k in range(2):
        path = save_genome(design.part_genome(k), tmp_path / f"part{k + 1}.json")
        out = tmp_path / f"part{k + 1}.npz"
        assert main(["genome", "realize", str(path), "-o", str(out)]) == 0
        s = load_surface(out)
        assert s.ndim == dim and s.periodic == (dim == 2)
        total = total + s.heights
    ref = design.surface().heights
    np.testing.assert_allclose(total, ref, rtol=1e-12, atol=1e-12 * np.abs(ref).max())


def test_genome_mechanics_without_figures_does_not_say_it_wrote_figures(tmp_path, capsys):
    g = tmp_path / "g.json"
    assert main(["genome", "example", "-o", str(g), "--seed", "3"]) == 0
    capsys.readouterr()
    mech = tmp_path / "mech"
    assert main(["genome", "mechanics", str(g), "--nodes", "32", "--kernels", "strip",
                 "--steps", "3", "--max-chromosomes", "1", "--no-figures", "-o",
                 str(mech)]) == 0
    captured = capsys.readouterr()
    out = captured.out
    assert f"curves, c_n -> {mech}" in out and "figures" not in out
    assert not list(mech.glob("*.png"))
    # the Table 1 profile at 10x is steep (rms slope > 10) and swept beyond E*: said
    # (a user's review found 49 E* in silence)
    p_max = max(json.loads((mech / "mechanics_strip.json").read_text())["complete"]["pressure"])
    assert p_max > 2.1e8 and f"mean pressure up to {p_max:.3g} Pa" in captured.err


def test_realize_names_its_own_option_for_a_missing_chromosome(tmp_path, capsys):
    """`genome realize --chromosomes 30` on the Table 1 example (phases for n = 1..22)
    suggested `random_genome(n_max=...)`, a Python call. It names the command line's own
    option now, and that option does give the chromosome."""
    g = tmp_path / "g.json"
    assert main(["genome", "example", "-o", str(g)]) == 0
    out = tmp_path / "a.npz"
    args = ["genome", "realize", str(g), "--scale", "10x", "--nodes", "64",
            "--chromosomes", "3", "30", "-o", str(out)]
    capsys.readouterr()
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "--chromosomes 30:" in err and "n = 1..22 only" in err
    assert "`roughfe genome example --n-max 30 -o FILE`" in err
    assert "random_genome" not in err
    assert main(["genome", "example", "-o", str(g), "--n-max", "30", "--overwrite"]) == 0
    assert main(args) == 0 and out.is_file()


def test_genome_mechanics_refuses_a_surface_genome(tmp_path, capsys):
    """A genome with ridge angles ran `genome mechanics` on its Eq. 3.1 profile, which
    ignores the angles (a user's review); it is refused with the commands that do it."""
    from roughfe.genomics.genome import random_genome, save_genome
    g = save_genome(random_genome(1, .75, 1.5, 1e-3, 4, 22, rng=0, angles=[0, .5, 1, 2]),
                    tmp_path / "g2d.json")
    assert main(["genome", "mechanics", str(g), "--length", "1e-3", "--nodes", "32",
                 "--steps", "3", "-o", str(tmp_path / "m")]) == 2
    err = capsys.readouterr().err
    assert "is a surface genome (ridge angles)" in err and "genome chromosomes" in err
    assert not (tmp_path / "m").exists()


def test_a_band_limited_realisation_is_warned_of(tmp_path, capsys):
    """A genome holds chromosomes over a finite band (a sequenced one: the band of its
    data). Realised at a window whose Eq. 3.5 range reaches beyond it, the heights lack
    those waves: said on stderr (it was silent; a user's review), not when the window
    lies inside the band."""
    g = tmp_path / "g.json"
    assert main(["genome", "example", "-o", str(g), "--seed", "1", "--n-max", "10"]) == 0
    capsys.readouterr()
    assert main(["genome", "realize", str(g), "--scale", "10x", "--nodes", "128",
                 "-o", str(tmp_path / "a.npz")]) == 0
    err = capsys.readouterr().err
    assert "band-limited realisation" in err and "holds only 1..10" in err
    assert "chromosomes 11..12" in err          # Eq. 3.5 at L = lambda1, N = 128: 1..12
    z = load_surface(tmp_path / "a.npz")
    assert z.metadata["chromosomes"] == list(range(1, 11)) and z.metadata["n_f"] == 12
    assert main(["genome", "realize", str(g), "--scale", "10x", "--nodes", "32",
                 "-o", str(tmp_path / "b.npz")]) == 0
    assert "band-limited" not in capsys.readouterr().err
