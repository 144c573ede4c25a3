"""The contract layer: what goes into a contact computation and what comes out of it.

One set of types shared by every method (thesis Sec. 2.2, Eq. 2.3-2.8):

* :class:`Material` (and :func:`composite`) -- the elastic body, E and nu (Pa, -).
* :class:`Loading` -- an imposed approach Delta (m), a mean pressure (Pa), or a sweep
  (``n_steps`` equispaced approaches, a list of ``deltas`` or of ``pressures``).
* :class:`ContactResult` -- one contact solution, returned by the BEM
  (:func:`roughfe.bem.solve_contact`) and the FEM (:func:`roughfe.fem.fem_contact_sweep`).
* :class:`SweepResult` -- a loading sweep: a tuple of ContactResult plus the step
  values as read-only arrays and the dimensionless curves of the thesis.

:func:`roughfe.response.response` (surface, material, loading, method) -> SweepResult is
the one way to ask for "a sweep of this surface" with either method.

Conventions (SI, signs fixed once): pressure p >= 0 is compressive; gap g >= 0; the
approach Delta >= 0 is counted from first contact of the highest point; ``area_fraction``
is the dimensionless A* = A_r / A_n, ``contact_area`` is A_r in m^2 (m per unit depth for
profiles). Every array in a result is read-only, every container immutable (tuples,
:class:`roughfe.frozen.FrozenMapping`), also after unpickling, and ``success`` is
computed from ``residual <= tolerance``: nobody sets it.

Adding an optional field
------------------------
A method-specific quantity (e.g. a plastic area fraction, a pull-off force) is ONE line
in :class:`ContactResult`, in the block of optional fields at the end::

    plastic_area_fraction: Optional[float] = None

It defaults to None for the methods that do not compute it; a number set there appears
automatically in :meth:`ContactResult.scalars` and in the per-step records of
:meth:`SweepResult.to_records` (results.json); an array is made read-only. To also get
it as a per-step array of a sweep, add the same name (one line) to the optional block of
:class:`SweepResult`: ``plastic_area_fraction: Optional[np.ndarray] = None``;
:meth:`SweepResult.from_results` fills it when every step has a value.
"""
from __future__ import annotations

import dataclasses
import math
import numbers
from dataclasses import dataclass, field
from typing import Any, Mapping, Optional

import numpy as np

from .errors import InputError, check_finite_positive, check_in_interval
from .frozen import Frozen, compact_repr, freeze_fields
from .writers import json_scalars, to_jsonable

#: The one default material of every command and study analysis: the thesis' E* = 210 MPa
#: (Sec. 3.4, "E = 210 MPa", nu = 0 so that E* = E). Pressures scale linearly with E* in
#: elastic contact, so A(p/E*) does not depend on it. ``roughfe.cli.options`` (``--E``,
#: ``--nu``) and ``roughfe.study.analyses`` read it from here.
DEFAULT_E = 210.0e6
DEFAULT_NU = 0.0

__all__ = ["DEFAULT_E", "DEFAULT_NU", "Material", "composite", "Loading", "ContactResult",
           "SweepResult",
           "RECORD_KEYS", "central_differences"]


# -- material -----------------------------------------------------------------------------
def _check_nu(name, nu):
    """Poisson's ratio of an isotropic elastic solid, -1 < nu <= 1/2 (a number; text such as
    "0.3" and bools refused): the shear modulus E / (2 (1 + nu)) and the bulk modulus
    E / (3 (1 - 2 nu)) are positive for -1 < nu < 1/2, and 1/2 is the incompressible
    limit (E* = 4 E / 3), which the BEM takes and the FEM body refuses
    (:mod:`roughfe.fem.contact`: its Lame lambda is infinite there)."""
    return check_in_interval(f"{name} (Poisson's ratio)", nu, -1, 0.5, "right")


@dataclass(frozen=True)
class Material:
    """An isotropic linear elastic solid (thesis Sec. 2.2).

    Parameters
    ----------
    E : float
        Young's modulus (Pa), finite and > 0.
    nu : float
        Poisson's ratio, in (-1, 0.5] (0.5 is incompressible).

    ``E_star = E / (1 - nu^2)`` is the plane-strain modulus of this solid against a
    rigid counter-surface; use :func:`composite` for two elastic solids.
    """

    E: float
    nu: float

    def __post_init__(self):
        if isinstance(self.E, bool):
            raise InputError(f"E (Young's modulus, Pa) must be a positive number, got {self.E!r}")
        object.__setattr__(self, "E", check_finite_positive("E (Young's modulus, Pa)", self.E))
        object.__setattr__(self, "nu", _check_nu("nu", self.nu))

    @property
    def E_star(self) -> float:
        """Composite (plane-strain) modulus E* = E / (1 - nu^2) in Pa."""
        return self.E / (1.0 - self.nu ** 2)


def composite(E1, nu1, E2, nu2) -> Material:
    """Equivalent material of two elastic solids in contact (Johnson 1985, Eq. 4.22).

    E* = [(1 - nu1^2)/E1 + (1 - nu2^2)/E2]^-1. The thesis (Sec. 2.2) writes
    (1 - nu)/E without the squares: that is a typo, the squares are right.
    Returns ``Material(E*, 0)``, whose ``E_star`` is E*. Pass ``E2=float('inf')`` for a
    rigid second body.
    """
    m1 = Material(E1, nu1)
    nu2 = _check_nu("nu2", nu2)
    # a number as Material's E (text such as "7e10" ran as one), inf allowed: rigid
    E2 = check_in_interval("E2 (Young's modulus, Pa; inf: rigid)", E2, 0, float("inf"),
                           "right")
    if E2 == float("inf"):
        return Material(m1.E_star, 0.0)
    return Material(1.0 / (1.0 / m1.E_star + (1.0 - nu2 ** 2) / E2), 0.0)


# -- loading ------------------------------------------------------------------------------
def _number(name, value, what):
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Real, np.ndarray)):
        raise InputError(f"{name} must be {what}, got {value!r}")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be {what}, got {value!r}") from None
    return v


def _check_delta(name, value, apart=False):
    """The approach ``value`` (m) as a float: finite, and >= 0 unless ``apart``."""
    v = _number(name, value, "a number of metres" + ("" if apart else " >= 0"))
    if not (math.isfinite(v) and (apart or v >= 0.0)):
        raise InputError(f"{name} (approach from first contact, m) must be finite"
                         f"{'' if apart else ' and >= 0'}, got {value!r}")
    return v


def _check_pressure(name, value):
    v = _number(name, value, "a number of Pa > 0")
    if not (math.isfinite(v) and v > 0.0):
        raise InputError(f"{name} (mean pressure, Pa) must be finite and > 0, got {value!r}")
    return v


def _check_series(name, values, check):
    if isinstance(values, (str, bytes)) or np.ndim(values) == 0:
        raise InputError(f"{name} must be a non-empty 1D sequence of numbers, got {values!r}")
    arr = np.asarray(values, dtype=object)
    if arr.ndim != 1 or arr.size == 0:
        raise InputError(f"{name} must be a non-empty 1D sequence of numbers, got shape "
                         f"{arr.shape}")
    return tuple(check(f"{name}[{k}]", v) for k, v in enumerate(arr))


@dataclass(frozen=True)
class Loading:
    """How a contact problem is loaded: ONE of the fields below (SI).

    Parameters
    ----------
    delta : float, optional
        One imposed approach Delta from first contact (m), Eq. 2.5; negative (apart)
        only with adhesion (:meth:`require_contact`).
    mean_pressure : float, optional
        One imposed mean pressure p > 0 over the nominal area (Pa), Eq. 2.6.
    n_steps : int, optional
        A sweep of ``n_steps`` equispaced approaches up to the peak-to-valley height
        (up to max h - mean h, i.e. full contact, for periodic problems; with adhesion
        k / (n_steps + 1) of it, k = 1..n_steps: :func:`~roughfe.bem.adhesion.adhesive_sweep`),
        as in the thesis. The default when nothing is given: ``Loading()`` is 20 steps.
    deltas : sequence of float, optional
        A sweep over these approaches (m), solved in the order given; negative ones as
        for ``delta``.
    pressures : sequence of float, optional
        A sweep over these mean pressures (Pa), solved in the order given.

    Sequences are stored as tuples of floats (a Loading is hashable and immutable).

    Raises
    ------
    InputError
        More than one kind given, or a value that is not finite, not positive
        (pressure), not an integer >= 1 (``n_steps``) or an empty sequence.
    """

    delta: Optional[float] = None
    mean_pressure: Optional[float] = None
    n_steps: Optional[int] = None
    deltas: Optional[tuple] = None
    pressures: Optional[tuple] = None

    KINDS = ("delta", "mean_pressure", "n_steps", "deltas", "pressures")
    DEFAULT_STEPS = 20

    def __post_init__(self):
        given = [k for k in self.KINDS if getattr(self, k) is not None]
        if len(given) > 1:
            raise InputError(f"a Loading takes ONE of {self.KINDS}, got {given}")
        set_ = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731
        if not given:
            set_("n_steps", self.DEFAULT_STEPS)
        elif self.delta is not None:
            set_("delta", _check_delta("delta", self.delta, apart=True))
        elif self.mean_pressure is not None:
            set_("mean_pressure", _check_pressure("mean_pressure", self.mean_pressure))
        elif self.n_steps is not None:
            n = self.n_steps
            if isinstance(n, (bool, np.bool_)) or not isinstance(n, numbers.Integral) \
                    and not (isinstance(n, float) and n.is_integer()):
                raise InputError(f"n_steps must be an integer >= 1, got {n!r}")
            if int(n) < 1:
                raise InputError(f"n_steps must be an integer >= 1, got {n!r}")
            set_("n_steps", int(n))
        elif self.deltas is not None:
            set_("deltas", _check_series("deltas", self.deltas,
                                         lambda k, v: _check_delta(k, v, apart=True)))
        else:
            set_("pressures", _check_series("pressures", self.pressures, _check_pressure))

    @property
    def kind(self) -> str:
        """Which field is set: one of :attr:`KINDS`."""
        return next(k for k in self.KINDS if getattr(self, k) is not None)

    @property
    def controls_pressure(self) -> bool:
        """True for load control (mean_pressure / pressures), False for approaches."""
        return self.kind in ("mean_pressure", "pressures")

    def require_contact(self, words=None) -> None:
        """Raise :class:`InputError` if an approach is negative: the surfaces then stand
        apart, a state only an attraction makes a problem of (``response(...,
        adhesion=law)``, whose loading can start apart and jump in); the non-adhesive
        solvers have no contact to solve there.

        ``words`` maps the names in the message (``delta``, ``deltas``, ``adhesion``) to
        a front end's own, as for :func:`roughfe.bem.adhesive_rules.check_adhesive_run`
        (the command line passes ``--delta`` and ``--adhesion``); by default they are the
        library's keyword arguments."""
        say = {"adhesion": "response(..., adhesion=law)", **(words or {})}
        values = {"delta": (self.delta,), "deltas": self.deltas}.get(self.kind, ())
        for k, v in enumerate(values):
            if v < 0.0:
                name = say.get(self.kind, self.kind) + ("" if self.kind == "delta"
                                                        else f"[{k}]")
                raise InputError(f"{name} = {v!r} m is a negative approach (the surfaces "
                                 f"apart): meaningful with adhesion only ({say['adhesion']}"
                                 f"); without it give approaches >= 0")

    def sweep_arguments(self) -> dict:
        """The keyword arguments of :func:`roughfe.bem.contact_sweep` for this loading:
        ``{"n_steps": n}``, ``{"deltas": (...)}`` or ``{"pressures": (...)}`` (a single
        delta / mean pressure is a one-step sweep)."""
        if self.kind == "delta":
            return {"deltas": (self.delta,)}
        if self.kind == "mean_pressure":
            return {"pressures": (self.mean_pressure,)}
        return {self.kind: getattr(self, self.kind)}

    def describe(self) -> dict:
        """JSON-safe description, e.g. ``{"deltas": [1e-6, 2e-6]}`` (SI)."""
        v = getattr(self, self.kind)
        return {self.kind: list(v) if isinstance(v, tuple) else v}


# -- results ------------------------------------------------------------------------------
def _is_number(v) -> bool:
    return isinstance(v, (numbers.Number, np.number, np.bool_)) and not isinstance(v, complex)


#: Per-step scalars of every method, in the order of :meth:`ContactResult.scalars`.
STEP_SCALARS = ("delta", "load", "mean_pressure", "area_fraction", "contact_area",
                "n_contact", "mean_gap", "mean_plane_separation", "free_volume",
                "free_volume_star", "stiffness", "nit", "residual")

#: Keys of every per-step record of :meth:`SweepResult.to_records` (results.json);
#: optional numeric fields that a method sets follow them.
RECORD_KEYS = ("delta", "load", "mean_pressure", "area_fraction", "contact_area",
               "n_contact", "stiffness",
               "stiffness_fd", "mean_gap", "mean_plane_separation", "free_volume",
               "free_volume_star", "iterations", "residual")


@dataclass(frozen=True, eq=False)
class ContactResult(Frozen):
    """Solution of one contact problem, the same type from the BEM and the FEM (SI).

    Attributes
    ----------
    pressure : ndarray
        Contact pressure p (Pa), >= 0 (compressive), grid shape (BEM: cell values; FEM:
        nodal reaction / tributary length at the top vertices).
    displacement : ndarray
        Normal surface displacement u of the elastic body (m), positive into the body
        (BEM: u = H p; FEM: with zero mean, the half-plane convention).
    gap : ndarray
        g = u + max h - h - Delta (m), >= 0 (round-off clipped at 0 by the BEM; the FEM
        penalty method allows -penetration).
    contact : ndarray of bool
        Contact mask (points that carry a positive pressure).
    delta : float
        Approach Delta from first contact (m) of a half-space/half-plane.
    load : float
        Total load P = mean_pressure * A_n: N for surfaces, N/m for profiles.
    mean_pressure : float
        p = P / A_n (Pa).
    area_fraction : float
        A* = A_r / A_n (dimensionless, in [0, 1]).
    contact_area : float
        A_r (m^2; m per unit depth for profiles).
    n_contact : int
        Number of contact points n_c.
    mean_gap : float
        Mean of the gap over the nominal area (m).
    mean_plane_separation : float
        d = max h - mean h - Delta (m).
    free_volume : float
        V = gap integrated over the nominal area (Eq. 2.8): m^3, or m^2 per unit depth
        for profiles (= mean_gap * A_n).
    free_volume_star : float
        V* = V / (A_n sigma) = mean_gap / sigma, sigma the rms height.
    stiffness : float
        Incremental contact stiffness K = d p / d Delta (Eq. 2.7) in Pa/m, exact for the
        converged contact set. ``inf`` at full contact of a periodic surface; NaN if not
        computed.
    success : bool
        Computed, not passed: ``residual <= tolerance``.
    message : str
    nit : int
        Iterations (BEM: CG iterations / pivoting steps; FEM: SNES iterations).
    residual : float
        Final residual (BEM: relative KKT residual, :mod:`roughfe.bem.solvers`; FEM: SNES
        residual norm, non-dimensional).
    tolerance : float
        The residual the solver had to reach (same measure as ``residual``).
    kernel : str or None
        BEM influence operator; None for the FEM.
    solver : str
        Solver used (``"dense"``, ``"pk"``, ``"closed form"``, ``"fem-vi"``, ...).
    e_star : float
        Composite modulus E* (Pa).
    rms_height : float
        sigma (m).
    size, spacing : tuple
        Physical size and grid spacing per axis (m).
    periodic : bool
        Whether the problem is periodic.
    references : tuple of str
    method : str
        ``"bem"`` or ``"fem"``.
    x : ndarray or None
        Optional (None where a method does not compute it; the same for the fields
        below). FEM: positions of the top vertices (m).
    delta_applied : float, FEM
        Approach imposed on the finite layer (m); ``delta`` is it minus the layer
        shortening ``mean_pressure * layer_compliance``.
    layer_compliance : float, FEM
        H_d / M (m/Pa), the uniform compliance of the finite layer.
    formulation : str, FEM
        ``"flat"`` or ``"profile"``.
    fields : mapping, FEM; BEM adhesion
        Full fields for pictures (read-only), see :mod:`roughfe.fem.contact`; the
        non-periodic adhesive BEM keeps ``padded_displacement`` (m: the gap on the grid,
        the displacement on the zero padding; its warm start).
    plastic_area_fraction : float, BEM with a hardness
        Fraction of the nominal area at p = H_p (perfectly plastic flow; within
        ``roughfe.bem.contact.YIELD_RTOL`` or 100 tol of H_p, the solver's accuracy,
        at most 1 %).
    plastic_displacement : ndarray, BEM with a hardness
        Permanent displacement u_pl >= 0 (m) of the elastic surface after this step
        (read-only); kept by the next steps of a sweep.
    unloading : bool, BEM sweeps with a hardness or ``unload``; BEM adhesion
        The branch of the step: False on loading, True on unloading.
    adhesive_area_fraction : float, BEM adhesion
        Fraction of the nominal area under tensile (adhesive) traction.
    patch_width : float, BEM (with adhesion: the patches of g = 0) and FEM
        Load-weighted width of the contact patches in grid points (NaN without contact);
        below ``roughfe.bem.patches.MIN_PATCH_POINTS`` the grid does not resolve them
        (:func:`roughfe.bem.patches.resolution_note`).
    rim_width : float, BEM with a hardness
        Mean width of the elastic rim around the plastic zone in grid points (NaN
        without flow); below ``roughfe.bem.patches.MIN_RIM_POINTS`` the loading
        stiffness depends on the grid (:func:`roughfe.bem.patches.rim_note`).

    With adhesion (:mod:`roughfe.bem.adhesion`) ``pressure`` is the total interface
    traction and is negative (tensile) in the interaction zone; ``contact`` marks g = 0.
    """

    pressure: np.ndarray
    displacement: np.ndarray
    gap: np.ndarray
    contact: np.ndarray
    delta: float
    load: float
    mean_pressure: float
    area_fraction: float
    contact_area: float
    n_contact: int
    mean_gap: float
    mean_plane_separation: float
    free_volume: float
    free_volume_star: float
    stiffness: float
    message: str
    nit: int
    residual: float
    tolerance: float
    kernel: Optional[str]
    solver: str
    e_star: float
    rms_height: float
    size: tuple
    spacing: tuple
    periodic: bool
    references: tuple
    method: str = "bem"
    success: bool = field(init=False)
    # -- optional, method-specific fields (one line each; see the module docstring) --
    x: Optional[np.ndarray] = None
    delta_applied: Optional[float] = None
    layer_compliance: Optional[float] = None
    formulation: Optional[str] = None
    fields: Optional[Mapping[str, Any]] = None
    plastic_area_fraction: Optional[float] = None
    plastic_displacement: Optional[np.ndarray] = None
    unloading: Optional[bool] = None
    adhesive_area_fraction: Optional[float] = None
    patch_width: Optional[float] = None
    rim_width: Optional[float] = None

    __repr__ = compact_repr          # one line: fields as shape and dtype, unset optionals left out

    def __post_init__(self):
        freeze_fields(self)
        object.__setattr__(self, "success", bool(self.residual <= self.tolerance))

    @property
    def full_contact(self) -> bool:
        """True when every point is in contact (A* = 1)."""
        return self.n_contact == self.pressure.size

    @classmethod
    def optional_fields(cls) -> tuple:
        """Names of the optional (default None) fields."""
        return tuple(f.name for f in dataclasses.fields(cls)
                     if f.init and f.default is None)

    def optional_scalars(self) -> tuple:
        """Names of the optional fields that hold a number in this result."""
        return tuple(k for k in self.optional_fields() if _is_number(getattr(self, k)))

    def scalars(self) -> dict:
        """The per-step scalars (:data:`STEP_SCALARS` and the optional numeric fields set)
        as a JSON-safe dict (non-finite values -> None)."""
        return json_scalars(self, STEP_SCALARS + self.optional_scalars())


def central_differences(x, y, branch=None):
    """dy/dx along the curve y(x): the points ordered by x, then (y[i+1] - y[i-1]) /
    (x[i+1] - x[i-1]) between neighbours on the curve inside, one-sided at the ends,
    returned in the order given; NaN where the spacing is zero to round-off (1e-12 of
    max |x|: e.g. repeated full-contact steps) and on a curve of fewer than 3 points: two
    points give one secant, the derivative at neither (until round 2, session 29 both
    points got it, and ``roughfe contact --pressure 1e7 1e8`` drew a flat K_fd beside an
    exact K that rose 3.5x between them). (Until session 25
    the neighbours were those in the order given: loads solved as 3e5, 1e4, 1e5, 3e4,
    2e5 Pa read K = 7.3e11, 1.9e11, 6.6e11 Pa/m at 1e4, 1e5, 3e4 Pa where the exact K
    is 1.0e11, 5.3e11, 2.7e11.)

    ``branch`` (optional, one flag per point, e.g. 1 on an unloading branch): the
    differences are taken within each run of equal flags, never across the turn of a
    loading-unloading sweep (where the two neighbours of the top step are the same load
    on either branch, and the difference read K = 0). A run after a turn starts at the
    turning point (the last point before it: the unloading curve leaves the top state),
    which is used as its first neighbour; the turning point's own value is its run's
    one-sided one. (Until round 2, session 22 the unloading run was differenced
    without it: an elastic unloading 30 -> 10 -> 1 MPa read K = 1.3e13 Pa/m at 10 MPa
    where the loading run and the exact K read 2.5e13.)"""
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    out = np.full(x.shape, np.nan)
    if branch is not None:
        edges = np.flatnonzero(np.diff(np.asarray(branch)) != 0) + 1
        for run in np.split(np.arange(x.size), edges):
            if run[0] == 0:
                out[run] = central_differences(x[run], y[run])
            else:             # with the turning point in front
                ext = np.concatenate([[run[0] - 1], run])
                out[run] = central_differences(x[ext], y[ext])[1:]
        return out
    if x.size < 3:
        return out
    order = np.argsort(x, kind="stable")      # along the curve; scattered back below
    xs, ys = x[order], y[order]
    tiny = 1e-12 * float(np.max(np.abs(x)))
    with np.errstate(divide="ignore", invalid="ignore"):
        dx = np.concatenate([[xs[1] - xs[0]], xs[2:] - xs[:-2], [xs[-1] - xs[-2]]])
        dy = np.concatenate([[ys[1] - ys[0]], ys[2:] - ys[:-2], [ys[-1] - ys[-2]]])
        out[order] = np.where(np.abs(dx) > tiny, dy / dx, np.nan)
    out[~np.isfinite(out)] = np.nan
    return out


#: Per-step arrays of a sweep, taken from the ContactResult fields of the same name.
_SWEEP_SERIES = ("delta", "mean_pressure", "load", "area_fraction", "stiffness", "mean_gap",
                 "mean_plane_separation", "free_volume_star")
#: Optional values of a whole sweep (SweepResult.from_results' keywords), not per step.
_SWEEP_WHOLE = ("pull_off_force", "pull_off_pressure", "detached")


@dataclass(frozen=True, eq=False)
class SweepResult(Frozen):
    """A loading sweep (SI units), the same type from the BEM and the FEM.

    Attributes
    ----------
    results : tuple of ContactResult
        One solution per step.
    delta, mean_pressure, load, area_fraction, stiffness, mean_gap,
    mean_plane_separation, free_volume_star : ndarray (float)
        The step values (see :class:`ContactResult`).
    n_contact : ndarray (int)
        Contact points per step.
    stiffness_fd : ndarray
        K by central finite differences of mean_pressure over delta along the curve
        (each branch's steps ordered by delta, whatever the solve order; one-sided at
        a branch's ends; NaN on a branch of fewer than 3 steps; Pa/m); agrees with the
        exact ``stiffness`` away from contact-set changes where the steps are close.
    load_star : ndarray
        P* = p L / (E* sigma), the thesis' dimensionless load (L = size along x: the
        grid length for the BEM, the body width W for the FEM).
    pressure_star : ndarray
        p / (E* gbar), gbar the rms slope.
    separation_star : ndarray
        d / sigma.
    rms_height, rms_slope, e_star : float
        sigma (m), gbar, E* (Pa).
    delta_applied : ndarray or None
        Optional (None unless every step has the value; the same below). FEM:
        approaches imposed on the finite layer (m).
    plastic_area_fraction : ndarray or None
        BEM with a hardness: plastic area fraction per step.
    unloading : ndarray or None
        BEM sweeps with a branch: 1.0 on the unloading branch, 0.0 on loading.
    patch_width : ndarray or None
        Load-weighted contact patch width per step (grid points; see ContactResult).
    pull_off_force, pull_off_pressure, detached : float, float, bool or None
        Adhesive sweeps with an unloading branch (None otherwise): the most tensile load
        of that branch (N, N/m for profiles; 0 when none is tensile), as a mean pressure
        (Pa), and whether the branch reached separation (False: the force is a bound);
        :class:`roughfe.bem.adhesion.AdhesiveSweep`.

    All arrays are read-only.
    """

    results: tuple
    delta: np.ndarray
    mean_pressure: np.ndarray
    load: np.ndarray
    area_fraction: np.ndarray
    n_contact: np.ndarray
    stiffness: np.ndarray
    stiffness_fd: np.ndarray
    mean_gap: np.ndarray
    mean_plane_separation: np.ndarray
    free_volume_star: np.ndarray
    load_star: np.ndarray
    pressure_star: np.ndarray
    separation_star: np.ndarray
    rms_height: float
    rms_slope: float
    e_star: float
    # -- optional per-step arrays: the ContactResult field of the same name per step --
    delta_applied: Optional[np.ndarray] = None
    plastic_area_fraction: Optional[np.ndarray] = None
    unloading: Optional[np.ndarray] = None
    patch_width: Optional[np.ndarray] = None
    # -- optional values of the whole sweep (not per step; from_results' keywords) --
    pull_off_force: Optional[float] = None
    pull_off_pressure: Optional[float] = None
    detached: Optional[bool] = None

    __repr__ = compact_repr          # one line: arrays as shape and dtype, results counted

    @classmethod
    def from_results(cls, results, *, rms_slope: float, length: float,
                     **whole) -> "SweepResult":
        """Build a sweep from its steps (the one place the step arrays are made).

        Parameters
        ----------
        results : sequence of ContactResult
            The steps, in order; at least one.
        rms_slope : float
            gbar of the surface (for ``pressure_star``).
        length : float
            L in P* = p L / (E* sigma) (m).
        **whole
            Values of the whole sweep (:data:`_SWEEP_WHOLE`: the pull-off of an
            adhesive unloading branch).
        """
        results = tuple(results)
        if set(whole) - set(_SWEEP_WHOLE):
            raise InputError(f"from_results takes {_SWEEP_WHOLE} beside the steps, got "
                             f"{sorted(whole)}")
        if not results or not all(isinstance(r, ContactResult) for r in results):
            raise InputError("a SweepResult needs at least one ContactResult")
        arr = {k: np.array([getattr(r, k) for r in results], float) for k in _SWEEP_SERIES}
        optional = {}
        for f in dataclasses.fields(cls):
            if f.default is None and f.name not in _SWEEP_WHOLE:
                vals = [getattr(r, f.name, None) for r in results]
                if all(_is_number(v) for v in vals):
                    optional[f.name] = np.array(vals, float)
        sigma, e = results[0].rms_height, results[0].e_star
        pm = arr["mean_pressure"]
        with np.errstate(divide="ignore", invalid="ignore"):   # a flat punch: sigma = 0
            stars = {"load_star": pm * float(length) / (e * sigma),
                     "pressure_star": pm / (e * float(rms_slope)),
                     "separation_star": arr["mean_plane_separation"] / sigma}
        return cls(results=results, **arr, **optional, **stars, **whole,
                   n_contact=np.array([r.n_contact for r in results], dtype=np.int64),
                   stiffness_fd=central_differences(arr["delta"], pm,
                                                    optional.get("unloading")),
                   rms_height=sigma, rms_slope=float(rms_slope), e_star=e)

    @property
    def success(self) -> bool:
        """Every step reached its tolerance."""
        return all(r.success for r in self.results)

    @property
    def nit(self) -> int:
        """Iterations summed over the steps."""
        return int(sum(r.nit for r in self.results))

    @property
    def method(self) -> str:
        """``"bem"`` or ``"fem"``."""
        return self.results[0].method

    def series(self, name: str) -> np.ndarray:
        """The ContactResult field ``name`` of every step as a read-only float array
        (NaN where a step has None), e.g. ``sweep.series("contact_area")``."""
        if name not in {f.name for f in dataclasses.fields(ContactResult)}:
            raise InputError(f"ContactResult has no field {name!r}")
        vals = [getattr(r, name) for r in self.results]
        out = np.array([np.nan if v is None else v for v in vals], float)
        out.setflags(write=False)
        return out

    def to_records(self) -> list:
        """One JSON-safe dict per step (SI; None for non-finite values such as the
        infinite stiffness at full periodic contact): the keys :data:`RECORD_KEYS`, then
        the optional numeric fields the method set (e.g. FEM ``delta_applied``)."""
        recs = []
        for r, kfd in zip(self.results, self.stiffness_fd):
            s = r.scalars()
            s["stiffness_fd"] = to_jsonable(kfd)
            s["iterations"] = int(r.nit)
            recs.append({k: s[k] for k in RECORD_KEYS + r.optional_scalars()})
        return recs
