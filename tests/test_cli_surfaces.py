"""The surface subcommands: generate, info, demo (in-process through ``main``)."""
import json

import numpy as np
import pytest

from roughfe.cli import main
from roughfe.surfaces import load_surface
from roughfe.surfaces.stats import rms_height


def _nonblank(png):
    import matplotlib.image as mpimg
    img = mpimg.imread(png)
    return img.ndim == 3 and float(img[..., :3].std()) > 0.05


@pytest.mark.parametrize("model, extra", [
    ("rmd", ["--m", "5", "--D", "2.4"]),
    ("rmd", ["--m", "8", "--D", "1.4", "--profile"]),
    ("rmd", ["--m", "6", "--profile"]),        # a profile's default D (1.3), not 2.3's
    ("wm", ["--n", "512", "--hurst", "0.6"]),
    ("mwm", ["--n", "48", "--ridges", "4", "--rms-height", "2e-6"]),
    ("spectral", ["--n", "64", "--hurst", "0.7", "--rms-slope", "0.2"]),
])
def test_generate_writes_a_loadable_npz(tmp_path, model, extra):
    out = tmp_path / f"{model}.npz"
    assert main(["generate", model, *extra, "--seed", "11", "--no-figures", "-o", str(out)]) == 0
    s = load_surface(out)
    assert s.metadata["seed"] == 11 and rms_height(s) > 0
    if model == "mwm":
        assert rms_height(s) == pytest.approx(2e-6, rel=1e-12, abs=0)
    if model == "rmd" and "--profile" not in extra:
        assert s.shape == (33, 33)
    if extra == ["--m", "6", "--profile"]:
        assert s.ndim == 1 and s.metadata["fractal_dimension"] == pytest.approx(1.3)
    again = tmp_path / "again.npz"
    main(["generate", model, *extra, "--seed", "11", "--no-figures", "-o", str(again)])
    np.testing.assert_array_equal(load_surface(again).heights, s.heights)   # reproducible


def _regenerate(surface):
    """The surface that the library makes from ``surface``'s own metadata."""
    from roughfe.surfaces.wm import mwm_surface, wm_profile
    m = surface.metadata
    if m["generator"] == "wm":
        return wm_profile(surface.shape[0], surface.size[0], m["hurst"], gamma=m["gamma"],
                          amplitude=m["amplitude_A"], q0=m["q0"], k_range=m["k_range"],
                          rng=m["seed"])
    return mwm_surface(surface.shape[0], surface.size[0], m["hurst"], gamma=m["gamma"],
                       wavelength=m["wavelength"], n_range=m["n_range"], ridges=m["ridges"],
                       amplitude=m["amplitude_A"], anisotropy=m["anisotropy"],
                       angles=m["angles"], rng=m["seed"])


@pytest.mark.parametrize("model, extra", [
    ("wm", ["--n", "512"]),
    ("mwm", ["--n", "48", "--ridges", "4", "--anisotropy", "0.9", "1", "1.1", "1"]),
])
def test_rescaled_wm_metadata_regenerates_its_heights(tmp_path, model, extra):
    """--rms-height rescales the heights; Eq. (2.1) and (3.17) are linear in A, so the
    stored amplitude_A must be the effective one (it kept the A before the rescaling,
    a factor 17.6 off for wm --n 512 --seed 1 --rms-height 2e-6)."""
    out = tmp_path / f"{model}.npz"
    assert main(["generate", model, *extra, "--seed", "1", "--rms-height", "2e-6",
                 "--no-figures", "-o", str(out)]) == 0
    s = load_surface(out)
    assert rms_height(s) == pytest.approx(2e-6, rel=1e-12, abs=0)
    assert s.metadata["rms_height_target"] == 2e-6
    again = _regenerate(s)
    np.testing.assert_allclose(again.heights, s.heights, rtol=0,
                               atol=1e-12 * np.abs(s.heights).max())   # round-off of A * factor


def test_generate_png_and_info(tmp_path, capsys):
    out = tmp_path / "s.npz"
    assert main(["generate", "spectral", "--n", "32", "--seed", "1", "-o", str(out)]) == 0
    assert _nonblank(out.with_suffix(".png"))
    capsys.readouterr()
    assert main(["info", str(out), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["statistics"]["rms_height"] == pytest.approx(1e-6, rel=1e-9, abs=0)
    assert info["statistics"]["periodic"] is True
    # units of every dimensional number (none until round 2, session 28: m4 1e10 of what?)
    assert info["units"]["rms_height"] == "m" and info["units"]["m4"] == "1/m^2"
    assert set(info["statistics"]) - set(info["units"]) == {"ndim", "periodic", "hurst_success"}
    assert main(["info", str(out)]) == 0
    assert "rms height" in capsys.readouterr().out


def test_info_plain_matrix_needs_size(tmp_path, capsys):
    path = tmp_path / "h.npy"
    np.save(path, np.random.default_rng(0).standard_normal((16, 16)) * 1e-6)
    assert main(["info", str(path)]) == 2
    assert "size" in capsys.readouterr().err
    assert main(["info", str(path), "--size", "1e-4", "2e-4", "--periodic", "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["statistics"]["size"] == [1e-4, 2e-4] and info["statistics"]["periodic"]


def test_generate_rejects_bad_parameters(tmp_path, capsys):
    assert main(["generate", "rmd", "--D", "3.5", "-o", str(tmp_path / "x.npz")]) == 2
    assert "3.5" in capsys.readouterr().err
    assert not (tmp_path / "x.npz").exists()


def test_demo_writes_index_and_nonblank_figures(tmp_path):
    # only the surface section (later sections belong to other parts and their tests)
    from roughfe.cli.demo_cmd import SECTIONS, run_demo, section_surface
    assert SECTIONS[0] is section_surface
    run_demo(tmp_path, sections=(section_surface,))
    index = (tmp_path / "index.md").read_text()
    assert "RMD" in index and "rmd_render.png" in index
    for png in ("rmd_render.png", "rmd_psd.png"):
        assert _nonblank(tmp_path / png), png
    stats = json.loads((tmp_path / "rmd_statistics.json").read_text())
    assert stats["fractal_dimension"] == pytest.approx(2.3, abs=0.1)
    assert "Note on H" not in index           # one power law: no note beside H


def test_demo_table_notes_a_psd_that_is_not_one_power_law(topographies_dir):
    """The demo's statistics table says what `roughfe info` says when the fit range is
    not one power law (x3p-2, plane removed: H -0.92 below 8.8e5 rad/m, 0.94 above;
    round 2, session 32), and nothing on a self-affine surface."""
    from roughfe.cli.demo_cmd import _stats_table
    from roughfe.surfaces import load_surface, spectral_surface, surface_statistics
    s = spectral_surface(128, 1e-4, 0.8, rms_height=1e-6, rng=2)
    assert "Note on H" not in _stats_table(surface_statistics(s))
    measured = load_surface(topographies_dir / "x3p-2.x3p").detrended("plane")
    table = _stats_table(surface_statistics(measured))
    assert "Note on H: the PSD is not one power law" in table
    assert "--hurst-q-range" in table


def test_info_hurst_range_row_option_and_note(tmp_path, capsys):
    """info prints the fitted wavenumber range, takes --hurst-q-range (rad/m), prints the
    fit's note when the range is not one power law, and on a grid too small for the
    default range says why instead of an inverted range (round 2, session 32)."""
    out = tmp_path / "s.npz"
    assert main(["generate", "spectral", "--n", "64", "--seed", "1", "--no-figures",
                 "-o", str(out)]) == 0
    capsys.readouterr()
    assert main(["info", str(out), "--json", "--hurst-q-range", "2e5", "1e6"]) == 0
    stats = json.loads(capsys.readouterr().out)["statistics"]
    assert stats["hurst_q_range"] == pytest.approx([2e5, 1e6], rel=1e-12, abs=0)
    assert main(["info", str(out), "--hurst-q-range", "1e6", "2e5"]) == 2
    assert "--hurst-q-range" in capsys.readouterr().err
    assert main(["info", str(out)]) == 0
    row = next(line for line in capsys.readouterr().out.splitlines()
               if line.startswith("Hurst fit range"))
    low, high = (float(v) for v in row.split()[4:7:2])
    assert low < high and row.endswith("rad/um")
    small = tmp_path / "small.npz"
    main(["generate", "spectral", "--n", "16", "--seed", "1", "--no-figures", "-o", str(small)])
    capsys.readouterr()
    assert main(["info", str(small)]) == 0
    text = capsys.readouterr().out
    assert "grid too small" in text and "--hurst-q-range" in text
    assert "Hurst fit range q            n/a" in text


def test_info_notes_a_curved_psd(topographies_dir, capsys):
    assert main(["info", str(topographies_dir / "opd-1.opd"), "--detrend", "plane"]) == 0
    note = [line for line in capsys.readouterr().out.splitlines() if line.startswith("note:")]
    assert len(note) == 1 and "not one power law" in note[0] and "--hurst-q-range" in note[0]
