"""Trapped-fluid pockets of the two-way coupling (issue 12 section 3): identity, fluid
content and pressure law (used by :mod:`roughfe.leakage.fsi`).

A **pocket** is a face-connected component of wet cells (gap > ``h_reg``) that reaches
neither the inlet nor the outlet. Each pocket holds a fixed amount of fluid, stored as a
reference state ``(V_c, P_c)``: the volume ``V_c`` (m^3) the fluid takes at the pressure
``P_c`` (Pa). The pocket pressure law (``trapped`` model):

* ``"volume"``, incompressible (``bulk_modulus=inf``): the fluid keeps its volume,
  ``V = V_c``; the uniform pocket pressure ``P`` is the unknown that enforces it;
* ``"volume"`` with a bulk modulus ``K`` (Pa): a liquid of constant bulk modulus,
  ``dp = -K dV/V``, i.e. ``V(P) = V_c exp(-(P - P_c)/K)`` or ``P = P_c + K ln(V_c/V)``
  (mass ``rho V`` conserved with ``rho ~ exp(P/K)``). ``K -> inf`` is the incompressible
  pocket, ``K -> 0`` keeps ``P = P_c``: the ``"pressure"`` model (tested both ways);
* ``"pressure"``: the pocket keeps its pressure at closure, ``P = P_c``;
* ``"film"``: no pocket is sealed; a pocket takes the regularised film's pressure (the
  limit of its surroundings): a drained pocket (leaky seal, or the closure state itself).

Membership hysteresis. A cell joins a pocket (or the flowing film) when its gap exceeds the
film ``h_reg``, and a cell that holds pocket liquid stays in its pocket while it is open
(``0 < gap <= h_reg``); it leaves when it closes (gap = 0, solid contact). Why: with one
threshold both ways a rim cell whose gap sits at ``h_reg`` moves across it with its own
pressure, in the pocket (pocket pressure) below it and in the film (film pressure) above
it, so no layout was self-consistent and the pocket passes alternated between two
layouts for ever (measured: 64^2 at 60 MPa, one cell at 0.91 / 1.03 ``h_reg``; 512^2 at
30 MPa, 6-7 cells at 0.975-1.19 ``h_reg`` splitting and re-merging one pocket). Physically
the liquid fills every open cell of its pocket; ``h_reg`` is the regularising film of the
contact spots, not a gap a liquid cannot enter. The seal against the flowing film stays the
film criterion: a pocket is released only when cells thicker than ``h_reg`` join it to
inlet or outlet (so a thin cell of a pocket next to the flow does not reopen it), and held
cells only count in a component with a wet cell (no pocket of thin cells alone).

Contact spots inside a pocket. A closed component (cells neither wet nor held) that borders
exactly one pocket, no flowing cell and neither inlet nor outlet belongs to that pocket:
the liquid around it is the pocket's, so its pore pressure (the limit of its surroundings,
:mod:`roughfe.leakage.fsi`) is the pocket pressure, not the film pressure of the
regularised Reynolds solve, which does not see the seal. Without it a spot inside a
cavitating (0 Pa) pocket felt the ambient film pressure, opened, joined the pocket, closed
under its 0 Pa and left again: a 2-cycle of the passes (measured on a sealed box unloaded
from 30 to 25 MPa, tests/test_leakage_pockets.py).

A liquid cannot sustain tension: the pocket pressure is bounded below by 0 Pa
(absolute; cavitation, the pocket then also holds vapour and ``V > V(P)``).

Identity between load steps (and between the pocket passes of one step): each pocket of
the previous state gives its fluid to the current components it overlaps, in proportion
to the current gap volume of the overlap. Shares that reach a component connected to
inlet or outlet are released (the pocket reopened: its fluid joins the flow); shares
reaching one pocket merge (``V_c`` summed at a common ``P_c``, the volume-weighted mean:
``V_c = sum V_i exp((P_i - P_c)/K)``, exact for the law above); a pocket split in two gives
each part its share. A component with no share is new in the current step: sealed off
from the flowing film, or (on unloading) a cavity opened among contact spots, counted
alike as ``"new"`` (``transfer`` does not see the previous gap); its closure state is
its drained state (volume, and gap-weighted mean film pressure), i.e. the closure
is placed at the end of the load step (a finer load path moves it closer to the true
closure load; measured in docs/theory/04b_leakage_ii.md). A previous pocket that
overlaps no wet cell (every cell closed or thinner than ``h_reg``) keeps its cells and
fluid, except under the ``"pressure"`` law (``bulk_modulus = 0``, ``K -> 0``) when every
cell is closed: a pocket squeezed shut keeps no liquid there (until round 2, session 24
it kept its label and closure pressure and carried fluid load on solid contact: 64^2,
10 -> 30 MPa, 9 such pockets, 12 % of the trapped load). Every case is a defined state.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .components import components_reaching

TRAPPED_MODELS = ("volume", "pressure", "film")
SEALED = ("volume", "pressure")
_EXP_CLIP = 50.0        # exp arguments of the merge rule (pressures far apart, small K)


@dataclass(frozen=True, eq=False)
class Pockets:
    """Sealed pockets: cell labels (-1 elsewhere) and per pocket the reference volume
    ``volume`` (m^3) of its fluid at the reference pressure ``pressure`` (Pa)."""

    labels: np.ndarray
    volume: np.ndarray
    pressure: np.ndarray

    @property
    def n(self) -> int:
        return int(self.volume.size)

    @classmethod
    def none(cls, shape) -> "Pockets":
        return cls(labels=np.full(shape, -1), volume=np.zeros(0), pressure=np.zeros(0))

    def same_cells(self, other: "Pockets") -> bool:
        """The same partition of the same cells (labels may be permuted)."""
        a, b = self.labels, other.labels
        if self.n != other.n or not np.array_equal(a >= 0, b >= 0):
            return False
        if not self.n:
            return True
        pairs = np.unique(a[a >= 0] * other.n + b[b >= 0])
        return pairs.size == self.n


def _components(mask, axis, periodic):
    lab, t_in, t_out = components_reaching(mask if axis == 0 else mask.T, periodic=periodic)
    return (lab if axis == 0 else lab.T), t_in | t_out


def wet_components(gap, h_reg, *, axis, periodic, hold=None):
    """Labels of the face-connected wet components (-1 elsewhere) and which of them reach
    inlet or outlet (flow along ``axis``).

    A cell is wet when its gap exceeds the film ``h_reg``; a cell of ``hold`` (the cells of
    the previous pockets) stays wet while it is open (gap > 0) and not part of a component
    that reaches inlet or outlet through cells thicker than the film: the hysteresis of
    the module docstring. The flowing components are those of the plain criterion; held
    cells count only in a component with a wet cell. When no cell outside the flow is
    wet or held open (the last pocket squeezed shut or reopened to the flow) the result
    is the flowing labelling (until round 2, session 24: an IndexError)."""
    wet = gap > h_reg
    lab, connected = _components(wet, axis, periodic)
    if hold is None or not np.any(hold):
        return lab, connected
    flowing = (lab >= 0) & connected[np.maximum(lab, 0)]
    inner = (wet | (np.asarray(hold, bool) & (gap > 0))) & ~flowing
    if not inner.any():     # the held cells closed or joined the flow: no pocket left
        return lab, connected
    lab2, conn2 = _components(inner, axis, periodic)
    # held cells only count with a wet cell of their component (no pocket of thin cells)
    some_wet = np.bincount(lab2[inner & wet], minlength=conn2.size) > 0
    inner &= some_wet[np.maximum(lab2, 0)]
    out = np.where(inner, lab2, np.where(flowing, lab + conn2.size, -1))
    return out, np.concatenate([conn2, connected])


def _enclose(lab, connected, *, axis, periodic):
    """``lab`` with every closed component (cells of label -1) that borders exactly one
    pocket component, no flowing one and neither inlet nor outlet given to that pocket: the
    contact spots inside a pocket (module docstring)."""
    closed = lab < 0
    if not closed.any() or closed.all():
        return lab
    cl, touch = _components(closed, axis, periodic)
    # category of every cell: its pocket component, -2 flowing, -3 closed
    cat = np.where(closed, -3, np.where(connected[np.maximum(lab, 0)], -2, lab))
    src, dst = [], []
    for ax in (0, 1):
        wrap = periodic and ax != axis          # the flow axis has inlet and outlet
        for step in (1, -1):
            if wrap:
                nb = np.roll(cat, step, axis=ax)
                a, b = cl, nb
            else:
                sl = [slice(None)] * 2
                sn = [slice(None)] * 2
                sl[ax] = slice(1, None) if step == 1 else slice(None, -1)
                sn[ax] = slice(None, -1) if step == 1 else slice(1, None)
                a, b = cl[tuple(sl)], cat[tuple(sn)]
            m = (a >= 0) & (b != -3)
            src.append(a[m])
            dst.append(b[m])
    src, dst = np.concatenate(src), np.concatenate(dst)
    if not src.size:
        return lab
    lo = np.full(touch.size, np.iinfo(np.int64).max)
    hi = np.full(touch.size, -4)
    np.minimum.at(lo, src, dst)
    np.maximum.at(hi, src, dst)
    owner = np.where((lo == hi) & (lo >= 0) & ~touch, hi, -1)
    out = lab.copy()
    inside = closed & (owner[np.maximum(cl, 0)] >= 0)
    out[inside] = owner[cl[inside]]
    return out


def _merge(volume, pressure, bulk_modulus):
    """One reference state of fluid shares at different pressures (module docstring)."""
    total = volume.sum()
    if total <= 0:
        return 0.0, float(pressure.mean())
    p_c = float((volume * pressure).sum() / total)
    if np.isfinite(bulk_modulus) and bulk_modulus > 0:
        total = float((volume * np.exp(np.clip((pressure - p_c) / bulk_modulus,
                                               -_EXP_CLIP, _EXP_CLIP))).sum())
    return float(total), p_c


def transfer(previous: Pockets, gap, fluid, cell_area, h_reg, *, axis, periodic,
             bulk_modulus=np.inf):
    """The pockets of the current gap with the fluid of ``previous`` (module docstring).

    Parameters
    ----------
    previous : Pockets
    gap : ndarray
        Current gap (m; 0 in contact).
    fluid : ndarray
        Current fluid pressure per cell (Pa): the closure pressure of new pockets.
    cell_area : float
        m^2.
    h_reg : float
        Wet threshold (m).
    axis : {0, 1}
        Flow axis.
    periodic : bool
    bulk_modulus : float
        Of the merge rule (inf: incompressible); 0 is the ``"pressure"`` law, under which a
        pocket squeezed shut loses its liquid (module docstring).

    Returns
    -------
    (Pockets, dict)
        The current pockets and counts ``{"new", "released", "merged", "kept",
        "squeezed"}``: new, no share of ``previous`` (sealed off or opened); kept, on
        no wet cell; squeezed, shut and dropped (``K = 0``).
    """
    lab, connected = wet_components(gap, h_reg, axis=axis, periodic=periodic,
                                    hold=previous.labels >= 0)
    lab = _enclose(lab, connected, axis=axis, periodic=periodic)
    ncomp = connected.size
    vol_cell = gap * cell_area
    shares = {}                         # component -> list of (volume, pressure)
    kept_cells, kept = [], []
    released = merged = squeezed = 0
    for i in range(previous.n):
        cells = previous.labels == i
        comp = lab[cells]
        on = comp >= 0
        if not on.any() and bulk_modulus == 0 and not np.any(gap[cells] > 0):
            squeezed += 1               # shut under the "pressure" law: its liquid is lost
            continue
        if not on.any():                # collapsed below the film: keeps cells and fluid
            kept_cells.append(cells)
            kept.append((previous.volume[i], previous.pressure[i]))
            continue
        w = np.bincount(comp[on], vol_cell[cells][on], ncomp)
        if w.sum() <= 0:
            w = np.bincount(comp[on], minlength=ncomp).astype(float)
        frac = w / w.sum()
        released += bool((frac[connected] > 0).any())
        for c in np.flatnonzero((frac > 0) & ~connected):
            shares.setdefault(int(c), []).append((previous.volume[i] * frac[c],
                                                  previous.pressure[i]))
    present = np.bincount(lab[lab >= 0], minlength=ncomp) > 0
    pockets = np.flatnonzero(present & ~connected)
    labels = np.full(gap.shape, -1)
    volume, pressure = [], []
    new = 0
    for k, c in enumerate(pockets):
        cells = lab == c
        labels[cells] = k
        if c in shares:
            v, p = np.array(shares[c]).T
            merged += v.size > 1
            vc, pc = _merge(v, p, bulk_modulus)
        else:                           # new in this step: its drained state
            new += 1
            vc = float(vol_cell[cells].sum())
            g = vol_cell[cells]
            pc = float((g * fluid[cells]).sum() / g.sum()) if g.sum() > 0 else \
                float(fluid[cells].mean())
        volume.append(vc)
        pressure.append(pc)
    for cells, (vc, pc) in zip(kept_cells, kept):
        labels[cells & (labels < 0)] = len(volume)
        volume.append(vc)
        pressure.append(pc)
    return (Pockets(labels=labels, volume=np.array(volume, float),
                    pressure=np.array(pressure, float)),
            {"new": new, "released": int(released), "merged": int(merged),
             "kept": len(kept), "squeezed": squeezed})


def penny_compliance(area, e_star):
    """dV/dP (m^3/Pa) of a uniformly pressurised disc of ``area`` (m^2) on a half-space:
    ``16 a^3 / (3 E*)`` with ``a = sqrt(area/pi)`` (the integral of the Boussinesq
    displacement under the disc)."""
    return 16.0 * (area / np.pi) ** 1.5 / (3.0 * e_star)


class PocketNewton:
    """The Newton step on the pocket pressures of the ``"volume"`` model.

    ``dP = -(J + diag(V/K))^-1 (V(gap) - V(P))`` with the pocket compliance
    ``J_jk = dV_j/dP_k`` (m^3/Pa) of the BEM with the contact set and the total load held
    fixed (:func:`roughfe.bem.stiffness.load_controlled_gap_response`): exact columns for
    the ``n_columns`` largest pockets (one restricted CG each; J is symmetric, so their
    rows too), :func:`penny_compliance` on the diagonal of the others; recomputed when
    more than 1 % of the contact set changed. The new pressures are >= 0 (cavitation)
    and the step is halved while the fluid alone would carry ``p_ext``.
    """

    def __init__(self, pockets, bulk_modulus, cell, e_star, n_columns):
        self.pk, self.K, self.cell, self.e_star = pockets, bulk_modulus, cell, e_star
        lab = pockets.labels
        self.inp = lab >= 0
        self.idx = lab[self.inp]
        self.count = np.bincount(self.idx, minlength=pockets.n)
        self.columns = np.argsort(-self.count, kind="stable")[:n_columns]
        self.J, self.J_contact, self.solves = None, None, 0

    def _jacobian(self, contact):
        from ..bem.stiffness import load_controlled_gap_response

        c = contact.contact
        if self.J is not None and (np.count_nonzero(c != self.J_contact)
                                   <= 0.01 * max(int(c.sum()), 1)):
            return self.J
        n = self.pk.n
        J = np.diag(penny_compliance(self.count * self.cell, self.e_star))
        units = [(self.pk.labels == k).astype(float) for k in self.columns]
        # the pocket cells count as open: a closed cell under the pocket pressure opens
        # (with them in the contact set a pocket squeezed shut has J ~ 0 and the Newton
        # step explodes: measured)
        dg = load_controlled_gap_response(contact, units, released=self.inp)
        self.solves += len(units)
        for col, k in zip(dg, self.columns):
            J[:, k] = np.bincount(self.idx, col[self.inp], n) * self.cell
            J[k, :] = J[:, k]
        self.J, self.J_contact = J, c.copy()
        return J

    def _law_step(self, p, vol, b):
        """Compressible pockets: per pocket the root of the linearised volume against the
        exact law, ``vol + b dP = V_c exp(-(p + dP - P_c)/K)``, with ``dP >= -p``
        (cavitation), by bisection (a Newton step on the exponential law moves at most
        ~K per evaluation and stalls when K is small: measured). The left side rises and
        the right side falls with dP: one root, bracketed by ``[-p, U]``,
        ``U = max(P_c - p, 0) + max(V_c - vol, 0)/b + 1``."""
        vc, pc = self.pk.volume, self.pk.pressure

        def f(dp):
            with np.errstate(over="ignore"):
                return vol + b * dp - vc * np.exp(-(p + dp - pc) / self.K)

        lo = -p
        hi = np.maximum(pc - p, 0.0) + np.maximum(vc - vol, 0.0) / b + 1.0
        cavitates = f(lo) >= 0
        for _ in range(400):
            if np.all(hi - lo <= 1e-14 * np.maximum(np.abs(hi), np.abs(lo)) + 1e-300):
                break
            mid = 0.5 * (lo + hi)
            up = f(mid) > 0
            hi = np.where(up, mid, hi)
            lo = np.where(up, lo, mid)
        return np.where(cavitates, -p, 0.5 * (lo + hi))

    def __call__(self, x, gap, contact, p_ext):
        """New pocket pressures (Pa) from the iterate ``x`` and its contact solution."""
        n = self.pk.n
        p = np.bincount(self.idx, x[self.inp], n) / self.count
        vol = np.bincount(self.idx, gap[self.inp], n) * self.cell
        J = self._jacobian(contact)
        # a pocket squeezed shut (volume 0) opens once its pressure exceeds the least solid
        # contact pressure on its cells (effective stress: the fluid takes over that load);
        # the linear model starts there (else the step is ~V(P)/J and, with a small bulk
        # modulus, V(P) ~ 0 stalls the pressure below the opening one: measured)
        shut = vol <= 0
        s_open = np.zeros(n)
        if shut.any():
            lab = self.pk.labels[self.inp]
            pc = np.full(n, np.inf)
            np.minimum.at(pc, lab, contact.pressure[self.inp])
            s_open = np.where(shut & np.isfinite(pc), pc, 0.0)
        dp = s_open + self._law_step(p + s_open, vol, np.diag(J).copy())
        # safeguard: the pockets alone may not lift the body off (halve the step)
        base = float(x[~self.inp].sum())
        for _ in range(40):
            new = np.maximum(p + dp, 0.0)
            if (base + (new * self.count).sum()) / x.size < p_ext:
                return new
            dp *= 0.5
        return np.maximum(p, 0.0)
