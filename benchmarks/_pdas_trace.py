"""Per-outer-step trace of the PDAS loop of ``benchmarks/pdas_eisenstat_walker.py``
(``--trace``; round 2, session 40, issue 16 section 1): where the set search spends its
steps, measured against the converged contact set A = {p > 0} of the same solve.

Each outer step k solves on the set I_k and hands I_{k+1} on. The trace records I_k
(a bool copy per step) and the step's scalars; once the solve has converged it reads:

* ``err``: |I_k xor A| (``miss`` = |A \\ I_k|, ``extra`` = |I_k \\ A|), grid points;
* ``enter`` / ``leave``: |I_{k+1} \\ I_k| / |I_k \\ I_{k+1}|, each split into the moves
  toward A (``ok``: entering points of A, leaving points off A) and away from it;
* the changed points by their distance to the edge of A (4-neighbour, periodic):
  ``edge`` 1 pixel (a point of A with a neighbour off A, or off A with one in A),
  ``near`` 2-3 pixels, else ``in`` (inside A) or ``out``;
* ``tiny``: changed points in a patch of A (4-connected, joined across the period) of
  at most ``TINY`` points that the first set I_1 (the coarse start's) does not touch;
  ``newp``: the same for new patches of any size;
* the residual's dominant term (``roughfe`` KKT residual extended to p < 0, as the
  script's ``extended_residual``: comp = sum |p| |w| / (n P h_pv), feas = max(-w) /
  h_pv, neg = max(-p) H_ii / h_pv) at the end of the inner solve;
* the globalization's state after the step (``bad`` count, ``tighten`` next).

Measured (session 40; H = 0.8, one load p/E* = 0.05, EW eta_max 0.03, seeds 1-3,
2048^2 and 4096^2): the first set is 32-37 % of |A| wrong at both sizes, 97 % of that
extras (the coarse pressure injected on 2 x 2 blocks); of all changed points 86-88 % lie
within 1 pixel of A's edge, 11-13 % at 2-3 pixels, < 1 % farther, 0.4 % in tiny new
patches (2082 such patches of A at 4096^2, seed 3, all but 39 points found at step 1);
the globalization never fired; the residual's dominant term is ``neg`` until the last
step or two. The failing rows (seed 3 26 -> 37, seed 2 26 -> 32) differ from seed 1 (31
-> 31) in the wrong-way moves of steps 2-3 (4096^2: 8766 / 5787 and 5637 / 549 points
into / out of A on seed 3, 2410 / 2614 and 5023 / 2285 on seed 2, 691 / 2543 and 675 /
454 on seed 1), after which the set error falls 2.8-4.6x per step instead of 6-10x
(``_pdas_restart.py``: the restart's rescaling of p is the cause).
"""
from __future__ import annotations

import numpy as np
from scipy import ndimage

from roughfe.bem.patches import _roots

#: a patch of A with at most this many points is "tiny"
TINY = 4


def _dilate(m, times=1):
    """4-neighbour periodic dilation of a bool grid, ``times`` times."""
    for _ in range(times):
        m = (m | np.roll(m, 1, 0) | np.roll(m, -1, 0) | np.roll(m, 1, 1)
             | np.roll(m, -1, 1))
    return m


def residual_terms(fine, p, u, mask, target):
    """The three terms of the extended residual (module docstring), as a dict."""
    g = u - fine.h
    g -= float(g[mask].mean())
    return {"comp": float(np.dot(np.abs(p), np.abs(g))) / (target * fine.scale),
            "feas": max(0.0, -float(g.min())) / fine.scale,
            "neg": max(0.0, -float(p.min())) * fine.c / fine.scale}


class Trace:
    """The sets I_k of one PDAS solve and the scalars of each step (module docstring)."""

    def __init__(self, shape):
        self.shape = shape
        self.sets, self.rows = [], []

    def step(self, mask, row, terms, bad, tighten):
        """Record I_k (``mask``, flat bool) and step k's scalars (``row``: the script's
        step dict; ``terms``: :func:`residual_terms` after the inner solve)."""
        self.sets.append(mask.copy())
        dom = max(terms, key=terms.get)
        self.rows.append({**row, "size": int(np.count_nonzero(mask)), "dominant": dom,
                          "terms": terms, "bad": int(bad), "tighten": bool(tighten)})

    def finish(self, final):
        """Classify every step against A = ``final`` (flat bool); a list of dicts."""
        A = final.reshape(self.shape)
        band1 = _dilate(A) & _dilate(~A)                     # 1 pixel from A's edge
        band3 = _dilate(A, 3) & _dilate(~A, 3)
        labels, nlab = ndimage.label(A)
        roots = _roots(labels, nlab, True)
        lab = roots[labels].reshape(-1)
        del labels
        size = np.bincount(lab, minlength=nlab + 1)
        seen = np.bincount(lab[self.sets[0]], minlength=nlab + 1) > 0
        new_patch = ~seen & (size > 0)        # size 0: a label joined to another root
        new_patch[0] = False
        tiny = new_patch & (size <= TINY)
        in_tiny, in_new = tiny[lab], new_patch[lab]
        band1, band3, A = band1.reshape(-1), band3.reshape(-1), A.reshape(-1)
        summary = {"A": int(A.sum()), "patches": int(np.count_nonzero(size[1:])),
                   "new_patches": int(new_patch.sum()), "new_patch_points": int(in_new.sum()),
                   "tiny_new_patches": int(tiny.sum()), "tiny_new_points": int(in_tiny.sum())}
        out = []
        for k, (I, row) in enumerate(zip(self.sets, self.rows)):
            nxt = self.sets[k + 1] if k + 1 < len(self.sets) else I
            enter, leave = nxt & ~I, I & ~nxt
            ch = enter | leave
            near = ch & band3 & ~band1
            far = ch & ~band3
            out.append({**row,
                        "err": int(np.count_nonzero(I != A)),
                        "miss": int(np.count_nonzero(A & ~I)),
                        "extra": int(np.count_nonzero(I & ~A)),
                        "enter": int(enter.sum()), "enter_ok": int((enter & A).sum()),
                        "leave": int(leave.sum()), "leave_ok": int((leave & ~A).sum()),
                        "edge": int((ch & band1).sum()), "near": int(near.sum()),
                        "in": int((far & A).sum()), "out": int((far & ~A).sum()),
                        "tiny": int((ch & in_tiny).sum()), "newp": int((ch & in_new).sum()),
                        "tiny_missing": int((in_tiny & ~I).sum())})
        return {"summary": summary, "steps": out}


def lines(trace):
    """Printable lines of :meth:`Trace.finish`'s result."""
    s = trace["summary"]
    yield (f"    trace: |A| {s['A']}, {s['patches']} patches; not touched by I_1: "
           f"{s['new_patches']} patches ({s['new_patch_points']} points), of them "
           f"{s['tiny_new_patches']} with <= {TINY} points ({s['tiny_new_points']} points)")
    yield ("    k  eta     its  r_k      dom   |I_k|     err(miss/extra)       "
           "enter(ok) leave(ok) | edge near in out | tiny(missing) newp | bad tight")
    for k, st in enumerate(trace["steps"], 1):
        eta = "-" if st["eta"] is None else f"{st['eta']:.2g}"
        yield (f"    {k:<2d} {eta:<7s} {st['inner']:<4d} {st['residual']:.2e} "
               f"{st['dominant']:<5s} {st['size']:<9d} {st['err']}({st['miss']}/"
               f"{st['extra']}) {st['enter']}({st['enter_ok']}) {st['leave']}"
               f"({st['leave_ok']}) | {st['edge']} {st['near']} {st['in']} {st['out']} | "
               f"{st['tiny']}({st['tiny_missing']}) {st['newp']} | {st['bad']} "
               f"{'T' if st['tighten'] else '-'}")
