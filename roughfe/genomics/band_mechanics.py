"""Contact mechanics of band chromosomes and their partial sums (thesis Sec. 3.4, Alg. 2, on any surface).

The thesis computes, for a WM profile, the A(p) and K(p) curves of every chromosome, of every
top-down (TD) and bottom-up (BU) partial sum, and the correlation c_n of each with the
complete profile (Fig. 36-39), then splits the chromosomes into macro- and micro-scale
roughness by c_n of K(p) (Alg. 2). :func:`band_mechanics` does the same for the band
chromosomes of :mod:`roughfe.genomics.bands`, so it runs on measured topographies and on
2D surfaces with the surface BEM: each partial sum is its own rigid rough surface, loaded in
``n_steps`` equal approaches up to its own peak-to-valley height (periodic: up to full
contact), exactly as :func:`roughfe.genomics.macro_micro.profile_response` loads a profile.

Duplicated sweeps are not run twice: TD_1 = C_1 and BU_1 = C_{n_c}. The sum of all
bands TD_{n_c} is swept as its own surface (one sweep more than taking the complete
surface's curve: 37 sweeps instead of 36 for each measured file of the surface-genomics
study, ~0.08 s CPU of ~4 s at 48^2), so its c_n checks the decomposition through the
contact response instead of correlating the complete curve with itself; BU_{n_c} is the
same bands summed in reverse order (round-off apart) and shares that curve. Empty bands (no transform bin, e.g. band 2 of a strongly anisotropic
grid) and flat partial sums have no curve (None) and c_n = NaN. The result is the one
:class:`~roughfe.genomics.mechanics.ChromosomeMechanics` of the profile mechanics (``length``
= the larger side of the surface, m).
"""
from __future__ import annotations

import time
from typing import Callable, Optional

from ..errors import InputError
from ..surfaces.surface import Surface
from .bands import REFERENCES as BAND_REFERENCES, BandChromosomes
from .macro_micro import MacroMicroResult, classify, profile_response
from .mechanics import ChromosomeMechanics, correlations, sweep_fields, sweep_report
from .similarity import ResponseCurve

REFERENCES = BAND_REFERENCES + ("thesis Sec. 3.4.1, Fig. 36-39 and Alg. 2, on band chromosomes",)


def band_fields(bands: BandChromosomes) -> dict:
    """The height fields :func:`band_mechanics` sweeps: the complete surface, each
    chromosome, TD sums 2..n_c (the last: the sum of all bands, swept as its own surface)
    and BU sums 2..n_c-1 (TD_1 = C_1 and BU_1 = C_{n_c} are not repeated)."""
    chrom, n_c = bands.chromosomes, bands.n_chromosomes
    td, bu = bands.partial_sums("td"), bands.partial_sums("bu")
    jobs = {"complete": bands.surface.heights}
    jobs.update({("c", k): chrom[k] for k in range(n_c)})
    jobs.update({("td", k): td[k] for k in range(1, n_c)})
    jobs.update({("bu", k): bu[k] for k in range(1, n_c - 1)})
    return jobs


def band_mechanics(bands: BandChromosomes, *, youngs_modulus: float, poisson: float = 0.0,
                   n_steps: int = 20, kernel: str = "auto",
                   response: Optional[Callable[[Surface], ResponseCurve]] = None,
                   workers: int = 2) -> ChromosomeMechanics:
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
    workers : int
        Sweeps run at once (threads, :func:`~roughfe.genomics.mechanics.sweep_fields`):
        the default 2 uses both cores of the issue 15 target machine; the curves are the
        same for any value.

    Progress is reported through :func:`roughfe.progress.iterate` ("band sweeps").
    """
    if int(n_steps) < 3:
        # K(p) is the central difference over the steps (sweep_curve "fd"): two steps give
        # one secant, every K curve flat, every c_n of Alg. 2 zero (all bands "micro",
        # reported as a success: a user's review, round 2, session 28)
        raise InputError(f"n_steps must be >= 3: K(p) is differenced over the steps, and "
                         f"{n_steps!r} give(s) at most one secant (every K curve flat, c_n "
                         f"undefined), got {n_steps!r}")
    if response is None:
        def response(s):
            return profile_response(s, youngs_modulus=youngs_modulus, poisson=poisson,
                                    n_steps=int(n_steps), kernel=kernel)
    t0 = time.perf_counter()
    n_c = bands.n_chromosomes
    curves, failed, done = sweep_fields(band_fields(bands), bands.as_surface, response,
                                        "band sweeps",
                                        workers=workers)
    complete = curves["complete"]
    if complete is None:
        raise InputError("the surface is flat: no contact curve")
    c_curves = tuple(curves[("c", k)] for k in range(n_c))

    def sums(kind, first_key):
        if n_c == 1:                    # the one band is the sum of all bands
            return c_curves
        # both end on the sum of all bands, swept as its own surface (TD key n_c - 1)
        return ((curves[first_key],) + tuple(curves[(kind, k)] for k in range(1, n_c - 1))
                + (curves[("td", n_c - 1)],))
    # a TD key k is the sum ending at band indices[k]; a BU key k the sum ending at
    # indices[-1 - k] (it was labelled indices[k]: "bu 4" for the sum ending at band 7)
    ok, why = sweep_report(failed, lambda key: key if isinstance(key, str) else
                           f"bu {int(bands.indices[-1 - key[1]])}" if key[0] == "bu" else
                           f"{key[0]} {int(bands.indices[key[1]])}")
    td_curves = sums("td", ("c", 0))
    bu_curves = sums("bu", ("c", n_c - 1))
    return ChromosomeMechanics(
        length=float(max(bands.surface.size)), kernel=kernel,
        youngs_modulus=float(youngs_modulus), poisson=float(poisson), indices=bands.indices,
        complete=complete, chromosome_curves=c_curves, td_curves=td_curves,
        bu_curves=bu_curves, c_chromosome=correlations(complete, c_curves),
        c_td=correlations(complete, td_curves), c_bu=correlations(complete, bu_curves),
        success=ok, message=f"{done} BEM sweeps of {n_steps} steps ({n_c} bands){why}", nit=done,
        elapsed=time.perf_counter() - t0, references=REFERENCES,
        failed_chromosomes=tuple(int(bands.indices[key[1]]) for key in failed
                                 if not isinstance(key, str) and key[0] == "c"))


def band_macro_micro(mech: ChromosomeMechanics, threshold: float = 0.95,
                     axis: str = "steps") -> MacroMicroResult:
    """Alg. 2 on band chromosomes: macro = bands whose K(p) correlates with the complete
    K(p) by c_n > ``threshold``; empty/flat bands count as micro (c_n undefined). A band
    whose sweep did not converge (``mech.failed_chromosomes``) is in neither: it is not
    classified and ``success`` is False (it was counted as a flat micro band, 31 % of
    <h^2> in a measured case)."""
    keep = [k for k, c in enumerate(mech.chromosome_curves) if c is not None]
    res = classify(mech.complete, [mech.chromosome_curves[k] for k in keep],
                   mech.indices[keep], threshold, axis)
    failed = tuple(sorted(int(n) for n in mech.failed_chromosomes))
    flat = tuple(int(mech.indices[k]) for k, c in enumerate(mech.chromosome_curves)
                 if c is None and int(mech.indices[k]) not in failed)
    if not flat and not failed:
        return res
    message = res.message + (f" ({len(flat)} flat bands counted as micro)" if flat else "")
    if failed:
        message += (f"; band(s) {', '.join(map(str, failed))} NOT classified: their BEM "
                    f"sweep did not converge")
    return MacroMicroResult(res.chromosomes, res.curve, res.chromosome_curves, res.corr_k,
                            res.corr_a, res.threshold, res.macro,
                            tuple(sorted(res.micro + flat)), res.success and not failed,
                            message, res.nit)
