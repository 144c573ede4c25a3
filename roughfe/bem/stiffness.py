"""The one fixed-contact-set solve of the BEM: H_cc x = 1 (thesis Eq. 2.5 and 2.7).

With the contact set c of a solution held fixed, Eq. (2.5) is linear in the approach:
``H_cc p_c = h_c - max h + Delta``. Its derivative ``x = dp/dDelta`` solves
``H_cc x_c = 1`` (zero outside c). The mean of x is the exact incremental stiffness K of
Eq. (2.7) (:func:`exact_stiffness`, used by :func:`roughfe.bem.solve_contact`); x itself
gives the derivative of the mean pressure with respect to the heights on c, ``x_c / N``
(H is symmetric), behind the exact design sensitivities
(:mod:`roughfe.genomics.design.sensitivities`) through :func:`contact_set_pressure_rate`.
The dense and matrix-free paths reuse the solver's cached operator, matrix and
preconditioner (:mod:`roughfe.bem.contact`).
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError, NoConvergenceError, check_real_array
from ..model import ContactResult
from .directions import _descent_guard
from .fft import FFTWorkspace
from .solvers import pr_beta, restricted_cg, solve_spd, step_length


#: tolerance of the matrix-free solve behind K alone (:func:`exact_stiffness`): the mean
#: of x is the inverse energy of the unit load, accurate to the square of the solve's
#: error (RMD 1025^2, three loads: K within 3.4e-11 of a 1e-12 reference at 1e-6, 20-25 %
#: less CPU than 1e-8); the rate x itself (design sensitivities) keeps 1e-8
STIFFNESS_TOL = 1e-6


def pressure_rate(op, solver, contact, tol=1e-8):
    """x = dp/dDelta (Pa/m) at every point for the FIXED contact set ``contact``:
    ``H_cc x_c = 1``, x = 0 outside. Cholesky on the cached dense matrix for the dense
    solvers, the load-controlled CG of :func:`unit_load_rate` otherwise. Returns
    ``(x, x_c)``."""
    from .contact import _cg_preconditioner, _dense   # the solver's caches (contact imports us)

    if solver in ("dense", "nnls"):
        idx = np.flatnonzero(contact.ravel())
        xc = solve_spd(_dense(op)[np.ix_(idx, idx)], np.ones(idx.size))
        x = np.zeros(contact.size)
        x[idx] = xc
        return x.reshape(contact.shape), xc
    x = unit_load_rate(op, contact, tol=tol)
    return x, x


def unit_load_rate(op, contact, tol=1e-8, max_iter=2000):
    """x = dp/dDelta (Pa/m, grid) on the FIXED contact set ``contact`` (bool grid), by the
    load-controlled form of ``H_cc x_c = 1``: the pressure y of unit total load on c
    with a uniform gap there, ``H_cc y_c = mu 1``, ``sum y = 1``; then ``x = y / mu``
    (H is linear: the unit-load pressure times the approach rate of the load, and the
    stiffness K = mean x = 1 / (N mu), N grid points).

    The load-controlled form is the linear phase of the Polonsky-Keer CG itself (the
    gradient is the gap's deviation from its mean on c), so the two-level correction
    of the contact solve applies to it as it is (:func:`roughfe.bem.contact._deflation`,
    its automatic choice for this contact set): preconditioned CG in the zero-mean
    subspace of c (flexible: Polak-Ribiere's beta), stopped when the gap's deviation is
    at most ``tol`` of its mean (rms); the displacement is updated by recursion and
    recomputed once at the end, and mu is the energy of the unit load, y . H y (the
    minimum over unit loads on c: its error is quadratic in y's, so K is accurate to
    about the square of ``tol``). Measured (RMD 1025^2, non-periodic, A* = 0.006 / 0.058
    / 0.29; round 2, session 16), tol 1e-8: 14 iterations at every load with the
    correction, 24 / 36 / 50 without, against 27 / 38 / 55 for the unit right-hand side
    (:func:`~roughfe.bem.solvers.restricted_cg`); K within 1e-13 of a 1e-12 reference
    (3.4e-11 at tol 1e-6, :data:`STIFFNESS_TOL`).
    """
    from .contact import _cg_preconditioner, _deflation   # the solver's caches and rule

    shape = contact.shape
    mask = np.ascontiguousarray(contact, dtype=bool).reshape(-1)
    c = np.flatnonzero(mask)
    nc = c.size
    if nc == 0:                          # no contact: no point responds
        return np.zeros(shape)
    work = FFTWorkspace()
    grid = np.zeros(mask.size)           # zero off c: only c is ever written
    out = np.empty(shape)
    precond = _cg_preconditioner(op)
    deflation = _deflation(op, None, None, None, contact) if len(shape) == 2 else None

    def apply_free(xF):
        grid[c] = xF
        return op.apply_unchecked(grid.reshape(shape), out=out, work=work).reshape(-1)[c]

    y = np.full(nc, 1.0 / nc)
    u = apply_free(y)
    g = u - u.mean()
    t = g_old = None
    gz_old = 0.0
    for _ in range(max_iter):
        if float(np.linalg.norm(g)) <= tol * float(u.mean()) * np.sqrt(nc):
            break
        grid[c] = g
        z = precond(grid.reshape(shape), work=work).reshape(-1)[c].astype(np.float64)
        z -= z.mean()
        if deflation is not None:
            z, gz = _descent_guard(g, z, deflation.correct(c, g, z, apply_free,
                                                           free_mask=mask))
        else:
            gz = float(np.dot(g, z))
        t = z if t is None else z + float(pr_beta(gz - float(np.dot(z, g_old)), gz_old)) * t
        ht = apply_free(t)
        tau = float(step_length(float(np.dot(g, t)), float(np.dot(t, ht))))
        y -= tau * t
        u -= tau * ht
        g_old, gz_old = g, gz
        g = u - u.mean()
    else:
        dev = float(np.linalg.norm(g)) / (float(u.mean()) * np.sqrt(nc))
        raise NoConvergenceError(f"stiffness CG: the gap's deviation on the contact set is "
                                 f"{dev:.2e} of its mean after {max_iter} iterations")
    # mu from the energy of the unit load, y . H y (sum y = 1), recomputed (no drift of the
    # recursion): y . H y is the minimum of the energy over the unit loads on c, so its
    # error is quadratic in y's (measured at 1025^2: K within 3e-11 at tol 1e-6, against
    # 1e-7 for the mean gap on c, u.mean())
    mu = float(np.dot(y, apply_free(y))) / float(y.sum()) ** 2
    x = np.zeros(mask.size)
    x[c] = y / mu
    return x.reshape(shape)


def exact_stiffness(op, solver, contact, w, scale) -> float:
    """Exact incremental stiffness K = dp/dDelta (Pa/m, Eq. 2.7) of the contact set: the
    mean of :func:`pressure_rate`; at Delta = 0 the touching point(s) (gap w <= 1e-12
    scale); 0 when nothing touches (a separated state: the end of an unloading branch
    after plastic flow, whose recess lifts the surface off the flat); ``inf`` at full
    contact of a periodic surface."""
    c = contact
    if not c.any():
        c = w <= 1e-12 * scale          # Delta = 0: the touching point(s)
        if not c.any():                 # separated: no point responds (every solver)
            return 0.0
    if op.periodic and c.all():
        return float("inf")
    return float(pressure_rate(op, solver, c, tol=STIFFNESS_TOL)[1].sum()) / c.size


def contact_set_pressure_rate(result: ContactResult) -> np.ndarray:
    """dp/dDelta (Pa/m) at every point of a BEM solution with its contact set held fixed.

    The solution x of ``H_cc x_c = 1`` on the contact set c of ``result`` (zero outside):
    the pressure increment per unit approach while no point enters or leaves contact.
    Its mean is the exact stiffness K (``result.stiffness``).

    Raises
    ------
    InputError
        A FEM result (no influence operator), plastic points (hardness), no contact, or
        full contact of a periodic surface (the mean displacement is free: no finite rate).
    """
    from .contact import _operator

    if result.kernel is None:
        raise InputError("contact_set_pressure_rate needs a BEM result (an influence kernel)")
    if result.plastic_area_fraction:
        raise InputError("contact_set_pressure_rate is for elastic contact: this solution has "
                         f"plastic points (plastic area fraction {result.plastic_area_fraction})")
    c = np.asarray(result.contact, bool)
    op = _operator(c.shape, tuple(result.size), result.e_star, result.kernel)
    if not c.any() or (op.periodic and c.all()):
        raise InputError(f"no finite pressure rate with {int(c.sum())} of {c.size} points in "
                         f"contact")
    return pressure_rate(op, result.solver, c)[0]


def load_controlled_gap_response(result: ContactResult, tractions, *,
                                 released=None) -> np.ndarray:
    """Gap change (m per Pa) under known normal tractions, contact set held fixed, mean
    pressure held fixed (load control): the compliance of trapped-fluid pockets.

    For each traction pattern ``t`` (Pa per unit amplitude) acting on the body with the
    contact pressure of ``result``: the contact pressure changes by ``dp`` on the contact
    set c and the approach by ``dD`` so that the gap stays 0 on c and the TOTAL load
    (contact + ``t``) is unchanged (``sum dp = -sum t``, thesis Eq. 2.5 with Eq. 2.6):
    ``dp = -a + dD b`` with ``H_cc a = (H t)_c`` and ``H_cc b = 1`` (:func:`pressure_rate`),
    ``dD = (sum a - sum t) / sum b``; the gap change is ``H (dp + t) - dD`` off c, 0 on c.
    By reciprocity (Maxwell-Betti) ``<s, dg(t)> = <t, dg(s)>``: the pocket compliance
    matrix built from it is symmetric (tested).

    Parameters
    ----------
    result : ContactResult
        Elastic BEM solution (its kernel and contact set).
    tractions : sequence of ndarray
        Traction patterns with the surface's shape (Pa).
    released : ndarray of bool, optional
        Points taken out of the contact set (e.g. those under a fluid pressure that
        will open them).

    Returns
    -------
    ndarray, shape (len(tractions),) + shape
        ``dg`` per pattern (m per unit amplitude).
    """
    from .contact import _cg_preconditioner, _operator

    if result.kernel is None or result.plastic_area_fraction:
        raise InputError("load_controlled_gap_response needs an elastic BEM result")
    c = np.asarray(result.contact, bool)
    if released is not None:
        c = c & ~np.asarray(released, bool)
    op = _operator(c.shape, tuple(result.size), result.e_star, result.kernel)
    if not c.any() or (op.periodic and c.all()):
        raise InputError(f"no fixed-set response with {int(c.sum())} of {c.size} points in "
                         f"contact")
    b = pressure_rate(op, result.solver, c)[0]
    precond = _cg_preconditioner(op)
    out = []
    for t in tractions:
        t = check_real_array("traction pattern", t, unit="Pa")
        if t.shape != c.shape:
            raise InputError(f"a traction pattern must have the surface's shape {c.shape}, "
                             f"got {t.shape}")
        ht = np.asarray(op.apply_unchecked(t)).reshape(c.shape)
        a, _ = restricted_cg(op.apply_unchecked, c, ht, precond=precond, tol=1e-10)
        dD = (a.sum() - t.sum()) / b.sum()
        dp = np.where(c, dD * b - a, 0.0)
        dg = np.asarray(op.apply_unchecked(dp + t)).reshape(c.shape) - dD
        out.append(np.where(c, 0.0, dg))
    return np.array(out).reshape((len(out),) + c.shape)
