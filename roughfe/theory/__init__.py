"""Analytic theories of rough contact evaluated from the PSD of a surface.

* :func:`persson` -> :class:`PerssonResult`: Persson's A*(p) and mean separation u(p).
* :func:`critical_junction` -> :class:`CriticalJunction`: Lorenz & Persson's leak rate.
* :func:`elastoplastic_area` -> :class:`ElastoplasticArea`: Persson's elastic and plastic
  area of a perfectly plastic interface of hardness H (:mod:`roughfe.theory.plastic`).
* :func:`pastewka_robbins` -> :class:`Stickiness`: the stickiness criterion of a rough
  adhesive contact (Pastewka & Robbins 2014); :func:`load_balance` -> :class:`LoadBalance`:
  its load balance with the attractive area measured on a solved non-adhesive contact.
* :func:`capped_hertz` -> :class:`CappedHertz`: Hertz's sphere on a perfectly plastic
  interface (pressure capped at H_p), solved on rings (:mod:`roughfe.theory.capped_hertz`).
* :func:`beside`: the theory added to the step records of a simulation (results.json).

Layer: after :mod:`roughfe.surfaces` (it needs only the PSD), before the solvers and
their consumers, which draw the theory beside their results.
"""
from .beside import beside, theory_area_fraction
from .capped_hertz import CappedHertz, capped_hertz
from .junction import CriticalJunction, critical_junction
from .plastic import ElastoplasticArea, elastoplastic_area
from .persson import (GAMMA_DEFAULT, KAPPA_PERSSON, PERCOLATION_THRESHOLD, PerssonResult,
                      area_fraction, mean_separation, persson)
from .stickiness import LoadBalance, Stickiness, load_balance, pastewka_robbins

__all__ = ["persson", "beside", "PerssonResult", "critical_junction", "CriticalJunction",
           "area_fraction", "mean_separation", "KAPPA_PERSSON", "GAMMA_DEFAULT",
           "PERCOLATION_THRESHOLD", "pastewka_robbins", "Stickiness", "load_balance",
           "LoadBalance", "elastoplastic_area", "ElastoplasticArea", "capped_hertz",
           "CappedHertz", "theory_area_fraction"]
