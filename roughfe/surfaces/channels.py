"""The channels of a multi-channel instrument file: what :func:`roughfe.surfaces.io.load_surface`
stores of them, how they are shown, the choice of the one to read and the pairing of the
two scan directions of one quantity.

A SurfaceTopography reader lists its channels (``reader.channels``); roughfe keeps each as
a :func:`channel_entry` (index, name, scan direction), the channel read in
``metadata["channel"]`` and all of them in ``metadata["channel_table"]``, and shows them
as :func:`channel_label` (``0 'Height' (Trace)``) in ``metadata["channels"]``, in
``info`` and in the errors that list them. :func:`trace_retrace_partner` pairs a trace
with its retrace from that data (the reliability cutoff of
:mod:`roughfe.surfaces.reliability`). Moved out of :mod:`roughfe.surfaces.io` in round
2, session 37 (one job per module; io.py was at its 500-line limit).
"""
from __future__ import annotations

from ..errors import InputError


def channel_entry(channel) -> dict:
    """``{"index": int, "name": str, "direction": str or None}`` of a SurfaceTopography
    channel: the scan direction where the file gives one (its raw metadata's ``line
    direction``: a .di file holds trace and retrace heights under one name, di-1's
    ``"Trace"`` and ``"Retrace"``), else None. ``metadata["channel"]`` of an instrument
    surface is the entry of the channel read, ``metadata["channel_table"]`` the file's."""
    raw = (channel.info or {}).get("raw_metadata")
    direction = raw.get("line direction") if isinstance(raw, dict) else None
    return {"index": int(channel.index), "name": str(channel.name),
            "direction": None if direction is None else str(direction)}


def channel_label(entry) -> str:
    """``0 'Height'`` for a :func:`channel_entry`, with the scan direction where there is
    one (``0 'Height' (Trace)``): how the channels are shown (``metadata["channels"]``,
    ``info``, the errors that list them)."""
    direction = entry.get("direction")
    return f"{entry['index']} {entry['name']!r}" + (f" ({direction})" if direction else "")


def read_channel_label(metadata) -> "str | None":
    """:func:`channel_label` of the channel read (``metadata["channel"]``; None without
    one). Metadata written before round 2, session 37 (a ``.npz``, results.json) has no
    ``direction`` in it: the label at its index in ``metadata["channels"]`` (listed in
    index order), which shows the direction as the file gave it."""
    read = metadata.get("channel")
    if not isinstance(read, dict):
        return None
    labels = metadata.get("channels") or []
    if "direction" not in read and 0 <= read.get("index", -1) < len(labels):
        return str(labels[read["index"]])
    return channel_label(read)


#: the two scan directions of one quantity that :func:`trace_retrace_partner` pairs
SWEEPS = ("trace", "retrace")


def trace_retrace_partner(metadata) -> "int | None":
    """Index of the channel that holds the other sweep of the channel read, from an
    instrument surface's ``metadata["channel"]`` and ``metadata["channel_table"]``
    (:func:`channel_entry`): the one channel of the same name whose direction is the
    other of Trace / Retrace (di-1: 0 'Height' (Trace) and 1 'Height' (Retrace)). None
    when the channel read has no such direction, or no single partner.

    Raises
    ------
    InputError
        Metadata of a multi-channel file written before round 2, session 37 (a ``.npz``
        saved then): it lists the channels as text labels only, without their directions
        as data; read the instrument file (``metadata["source"]``) again.
    """
    read = metadata.get("channel")
    if not isinstance(read, dict):
        return None
    table = metadata.get("channel_table")
    if table is None:
        labels = metadata.get("channels") or []
        if len(labels) > 1 and "direction" not in read:
            raise InputError(
                f"the metadata of this surface (read from {metadata.get('source')!r} by a "
                f"roughfe before round 2, session 37) lists the file's channels as text "
                f"only ({', '.join(map(str, labels))}), without their scan directions as "
                f"data: the trace/retrace partner of channel {read.get('index')} is not "
                f"looked for in text; read the instrument file again "
                f"(load_surface(source, channel=N))")
        return None
    own = read.get("direction")
    if own is None or own.lower() not in SWEEPS:
        return None
    other = SWEEPS[1 - SWEEPS.index(own.lower())]
    partners = [int(c["index"]) for c in table if c["name"] == read["name"]
                and (c.get("direction") or "").lower() == other]
    return partners[0] if len(partners) == 1 else None


def choose_channel(reader, channel, path):
    """The SurfaceTopography channel of ``reader`` that ``channel`` names: None for the
    reader's default, an index (an int or its digits, spaces stripped) or a name that one
    channel has; an :class:`InputError` listing the channels otherwise (a name two
    channels share, di-1's 'Height', needs the index)."""
    channels = reader.channels
    labels = [channel_label(channel_entry(c)) for c in channels]
    listed = ", ".join(labels)
    if channel is None:
        return reader.default_channel
    if isinstance(channel, str):           # " 1" was the name ' 1' (round 2, session 37)
        if not channel.strip():
            raise InputError(f"{path}: channel {channel!r} is blank; give a channel index "
                             f"or name: channels (index name) are {listed}")
        channel = channel.strip()
    if isinstance(channel, str) and not channel.lstrip("-").isdigit():
        named = [c for c in channels if c.name.strip() == channel]
        if not named:
            raise InputError(f"{path}: no channel named {channel!r}; channels (index name) "
                             f"are {listed}")
        if len(named) > 1:
            # di-1: trace (rms 9.95 nm) and retrace (114 nm) are both 'Height'; the
            # name took the first without a word until round 2, session 24
            raise InputError(f"{path}: {len(named)} channels are named {channel!r} "
                             f"({', '.join(labels[channels.index(c)] for c in named)}): give the "
                             f"channel index (channel=N, --channel N); channels (index "
                             f"name) are {listed}")
        return named[0]
    index = int(channel)
    if not 0 <= index < len(channels):
        raise InputError(f"{path}: channel index {index} out of range 0..{len(channels) - 1} "
                         f"(channels (index name) {listed})")
    return channels[index]
