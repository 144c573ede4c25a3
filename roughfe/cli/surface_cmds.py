"""``roughfe generate`` (rmd | wm | mwm | spectral) and ``roughfe info FILE``."""
from __future__ import annotations

import numpy as np

from ..errors import InputError, check_memory
from .options import (add_detrend_option, add_output_file, add_run_options,
                      add_surface_options, nonnegative_int, output_file_of, positive_float,
                      positive_int, print_surface_notes, surface_file)

# (key, label, unit, scale) rows of the info table
_TABLE = (
    ("shape", "grid points", "", None),
    ("size", "physical size", "um", 1e6),
    ("periodic", "periodic", "", None),
    ("rms_height", "rms height Sq/Rq", "um", 1e6),
    ("peak_to_valley", "peak-to-valley", "um", 1e6),
    ("rms_slope", "rms slope", "-", 1.0),
    ("rms_slope_iso", "rms slope Sdq/Rdq (ISO 7-pt)", "-", 1.0),
    ("rms_curvature", "rms curvature", "1/um", 1e-6),
    ("skewness", "skewness", "-", 1.0),
    ("kurtosis", "kurtosis", "-", 1.0),
    ("m0", "spectral moment m0", "um^2", 1e12),
    ("m2", "spectral moment m2", "-", 1.0),
    ("m4", "spectral moment m4", "1/um^2", 1e-12),
    ("nayak_alpha", "Nayak bandwidth alpha", "-", 1.0),
    ("hurst", "Hurst exponent (PSD fit)", "- (+- its standard error)", 1.0),
    ("fractal_dimension", "fractal dimension D", "-", 1.0),
    ("hurst_q_range", "Hurst fit range q", "rad/um", 1e-6),
)


#: SI units of the statistics in ``info --json`` ("1": dimensionless)
STATISTICS_UNITS = {"shape": "points", "size": "m", "mean": "m", "rms_height": "m",
                    "rms_slope": "1", "rms_slope_iso": "1", "rms_curvature": "1/m", "peak_to_valley": "m",
                    "skewness": "1", "kurtosis": "1", "m0": "m^2", "m2": "1", "m4": "1/m^2",
                    "nayak_alpha": "1", "hurst": "1 (meaningful when hurst_success)",
                    "fractal_dimension": "1 (meaningful when hurst_success)",
                    "hurst_q_range": "rad/m", "hurst_message": "text",
                    "hurst_error": "1 (standard error of hurst, Gaussian surface)"}


#: SI units of the ``scan_lines`` block of ``info --json``
SCAN_LINE_UNITS = {"ratio": "1", "threshold": "1", "line_jump": "m", "rms_height": "m"}


def scan_line_block(surface):
    """``info``'s ``scan_lines``: :func:`roughfe.surfaces.scan_lines.scan_line_check` of the
    heights the statistics describe (after ``--detrend``: the same R under none, mean and
    plane, about 0 after lines), as ``ratio``, ``threshold``, ``fires``, ``line_jump``,
    ``rms_height`` and ``axis`` (``"x"`` or ``"y"``, ``--scan-axis``) with their
    ``units``; None where the check does not apply (a profile, fewer than 3 lines)."""
    from dataclasses import asdict

    from ..surfaces.scan_lines import scan_line_check
    check = scan_line_check(surface)
    return None if check is None else {**asdict(check), "units": dict(SCAN_LINE_UNITS)}


def scan_line_row(block, mirrored: bool = False) -> str:
    """The table row of :func:`scan_line_block` (``""`` when it is None). Where the check
    fires it advises ``--detrend lines``, or, when the map as read is a ``mirrored``
    window (:func:`roughfe.surfaces.scan_lines.is_mirrored`), to level the measured window
    before mirroring: the advice of the stderr warnings
    (:func:`roughfe.cli.surface_warnings.warn_scan_lines`, ``warn_mirrored_lines``);
    the row said ``--detrend lines`` there too until round 2, session 36."""
    if block is None:
        return ""
    advice = ("a mirrored window: level the measured window before mirroring" if mirrored
              else "--detrend lines")
    verdict = (f"> {block['threshold']:.3g}: the scan lines look offset ({advice})"
               if block["fires"] else f"<= {block['threshold']:.3g}: no scan-line offsets")
    return f"{'scan-line check R':<28s} {block['ratio']:.3g} {verdict}"


def format_table(stats: dict) -> str:
    """Plain-text table of a ``SurfaceStatistics.as_dict()``."""
    lines = []
    for key, label, unit, scale in _TABLE:
        v = stats[key]
        if key in ("hurst", "fractal_dimension") and not stats["hurst_success"]:
            if v is None:        # the fit's own reason (too few points, grid too small)
                why = stats.get("hurst_message", "").split(";")[0] or "too few PSD points"
                hint = "" if "flat" in why else "; give --hurst-q-range"   # no range helps
                lines.append(f"{label:<28s} n/a (" + ("no Hurst exponent" if key !=
                             "hurst" else f"{why}{hint}") + ")")
                continue
            lines.append(f"{label:<28s} n/a (PSD fit gives H = {stats['hurst']:.3g}, "
                         f"outside (0, 1))")
            continue
        if v is None or (isinstance(v, list) and None in v):
            text, unit = "n/a", ""
        elif scale is None:
            text = " x ".join(str(x) for x in v) if isinstance(v, list) else str(v)
        elif key == "hurst_q_range":
            text = " - ".join(f"{x * scale:.4g}" for x in v)
        elif isinstance(v, list):
            text = " x ".join(f"{x * scale:.6g}" for x in v)
        else:
            text = f"{v * scale:.6g}"
            if key == "hurst" and stats.get("hurst_error") is not None:
                text += f" +- {stats['hurst_error']:.2g}"
        lines.append(f"{label:<28s} {text} {unit}".rstrip())
    from ..surfaces.psd_fit import range_note
    note = range_note(stats.get("hurst_message", ""))
    if note:             # split_fit: the range is not one power law
        lines.append(f"note: Hurst fit: {note}")
    return "\n".join(lines)


def write_psd(surface, path, title: str, coherence=None):
    """``info --psd``: the PSD (radially averaged for a map) and, for a map, the mean 1D
    PSDs along x and y (:mod:`roughfe.surfaces.line_psd`) as CSV rows ``kind, q, C,
    C_jacobs, weight`` (SI; C in Persson's normalisation, C_jacobs = (2 pi)^d C is
    SurfaceTopography's / contact.engineering's) or as a PNG figure. With ``coherence``
    (the file's trace/retrace :class:`~roughfe.surfaces.reliability.TraceRetraceCoherence`)
    the CSV gets a second file ``FILE_coherence.csv``
    (:func:`roughfe.cli.info_reliability.write_coherence`) and the figure a third panel
    with the curve and the cutoff marked in every panel."""
    from ..surfaces.line_psd import line_spectra
    from ..surfaces.stats import HANN_MIN_POINTS, fit_hurst, power_spectrum
    from ..writers import write_text
    if not surface.periodic and min(surface.shape) < HANN_MIN_POINTS:
        # said the library's "... use window='none'", no option of info (session 37)
        raise InputError(
            f"--psd: a non-periodic {' x '.join(map(str, surface.shape))} map is too small "
            f"for its Hann-windowed PSD (at least {HANN_MIN_POINTS} points per side; "
            "--periodic takes the heights unwindowed)")
    main = "radial" if surface.ndim == 2 else "profile"
    spectra = {main: power_spectrum(surface), **line_spectra(surface)}
    if path.suffix.lower() == ".png":
        from ..plotting.surfaces import plot_psd
        lines = {k: v for k, v in spectra.items() if k != main}
        return plot_psd({main: spectra[main]}, path, title=f"{title}: PSD",
                        fits={main: fit_hurst(surface)}, lines=lines, coherence=coherence)
    if coherence is not None:
        from .info_reliability import write_coherence
        write_coherence(coherence, path)
    rows = ["kind,q (rad/m),C (m^3 or m^4; Persson),C_jacobs (m^3 or m^4; "
            "SurfaceTopography),weight (rad/m or rad^2/m^2),window"]
    for kind, p in spectra.items():
        rows += [f"{kind.replace('along ', '')},{q:.10g},{c:.10g},{cj:.10g},{w:.10g},{p.window}"
                 for q, c, cj, w in zip(p.q, p.C, p.C_jacobs, p.weight)]
    return write_text(path, "\n".join(rows) + "\n")


def _info(args) -> int:
    from ..surfaces.scan_lines import is_mirrored
    from ..surfaces.stats import surface_statistics
    from ..writers import output_file, to_json_text
    from .info_reliability import (coherence_path, reliability_row, trace_retrace_of,
                                   warn_hurst_range)
    from .surface_warnings import plausible_surface
    read = surface_file(args, args.surface)      # as read: --detrend plane breaks the
    mirrored = is_mirrored(read)                 # evenness of a mirrored .npy
    surface = plausible_surface(args, read, args.detrend)     # (surface_from_args)
    q_range = None if args.hurst_q_range is None else tuple(args.hurst_q_range)
    if q_range is not None and not q_range[0] < q_range[1]:
        raise InputError(f"--hurst-q-range QMIN QMAX needs QMIN < QMAX (rad/m), got "
                         f"{q_range[0]:g} {q_range[1]:g}")
    psd_path = None if args.psd is None else output_file(
        args.psd, overwrite=args.overwrite, suffixes=(".csv", ".png"), option="--psd")
    stats = surface_statistics(surface, q_range=q_range).as_dict()
    reliability, coherence = trace_retrace_of(args, read, surface)   # trace vs retrace
    if psd_path is not None:
        if coherence is not None and psd_path.suffix.lower() == ".csv":
            output_file(coherence_path(psd_path), overwrite=args.overwrite,  # both checked
                        option="--psd (its coherence curve, beside it)")
        write_psd(surface, psd_path, str(args.surface), coherence)
    scan_lines = scan_line_block(surface)
    warn_hurst_range(args, reliability, stats["hurst_q_range"])
    if args.json:
        units = {k: v for k, v in STATISTICS_UNITS.items() if k in stats}
        print(to_json_text({"file": str(args.surface), "statistics": stats, "units": units,
                            "scan_lines": scan_lines, "reliability": reliability,
                            "metadata": dict(surface.metadata)}))
    else:
        print(f"{args.surface}: {surface!r}")
        print_surface_notes(args, surface, channel=True)
        print(format_table(stats))
        if scan_lines is not None:
            print(scan_line_row(scan_lines, mirrored))
        if reliability is not None:
            print(reliability_row(reliability))
    return 0


# -- generate --------------------------------------------------------------------------
def _make_rmd(a):
    from ..surfaces.rmd import rmd_profile, rmd_surface
    if a.profile:      # the default D is the surface's; a profile's is one less
        return rmd_profile(a.m, 1.3 if a.D is None else a.D, a.length, rng=a.seed,
                           rms_height=a.rms_height)
    return rmd_surface(a.m, 2.3 if a.D is None else a.D, a.length, rng=a.seed,
                       rms_height=a.rms_height)


def _make_wm(a):
    from ..surfaces.wm import wm_profile
    k_range = None if a.k_range is None else tuple(a.k_range)
    return wm_profile(a.n, a.length, a.hurst, gamma=a.gamma, amplitude=a.amplitude,
                      k_range=k_range, rng=a.seed)


def _make_mwm(a):
    from ..surfaces.wm import mwm_surface
    n_range = None if a.n_range is None else tuple(a.n_range)
    return mwm_surface(a.n, a.length, a.hurst, gamma=a.gamma, wavelength=a.wavelength,
                       n_range=n_range, ridges=a.ridges, amplitude=a.amplitude,
                       anisotropy=a.anisotropy, angles="random" if a.random_angles else None,
                       rng=a.seed)


def _make_spectral(a):
    from ..surfaces.spectral import spectral_profile, spectral_surface
    make = spectral_profile if a.profile else spectral_surface
    rms_h = a.rms_height if (a.rms_height is not None or a.rms_slope is not None) else 1e-6
    return make(a.n, a.length, a.hurst, rms_height=rms_h,
                rms_slope=a.rms_slope, q_long=a.q_long, q_roll=a.q_roll, q_short=a.q_short,
                amplitudes="fixed" if a.fixed_amplitudes else "gaussian", rng=a.seed,
                match=a.match)


def _check_rms_height(a) -> None:
    """``--rms-height`` within the one range of topography lengths (1 fm to 1000 km,
    :data:`~roughfe.surfaces.surface.SIZE_RANGE`), before anything is generated (1e308 gave
    "heights must be finite ... = inf" and 1e-300 heights of rms 0, neither naming it)."""
    from ..surfaces.surface import SIZE_RANGE
    if a.rms_height is not None and not SIZE_RANGE[0] <= a.rms_height <= SIZE_RANGE[1]:
        raise InputError(f"--rms-height {a.rms_height:g} m: allowed are {SIZE_RANGE[0]:g} m "
                         f"to {SIZE_RANGE[1]:g} m (the range of lengths of a topography; a "
                         f"height in another unit?)")


#: the unit of ``--amplitude`` A of each WM model (Eq. 2.1: m; Eq. 3.17: m^(1-H))
_AMPLITUDE_UNIT = {"wm": "m", "mwm": "m^(1-H)"}


def _made(a):
    """``a.make(a)``; a WM profile's or surface's rms height checked within the range of
    :func:`_check_rms_height` and said in the words of ``--amplitude``, the A that sets it
    (1e308 gave "heights must be finite", 1e200 a file of rms height inf, exit 0)."""
    from ..surfaces.surface import SIZE_RANGE
    unit = _AMPLITUDE_UNIT.get(a.model)
    try:
        surface = a.make(a)
    except InputError as exc:
        if unit and str(exc).startswith("heights must be finite"):
            raise InputError(f"--amplitude {a.amplitude:g} {unit}: the heights overflow the "
                             f"floating-point range ({exc})") from None
        raise
    if unit:
        with np.errstate(over="ignore", invalid="ignore"):
            h = surface.heights - np.mean(surface.heights)
            rms = float(np.sqrt(np.mean(h * h)))
        if not SIZE_RANGE[0] <= rms <= SIZE_RANGE[1]:
            raise InputError(f"--amplitude {a.amplitude:g} {unit} gives heights of rms "
                             f"{rms:.3g} m: allowed are {SIZE_RANGE[0]:g} m to "
                             f"{SIZE_RANGE[1]:g} m (the range of lengths of a topography)")
    return surface


def _grid_points(a) -> tuple:
    """Points per axis of the requested grid (for the memory check before generating)."""
    if a.model == "rmd":  # m checked first (the bounds of rmd_profile, rmd_surface):
        from ..surfaces.rmd import _check_m     # 2 ** 99999999999 alone ran for minutes
        n = 2 ** _check_m(a.m, mmax=24 if a.profile else 13) + 1
        return (n,) if a.profile else (n, n)
    return (a.n,) if a.model == "wm" or getattr(a, "profile", False) else (a.n, a.n)


def _figure_of(path):
    """The figure file named in the metadata of the roughfe surface at ``path`` (None
    when it is not one or names none)."""
    from ..surfaces.io import load_surface
    try:
        return load_surface(path).metadata.get("figure")
    except Exception:  # noqa: BLE001 - any file that is not a readable roughfe surface
        return None


def _rescaled_wm(surface, target):
    """A WM profile or MWM surface rescaled to the rms height ``target`` (m), with its
    metadata's ``amplitude_A`` the effective one: the heights of Eq. (2.1) and Eq. (3.17)
    are linear in A, so the stored A regenerates the stored heights (it kept the A before
    the rescaling until round 2, session 25: a factor 17.6 off for ``generate wm --n 512
    --seed 1 --rms-height 2e-6``); ``rms_height_target`` records the target as
    :func:`~roughfe.surfaces.rmd.rmd_surface` does."""
    from ..surfaces.stats import rms_height
    factor = target / rms_height(surface)
    return surface.with_heights(surface.heights * factor, rms_height_target=float(target),
                                amplitude_A=surface.metadata["amplitude_A"] * factor)


def _generate(args) -> int:
    from ..surfaces.io import save_surface
    from ..surfaces.stats import rms_height
    from ..writers import output_file
    out = output_file_of(args, suffixes=(".npz",))
    png = out.with_suffix(".png")          # the figure of this surface, beside it
    # with --overwrite: the replaced surface's own figure (its metadata names it) goes,
    # a picture of the same name that roughfe did not draw for it stays
    stale = out.exists() and png.is_file() and _figure_of(out) == png.name
    if not args.no_figures:
        output_file(png, overwrite=args.overwrite)
    from ..surfaces.surface import _as_size
    try:                          # the one size range (1e308 gave NaN heights first)
        _as_size(args.length, 1)
    except InputError as exc:
        raise InputError(f"--length {args.length:g} m: {exc}") from None
    _check_rms_height(args)
    shape = _grid_points(args)
    check_memory(f"a {' x '.join(map(str, shape))} grid", 8.0 * float(np.prod(shape)))
    surface = _made(args)
    if args.rms_height is not None and args.model in ("wm", "mwm"):
        surface = _rescaled_wm(surface, args.rms_height)
    if not args.no_figures:
        surface = surface.with_heights(surface.heights, figure=png.name)
    save_surface(surface, out)
    if png.is_file() and (stale or not args.no_figures):
        png.unlink()  # the old picture never stands beside the new surface (a Ctrl-C while
        #               the new one was drawn left it, named in the new .npz's metadata)
    print(f"wrote {out}: {surface!r}, rms height {rms_height(surface) * 1e6:.4g} um, "
          f"seed {surface.metadata.get('seed')}")
    if args.no_figures and stale:
        print(f"removed {png} (the figure of the surface this file replaced)")
    if not args.no_figures:
        from ..plotting.surfaces import plot_profile, render_surface
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
        add_output_file(m, "output .npz file (the figure goes beside it, FILE.png)")
        m.add_argument("--seed", type=nonnegative_int, default=None,
                       help="random seed (default: fresh, recorded in the file)")
        m.add_argument("--rms-height", type=positive_float, default=None,
                       help="rescale to this rms height (m)")
        add_run_options(m)
        m.set_defaults(func=_generate, make=make)
        return m

    m = common("rmd", "Random Midpoint Displacement surface (thesis Sec. 2.1.1), (2^m+1)^2 grid",
               _make_rmd)
    m.add_argument("--m", type=positive_int, default=7, help="refinement levels: (2^m+1)^2 points")
    m.add_argument("--D", type=float, default=None,
                   help="fractal dimension, in (2, 3) for a surface (default 2.3), (1, 2) "
                        "for a profile (default 1.3): the same Hurst exponent 0.7")
    m.add_argument("--length", type=positive_float, default=1e-4,
                   help="thesis L end to end (m); size = (2^m+1) L / 2^m")
    m.add_argument("--profile", action="store_true", help="a 1D profile instead of a surface")

    m = common("wm", "Weierstrass-Mandelbrot profile (thesis Eq. 2.1)", _make_wm)
    m.add_argument("--n", type=positive_int, default=2048, help="number of points")
    m.add_argument("--length", type=positive_float, default=1e-3, help="profile length (m)")
    m.add_argument("--hurst", type=float, default=0.7, help="Hurst exponent in (0,1)")
    m.add_argument("--gamma", type=float, default=1.5, help="frequency density > 1")
    m.add_argument("--amplitude", type=positive_float, default=1e-7, help="A (m)")
    m.add_argument("--k-range", type=int, nargs=2, metavar=("K1", "K2"), default=None,
                   help="truncation k1 k2 (default: profile length to Nyquist)")

    m = common("mwm", "multivariate WM surface (thesis Eq. 2.2 / 3.17)", _make_mwm)
    m.add_argument("--n", type=positive_int, default=256, help="grid points per side")
    m.add_argument("--length", type=positive_float, default=1e-4, help="side (m)")
    m.add_argument("--hurst", type=float, default=0.7, help="Hurst exponent in (0,1)")
    m.add_argument("--gamma", type=float, default=1.5, help="frequency density > 1")
    m.add_argument("--wavelength", type=positive_float, default=None, help="lambda (m), default L")
    m.add_argument("--n-range", type=int, nargs=2, metavar=("NS", "NF"), default=None,
                   help="frequency indices n_s n_f (default: 1 to Nyquist)")
    m.add_argument("--ridges", type=positive_int, default=10, help="number of ridges M")
    m.add_argument("--amplitude", type=positive_float, default=1e-6,
                   help="A of Eq. 3.17 (m^(1-H))")
    m.add_argument("--anisotropy", type=float, nargs="+", default=None,
                   help="M factors a_m (default all 1)")
    m.add_argument("--random-angles", action="store_true",
                   help="random ridge angles (default pi m / M)")

    m = common("spectral", "periodic self-affine surface by Fourier filtering", _make_spectral)
    m.add_argument("--n", type=positive_int, default=256, help="grid points per side")
    m.add_argument("--length", type=positive_float, default=1e-4, help="period (m)")
    m.add_argument("--hurst", type=float, default=0.8, help="Hurst exponent in (0,1]")
    m.add_argument("--rms-slope", type=float, default=None,
                   help="target rms slope instead of rms height (1 um if neither)")
    m.add_argument("--q-long", type=float, default=None, help="q_l cut-off (rad/m)")
    m.add_argument("--q-roll", type=float, default=None, help="roll-off q_r (rad/m)")
    m.add_argument("--q-short", type=float, default=None, help="q_s cut-off (rad/m)")
    m.add_argument("--fixed-amplitudes", action="store_true",
                   help="random phases only (PSD exactly the target)")
    m.add_argument("--match", choices=("realisation", "expectation"), default="realisation",
                   help="meet the rms target on this surface exactly (default), or in the "
                        "ensemble mean with the mean PSD exactly the target (Gaussian "
                        "amplitudes: the default inflates the mean short-wave PSD)")
    m.add_argument("--profile", action="store_true", help="a 1D profile instead of a surface")


def register(sub):
    _register_generate(sub)
    p = sub.add_parser("info", help="statistics of a surface file (table or JSON)",
                       description="Statistics of a profile or surface: rms height/slope/"
                                   "curvature, spectral moments, Nayak alpha, Hurst exponent.")
    add_surface_options(p)
    add_detrend_option(p)
    p.add_argument("--hurst-q-range", type=positive_float, nargs=2, metavar=("QMIN", "QMAX"),
                   default=None,
                   help="angular wavenumbers (rad/m) bounding the Hurst fit (default "
                        "8 pi / L to pi / (2 dx)); restrict it to the self-affine range "
                        "when the table notes that the PSD is not one power law")
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    p.add_argument("--psd", metavar="FILE", default=None,
                   help="also write the PSD (radially averaged for a map) and a map's mean "
                        "1D PSDs along x and y: .csv (q, C in Persson's normalisation, "
                        "C_jacobs = SurfaceTopography's / contact.engineering's) or .png; "
                        "a file with a trace and a retrace channel adds their coherence "
                        "(FILE_coherence.csv beside a .csv; a panel and the cutoff on a "
                        ".png)")
    p.add_argument("--overwrite", action="store_true", help="replace an existing --psd file")
    p.set_defaults(func=_info)
