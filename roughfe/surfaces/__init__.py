"""Rough profiles and surfaces: the data type, generators, readers and statistics.

Generators (each takes ``rng`` = Generator or seed and records the seed):
:func:`rmd_surface`/:func:`rmd_profile` (thesis Sec. 2.1.1), :func:`wm_profile`
(Eq. 2.1), :func:`mwm_surface` (Eq. 2.2/3.17), :func:`spectral_surface`/
:func:`spectral_profile` (Fourier filtering). A smooth reference shape (no seed):
:func:`sphere_cap`, the parabolic sphere of Hertz's and Maugis' solutions
(:mod:`roughfe.reference`). The same surface on a finer grid (band-limited, no new
roughness): ``Surface.refined`` (:mod:`roughfe.surfaces.resample`). I/O:
:func:`load_surface`, :func:`save_surface`. Statistics: :mod:`roughfe.surfaces.stats`;
texture direction (ISO 25178-2 Str): :mod:`roughfe.surfaces.texture`.
"""
from .io import load_surface, save_surface
from .rmd import rmd_profile, rmd_surface
from .shapes import sphere_cap
from .spectral import spectral_profile, spectral_surface
from .stats import fit_hurst, power_spectrum, spectral_moments, surface_statistics
from .surface import Surface
from .wm import mwm_coefficients, mwm_surface, resolve_rng, wm_profile, wm_series

__all__ = [
    "Surface", "load_surface", "save_surface",
    "rmd_surface", "rmd_profile", "wm_profile", "mwm_surface", "mwm_coefficients", "wm_series",
    "spectral_surface", "spectral_profile", "sphere_cap", "resolve_rng",
    "power_spectrum", "spectral_moments", "fit_hurst", "surface_statistics",
]
