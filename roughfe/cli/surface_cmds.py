"""``roughfe generate`` (rmd | wm | mwm | spectral) and ``roughfe info FILE``."""
from __future__ import annotations

import json
from pathlib import Path

from ..errors import InputError
from ..surfaces.io import save_surface
from ..surfaces.rmd import rmd_profile, rmd_surface
from ..surfaces.spectral import spectral_profile, spectral_surface
from ..surfaces.stats import rms_height, surface_statistics
from ..surfaces.wm import mwm_surface, wm_profile
from .common import add_surface_options, surface_from_args

# (key, label, unit, scale) rows of the info table
_TABLE = (
    ("shape", "grid points", "", None),
    ("size", "physical size", "um", 1e6),
    ("periodic", "periodic", "", None),
    ("rms_height", "rms height Sq/Rq", "um", 1e6),
    ("peak_to_valley", "peak-to-valley", "um", 1e6),
    ("rms_slope", "rms slope", "-", 1.0),
    ("rms_curvature", "rms curvature", "1/um", 1e-6),
    ("skewness", "skewness", "-", 1.0),
    ("kurtosis", "kurtosis", "-", 1.0),
    ("m0", "spectral moment m0", "um^2", 1e12),
    ("m2", "spectral moment m2", "-", 1.0),
    ("m4", "spectral moment m4", "1/um^2", 1e-12),
    ("nayak_alpha", "Nayak bandwidth alpha", "-", 1.0),
    ("hurst", "Hurst exponent (PSD fit)", "-", 1.0),
    ("fractal_dimension", "fractal dimension D", "-", 1.0),
)


def format_table(stats: dict) -> str:
    """Plain-text table of a ``SurfaceStatistics.as_dict()``."""
    lines = []
    for key, label, unit, scale in _TABLE:
        v = stats[key]
        if key in ("hurst", "fractal_dimension") and not stats["hurst_success"]:
            if v is None:
                lines.append(f"{label:<28s} n/a (too few PSD points to fit)")
                continue
            lines.append(f"{label:<28s} n/a (PSD fit gives H = {stats['hurst']:.3g}, "
                         f"outside (0, 1))")
            continue
        if v is None:
            text = "n/a"
        elif scale is None:
            text = " x ".join(str(x) for x in v) if isinstance(v, list) else str(v)
        elif isinstance(v, list):
            text = " x ".join(f"{x * scale:.6g}" for x in v)
        else:
            text = f"{v * scale:.6g}"
        lines.append(f"{label:<28s} {text} {unit}".rstrip())
    return "\n".join(lines)


def _info(args) -> int:
    surface = surface_from_args(args)
    if args.detrend != "none":
        surface = surface.detrended(args.detrend)
    stats = surface_statistics(surface).as_dict()
    if args.json:
        print(json.dumps({"file": str(args.surface), "statistics": stats,
                          "metadata": dict(surface.metadata)}, indent=2))
    else:
        print(f"{args.surface}: {surface!r}")
        print(format_table(stats))
    return 0


# -- generate --------------------------------------------------------------------------
def _make_rmd(a):
    if a.profile:
        return rmd_profile(a.m, a.D, a.length, rng=a.seed, rms_height=a.rms_height)
    return rmd_surface(a.m, a.D, a.length, rng=a.seed, rms_height=a.rms_height)


def _make_wm(a):
    k_range = None if a.k_range is None else tuple(a.k_range)
    return wm_profile(a.n, a.length, a.hurst, gamma=a.gamma, amplitude=a.amplitude,
                      k_range=k_range, rng=a.seed)


def _make_mwm(a):
    n_range = None if a.n_range is None else tuple(a.n_range)
    return mwm_surface(a.n, a.length, a.hurst, gamma=a.gamma, wavelength=a.wavelength,
                       n_range=n_range, ridges=a.ridges, amplitude=a.amplitude,
                       anisotropy=a.anisotropy, angles="random" if a.random_angles else None,
                       rng=a.seed)


def _make_spectral(a):
    make = spectral_profile if a.profile else spectral_surface
    rms_h = a.rms_height if (a.rms_height is not None or a.rms_slope is not None) else 1e-6
    return make(a.n, a.length, a.hurst, rms_height=rms_h,
                rms_slope=a.rms_slope, q_long=a.q_long, q_roll=a.q_roll, q_short=a.q_short,
                amplitudes="fixed" if a.fixed_amplitudes else "gaussian", rng=a.seed)


def _generate(args) -> int:
    surface = args.make(args)
    if args.rms_height is not None and args.model in ("wm", "mwm"):
        surface = surface.scaled(args.rms_height / rms_height(surface))
    out = Path(args.output)
    if out.suffix.lower() != ".npz":
        raise InputError(f"-o/--output must name a .npz file, got {str(out)!r}")
    save_surface(surface, out)
    print(f"wrote {out}: {surface!r}, rms height {rms_height(surface) * 1e6:.4g} um, "
          f"seed {surface.metadata.get('seed')}")
    if not args.no_png:
        from ..plotting.surfaces import plot_profile, render_surface
        png = out.with_suffix(".png")
        kind = "surface" if surface.ndim == 2 else "profile"
        title = f"{args.model} {kind}, seed {surface.metadata.get('seed')}"
        (render_surface if surface.ndim == 2 else plot_profile)(surface, png, title=title)
        print(f"wrote {png}")
    return 0


def _register_generate(sub):
    p = sub.add_parser("generate", help="generate a rough surface or profile (.npz + PNG)",
                       description="Generate a seeded rough surface/profile and save it as "
                                   "roughfe .npz (and a PNG beside it). Lengths in metres.")
    models = p.add_subparsers(dest="model", metavar="MODEL")
    models.required = True

    def common(q, help_, make):
        m = models.add_parser(q, help=help_, description=help_)
        m.add_argument("-o", "--output", required=True, help="output .npz file")
        m.add_argument("--seed", type=int, default=None,
                       help="random seed (default: fresh, recorded in the file)")
        m.add_argument("--rms-height", type=float, default=None,
                       help="rescale to this rms height (m)")
        m.add_argument("--no-png", action="store_true", help="do not write the PNG")
        m.set_defaults(func=_generate, make=make)
        return m

    m = common("rmd", "Random Midpoint Displacement surface (thesis Sec. 2.1.1), (2^m+1)^2 grid",
               _make_rmd)
    m.add_argument("--m", type=int, default=7, help="refinement levels (default 7)")
    m.add_argument("--D", type=float, default=2.3,
                   help="fractal dimension, (2,3) surface / (1,2) profile (default 2.3)")
    m.add_argument("--length", type=float, default=1e-4,
                   help="thesis L end to end (m), default 1e-4; size = (2^m+1) L / 2^m")
    m.add_argument("--profile", action="store_true", help="a 1D profile instead of a surface")

    m = common("wm", "Weierstrass-Mandelbrot profile (thesis Eq. 2.1)", _make_wm)
    m.add_argument("--n", type=int, default=2048, help="number of points (default 2048)")
    m.add_argument("--length", type=float, default=1e-3, help="profile length (m), default 1e-3")
    m.add_argument("--hurst", type=float, default=0.7, help="Hurst exponent in (0,1)")
    m.add_argument("--gamma", type=float, default=1.5, help="frequency density > 1")
    m.add_argument("--amplitude", type=float, default=1e-7, help="A (m)")
    m.add_argument("--k-range", type=int, nargs=2, metavar=("K1", "K2"), default=None,
                   help="truncation k1 k2 (default: profile length to Nyquist)")

    m = common("mwm", "multivariate WM surface (thesis Eq. 2.2 / 3.17)", _make_mwm)
    m.add_argument("--n", type=int, default=256, help="grid points per side (default 256)")
    m.add_argument("--length", type=float, default=1e-4, help="side (m), default 1e-4")
    m.add_argument("--hurst", type=float, default=0.7, help="Hurst exponent in (0,1)")
    m.add_argument("--gamma", type=float, default=1.5, help="frequency density > 1")
    m.add_argument("--wavelength", type=float, default=None, help="lambda (m), default L")
    m.add_argument("--n-range", type=int, nargs=2, metavar=("NS", "NF"), default=None,
                   help="frequency indices n_s n_f (default: 1 to Nyquist)")
    m.add_argument("--ridges", type=int, default=10, help="number of ridges M")
    m.add_argument("--amplitude", type=float, default=1e-6, help="A of Eq. 3.17 (m^(1-H))")
    m.add_argument("--anisotropy", type=float, nargs="+", default=None,
                   help="M factors a_m (default all 1)")
    m.add_argument("--random-angles", action="store_true",
                   help="random ridge angles (default pi m / M)")

    m = common("spectral", "periodic self-affine surface by Fourier filtering", _make_spectral)
    m.add_argument("--n", type=int, default=256, help="grid points per side (default 256)")
    m.add_argument("--length", type=float, default=1e-4, help="period (m), default 1e-4")
    m.add_argument("--hurst", type=float, default=0.8, help="Hurst exponent in (0,1)")
    m.add_argument("--rms-slope", type=float, default=None,
                   help="target rms slope instead of rms height (1 um if neither)")
    m.add_argument("--q-long", type=float, default=None, help="q_l cut-off (rad/m)")
    m.add_argument("--q-roll", type=float, default=None, help="roll-off q_r (rad/m)")
    m.add_argument("--q-short", type=float, default=None, help="q_s cut-off (rad/m)")
    m.add_argument("--fixed-amplitudes", action="store_true",
                   help="random phases only (PSD exactly the target)")
    m.add_argument("--profile", action="store_true", help="a 1D profile instead of a surface")


def register(sub):
    _register_generate(sub)
    p = sub.add_parser("info", help="statistics of a surface file (table or JSON)",
                       description="Statistics of a profile or surface: rms height/slope/"
                                   "curvature, spectral moments, Nayak alpha, Hurst exponent.")
    add_surface_options(p)
    p.add_argument("--detrend", choices=("none", "mean", "plane"), default="mean",
                   help="remove the mean (default) or the best plane before the statistics")
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    p.set_defaults(func=_info)
