"""Tools of the validation studies: target rows (the JSON schema of ``validation/output``)
and Richardson extrapolation of a refinement sequence.

Target rows
-----------
Every validation script (``roughfe validate NAME``) writes ``<outdir>/<script>.json`` with a
top-level key ``"targets"``: a list of rows::

    {"name": str,        what is compared, e.g. "RMD: A* limits FEM vs BEM"
     "target": str,      the criterion as text, e.g. "<= 1 %"
     "measured": str,    the measured value as text, e.g. "0.42 %"
     "value": float|null the measured value as a number (SI or a fraction), if any
     "met": bool|null,   null: not checked, either a row reported beside the targets
                         (:func:`reported`: e.g. a number fixed by construction) or a
                         target the run did not check (:func:`skipped`)
     "reason": str}      why it is (not) met, or what it measures; "" when obvious

A target that the run was to check but did not (an optional tool missing, a case or a
script that ``--quick`` leaves out) is a :func:`skipped` row: ``met`` null, ``measured``
"not run" and a name ending in ``": not run"`` (:data:`NOT_RUN`), which
:func:`is_skipped` recognises; ``roughfe validate`` prints it, lists it under ``not_run``
and never calls such a run "all met". A :func:`reported` row is not counted.

``roughfe validate`` writes ``<outdir>/summary.json`` (see :mod:`roughfe.cli.validate_cmd`):
``{"planned": [names], "complete": bool, "pending": [names], "validations": {name:
{"met": bool|null, "targets": [rows], "not_run": [...]}}, "all_met": bool, "not_run":
[...]}``; ``all_met`` is true only for a complete run with every target run and met. The
documentation pages are generated from these files; no number is typed by hand.

Richardson extrapolation
------------------------
For a quantity Q_h computed on a sequence of discretisations refined by a constant ratio
rho (h, h/rho, h/rho^2, ...), Q_h = Q + C h^p + o(h^p). Three consecutive levels give the
observed order p = ln((Q_1 - Q_0) / (Q_2 - Q_1)) / ln(rho) and the extrapolated limit
Q = Q_2 + (Q_2 - Q_1) / (rho^p - 1) (Roache 1998, Verification and Validation in
Computational Science and Engineering, Ch. 5).
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from .errors import InputError
from .writers import finite_or_none

#: Orders outside this range are taken as "not in the asymptotic range".
ORDER_RANGE = (0.5, 4.0)
#: Roache's safety factors of the grid convergence index: 1.25 with an observed order from
#: three grids, 3 when the order is not observed (fallback); kept for the comparison of
#: ``validation/richardson_calibration.py``. Since round 2, session 43, the uncertainty is
#: at least FLOOR_FACTOR times the larger of the last two differences (:class:`Richardson`).
SAFETY_OBSERVED, SAFETY_FALLBACK = 1.25, 3.0
#: the calibrated floor's factor (three protocols, session 43: see :class:`Richardson`)
FLOOR_FACTOR = 1.25


@dataclass(frozen=True)
class Target:
    """One validation target: the row of the JSON schema (see the module docstring)."""

    name: str
    target: str
    measured: str
    met: bool | None          # None: reported, not a target (it cannot decide anything)
    reason: str = ""
    value: float | None = None

    def to_dict(self) -> dict:
        d = asdict(self)
        d["met"] = None if self.met is None else bool(self.met)
        d["value"] = finite_or_none(d["value"])
        return d


def percent(value: float, digits: int = 2) -> str:
    """``0.0123 -> "1.23 %"``; non-finite -> ``"n/a"``."""
    return f"{100 * value:.{digits}f} %" if np.isfinite(value) else "n/a"


def fraction(value: float) -> str:
    """A relative quantity as text: in % with 3 decimals from 1e-4 up (``"0.012 %"``), in
    scientific notation below (``"1.8e-12"``: a 1e-8 limit printed as "0 %" read as a
    verdict that could not be checked); non-finite -> ``"n/a"``."""
    v = float(value)
    if not np.isfinite(v):
        return "n/a"
    if v != 0.0 and abs(v) < 1e-4:
        return f"{v:.2g}"
    return percent(v, 3).replace(".000 %", " %")


def reported(row: Target, why: str) -> Target:
    """``row`` kept in the report as a number, not a target (``met`` None): e.g. a quantity
    that the method fixes by construction, which no error could move."""
    return Target(row.name, row.target, row.measured, None,
                  f"{why}: reported, not a target" + (f"; {row.reason}" if row.reason else ""),
                  row.value)


#: The end of the name of a :func:`skipped` row.
NOT_RUN = ": not run"


def skipped(name: str, target: str, why: str) -> Target:
    """The row of a target the run was to check and did not (``met`` None, ``measured``
    "not run", the name ``name + ": not run"``): counted as not run by ``roughfe
    validate``, never as met. ``why``: what was missing and how to run it."""
    return Target(f"{name}{NOT_RUN}", target, "not run", None, why)


def is_skipped(row) -> bool:
    """True for a :func:`skipped` row (a :class:`Target` or its dict); False for a
    :func:`reported` one."""
    met, name = ((row.get("met"), row.get("name")) if isinstance(row, dict)
                 else (row.met, row.name))
    return met is None and str(name or "").endswith(NOT_RUN)


def within(name: str, value: float, limit: float, reason: str = "") -> Target:
    """A target ``|value| <= limit`` for a relative quantity (fractions, in % or, below
    1e-4, in scientific notation: :func:`fraction`)."""
    v = float(value)
    return Target(name=name, target=f"<= {fraction(limit)}", measured=fraction(v),
                  met=bool(np.isfinite(v) and abs(v) <= limit), reason=reason, value=v)


def report_title(title: str, quick: bool = False, reduced: str = "") -> str:
    """The first line of a validation report ``<script>.md``: ``# title``; for the
    reduced case (``quick``, ``roughfe validate --quick``) the line says so, and the next
    one says what is reduced (``reduced``, e.g. "3 seeds instead of 20") and that the
    full case runs without ``--quick``. Ends with a newline."""
    if not quick:
        return f"# {title}\n"
    return (f"# {title}: reduced case (`--quick`)\n\n"
            f"Reduced case{': ' + reduced if reduced else ''}. The numbers below are not "
            "those of the full validation, which `roughfe validate` without `--quick` runs.\n")


def targets_markdown(rows) -> str:
    """The rows as a Markdown table (target | criterion | measured | status | reason); a
    ``|`` inside a cell (``|p256 / p128 - 1|``) is escaped, so it cannot split the row."""
    def cell(text):
        return str(text).replace("|", "\\|").replace("\n", " ")
    lines = ["| target | criterion | measured | status | reason |", "|---|---|---|---|---|"]
    for t in rows:
        status = ("**not run**" if is_skipped(t) else "not checked" if t.met is None
                  else "met" if t.met else "**NOT met**")
        lines.append("| " + " | ".join(cell(c) for c in (t.name, t.target, t.measured, status,
                                                          t.reason)) + " |")
    return "\n".join(lines) + "\n"


@dataclass(frozen=True)
class Richardson:
    """Richardson extrapolation of a refinement sequence (see the module docstring).

    Attributes
    ----------
    values : tuple of float
        Q at the levels, coarsest first.
    ratio : float
        Refinement ratio rho between consecutive levels.
    orders : tuple of float
        Observed order of every consecutive triple of levels (NaN where the two
        differences change sign or one is zero).
    order : float
        Order used: that of the finest triple if it is observed and within
        :data:`ORDER_RANGE`, else NaN (fallback).
    asymptotic : bool
        True when ``order`` is observed (the finest triple converges monotonically at an
        order within :data:`ORDER_RANGE`).
    limit : float
        Extrapolated value; in the fallback the finest value (no extrapolation).
    uncertainty : float
        Estimated error of ``limit``: fallback, FLOOR_FACTOR = 1.25 times the larger of
        the last two differences; asymptotic, the larger of that and (F_s - 1) |Q_fine -
        limit| with F_s = 1.25 (a quarter of the extrapolation step). Roache's grid
        convergence index takes 3x the last difference alone (fallback) and the quarter
        step alone (asymptotic). Calibrated in round 2, session 43, against the known
        limits of BEM refinement sequences of rough profiles
        (``validation/richardson_calibration.py``, docs/validation/fem-convergence.md,
        three protocols on three sets of 216 sequences each): the quarter step alone
        covered the limit in 24.6-30.1 % (the order of the finest triple is not the
        sequence's when refinement resolves new contact), 3x the last difference alone
        in 83.6-93.9 %; a floor of 3x the larger of the last two differences in
        99.3-100 %, and of 1.25x (fitted to >= 95 % on the first two sets, tested on
        the third) in 97.9 % (asymptotic) and 96.9 % (fallback) of the third set, the
        median error then 0.05 and 0.22 of the uncertainty.
    errors : tuple of float
        Estimated discretisation error of every level: ``|Q_level - limit| +
        uncertainty``.
    method : str
        How the limit was obtained, in words.
    """

    values: tuple
    ratio: float
    orders: tuple
    order: float
    asymptotic: bool
    limit: float
    uncertainty: float
    errors: tuple
    method: str

    def to_dict(self) -> dict:
        clean = finite_or_none
        return {"values": [clean(v) for v in self.values], "ratio": self.ratio,
                "orders": [clean(v) for v in self.orders], "order": clean(self.order),
                "asymptotic": self.asymptotic, "limit": clean(self.limit),
                "uncertainty": clean(self.uncertainty),
                "errors": [clean(v) for v in self.errors], "method": self.method}


def judge_claim(distance: float, claimed: float, reference_error: float) -> str:
    """Whether an error claim ``distance <= claimed`` holds, judged against a reference
    that is itself uncertain by ``reference_error`` (all >= 0, same units):
    ``"covered"`` when ``distance + reference_error <= claimed`` (holds whatever the
    reference's error), ``"missed"`` when ``distance - reference_error > claimed`` (fails
    whatever it), ``"undecided"`` otherwise (the reference cannot judge it)."""
    if not (distance >= 0 and claimed >= 0 and reference_error >= 0):
        raise InputError(f"judge_claim needs non-negative numbers (no NaN), got distance "
                         f"{distance!r}, claimed {claimed!r}, reference_error "
                         f"{reference_error!r}")
    if distance + reference_error <= claimed:
        return "covered"
    return "missed" if distance - reference_error > claimed else "undecided"


def judge_richardson(estimate: "Richardson", reference: float, reference_error: float) -> dict:
    """The two claims of a :class:`Richardson` estimate against a known ``reference``
    (uncertain by ``reference_error``), each judged by :func:`judge_claim`: ``"limit"``,
    |reference - limit| <= uncertainty; ``"levels"``, |Q_r - reference| <= errors[r] at
    every level (missed if missed at one level, covered if covered at all)."""
    limit = judge_claim(abs(reference - estimate.limit), estimate.uncertainty, reference_error)
    each = [judge_claim(abs(q - reference), e, reference_error)
            for q, e in zip(estimate.values, estimate.errors)]
    levels = ("missed" if "missed" in each else
              "covered" if all(v == "covered" for v in each) else "undecided")
    return {"limit": limit, "levels": levels}


def observed_orders(values, ratio: float = 2.0) -> np.ndarray:
    """Observed order of each consecutive triple of ``values`` (NaN if not monotone)."""
    q = np.asarray(values, dtype=float)
    d = np.diff(q)
    with np.errstate(divide="ignore", invalid="ignore"):
        quotient = d[:-1] / d[1:]
        return np.where(quotient > 0, np.log(np.abs(quotient)) / math.log(ratio), np.nan)


def richardson(values, ratio: float = 2.0) -> Richardson:
    """Richardson-extrapolate ``values`` (coarsest first, refined by ``ratio`` each).

    Uses the finest three levels. If their differences have one sign and the observed
    order lies in :data:`ORDER_RANGE`, the limit is extrapolated with that order;
    otherwise the sequence is not in its asymptotic range and the fallback keeps the
    finest value as the limit with the wider uncertainty (see :class:`Richardson`).

    Raises
    ------
    InputError
        Fewer than 3 finite values, or ``ratio <= 1``.
    """
    q = np.asarray(values, dtype=float).ravel()
    if q.size < 3 or not np.all(np.isfinite(q)):
        raise InputError(f"Richardson extrapolation needs >= 3 finite values, got {q.tolist()}")
    if not ratio > 1:
        raise InputError(f"the refinement ratio must be > 1, got {ratio!r}")
    orders = observed_orders(q, ratio)
    p = float(orders[-1])
    step = q[-1] - q[-2]
    # the floor of both branches (calibrated, session 43: see Richardson.uncertainty)
    floor = FLOOR_FACTOR * float(np.abs(np.diff(q)[-2:]).max())
    if np.isfinite(p) and ORDER_RANGE[0] <= p <= ORDER_RANGE[1]:
        limit = float(q[-1] + step / (ratio ** p - 1.0))
        unc = max((SAFETY_OBSERVED - 1.0) * abs(q[-1] - limit), floor)
        method = (f"extrapolated with the observed order {p:.2f} of the finest three levels; "
                  f"uncertainty at least {FLOOR_FACTOR:g} x the larger of the last two "
                  "differences")
        asymptotic = True
    else:
        why = ("the last two differences change sign" if not np.isfinite(p)
               else f"observed order {p:.2f} outside {ORDER_RANGE}")
        limit, unc, asymptotic = float(q[-1]), floor, False
        method = (f"not in the asymptotic range ({why}): limit = finest value, "
                  f"uncertainty {FLOOR_FACTOR:g} x the larger of the last two differences")
        p = float("nan")
    errors = tuple(float(abs(v - limit) + unc) for v in q)
    return Richardson(values=tuple(float(v) for v in q), ratio=float(ratio),
                      orders=tuple(float(o) for o in orders), order=p, asymptotic=asymptotic,
                      limit=limit, uncertainty=float(unc), errors=errors, method=method)
