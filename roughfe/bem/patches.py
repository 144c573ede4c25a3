"""Whether the grid resolves the contact patches of a result: one rule for the BEM and the
FEM (:func:`patch_width`, :func:`resolution_note`); with a hardness, whether it resolves
the elastic rim around the plastic zone, on which the loading stiffness rests
(:func:`rim_width`, :func:`rim_note`).

A contact patch is a connected set of contact points (a run of nodes on a profile; a
4-connected set of cells on a surface; across the period's edges when periodic, and
mirrored at the ends for the FEM body, whose rollers are mirror planes). Its width in
grid points is its number of points on a profile and the diameter 2 sqrt(n / pi) of the
disc of its n cells on a surface. A result's ``patch_width`` is the mean width of its
patches weighted by the load each carries: the width of the patches that carry the load,
which a few single-point spots at the edge of a resolved contact do not pull down.

Below :data:`MIN_PATCH_POINTS` the grid cannot place the patch edges: A* by counting
points and the load at an imposed approach are off by several % and converge slowly
(a symmetric random profile with its contact on one node: the FEM was -4.6, -3.6 and
-3.1 % below the BEM at 33, 65 and 129 nodes; measured against Westergaard and Hertz in
docs/theory/02_bem_contact.md, section "Resolution of the contact patches").

A resolved width does not bound the grid's error of a rough surface (round 2, session
33): solved again on the same surface refined 2x and 4x (band-limited), A* by counting
fell by 10-20 % at widths 7-25 on di-1.di and on surfaces rough to the grid scale, by
3-5 % on surfaces smooth there; no rule on one solution (this width, the share of
single-point patches, the perimeter per contact point) gave that error within a factor
3. It is measured, not predicted: :mod:`roughfe.bem.grid_check` (the contact command's
``--grid-check``; docs/theory/02, "Discretisation error at a fixed surface").
"""
from __future__ import annotations

import numpy as np

#: load-weighted patch width (grid points) below which a result's contact is said not
#: to be resolved. Measured against Westergaard (profiles, BEM and FEM) and Hertz
#: (sphere, BEM), docs/theory/02: with 1-3 points across, the load at an imposed
#: approach was off by up to 26 % (1 point) and 5 % (3 points); from 4 points on by at
#: most 2 % (BEM 0.6 % on profiles, 2.0 % on the sphere; FEM 1.8 %, its mesh's +0.5..0.9
#: % included). A* and K by counting points converge only like 1 / width (A* +-33 % at
#: 5 points, +-14 % at 9, +-5 % at 21): this rule says where the load is resolved, and
#: that A* and K are not below it
MIN_PATCH_POINTS = 4.0


def _roots(labels, n, periodic):
    """The patch of each label 0..n of ``labels`` (0: no contact) once the labels that
    meet across the period's edges are joined (union-find on the edge pairs; the grid
    itself is never relabelled: a full-size int64 copy at 8192^2 is 0.5 GB)."""
    parent = np.arange(n + 1)
    if not periodic:
        return parent

    def root(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for axis in range(labels.ndim):
        first, last = np.take(labels, 0, axis=axis), np.take(labels, -1, axis=axis)
        both = (first > 0) & (last > 0)
        for a, b in zip(first[both].tolist(), last[both].tolist()):
            ra, rb = root(a), root(b)
            if ra != rb:
                parent[max(ra, rb)] = min(ra, rb)
    while True:                              # every label to its root (pointer jumping)
        up = parent[parent]
        if np.array_equal(up, parent):
            return parent
        parent = up


def patch_width(contact, pressure, *, periodic: bool = False,
                mirrored_ends: bool = False) -> float:
    """Load-weighted mean width of the contact patches, in grid points (NaN without
    contact). ``contact``: the mask (profile or surface); ``pressure``: the contact
    pressure on the same grid (Pa; only its distribution among the patches counts);
    ``periodic``: patches join across the period's edges; ``mirrored_ends`` (profiles):
    the ends are mirror planes (the FEM body's rollers), so a patch at an end is half of
    one twice as wide (less the shared end node). Sizes and loads are summed per label,
    then per joined patch: one int32 label grid is the only full-size temporary."""
    from scipy import ndimage

    contact = np.asarray(contact, bool)
    if not contact.any():
        return float("nan")
    labels, n = ndimage.label(contact)
    p = np.asarray(pressure, float).ravel()
    if (p < 0).any():                        # only compressive pressure carries load
        p = np.maximum(p, 0.0)
    flat = labels.ravel()
    roots = _roots(labels, n, periodic)
    size = np.bincount(roots, weights=np.bincount(flat, minlength=n + 1), minlength=n + 1)
    load = np.bincount(roots, weights=np.bincount(flat, weights=p, minlength=n + 1),
                       minlength=n + 1)
    keep = np.flatnonzero(size[1:] > 0) + 1   # the patches (roots), not label 0
    if contact.ndim == 1 and mirrored_ends and not periodic:
        for end in {int(roots[labels[0]]), int(roots[labels[-1]])} - {0}:
            if size[end] < contact.size:  # a patch over the whole profile: mirrored, whole
                size[end] = 2 * size[end] - 1
    size, load = size[keep], load[keep]
    width = size if contact.ndim == 1 else 2.0 * np.sqrt(size / np.pi)
    if load.sum() <= 0:                       # a contact without load (round-off): by area
        load = size
    return float(np.sum(load * width) / np.sum(load))


def resolution_note(width) -> str | None:
    """The note of a result whose contact patches are narrower than
    :data:`MIN_PATCH_POINTS` (None when resolved or without contact)."""
    if width is None or not np.isfinite(width) or width >= MIN_PATCH_POINTS:
        return None
    return (f"contact patches of width {width:.3g} grid points (load-weighted; fewer than "
            f"{MIN_PATCH_POINTS:g}): not resolved, the load, A* and K depend on the grid")


#: elastic rim (grid points, :func:`rim_width`) around a plastic zone below which the
#: loading stiffness K of a hardness run is said to depend on the grid. K is that of the
#: contact points below the cap (the flowing ones do not respond); where the plastic
#: zone meets the free surface across less than a cell it rests on a few rim points.
#: Measured on a sphere (R = 10 mm, P = 0.1 N, E* = 1.1 GPa) against the axisymmetric
#: reference (:mod:`roughfe.theory.capped_hertz`) at 64^2 / 128^2 / 256^2: capped at
#: 0.2 p0 rims 0.09 / 0.16 / 0.17 and K 0.92 / 1.38 / 1.31 of the reference; at 0.3 p0
#: 0.32 / 0.29 / 0.28 and 1.24 / 1.21 / 1.08; at 0.5 p0 0.68 / 0.82 / 1.0 and K within
#: 1.1 %; at 0.8 p0 (32^2-128^2) 2.4-4 and within 1.3 %. (A rule at 2 points, the
#: first guess, fired at 0.5 p0, where K was right.) On self-affine surfaces capped at
#: 0.1-0.3 E* gbar (rims 0.12-0.68) K moved 2-11 % between 64^2, 128^2 and 256^2
#: (round 2, session 34, docs/theory/02b)
MIN_RIM_POINTS = 0.5
#: rims are counted up to this many grid points (wider ones count as this wide)
RIM_COUNT = 4


def _grow(mask, periodic, diagonal):
    """``mask`` grown by one grid point (4- or, ``diagonal``, 8-neighbours on a surface;
    across the period's edges when ``periodic``, else not beyond the grid)."""
    out = mask.copy()
    shifts = [tuple(int(i == ax) * s for i in range(mask.ndim))
              for ax in range(mask.ndim) for s in (-1, 1)]
    if diagonal and mask.ndim == 2:
        shifts += [(i, j) for i in (-1, 1) for j in (-1, 1)]
    for shift in shifts:
        if periodic:
            out |= np.roll(mask, shift, axis=tuple(range(mask.ndim)))
            continue
        src = tuple(slice(max(-s, 0), mask.shape[k] - max(s, 0)) for k, s in enumerate(shift))
        dst = tuple(slice(max(s, 0), mask.shape[k] - max(-s, 0)) for k, s in enumerate(shift))
        out[dst] |= mask[src]
    return out


def rim_width(contact, flowing, *, periodic: bool = False) -> float:
    """Mean width in grid points of the elastic rim around the plastic zone of a
    hardness result (NaN without flow): for each point of the zone's border (a flowing
    point with a 4-neighbour that does not flow), the number of contact points not at
    the cap between it and the nearest point out of contact, counted by growing the
    free area one point at a time (4- and 8-neighbours in turn: an octagonal distance,
    within 8 % of the Euclidean one) up to :data:`RIM_COUNT`. On a capped sphere it is
    the rim a - c in grid points; a zone that borders the free surface scores 0.
    ``flowing``: the contact points at p = H_p. Cost: a few boolean passes over the grid."""
    contact, flowing = np.asarray(contact, bool), np.asarray(flowing, bool)
    if not flowing.any():
        return float("nan")
    border = flowing & _grow(~flowing, periodic, False)
    if not border.any():          # the whole grid flows: no rim, no border to the free area
        return 0.0 if flowing.all() else float(RIM_COUNT)
    reached, width = ~contact, np.full(int(border.sum()), float(RIM_COUNT))
    for k in range(RIM_COUNT):
        reached = _grow(reached, periodic, diagonal=k % 2 == 1)
        first = reached[border] & (width == RIM_COUNT)
        width[first] = k
    return float(width.mean())


def rim_note(width) -> str | None:
    """The note of a hardness result whose elastic rim is thinner than
    :data:`MIN_RIM_POINTS` (None when wider, or without flow)."""
    if width is None or not np.isfinite(width) or width >= MIN_RIM_POINTS:
        return None
    return (f"elastic rim around the plastic zone {width:.2g} grid points wide (fewer than "
            f"{MIN_RIM_POINTS:g}): the loading stiffness K, of the few points below the "
            f"hardness there, depends on the grid (--grid-check measures it)")
