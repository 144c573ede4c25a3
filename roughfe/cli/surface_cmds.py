"""``roughfe generate`` (rmd | wm | mwm | spectral) and ``roughfe info FILE``."""
from __future__ import annotations

import json

from ..surfaces.stats import surface_statistics
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


def register(sub):
    p = sub.add_parser("info", help="statistics of a surface file (table or JSON)",
                       description="Statistics of a profile or surface: rms height/slope/"
                                   "curvature, spectral moments, Nayak alpha, Hurst exponent.")
    add_surface_options(p)
    p.add_argument("--detrend", choices=("none", "mean", "plane"), default="mean",
                   help="remove the mean (default) or the best plane before the statistics")
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    p.set_defaults(func=_info)
