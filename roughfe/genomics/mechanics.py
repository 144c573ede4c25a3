"""Contact mechanics of chromosomes (thesis Sec. 3.4.1-3.4.2, Fig. 36-39, 44-45).

For one realisation of a genome: the K(p) and A(p) curves (BEM, ``n_steps`` equispaced
approaches up to each profile's own peak-valley amplitude, E = 210 MPa as the thesis) of

* the complete profile,
* every chromosome C_n alone (Fig. 36, 44),
* every top-down partial sum C_{n_s} + ... + C_n and bottom-up partial sum
  C_{n_f} + ... + C_n (Fig. 37-38),

and the correlation coefficients c_n of each of those curves with the complete one
(Fig. 39, 45). The curves are :class:`~roughfe.genomics.similarity.ResponseCurve` and
the BEM call and c_n are :func:`~roughfe.genomics.macro_micro.profile_response` and
:func:`~roughfe.genomics.macro_micro.correlation` (shared with roughness design): c_n is
Pearson's coefficient of the two curves paired step by step (each loaded to its own
peak-to-valley in the same number of steps; ``axis="steps"``, the default), or on the
complete profile's pressures after the Eq. (4.2) stretch (``axis="pressure"``).

Amplitude. The genes of Table 1 read in SI (A = 1 m^0.25, lambda1 = 1 mm) give a 10x
profile with rms height 0.73 mm and rms slope ~27: far outside the small-slope
assumption of any half-space BEM, and pressures well above E. Because the contact problem
is linear in the heights (Eq. 4.2 scaling, :mod:`roughfe.genomics.similarity`), A only
stretches the pressure axis: A(p) and K(p) *shapes* and the c_n do not depend on it, and
p scales with A. Use a smaller A for physically meaningful absolute pressures.

Kernels: ``"thesis"`` is Eq. (2.4) (a line of 3D punch patches), ``"strip"`` the
plane-strain half-plane of a profile; they give different pressures for the same
profile (see :mod:`roughfe.bem.operators`), so both are offered and labelled.
"""
from __future__ import annotations

import contextlib
import hashlib
import math
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from functools import partial

import numpy as np

from .. import progress
from ..errors import FileFormatError, InputError, NoConvergenceError
from ..frozen import freeze_containers
from ..surfaces.surface import Surface
from ..writers import to_jsonable
from .chromosomes import reconstruction
from .genome import DEFAULT_NODES, Genome
from .macro_micro import correlation, is_flat, profile_response
from .similarity import ResponseCurve

THESIS_YOUNGS_MODULUS = 210e6     # Pa (Sec. 3.4.1)


def response(surface: Surface, *, youngs_modulus=THESIS_YOUNGS_MODULUS, poisson=0.0,
             kernel="thesis", n_steps=20) -> ResponseCurve:
    """K(p) (Pa/m) and A(p) (-) of a profile: ``n_steps`` equal approaches up to its peak-valley."""
    return profile_response(surface, youngs_modulus=youngs_modulus, poisson=poisson,
                            n_steps=n_steps, kernel=kernel)


def curve_difference(reference: ResponseCurve, other: ResponseCurve) -> dict:
    """Largest relative differences of K and A of ``other`` vs ``reference`` (-).

    ``other`` is interpolated (linearly) at the reference pressures inside its own range;
    differences are |y_o - y_r| / max|y_r| (A and K normalised by their largest value, so
    a zero area at first contact does not blow up the ratio).

    Curves whose pressure ranges share fewer than 2 reference pressures (e.g. a sequenced
    profile of a measured row whose genome is not that row's, loaded to other pressures)
    cannot be compared: K and A are then NaN and ``"note"`` says why (it was an
    InputError, raised after the sequencing had run; a user's review).
    """
    p = reference.pressure
    inside = (p >= other.pressure[0]) & (p <= other.pressure[-1])
    if inside.sum() < 2:
        return {"K": math.nan, "A": math.nan, "n_points": int(inside.sum()),
                "note": (f"the curves share {int(inside.sum())} pressure(s): the reference "
                         f"spans {p[0]:.4g}..{p[-1]:.4g} Pa, the other "
                         f"{other.pressure[0]:.4g}..{other.pressure[-1]:.4g} Pa")}
    out = {}
    for q in ("K", "A"):
        yr = reference.values(q)[inside]
        yo = np.interp(p[inside], other.pressure, other.values(q))
        out[q] = float(np.max(np.abs(yo - yr)) / max(np.max(np.abs(yr)), 1e-300))
    out["n_points"] = int(inside.sum())
    return out


#: Units of the numbers of :meth:`ChromosomeMechanics.to_dict` (mechanics.json); the
#: curves (``complete``, ``chromosomes``, ``td``, ``bu``) hold ``pressure``, ``stiffness``
#: and ``area_fraction``; "1": dimensionless
MECHANICS_UNITS = {"length": "m", "E": "Pa", "nu": "1", "indices": "1 (chromosome numbers n)",
                   "pressure": "Pa (mean contact pressure)",
                   "stiffness": "Pa/m (K = dp/dDelta)", "area_fraction": "1 (A*)",
                   "c_chromosome": "1 (correlation c_n)", "c_td": "1 (correlation c_n)",
                   "c_bu": "1 (correlation c_n)", "nit": "1 (BEM sweeps)", "elapsed_s": "s"}


@dataclass(frozen=True, eq=False)
class ChromosomeMechanics:
    """Contact curves of a realisation, its chromosomes and TD/BU partial sums.

    Attributes
    ----------
    length : float
        Observation length (m).
    kernel : str
    youngs_modulus, poisson : float
    indices : ndarray of int
        Chromosomes n_s..n_f of the realisation (Eq. 3.5).
    complete : ResponseCurve
    chromosome_curves, td_curves, bu_curves : tuple of ResponseCurve or None
        Curve of C_n; of the TD sum ending at n; of the BU sum ending at n (same order as
        ``indices`` for chromosomes and TD; BU in the order n_f, n_f - 1, ...). None where
        the profile is flat (no contact curve).
    c_chromosome, c_td, c_bu : dict
        ``{"K": ndarray, "A": ndarray}`` correlation coefficients c_n (NaN where None).
    success, message, nit : scipy-like report; nit = number of BEM sweeps. ``success``
        is True only when every BEM sweep converged (:func:`sweep_fields`); a chromosome
        or partial sum whose sweep raised :class:`~roughfe.errors.NoConvergenceError`
        has curve None and c_n NaN, and the message names it.
    elapsed : float
        Wall time (s).
    failed_chromosomes : tuple of int
        Chromosomes n whose own sweep did not converge (curve None like a flat one's;
        Alg. 2 must not count them as flat micro chromosomes).
    """

    length: float
    kernel: str
    youngs_modulus: float
    poisson: float
    indices: np.ndarray
    complete: ResponseCurve
    chromosome_curves: tuple
    td_curves: tuple
    bu_curves: tuple
    c_chromosome: dict
    c_td: dict
    c_bu: dict
    success: bool
    message: str
    nit: int
    elapsed: float = 0.0
    references: tuple = field(default=("thesis Sec. 3.4.1, Fig. 36-39",))
    failed_chromosomes: tuple = ()

    def __post_init__(self):
        freeze_containers(self)

    def to_dict(self) -> dict:
        """JSON-safe curves and coefficients; the material under the one vocabulary of the
        package, ``E`` (Pa) and ``nu`` (-) (files before issue 15 wrote ``youngs_modulus``
        and ``poisson``: :meth:`from_dict` reads both); ``units`` names the unit of every
        number (:data:`MECHANICS_UNITS`; the curves' keys ``pressure``, ``stiffness``,
        ``area_fraction``)."""
        def curves(cs):
            return [None if c is None else c.to_dict() for c in cs]

        return {"length": self.length, "kernel": self.kernel, "E": self.youngs_modulus,
                "nu": self.poisson, "indices": self.indices.tolist(),
                "complete": self.complete.to_dict(), "chromosomes": curves(self.chromosome_curves),
                "td": curves(self.td_curves), "bu": curves(self.bu_curves),
                "c_chromosome": to_jsonable(self.c_chromosome), "c_td": to_jsonable(self.c_td),
                "c_bu": to_jsonable(self.c_bu), "success": self.success, "message": self.message,
                "nit": self.nit, "elapsed_s": self.elapsed,
                "failed_chromosomes": [int(n) for n in self.failed_chromosomes],
                "units": dict(MECHANICS_UNITS)}

    @classmethod
    def from_dict(cls, d) -> "ChromosomeMechanics":
        """Inverse of :meth:`to_dict` (a ``mechanics.json``); the old material keys
        ``youngs_modulus``/``poisson`` are accepted (files written before the rename)."""
        def curves(cs):
            return tuple(None if c is None else ResponseCurve.from_dict(c) for c in cs)

        def coefficients(c):
            return {q: np.array([np.nan if v is None else v for v in c[q]], float) for q in c}

        missing = [k for k in ("length", "kernel", "indices", "complete") if k not in d]
        material = [k for k in (("E", "youngs_modulus"), ("nu", "poisson"))
                    if not any(name in d for name in k)]
        if missing or material:
            raise FileFormatError(f"not a chromosome mechanics JSON: lacks {missing + material}")
        return cls(length=float(d["length"]), kernel=d["kernel"],
                   youngs_modulus=float(d["E"] if "E" in d else d["youngs_modulus"]),
                   poisson=float(d["nu"] if "nu" in d else d["poisson"]),
                   indices=np.asarray(d["indices"], int),
                   complete=ResponseCurve.from_dict(d["complete"]),
                   chromosome_curves=curves(d.get("chromosomes", ())),
                   td_curves=curves(d.get("td", ())), bu_curves=curves(d.get("bu", ())),
                   c_chromosome=coefficients(d.get("c_chromosome", {})),
                   c_td=coefficients(d.get("c_td", {})), c_bu=coefficients(d.get("c_bu", {})),
                   success=bool(d.get("success", True)), message=d.get("message", ""),
                   nit=int(d.get("nit", 0)), elapsed=float(d.get("elapsed_s", 0.0)),
                   failed_chromosomes=tuple(int(n) for n in d.get("failed_chromosomes", ())))


def sweep_fields(fields: dict, surface_of, response, label=None, workers: int = 1):
    """BEM curves of several height fields, one sweep each; the first field is the
    reference (the complete surface): its failure re-raises, since nothing compares
    without it.

    Parameters
    ----------
    fields : dict
        ``{key: heights}``.
    surface_of : callable
        ``heights -> Surface``.
    response : callable
        ``Surface -> ResponseCurve`` (a BEM sweep).
    label : str, optional
        Progress label (:func:`roughfe.progress.iterate`).
    workers : int
        Sweeps run at once, in threads (the sweeps are independent; the FFTs and the
        array arithmetic of the BEM release the GIL). The curves do not depend on it:
        each sweep is the same deterministic computation.

    Returns
    -------
    curves : dict
        ``{key: ResponseCurve or None}``: None for a flat field (no contact curve) and for
        a field whose sweep raised :class:`~roughfe.errors.NoConvergenceError`.
    failed : dict
        ``{key: message}`` of the sweeps that did not converge.
    n_sweeps : int
        Sweeps run (flat fields are not run; fields equal bit for bit are run once and
        share their curve, and their failure).
    """
    workers = int(workers)
    if workers < 1:
        raise InputError(f"workers must be an integer >= 1, got {workers!r}")
    first = next(iter(fields), None)
    flat, same = distinct_fields(fields)
    curves = {key: None for key in flat}
    todo = [key for key in same if same[key] == key]
    failed = {}

    def sweep(key):
        try:
            return key, response(surface_of(fields[key])), None
        except NoConvergenceError as exc:
            if key == first:
                raise
            return key, None, str(exc)

    with ThreadPoolExecutor(workers) if workers > 1 and len(todo) > 1 else \
            contextlib.nullcontext() as pool:
        runs = pool.map(sweep, todo) if pool is not None else map(sweep, todo)
        for key, curve, why in (progress.iterate(runs, label, len(todo)) if label else runs):
            curves[key] = curve
            if why is not None:
                failed[key] = why
    for key, first_key in same.items():
        curves[key] = curves[first_key]
        if first_key in failed:
            failed[key] = failed[first_key]
    return {key: curves[key] for key in fields}, failed, len(todo)


def distinct_fields(fields: dict) -> tuple:
    """``(flat, same)`` of ``{key: heights}``: the keys of the flat fields (no contact
    curve, judged against the largest height of the first field, the complete surface),
    and ``{key: first key of the same field}`` for the others. Identical fields are swept
    once (a partial sum across an empty band equals the sum before it, bit for bit: 44
    sweeps for 42 distinct fields on one profile): :func:`sweep_fields` runs the keys
    with ``same[key] == key``."""
    first = next(iter(fields), None)
    scale = float(np.max(np.abs(fields[first]))) if first is not None else 0.0
    flat = [key for key, z in fields.items() if is_flat(z, scale)]
    same, seen = {}, {}
    for key in fields:
        if key not in flat:
            z = np.ascontiguousarray(fields[key])
            digest = hashlib.blake2b(z, digest_size=20).digest()
            same[key] = seen.setdefault((z.shape, z.dtype.str, digest), key)
    return flat, same


def sweep_report(failed: dict, names) -> tuple:
    """``(success, message suffix)`` of :func:`sweep_fields`: success only when no sweep
    failed; ``names(key)`` labels a failed field."""
    if not failed:
        return True, ""
    labels = ", ".join(names(k) for k in failed)
    first = next(iter(failed.values()))
    return False, f"; {len(failed)} BEM sweep(s) did NOT converge ({labels}): {first}"


def correlations(complete, curves):
    """``{"K": c_n, "A": c_n}``: Pearson c_n of each curve with the complete one (Alg. 2,
    paired by loading step); NaN where a curve is None or constant (an undefined correlation,
    :func:`~roughfe.genomics.macro_micro.correlation`)."""
    out = {}
    for q in ("K", "A"):
        out[q] = np.array([np.nan if c is None else correlation(complete, c, q) for c in curves])
    return out


def chromosome_mechanics(genome: Genome, length=None, n_nodes=DEFAULT_NODES, *, scale=None,
                         youngs_modulus=THESIS_YOUNGS_MODULUS, poisson=0.0, kernel="thesis",
                         n_steps=20, max_chromosomes=None, partial_sums=True,
                         response=None) -> ChromosomeMechanics:
    """A(p), K(p) of a realisation, of each chromosome and of each TD and BU partial sum.

    Parameters
    ----------
    genome : Genome
    length : float, optional
        Observation length L (m); or ``scale`` ("10x", "20x", "100x").
    n_nodes : int
        Nodes N.
    youngs_modulus, poisson : float
        Elastic body (Pa, -); the thesis uses E* = 210 MPa.
    kernel : {"thesis", "strip", ...}
        BEM influence kernel (:func:`roughfe.bem.solve_contact`).
    n_steps : int
        Equal approaches up to each profile's peak-valley amplitude (20 in the thesis).
    max_chromosomes : int, optional
        Only the first ``max_chromosomes`` single-chromosome curves (the thesis shows 10).
    partial_sums : bool
        Also compute every TD and BU partial sum (2 n_c curves; TD_1 = C_1 and TD_n_c =
        the complete profile are swept once).
    response : callable, optional
        ``Surface -> ResponseCurve``; default :func:`response` with the above. A sweep
        that raises :class:`~roughfe.errors.NoConvergenceError` is reported (curve None,
        ``success`` False); one of the complete profile re-raises.
    """
    t0 = time.perf_counter()
    if (length is None) == (scale is None):
        raise InputError("give exactly one of length (m) or scale ('10x', '20x', '100x')")
    if scale is not None:
        length = genome.length_of(scale)
    if response is None:
        response = partial(profile_response, youngs_modulus=youngs_modulus, poisson=poisson,
                           n_steps=n_steps, kernel=kernel)
    td = reconstruction(genome, length, n_nodes, order="td")
    x0 = float(td.x[0])
    n_td = len(td.indices)
    k = n_td if max_chromosomes is None else max(1, min(int(max_chromosomes), n_td))
    fields = {"complete": td.complete}
    fields.update({("c", j): td.chromosomes[j] for j in range(k)})
    if partial_sums:
        bu = reconstruction(genome, length, n_nodes, order="bu")
        fields.update({("td", j): z for j, z in enumerate(td.partial_sums)})
        fields.update({("bu", j): z for j, z in enumerate(bu.partial_sums)})

    def surface_of(z):
        return Surface(z, n_nodes * length / (n_nodes - 1),
                       metadata={"x0": x0, "length": float(length)})
    curves, failed, nit = sweep_fields(fields, surface_of, response)
    complete = curves["complete"]
    if complete is None:
        raise InputError("the realisation is flat: no contact curve")
    chrom = tuple(curves[("c", j)] for j in range(k))
    td_c = tuple(curves[("td", j)] for j in range(n_td)) if partial_sums else ()
    bu_c = tuple(curves[("bu", j)] for j in range(n_td)) if partial_sums else ()
    ok, why = sweep_report(failed, lambda key: f"{key[0]} {int(td.indices[0]) + key[1]}"
                           if key[0] != "bu" else f"bu {int(td.indices[-1]) - key[1]}")
    return ChromosomeMechanics(
        length=float(length), kernel=kernel, youngs_modulus=float(youngs_modulus),
        poisson=float(poisson), indices=td.indices.copy(), complete=complete,
        chromosome_curves=chrom, td_curves=td_c, bu_curves=bu_c,
        c_chromosome=correlations(complete, chrom), c_td=correlations(complete, td_c),
        c_bu=correlations(complete, bu_c), success=ok,
        message=f"{nit} BEM sweeps ({kernel} kernel, {n_steps} steps each){why}", nit=nit,
        elapsed=time.perf_counter() - t0,
        failed_chromosomes=tuple(int(td.indices[0]) + key[1] for key in failed
                                 if key[0] == "c"))
