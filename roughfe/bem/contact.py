"""Frictionless normal contact of a rigid rough surface on an elastic half-space by the
BEM (thesis Sec. 2.2, Eq. 2.3-2.8): :func:`solve_contact` -> :class:`ContactResult`.

Geometry and signs (SI): heights h (m, axis 0 = x) point towards the elastic body; the
flat elastic half-space first touches the highest point (Delta = 0) and is then pushed
by the far-field approach Delta (m). Pressure p >= 0 is compressive; the displacement
u = H p (m) of the half-space surface points away from the rough surface; the gap is

    g = u + max(h) - h - Delta >= 0,      p g = 0.

The mean plane separation is d = max(h) - mean(h) - Delta (the distance between the
undeformed flat and the mean plane of the rough surface, as in Greenwood-Williamson
and Paggi & He 2015); with the periodic kernel mean(u) = 0, so d equals the mean gap.
"""
from __future__ import annotations

import dataclasses
import functools
import warnings
from typing import Optional

import numpy as np
import scipy.fft

from ..caching import MB, bytes_bounded_cache
from ..errors import InputError, NoConvergenceError, check_instance, check_int, check_real_array
from ..surfaces.stats import rms_height
from ..surfaces.surface import Surface
from ..model import ContactResult, Material
from .operators import (WORKERS, InfluenceOperator, _irfftn_owned, check_kernel_name,
                        influence_operator)
from .approach import MAX_START_AREA, approach_by_load, approach_start
from .periodic import periodic_bounded_displacement, periodic_full_contact, periodic_gap_control
from .coarse_start import CORRECTION_MIN_PARTS, _coarse_start, _contact_parts
from .contact_checks import (_check_coarse_correction, _check_hardness, _check_surface,
                             _check_target, _check_tol)
from .deflation import BlockDeflation
from .memory import check_solve_memory
from .padded_deflation import PaddedBlockDeflation
from .patches import patch_width, rim_width
from .pk import polonsky_keer
from .solvers import SolverOutput, dense_solve
from .stiffness import exact_stiffness

SOLVERS = ("auto", "dense", "nnls", "pk")
#: largest number of grid points solved with the dense solvers by ``solver="auto"``
#: (measured: a 20-step sweep of a 512-point profile takes the same time with both, at
#: 1024 points pk is 3x faster, at 2048 15x)
DENSE_MAX_POINTS = 512
#: a contact point with p within max(YIELD_RTOL, min(100 tol, YIELD_BAND_MAX)) of the
#: hardness is at yield (no stiffness): pressures are exact to ~1e-8 of max p at tol
#: 1e-10, and an elastic reload to the previous peak load comes out just below H_p. The
#: cap: at tol 1e-3 the band was all of 0..H_p, so every point yielded (K = 0)
YIELD_RTOL, YIELD_BAND_MAX = 1e-6, 1e-2

REFERENCES = (
    "Bemporad A., Paggi M. (2015) Int. J. Solids Struct. 69-70:94-105 (NNLS BEM)",
    "Polonsky I.A., Keer L.M. (1999) Wear 231:206-219 (constrained CG)",
    "Paggi M., He Q.-C. (2015) Wear 336-337:86-95 (free volume, Eq. 2.8)",
)


# -- cached operators ---------------------------------------------------------------------
#: Memory budgets of the operator caches (bytes of the arrays kept): a sweep reuses one
#: operator, its preconditioner and (dense solvers) its matrix; larger ones (a 2048^2
#: operator, a dense matrix of > ~5800 points) are rebuilt per solve, not pinned.
OPERATOR_CACHE_BYTES = 256 * MB
DENSE_CACHE_BYTES = 256 * MB


def _operator_key(op: InfluenceOperator) -> tuple:
    return op.name, op.shape, op.spacing, op.e_star


def _read_only(*arrays):
    for a in arrays:
        a.setflags(write=False)


@bytes_bounded_cache(OPERATOR_CACHE_BYTES)
def _operator(shape, size, e_star, kernel) -> InfluenceOperator:
    op = influence_operator(shape, size, e_star, kernel)
    _read_only(op.spectrum, *([] if op.padded_kernel is None else [op.padded_kernel]))
    return op


@bytes_bounded_cache(OPERATOR_CACHE_BYTES, key=_operator_key)
def _inverse_spectrum(op: InfluenceOperator) -> np.ndarray:
    spec = op.inverse_spectrum()
    _read_only(spec)
    return spec


def _preconditioner(op: InfluenceOperator):
    """The map g -> M g with M ~ H^-1 (exact stiffness E*|q|/2 when periodic)."""
    return functools.partial(op.precondition, spectrum=_inverse_spectrum(op))


@bytes_bounded_cache(OPERATOR_CACHE_BYTES, key=_operator_key)
def _inverse_spectrum32(op: InfluenceOperator) -> np.ndarray:
    spec = op.inverse_spectrum().astype(np.float32)    # the float64 one is not kept
    _read_only(spec)
    return spec


def _cg_preconditioner(op: InfluenceOperator):
    """M of :func:`_preconditioner` in single precision, for the CG direction only: the
    rounding (1e-7 relative) perturbs the search direction, never the float64 residual
    that decides convergence; measured: the same iterations at 512^2 (4 loads, 189 vs
    190) for ~15 % less CPU."""
    return functools.partial(op.precondition, spectrum=_inverse_spectrum32(op))


@bytes_bounded_cache(DENSE_CACHE_BYTES, key=_operator_key)
def _dense(op: InfluenceOperator) -> np.ndarray:
    H = op.dense()
    _read_only(H)
    return H


def check_solver_name(solver: str) -> str:
    """Return ``solver`` or raise :class:`InputError` unless it is one of :data:`SOLVERS`."""
    if solver not in SOLVERS:
        raise InputError(f"solver must be one of {SOLVERS}, got {solver!r}")
    return solver


def _choose_kernel(surface: Surface, kernel: str) -> str:
    if check_kernel_name(kernel) == "auto":
        if surface.periodic:
            return "spectral"
        return "strip" if surface.ndim == 1 else "love"
    if kernel == "spectral" and not surface.periodic:
        raise InputError("kernel 'spectral' is periodic and needs a periodic surface "
                         "(Surface(..., periodic=True)); use 'strip'/'love' otherwise")
    return kernel


def _choose_solver(n_points: int, op: InfluenceOperator, solver: str,
                   bounded: bool = False) -> str:
    if check_solver_name(solver) == "auto":
        if bounded:
            # the dense bounded path (BVLS) is the slower one at every size measured: a
            # 10-load cycle on 64 / 512-point profiles and a 22^2 patch took 0.09 / 16.6 /
            # 11.3 s against pk's 0.06 / 0.07 / 0.15 s, the same states (pressures within
            # 1e-8 H_p; round 2, session 33). DENSE_MAX_POINTS was measured for pivoting
            return "pk"
        return "dense" if n_points <= DENSE_MAX_POINTS else "pk"
    if bounded and solver == "dense":
        raise InputError("solver 'dense' (block principal pivoting) has no hardness bound; "
                         "use solver='pk', or solver='nnls' (bounded least squares) on a "
                         "non-periodic kernel")
    if solver in ("dense", "nnls") and n_points > 8192:
        raise InputError(f"solver {solver!r} would build a dense {n_points} x {n_points} "
                         f"matrix ({8 * n_points ** 2 / 1e9:.1f} GB); use solver='pk' above "
                         f"8192 points")
    if solver == "nnls" and op.periodic:
        raise InputError("solver 'nnls' (Cholesky + Lawson-Hanson) needs a positive definite "
                         "operator: not the periodic one (its mean mode is free); use "
                         + ("solver='pk' (with a hardness the one solver of a periodic "
                            "surface)" if bounded else "solver='dense' or solver='pk'"))
    return solver


#: elastic surface solves (load-controlled, or non-periodic) whose FFT grid has lo^2 to
#: hi^2 points use the two-level correction: BlockDeflation when periodic (4 loads, cold,
#: tol 1e-10: 1024^2 177 -> 94 its, 7.8 -> 5.6 s CPU; 2048^2 237 -> 111, 38.6 -> 26.3 s),
#: PaddedBlockDeflation on the ~2n padded grid of a non-periodic one (02b, session 16)
DEFLATION_SIDES = (1024, 8192)


def _two_level_unfit(op, hardness):
    """Why the two-level correction cannot act on a pk solve with ``op`` (what it
    needs), or None."""
    return ("a 2D surface, not a profile" if len(op.shape) != 2 else
            "an elastic interface (no hardness)" if hardness is not None else
            f"grid sides that are multiples of 8 and >= 24, got {op.shape}"
            if op.periodic and any(n % 8 or n < 24 for n in op.shape) else
            f"grid sides >= 12, got {op.shape}" if min(op.shape) < 12 else None)


def _deflation(op: InfluenceOperator, hardness, plastic, coarse_correction=None,
               start=None, load=True):
    """The coarse correction of a pk solve with ``op``, or None; its
    solves alone take the split line search (``polonsky_keer(split=)``, 02b session 11).
    ``coarse_correction``: None = where measured to pay (``DEFLATION_SIDES``,
    and a ``start`` pressure, when given, whose contact set has at least
    ``CORRECTION_MIN_PARTS`` parts: :func:`~roughfe.bem.coarse_start._contact_parts`),
    False = never, True = wherever it applies (:func:`_check_coarse_correction`). A
    plastic displacement comes with a hardness, which rules the correction out; without
    ``load`` (displacement control) only a non-periodic H takes it (its full space)."""
    lo, hi = DEFLATION_SIDES
    if (coarse_correction is False or plastic is not None or (op.periodic and not load)
            or _two_level_unfit(op, hardness)
            or (coarse_correction is None
                and not lo * lo <= float(np.prod(op.fft_shape)) <= hi * hi)):
        return None
    if coarse_correction is None and start is not None:
        parts = _contact_parts(start)
        if parts is not None and parts < CORRECTION_MIN_PARTS:
            return None
    return BlockDeflation(op, 8) if op.periodic else PaddedBlockDeflation(op, 8,
                                                                          zero_mean=load)


def _pk(op, h, hmax, scale, tol, max_iter, initial, own, deflation, **target):
    """The Polonsky-Keer CG on ``op`` for the heights ``h`` (max ``hmax``): the float32
    products and preconditioner of its direction, the split line search with a
    ``deflation``; ``target``: delta or mean_pressure (and hardness, approach)."""
    return polonsky_keer(op.apply_unchecked, h, scale, initial=initial, diagonal=op.diagonal,
                         tol=tol, precond=_cg_preconditioner(op), overwrite_initial=own,
                         max_iter=max_iter or 20000, offset=-hmax,
                         apply_single=functools.partial(op.apply_unchecked, single=True),
                         deflation=deflation,
                         split=None if deflation is None else op.split_product, **target)


def _elastic_approach(surface, material, op, h, hmax, scale, delta, tol, max_iter,
                      coarse_correction, initial):
    """The elastic periodic solve at the imposed approach ``delta`` (m) and its
    tolerance: a 2D surface through load control (:mod:`roughfe.bem.approach`, ``tol``)
    where the load has an estimate; otherwise, or when that solve does not converge
    (with a RuntimeWarning), the gap-variable CG (:func:`periodic_gap_control`, which
    accepts a primal residual of 10 ``tol``). ``surface``: the (recessed) heights h."""
    start = (approach_start(surface, material, delta - (hmax - float(h.max())), initial,
                            coarse_correction) if surface.ndim == 2 else None)
    spent = 0                  # iterations of a load-controlled attempt that fell back
    if start is not None:
        p0, deflation = start[0], _deflation(op, None, None, coarse_correction, start[0])
        try:
            return approach_by_load(lambda pm, t, hook: _pk(
                op, h, hmax, scale, t, max_iter, p0, True, deflation, mean_pressure=pm,
                approach=hook), h, hmax, scale, delta, start[1], rms_height(surface),
                tol), tol
        except NoConvergenceError as exc:
            warnings.warn(f"{exc}; solved in the gap variable instead", RuntimeWarning,
                          stacklevel=3)
            spent = exc.result.nit if exc.result is not None else 0
    elif coarse_correction is True:
        warnings.warn(f"coarse_correction=True: the approach {delta:.6g} m has no start in "
                      f"load control (the coarsened grid does not touch, or the start is in "
                      f"contact on more than {MAX_START_AREA:g} of the grid); solved in the "
                      f"gap variable, without the two-level correction", RuntimeWarning,
                      stacklevel=3)
    out = periodic_gap_control(op, h - hmax, scale, delta, initial, tol, max_iter or 20000,
                               _preconditioner(op))
    return dataclasses.replace(out, nit=out.nit + spent), 10 * tol     # every one counted


def solve_contact(surface: Surface, material: Material, *, delta=None, mean_pressure=None,
                  kernel: str = "auto", solver: str = "auto", tol: float = 1e-10,
                  max_iter: Optional[int] = None, initial=None,
                  compute_stiffness: bool = True, hardness=None,
                  plastic_displacement=None, coarse_correction=None) -> ContactResult:
    """Solve the frictionless contact of a rigid rough surface on an elastic half-space.

    Displacement control (``delta``) or load control (``mean_pressure``), Eq. 2.5-2.6;
    with a ``hardness`` the interface is perfectly plastic: 0 <= p <= H_p (box
    constraint; the thesis has no plasticity, this is the Kato-type saturated model of
    e.g. Almqvist et al. 2007 and Tamaas' ``KatoSaturated``).

    Parameters
    ----------
    surface : Surface
        Profile (plane strain, per unit depth) or surface; heights in m.
    material : Material
        Elastic body; its ``E_star`` (Pa) enters the influence operator.
    delta : float, optional
        Approach from first contact Delta >= 0 (m). For a periodic surface Delta can not
        exceed max h - mean h (full contact; the mean displacement is zero there, see
        :mod:`roughfe.bem.operators`); at that value the smallest full-contact
        pressure is returned. With a ``hardness`` any Delta >= 0 is allowed.
    mean_pressure : float, optional
        Imposed mean pressure p > 0 over the nominal area (Pa). Above the full-contact
        pressure of a periodic surface the state is full contact (A* = 1).
    kernel : {"auto", "spectral", "strip", "thesis", "love"}
        Influence operator; "auto" = "spectral" for periodic surfaces, "strip"
        (profiles) / "love" (surfaces) otherwise.
    solver : {"auto", "dense", "nnls", "pk"}
        "dense": block principal pivoting on the dense matrix (warm-startable);
        "nnls": Bemporad & Paggi's Cholesky + scipy NNLS (non-periodic kernels);
        "pk": matrix-free Polonsky-Keer CG with FFT products. "auto": dense up to
        ``DENSE_MAX_POINTS`` points, pk above; pk at every size with a ``hardness``.
    tol : float
        Relative KKT residual to reach.
    max_iter : int, optional
        Iteration limit (pk CG iterations / Newton steps of dense load control), >= 1;
        None (the default) takes the solver's own limit.
    initial : ndarray, optional
        Initial pressure (Pa), e.g. the previous step of a sweep.
    compute_stiffness : bool
        Compute the exact incremental stiffness (one extra solve on the contact set).
    hardness : float, optional
        Indentation hardness H_p (Pa), finite and > 0: the pressure cap of a perfectly
        plastic interface. Points at p = H_p flow: there the rigid surface
        interpenetrates the elastic one by the plastic (permanent) displacement. The
        dense path, on request, is bounded least squares (``solver="nnls"``, non-periodic
        kernels; 30-250x slower than pk from 512 points or a 22^2 patch up).
        A periodic surface in displacement control is solved by the bounded
        Polonsky-Keer CG on ``0 <= p <= H_p`` directly: the box makes that problem well
        posed (the minimum of 1/2 p.Hp - p.(b + Delta) over a compact set; the mean
        pressure, which the periodic H does not see, is fixed by the points at the
        bounds), and Delta may exceed max h - mean h (the mean gap then becomes
        negative: plastic flow; Delta >= max h - min h flows everywhere, p = H_p).
    plastic_displacement : ndarray, optional
        Permanent displacement (m, >= 0, grid shape) left by an earlier loading, e.g. on
        the unloading branch of a cycle: the elastic body's surface is recessed by it,
        so the gap is u + u_pl + max h - h - Delta.
    coarse_correction : bool, optional
        The two-level correction of the Polonsky-Keer CG (8 x 8 blocks: BlockDeflation,
        on the padded torus of a non-periodic kernel PaddedBlockDeflation; elastic
        surface solves: load-controlled, non-periodic, or an imposed approach on a
        periodic 2D grid of at least ``COARSE_START_MIN`` points per axis, which is
        solved through load control). None: on for FFT grids of
        ``DEFLATION_SIDES``^2 points, where it pays on rough surfaces (2-3x fewer
        iterations), unless the start's contact set (or the rigid interpenetration of a
        cold approach) has fewer than ``CORRECTION_MIN_PARTS`` connected parts: there it
        costs 1.2-1.6x CPU (02b, sessions 12-13 and 16). False: off. True: on at
        any size it applies to (an InputError says why it does not; an approach whose
        load-control start fails falls back to the gap-variable CG without it, with a
        RuntimeWarning).

    Raises
    ------
    InputError (a ValueError)
        Bad input (see the messages).
    NoConvergenceError (a RuntimeError)
        The tolerance was not reached; its ``result`` holds the last iterate.
    """
    _check_surface(surface)
    check_instance("material", material, Material, "a roughfe.model.Material")
    delta, mean_pressure = _check_target(delta, mean_pressure)
    tol = _check_tol(tol)
    if max_iter is not None:
        max_iter = check_int("max_iter (None: the solver's default)", max_iter, 1)
    hardness, plastic = _check_hardness(hardness, mean_pressure, plastic_displacement,
                                        surface.shape)
    kernel = _choose_kernel(surface, kernel)
    check_solve_memory(surface.shape, kernel == "spectral")   # before the operator
    op = _operator(surface.shape, surface.size, material.E_star, kernel)
    solver = _choose_solver(surface.heights.size, op, solver, hardness is not None)
    coarse_correction = _check_coarse_correction(coarse_correction, op, solver,
                                                 mean_pressure, hardness, _two_level_unfit)
    h = surface.heights
    hmax = float(h.max())
    if plastic is not None:
        h = h - plastic   # the recessed elastic surface acts as lowered rigid heights
    scale = float(np.ptp(surface.heights))
    if initial is not None:
        initial = check_real_array("initial pressure", initial, unit="Pa")
        if initial.shape != h.shape:
            raise InputError(f"initial pressure has shape {initial.shape}, expected {h.shape}")

    out = None
    if delta is not None and delta <= hmax - float(h.max()):
        # the flat at or above the top of the (recessed) heights: p = 0, no contact, exactly
        out = SolverOutput(np.zeros(h.shape), np.zeros(h.shape), delta, 0, 0.0, solver)
    # the gap-variable CG accepts a primal residual of 10 tol (its dual reaches tol)
    periodic_delta = solver == "pk" and op.periodic and delta is not None
    gap_control = periodic_delta and hardness is None
    tolerance = 10 * tol if periodic_delta else tol
    if op.periodic and not (hardness is not None and delta is not None):
        delta_full = hmax - float(h.mean())
        if delta is not None and delta > delta_full * (1 + 1e-12):
            raise InputError(
                f"delta = {delta:.6g} m exceeds max h - mean h = {delta_full:.6g} m: for a "
                f"periodic surface (zero mean displacement) that is full contact already; "
                f"impose a mean_pressure to go beyond it")
        if delta is not None and delta >= delta_full * (1 - 1e-12) \
                or mean_pressure is not None:
            p0 = periodic_full_contact(op, h)
            p_full = -float(p0.min())
            capped = hardness is not None and float(p0.max()) + max(p_full, mean_pressure
                                                                    or 0.0) > hardness
            if (delta is not None or mean_pressure >= p_full) and not capped:
                level = p_full if delta is not None else mean_pressure
                p = p0 + level
                p[p < 0] = 0.0
                out = SolverOutput(p, h - h.mean(), delta_full, 0, 0.0, "closed form")
            del p0            # not kept through the iterative solve (one field)
    if out is None:
        recessed = surface if plastic is None else Surface(h, surface.size, True)
        elastic = functools.partial(_elastic_approach, recessed, material, op, h, hmax,
                                    scale, delta, tol, max_iter, coarse_correction)
        if gap_control:
            out, tolerance = elastic(initial)
        elif periodic_delta:
            out = periodic_bounded_displacement(op, h, hmax, scale, delta, initial, tol,
                                                max_iter or 20000, hardness,
                                                lambda: elastic(None)[0],
                                                _cg_preconditioner(op))
        elif solver == "pk":
            own = initial is None and mean_pressure is not None and plastic is None
            if own:
                initial = _coarse_start(surface, material, mean_pressure, hardness,
                                        coarse_correction=coarse_correction, kernel=op.name)
            deflation = _deflation(op, hardness, plastic, coarse_correction, initial if (
                initial is not None or delta is None) else np.maximum(h - hmax + delta, 0),
                                   load=mean_pressure is not None)   # cold: h's contact
            out = _pk(op, h, hmax, scale, tol, max_iter, initial, own, deflation,
                      delta=delta, mean_pressure=mean_pressure, hardness=hardness)
        else:
            H = _dense(op)
            if initial is None:
                # a rough matrix-free solve gives the contact set: pivoting then needs
                # only a few exchanges (the answer is still the exact pivoting solution)
                try:
                    initial = solve_contact(surface, material, delta=delta,
                                            mean_pressure=mean_pressure, kernel=kernel,
                                            solver="pk", tol=1e-4, compute_stiffness=False,
                                            max_iter=2000, hardness=hardness,
                                            plastic_displacement=plastic).pressure
                except NoConvergenceError as exc:
                    initial = exc.result.pressure
            o = dense_solve(H, (h - hmax).ravel(), scale, delta=delta,
                            mean_pressure=mean_pressure, initial=initial,
                            method="nnls" if solver == "nnls" else "bpp", tol=tol,
                            max_iter=max_iter or 100,
                            upper=np.inf if hardness is None else hardness,
                            delta_max=hmax - float(h.mean()) if op.periodic else np.inf)
            out = SolverOutput(o.pressure.reshape(h.shape), o.displacement.reshape(h.shape),
                               o.delta, o.nit, o.residual, solver)
    return _result(surface, material, op, solver, out, scale, compute_stiffness, tolerance,
                   hardness, plastic)


def _result(surface, material, op, solver, out, scale, compute_stiffness, tolerance,
            hardness=None, plastic=None):
    h = surface.heights
    p, u, d = out.pressure, out.displacement, out.delta
    w = u + h.max() - h - d
    if plastic is not None:
        w += plastic
    # closed-form full contact at the least pressure: one point has p = 0 and g = 0
    contact = p > 0 if out.solver != "closed form" else np.ones(p.shape, bool)
    gap = np.where(contact, 0.0, np.maximum(w, 0.0))
    plastic_fraction = rim = None
    if hardness is not None:
        band = max(YIELD_RTOL, min(100.0 * tolerance, YIELD_BAND_MAX))
        flowing = contact & (p >= hardness * (1.0 - band))
        plastic_fraction = float(np.count_nonzero(flowing)) / p.size
        new = np.where(flowing, np.maximum(-w, 0.0), 0.0)
        plastic = new if plastic is None else plastic + new
        plastic.setflags(write=False)
        # the stiffness: saturated points carry a fixed pressure and do not respond
        stiff_set = contact & ~flowing
        rim = rim_width(contact, flowing, periodic=op.periodic)
    else:
        stiff_set = contact
    n = p.size
    nc = int(contact.sum())
    pm = float(p.mean())
    sigma = rms_height(surface)
    A = surface.nominal_area
    mean_gap = float(gap.mean())
    K = float("nan")
    if compute_stiffness:
        K = 0.0 if contact.any() and not stiff_set.any() else \
            exact_stiffness(op, solver, stiff_set, w, scale)
    del w                       # the label grid of patch_width takes its place
    width = patch_width(contact, p, periodic=op.periodic)
    return ContactResult(
        pressure=p, displacement=u, gap=gap, contact=contact, delta=float(d),
        load=pm * A, mean_pressure=pm, area_fraction=nc / n,
        contact_area=nc * surface.cell_area, n_contact=nc, mean_gap=mean_gap,
        mean_plane_separation=float(h.max() - h.mean() - d),
        free_volume=float(gap.sum()) * surface.cell_area,       # gap >= 0 everywhere
        free_volume_star=mean_gap / sigma, stiffness=K,
        message=("full contact" if nc == n else "converged") + f" ({out.solver})",
        nit=int(out.nit), residual=float(out.residual), tolerance=float(tolerance),
        kernel=op.name,
        solver=out.solver, e_star=material.E_star, rms_height=sigma,
        size=tuple(surface.size), spacing=tuple(surface.spacing),
        periodic=op.periodic, references=REFERENCES + op.references, method="bem",
        plastic_area_fraction=plastic_fraction, plastic_displacement=plastic,
        patch_width=width, rim_width=rim)


def surface_displacement(surface: Surface, material: Material, traction,
                         kernel: str = "auto") -> np.ndarray:
    """Displacement ``u = H t`` (m) of the elastic body under a known normal traction (Pa).

    The operator and the kernel choice are those of :func:`solve_contact` (for a periodic
    surface the uniform part of ``t`` gives no displacement: zero mean displacement). A
    known traction ``t`` acting with the contact pressure ``p`` is the dry contact of the
    heights ``h - H t`` (used by the fluid-structure coupling of
    :mod:`roughfe.leakage.fsi`).
    """
    _check_surface(surface)
    t = check_real_array("traction", traction, unit="Pa")
    if t.shape != surface.heights.shape:
        raise InputError(f"traction must have the surface's shape "
                         f"{surface.heights.shape} (Pa), got shape {t.shape}")
    op = _operator(surface.shape, surface.size, material.E_star,
                   _choose_kernel(surface, kernel))
    return np.asarray(op.apply(t)).reshape(t.shape)
