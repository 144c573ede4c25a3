"""Adhesive frictionless contact by the BEM: Maugis-Dugdale and exponential interface
laws in the gap-based formulation, loading and unloading branches, pull-off force.

Problem (SI; geometry and signs of :mod:`roughfe.bem.contact`)
--------------------------------------------------------------
The rigid rough surface h and the elastic half-space (profile: half-plane in plane
strain) interact through a potential phi(g) per unit area of the gap g >= 0,
``phi(0) = -w`` (w the work of adhesion, J/m^2), ``phi(inf) = 0``:

* Maugis-Dugdale (``"md"``) and exponential (``"exp"``) laws and their cell average:
  :mod:`roughfe.bem.interface_law` (:class:`AdhesionLaw`, re-exported here).

With the gap g (m), the elastic displacement u = g - c, ``c = max h - h - Delta``, and
the stiffness operator K = H^-1 (Pa/m) the total energy per nominal area is

    Pi(g) = (1/A) [ 1/2 u' K u + sum phi(g) ] dA,   g >= 0,                       (1)

whose stationary points are the equilibria: ``p = K u = -phi'(g)`` where g > 0 (tensile
where attractive), ``p = -phi'(0) + lambda``, ``lambda >= 0`` in contact (g = 0). The
total traction p (Pa, compressive > 0) is ``ContactResult.pressure``: unlike the
non-adhesive solver it is negative in the interaction zone.

Pi is not convex (phi is concave where the attraction decays), so an equilibrium depends
on the path: loading and unloading branches differ (hysteresis), and the pull-off force
is the most tensile load of the unloading branch.

Solver and continuation
-----------------------
Eq. (1) is minimised in the gap variable, scaled by the range (x = g / range), by the
compliance-preconditioned projected nonlinear CG of :mod:`roughfe.bem.adhesive_cg`
(default; two FFT pairs per iteration) or by L-BFGS-B (scipy; Byrd, Lu, Nocedal & Zhu
1995; ``solver="lbfgsb"``, and the hand-over when the CG stalls), with the gradient
scaled by the traction scale S = max(sigma0, E* gbar / 2) (gbar the rms slope: the
elastic pressure scale of the roughness), so that the stopping measure is the largest
projected traction residual over S (the ``residual``; default tolerance 1e-5). The
energy and its gradient cost two FFTs:

* periodic (``"spectral"``): K is the exact spectral stiffness E*|q|/2. An imposed
  Delta fixes the mean gap (mean u = 0, see :mod:`roughfe.bem.operators`); it is
  imposed through a stiff "machine" spring on the mean gap, ``k0/2 (mean g - gbar)^2``
  with ``k0`` = 10x the stiffest elastic mode, whose force is the mean pressure
  ``pbar = k0 (mean g - gbar)``; its rest length ``gbar`` is moved until the mean gap
  is the imposed one (an augmented Lagrangian, :mod:`roughfe.bem.adhesive_minimise`):
  every reported state is an equilibrium at the imposed Delta, the same for every k0
  (until round 2, session 32 it sat pbar/k0 off it, and could jump into full contact).
* non-periodic (``"strip"``, ``"love"``, ``"thesis"``): the DC-FFT operator lives on the
  zero-padded grid, where it is a positive definite circulant (all eigenvalues > 0,
  checked), so K is its exact inverse there. The unknowns are the gap on the grid and
  the displacement of the padding; stationarity makes the pressure vanish on the
  padding, so the solution is that of the isolated body.

The continuation in the approach (:func:`adhesive_sweep`) starts each step from the
previous state carried along its branch by the elastic tangent of its contact set (the
Euler predictor, :func:`roughfe.bem.adhesive_start.continued_start`; until round 2,
session 19 the previous gap shifted by the change of Delta): the minimiser then descends
to the nearest local minimum, which follows the stable branch until it disappears
(jump-in on loading, jump-out on unloading), as a quasi-static displacement-controlled
experiment does. On a law whose process zone the grid does not resolve the branch
breaks into a jump per cell and the path depends on the steps
(:func:`roughfe.bem.interface_law.check_resolution` warns). A solve that does
not reach the tolerance raises :class:`~roughfe.errors.NoConvergenceError` with the
residual.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import (InputError, NoConvergenceError, ResolutionWarning,
                      check_finite_positive, check_in_open_interval, check_instance,
                      check_int)
from ..model import ContactResult, Loading, Material, SweepResult
from ..surfaces.stats import rms_height, rms_slope
from ..surfaces.surface import Surface
from .contact import _choose_kernel, _operator
from .adhesive_energy import AdhesiveEnergy
from .adhesive_minimise import (MAX_SPREAD_PASSES, SOLVERS,  # noqa: F401
                                mean_gap_tolerance, minimise)
from .adhesive_pull_off import refine_pull_off, tensile_floor
from .adhesive_rules import check_adhesive_run
from .adhesive_start import continued_start, elastic_start
from .contact_checks import is_flat
from .patches import patch_width
from .interface_law import LAWS, AdhesionLaw, cell_relief, check_resolution, resolution

__all__ = ["LAWS", "AdhesionLaw", "AdhesiveSweep", "adhesive_sweep", "cell_compliance",
           "check_adhesive_objects", "solve_adhesive"]

REFERENCES = (
    "Maugis D. (1992) J. Colloid Interface Sci. 150:243-269 (Maugis-Dugdale law)",
    "Rey V., Anciaux G., Molinari J.-F. (2017) Comput. Mech. 60:69-81 (gap-based "
    "adhesive BEM)",
    "Byrd R.H., Lu P., Nocedal J., Zhu C. (1995) SIAM J. Sci. Comput. 16:1190-1208 "
    "(L-BFGS-B)",
)


def check_adhesive_objects(surface, material, law, law_name="law"):
    """Raise :class:`InputError` unless ``surface``, ``material`` and ``law`` (called
    ``law_name`` in the message: ``adhesion`` for :func:`roughfe.response.response`) are a
    :class:`Surface`, a :class:`Material` and an :class:`AdhesionLaw`."""
    check_instance("surface", surface, Surface, "a roughfe Surface")
    check_instance("material", material, Material, "a roughfe.model.Material")
    check_instance(law_name, law, AdhesionLaw, "an AdhesionLaw")


def _check(surface, material, law, delta):
    check_adhesive_objects(surface, material, law)
    try:
        d = float(delta)
    except (TypeError, ValueError):
        raise InputError(f"delta must be a number of metres, got {delta!r}") from None
    if not np.isfinite(d):
        raise InputError(f"delta (approach, m; negative = apart) must be finite, got {delta!r}")
    return d


def _check_below_full_contact(surface, periodic, delta):
    """Raise :class:`InputError` when the approach ``delta`` (m; the largest of a sweep)
    reaches max h - mean h on a ``periodic`` kernel: with zero mean displacement that is
    full contact, where the adhesive state is not defined by the approach."""
    h = surface.heights
    top = float(h.max() - h.mean())
    if periodic and delta >= top:
        raise InputError(f"delta = {delta:.6g} m reaches max h - mean h = {top:.6g} m: on a "
                         f"periodic surface (zero mean displacement) that is full contact, "
                         f"where the adhesive state is not defined by the approach; stay "
                         f"below it")


def _check_unloading(unload_growth, max_unload_steps, n_loading):
    """``(growth, extra)`` of :func:`adhesive_sweep`'s unloading controls, or
    :class:`InputError`: ``unload_growth`` a finite factor >= 1, ``max_unload_steps`` an
    integer >= 0 (None: 4 x the ``n_loading`` loading steps)."""
    try:
        growth = float(unload_growth)
    except (TypeError, ValueError):
        growth = float("nan")
    if not (np.isfinite(growth) and growth >= 1.0):
        raise InputError(f"unload_growth must be a finite factor >= 1, got {unload_growth!r}")
    extra = 4 * n_loading if max_unload_steps is None else check_int(
        "max_unload_steps", max_unload_steps, 0)
    return growth, extra


def solve_adhesive(surface: Surface, material: Material, law: AdhesionLaw, *, delta,
                   kernel: str = "auto", initial=None, tol: float = 1e-5,
                   max_iter: int = 20000, spring=None, unloading: bool = False,
                   cell_average: bool = True, solver: str = "pcg") -> ContactResult:
    """Equilibrium of the adhesive contact at the approach ``delta`` (Eq. (1)).

    Parameters
    ----------
    surface : Surface
        Profile (plane strain) or surface; heights in m.
    material : Material
        Elastic body (E* in Pa).
    law : AdhesionLaw
        Interface law.
    delta : float
        Approach from first contact of the highest point (m); negative: apart.
    kernel : str
        As in :func:`roughfe.bem.solve_contact`.
    initial : ContactResult, optional
        A previous adhesive state, carried to ``delta`` by the elastic tangent of its
        contact set, starts the descent (the continuation of :func:`adhesive_sweep`;
        :func:`roughfe.bem.adhesive_start.continued_start`). Without it the descent
        starts from the non-adhesive equilibrium at ``delta`` (Polonsky-Keer).
    tol : float
        Largest projected traction residual, relative to S = max(sigma0, E* gbar / 2).
    max_iter : int
        Iterations (CG and L-BFGS-B together).
    spring : float, optional
        Periodic only: stiffness k0 (Pa/m, finite and > 0) of the spring imposing the
        mean gap (the penalty of an augmented Lagrangian: the state does not depend on
        it); default 10x the stiffest elastic mode. Refused with a non-periodic kernel,
        which has no such spring.
    unloading : bool
        The branch stored in the result (``ContactResult.unloading``).
    cell_average : bool
        Maugis-Dugdale: evaluate the law averaged over each cell
        (:mod:`roughfe.bem.interface_law`); False samples it at the cell centres.
    solver : {"pcg", "lbfgsb"}
        Preconditioned projected nonlinear CG (:mod:`roughfe.bem.adhesive_cg`; it hands
        over to L-BFGS-B if it stalls) or L-BFGS-B alone.

    Returns
    -------
    ContactResult
        ``pressure`` is the total traction (Pa, < 0 where tensile), ``contact`` the
        points at g = 0, ``adhesive_area_fraction`` the fraction with tensile traction,
        ``unloading`` the branch; ``stiffness`` is not computed (NaN).

    Raises
    ------
    InputError
        Bad input.
    NoConvergenceError
        The residual stayed above ``tol``, or (periodic) the mean gap missed the imposed
        approach (:func:`~roughfe.bem.adhesive_minimise.mean_gap_tolerance`); ``result``
        holds the last state.

    Warns
    -----
    ResolutionWarning
        The law's process zone spans fewer grid spacings than it needs
        (``check_resolution``, ``AdhesionLaw.resolution_cells``).
    """
    d = _check(surface, material, law, delta)
    if solver not in SOLVERS:
        raise InputError(f"solver must be one of {SOLVERS}, got {solver!r}")
    tol = check_in_open_interval("tol (relative traction residual)", tol, 0.0, 1.0)
    max_iter = check_int("max_iter", max_iter, 1)
    kernel = _choose_kernel(surface, kernel)
    op = _operator(surface.shape, surface.size, material.E_star, kernel)
    if spring is not None:
        if not op.periodic:
            raise InputError(f"spring (the mean-gap spring, Pa/m) applies to the periodic "
                             f"kernel 'spectral' only; kernel {kernel!r} has none: leave "
                             f"it None (got spring={spring!r})")
        spring = check_finite_positive("spring (stiffness of the mean-gap spring, Pa/m)",
                                       spring)
    check_resolution(law, material.E_star, surface.spacing, cell_compliance(
        surface, material.E_star, kernel), cell_relief(surface.heights))
    _check_below_full_contact(surface, op.periodic, d)
    h = surface.heights
    c = float(h.max()) - h - d
    scale = max(law.max_traction, 0.5 * material.E_star * rms_slope(surface))
    energy = AdhesiveEnergy(op, law, c, spring, scale)
    if initial is not None:
        check_instance("initial", initial, ContactResult,
                       "a ContactResult of a previous adhesive solve (or None)")
        x0 = continued_start(initial, d, op, energy)
    else:
        x0 = elastic_start(surface, material, op, d, c, energy)
    x0 = np.maximum(x0 / law.range, energy.bounds().lb.reshape(x0.shape)).ravel()
    averaged = bool(cell_average) and law.kind == "md"
    if averaged:
        energy.spread = energy.cell_spread(x0)
    x, nit, r, message, miss = minimise(energy, x0, law, tol, max_iter, solver, averaged)
    out = _adhesive_result(surface, material, op, law, energy, x, d, r, tol, nit,
                           bool(unloading), solver)
    if not r <= tol:          # (a NaN residual is not converged)
        raise NoConvergenceError(
            f"adhesive solver ({solver}) did not converge: traction residual {r:.3e} "
            f"(relative to {scale:.3e} Pa) after {nit} iterations ({message}), tolerance "
            f"{tol:.1e}", result=out)
    if op.periodic and not abs(miss) <= mean_gap_tolerance(energy, tol):
        raise NoConvergenceError(
            f"adhesive solver ({solver}): the imposed approach delta = {d:.6g} m was not "
            f"met: the state's mean gap is off by {miss:.3e} m (tolerance "
            f"{mean_gap_tolerance(energy, tol):.1e} m) after {nit} iterations; "
            f"result.delta is its approach", result=out)
    return out


def cell_compliance(surface: Surface, e_star: float, kernel: str = "auto") -> float:
    """The self-compliance of one cell of ``surface``'s grid, H_ii E*/dx (the centre
    displacement under a uniform pressure p on the cell, in p dx / E*; dx the largest
    spacing): the measure of :meth:`AdhesionLaw.resolution_cells`. 1.12 on a square cell
    of a surface; 3-7 on a profile (growing as log n)."""
    kernel = _choose_kernel(surface, kernel)
    op = _operator(surface.shape, surface.size, float(e_star), kernel)
    return float(op.diagonal * op.e_star / max(surface.spacing))


def _adhesive_result(surface, material, op, law, energy, x, delta, resid, tol, nit,
                     unloading, solver):
    p, pbar, g, u, _ = energy.pressure(x)
    h = surface.heights
    g = np.maximum(g, 0.0)
    contact = g <= 0.0
    n = g.size
    nc = int(contact.sum())
    pm = float(p.mean())
    if op.periodic:   # the approach this equilibrium belongs to (mean u = 0)
        delta = float(h.max() - h.mean() - g.mean())
        disp = u - u.mean()
        fields = None
    else:
        disp = u[energy.phys]
        fields = {"padded_displacement": x.reshape(energy.shape) * law.range}
    sigma = rms_height(surface)
    mean_gap = float(g.mean())
    return ContactResult(
        pressure=p, displacement=disp, gap=g, contact=contact, delta=delta,
        load=pm * surface.nominal_area, mean_pressure=pm, area_fraction=nc / n,
        contact_area=nc * surface.cell_area, n_contact=nc, mean_gap=mean_gap,
        mean_plane_separation=float(h.max() - h.mean() - delta),
        free_volume=float(g.sum()) * surface.cell_area,
        free_volume_star=mean_gap / sigma if sigma > 0 else float("nan"),
        stiffness=float("nan"),
        message=f"{'unloading' if unloading else 'loading'} ({law.kind}, {solver})", nit=nit,
        residual=float(resid), tolerance=float(tol), kernel=op.name,
        solver=f"adhesive-{solver}-{law.kind}", e_star=material.E_star, rms_height=sigma,
        size=tuple(surface.size), spacing=tuple(surface.spacing), periodic=op.periodic,
        references=REFERENCES + op.references, method="bem", unloading=unloading,
        adhesive_area_fraction=float(np.count_nonzero(p < 0)) / n, fields=fields,
        patch_width=patch_width(contact, p, periodic=op.periodic))


@dataclass(frozen=True, eq=False)
class AdhesiveSweep:
    """Loading (and unloading) branches of an adhesive contact (SI).

    Attributes
    ----------
    sweep : SweepResult
        Every step in order (loading, then unloading); each ContactResult has
        ``unloading`` (``sweep.unloading`` per step, 1.0 on unloading); with ``unload``
        it carries the three values below too.
    pull_off_force : float
        Most tensile load of the unloading branch (N for surfaces, N/m for profiles;
        negative), NaN without unloading, 0 when no load of the branch is tensile beyond
        what the solves resolve (``tol`` of the largest |load|,
        :func:`~roughfe.bem.adhesive_pull_off.tensile_floor`): that of this
        load path (independent of the step, more tensile the larger the largest loading
        approach).
    pull_off_pressure : float
        The same as a mean pressure (Pa).
    detached : bool
        The unloading reached separation (no contact, load back above 1e-3 of the
        pull-off load); if False the pull-off force is a bound (the branch was cut).
    law : AdhesionLaw
    resolution : dict
        The law's process zone against the grid
        (:func:`roughfe.bem.interface_law.resolution`; ``resolved`` False where the
        solves warned).
    """

    sweep: SweepResult
    pull_off_force: float
    pull_off_pressure: float
    detached: bool
    law: AdhesionLaw
    resolution: dict = None

    def records(self) -> list:
        """Per-step records (``sweep.to_records()``: with ``unloading`` and
        ``adhesive_area_fraction``)."""
        return self.sweep.to_records()


def adhesive_sweep(surface: Surface, material: Material, law: AdhesionLaw, deltas=None, *,
                   n_steps=None, unload: bool = False, max_unload_steps=None,
                   unload_growth: float = 2.0, kernel: str = "auto", tol: float = 1e-5,
                   max_iter: int = 20000, spring=None) -> AdhesiveSweep:
    """Continuation in the approach: loading through ``deltas`` and, with ``unload``,
    back down past them until the surfaces separate (see the module docstring).

    Parameters
    ----------
    deltas : sequence of float, optional
        Strictly increasing approaches (m) of the loading branch (``unload`` traces the
        unloading branch; approaches in another order are refused).
    n_steps : int, optional
        Instead of ``deltas``: that many equispaced approaches, k / n of the
        peak-to-valley height, or with a periodic kernel k / (n + 1) of max h - mean h
        (k = 1..n: full contact itself is left out, where the adhesive state is not
        defined by the approach; :func:`roughfe.bem.sweep.default_deltas` gives the
        non-adhesive sweep's); ``Loading.DEFAULT_STEPS`` when neither is given. The one
        place where ``response(..., adhesion=)`` and ``roughfe contact --adhesion`` get
        their default approaches.
    unload : bool
        Also trace the unloading branch: the loading approaches in reverse, then further
        apart until separation (at most ``max_unload_steps`` solves beyond the loading
        range, default 4 x the loading steps; 0: none). The pull-off force is the most
        tensile load of the branch, its starting state at the largest approach included,
        with the steps on both sides of it bisected down to a quarter of the law's range
        (:func:`~roughfe.bem.adhesive_pull_off.refine_pull_off`: at most 8 more solves;
        the sampled minimum alone read 11 % short on a Maugis-Dugdale sphere).
    unload_growth : float
        Step control beyond the loading range: the step is the last loading step while
        each state is more tensile than every earlier one (the approach to the pull-off
        is sampled at the loading resolution, in displacement control), and grows by
        this factor per step once the load recovers from its minimum (the separation
        tail: in a periodic cell the last patches peel off over a mean-gap opening of
        order ``|pull-off pressure| L / E*``, far beyond the loading range). 1 keeps
        the step fixed. Must be >= 1.
    Other parameters as in :func:`solve_adhesive`.
    """
    check_adhesive_objects(surface, material, law)
    if deltas is None:
        from .memory import check_sweep_memory
        from .sweep import default_deltas
        n_steps = Loading(n_steps=n_steps).n_steps     # checked, default 20
        periodic = surface.periodic and kernel in ("auto", "spectral")
        check_sweep_memory(surface.shape, n_steps, periodic=periodic)
        if is_flat(surface):      # (the BEM's rule) it said "deltas must be strictly increasing"
            raise InputError("the surface is flat (constant heights): its height range "
                             "gives no approaches for n_steps; give the approaches (m)")
        deltas = default_deltas(surface, n_steps + periodic, periodic)[:n_steps]
    elif n_steps is not None:
        raise InputError(f"give deltas or n_steps, not both (got n_steps={n_steps!r})")
    try:
        deltas = np.atleast_1d(np.asarray(deltas, float))
    except (TypeError, ValueError):
        raise InputError(f"deltas must be a non-empty sequence of finite approaches (m), "
                         f"got {deltas!r}") from None
    if deltas.ndim != 1 or deltas.size == 0 or not np.all(np.isfinite(deltas)):
        raise InputError(f"deltas must be a non-empty sequence of finite approaches (m), "
                         f"got {deltas!r}")
    check_adhesive_run(deltas=deltas)
    growth, extra = _check_unloading(unload_growth, max_unload_steps, deltas.size)
    op = _operator(surface.shape, surface.size, material.E_star, _choose_kernel(surface, kernel))
    _check_below_full_contact(surface, op.periodic, float(deltas.max()))
    grid = (law, material.E_star, surface.spacing,
            cell_compliance(surface, material.E_star, kernel), cell_relief(surface.heights))
    check_resolution(*grid)   # once for the sweep
    with warnings.catch_warnings():       # not again at every step
        warnings.simplefilter("ignore", ResolutionWarning)
        results = []
        prev = None
        for d in deltas:
            prev = solve_adhesive(surface, material, law, delta=d, kernel=kernel, initial=prev,
                                  tol=tol, max_iter=max_iter, spring=spring, unloading=False)
            results.append(prev)
        pull, detached = float("nan"), False
        if unload:
            step = float(deltas[-1] - deltas[-2]) if deltas.size > 1 else float(abs(deltas[0]))
            step = step if step > 0 else law.range
            # the branch starts at the largest approach: its state (often the most
            # tensile of a sticky contact) is the first of the unloading loads (it was
            # left out, and the pull-off read up to 4 % short, converging with the step)
            loads = [prev.load]

            imposed = list(deltas)

            def unloaded(d, initial):
                return solve_adhesive(surface, material, law, delta=d, kernel=kernel,
                                      initial=initial, tol=tol, max_iter=max_iter,
                                      spring=spring, unloading=True)

            def unload_to(d):
                state = unloaded(d, prev)
                results.append(state)
                imposed.append(d)
                loads.append(state.load)
                return state

            for d in deltas[-2::-1]:              # the loading approaches in reverse
                prev = unload_to(d)
            d, h = float(deltas[0]), step
            for _ in range(extra):
                low = min(loads) if loads else float("inf")
                d -= h
                prev = unload_to(d)
                tensile = min(loads) < -tensile_floor(loads, tol)   # resolved
                if prev.n_contact == 0 and (not tensile or prev.load > 1e-3 * min(loads)):
                    detached = True        # separated (without a tensile state: pull 0)
                    break
                h = step if prev.load < low else growth * h
            # the most tensile state between samples (refine_pull_off): bisected steps
            # around the minimum, down to a quarter of the law's range
            top, pull = deltas.size - 1, 0.0
            if min(loads) < -tensile_floor(loads, tol):
                branch = refine_pull_off(list(zip(imposed[top:], results[top:])), unloaded,
                                         0.25 * law.range)
                results[top:] = [state for _, state in branch]
                pull = float(min(state.load for _, state in branch))
    whole = dict(pull_off_force=pull, pull_off_pressure=pull / surface.nominal_area,
                 detached=detached)       # the sweep carries them when they were traced
    sweep = SweepResult.from_results(results, rms_slope=rms_slope(surface),
                                     length=surface.size[0], **(whole if unload else {}))
    return AdhesiveSweep(sweep=sweep, law=law, resolution=resolution(*grid), **whole)
