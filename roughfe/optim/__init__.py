"""Generic optimisers used by roughfe (no physics here): :mod:`roughfe.optim.gcmma`."""
from .gcmma import GcmmaResult, gcmma, gcmma_maximize, gcmma_minimax

__all__ = ["GcmmaResult", "gcmma", "gcmma_maximize", "gcmma_minimax"]
