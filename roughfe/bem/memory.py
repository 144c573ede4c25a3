"""The memory a BEM solve and a load sweep need, checked before the work.

A solve that does not fit ended in a ``MemoryError`` from inside numpy, or in the kernel's
OOM killer ending the process without a word: a non-periodic 16384^2 surface needs its
kernel and FFT fields on the zero-padded 32768^2 grid (40-60 GiB). The checks raise
:class:`~roughfe.errors.MemoryShortage` (an ``InputError``) naming the grid, before
anything is allocated.

Two measurements of a solve's peak (load control, spectral H = 0.8 surfaces of unit rms
slope, tol 1e-10; bytes per point of the FFT grid, the surface's
own when periodic, the zero-padded one otherwise: :func:`fft_points`; round 2, session
38):

* numpy allocations (tracemalloc; the stiffness computed) at 512^2, p/E* = 0.005 /
  0.1 / 0.3: periodic 74 / 80 / 103, non-periodic 63 / 46 / 53; at 1024^2 (p/E* =
  0.05) 81 and 61, at 2048^2 (0.005) 76 and 64;
* resident memory above the generated surface (``ru_maxrss``, 2048^2, p/E* = 0.05):
  periodic 35 (52 with the stiffness), non-periodic 51 (54).

Allocations grow with the contact (the CG vectors live on the free set: ~28 bytes a free
point), and resident memory counts only the pages touched. The checks count the solve
with its operator (kernel spectra, cached between solves: ~16 bytes a padded point) and
take :data:`SOLVE_BYTES_PER_FFT_POINT` = 40 bytes per FFT point, below every figure, so
that a shortage they report is certain (a non-periodic 16384^2 surface: 40 GiB on its
32768^2 grid); a pass is no promise (a periodic one may need 2.5x its 10 GiB at a
large contact area, and figures come on top).
"""
from __future__ import annotations

import numpy as np

from ..errors import check_memory
from .operators import padded_length

__all__ = ["SOLVE_BYTES_PER_FFT_POINT", "STEP_BYTES_PER_POINT", "fft_points",
           "check_solve_memory", "check_sweep_memory"]

#: peak bytes of one solve per point of its FFT grid: a lower bound (module docstring:
#: measured 35-103)
SOLVE_BYTES_PER_FFT_POINT = 40

#: bytes per grid point that one step of a sweep keeps: its pressure, displacement and gap
#: (float64), contact set (bool) and, with a hardness, plastic displacement (float64)
STEP_BYTES_PER_POINT = 4 * 8 + 1


def fft_points(shape, periodic: bool) -> tuple:
    """The FFT grid of a solve on ``shape``: ``shape`` itself with a periodic kernel, the
    zero-padded grid (:func:`~roughfe.bem.operators.padded_length` per axis) otherwise."""
    shape = tuple(int(n) for n in shape)
    return shape if periodic else tuple(padded_length(n) for n in shape)


def _grid(shape) -> str:
    return " x ".join(str(int(n)) for n in shape)


def check_solve_memory(shape, periodic: bool, kept_steps: int = 0) -> None:
    """Raise :class:`~roughfe.errors.MemoryShortage` when a solve on a grid of ``shape``
    (periodic or not: the kernel's) plus the fields of ``kept_steps`` sweep steps need
    more than the available memory: ``SOLVE_BYTES_PER_FFT_POINT`` per FFT point
    (:func:`fft_points`) and ``STEP_BYTES_PER_POINT`` per point and kept step."""
    fft = fft_points(shape, periodic)
    points = float(np.prod(shape, dtype=float))
    need = float(np.prod(fft, dtype=float)) * SOLVE_BYTES_PER_FFT_POINT \
        + float(kept_steps) * points * STEP_BYTES_PER_POINT
    where = "" if periodic else f" (non-periodic: on its zero-padded {_grid(fft)} FFT grid)"
    what = (f"keeping the fields of {kept_steps} load steps of a {_grid(shape)} grid and "
            f"solving them{where}" if kept_steps else
            f"a contact solve on a {_grid(shape)} grid{where}")
    check_memory(what, need)


def check_sweep_memory(shape, n_steps: int, periodic: bool = False) -> None:
    """:func:`check_solve_memory` of a sweep of ``n_steps`` steps on ``shape``, which keeps
    every step's fields (``periodic``: the kernel's; False, the default, counts the padded
    grid: the larger need).

    Checked before the approaches are made: ``roughfe contact --steps 100000000`` on a
    32^2 grid started, to run for about two weeks (2000 steps: 24 s) towards 3.4 TB of
    fields and a MemoryError (round 2, session 37). It takes the shape, not the surface,
    so that a study checks its tasks before any surface is generated
    (:func:`roughfe.study.analyses.check_parameters`).
    """
    check_solve_memory(shape, periodic, kept_steps=int(n_steps))
