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
    assert z.shape == (128,) and z.heights[64] == 0.0
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
