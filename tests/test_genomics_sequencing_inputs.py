"""What each sequencer takes, and the InputError for everything else (round 2, session 32).

Profiles (1D, 2 or more nested windows) go to ``sequence_profiles``, square 2D windows of
equal spacings to ``sequence_surfaces``; periodic surfaces (a design's or database's
periodic realisation, Fourier-filtered surfaces) are neither. Every refusal names what
was given, what the sequencer takes and what to do instead (the other sequencer, the
central row of `genome natural`, the band chromosomes of `genome chromosomes`).
"""
import numpy as np
import pytest

from roughfe.errors import InputError
from roughfe.genomics.genome import realize, table1_genome
from roughfe.genomics.periodic import realize_periodic_surface
from roughfe.genomics.sequencing import sequence_profiles, sequence_surfaces
from roughfe.genomics.sequencing.surface_data import resolvable_surface_genome
from roughfe.surfaces.surface import Surface

N = 48
L1 = 1e-3


@pytest.fixture(scope="module")
def surface_case():
    g, acq, _ = resolvable_surface_genome(5, length=L1, n_nodes=N, n_ridges=3, gamma=1.8,
                                          hurst=0.8)
    return g, acq


@pytest.fixture(scope="module")
def profiles():
    g = table1_genome(rng=0)
    return [realize(g, scale=s, n_nodes=64) for s in ("10x", "20x")]


def test_the_profile_sequencer_refuses_surfaces_and_says_where_they_go(surface_case, profiles):
    _, acq = surface_case
    with pytest.raises(InputError) as e:
        sequence_profiles(acq)
    msg = str(e.value)
    assert f"acquisition 0 is a {N} x {N} surface (2D)" in msg          # what was given
    assert "profile sequencer takes profiles (1D) only" in msg          # what is taken
    assert "sequence_surfaces" in msg and "genome natural" in msg       # what to do
    with pytest.raises(InputError, match="a mix of profiles and surfaces"):
        sequence_profiles([profiles[0], acq[0]])


def test_the_surface_sequencer_refuses_profiles_and_says_where_they_go(surface_case,
                                                                        profiles):
    _, acq = surface_case
    for given in (profiles, [acq[0], profiles[0]]):
        with pytest.raises(InputError) as e:
            sequence_surfaces(given)
        msg = str(e.value)
        assert "is a profile (1D) of 64 nodes" in msg
        assert "surface sequencer takes 2D surfaces only" in msg
        assert "sequence_profiles" in msg


def test_one_profile_is_refused_with_the_two_ways_to_nested_windows(profiles):
    with pytest.raises(InputError) as e:
        sequence_profiles(profiles[:1])
    msg = str(e.value)
    assert "at least 2 nested acquisitions" in msg and "got 1" in msg
    assert "--scale 20x" in msg and "genome natural" in msg


def test_a_periodic_realisation_is_refused_before_any_fit(surface_case, profiles):
    """The periodic realisation of a surface genome (databases and designs, dim 2) rounds
    every wavevector onto the torus lattice: it is no Eq. 3.17 window. It used to be
    fitted for 3.6 s and reported as "not a WM surface" (exponent H = -0.27)."""
    g, _ = surface_case
    torus = realize_periodic_surface(g, L1, N)
    with pytest.raises(InputError) as e:
        sequence_surfaces([torus])
    msg = str(e.value)
    assert "acquisition 0 is periodic" in msg and "genome.json" in msg
    assert "periodic=False" in msg
    flagged = [Surface(p.heights, p.size, periodic=True, metadata=p.metadata)
               for p in profiles]
    with pytest.raises(InputError, match="acquisition 0 is periodic"):
        sequence_profiles(flagged)


def test_measured_grids_the_surface_sequencer_cannot_take(topographies_dir, tmp_path,
                                                            capsys):
    """sur-2 (563 x 484) is not square, x3p-2 (650 x 650) has unequal spacings: both are
    refused by `genome sequence` with the ways that do work on them."""
    from roughfe.cli import main
    for name, given in (("sur-2.sur", "got 563 x 484"), ("x3p-2.x3p", "has spacings")):
        assert main(["genome", "sequence", str(topographies_dir / name), "--no-figures",
                     "-o", str(tmp_path / name)]) == 2
        err = capsys.readouterr().err
        assert given in err and "genome natural" in err and "genome chromosomes" in err


def test_the_command_line_names_the_way_for_a_mix(surface_case, profiles, tmp_path, capsys):
    from roughfe.cli import main
    from roughfe.surfaces.io import save_surface
    _, acq = surface_case
    s = save_surface(acq[0], tmp_path / "s.npz")
    p = save_surface(profiles[0], tmp_path / "p.npz")
    assert main(["genome", "sequence", str(s), str(p), "-o", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "mix profiles (1D) and surfaces (2D)" in err
    assert "sequence them apart" in err and "sequence_surfaces" in err
    assert np.isfinite(acq[0].heights).all()
