"""The adhesive CG (roughfe.bem.adhesive_cg) in mixed precision: its products are float32
transforms of increments, and a state is reported converged only on a double-precision
Ku, so the residual it reports is that of the state it returns, down to tight
tolerances, on the periodic grid and on the padded torus of a non-periodic kernel."""
import warnings

import numpy as np
import pytest

from roughfe.bem import adhesive_minimise
from roughfe.bem.adhesion import AdhesionLaw, solve_adhesive
from roughfe.model import Material
from roughfe.surfaces.shapes import sphere_cap
from roughfe.surfaces.spectral import spectral_surface


def _cases(kind):
    """A periodic rough cell (spectral kernel, mean-gap spring) and a sphere on the padded
    Love grid, each with ``kind``'s law, at an approach with adhesive contact."""
    s = spectral_surface(64, 1e-4, 0.8, rms_height=1e-6, rng=1)
    yield s, Material(1e9, 0.3), AdhesionLaw(kind, 0.01, 20e-9), float(
        s.heights.max() - s.heights.mean() - 0.5e-6)
    # Maugis' sphere of tests/test_bem_adhesion.py (R = 1 m, E* = 1 Pa), lambda = 1
    w, sigma0 = 2.83e-4, 1.0 / (2 * (1.0 / (np.pi * 2.83e-4 * (4 / 3) ** 2)) ** (1 / 3))
    d_scale = (np.pi ** 2 * w ** 2 / (4 / 3) ** 2) ** (1 / 3)
    yield (sphere_cap(32, 0.21, 1.0), Material(0.91, 0.3), AdhesionLaw(kind, w, w / sigma0),
           0.1 * d_scale)


@pytest.mark.parametrize("tol", [1e-5, 1e-8])
@pytest.mark.parametrize("kind", ["exp", "md"])
def test_the_cg_reports_the_residual_of_the_state_it_returns(kind, tol, monkeypatch):
    # float32 increments of Ku (rounding ~1e-7 of each increment) could leave the CG's
    # running Ku off the state's: it must neither stop on such a residual nor stall
    # above a tight tolerance and hand over to L-BFGS-B
    calls = []
    pcg = adhesive_minimise.adhesive_pcg

    def watched(energy, x, tol_, max_iter):
        out = pcg(energy, x, tol_, max_iter)
        calls.append((out[2], energy.residual(out[0]), out[3]))
        return out

    monkeypatch.setattr(adhesive_minimise, "adhesive_pcg", watched)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")          # the coarse sphere's ResolutionWarning
        for surface, mat, law, delta in _cases(kind):
            calls.clear()
            r = solve_adhesive(surface, mat, law, delta=delta, tol=tol)
            assert r.residual <= tol and calls
            for reported, exact, message in calls:
                assert message == "converged"
                # the same up to float64 rounding (2e-14 of S seen at tol 1e-8)
                assert reported == pytest.approx(exact, rel=1e-6, abs=1e-3 * tol)
