"""The shared pieces of the BEM vs FEM studies (``validation/bem_vs_fem.py`` and
``validation/fem_convergence.py``): the material and mesh grading, the two rough
profiles, the sub-element contact area and the measures of how the two discretisations
differ (SI units: m, Pa). A helper module of the studies, not a study of its own.
"""
from __future__ import annotations

import numpy as np

from roughfe.bem import Material, contact_sweep
from roughfe.fem.contact import contact_length, p_wave_modulus


MATERIAL = Material(E=210e9, nu=0.3)
GROWTH = 0.03                 # element-size growth with depth (<= 0.14 % on Westergaard)
MIN_CONTACT = 5               # compare A and K only where >= 5 nodes touch (issue 4)


def rel_diff(a, b):
    """|a / b - 1| elementwise (arrays of floats)."""
    return np.abs(np.asarray(a, float) / np.asarray(b, float) - 1.0)


def subcell_area(result, n):
    """A* from the contact length with sub-element edges (:func:`contact_length`) of the
    first n samples (the profile; for the mirrored BEM the first half period)."""
    x = np.arange(n) * result.spacing[0]
    return contact_length(x, result.pressure[:n], result.gap[:n], result.contact[:n],
                          MATERIAL.E_star) / x[-1]


def applied_for(surface_m, targets, pmesh):
    """Approaches to impose on the FEM layer so that its half-plane approach is close to
    ``targets``: target + p_BEM(target) H_d / M. One FEM solve per load (instead of a
    Newton loop); the BEM is then solved at the FEM's own half-plane approach, so the two
    are compared at exactly equal Delta."""
    est = contact_sweep(surface_m, MATERIAL, deltas=targets, kernel="spectral",
                        compute_stiffness=False)
    return np.asarray(targets) + est.mean_pressure * pmesh.depth / p_wave_modulus(MATERIAL)


def patch_stats(contact):
    """Number of contact patches (runs of contact vertices) and their mean size (vertices)."""
    step = np.diff(np.concatenate([[0], np.asarray(contact, np.int8), [0]]))
    sizes = np.flatnonzero(step == -1) - np.flatnonzero(step == 1)
    return int(sizes.size), (float(sizes.mean()) if sizes.size else 0.0), int(np.sum(sizes == 1))


def neighbour_gap_difference(rb, rf, n):
    """Median of g_FEM / g_BEM - 1 (signed) at vertices open in both, (a) next to a vertex in contact
    in both, (b) at least 3 vertices from any contact: how differently the two
    discretisations move the neighbours of a loaded vertex."""
    cb, cf = rb.contact[:n], rf.contact
    both = cb & cf
    open_ = ~cb & ~cf & (rb.gap[:n] > 0)
    near = np.zeros(n, bool)
    near[1:] |= both[:-1]
    near[:-1] |= both[1:]
    far = np.ones(n, bool)
    for k in range(-3, 4):
        far &= ~np.roll(cb | cf, k)
    ratio = rf.gap / np.where(open_, rb.gap[:n], 1.0) - 1.0
    a, b = ratio[open_ & near], ratio[open_ & far]
    return (float(np.median(a)) if a.size else float("nan"),
            float(np.median(b)) if b.size else float("nan"))



# -- (ii), (iii) rough profiles -------------------------------------------------------------
def table1_profile():
    from roughfe.genomics.genome import realize, table1_genome
    from roughfe.surfaces.stats import rms_height
    s = realize(table1_genome(rng=0), scale="10x")
    # Eq. 3.1 with A = 1 gives an rms height of 0.7 mm on L = 1 mm (rms slope 27):
    # rescaled to 1 um rms (linear elasticity in formulation (a) is scale-invariant in
    # p / (E* h_rms / L); formulation (b) is reported at the rescaled slope).
    return s.scaled(1e-6 / rms_height(s))


def rmd_profile_case():
    from roughfe.surfaces.rmd import rmd_profile
    return rmd_profile(9, 1.5, 1e-3, rng=1, rms_height=1e-6)
