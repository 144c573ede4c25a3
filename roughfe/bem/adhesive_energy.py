"""The total energy of an adhesive contact, Eq. (1) of :mod:`roughfe.bem.adhesion`, and its
gradient on one grid: what the minimisers of :mod:`roughfe.bem.adhesive_cg` and L-BFGS-B
descend. Unknowns are the gap scaled by the law's range (x = g / range, dimensionless),
values and gradients are returned per traction scale S (Pa) so that both are O(1) per
cell; the pressure (Pa), the gap (m) and the cell spread of the gap (m) are read off the
same object.
"""
from __future__ import annotations

import numpy as np
import scipy.optimize


class AdhesiveEnergy:
    """Eq. (1) on one grid: value and gradient in the scaled gap variable x = g / range."""

    def __init__(self, op, law, c, spring, traction_scale):
        self.op, self.law, self.c = op, law, c
        self.spread = None            # the cell spread of the law (m), and its ramp
        self.ell, self.s0 = law.range, traction_scale
        self.n = c.size
        if op.periodic:
            self.kspec = op.inverse_spectrum()
            self.k0 = spring if spring is not None else 10.0 * float(self.kspec.max())
            self.target = float(c.mean())     # the imposed mean gap (m)
            self.gbar = self.target           # the spring's rest length (m; moved by
            #                                   roughfe.bem.adhesive_minimise to meet it)
            self.shape = c.shape
        else:
            self.kspec = 1.0 / op.spectrum.real
            self.shape = op.fft_shape
            self.phys = tuple(slice(0, m) for m in op.shape)
            self.inside = np.zeros(self.shape, bool)
            self.inside[self.phys] = True

    def bounds(self):
        lb = np.where(self.inside, 0.0, -np.inf).ravel() if not self.op.periodic \
            else np.zeros(self.n)
        return scipy.optimize.Bounds(lb, np.full(lb.size, np.inf))

    def split(self, x):
        """Gap g on the grid and the displacement field on ``shape`` (m)."""
        v = x.reshape(self.shape) * self.ell
        if self.op.periodic:
            return v, v - self.c
        u = v.copy()
        g = v[self.phys]
        u[self.phys] = g - self.c
        return g, u

    def pressure(self, x):
        """Total traction p (Pa) on the grid and the mean pressure pbar of the spring."""
        g, u = self.split(x)
        ku = self.op.convolve_spectrum(u, self.kspec)
        if self.op.periodic:
            pbar = self.k0 * (float(g.mean()) - self.gbar)
            return ku + pbar, pbar, g, u, ku
        return ku[self.phys], 0.0, g, u, ku

    def __call__(self, x):
        p, pbar, g, u, ku = self.pressure(x)
        phi, traction = self.law_at(g)
        value = 0.5 * float(np.vdot(u, ku)) + float(phi.sum())
        grad = ku
        if self.op.periodic:
            value += 0.5 * self.k0 * self.n * (float(g.mean()) - self.gbar) ** 2
            grad += pbar
            grad += traction
        else:
            grad[self.phys] += traction
        # Pi*A per (S range) and the traction residual per S: both O(1) per cell
        return value / (self.s0 * self.ell), (grad / self.s0).ravel()

    @property
    def spread(self):
        return self._spread

    @spread.setter
    def spread(self, value):
        self._spread = value
        self._ramp = None if value is None else self.law.cell_ramp(value)

    def law_at(self, g, rows=None):
        """``(phi, phi')`` of the interface law at the gap ``g`` (m), cell-averaged with
        the current spread; ``rows`` (a slice of the grid's first axis): ``g`` is the gap
        of those rows only (the blocks of :func:`roughfe.bem.adhesive_cg.adhesive_pcg`)."""
        if self._ramp is None:
            return self.law.evaluate(g)
        if rows is None:
            return self.law.evaluate(g, ramp=self._ramp)
        g1, width = self._ramp
        return self.law.evaluate(g, ramp=(g1[rows], width[rows]))

    def cell_spread(self, x):
        """Half-range of the gap across each cell (m), ``|grad g| dx / 2`` by central
        differences (one-sided at a non-periodic edge): the uniform spread of a linear
        gap over a cell in 1D, and the one with the same variance in 2D."""
        g = self.split(x)[0]
        grad2 = np.zeros(g.shape)
        for axis in range(g.ndim):
            if self.op.periodic:
                d = 0.5 * (np.roll(g, -1, axis) - np.roll(g, 1, axis))
            else:
                d = np.gradient(g, axis=axis)
            grad2 += d * d
        return 0.5 * np.sqrt(grad2)

    def residual(self, x):
        """Largest projected gradient (traction residual / traction scale S)."""
        _, grad = self(x)
        lb = self.bounds().lb
        pg = np.where((x <= lb) & (grad > 0), 0.0, grad)
        return float(np.max(np.abs(pg)))
