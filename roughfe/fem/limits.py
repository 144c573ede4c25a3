"""Where the FEM body stops being the BEM's elastic half-plane: measured limits.

Two approximations of :mod:`roughfe.fem.contact` do not go away with the mesh size dx:

* **Volumetric locking** of the ``"element"`` volumetric form
  (:mod:`roughfe.fem.elasticity`). P1 (constant-strain) displacement triangles cannot
  deform at constant volume, so as nu -> 1/2 (lambda / mu -> inf) the body is too stiff.
  Refining helps only slowly (at nu = 0.499 the error fell from +33..42 % to +16..19 %
  from 33 to 257 top nodes: :data:`LOCKING_ERRORS`). The cure (round 2, session 28) is
  the ``"nodal"`` form, the volumetric term on the nodal average of div u, with the nodal
  contact of the top vertices kept: :data:`NODAL_ERRORS`, +0.3..0.7 % up to nu =
  0.49999 on the cosine; on measured lines it is softer than the BEM, 1-4 % low at 257
  nodes (:mod:`roughfe.fem.elasticity`). ``FemSolverOptions(volumetric="auto")`` (the
  default) takes it above
  :data:`LOCKING_NU`; with ``volumetric="element"`` above it a
  :class:`~roughfe.errors.ResolutionWarning` names the measured error. nu >= 0.5 is
  refused (:func:`roughfe.fem.contact._check_body`).
* **Finite depth.** The body of depth H_d stands on rollers. The uniform part of the load
  is corrected exactly (the layer compliance H_d / M), but the non-uniform part decays as
  exp(-pi y / W) for the longest mode of the mirrored profile (period 2 W), so a shallow
  body is stiffer than the half-plane. Below :data:`HALF_PLANE_DEPTH` W a
  ResolutionWarning names the measured error; a body thinner than the top element size dx
  cannot be meshed with triangles of that size and is refused (:class:`InputError`).
* **Contact patches.** A patch only 1-3 nodes wide is not resolved by the mesh (the
  load at an imposed approach was 5-13 % off Westergaard's; a symmetric random profile
  with one contact node was -4.6, -3.6, -3.1 % below the BEM at 33, 65, 129 nodes):
  every result carries ``patch_width`` (:mod:`roughfe.bem.patches`, the BEM's rule) and
  a sweep warns (:func:`warn_patches`).
* **Mesh size.** A body of more than :data:`MAX_TRIANGLES` triangles (estimated before
  gmsh runs, :func:`estimated_triangles`) is refused: a deep body or a small
  ``size_max`` asked gmsh for 7e7 triangles, and gmsh stopped to ask on the terminal
  whether to continue (a batch job waited there for ever).

Measured (the tables below): a cosine half period (lambda = 1 mm, g = 1 um, W =
lambda/2; growth 0.1), FEM-VI against the periodic BEM of the mirrored profile at the
half-plane approaches Delta = 0.3, 0.7 g (nu: E = 1 GPa, depth 2 W; 33, 65, 129 and 257 top
nodes) and 0.1, 0.3, 0.7 g (depth: E = 210 GPa, nu = 0.3; 33, 65 and 129 top nodes).
``p``: mean pressure, ``K``: stiffness dp/dDelta, FEM / BEM - 1.
"""
from __future__ import annotations

import warnings

from ..bem.patches import MIN_PATCH_POINTS, patch_width, resolution_note  # noqa: F401
from ..errors import InputError, ResolutionWarning

#: Poisson's ratio above which volumetric locking is warned about: at 0.45 the FEM-BEM
#: difference is about twice that at nu = 0.3 (+0.9..2.1 % against +0.4..0.9 %).
LOCKING_NU = 0.45
#: nu, then the measured p and K errors (ranges over the meshes and loads).
LOCKING_ERRORS = ((0.3, "+0.4..0.9 %", "+0.4..0.9 %"),
                  (0.45, "+0.9..2.1 %", "-0.5..+2.7 %"),
                  (0.46, "+1.1..2.5 %", "-0.3..+3.3 %"),
                  (0.47, "+1.4..3.1 %", "+0.1..4.4 %"),
                  (0.49, "+3.4..8.1 %", "-2.9..+10 %"),
                  (0.499, "+16..42 %", "+13..25 %"),
                  (0.49999, "+46..111 %", "+44..98 %"))
#: The same (the cosine) for the ``"nodal"`` volumetric form (:mod:`roughfe.fem.elasticity`;
#: round 2, session 28): no locking, the error falls with the mesh at every nu (p at 257
#: nodes: +0.24 % at nu = 0.3, +0.32 % at 0.49999; the rest is the 2 W depth and the
#: mesh). On measured lines, with contact patches a few nodes wide, the nodal body is
#: softer: p 1-4 % low at 257 nodes (the elasticity module's docstring).
NODAL_ERRORS = ((0.3, "+0.24..0.48 %", "-0.03..+0.19 %"),
                (0.45, "+0.28..0.54 %", "-0.33..+0.20 %"),
                (0.49, "+0.30..0.61 %", "-0.01..+0.26 %"),
                (0.499, "+0.32..0.66 %", "+0.28..0.44 %"),
                (0.49999, "+0.32..0.67 %", "+0.30..0.63 %"))
#: The depth (in W) of a body that is the half-plane to the discretisation error: at 2 W
#: the difference to the BEM equals that at 3 W and 4 W to 0.1 % (the default depth).
HALF_PLANE_DEPTH = 2.0
#: depth / W, then the measured p and K errors (ranges over the meshes and loads).
DEPTH_ERRORS = ((0.25, "+67..159 %", "+65..216 %"),
                (0.5, "+18..40 %", "+18..48 %"),
                (1.0, "+1.8..3.3 %", "+1.8..3.0 %"),
                (1.5, "+0.5..1.2 %", "+0.6..0.9 %"),
                (2.0, "+0.4..1.2 %", "+0.5..0.9 %"))


def _measured(row, name="", unit=""):
    """``"p <error>, K <error> at <name><value><unit>"`` of a row of a table."""
    return f"p {row[1]}, K {row[2]} at {name}{row[0]:g}{unit}"


def _bracket(table, value, name="", unit=""):
    """The errors of ``table`` measured at ``value``, or at the rows on either side of it,
    or "more than" those of the last row it lies beyond (the worse end of each table)."""
    lower = [r for r in table if r[0] <= value]
    upper = [r for r in table if r[0] >= value]
    if lower and upper:
        if lower[-1] is upper[0]:
            return _measured(upper[0], name, unit)
        return (f"between {_measured(lower[-1], name, unit)} and "
                f"{_measured(upper[0], name, unit)}")
    return f"more than {_measured(lower[-1] if lower else upper[0], name, unit)}"


def warn_locking(nu: float, stacklevel: int = 3) -> None:
    """ResolutionWarning when ``nu`` > :data:`LOCKING_NU`, naming the errors measured at
    that nu or the tabulated ones on either side (:data:`LOCKING_ERRORS`); called for
    the ``"element"`` volumetric form only."""
    if nu <= LOCKING_NU:
        return
    warnings.warn(
        f"nu = {nu!r} > {LOCKING_NU}: the P1 displacement FEM locks volumetrically and "
        f"overestimates the pressure; against the BEM on a cosine (33-257 top nodes) it "
        f"was off by {_bracket(LOCKING_ERRORS, nu, 'nu = ')} (the discretisation error: "
        f"{_measured(LOCKING_ERRORS[0], 'nu = ')}); a finer mesh helps little; use "
        f"FemSolverOptions(volumetric='nodal') (the default 'auto' above {LOCKING_NU}: "
        f"{_measured(NODAL_ERRORS[-1], 'nu = ')} on the cosine, 1-4 % low on measured "
        f"lines of 257 nodes) or method='bem'",
        ResolutionWarning, stacklevel=stacklevel)


#: The most triangles of a FEM body (estimated, :func:`estimated_triangles`). Measured:
#: 2.1e5 triangles (65 top nodes, depth 5000 W) took 0.8 GB and 12 s for one VI step
#: with MUMPS LU; memory and time grow at least linearly from there.
MAX_TRIANGLES = 2_000_000


def estimated_triangles(width: float, depth: float, dx: float, growth: float,
                        size_max: float) -> float:
    """Triangles gmsh makes for the body of :func:`roughfe.fem.mesh_profile`: equilateral
    triangles (4 / (sqrt(3) s^2) per unit area) of the size ``s(d) = min(dx + growth d,
    size_max)`` at the distance ``d`` below the top, over the ``width x depth`` body.
    Measured against gmsh: 0.6-1.0 of its count (an underestimate; 0.9-1.0 at growth
    <= 0.1)."""
    size_max = max(size_max, dx)
    graded = min(depth, (size_max - dx) / growth)       # depth where s reaches size_max
    per_width = (1.0 / dx - 1.0 / (dx + growth * graded)) / growth \
        + (depth - graded) / size_max ** 2
    return 4.0 / 3.0 ** 0.5 * width * per_width


def check_mesh_size(width: float, depth: float, dx: float, growth: float,
                    size_max: float) -> float:
    """The estimated triangle count of the body; an InputError above
    :data:`MAX_TRIANGLES` naming the arguments that set it."""
    n = estimated_triangles(width, depth, dx, growth, size_max)
    if n > MAX_TRIANGLES:
        raise InputError(
            f"the FEM body would have about {n:.3g} triangles, more than the "
            f"{MAX_TRIANGLES:.3g} allowed (2.1e5 took 0.8 GB and 12 s per step): depth = "
            f"{depth:.3g} m = {depth / width:.3g} W, size_max = {size_max:.3g} m, growth = "
            f"{growth:g}, dx = {dx:.3g} m over W = {width:.3g} m; omit depth and size_max "
            f"(2 W and W/4), raise growth (<= 1) or take fewer profile samples")
    return n


#: Penalty penetration, as a fraction of the imposed approach, above which a penalty
#: sweep warns: the pressure is low by about 0.7-0.9 times that fraction (cosine, 17 and
#: 129 nodes, penalty_factor 0.01-1e8 against the VI).
PENETRATION_RTOL = 1e-3


def warn_penetration(results, penalty_factor: float, stacklevel: int = 3) -> None:
    """ResolutionWarning when the penalty solutions ``results`` (ContactResults) let the
    body into the obstacle by more than :data:`PENETRATION_RTOL` of their imposed
    approach (``delta_applied``): a penalty factor too small for the load."""
    worst, step = 0.0, None
    for k, r in enumerate(results):
        if r.delta_applied > 0:
            ratio = max(-float(r.gap.min()), 0.0) / r.delta_applied
            if ratio > worst:
                worst, step = ratio, k
    if worst <= PENETRATION_RTOL:
        return
    r = results[step]
    warnings.warn(
        f"penalty_factor = {penalty_factor:g} lets the body into the obstacle by "
        f"{-float(r.gap.min()):.3g} m at step {step} (imposed approach "
        f"{r.delta_applied:.3g} m), {worst:.3g} of the approach (allowed "
        f"{PENETRATION_RTOL:g}): the pressure is low by about that fraction; raise "
        f"penalty_factor (1e3-1e4 recommended, at most 1e8) or use method='vi'",
        ResolutionWarning, stacklevel=stacklevel)


def warn_patches(results, stacklevel: int = 3) -> None:
    """ResolutionWarning when steps of a sweep (ContactResults) have contact patches
    narrower than :data:`~roughfe.bem.patches.MIN_PATCH_POINTS` nodes (load-weighted):
    their load, A* and K depend on the mesh."""
    few = [(k, r.patch_width) for k, r in enumerate(results) if resolution_note(r.patch_width)]
    if few:
        k, w = few[0]
        warnings.warn(
            f"step{'s' if len(few) > 1 else ''} {', '.join(str(j) for j, _ in few[:6])}"
            f"{', ...' if len(few) > 6 else ''}: {resolution_note(w)}{f' (step {k})' if len(few) > 1 else ''}; sample the "
            f"profile more finely (more nodes across each patch) or raise the load",
            ResolutionWarning, stacklevel=stacklevel)


def warn_sweep(results, options) -> None:
    """The warnings of a finished FEM sweep: the penalty's penetration
    (:func:`warn_penetration`) and unresolved contact patches (:func:`warn_patches`)."""
    if options.method == "penalty":
        warn_penetration(results, options.penalty_factor, stacklevel=4)
    warn_patches(results, stacklevel=4)


def check_depth(depth: float, width: float, dx: float, thinnest: float) -> None:
    """Refuse a body thinner than the top element size; warn below 2 W.

    Parameters
    ----------
    depth, width, dx : float
        H_d, W = (n-1) dx and dx (m).
    thinnest : float
        The least thickness of the body (m): ``depth`` for the flat top, ``depth + min
        top(x)`` for the profile top.

    Raises
    ------
    InputError
        ``thinnest < dx``: triangles of size dx do not fit (gmsh makes one layer of
        slivers of aspect dx / thickness; at depth = 1e-4 dx the SNES stopped with
        DIVERGED_MAX_IT).
    """
    if thinnest < dx:
        raise InputError(
            f"depth = {depth:.3g} m leaves a body {thinnest:.3g} m thick, less than the top "
            f"element size dx = {dx:.3g} m: it cannot be meshed with triangles of that size "
            f"(slivers of aspect {dx / thinnest:.3g}); give depth >= dx, and >= "
            f"{HALF_PLANE_DEPTH:g} W = {HALF_PLANE_DEPTH * width:.3g} m (the default) for "
            f"the BEM's half-plane")
    d = depth / width
    if d >= HALF_PLANE_DEPTH:
        return
    warnings.warn(
        f"depth = {depth:.3g} m = {d:.3g} W is shallower than the {HALF_PLANE_DEPTH:g} W = "
        f"{HALF_PLANE_DEPTH * width:.3g} m of a half-plane (W = (n-1) dx = {width:.3g} m): "
        f"the roller bottom stiffens the body; against the BEM on a cosine (33-129 top "
        f"nodes) the FEM was off by {_bracket(DEPTH_ERRORS, d, unit=' W')} (the "
        f"discretisation error: {_measured(DEPTH_ERRORS[-1], unit=' W')}); omit depth for "
        f"the default {HALF_PLANE_DEPTH:g} W", ResolutionWarning, stacklevel=3)
