"""The conjugation chain of the Polonsky-Keer CG (round 2, session 43): a direction whose
Polak-Ribiere coefficients multiply up far beyond the decrease of g . z they imply (linear
CG: beta_1 ... beta_k = (g.z)_k / (g.z)_0) is restarted. Without it a warm-started load
step of a 1D sweep alternated between two contact sets, the direction grew geometrically
and its float32 FFT product overflowed (247 iterations and numpy's "invalid value"
warning where a cold solve takes 50)."""
import sys
import warnings
from pathlib import Path

import numpy as np

from roughfe.bem import contact_sweep, solve_contact
from roughfe.bem.directions import CONJUGATION_LIMIT, _ConjugationChain
from roughfe.fem import mirrored_profile
from roughfe.surfaces.rmd import rmd_profile

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "validation"))


def test_a_telescoping_chain_is_never_restarted():
    """Linear CG's coefficients: beta_k = (g.z)_k / (g.z)_(k-1), any decrease."""
    chain = _ConjugationChain()
    gz = np.geomspace(1.0, 1e-12, 60) * (1 + 0.3 * np.sin(np.arange(60)))
    assert chain.beta(0.0, gz[0]) == 0.0                 # the first iteration: no beta
    for prev, new in zip(gz, gz[1:]):
        assert chain.beta(new / prev, new) == new / prev
    assert chain.restarts == 0


def test_a_cycling_chain_is_restarted_once_it_exceeds_the_limit():
    """g.z alternating between two values while beta alternates 0.2153 / 6.858 (the
    measured cycle): the product grows 1.48x per two iterations while g.z does not
    fall; a restart comes exactly when the product passes CONJUGATION_LIMIT times
    (g.z)_k / (g.z)_start, and the count then starts again from that iteration."""
    chain = _ConjugationChain()
    values = (91878.0, 14834.0)
    chain.beta(0.0, values[0])
    product, start, restarts = 1.0, values[0], 0
    for k in range(1, 400):
        beta, gz = (0.2153, values[1]) if k % 2 else (6.858, values[0])
        got = chain.beta(beta, gz)
        product *= beta
        if product * start > CONJUGATION_LIMIT * gz:
            assert got == 0.0
            product, start, restarts = 1.0, gz, restarts + 1
        else:
            assert got == beta
    assert restarts >= 5 and chain.restarts == restarts


def test_a_warm_started_1d_sweep_step_does_not_cycle():
    """The step that cycled: mirrored RMD profile (D = 1.3, seed 3, 1024 points), the
    load 2.411e8 Pa warm-started from the solution at 2.290e8 Pa. Now within 1.5x the
    cold solve's iterations, no floating-point warning, and the same solution."""
    from _fem_cases import MATERIAL
    profile = mirrored_profile(rmd_profile(9, 1.3, 1e-3, rng=3, rms_height=1e-6))
    loads = (229045054.94696555, 241100057.83891112)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        sweep = contact_sweep(profile, MATERIAL, pressures=loads, kernel="spectral",
                              compute_stiffness=False)
        cold = solve_contact(profile, MATERIAL, mean_pressure=loads[1], kernel="spectral",
                             compute_stiffness=False)
    warm = sweep.results[1]
    assert warm.nit <= 1.5 * cold.nit, (warm.nit, cold.nit)        # old code: 247 vs 50
    assert np.array_equal(warm.contact, cold.contact)
    assert np.max(np.abs(warm.pressure - cold.pressure)) <= 1e-6 * cold.pressure.max()


def test_the_batched_solver_restarts_each_row_on_its_own():
    """The batched CG (bem/batch.py, design searches and databases) carries one chain per
    row: the 9 load steps of the same profile (seed 3) took 1924 iterations in all and
    overflowed ("overflow encountered in reduce") without it, beside a row (seed 2) the
    restart never touches (494); now 264, and the same contact states as the exact
    pivoting solver."""
    from _fem_cases import MATERIAL
    from _refinement import load_window, study_pressures
    from roughfe.bem.batch_exact import batch_sweep
    from roughfe.bem.operators import influence_operator
    rows = [rmd_profile(9, 1.3, 1e-3, rng=seed, rms_height=1e-6) for seed in (2, 3)]
    mirrored = [mirrored_profile(s) for s in rows]
    heights = np.array([m.heights for m in mirrored])
    pressures = np.array([load_window(study_pressures(s)) for s in rows])
    op = influence_operator(mirrored[0].shape, mirrored[0].size, MATERIAL.E_star, "spectral")
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        cg = batch_sweep(op, heights, pressures, method="pk")
    assert cg.nit[1] <= 3 * cg.nit[0], cg.nit.tolist()            # old code: 1924 vs 494
    for b, profile in enumerate(mirrored):                          # the exact solutions
        for k, p in enumerate(pressures[b]):
            exact = solve_contact(profile, MATERIAL, mean_pressure=p, kernel="spectral",
                                  solver="dense", compute_stiffness=False)
            assert cg.area_fraction[b, k] == exact.area_fraction
            assert abs(cg.delta[b, k] - exact.delta) <= 1e-8 * abs(exact.delta)
