"""Step 4 of 2D MWM sequencing: the surface model over all acquisitions on tensor grids,
with separable linear algebra (:class:`GridModel`).

See :mod:`roughfe.genomics.sequencing.surface` for the model and the conventions.
"""
from __future__ import annotations

import math

import numpy as np
import scipy.linalg
import scipy.linalg.lapack

from ..genome import chromosome_range
from .regularise import noise_damping
from .surface_result import about_plane


#: the diagonal (times the number of columns) added to the column-scaled Gram matrix of
#: the nonlinear fit's solves, and of an exact solve when it is too ill-conditioned to
#: solve (:data:`MAX_COND`)
RIDGE = 1e-13
#: the largest condition number (1-norm estimate, LAPACK dpocon) of the column-scaled Gram
#: matrix that an exact solve (:meth:`GridModel.solve`) solves as it is: its two refinement
#: steps, each contracting the error by about cond x 1.1e-16, then reach round-off
MAX_COND = 1e15


def _factor(gram, ridge=True):
    """Cholesky factor (``scipy.linalg.cho_factor``) of the column-scaled Gram matrix, with
    the diagonal :data:`RIDGE` times its size added (``ridge``), or (``ridge=False``, the
    exact solves) only when its condition number exceeds :data:`MAX_COND` or the
    factorisation fails (two ridges merging, chromosomes collinear).

    The diagonal keeps the nonlinear fit's landscape smooth where the model is singular
    (merging ridges, fine sub-lattices); it also bounds the fit's accuracy by the
    directions below it, which the refinement steps contract by only 0.99 each. The 10
    ridges of an ``mwm_surface`` (its longest waves span the window) make a full-rank
    Gram matrix of cond 3e13 (1-norm estimate 6-7e13 at 64^2-256^2; smallest eigenvalue
    1.4e-13 under the 1.8e-11 added): with the diagonal, the fit at the true lattice
    misfits by 1.6e-7 and its genes are H 0.7036 and A 1.049e-6 for 0.7 and 1e-6; solved
    as it is, 3.9e-15 and H, A to 2e-10. Until round 2, session 33 the exact solves added
    it too. The nonlinear fit keeps it: solved as they are, its poor fits (one ridge
    found, cost 7 %) ended on another sub-lattice (gamma^(1/8) for gamma^(1/4)), beyond
    the coarser lattices tried, and a test genome was lost. (14 ridges make the Gram
    matrix singular to working precision: their longest waves are not told apart by the
    heights.)"""
    if not ridge:
        try:
            chol = scipy.linalg.cho_factor(gram)
            rcond, info = scipy.linalg.lapack.dpocon(
                chol[0], float(np.abs(gram).sum(axis=0).max()), uplo="L" if chol[1] else "U")
            if info == 0 and rcond * MAX_COND > 1.0:
                return chol
        except np.linalg.LinAlgError:
            pass
    return scipy.linalg.cho_factor(gram + RIDGE * gram.shape[0] * np.eye(gram.shape[0]))


class GridModel:
    """The MWM surface model over all acquisitions, with separable linear algebra (step 4).

    Rows are the valid nodes of a tensor grid per acquisition: all nodes, or a fixed
    pseudo-random choice of ``axis_nodes`` x and ``axis_nodes`` y coordinates (the nonlinear
    fit needs a few rows per unknown, not every node). Columns: cos and sin of every (m, n)
    plane wave active in the acquisition (Eq. 3.5 range), then a plane (1, x/L, y/L) per
    acquisition.

    A plane wave is separable, exp(i k.r) = exp(i k_x x) exp(i k_y y), and so are the plane
    columns and the x- and y-weighted waves of the Jacobian: on a tensor grid the Gram entry
    sum_r conj(e_a) e_b is (sum_x ...)(sum_y ...), O(N K^2) instead of O(N^2 K^2), and a
    projection A^T f or an evaluation A c is a product of the N x N grid with N x K factors,
    O(N^2 K), with no N^2 x K design matrix. Undefined nodes are removed from the Gram
    matrix by subtracting their (few) rows, and from projections by zeroing the field there.
    """

    def __init__(self, acqs, n_nodes, axis_nodes=None):
        self.acqs = acqs
        self.n_nodes = n_nodes
        rng = np.random.default_rng(0)
        self.grids = []
        zs, blocks = [], []
        for k, a in enumerate(acqs):
            n = a.z.shape[0]
            idx = [np.arange(n) if axis_nodes is None or axis_nodes >= n
                   else np.sort(rng.choice(n, size=axis_nodes, replace=False)) for _ in "xy"]
            z = a.z[np.ix_(*idx)]
            ok = np.isfinite(z)
            self.grids.append(dict(x=a.x[idx[0]], y=a.y[idx[1]], ok=ok,
                                   z0=np.where(ok, z, 0.0), bad=np.nonzero(~ok)))
            zs.append(z[ok])
            blocks.append(np.full(int(ok.sum()), k))
        self.z = np.concatenate(zs)
        self.block = np.concatenate(blocks)
        self.scale = float(np.sqrt(np.mean(self.z ** 2)))

    def ranges(self, log_q1, log_gamma):
        lam1 = 2 * math.pi / math.exp(log_q1)
        return [chromosome_range(math.exp(log_gamma), lam1, a.length, self.n_nodes)
                for a in self.acqs]

    def _waves(self, p, ranges, cap):
        """Waves (n, m, q, theta_m) of the model, lowest chromosome first."""
        lo = min(r[0] for r in ranges)
        hi = max(r[1] for r in ranges) if cap is None else min(cap, max(r[1] for r in ranges))
        theta = np.asarray(p[2:], float)
        nn, mm = np.meshgrid(np.arange(lo, hi + 1), np.arange(theta.size), indexing="ij")
        nn, mm = nn.ravel(), mm.ravel()
        return nn, mm, np.exp(p[0] + (nn - 1) * p[1]), theta[mm]

    def _factors(self, k, q, theta_w, active):
        """x and y factors (N x (W + 3), complex) of the waves (zero where inactive in
        acquisition k) and of the plane columns 1, x/L, y/L."""
        g, length = self.grids[k], self.acqs[k].length
        fx = np.exp(1j * np.multiply.outer(g["x"], q * np.cos(theta_w))) * active
        fy = np.exp(1j * np.multiply.outer(g["y"], q * np.sin(theta_w)))
        ox, oy = np.ones(g["x"].size), np.ones(g["y"].size)
        return (np.column_stack([fx, ox, g["x"] / length, ox]),
                np.column_stack([fy, oy, oy, g["y"] / length]))

    def _real(self, k, values, n_waves, n_cols):
        """Complex column values (..., W + 3) in the real design layout
        [cos (W), sin (W), 3 plane columns per acquisition] (zero for other acquisitions)."""
        out = np.zeros(values.shape[:-1] + (n_cols,))
        out[..., :n_waves] = values[..., :n_waves].real
        out[..., n_waves:2 * n_waves] = values[..., :n_waves].imag
        out[..., 2 * n_waves + 3 * k:2 * n_waves + 3 * k + 3] = values[..., n_waves:].real
        return out

    def _project(self, k, fx, fy, fields, n_waves, n_cols):
        """A_k^T f for each grid field f (..., N, N; zero at undefined nodes), real layout."""
        return self._real(k, np.sum((fx.T @ fields) * fy.T, axis=-1), n_waves, n_cols)

    @staticmethod
    def _weights(k, coef, n_waves):
        """Complex weights c (..., W + 3) of the separable columns for coefficients
        coef (..., n_cols) in the real layout: A_k coef = Re(sum_b c_b F_b)."""
        w = n_waves
        return np.concatenate([coef[..., :w] - 1j * coef[..., w:2 * w],
                               coef[..., 2 * w + 3 * k:2 * w + 3 * k + 3]], axis=-1)

    @staticmethod
    def _evaluate(fx, fy, weights):
        """Re(sum_b c_b F_b) on the grid for weights c (..., W + 3): (..., N, N)."""
        return ((fx * weights[..., None, :]) @ fy.T).real

    def _gram(self, k, fx, fy, n_waves, n_cols, bad=None):
        """Real Gram matrix A_k^T A_k over the valid nodes of acquisition k (those not in
        ``bad``, the (x, y) indices of the nodes left out; default the undefined ones)."""
        sp = (fx.T @ fx) * (fy.T @ fy)                      # sum e_a e_b
        sm = (fx.conj().T @ fx) * (fy.conj().T @ fy)        # sum conj(e_a) e_b
        w = n_waves
        re = np.r_[np.arange(w), 2 * w + 3 * k + np.arange(3)]   # cos and plane columns
        fi = np.r_[np.arange(w), w + np.arange(3)]                # their separable index
        im = np.arange(w, 2 * w)                                  # sin columns
        gram = np.zeros((n_cols, n_cols))
        gram[np.ix_(re, re)] = 0.5 * (sp + sm).real[np.ix_(fi, fi)]
        gram[np.ix_(im, im)] = 0.5 * (sm - sp).real[:w, :w]
        cross = 0.5 * (sp + sm).imag[fi, :w]                      # sum Re(F_a) Im(e_b)
        gram[np.ix_(re, im)] = cross
        gram[np.ix_(im, re)] = cross.T
        bx, by = self.grids[k]["bad"] if bad is None else bad
        if bx.size:
            rows = self._real(k, fx[bx] * fy[by], w, n_cols)
            gram -= rows.T @ rows
        return gram

    def _kept(self, keep):
        """The grids with only the rows ``keep`` (bool per row, in the order of :attr:`z`)
        valid: the others are left out as undefined nodes are."""
        out = []
        for k, g in enumerate(self.grids):
            ok = g["ok"].copy()
            ok[ok] = keep[self.block == k]
            out.append(dict(g, ok=ok, z0=np.where(ok, g["z0"], 0.0), bad=np.nonzero(~ok)))
        return out

    def solve(self, p, ranges, cap=None, exact=False, keep=None, regularise=False):
        """Linear least squares for the wave and plane coefficients at the lattice ``p``
        (fitted to the rows ``keep`` only when given: bool per row, the others left out
        as undefined nodes are, for the held-out nodes of :mod:`.holdout`; ``resid`` is
        then over the kept rows).

        Normal equations with a Cholesky factor of the column-scaled Gram matrix (plane
        waves of distinct wavevectors are nearly orthogonal, so it is mostly well
        conditioned; many ridges whose longest waves span the window are not, cond 3e13
        with 10 ridges; a ridge duplicated by the fit makes it singular), with a small
        diagonal added except in an exact solve (``exact``) that does not need it
        (:func:`_factor`). The residual is
        evaluated on the grid, and one step of iterative refinement (``exact``: two)
        restores the accuracy of a backward-stable solver: noise-free data are fitted to
        round-off (relative cost ~1e-29, not the ~1e-20 floor of the plain normal
        equations), which the fit's "reproduced to round-off" test needs. ``gram``: the
        Gram matrix A^T A of the design (real layout), for the genes' height misfit.

        ``regularise``: the least-squares fit is followed by Tikhonov's at the damping
        lambda of its own misfit (:func:`~.regularise.noise_damping`, as the profile
        fit's, :mod:`.regularise`, with the data's norm that of the heights about each
        acquisition's best plane, as the misfits are taken,
        :func:`~.surface_result.plane_free_misfits`: the planes are free unknowns, and a
        mean or tilt of the data is no height a wave may carry): lambda^2 added to the
        diagonal of the column-scaled Gram matrix, and each refinement step less lambda^2 times the scaled
        coefficients (the gradient of the damped misfit), so that the steps converge to
        the damped fit, not back to least squares. ``damping`` (lambda, 0 for a fit
        not regularised) is returned with the solution.
        """
        nn, mm, q, theta_w = self._waves(p, ranges, cap)
        w = nn.size
        n_cols = 2 * w + 3 * len(self.acqs)
        fac = [self._factors(k, q, theta_w, (nn >= ns) & (nn <= nf))
               for k, (ns, nf) in enumerate(ranges)]
        grids = self.grids if keep is None else self._kept(keep)
        gram = sum(self._gram(k, fx, fy, w, n_cols, grids[k]["bad"])
                   for k, (fx, fy) in enumerate(fac))
        norm = np.sqrt(np.clip(np.diag(gram), 0.0, None))    # round-off: undefined nodes
        norm[norm == 0] = 1.0
        gram = gram / np.outer(norm, norm)

        def residual(coef):
            return [np.where(g["ok"], g["z0"] - self._evaluate(fx, fy, self._weights(k, coef, w)),
                             0.0) for k, (g, (fx, fy)) in enumerate(zip(grids, fac))]

        def fit(damping):
            """(coef, residual fields, lsq) of the fit damped by ``damping`` (0: least
            squares)."""
            chol = _factor(gram + damping ** 2 * np.eye(n_cols), ridge=not exact)

            def lsq(fields):
                """G^-1 A^T f for grid fields f (per acquisition: (..., N, N))."""
                rhs = sum(self._project(k, fx, fy, f, w, n_cols)
                          for k, ((fx, fy), f) in enumerate(zip(fac, fields)))
                return scipy.linalg.cho_solve(chol, (rhs / norm).T).T / norm

            coef = lsq([g["z0"] for g in grids])
            res = residual(coef)
            for _ in range(2 if exact else 1):
                step = lsq(res)
                if damping:
                    step -= damping ** 2 * scipy.linalg.cho_solve(chol, norm * coef) / norm
                coef = coef + step
                res = residual(coef)
            return coef, res, lsq

        coef, res, lsq = fit(0.0)
        damping = 0.0
        if regularise:
            data = math.sqrt(sum(float(np.sum(about_plane(g["x"], g["y"], g["ok"],
                                                          g["z0"][g["ok"]]) ** 2))
                                 for g in grids))
            rss = sum(float(np.sum(r[g["ok"]] ** 2)) for r, g in zip(res, grids))
            damping = noise_damping(rss, sum(int(g["ok"].sum()) for g in grids), n_cols, data)
            if damping > 0.0:
                coef, res, lsq = fit(damping)
        resid = np.concatenate([r[g["ok"]] for r, g in zip(res, grids)])
        return dict(nn=nn, mm=mm, q=q, theta_w=theta_w, coef=coef, resid=resid, fac=fac,
                    lsq=lsq, gram=gram * np.outer(norm, norm), damping=damping)

    def node_coordinates(self):
        """(x, y) of every row (valid node, in the order of :attr:`z`), m: (rows, 2)."""
        out = []
        for g in self.grids:
            ix, iy = np.nonzero(g["ok"])
            out.append(np.column_stack([g["x"][ix], g["y"][iy]]))
        return np.vstack(out)

    def heights(self, p, ranges, coef):
        """The model's heights (waves and planes) for the coefficients ``coef`` (real
        layout, as :meth:`solve` returns them at ``p``, ``ranges``) on every node of each
        acquisition's grid, undefined nodes included: one array per acquisition."""
        nn, _, q, theta_w = self._waves(p, ranges, None)
        return [self._evaluate(*self._factors(k, q, theta_w, (nn >= ns) & (nn <= nf)),
                               self._weights(k, coef, nn.size))
                for k, (ns, nf) in enumerate(ranges)]

    def jacobian(self, p, sol):
        """Kaufman's variable-projection Jacobian d(resid)/d(p) ~ -(I - P) (dA/dp) c for
        p = (ln q1, ln gamma, theta_1..theta_M), evaluated on the grid by separable products:
        d/dp Re(c_w e_w) = Re(i c_w (d arg_w/dp) e_w) with d arg_w/dp = a_w x + b_w y."""
        nn, mm, q, theta_w, coef = sol["nn"], sol["mm"], sol["q"], sol["theta_w"], sol["coef"]
        w, n_ridges = nn.size, len(p) - 2
        base = 1j * (coef[:w] - 1j * coef[w:2 * w]) * q
        ct, st = np.cos(theta_w), np.sin(theta_w)
        alpha = [base * ct, base * ct * (nn - 1)]          # d arg / dp = alpha x + beta y
        beta = [base * st, base * st * (nn - 1)]
        for m in range(n_ridges):
            alpha.append(np.where(mm == m, -base * st, 0))
            beta.append(np.where(mm == m, base * ct, 0))
        alpha, beta = np.array(alpha)[:, None, :], np.array(beta)[:, None, :]   # J x 1 x W
        grids = []
        for g, (fx, fy) in zip(self.grids, sol["fac"]):
            # D_j = Re(sum_w alpha_jw x e_w + beta_jw y e_w): one (J, N, 2W) @ (2W, N)
            left = np.concatenate([g["x"][:, None] * fx[:, :w] * alpha, fx[:, :w] * beta], axis=2)
            right = np.concatenate([fy[:, :w], g["y"][:, None] * fy[:, :w]], axis=1)
            grids.append(np.where(g["ok"], (left @ right.T).real, 0.0))
        x = sol["lsq"](grids)                                 # J x n_cols
        d = [dk[:, g["ok"]].T - self._evaluate(fx, fy, self._weights(k, x, w))[:, g["ok"]].T
             for k, (g, (fx, fy), dk) in enumerate(zip(self.grids, sol["fac"], grids))]
        return -np.concatenate(d)
