"""roughfe: contact mechanics of rough surfaces.

Surfaces (generation, measured files, statistics) -> BEM contact (production solver)
-> FEM cross-validation (dolfinx) -> leakage (networks, Reynolds flow) -> surface
roughness genomics (sequencing, design) -> parameter studies -> figures and reports.

Data flows one way; see ``tests/test_architecture.py`` for the enforced import order.
All quantities are SI (metres, pascals, newtons) unless a name says otherwise.
"""
__version__ = "0.1.0"
