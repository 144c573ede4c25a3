"""Contact mechanics of band chromosomes and their partial sums (thesis Sec. 3.4, Alg. 2, on any surface).

The thesis computes, for a WM profile, the A(p) and K(p) curves of every chromosome, of every
top-down (TD) and bottom-up (BU) partial sum, and the correlation c_n of each with the
complete profile (Fig. 36-39), then splits the chromosomes into macro- and micro-scale
roughness by c_n of K(p) (Alg. 2). :func:`band_mechanics` does the same for the band
chromosomes of :mod:`roughfe.genomics.bands`, so it runs on measured topographies and on
2D surfaces with the surface BEM: each partial sum is its own rigid rough surface, loaded in
``n_steps`` equal approaches up to its own peak-to-valley height (periodic: up to full
contact), exactly as :func:`roughfe.genomics.macro_micro.profile_response` loads a profile.

Duplicated sweeps are not run twice: TD_1 = C_1, BU_1 = C_{n_c} and TD_{n_c} = BU_{n_c} =
the complete surface. Empty bands (no transform bin, e.g. band 2 of a strongly anisotropic
grid) and flat partial sums have no curve (None) and c_n = NaN.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np

from .. import progress
from ..errors import InputError
from ..frozen import freeze_containers
from ..surfaces.surface import Surface
from ..writers import to_jsonable
from .bands import BandChromosomes
from .macro_micro import MacroMicroResult, classify, correlation, profile_response
from .similarity import ResponseCurve


@dataclass(frozen=True, eq=False)
class BandMechanics:
    """A(p), K(p) of a surface, its band chromosomes and their TD/BU partial sums.

    Attributes
    ----------
    indices : ndarray of int
        Chromosome numbers n = 1..n_c (band 1 = longest waves).
    complete : ResponseCurve
        The whole (detrended) surface.
    chromosome_curves, td_curves, bu_curves : tuple of (ResponseCurve or None)
        Curve of C_n (order n = 1..n_c); of TD sum C_1 + ... + C_n (same order); of BU
        sum C_{n_c} + ... + C_n (order n = n_c, n_c - 1, ..., 1). None: flat, no contact.
    c_chromosome, c_td, c_bu : mapping
        ``{"K": ndarray, "A": ndarray}`` Pearson c_n of each curve with the complete one
        (Alg. 2, paired by loading step); NaN where the curve is None.
    youngs_modulus, poisson : float
        Elastic body (Pa, -).
    n_steps : int
    nit : int
        Number of BEM sweeps run.
    elapsed : float
        Wall time (s).
    """

    indices: np.ndarray
    complete: ResponseCurve
    chromosome_curves: tuple
    td_curves: tuple
    bu_curves: tuple
    c_chromosome: dict
    c_td: dict
    c_bu: dict
    youngs_modulus: float
    poisson: float
    n_steps: int
    nit: int
    elapsed: float
    success: bool = True
    message: str = ""

    def __post_init__(self):
        freeze_containers(self)

    def to_dict(self) -> dict:
        """JSON-ready curves and coefficients (NaN -> None)."""
        def curves(cs):
            return [None if c is None else c.to_dict() for c in cs]

        return {"indices": [int(n) for n in self.indices], "complete": self.complete.to_dict(),
                "chromosomes": curves(self.chromosome_curves), "td": curves(self.td_curves),
                "bu": curves(self.bu_curves), "c_chromosome": to_jsonable(self.c_chromosome),
                "c_td": to_jsonable(self.c_td), "c_bu": to_jsonable(self.c_bu),
                "youngs_modulus": self.youngs_modulus, "poisson": self.poisson,
                "n_steps": self.n_steps, "nit": self.nit, "elapsed_s": self.elapsed,
                "success": self.success, "message": self.message}


def _is_flat(z) -> bool:
    return np.ptp(z) <= 1e-12 * max(float(np.max(np.abs(z))), 1e-300)


def _coeffs(complete, curves):
    return {q: np.array([np.nan if c is None else correlation(complete, c, q) for c in curves])
            for q in ("K", "A")}


def band_mechanics(bands: BandChromosomes, *, youngs_modulus: float, poisson: float = 0.0,
                   n_steps: int = 20, kernel: str = "auto",
                   response: Optional[Callable[[Surface], ResponseCurve]] = None
                   ) -> BandMechanics:
    """BEM curves of every band chromosome and TD/BU partial sum (see the module notes).

    Parameters
    ----------
    bands : BandChromosomes
        From :func:`roughfe.genomics.bands.band_chromosomes`.
    youngs_modulus, poisson : float
        E (Pa) and nu of the elastic body (the rough surface is rigid).
    n_steps : int
        Equal approaches per curve (20 as in the thesis).
    kernel : str
        BEM kernel (``"auto"``: spectral if periodic, strip/love otherwise).
    response : callable, optional
        ``Surface -> ResponseCurve``; default the BEM sweep of
        :func:`~roughfe.genomics.macro_micro.profile_response` with the above.

    Progress is reported through :func:`roughfe.progress.iterate` ("band sweeps").
    """
    if int(n_steps) < 2:
        raise InputError(f"n_steps must be >= 2 (a curve needs two points), got {n_steps!r}")
    if response is None:
        def response(s):
            return profile_response(s, youngs_modulus=youngs_modulus, poisson=poisson,
                                    n_steps=int(n_steps), kernel=kernel)
    t0 = time.perf_counter()
    chrom = bands.chromosomes
    td = bands.partial_sums("td")
    bu = bands.partial_sums("bu")
    n_c = bands.n_chromosomes
    # unique height fields: the complete surface, each chromosome, TD/BU sums 2..n_c-1
    jobs = {"complete": bands.surface.heights}
    jobs.update({("c", k): chrom[k] for k in range(n_c)})
    jobs.update({("td", k): td[k] for k in range(1, n_c - 1)})
    jobs.update({("bu", k): bu[k] for k in range(1, n_c - 1)})
    curves = {key: None for key, z in jobs.items() if _is_flat(z)}
    todo = [key for key in jobs if key not in curves]
    for key in progress.iterate(todo, "band sweeps"):
        curves[key] = response(bands.as_surface(jobs[key]))
    done = len(todo)
    complete = curves["complete"]
    if complete is None:
        raise InputError("the surface is flat: no contact curve")
    c_curves = tuple(curves[("c", k)] for k in range(n_c))

    def sums(kind, first_key):
        out = [curves[first_key]] + [curves[(kind, k)] for k in range(1, n_c - 1)]
        return tuple(out + [complete]) if n_c > 1 else (complete,)
    td_curves = sums("td", ("c", 0))
    bu_curves = sums("bu", ("c", n_c - 1))
    return BandMechanics(
        indices=bands.indices, complete=complete, chromosome_curves=c_curves,
        td_curves=td_curves, bu_curves=bu_curves, c_chromosome=_coeffs(complete, c_curves),
        c_td=_coeffs(complete, td_curves), c_bu=_coeffs(complete, bu_curves),
        youngs_modulus=float(youngs_modulus), poisson=float(poisson), n_steps=int(n_steps),
        nit=done, elapsed=time.perf_counter() - t0,
        message=f"{done} BEM sweeps of {n_steps} steps ({n_c} bands)")


def band_macro_micro(mech: BandMechanics, threshold: float = 0.95,
                     axis: str = "steps") -> MacroMicroResult:
    """Alg. 2 on band chromosomes: macro = bands whose K(p) correlates with the complete
    K(p) by c_n > ``threshold``; empty/flat bands count as micro (c_n undefined)."""
    keep = [k for k, c in enumerate(mech.chromosome_curves) if c is not None]
    res = classify(mech.complete, [mech.chromosome_curves[k] for k in keep],
                   mech.indices[keep], threshold, axis)
    flat = tuple(int(mech.indices[k]) for k, c in enumerate(mech.chromosome_curves) if c is None)
    if not flat:
        return res
    return MacroMicroResult(res.chromosomes, res.curve, res.chromosome_curves, res.corr_k,
                            res.corr_a, res.threshold, res.macro,
                            tuple(sorted(res.micro + flat)), res.success,
                            res.message + f" ({len(flat)} flat bands counted as micro)", res.nit)
