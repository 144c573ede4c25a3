"""The coarse-to-fine start of a load-controlled BEM solve of a surface (02b): the same
problem on the grid coarsened by 2 (Fourier-truncated heights when periodic, 2 x 2 block
means when not), recursively, its pressure injected on 2 x 2 blocks as the initial guess
of the finer grid; and what the
start tells of the contact's structure (:func:`_contact_parts`), which decides whether
the two-level correction has work to do."""
from __future__ import annotations

import numpy as np
import scipy.fft
import scipy.ndimage

from ..errors import NoConvergenceError
from ..surfaces.surface import Surface
from .operators import WORKERS

#: cold, load-controlled, periodic surface solves with at least this many points per (even)
#: axis start from the solution on the grid coarsened twice (recursively)
COARSE_START_MIN = 256
COARSE_START_TOL = 1e-4  #: KKT tolerance of those coarse solves (only a starting guess)
#: the automatic two-level correction acts only on a start whose contact set has at least
#: this many connected parts (contact patches plus non-contact islands, 02b session 13)
CORRECTION_MIN_PARTS = 32


def _contact_parts(pressure):
    """Connected parts of the contact set of a starting ``pressure`` (Pa, 2D): its
    patches (p > 0) plus its non-contact islands (p = 0), 4-connected, counted on every
    second point per axis (the 2 x 2 injection of :func:`_coarse_start` makes that the
    coarse solution itself; the periodic wrap is not joined, which adds at most a few).
    Contact everywhere is one part (a nearly full contact: one patch, nothing to
    exchange); None when there is no contact at all (nothing to read).

    The two-level correction exists for the exchange of load between many patches (and
    around many islands), the smooth modes the stiffness preconditioner handles poorly;
    a contact of a few parts (a sphere, a sinusoid, a few asperities) has none of that
    to do, and there the correction buys no iterations and costs 1.2-1.6x CPU (measured
    at 1024^2-4096^2, 02b session 13). Rough surfaces give hundreds to thousands of
    parts at every load measured (p/E* = 0.005-1)."""
    c = np.greater(pressure[::2, ::2], 0.0)
    patches = scipy.ndimage.label(c)[1]
    if patches == 0:
        return None
    np.logical_not(c, out=c)
    return int(patches) + int(scipy.ndimage.label(c)[1])


def _coarse_surface(surface: Surface) -> Surface:
    """The same surface on a grid coarsened by 2 per axis.

    Periodic: its Fourier modes below the coarse Nyquist wavenumber (the coarse Nyquist
    row/column dropped; even sides). Non-periodic: the means of 2 x 2 blocks, ceil(n/2)
    per axis (an odd side's last block is its edge row/column repeated), on a domain of
    twice the spacing, which extends half a cell beyond the surface's when n is odd."""
    h = surface.heights
    n0, n1 = h.shape
    if not surface.periodic:
        m0, m1 = (n0 + 1) // 2, (n1 + 1) // 2
        hp = np.pad(h, ((0, 2 * m0 - n0), (0, 2 * m1 - n1)), mode="edge")
        hc = hp.reshape(m0, 2, m1, 2).mean(axis=(1, 3))
        return Surface(hc, (surface.size[0] * 2 * m0 / n0, surface.size[1] * 2 * m1 / n1),
                       periodic=False)
    m0, m1 = n0 // 2, n1 // 2
    spec = scipy.fft.rfftn(h, workers=WORKERS)
    coarse = np.zeros((m0, m1 // 2 + 1), complex)
    k0, k1 = m0 // 2, m1 // 2
    coarse[:k0, :k1] = spec[:k0, :k1]
    coarse[m0 - k0 + 1:, :k1] = spec[n0 - k0 + 1:, :k1]
    del spec
    hc = scipy.fft.irfftn(coarse, s=(m0, m1), workers=WORKERS)
    hc *= (m0 * m1) / (n0 * n1)
    return Surface(hc, surface.size, periodic=True)


def _coarse_pressure(coarse, material, coarse_correction, **target):
    """The pressure (Pa) of the ``coarse`` surface solved by pk to ``COARSE_START_TOL``
    without the stiffness (``target``: the other keywords of
    :func:`~roughfe.bem.solve_contact`, the load or the approach first), or its last
    iterate when it stops short: a start needs no more. ``coarse_correction`` False
    stays off on the coarse level; otherwise the level chooses."""
    from .contact import solve_contact   # the coarse level is a solve of its own
    try:
        return solve_contact(coarse, material, solver="pk", tol=COARSE_START_TOL,
                             compute_stiffness=False,
                             coarse_correction=False if coarse_correction is False else None,
                             **target).pressure
    except NoConvergenceError as exc:
        return exc.result.pressure


def _inject(pc, shape):
    """The coarse pressure ``pc`` (Pa) on the fine grid ``shape``: each value on its 2 x 2
    block, cropped to ``shape`` (odd non-periodic sides; the solver scales its start to
    the load)."""
    p = np.repeat(np.repeat(pc, 2, axis=0), 2, axis=1)
    return p if p.shape == tuple(shape) else np.ascontiguousarray(p[:shape[0], :shape[1]])


def _coarse_start(surface, material, mean_pressure, hardness, previous=None,
                  coarse_correction=None, kernel="auto"):
    """Coarse-to-fine initial pressure (Pa) of a load-controlled surface solve, or None.

    The problem is solved on the grid coarsened by 2 (:func:`_coarse_surface`, the same
    mean pressure, recursively down to ``COARSE_START_MIN`` points per axis) to
    ``COARSE_START_TOL`` and its pressure injected on 2 x 2 blocks (a level costs a
    quarter of the next). Periodic: 15-20 % fewer fine iterations at 512^2-1024^2, 4
    loads (02b). Non-periodic (``kernel`` "love" or "thesis", as the fine solve's): RMD
    surfaces 513^2 and 1025^2, p/E* h'_rms = 0.005 and 0.05, 49 -> 40 and 66 -> 59
    fine iterations at 1025^2, start included 20-25 % less CPU (02b, session 16).

    ``previous`` (dict grid shape -> the previous sweep step's solution on that grid,
    updated in place; the caller stores the fine one): every level then starts from
    the injected coarser solution plus its previous detail, P_c(new) + p_prev -
    P_c(prev), clipped at 0 (a full-approximation-scheme start; measured in
    :func:`roughfe.bem.sweep.contact_sweep`). ``coarse_correction`` False (see
    :func:`roughfe.bem.solve_contact`) keeps the two-level correction off on every
    level; otherwise the levels choose it automatically.
    """
    level = False if coarse_correction is False else None
    shape = surface.shape
    if (surface.ndim != 2 or min(shape) < COARSE_START_MIN
            or (surface.periodic and any(n % 2 for n in shape))):
        return None
    coarse = _coarse_surface(surface)
    before = initial = None
    if previous is not None:
        before, initial = previous.get(coarse.shape), _coarse_start(
            coarse, material, mean_pressure, hardness, previous, level, kernel)
    pc = _coarse_pressure(coarse, material, level, mean_pressure=mean_pressure,
                          kernel=kernel, hardness=hardness, initial=initial)
    if previous is not None:
        previous[coarse.shape] = pc
        if before is not None and shape in previous:     # the previous detail
            start = _inject(pc - before, shape)
            return np.maximum(start + previous[shape], 0.0, out=start)
    return _inject(pc, shape)
