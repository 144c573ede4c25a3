"""``roughfe info``'s row "trace/retrace reliable to" and its Hurst-range warning.

When the instrument file read holds the other sweep of the channel read (a trace and a
retrace channel of the same name, as :func:`roughfe.surfaces.io.channel_label` shows
them: di-1's 0 'Height' (Trace) and 1 'Height' (Retrace);
:func:`roughfe.surfaces.io.trace_retrace_partner`), ``info`` reads that channel with the
same ``--size``/``--periodic``/``--scan-axis`` and reports the reliability cutoff
``q_c`` of :func:`roughfe.surfaces.reliability.trace_retrace_coherence`: its wavelength,
and the lag between the sweeps. Both channels are taken as read (the coherence levels
each line itself), so the row is the same under every ``--detrend``. Where the Hurst
fit range reaches above ``q_c`` a warning (stderr) says that the fit includes scales
where each sweep holds more noise than surface, and how to restrict it
(``--hurst-q-range``); the fit's default range is not changed.
"""
from __future__ import annotations

import argparse
import math
import warnings

from ..errors import RoughfeError
from .options import surface_file, warn

#: the label of the row in the table
ROW = "trace/retrace reliable to"


def reliability_block(args, read):
    """``info --json``'s ``reliability``: the scalars of the trace/retrace coherence of
    ``read`` (the surface as its file gave it) with its other sweep, with ``units`` and
    ``channels``; ``error`` instead when the pair cannot be compared (the other channel
    unreadable, too few lines); None when the file holds no trace/retrace pair of the
    channel read (a single-channel file, a ``.npz``, a profile)."""
    from ..surfaces.io import trace_retrace_partner
    from ..surfaces.reliability import SUMMARY_UNITS, trace_retrace_coherence
    meta = read.metadata
    if read.ndim != 2 or meta.get("source") != str(args.surface):
        return None                            # the instrument file itself, as read
    partner = trace_retrace_partner(meta)
    if partner is None:
        return None
    channels = [next(c for c in meta["channels"] if c.split(" ", 1)[0] == str(i))
                for i in (meta["channel"]["index"], partner)]
    try:
        with warnings.catch_warnings():        # the same file: its warnings are said once
            warnings.simplefilter("ignore")
            other = surface_file(argparse.Namespace(**{**vars(args),
                                                       "channel": str(partner)}), args.surface)
        result = trace_retrace_coherence(read, other)
    except RoughfeError as exc:                # the other channel unreadable, too few lines
        return {"channels": channels, "error": str(exc)}
    return {**result.summary(), "channels": channels, "units": dict(SUMMARY_UNITS)}


def reliability_row(block) -> str:
    """The table row of :func:`reliability_block` (``""`` when it is None)."""
    if block is None:
        return ""
    if "error" in block:
        return f"{ROW:<28s} n/a ({block['error']})"
    lag = (f"{block['channels'][1]} is {block['channels'][0]} shifted by "
           f"{block['lag']:.3g} samples ({block['lag_length'] * 1e6:.3g} um)")
    if block["q_cutoff"] is None:
        return (f"{ROW:<28s} the pixel (coherence >= {block['threshold']:g} up to the "
                f"Nyquist wavenumber along {block['axis']}); {lag}")
    if not block["reliable_anywhere"]:
        return (f"{ROW:<28s} no wavelength (coherence < {block['threshold']:g} at every "
                f"wavenumber along {block['axis']}: the sweeps do not agree); {lag}")
    return (f"{ROW:<28s} q < {block['q_cutoff'] * 1e-6:.4g} rad/um (wavelengths > "
            f"{block['wavelength_cutoff'] * 1e6:.3g} um) along {block['axis']}, the fast "
            f"axis; {lag}")


def warn_hurst_range(args, block, q_range) -> None:
    """Warn (stderr) when the Hurst fit range ``q_range`` (rad/m) reaches above the
    cutoff of ``block``: the fit includes scales where each sweep holds more noise than
    surface."""
    if block is None or block.get("q_cutoff") is None or "error" in block:
        return
    q_max, q_c = q_range[1], block["q_cutoff"]
    if q_max is None or not math.isfinite(q_max) or q_max <= q_c:
        return
    warn(args, f"the Hurst fit range q = {q_range[0] * 1e-6:.4g} - {q_max * 1e-6:.4g} "
               f"rad/um reaches above {q_c * 1e-6:.4g} rad/um (wavelength "
               f"{block['wavelength_cutoff'] * 1e6:.3g} um), where the trace and the "
               f"retrace stop agreeing (coherence < {block['threshold']:g}: each sweep "
               f"holds more noise than surface): the fit includes unreliable scales; "
               f"restrict it with --hurst-q-range {q_range[0]:.4g} {q_c:.4g} (rad/m)")
