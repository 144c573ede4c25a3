"""Hertz's sphere capped by a hardness: a paraboloid pressed on an elastic half-space
whose interface is perfectly plastic (0 <= p <= H_p), the single-asperity reference of
``roughfe.bem.solve_contact(..., hardness=)`` (SI).

A sphere z = r^2 / (2 R) (R in m) meets a half-space of contact modulus E* (Pa) under a
load P (N) with the contact pressure capped at the hardness H_p (Pa), as in the BEM
(docs/theory/02b, "Hardness limit"): where p = H_p the interface flows and takes the
plastic displacement u_pl >= 0 that closes the gap; elsewhere in contact p < H_p and the
gap is 0; out of contact p = 0 and the gap is >= 0. Below the Hertz peak pressure
p0 = 3 P / (2 pi a^2) the cap is never reached and the answer is Hertz's
(a = (3 P R / (4 E*))^(1/3), Delta = a^2 / R, K = 2 E* a). Above it a plastic disc
r < c carries p = H_p, an elastic annulus c < r < a the rest: a mixed problem with no
closed form, solved here on rings.

Method (a session 33 review's reference, moved here in session 34):

* Rings. The radius is cut into ``n`` rings of equal width up to
  r_max = 1.5 max(a_Hertz, sqrt(P / (pi H_p))), each with a constant pressure p_j. The
  surface displacement of a uniform pressure on a disc of radius b at radius r is
  (Johnson 1985, Eq. 3.39; E, K: complete elliptic integrals of parameter m)

      u(r; b) = 4 b E(r^2 / b^2) / (pi E*)                          for r < b,
      u(r; b) = 4 r [E(m) - (1 - m) K(m)] / (pi E*),  m = b^2 / r^2,  for r >= b,

  and a ring b_j < r < b_{j+1} is the difference of two discs: the exact influence
  A_ij = u(r_i; b_{j+1}) - u(r_i; b_j) at the ring middles r_i (m/Pa).
* The cap (three sets). For an approach Delta, every ring is off (p = 0), elastic
  (gap w = 0, p free) or at the cap (p = H_p); with p_S = H_p on the capped set S the
  elastic set C solves A_CC p_C = Delta - z_C - A_CS H_p, and
  w = A p + z - Delta. Rings move between the sets until they agree: p < 0 -> off,
  p > H_p -> capped, an off ring with w < 0 -> elastic, a capped ring with w > 0 (it
  would need a negative u_pl) -> elastic. At the cap u_pl = -w.
* The load balance. P(Delta) = sum_j p_j pi (b_{j+1}^2 - b_j^2) is set equal to the
  load by Brent's method on Delta.

The rings are solved twice: ``n`` of equal width, then half of them across the rim
c0 - 4 dr .. a0 + 4 dr that the first pass found (a thin rim had 1-2 of 200 uniform
rings) and half inside it. The contact radius a and the plastic radius c are where p^2
and (H_p - p)^2 reach 0 (both linear in the distance to a smooth edge: p ~ sqrt(a - r),
H_p - p ~ sqrt(r - c)), extrapolated from the two elastic rings beside each edge (the
edge between the sets where there are not two). The loading stiffness K = dP/dDelta
(N/m) is taken by central differences (load +-1 %; +-0.1 % spans too few rings of a
thin rim) on the same rings: the fixed-set tangent of the rings (the capped rings held
at H_p) needs the rim resolved, and at 0.2 p0, where the rim is under 2e-4 a, it was
2.4-3.1x dP/dDelta on 100-800 uniform rings.

Measured (R = 10 mm, E* = 1.1 GPa, P = 0.1 N, 200 rings; docs/theory/02b, "Hardness
limit"): at H_p = (1 - 1e-6) p0 Hertz's a, Delta and K within 6.6e-4, 3e-6 and 2.8e-4;
at 1e-3 p0 A within 1.2e-3 of the rigid-plastic P / H_p; 100 and 400 rings within 4e-4
(a, c, Delta) and 8e-4 (K) at 0.5 p0. The BEM (64^2) at 0.8, 0.5, 0.2 p0: Delta within
1e-4, 6.6e-4, 6.1e-3, A within 2.8 %, plastic area 1.9 %, K 0.7, 1.1 and 8 % (a rim
under a grid point: :func:`roughfe.bem.patches.rim_note`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.optimize
from scipy.special import ellipe, ellipk

from ..errors import InputError, check_finite_positive
from ..frozen import ReadOnlyArrays, compact_repr, read_only_arrays
from ..reference import hertz_sphere

#: rings of the default reference (200: the contact area within 0.5 % of the ring
#: refinement's limit, 0.2 s per load)
RINGS = 200

REFERENCES = ("Hertz H. (1882) J. reine angew. Math. 92:156-171",
              "Johnson K.L. (1985) Contact Mechanics, Cambridge University Press, "
              "Eq. 3.39 (uniform pressure on a disc) and Sec. 4.2")


@dataclass(frozen=True, eq=False)
class CappedHertz(ReadOnlyArrays):
    """A sphere on a perfectly plastic interface at one load (SI).

    Attributes
    ----------
    radius, e_star, load, hardness : float
        R (m), E* (Pa), P (N), H_p (Pa).
    approach : float
        Delta (m), counted from the first contact, as the BEM's ``delta``.
    contact_radius, plastic_radius : float
        a and c (m): the edge of the contact and of the disc at p = H_p (0: no flow).
    stiffness : float
        K = dP/dDelta (N/m) of the loading, the capped rings held at H_p.
    central_plastic_displacement : float
        u_pl at the centre (m): the depth of the dent (0 without flow).
    ring_edges : ndarray
        The rings' edges b_0 = 0 < b_1 < ... < b_n (m).
    pressure, plastic_displacement : ndarray
        Each ring's pressure (Pa) and u_pl at its middle (m).
    rings : int
        n (0 below p0: Hertz's closed form, no rings).
    """

    radius: float
    e_star: float
    load: float
    hardness: float
    approach: float
    contact_radius: float
    plastic_radius: float
    stiffness: float
    central_plastic_displacement: float
    ring_edges: np.ndarray
    pressure: np.ndarray
    plastic_displacement: np.ndarray
    rings: int
    references: tuple = REFERENCES

    __repr__ = compact_repr

    def __post_init__(self):
        read_only_arrays(self)

    @property
    def ring_radius(self) -> np.ndarray:
        """The rings' middles (m)."""
        return 0.5 * (self.ring_edges[1:] + self.ring_edges[:-1])

    @property
    def contact_area(self) -> float:
        """pi a^2 (m^2)."""
        return float(np.pi * self.contact_radius ** 2)

    @property
    def plastic_area(self) -> float:
        """pi c^2 (m^2): the area at p = H_p, as the BEM's plastic area."""
        return float(np.pi * self.plastic_radius ** 2)


def disc_displacement(r, b, e_star):
    """Surface displacement (m) at radius ``r`` (m) of a unit pressure (1 Pa) on a disc
    of radius ``b`` (m) of a half-space of contact modulus ``e_star`` (Pa): Johnson 1985,
    Eq. 3.39 (module docstring); 0 for b = 0. Broadcasts ``r`` against ``b``."""
    r, b = np.broadcast_arrays(np.asarray(r, float), np.asarray(b, float))
    out = np.zeros(r.shape)
    inside = r < b
    out[inside] = 4 * b[inside] / (np.pi * e_star) * ellipe((r[inside] / b[inside]) ** 2)
    outside = ~inside & (b > 0)
    m = (b[outside] / r[outside]) ** 2
    out[outside] = 4 * r[outside] / (np.pi * e_star) * (ellipe(m) - (1 - m) * ellipk(m))
    return out


def capped_hertz(radius, e_star, load, hardness, rings: int = RINGS) -> CappedHertz:
    """The sphere of radius ``radius`` (m) under ``load`` (N) on a half-space of
    ``e_star`` (Pa) with the contact pressure capped at ``hardness`` (Pa): rings, the
    three-set cap and Brent's method on the approach (module docstring). Below Hertz's
    peak pressure (H_p >= p0) it is Hertz's solution."""
    R = check_finite_positive("radius", radius)
    e = check_finite_positive("e_star", e_star)
    P = check_finite_positive("load", load)
    H = check_finite_positive("hardness", hardness)
    if isinstance(rings, bool) or not isinstance(rings, (int, np.integer)) or rings < 20:
        raise InputError(f"rings must be an integer >= 20, got {rings!r}")
    hz = hertz_sphere(R, e, load=P)
    if H >= hz.peak_pressure:          # the cap is not reached: Hertz
        return CappedHertz(R, e, P, H, hz.approach, hz.contact_radius, 0.0, hz.stiffness,
                           0.0, np.zeros(1), np.zeros(0), np.zeros(0), 0)
    n = int(rings)
    dr = 1.5 * max(hz.contact_radius, np.sqrt(P / (np.pi * H))) / n
    first = _solve(np.arange(n + 1) * dr, R, e, P, H, hz)
    a0, c0 = first.contact_radius, first.plastic_radius
    # the rings again, half of them across the rim c0 - 4 dr .. a0 + 4 dr (a thin rim
    # had 1-2 of 200 uniform rings at 0.2 p0) and half inside the plastic disc
    inner, outer = c0 - 4 * dr, a0 + 4 * dr
    edges = (np.linspace(0.0, outer, n + 1) if inner <= 0 else np.concatenate(
        [np.linspace(0.0, inner, n // 2 + 1)[:-1], np.linspace(inner, outer, n - n // 2 + 1)]))
    s = _solve(edges, R, e, P, H, hz)
    eps = 1e-2          # dP/dDelta by central differences on the same rings
    lo, hi = (_solve(edges, R, e, P * (1 + f), H, hz).approach for f in (-eps, eps))
    return CappedHertz(R, e, P, H, s.approach, s.contact_radius, s.plastic_radius,
                       2 * eps * P / (hi - lo), float(s.plastic_displacement[0]),
                       edges, s.pressure, s.plastic_displacement, len(edges) - 1)


def _solve(edges, R, e, P, H, hz):
    """The rings ``edges`` (m) at the load P: Brent's method on the approach, each
    approach's state by :func:`_three_sets`; a :class:`CappedHertz` without K (NaN)."""
    mid = 0.5 * (edges[1:] + edges[:-1])
    D = disc_displacement(mid[:, None], edges[None, :], e)
    A = D[:, 1:] - D[:, :-1]                      # ring j's influence at middle i (m/Pa)
    area = np.pi * np.diff(edges ** 2)
    z = mid ** 2 / (2 * R)
    keep = {}

    def excess(delta):
        guess = keep["state"].sets if "state" in keep else (z < delta).astype(int)
        state = keep["state"] = _three_sets(A, z, delta, H, guess)
        return float(state.p @ area) - P

    scale = hz.approach
    delta = scipy.optimize.brentq(excess, 1e-3 * scale,
                                  20 * scale * max(1.0, hz.peak_pressure / H),
                                  xtol=1e-13 * scale, rtol=1e-14)
    excess(delta)
    s = keep["state"]
    plastic = np.where(s.sets == 2, -s.w, 0.0)
    return CappedHertz(R, e, P, H, float(delta), _edge(edges, s.p, s.sets),
                       _edge(edges, H - s.p, s.sets, plastic=True), float("nan"),
                       float(plastic[0]), edges, s.p, plastic, len(mid))


@dataclass(frozen=True, eq=False)
class _State:
    sets: np.ndarray        # 0 off, 1 elastic, 2 at H_p
    p: np.ndarray
    w: np.ndarray


def _three_sets(A, z, delta, hardness, sets):
    """The rings' state at the approach ``delta`` from the guess ``sets``: the exchanges
    of the module docstring until no ring moves (at most 4 n passes)."""
    sets = np.asarray(sets, int).copy()
    for _ in range(4 * len(z)):
        C, S = sets == 1, sets == 2
        p = np.where(S, hardness, 0.0)
        if C.any():
            p[C] = np.linalg.solve(A[np.ix_(C, C)], delta - z[C] - A[np.ix_(C, S)] @ p[S])
        w = A @ p + z - delta
        tol = 1e-14 * delta
        new = sets.copy()
        new[C & (p < 0)], new[C & (p > hardness)] = 0, 2
        new[(sets == 0) & (w < -tol)], new[S & (w > tol)] = 1, 1
        if np.array_equal(new, sets):
            break
        sets = new
    return _State(sets, p, w)


def _edge(edges, q, sets, plastic=False):
    """Where ``q`` of the elastic rings reaches 0 (m): p at the contact edge, H_p - p at
    the edge of the plastic disc (``plastic``). q^2 is linear in the distance to a smooth
    edge (p ~ sqrt(a - r), H_p - p ~ sqrt(r - c)): extrapolated from the two elastic
    rings beside the edge, kept within half a ring of the edge between the sets. Without
    two such rings: that edge (the outer edge of the last loaded, or capped, ring; 0
    without a capped ring)."""
    mid = 0.5 * (edges[1:] + edges[:-1])
    last = np.flatnonzero(sets == 2 if plastic else sets > 0)
    if last.size == 0:
        return 0.0
    k = int(last.max())
    i, j = (k + 2, k + 1) if plastic else (k - 1, k)   # j beside the edge, i further
    if not (0 <= i < len(mid) and sets[i] == 1 and sets[j] == 1 and q[i] > q[j] >= 0):
        return float(edges[k + 1])
    x = mid[j] - q[j] ** 2 * (mid[i] - mid[j]) / (q[i] ** 2 - q[j] ** 2)
    return float(np.clip(x, mid[k] if plastic else edges[k], mid[j] if plastic else
                         edges[k + 1]))


#: the step keys of :func:`beside_capped_hertz` and their units
UNITS = {"capped_hertz_area_fraction": "-", "capped_hertz_plastic_area_fraction": "-",
         "capped_hertz_approach": "m", "capped_hertz_stiffness": "Pa/m (dp/dDelta)"}

NOTE = ("Hertz's sphere with the contact pressure capped at the hardness (perfectly "
        "plastic interface), solved on rings (roughfe.theory.capped_hertz): the contact "
        "area, the area at p = H_p, the approach and the loading stiffness dp/dDelta of "
        "the first loading from the virgin sphere at each step's load; unloading steps and "
        "steps after one get None (docs/theory/02b, 'Hardness limit')")


def beside_capped_hertz(surface, shape, e_star, pressures, unloading, hardness):
    """The capped Hertz reference beside the steps of a hardness run on one smooth cap.

    ``shape``: :func:`roughfe.theory.asperity.single_asperity` of ``surface``;
    ``pressures`` (Pa or None) and ``unloading`` (bool) per step, in path order;
    ``hardness`` H_p (Pa). A sphere's steps of the first loading
    (:func:`roughfe.theory.plastic.first_loading`) whose contact fits in the window
    (2 a <= its shortest side) get :data:`UNITS`' keys at the load p A_n (the approach
    counted, as the BEM's, from the highest grid point: the reference's less the cap's
    ``summit_gap``); the other steps None. An ellipsoid or a cylinder has no reference here: every step gets None and the
    block says why. Returns ``(records, info)``: per step a dict of the keys, and the
    ``"capped_hertz"`` block (H_p, rings, units, note, references, or ``evaluated``
    False and ``why``)."""
    from .plastic import first_loading
    H = check_finite_positive("hardness (Pa, the yield pressure of the interface)", hardness)
    none = dict.fromkeys(UNITS)
    if shape["shape"] != "sphere":
        why = ("no capped reference for a cylinder (the half-plane's approach is not "
               "defined, and the rings are axisymmetric)" if shape["shape"] == "cylinder"
               else "no capped reference for an ellipsoid (the rings are axisymmetric; "
                    "principal radii beyond the sphere's ratio)")
        return [dict(none) for _ in pressures], {"evaluated": False, "why": why}
    side, area = min(surface.size), surface.nominal_area
    records = []
    for p, ok in zip(pressures, first_loading(pressures, unloading, H)):
        ref = capped_hertz(shape["radius"], e_star, p * area, H) if ok else None
        if ref is None or 2 * ref.contact_radius > side:
            records.append(dict(none))
            continue
        records.append({"capped_hertz_area_fraction": ref.contact_area / area,
                        "capped_hertz_plastic_area_fraction": ref.plastic_area / area,
                        "capped_hertz_approach": ref.approach - shape["summit_gap"],
                        "capped_hertz_stiffness": ref.stiffness / area})
    return records, {"evaluated": True, "hardness": H, "rings": RINGS, "note": NOTE,
                     "units": dict(UNITS), "references": list(REFERENCES)}
