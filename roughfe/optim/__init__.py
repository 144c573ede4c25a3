"""Generic optimisers used by roughfe (no physics here): :mod:`roughfe.optim.gcmma`,
:mod:`roughfe.optim.anderson` (fixed points)."""
from .anderson import FixedPoint, RejectedIterate, anderson_fixed_point
from .gcmma import GcmmaResult, gcmma, gcmma_maximize, gcmma_minimax

__all__ = ["GcmmaResult", "gcmma", "gcmma_maximize", "gcmma_minimax", "FixedPoint",
           "RejectedIterate", "anderson_fixed_point"]
