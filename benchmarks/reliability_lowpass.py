"""Research script (not in the package, not in ``make bench``): what the scales below
the trace/retrace reliability cutoff ``q_c`` do to the contact and the leak rates of
di-1 (round 2, session 36; the numbers and the verdict, a ``note:`` line in ``contact``
and ``leak`` and no warning, are in docs/theory/01_surfaces.md, "What the scales below
the cutoff do to contact").

di-1's trace (channel 0, least-squares plane removed as ``--detrend plane``) is solved
by the non-periodic BEM (E* = 210 MPa, nu = 0) at 8e5 / 8e6 / 2.4e7 Pa and its leak
rates by ``leakage_sweep`` (both directions, pressure drop 1 Pa, mu 1e-3 Pa s), as read
and low-passed at ``q_c`` (:func:`roughfe.surfaces.reliability.trace_retrace_coherence`
of trace and retrace): the window evenly mirrored (``Surface.mirrored``), its Fourier
coefficients beyond the cutoff set to zero (``|q_x|``, ``|q_y|`` or ``|q|`` above it;
sharp), cropped back. ``--coarse`` adds the 2x coarsened map (the mirrored window
low-passed at the 256^2 grid's Nyquist wavenumber, every second point), as read and
low-passed. About 50 s on one core (70 s with ``--coarse``).

Usage (from the repository root)::

    .venv/bin/python benchmarks/reliability_lowpass.py [--coarse]
"""
from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))     # the repository
from roughfe.leakage import leakage_sweep  # noqa: E402
from roughfe.model import Loading, Material  # noqa: E402
from roughfe.response import response  # noqa: E402
from roughfe.surfaces.io import load_surface  # noqa: E402
from roughfe.surfaces.reliability import trace_retrace_coherence  # noqa: E402
from roughfe.surfaces.surface import Surface  # noqa: E402

DI1 = Path("/work/shared/data/topographies/di-1.di")
PRESSURES = [8e5, 8e6, 2.4e7]


def low_passed(surface, q_cut, mode):
    """``surface`` (non-periodic) without the wavenumbers beyond ``q_cut`` (rad/m) along
    ``mode`` = "x", "y", "iso" (``|q|``) or "square" (both components), through its even
    mirror image."""
    m = surface.mirrored()
    qx, qy = (2 * np.pi * np.fft.fftfreq(n, d) for n, d in zip(m.shape, m.spacing))
    qx, qy = np.meshgrid(qx, qy, indexing="ij")
    keep = {"x": np.abs(qx) <= q_cut, "y": np.abs(qy) <= q_cut,
            "iso": np.hypot(qx, qy) <= q_cut,
            "square": (np.abs(qx) <= q_cut) & (np.abs(qy) <= q_cut)}[mode]
    h = np.fft.ifft2(np.fft.fft2(m.heights) * keep).real
    return surface.with_heights(h[: surface.shape[0], : surface.shape[1]])


def coarsened(surface):
    """The 2x coarser window: low-passed at the coarse grid's Nyquist wavenumber, every
    second point, the same size."""
    smooth = low_passed(surface, np.pi / (2 * surface.spacing[0]), "square")
    return Surface(smooth.heights[::2, ::2], surface.size, periodic=False)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--coarse", action="store_true", help="also the 2x coarsened map")
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore")
    trace, retrace = (load_surface(DI1, channel=c) for c in ("0", "1"))
    q_c = trace_retrace_coherence(trace, retrace).q_cutoff
    read = trace.detrended("plane")
    cases = {"as read": read}
    cases.update({f"|q_{m}| > q_c removed" if m != "iso" else "|q| > q_c removed":
                  low_passed(read, q_c, m) for m in ("x", "y", "iso")})
    cases["|q| > 2 q_c removed"] = low_passed(read, 2 * q_c, "iso")
    cases["|q| > 4e8 removed"] = low_passed(read, 4e8, "iso")
    if args.coarse:
        coarse = coarsened(read)
        cases.update({"256^2 as read": coarse,
                      "256^2 |q| > q_c removed": low_passed(coarse, q_c, "iso")})
    print(f"q_c = {q_c:.4g} rad/m; p = {PRESSURES} Pa")
    material = Material(E=210e6, nu=0.0)
    print(f"{'case':26s} {'A*':>22s} {'K (Pa/m)':>30s} {'gap (m)':>30s} {'Q_x (m^3/s)':>30s} "
          f"{'Q_y (m^3/s)':>30s}")
    for name, s in cases.items():
        contact = response(s, material, Loading(pressures=PRESSURES))   # with K
        rec = contact.to_records()
        leak = leakage_sweep(s, material, pressures=PRESSURES, direction="both",
                             mu=1e-3, pressure_drop=1.0).records()
        cols = [[r["area_fraction"] for r in rec], list(contact.stiffness),
                [r["mean_gap"] for r in rec], [r["leak_rate_x"] for r in leak],
                [r["leak_rate_y"] for r in leak]]
        print(f"{name:26s} " + " ".join(
            " ".join(f"{v:9.4g}" for v in col) for col in cols), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
