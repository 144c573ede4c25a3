"""Elastic material of the contact problem: moved to :mod:`roughfe.model` (re-exported
here so that ``from roughfe.bem import Material, composite`` keeps working)."""
from ..model import Material, composite

__all__ = ["Material", "composite"]
