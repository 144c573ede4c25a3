"""One resolution rule for the contact patches of a BEM and a FEM result
(roughfe.bem.patches): the load-weighted patch width in grid points, carried as
``patch_width``, said not resolved below MIN_PATCH_POINTS (measured: docs/theory/02,
"Resolution of the contact patches")."""
import warnings

import numpy as np
import pytest

from roughfe.bem import Material, solve_contact
from roughfe.bem.patches import MIN_PATCH_POINTS, patch_width, resolution_note
from roughfe.errors import ResolutionWarning
from roughfe.reference import hertz_sphere, westergaard
from roughfe.surfaces import Surface

MAT = Material(E=1e9, nu=0.3)
LAM, G = 1e-3, 1e-6


def test_patch_width_counts_runs_weighs_by_load_and_joins_across_edges():
    # two runs, 2 and 1 points, carrying 2 and 5: (2 * 2 + 5 * 1) / 7
    assert patch_width([0, 1, 1, 0, 0, 1], [0, 1, 1, 0, 0, 5]) == pytest.approx(9 / 7)
    # periodic: the runs at the two ends are one patch of 3
    assert patch_width([1, 1, 0, 0, 0, 1], np.ones(6), periodic=True) == 3.0
    assert patch_width([1, 1, 0, 0, 0, 1], np.ones(6)) == pytest.approx(5 / 3)
    # mirrored ends (the FEM's rollers): an end run of k nodes is a patch of 2 k - 1
    assert patch_width([1, 0, 0, 1, 1, 1], [1, 0, 0, 1, 1, 1], mirrored_ends=True) == 4.0
    assert patch_width(np.ones(5, bool), np.ones(5), mirrored_ends=True) == 5.0
    # surfaces: the diameter of the disc of the patch's cells; 4-connected, periodic
    m = np.zeros((8, 8), bool)
    m[0, 3] = m[7, 3] = True
    assert patch_width(m, m * 1.0, periodic=True) == pytest.approx(2 * np.sqrt(2 / np.pi))
    assert patch_width(m, m * 1.0) == pytest.approx(2 * np.sqrt(1 / np.pi))
    assert np.isnan(patch_width(np.zeros(4, bool), np.zeros(4)))
    assert resolution_note(float("nan")) is None and resolution_note(None) is None
    assert resolution_note(MIN_PATCH_POINTS) is None
    assert "not resolved" in resolution_note(1.0)


def _cosine(n):
    x = np.arange(n) * LAM / n
    return Surface(G * np.cos(2 * np.pi * x / LAM), LAM, periodic=True)


@pytest.mark.parametrize("s, resolved", [(1e-3, False), (2e-3, False), (0.2, True)])
def test_bem_westergaard_profile(s, resolved):
    """64 points per wavelength: at s = p/p* = 1e-3 and 2e-3 the contact is 1 and 3
    points wide (the load at the approach off by -2.2 and -3.1 %); at 0.2 it is 19
    points wide (load within 0.08 %), resolved."""
    r = solve_contact(_cosine(64), MAT, delta=G * (s - s * np.log(s)))
    ref = westergaard(G, LAM, MAT.E_star, s * np.pi * MAT.E_star * G / LAM)
    # one patch: its load-weighted width is its point count (to round-off: 3 - 4e-16
    # with OpenBLAS)
    assert r.patch_width == pytest.approx(r.n_contact, rel=1e-12)
    assert (resolution_note(r.patch_width) is None) == resolved
    if resolved:
        assert r.mean_pressure == pytest.approx(ref.mean_pressure, rel=0.005)


@pytest.mark.parametrize("a_cells, resolved", [(0.6, False), (1.5, False), (8.0, True)])
def test_bem_hertz_sphere(a_cells, resolved):
    """Love kernel, 64^2: a contact radius of 0.6 and 1.5 cells is one and five cells
    (width 1.1, 2.5); of 8 cells, width 16, resolved (load within 0.1 %)."""
    n, L, R = 64, 2e-4, 1e-3
    dx = L / n
    xs = (np.arange(n) - n / 2) * dx
    X, Y = np.meshgrid(xs, xs, indexing="ij")
    surf = Surface(-(X ** 2 + Y ** 2) / (2 * R), (L, L))
    a = a_cells * dx
    r = solve_contact(surf, MAT, delta=a * a / R, compute_stiffness=False)
    assert r.patch_width == pytest.approx(2 * np.sqrt(r.n_contact / np.pi))
    assert (resolution_note(r.patch_width) is None) == resolved
    if resolved:
        assert r.load == pytest.approx(hertz_sphere(R, MAT.E_star, approach=a * a / R).load,
                                       rel=0.005)


def test_sweep_carries_the_width_per_step():
    from roughfe.bem import contact_sweep
    sw = contact_sweep(_cosine(64), MAT, deltas=[1e-9, 0.3 * G])
    assert sw.patch_width[0] == 1 and sw.patch_width[1] > MIN_PATCH_POINTS
    assert [r["patch_width"] for r in sw.to_records()] == list(sw.patch_width)


@pytest.mark.fem
def test_fem_warns_on_a_contact_of_one_node_and_not_on_a_resolved_one():
    """33 nodes on a cosine half period (64 per mirrored wavelength): one contact node
    at s = 1e-3 (its load off Westergaard's by ~8 %, mirrored patch width 1), a
    ResolutionWarning from the sweep; 12 nodes at s = 0.3, none."""
    pytest.importorskip("dolfinx")
    from roughfe.fem import fem_contact_sweep, mesh_profile
    n = 33
    dx = (LAM / 2) / (n - 1)
    x = np.arange(n) * dx
    pm = mesh_profile(Surface(G * np.cos(2 * np.pi * x / LAM), n * dx), growth=0.1)
    with pytest.warns(ResolutionWarning, match=r"step 0: contact patches of width 1 grid"):
        sw = fem_contact_sweep(pm, MAT, [G * 1e-3 * (1 - np.log(1e-3))])
    assert sw.results[0].n_contact == 1 and sw.patch_width[0] == 1.0
    with warnings.catch_warnings():
        warnings.simplefilter("error", ResolutionWarning)
        sw = fem_contact_sweep(pm, MAT, [G * 0.3 * (1 - np.log(0.3))])
    r = sw.results[0]
    assert r.patch_width == 2 * r.n_contact - 1 > MIN_PATCH_POINTS
    ref = westergaard(G, LAM, MAT.E_star, 0.3 * np.pi * MAT.E_star * G / LAM)
    assert r.mean_pressure == pytest.approx(ref.mean_pressure, rel=0.02)
