"""Boundary-element contact solver (thesis Sec. 2.2, Eq. 2.3-2.8).

Public API (stable):

* :class:`Material` and :func:`composite` -- elastic constants, E* (Pa); defined in
  :mod:`roughfe.model` with :class:`ContactResult` and :class:`SweepResult`, the result
  types shared with the FEM (re-exported here).
* :func:`solve_contact` -> :class:`ContactResult` -- one contact problem under an
  imposed approach ``delta`` (m) or ``mean_pressure`` (Pa).
* :func:`contact_sweep` -> :class:`SweepResult` -- warm-started loading sweeps
  (A(p), K(p), V*(d/sigma)); ``SweepResult.to_records()`` for results.json.
* :func:`contact_set_pressure_rate` -- dp/dDelta per point on a fixed contact set
  (H_cc x = 1; its mean is the exact stiffness K).
* :func:`influence_operator` -- the operators u = H p (``"spectral"``, ``"strip"``,
  ``"thesis"``, ``"love"``).

Result files: :mod:`roughfe.bem.output` (results.json, fields.h5). Analytic references
(Westergaard, Hertz, Love, strip) live in :mod:`roughfe.reference`.
"""
from .contact import ContactResult, solve_contact  # noqa: F401 (re-export)
from ..model import Material, composite  # noqa: F401 (re-export)
from .operators import KERNELS, InfluenceOperator, influence_operator
from .stiffness import contact_set_pressure_rate
from .sweep import RECORD_KEYS, SweepResult, contact_sweep  # noqa: F401 (re-export)

# Material, composite, ContactResult, SweepResult and RECORD_KEYS are roughfe.model's,
# re-exported for round-1 code; __all__ lists what this package defines.
__all__ = ["solve_contact", "contact_sweep", "contact_set_pressure_rate", "influence_operator",
           "InfluenceOperator", "KERNELS"]
