"""Target CSV files of roughness design: :func:`read_target_csv` and
:func:`write_target_csv` (a :class:`~roughfe.genomics.similarity.Target` as two columns,
pressure in Pa and K in Pa/m or A)."""
from __future__ import annotations

import csv
import re
from pathlib import Path

import numpy as np

from ..errors import FileFormatError, InputError
from .similarity import QUANTITY_LABELS, Quantity, Target, _check_quantity, _float_or_none


def _said(line):
    """The quantity a comment line names (as :func:`write_target_csv` writes it), or None."""
    return next((q for q, (label, _) in QUANTITY_LABELS.items() if label in line), None)


#: the comment that carries :attr:`Target.p_top` (Eq. 4.2's p_max^t, Pa)
P_TOP_COMMENT = re.compile(r"#\s*p_top\s*[:=]\s*(\S+)")


def _p_top(path, k, text):
    """The p_top (Pa) of a ``# p_top: <number> Pa ...`` comment line, else None."""
    m = P_TOP_COMMENT.match(text.strip())
    if m is None:
        return None
    value = _float_or_none(m.group(1))
    if value is None:
        raise FileFormatError(f"{path}: line {k}: the comment {text.strip()!r} gives p_top "
                              f"{m.group(1)!r}, not a number (Pa)")
    return value


def _target_lines(path):
    """``(line number, raw text, stripped cells)`` of the lines of a target CSV that are
    neither blank nor comments, the quantity the first naming comment says and the
    ``p_top`` of a ``# p_top: ...`` comment (None without one)."""
    lines, said, p_top = [], None, None
    try:
        with path.open(newline="", encoding="utf-8-sig") as fh:
            for k, row in enumerate(csv.reader(fh), 1):
                cells = [c.strip() for c in row]
                if not any(cells):
                    continue
                if cells[0].startswith("#"):
                    text = ",".join(row)
                    top = _p_top(path, k, text)
                    if top is not None:
                        p_top = top
                    else:
                        said = said or _said(text)
                else:
                    lines.append((k, ",".join(row), cells))
    except (UnicodeDecodeError, csv.Error) as exc:
        raise FileFormatError(f"{path} is not a UTF-8 CSV text file of 'pressure,value' rows "
                              f"({exc})") from None
    return lines, said, p_top


def _is_pressure_name(name) -> bool:
    """A header name that says pressure: ``p``, ``pressure``, ``mean pressure``, with any
    unit or suffix after a non-letter (``pressure_Pa``, ``p [Pa]``, ``p_mean``)."""
    return re.match(r"(mean[ _-]?)?(p|pressure)(?![a-z])", name.lower()) is not None


#: units a header may name that are not the file's (pressure in Pa, K in Pa/m, A a
#: fraction): the reader takes numbers as they are, so a header 'pressure_MPa' was read in
#: Pa (a design for pressures 1e6 times lower, session 32)
_OTHER_PRESSURE = re.compile(r"(?<![a-z])(hpa|kpa|mpa|gpa|m?bar|psi|ksi|atm|torr|n/mm(\^?2|²)?)"
                             r"(?![a-z])")
_OTHER_VALUE = re.compile(r"%|(?<![a-z])(percent|hpa|kpa|mpa|gpa|n/mm(\^?[23]|[²³])?|mm|um|µm|"
                          r"nm)(?![a-z])")


def _check_units(path, k, text, cells):
    """A FileFormatError when the header names a unit the file is not read in: the
    pressure in anything but Pa, K in anything but Pa/m, A in percent."""
    p, v = (c.lower() for c in cells)
    m = _OTHER_PRESSURE.search(p)
    if m:
        raise FileFormatError(f"{path}: line {k}: the header {text!r} gives the pressure in "
                              f"{m.group(0)!r}; a target CSV is read in SI: pressure in Pa "
                              f"(convert the column, e.g. MPa x 1e6, and name it "
                              f"'pressure_Pa')")
    m = _OTHER_VALUE.search(v)
    if m:
        raise FileFormatError(f"{path}: line {k}: the header {text!r} gives the value in "
                              f"{m.group(0)!r}; a target CSV is read in SI: K in Pa/m, A as a "
                              f"fraction 0 < A <= 1 (not percent); convert the column")


def _named_quantity(path, k, text, name):
    """The quantity a header's value column names: K for a leading ``K``/``k`` token
    (``K [Pa/m]``, ``K_Pa_per_m``) or the word ``stiffness`` anywhere (``stiffness per
    unit area``: "per unit area" qualifies K, it does not name A); A for a leading
    ``A``/``Ar``/``A_r`` token (``A``, ``A*``, ``Ar/An``, ``A_r/A_n``) or, without
    ``stiffness``, the word ``area`` (``area_fraction``); None for a neutral name
    (``value``); a FileFormatError for a name that says both (a leading A token beside
    the word stiffness)."""
    low = name.lower()
    lead = re.match(r"(k|a(_?r)?)(?![a-z])", low)
    lead = None if lead is None else ("K" if lead.group(0) == "k" else "A")
    word = ("K" if re.search(r"(?<![a-z])stiffness(?![a-z])", low) else
            "A" if re.search(r"(?<![a-z])area(?![a-z])", low) else None)
    if lead == "A" and word == "K":
        raise FileFormatError(f"{path}: line {k}: the header {text!r} names both stiffness K "
                              f"and area A in its value column {name!r}; a target holds one")
    return lead or word


def _check_header(path, k, text, cells):
    """A header must name two columns, the pressure first (the reader takes columns by
    position: a file written value first was read with its values as pressures).
    Returns the quantity the value column names (:func:`_named_quantity`)."""
    if len(cells) != 2:
        raise FileFormatError(f"{path}: line {k}: the header {text!r} names {len(cells)} "
                              f"column(s); a target has two, comma-separated: pressure (Pa) "
                              f"then value (e.g. 'pressure_Pa,value')")
    if not _is_pressure_name(cells[0]) or _is_pressure_name(cells[1]):
        swapped = " (swapped? put the pressure first)" if _is_pressure_name(cells[1]) else ""
        raise FileFormatError(f"{path}: line {k}: the header {text!r} does not name the "
                              f"pressure first{swapped}; the columns are pressure (Pa) then "
                              f"value, e.g. 'pressure_Pa,value' or 'p,K'")
    _check_units(path, k, text, cells)
    return _named_quantity(path, k, text, cells[1])


def _agreed(path, named, quantity):
    """The one quantity of ``named`` (where the file says it: its comment, its header)
    and ``quantity`` (the caller's), None if no one says; an InputError naming both
    when two disagree."""
    said = [(where, q) for where, q in named if q is not None]
    if quantity is not None:
        said.append((f"--quantity {quantity}", quantity))
    for (w1, q1), (w2, q2) in zip(said, said[1:]):
        if q1 != q2:
            raise InputError(f"{path}: {w1} says {QUANTITY_LABELS[q1][0]} ({q1}) but {w2} "
                             f"says {QUANTITY_LABELS[q2][0]} ({q2}); give the quantity "
                             f"the file holds (--quantity {q1} or none), or correct the "
                             f"file")
    return said[0][1] if said else None


def read_target_csv(path, quantity=None, name=None, default: Quantity = "K") -> Target:
    """Read a target from a CSV file with two columns: pressure (Pa), value (K in Pa/m or A).

    The file is UTF-8 (a byte-order mark is skipped). Blank lines and lines starting with
    ``#`` are skipped anywhere; one header line of non-numeric names may precede the
    first data row (a line with a number in it is data: ``1e7,1e11x`` is an error, not a
    header), and it must name two columns, the pressure first (``pressure_Pa,value``,
    ``p,K``, ``p [Pa],A``) and name no unit other than Pa, Pa/m or a fraction
    (``pressure_MPa``, ``K [MPa/um]``, ``A [%]`` are errors: the numbers are read as
    given, in SI); every other line must be two numbers (empty cells after them,
    a trailing comma, are ignored; a third value is an error), else the error names the
    line and its content. An area target must be a fraction, 0 < A <= 1 (:class:`Target`).
    The quantity is the one the file names: in its ``# name: <label> (unit) vs pressure
    (Pa)`` comment (as :func:`write_target_csv` writes it) and in its header's value
    column (``p,K``, ``p [Pa],A``, ``pressure,area_fraction``: :func:`_named_quantity`;
    ``value`` names none). Where both name one they must agree, and ``quantity`` ("K" or
    "A") must agree with it (an area target read as a stiffness was a silent,
    meaningless objective: a header ``p [Pa],A`` was read as K); an InputError names
    the two. ``quantity`` is taken as given for a file that names none (``default``
    when None). A comment ``# p_top: <number> Pa`` gives the target's
    :attr:`~roughfe.genomics.similarity.Target.p_top` (Eq. 4.2's p_max^t for a curve
    that stops before Delta = peak-valley; ``roughfe design --target-p-top`` replaces it).
    """
    path = Path(path)
    if path.is_dir():    # said "does not exist" (round 2, session 37)
        raise InputError(f"target file {path} is a folder, not a 'pressure,value' CSV file")
    if not path.is_file():
        raise InputError(f"target file {path} does not exist")
    if quantity is not None:
        _check_quantity(quantity)
    lines, said, p_top = _target_lines(path)
    rows, header = [], None
    for i, (k, text, cells) in enumerate(lines):
        while not cells[-1]:                            # a trailing comma: no column
            cells = cells[:-1]
        values = [_float_or_none(c) for c in cells]
        if i == 0 and all(v is None for v in values):
            header = (f"the header {text!r}", _check_header(path, k, text, cells))
            continue
        if len(values) != 2 or None in values:
            raise FileFormatError(f"{path}: line {k} is not a row 'pressure,value' of two "
                                  f"comma-separated numbers: {text!r} (one header line of "
                                  f"names may precede the first row)")
        rows.append(values)
    if not rows:
        raise FileFormatError(f"{path}: no 'pressure,value' rows found")
    named = _agreed(path, [("its comment", said), header or ("", None)], quantity)
    a = np.asarray(rows)
    return Target(a[:, 0], a[:, 1], named or default, name or path.stem,
                  {"source": str(path)}, p_top=p_top)


def write_target_csv(path, target: Target):
    """Write ``target`` as 'pressure_Pa,value' CSV atomically (readable by
    :func:`read_target_csv`): a comment naming the quantity and its unit, how a surface
    target was solved, its :attr:`~roughfe.genomics.similarity.Target.p_top` (a
    ``# p_top: <Pa>`` comment, read back; it was lost until session 27), the header and
    the rows."""
    from ..writers import write_text
    unit = QUANTITY_LABELS[target.quantity][1]
    lines = [f"# {target.name}: {QUANTITY_LABELS[target.quantity][0]} ({unit}) vs pressure (Pa)"]
    meta = target.metadata or {}
    if "boundary" in meta:      # how a surface target was made (K differs 10x between them)
        lines.append(f"# solved with boundary {meta['boundary']}, resolution "
                     f"{meta.get('resolution')}, detrend {meta.get('detrend')} on a "
                     f"{' x '.join(map(str, meta.get('solved_shape', ())))} grid")
    settings = meta.get("settings") or {}
    if target.quantity == "K" and settings.get("stiffness") == "fd":
        # how K was taken: a user compared it with `contact`'s exact K (25-60 % apart)
        lines.append(f"# K by central finite differences of p over the database's "
                     f"{settings.get('n_steps')} approaches (stiffness 'fd', the thesis' "
                     f"Eq. 2.7 on coarse steps), not the exact K of the contact set")
    if target.p_top is not None:  # Eq. 4.2's p_max^t beyond the last row (read back)
        lines.append(f"# p_top: {target.p_top:.17g} Pa (the target's pressure at Delta = "
                     f"peak-valley, Eq. 4.2 p_max^t)")
    lines.append("pressure_Pa,value")
    lines += [f"{p:.17g},{y:.17g}" for p, y in zip(target.pressure, target.values)]
    return write_text(path, "\n".join(lines) + "\n")
