"""Leakage through a rough contact (thesis Sec. 2.3-2.4).

* :func:`free_volume_network` -> :class:`NetworkResult`: free volume, percolating and
  trapped domains by Algorithm 1 with the saddle-point rule (Eq. 2.8, 2.15-2.16).
* :func:`reynolds_flow` -> :class:`ReynoldsResult`: leak rate from the Reynolds equation
  (Eq. 2.10-2.12), cell-centred finite volumes by default, dolfinx Q1 as cross-check.
* :func:`analyse_leakage` / :func:`leakage_of_contact` -> :class:`LeakageResult`: both on
  one gap field (for example a BEM ``ContactResult``).
* :func:`finite_volume_leak_rate`: an independent two-point-flux finite-volume leak rate
  (scipy only) to cross-check the finite elements.
* :func:`critical_constriction` -> :class:`CriticalConstriction`: the critical gap
  (widest-path bottleneck), its junction, width and parent channel (thesis Ch. 5).
* :func:`coupled_leakage` / :func:`coupled_leakage_sweep` -> :class:`CoupledResult`: two-way
  fluid-structure coupling (the Reynolds pressure loads the elastic body; trapped fluid).
* :func:`channel_flow` -> :class:`ChannelFlow`: exact 1D Reynolds flow along a profile's gap;
  :func:`coupled_channel` -> :class:`ChannelCoupledResult`: its two-way coupling with a BEM
  or dolfinx FEM body (the FEM cross-validation of the coupling, issue 12 Sec. 5).
* :mod:`roughfe.leakage.study`: the percolation study of Sec. 2.4.2-2.4.5.
"""
from .analysis import (LeakageResult, LeakageSweep, analyse_leakage, leakage_of_contact,
                       leakage_sweep)
from .network import DirectionalNetwork, NetworkResult, directional_network, free_volume_network
from .finite_volume import finite_volume_leak_rate
from .fsi import CoupledResult, coupled_leakage
from .fsi_sweep import coupled_leakage_sweep
from .junction import CriticalConstriction, critical_constriction
from .channel import ChannelFlow, channel_flow
from .profile_fsi import ChannelCoupledResult, coupled_channel
from .reynolds import ReynoldsResult, hydraulic_aperture, reynolds_flow

__all__ = ["free_volume_network", "directional_network", "NetworkResult", "DirectionalNetwork",
           "reynolds_flow", "ReynoldsResult", "hydraulic_aperture", "analyse_leakage",
           "leakage_of_contact", "LeakageResult", "leakage_sweep", "LeakageSweep",
           "finite_volume_leak_rate", "critical_constriction", "CriticalConstriction",
           "coupled_leakage", "coupled_leakage_sweep", "CoupledResult", "channel_flow",
           "ChannelFlow", "coupled_channel", "ChannelCoupledResult"]
