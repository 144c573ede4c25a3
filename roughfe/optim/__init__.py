"""Generic optimisers used by roughfe (no physics here): :mod:`roughfe.optim.gcmma`,
:mod:`roughfe.optim.anderson` (fixed points), :mod:`roughfe.optim.es` (a (1+1) evolution
strategy for staircase objectives)."""
from .anderson import FixedPoint, RejectedIterate, anderson_fixed_point
from .es import EsResult, one_plus_one_es
from .gcmma import GcmmaResult, gcmma, gcmma_maximize, gcmma_minimax

__all__ = ["GcmmaResult", "gcmma", "gcmma_maximize", "gcmma_minimax", "FixedPoint",
           "RejectedIterate", "anderson_fixed_point", "EsResult", "one_plus_one_es"]
