"""``roughfe info``'s row "trace/retrace reliable to" and its Hurst-range warning.

When the instrument file read holds the other sweep of the channel read (a trace and a
retrace channel of the same name, from the channels' names and scan directions that
:func:`roughfe.surfaces.channels.channel_entry` stored on reading: di-1's 0 'Height' (Trace)
and 1 'Height' (Retrace); :func:`roughfe.surfaces.channels.trace_retrace_partner`), ``info``
reads that channel with the same ``--size``/``--periodic``/``--scan-axis`` and reports
the reliability cutoff ``q_c`` of
:func:`roughfe.surfaces.reliability.trace_retrace_coherence`: its wavelength, and the lag
between the sweeps. Both channels are taken as read (the coherence levels
each line itself), so the cutoff is the same under every ``--detrend``; the row adds how
much of the analysed map's mean-square slope (after ``--detrend``) lies above it, along
x and along y (:func:`slope_shares`; di-1 under ``--detrend plane``: 7.8 % along the fast
axis, 84 % across the lines). Where the Hurst
fit range reaches above ``q_c`` a warning (stderr) says that the fit includes scales
where each sweep holds more noise than surface, and how to restrict it
(``--hurst-q-range``); the fit's default range is not changed. ``info --psd`` adds the
coherence curve (:func:`write_coherence`: a second CSV beside the PSD's, or a panel and
the cutoff on its figure).

``contact`` and ``leak`` on such a file print the same facts as a ``note:`` line
(:func:`reliability_note`) and keep the block in results.json (``inputs.reliability``):
their contact patches and gaps at the pixel scale include the scales finer than the
cutoff. A note, not a warning: on di-1, removing those scales along the fast axis (what
the coherence judges) moved A* by 1.5-2.9 %, K by 0.2 % and the mean gap by 0.1 % at
8e5-2.4e7 Pa; the same scales across the lines moved A* 1.5-2.3x, but trace and retrace
cannot judge those (docs/theory/01_surfaces.md).
"""
from __future__ import annotations

import argparse
import math
import warnings

from ..errors import RoughfeError
from .options import surface_file, warn

#: the label of the row in the table
ROW = "trace/retrace reliable to"


#: units of the block's keys beside the coherence's summary (:func:`slope_shares`)
SHARE_UNITS = {f"slope_share_{d}": f"1 (share of the mean-square slope along {d} at "
                                    f"q > q_cutoff; null without a cutoff)" for d in "xy"}


def slope_shares(surface, q_cutoff) -> dict:
    """``{"slope_share_x": s_x, "slope_share_y": s_y}``: the shares of the mean-square
    slope along x and along y of ``surface`` (the heights the command analyses, after
    ``--detrend``) at wavenumbers above ``q_cutoff`` (rad/m;
    :func:`~roughfe.surfaces.reliability.slope_share_above`); None each without a
    cutoff."""
    from ..surfaces.reliability import slope_share_above
    return {f"slope_share_{d}": None if q_cutoff is None else
            slope_share_above(surface, q_cutoff, d) for d in "xy"}


def trace_retrace_of(args, read, surface=None):
    """``(block, result)``: :func:`reliability_block` and the
    :class:`~roughfe.surfaces.reliability.TraceRetraceCoherence` it summarises (None when
    the block is None or says why the pair cannot be compared). The coherence is of
    ``read`` and its other sweep; the slope shares of ``surface`` (default ``read``)."""
    from ..surfaces.channels import channel_label, trace_retrace_partner
    from ..surfaces.reliability import SUMMARY_UNITS, trace_retrace_coherence
    meta = read.metadata
    if read.ndim != 2 or meta.get("source") != str(args.surface):
        return None, None                      # the instrument file itself, as read
    try:
        partner = trace_retrace_partner(meta)
    except RoughfeError as exc:                # metadata of an older roughfe: labels only
        return {"channels": list(meta.get("channels") or []), "error": str(exc)}, None
    if partner is None:
        return None, None
    labels = {c["index"]: channel_label(c) for c in meta["channel_table"]}
    channels = [labels[meta["channel"]["index"]], labels[partner]]
    try:
        with warnings.catch_warnings():        # the same file: its warnings are said once
            warnings.simplefilter("ignore")
            other = surface_file(argparse.Namespace(**{**vars(args),
                                                       "channel": str(partner)}), args.surface)
        result = trace_retrace_coherence(read, other)
    except RoughfeError as exc:                # the other channel unreadable, too few lines
        return {"channels": channels, "error": str(exc)}, None
    shares = slope_shares(read if surface is None else surface, result.q_cutoff)
    return {**result.summary(), **shares, "channels": channels,
            "units": {**SUMMARY_UNITS, **SHARE_UNITS}}, result


def reliability_block(args, read, surface=None):
    """``info --json``'s ``reliability``: the scalars of the trace/retrace coherence of
    ``read`` (the surface as its file gave it; a detrended one gives the same, the
    coherence levels each line) with its other sweep, and the shares of the mean-square
    slope above its cutoff along x and y (:func:`slope_shares`) of ``surface`` (default
    ``read``: the heights the command analyses; they depend on ``--detrend``), with
    ``units`` and ``channels``; ``error`` instead when the pair cannot be compared (the
    other channel unreadable, too few lines); None when the file holds no trace/retrace
    pair of the channel read (a single-channel file, a ``.npz``, a profile)."""
    return trace_retrace_of(args, read, surface)[0]


def _text(block) -> str:
    """What the row says after its label."""
    if "error" in block:
        return f"n/a ({block['error']})"
    lag = (f"{block['channels'][1]} is {block['channels'][0]} shifted by "
           f"{block['lag']:.3g} samples ({block['lag_length'] * 1e6:.3g} um)")
    if block["q_cutoff"] is None:
        return (f"the pixel (coherence >= {block['threshold']:g} up to the Nyquist "
                f"wavenumber along {block['axis']}); {lag}")
    if not block["reliable_anywhere"]:
        return (f"no wavelength (coherence < {block['threshold']:g} at every wavenumber "
                f"along {block['axis']}: the sweeps do not agree); {lag}")
    return (f"q < {block['q_cutoff'] * 1e-6:.4g} rad/um (wavelengths > "
            f"{block['wavelength_cutoff'] * 1e6:.3g} um) along {block['axis']}, the fast "
            f"axis; {lag}{_shares_text(block)}")


def _shares_text(block) -> str:
    """``"; beyond it lie X % of the mean-square slope along x ..."`` (``""`` without
    the shares: a block written before they existed, or NaN ones)."""
    fast = block["axis"]
    slow = "y" if fast == "x" else "x"
    s_fast, s_slow = block.get(f"slope_share_{fast}"), block.get(f"slope_share_{slow}")
    if s_fast is None or s_slow is None or math.isnan(s_fast) or math.isnan(s_slow):
        return ""
    return (f"; beyond it lie {100 * s_fast:.3g} % of the mean-square slope along {fast} "
            f"and {100 * s_slow:.3g} % along {slow} (across the lines)")


def reliability_row(block) -> str:
    """The table row of :func:`reliability_block` (``""`` when it is None)."""
    return "" if block is None else f"{ROW:<28s} {_text(block)}"


def reliability_note(block, spacing, what: str) -> str:
    """``contact``'s and ``leak``'s ``note:`` line on :func:`reliability_block` (``""``
    when it is None): the row's facts and, when the sweeps agree only above a wavelength,
    that ``what`` (the command's results) at the pixel scale include the finer scales;
    ``spacing`` (m) the grid's along the fast axis. The measured effect on di-1 is in the
    module docstring: a note, not a warning."""
    if block is None:
        return ""
    note = f"note: {ROW} {_text(block)}"
    if "error" in block or block["q_cutoff"] is None or not block["reliable_anywhere"]:
        return note
    return (f"{note}. The {what} at the pixel scale ({spacing * 1e6:.3g} um) include the "
            f"scales below {block['wavelength_cutoff'] * 1e6:.3g} um "
            f"({block['wavelength_cutoff'] / spacing:.3g} pixels), where each sweep holds "
            f"more noise than surface along the fast axis (across the lines trace and "
            f"retrace share their noise and cannot tell; results.json inputs.reliability; "
            f"di-1's measured effect: docs/theory/01_surfaces.md)")


def print_reliability_note(block, surface, what: str) -> None:
    """Print :func:`reliability_note` of ``block`` (nothing when it is None) for the
    command's ``surface`` (its spacing along the block's fast axis)."""
    if block is not None:
        print(reliability_note(block, surface.spacing[0 if block.get("axis", "x") == "x"
                                                      else 1], what))


def write_coherence(result, psd_path):
    """``info --psd FILE.csv``'s second file ``FILE_coherence.csv``: rows ``q`` (rad/m),
    ``coherence`` (gamma^2, -), ``snr`` (P_S / P_N, -; ``inf`` where gamma^2 = 1) of
    ``result`` (a :class:`~roughfe.surfaces.reliability.TraceRetraceCoherence`); the
    path is :func:`coherence_path`, checked before anything is written."""
    from ..writers import write_text
    rows = ["q (rad/m),coherence gamma^2 (-),snr P_S/P_N (-)"]
    rows += [f"{q:.10g},{g:.10g},{r:.10g}"
             for q, g, r in zip(result.q, result.coherence, result.snr)]
    return write_text(coherence_path(psd_path), "\n".join(rows) + "\n")


def coherence_path(psd_path):
    """``FILE_coherence.csv`` beside ``info --psd FILE.csv``."""
    return psd_path.with_name(f"{psd_path.stem}_coherence.csv")


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
