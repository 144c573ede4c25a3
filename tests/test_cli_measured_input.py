"""What the commands say about the measured surface they read: a tilt left by the default
``--detrend mean``, filled undefined points, the channel of a multi-channel file."""
import re

import numpy as np
import pytest

from roughfe.cli import main
from roughfe.surfaces import Surface
from roughfe.surfaces.io import save_surface
from roughfe.surfaces.spectral import spectral_surface
from roughfe.surfaces.stats import rms_height


def _tilted(tmp_path, slope, periodic=False, name="tilted.npz"):
    rough = spectral_surface(32, 1e-4, 0.8, rms_height=1e-7, rng=5)
    x = np.arange(32) * rough.spacing[0]
    heights = rough.heights + slope * x[:, None]
    surface = Surface(heights, rough.size, periodic=periodic)
    return save_surface(surface, tmp_path / name), surface


def test_detrend_mean_on_a_tilted_window_warns_with_both_rms_heights(tmp_path, capsys):
    """plu-1 read with the default --detrend mean was a tilted plane without a word: rms
    2.834 um with the mean removed, 18.3 nm with the plane removed (the plane is 99.996 %
    of the variance); roughfe contact at 9.4 kPa gave A* 0.0069 instead of 0.037."""
    path, surface = _tilted(tmp_path, 0.02)
    assert main(["info", str(path)]) == 0
    err = capsys.readouterr().err
    assert err.count("warning: --detrend mean keeps the tilt") == 1 and "--detrend plane" in err
    shown = [float(v) for v in re.findall(r"rms height ([\d.e+-]+) m with the mean removed, "
                                          r"([\d.e+-]+) m with the plane removed", err)[0]]
    assert shown[0] == pytest.approx(rms_height(surface), rel=1e-3)
    assert shown[1] == pytest.approx(rms_height(surface.detrended("plane")), rel=1e-3)
    share = float(re.search(r"carries ([\d.]+) %", err).group(1)) / 100
    assert share == pytest.approx(1 - (shown[1] / shown[0]) ** 2, abs=1e-3) and share > 0.95
    # the same file with the plane removed, and a tilt that is not most of the variance
    assert main(["info", str(path), "--detrend", "plane"]) == 0
    assert "warning" not in capsys.readouterr().err
    small, _ = _tilted(tmp_path, 1e-4, name="small.npz")
    assert main(["info", str(small)]) == 0
    assert "warning" not in capsys.readouterr().err


def test_the_plane_of_a_self_affine_window_is_no_tilt(tmp_path, capsys):
    """The limit was half of the variance: the thesis' own Fig. 7 RMD surface (seed 0,
    59 %) and 47-88 % of RMD windows were told their results were "those of a tilted
    plane". On a self-affine window the plane is the longest roughness wavelength."""
    from roughfe.surfaces.rmd import rmd_surface
    s = rmd_surface(m=7, fractal_dimension=2.3, length=1e-4, rng=0)
    share = 1 - (rms_height(s.detrended("plane")) / rms_height(s)) ** 2
    assert 0.5 < share < 0.95
    path = save_surface(s, tmp_path / "rmd0.npz")
    assert main(["info", str(path)]) == 0
    assert "tilt" not in capsys.readouterr().err


def test_a_periodic_surface_has_no_tilt_to_warn_of(tmp_path, capsys):
    path, _ = _tilted(tmp_path, 0.02, periodic=True)
    assert main(["info", str(path)]) == 0
    assert "warning" not in capsys.readouterr().err


def test_contact_on_a_tilted_window_warns(tmp_path, capsys):
    path, _ = _tilted(tmp_path, 0.02)
    assert main(["contact", str(path), "--pressure", "1e5", "--no-figures", "-o",
                 str(tmp_path / "out")]) == 0
    assert capsys.readouterr().err.count("--detrend mean keeps the tilt") == 1


def test_detrend_lines_on_a_map_tilted_along_x_warns(tmp_path, capsys):
    """--detrend lines (round 2, session 34) levels each scan line's mean: a tilt along y
    goes, one along x stays, and the tilt warning spoke only for --detrend mean (plu-1
    with --detrend lines: its plane along x 99.996 % of the levelled map's variance, in
    silence)."""
    rough = spectral_surface(32, 1e-4, 0.8, rms_height=1e-7, rng=5)
    x = np.arange(32) * rough.spacing[0]
    for name, slope_x, slope_y in (("x.npz", 0.02, 0.0), ("xy.npz", 0.02, 0.03),
                                   ("y.npz", 0.0, 0.03)):
        surface = Surface(rough.heights + slope_x * x[:, None] + slope_y * x[None, :],
                          rough.size, periodic=False)
        path = save_surface(surface, tmp_path / name)
        assert main(["info", str(path), "--detrend", "lines"]) == 0
        err = capsys.readouterr().err
        if slope_x == 0:      # the lines' means took the tilt along y: nothing to say
            assert "tilt" not in err
            continue
        assert err.count("warning: --detrend lines keeps the tilt along x") == 1
        assert "--detrend lines-tilt" in err
        levelled = surface.detrended("lines")
        shown = [float(v) for v in re.findall(r"rms height ([\d.e+-]+) m with the lines "
                                              r"levelled, ([\d.e+-]+) m with the plane "
                                              r"removed too", err)[0]]
        assert shown[0] == pytest.approx(rms_height(levelled), rel=1e-3)
        assert shown[1] == pytest.approx(rms_height(levelled.detrended("plane")), rel=1e-3)
        # the plane left is the tilt along x alone: the same whatever the tilt along y
        window = Surface(rough.heights, rough.size, periodic=False)
        assert shown[1] == pytest.approx(rms_height(window.detrended("lines").detrended(
            "plane")), rel=1e-3)
        assert main(["info", str(path), "--detrend", "lines-tilt"]) == 0
        assert "warning" not in capsys.readouterr().err


def test_info_names_the_channel_read_and_the_filled_points(topographies_dir, capsys):
    """`info` said neither which of di-1's two 'Height' channels it read nor that opd-1
    had 116 undefined points filled (only --json's metadata did)."""
    di = topographies_dir / "di-1.di"
    assert main(["info", str(di), "--channel", "1", "--detrend", "plane"]) == 0
    out = capsys.readouterr().out
    assert "channel 1 'Height' (Retrace); the file has 4: 0 'Height' (Trace)" in out
    assert main(["info", str(di), "--channel", "Height"]) == 2
    err = capsys.readouterr().err
    assert "2 channels are named 'Height'" in err and "1 'Height' (Retrace)" in err
    assert main(["info", str(topographies_dir / "opd-1.opd")]) == 0
    out = capsys.readouterr().out
    assert "116 undefined points filled (harmonic interpolation)" in out
    assert "channel 0 'Raw'" in out and "the file has" not in out


def test_contact_and_leak_say_how_many_points_were_filled(tmp_path, capsys):
    rough = spectral_surface(32, 1e-4, 0.8, rms_height=1e-7, rng=5)
    filled = Surface(rough.heights, rough.size, periodic=True,
                     metadata={"filled_points": 7})
    path = save_surface(filled, tmp_path / "filled.npz")
    assert main(["contact", str(path), "--pressure", "1e5", "--no-figures", "-o",
                 str(tmp_path / "c")]) == 0
    assert "7 undefined points filled (harmonic interpolation)" in capsys.readouterr().out
    assert main(["leak", str(path), "--pressure", "1e6", "--no-figures", "-o",
                 str(tmp_path / "l")]) == 0
    assert "7 undefined points filled (harmonic interpolation)" in capsys.readouterr().out


# SurfaceTopography's XYZ reader divides by zero while it tests a 2 x 2 grid for regularity
@pytest.mark.filterwarnings("ignore:divide by zero:RuntimeWarning")
def test_a_file_without_unit_is_said_to_be_read_as_metres(tmp_path, capsys, topographies_dir):
    """An .xyz table gives no unit: its values are taken as metres, which only --json's
    metadata said ("m (assumed: the file gives no unit)") until round 2, session 25."""
    rough = spectral_surface(16, 1.6e-5, 0.8, rms_height=1e-7, rng=3)
    x = np.arange(16) * rough.spacing[0]
    X, Y = np.meshgrid(x, x, indexing="ij")
    path = tmp_path / "scan.xyz"
    np.savetxt(path, np.column_stack([X.ravel(), Y.ravel(), rough.heights.ravel()]))
    assert main(["info", str(path)]) == 0
    out = capsys.readouterr().out
    assert (f"{path}: the file gives no unit; heights and lengths taken as metres" in out
            and "rescale" in out and "--size" in out)
    assert main(["contact", str(path), "--pressure", "1e5", "--no-figures", "-o",
                 str(tmp_path / "c")]) == 0
    assert "the file gives no unit" in capsys.readouterr().out
    assert main(["info", str(topographies_dir / "x3p-2.x3p")]) == 0     # unit 'm' in file
    assert "gives no unit" not in capsys.readouterr().out


def test_contact_mirror_solves_the_mirrored_window(tmp_path, capsys):
    """``contact --mirror`` solves the evenly mirrored window as a periodic surface: the
    same records as the mirrored surface given directly, a pressure field with the
    window's mirror symmetry, no window compliance, and a stiffer K than the window's
    own (whose K includes the bulk compliance of a finite punch). A periodic surface is
    refused."""
    import h5py
    import json
    rough = spectral_surface(64, 1e-4, 0.8, rms_height=1e-7, rng=3)
    window = Surface(rough.heights[:33, :33], (33 * rough.spacing[0],) * 2, periodic=False)
    path = save_surface(window, tmp_path / "window.npz")
    mirrored = save_surface(window.mirrored(), tmp_path / "mirrored.npz")
    args = ["--E", "2e9", "--nu", "0.4", "--pressure", "2e6", "1e7", "--no-figures"]
    assert main(["contact", str(path), "--mirror", *args, "-o", str(tmp_path / "m")]) == 0
    assert main(["contact", str(mirrored), *args, "-o", str(tmp_path / "p")]) == 0
    assert main(["contact", str(path), *args, "-o", str(tmp_path / "w")]) == 0
    docs = {k: json.loads((tmp_path / k / "results.json").read_text()) for k in "mpw"}
    assert docs["m"]["inputs"]["mirror"] is True and docs["p"]["inputs"]["mirror"] is False
    assert docs["m"]["inputs"]["metadata"]["mirrored"] is True
    # the same surface up to its mean (--detrend mean acts before --mirror: the mirrored
    # window counts its interior twice), which the contact does not see
    for key in ("area_fraction", "stiffness", "mean_gap"):
        assert [s[key] for s in docs["m"]["steps"]] == pytest.approx(
            [s[key] for s in docs["p"]["steps"]], rel=1e-9, abs=0)
    assert "window_compliance" not in docs["m"]["derived"]
    assert docs["w"]["derived"]["window_compliance"] > 0
    with h5py.File(tmp_path / "m" / "fields.h5", "r") as f:
        p = f["pressure"][-1]
    assert p.shape == (64, 64)
    # even about the window's edges: p[i] = p[64 - i] along each axis
    back = np.roll(np.flip(p, axis=(0, 1)), 1, axis=(0, 1))
    assert np.max(np.abs(back - p)) <= 1e-8 * p.max()
    k_m = [s["stiffness"] for s in docs["m"]["steps"]]
    k_w = [s["stiffness"] for s in docs["w"]["steps"]]
    assert all(a > b for a, b in zip(k_m, k_w)), (k_m, k_w)
    out = capsys.readouterr().out
    assert out.count("--mirror: the fields and the load, contact area and contact count are "
                     "of the mirrored period") == 1
    assert main(["contact", str(mirrored), "--mirror", *args, "-o", str(tmp_path / "x")]) == 2
    assert "--mirror mirrors a non-periodic window" in capsys.readouterr().err


def test_heights_or_size_in_the_wrong_unit_are_warned(tmp_path, capsys, topographies_dir):
    """A plain matrix of heights in um read as metres (rms slope ~1e6) and a --size in nm
    given as if in metres were accepted without a word (a user's review): both are
    warned, once; the measured files themselves (rms slope up to 0.77) are not."""
    heights = np.random.default_rng(0).normal(size=(32, 32))         # "um", read as m
    path = tmp_path / "h_um.csv"
    np.savetxt(path, heights, delimiter=",")
    assert main(["info", str(path), "--size", "1e-4"]) == 0
    err = capsys.readouterr().err
    assert err.count("warning: rms slope") == 1 and "are the heights in metres" in err
    di = topographies_dir / "di-1.di"
    assert main(["info", str(di), "--size", "500"]) == 0
    err = capsys.readouterr().err
    assert "--size 500 x 500 m differs 1e+09x from the file's own size 5e-07 x 5e-07 m" in err
    assert main(["info", str(di), "--detrend", "lines"]) == 0   # no scan-line warning either
    err = capsys.readouterr().err      # (only the Hurst range above the trace/retrace
    assert [w for w in err.splitlines() if "warning" in w       # cutoff: session 36)
            and "where the trace and the retrace stop agreeing" not in w] == []


def test_the_slope_warning_judges_the_heights_the_command_uses(capsys, topographies_dir):
    """di-1's retrace channel is tilted (its plane carries 99.2 % of the variance): rms
    slope 1.06 as read, 0.72 with the plane removed. The slope warning judged the heights
    as read, so ``--detrend plane`` still warned of a slope of 1.06 its analysis did not
    have (session 36). Now the detrended heights are judged, and under ``--detrend mean``
    the warning says that the slope is the tilt's."""
    di = str(topographies_dir / "di-1.di")
    assert main(["info", di, "--channel", "1", "--detrend", "plane"]) == 0
    captured = capsys.readouterr()
    assert "warning: rms slope" not in captured.err
    assert "rms slope                    0.72" in captured.out
    assert main(["info", di, "--channel", "1"]) == 0          # --detrend mean: the tilt kept
    err = capsys.readouterr().err
    assert err.count("warning: rms slope 1.06 > 1") == 1
    assert "0.722 with its least-squares plane removed: the slope is the tilt's" in err


def test_an_option_of_another_command_is_named_by_the_command(tmp_path, capsys):
    """`roughfe leak ... --mirror` (an option of `contact`) was refused by the top parser,
    "roughfe: error: unrecognized arguments: --mirror (see `roughfe --help`)": now the
    command that did not know it says so and points at its own help."""
    assert main(["leak", str(tmp_path / "s.npz"), "--mirror", "--pressure", "1e6",
                 "-o", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err == ("roughfe leak: error: unrecognized arguments: --mirror (see `roughfe leak "
                   "--help`)\n")
    assert not (tmp_path / "o").exists()


def test_periodic_given_to_a_window_that_does_not_join_up_is_warned(tmp_path, capsys):
    # a 64^2 window cut from a 256^2 periodic surface (H = 0.8) jumps across its edges by
    # ~20x the neighbour step: --periodic makes that seam a ridge; the whole periodic
    # surface joins up (about 1x) and is not warned of
    whole = spectral_surface(256, 4e-4, 0.8, rms_height=1e-6, rng=2)
    window = Surface(whole.heights[:64, :64] - whole.heights[:64, :64].mean(), 1e-4,
                     periodic=False)
    small = spectral_surface(64, 1e-4, 0.8, rms_height=1e-6, rng=2)
    for name, surf, warned in (("window", window, True), ("periodic", small, False)):
        path = save_surface(surf, tmp_path / f"{name}.npz")
        capsys.readouterr()
        assert main(["contact", str(path), "--periodic", "--pressure", "1e5",
                     "--no-figures", "-o", str(tmp_path / name)]) == 0
        err = capsys.readouterr().err
        assert ("jump across the period's edges" in err) is warned, err
    # without --periodic the window is solved as what its file says: no seam
    path = tmp_path / "window.npz"
    assert main(["contact", str(path), "--pressure", "1e5", "--no-figures", "-o",
                 str(tmp_path / "w2")]) == 0
    assert "jump across" not in capsys.readouterr().err
