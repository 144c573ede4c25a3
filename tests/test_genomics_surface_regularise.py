"""The 2D sequencer's final fit damped where the data cannot resolve it (round 2, session
35): the rule of the profile fit (roughfe.genomics.sequencing.regularise) on the surface
model's normal equations (GridModel.solve(regularise=True))."""
import math

import numpy as np
import pytest

from roughfe.genomics.sequencing.regularise import damped_system, noise_damping
from roughfe.genomics.sequencing.surface_data import (resolvable_surface_genome,
                                                      surface_acquisitions)
from roughfe.genomics.sequencing.surface_grid import GridModel
from roughfe.genomics.sequencing.surface_result import about_plane

N, L1 = 48, 1e-3


def _fits(noise, sub):
    """A 3-ridge MWM pair (gamma 1.8, N = 48) with ``noise`` (relative white noise),
    fitted on its lattice's sub-lattice gamma^(1/``sub``) (true angles): the model, the
    least-squares and damped solves, and the explicit design and heights."""
    g, acq, _ = resolvable_surface_genome(5, length=L1, n_nodes=N, n_ridges=3, gamma=1.8,
                                          hurst=0.8)
    rng = np.random.default_rng(0)
    acq = [a.with_heights(a.heights + noise * a.heights.std() * rng.standard_normal(a.shape))
           for a in acq]
    model = GridModel(surface_acquisitions(acq), N)
    p = np.r_[math.log(2 * math.pi / g.lambda1), math.log(g.gamma) / sub, g.angles]
    ranges = model.ranges(p[0], p[1])
    ls = model.solve(p, ranges, exact=True)
    damped = model.solve(p, ranges, exact=True, regularise=True)
    cols = []
    for j in range(ls["coef"].size):                 # the design, one column at a time
        e = np.zeros(ls["coef"].size)
        e[j] = 1.0
        cols.append(np.concatenate([h[gr["ok"]] for h, gr in
                                    zip(model.heights(p, ranges, e), model.grids)]))
    return model, ls, damped, np.column_stack(cols), model.z


def _largest_wave(sol, model):
    w = sol["nn"].size
    return float(np.hypot(sol["coef"][:w], sol["coef"][w:2 * w]).max()
                 / np.abs(model.z - model.z.mean()).max())


def test_the_damped_surface_fit_is_tikhonov_at_the_profile_rules_lambda():
    """On the sub-lattice gamma^(1/4) (204 unknowns on 4608 nodes, column-scaled cond
    1.2e10) with 1 % noise, least squares puts waves of 2.5e5 times the largest height
    into the unresolved directions (36 times through the normal equations' small
    diagonal); the damped solve is the stacked least squares of
    ``regularise.damped_system`` on the explicit design at the lambda of
    ``regularise.noise_damping`` (the least-squares misfit over the norm of the heights
    about each acquisition's plane; its heights to 1e-6, coefficients to 1e-2: the normal
    equations' lambda is read from their own least squares), its waves below the
    heights, and its residual within the rule's bound 1 + p / (4 (m - p))."""
    model, ls, damped, mat, z = _fits(0.01, 4)
    x_ls = np.linalg.lstsq(mat, z, rcond=None)[0]
    heights = np.concatenate([about_plane(g["x"], g["y"], g["ok"], z[model.block == k])
                              for k, g in enumerate(model.grids)])
    lam = noise_damping(float(np.sum((mat @ x_ls - z) ** 2)), *mat.shape,
                        float(np.linalg.norm(heights)))
    x = np.linalg.lstsq(*damped_system(mat, z, lam), rcond=None)[0]
    scale = np.linalg.norm(mat, axis=0)
    assert damped["damping"] == pytest.approx(lam, rel=1e-2)
    assert np.linalg.norm(mat @ (damped["coef"] - x)) < 1e-6 * np.linalg.norm(z)
    assert np.linalg.norm(scale * (damped["coef"] - x)) < 1e-2 * np.linalg.norm(scale * x)
    top = np.abs(z - z.mean()).max()
    w = ls["nn"].size
    assert np.hypot(x_ls[:w], x_ls[w:2 * w]).max() > 1e3 * top
    assert np.hypot(ls["coef"][:w], ls["coef"][w:2 * w]).max() > 10 * top
    assert np.hypot(damped["coef"][:w], damped["coef"][w:2 * w]).max() < top
    m, p = mat.shape
    assert damped["resid"] @ damped["resid"] <= (1 + p / (4 * (m - p))) * (ls["resid"] @ ls["resid"])


@pytest.mark.parametrize("noise", [0.0, 0.01])
def test_a_surface_on_its_own_lattice_keeps_its_fit(noise):
    """On the data's own lattice (60 unknowns, cond 284) every direction is resolved:
    exact data keep their least-squares coefficients to round-off (lambda 3e-17); with
    1 % noise (lambda 1.2e-4) the waves move by at most 1.2e-4 of the largest (measured),
    the largest by 3e-7, and the residual sum of squares by less than 1e-6."""
    model, ls, damped, _, _ = _fits(noise, 1)
    w = ls["nn"].size
    amp = np.hypot(ls["coef"][:w], ls["coef"][w:2 * w])
    moved = np.hypot(*(damped["coef"] - ls["coef"])[:2 * w].reshape(2, w))
    if noise == 0:
        assert damped["damping"] < 1e-14
        assert moved.max() < 1e-12 * amp.max()
    else:
        assert 1e-5 < damped["damping"] < 1e-3
        assert moved.max() < 1e-3 * amp.max()
        assert damped["resid"] @ damped["resid"] < (1 + 1e-6) * (ls["resid"] @ ls["resid"])
    assert _largest_wave(damped, model) == pytest.approx(_largest_wave(ls, model), rel=1e-5)
