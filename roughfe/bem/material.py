"""Elastic material of the contact problem (Sec. 2.2 of the thesis)."""
from __future__ import annotations

from dataclasses import dataclass

from ..errors import InputError, check_finite_positive


def _check_nu(name, nu):
    try:
        v = float(nu)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number in (-1, 0.5], got {nu!r}") from None
    if not (-1.0 < v <= 0.5):
        raise InputError(f"{name} (Poisson's ratio) must lie in (-1, 0.5], got {nu!r}")
    return v


@dataclass(frozen=True)
class Material:
    """An isotropic linear elastic solid.

    Parameters
    ----------
    E : float
        Young's modulus (Pa), finite and > 0.
    nu : float
        Poisson's ratio, in (-1, 0.5] (0.5 is incompressible).

    ``E_star = E / (1 - nu^2)`` is the plane-strain modulus of this solid against a
    rigid counter-surface; use :func:`composite` for two elastic solids.
    """

    E: float
    nu: float

    def __post_init__(self):
        object.__setattr__(self, "E", check_finite_positive("E (Young's modulus, Pa)", self.E))
        object.__setattr__(self, "nu", _check_nu("nu", self.nu))

    @property
    def E_star(self) -> float:
        """Composite (plane-strain) modulus E* = E / (1 - nu^2) in Pa."""
        return self.E / (1.0 - self.nu ** 2)


def composite(E1, nu1, E2, nu2) -> Material:
    """Equivalent material of two elastic solids in contact (Johnson 1985, Eq. 4.22).

    E* = [(1 - nu1^2)/E1 + (1 - nu2^2)/E2]^-1. The thesis (Sec. 2.2) writes
    (1 - nu)/E without the squares: that is a typo, the squares are right.
    Returns ``Material(E*, 0)``, whose ``E_star`` is E*. Pass ``E2=float('inf')`` for a
    rigid second body.
    """
    m1 = Material(E1, nu1)
    nu2 = _check_nu("nu2", nu2)
    E2 = float(E2)
    if E2 == float("inf"):
        return Material(m1.E_star, 0.0)
    E2 = check_finite_positive("E2 (Young's modulus, Pa)", E2)
    return Material(1.0 / (1.0 / m1.E_star + (1.0 - nu2 ** 2) / E2), 0.0)
