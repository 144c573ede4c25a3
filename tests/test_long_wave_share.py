"""The share of a ``design --match-spectrum`` surface's mean square at wavelengths longer
than the database length L (:func:`roughfe.genomics.design.long_wave_share`), which the
designs (periodic of period L) cannot hold, and the warning of ``design`` above
:data:`roughfe.cli.plausibility.LONG_WAVE_SHARE_LIMIT` (round 2, session 37)."""
import math

import numpy as np
import pytest

from roughfe.cli import main
from roughfe.cli.plausibility import LONG_WAVE_SHARE_LIMIT
from roughfe.errors import InputError
from roughfe.genomics import database as db
from roughfe.genomics import design as de
from roughfe.genomics.design import long_wave_share
from roughfe.surfaces import Surface, save_surface, spectral_surface
from roughfe.surfaces.stats import power_spectrum

L = 1e-4            # the database length (m)
N = 16              # the database's nodes: spacing L / N


def _short_waves(rms=1e-8, seed=4):
    """Periodic roughness on a box of 2 L (2 N points, the database spacing) with no mode
    of wavelength above L (q_long = 2 pi / L): share 0."""
    return spectral_surface(2 * N, 2 * L, 0.7, rms_height=rms, q_long=2 * np.pi / L,
                            q_roll=2 * np.pi / L, rng=seed)


def _plus_wave(surface, amplitude, waves=(1, 0)):
    """``surface`` plus ``amplitude cos(2 pi (i x + j y) / (2 L))`` (wavevector (i, j)
    in units of the box's fundamental pi / L)."""
    x, y = (np.arange(n) * d for n, d in zip(surface.shape, surface.spacing))
    i, j = waves
    wave = amplitude * np.cos(np.pi * (i * x[:, None] + j * y[None, :]) / L)
    return surface.with_heights(surface.heights + wave)


def _analytic(surface, amplitude):
    """(a^2 / 2) / (a^2 / 2 + <h^2>): the cosine's mean square over the total; the
    short-wave roughness is mean-free and orthogonal to it."""
    ms = float(np.mean((surface.heights - surface.heights.mean()) ** 2))
    return 0.5 * amplitude ** 2 / (0.5 * amplitude ** 2 + ms)


def test_a_wave_of_2L_on_short_waves_carries_its_analytic_share():
    short = _short_waves()
    assert long_wave_share(short, L) < 1e-20          # round-off of the FFT
    for a in (3e-9, 1e-8, 3e-8):
        s = _plus_wave(short, a)
        assert long_wave_share(s, L) == pytest.approx(_analytic(short, a), rel=1e-12, abs=0)
    # the diagonal wave (1, 1) has wavelength sqrt(2) L > L: counted too
    assert long_wave_share(_plus_wave(short, 1e-8, (1, 1)), L) == \
        pytest.approx(_analytic(short, 1e-8), rel=1e-12, abs=0)
    # a wave of wavelength L itself (2, 0) or shorter the designs hold: not counted
    for waves in ((2, 0), (0, 2), (2, 1)):
        assert long_wave_share(_plus_wave(short, 1e-8, waves), L) < 1e-20


def test_the_share_agrees_with_the_radial_psd():
    """Independent code: on a square box of 2 L the first annulus of power_spectrum
    (width pi / L) holds exactly the modes of |q| / (pi / L) = 1 and sqrt(2), the
    wavelengths 2 L and sqrt(2) L; Parseval: sum C weight is the mean square."""
    s = _plus_wave(_short_waves(rms=2e-8, seed=9), 1.5e-8, (1, 1))
    s = s.with_heights(s.heights + 0.3 * _short_waves(rms=1e-8, seed=2).heights[::-1])
    psd = power_spectrum(s)
    first = psd.q < 2 * np.pi / L * 0.99
    assert first.sum() == 1
    assert long_wave_share(s, L) == pytest.approx(
        float(np.sum((psd.C * psd.weight)[first])) / psd.mean_square, rel=1e-10, abs=0)


def test_bad_input_is_refused_and_a_flat_surface_has_no_share():
    s = _plus_wave(_short_waves(), 1e-8)
    window = Surface(s.heights, s.size, periodic=False)
    with pytest.raises(InputError, match="periodic target surface"):
        long_wave_share(window, L)
    for bad in (0.0, -L, math.nan, math.inf):
        with pytest.raises(InputError, match="length"):
            long_wave_share(s, bad)
    assert math.isnan(long_wave_share(s.with_heights(np.full(s.shape, 2e-8)), L))


def _run_design(tmp_path, capsys, monkeypatch, surface,
                expect="stopped before the design (test)"):
    """``design --match-spectrum`` on ``surface`` (a .npz) up to the design: the database
    holds only its settings (no genome is read) and run_design stops the command."""
    from roughfe.genomics.database.store import connect, write_settings
    from roughfe.genomics.similarity import Target
    from roughfe.genomics.target_csv import write_target_csv
    path = tmp_path / "s.sqlite"
    con = connect(path, create=True)
    write_settings(con, db.DatabaseSettings(length=L, n_nodes=N, dim=2, top_fraction=0.8))
    con.commit()
    con.close()
    write_target_csv(tmp_path / "t.csv", Target([1e3, 2e3, 4e3], [1e9, 2e9, 3e9], "K", "t"))
    save_surface(surface, tmp_path / "f.npz")
    monkeypatch.setattr(db, "load_entries", lambda *a, **k: [])

    def stop(*a, **k):
        raise InputError("stopped before the design (test)")
    monkeypatch.setattr(de, "run_design", stop)
    assert main(["design", "--db", str(path), "--target", str(tmp_path / "t.csv"),
                 "--method", "sog", "--match-spectrum", str(tmp_path / "f.npz"),
                 "--no-figures", "-o", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert expect in err
    return err


def test_design_warns_of_a_file_whose_long_waves_the_designs_cannot_hold(tmp_path, capsys,
                                                                         monkeypatch):
    """A periodic file of 2 L (on the database spacing: prepared as it is): a cosine of
    wavelength 2 L carrying 20 % of the mean square warns, naming the share and L; the
    short-wave roughness alone (share 0) does not. Fails on the code before session 37
    (no warning)."""
    short = _short_waves()
    a = math.sqrt(2 * 0.25 * float(np.mean(short.heights ** 2)))     # 20 % of the total
    assert _analytic(short, a) == pytest.approx(0.2, rel=1e-12, abs=0)
    assert 0.2 > LONG_WAVE_SHARE_LIMIT
    err = _run_design(tmp_path, capsys, monkeypatch, _plus_wave(short, a))
    assert "warning: --match-spectrum: 20 % of the file's mean square" in err
    assert f"longer than the database length L = {L:.4g} m" in err
    assert f"A database of length {2 * L:.4g} m (db build --length" in err
    err = _run_design(tmp_path, capsys, monkeypatch, short)
    assert "--match-spectrum:" not in err and "warning" not in err


def test_design_onto_a_database_too_fine_for_the_file_is_refused_at_once(tmp_path, capsys,
                                                                         monkeypatch):
    """A file of 2 L on a database of spacing L / N with L 1e5 times smaller than the
    file: resampling onto it would need ~(2e5 N)^2 points; the command says so in one
    line and exits 2 instead of allocating (it hung towards ~80 GB with x3p-2 on a 7.8 nm
    database; round 2, session 37)."""
    big = _short_waves()
    big = Surface(big.heights, tuple(1e5 * s for s in big.size), periodic=True)
    err = _run_design(tmp_path, capsys, monkeypatch, big, expect="resampling a 32 x 32 grid")
    assert "GiB of memory" in err and "Traceback" not in err
