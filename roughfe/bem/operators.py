"""Influence operators u = H p of the BEM (thesis Eq. 2.3-2.4): pressure (Pa) -> normal
surface displacement (m) of an elastic half-space (surfaces) or half-plane in plane
strain (profiles), for pressures that are uniform over each grid cell.

Every operator is a discrete convolution, stored as its real-space kernel ``kernel``
(m/Pa, the displacement of cell ``i`` under a unit pressure on cell ``j`` at offset
``i - j``) on a grid of shape ``fft_shape`` and the kernel's real FFT ``spectrum``:

* periodic kernels (``"spectral"``) live on the grid itself (``fft_shape == shape``);
  ``apply`` is a circular convolution.
* non-periodic kernels (``"strip"``, ``"thesis"``, ``"love"``) live on a zero-padded
  grid (DC-FFT, Liu, Wang & Liu 2000) of m >= 2n - 1 points per axis, the first fast FFT
  length (:func:`padded_length`), not 2n, which keeps n's large prime factors (RMD grids
  2**m + 1: 257 -> 514 = 2 x 257, 4.9x slower transforms than 525 x 540; instrument grids
  such as 563 x 484: 3.4x). Offsets 0..n-1 are stored at 0..n-1 and -(n-1)..-1 at
  m-n+1..m-1, so the linear convolution of the n-point pressure is exact; the unused
  middle holds the kernel at the periodic-image distance (one smooth symmetric kernel:
  the non-periodic adhesion solver works on the padded torus).

Kernels (``kernel=`` in :func:`roughfe.bem.solve_contact`):

``"spectral"`` (periodic profiles and surfaces)
    u(q) = 2 p(q) / (E* |q|) for q != 0 (Johnson 1985; Stanley & Kato 1997), applied to
    the sampled pressure. The q = 0 mode is set to zero: a uniform pressure on a
    periodic half-space has no finite displacement, so the *mean displacement is zero
    by convention* and the mean pressure is an independent unknown, fixed either by
    the imposed mean pressure (load control) or by the approach Delta (displacement
    control; then Delta = max h - mean h - mean gap).
``"strip"`` (non-periodic profiles)
    Uniform pressure on each strip of width dx of an elastic half-plane (plane strain):
    H(r) = (2/(pi E*)) int_{r-dx/2}^{r+dx/2} ln(L/|t|) dt. The 2D displacement is defined
    up to a constant; it is fixed by taking the displacement of a line load as zero at a
    distance L = the profile length (``size[0]``). The same matrix gives loads and
    stiffness, so they are consistent; the load-approach curve shifts with the choice
    of L (a genuine property of 2D elasticity), contact areas and pressures do not
    depend on it for a prescribed load.
``"thesis"`` (non-periodic profiles and surfaces)
    Eq. 2.4 of the thesis, H_ij = 2/(pi E* delta) arcsin(delta / (2 |x_j - x_i|)) per
    unit force (Borri-Brunetto et al. 2001): the displacement at distance r outside a
    rigid circular punch of diameter delta carrying a force F = p * (cell area). It
    is the 3D (Boussinesq) point-load kernel 1/(pi E* r) at r >> delta, i.e. a line of
    patches in 3D, not a plane-strain profile (whose kernel is logarithmic). The
    diagonal is the punch displacement F/(E* delta) (arcsin argument clipped to 1).
    delta = dx for a profile (force p dx^2 per patch: a strip of width dx), and
    sqrt(dx dy) for a surface.
``"love"`` (non-periodic surfaces)
    Love's exact displacement of a uniformly loaded rectangle dx x dy (Love 1929;
    Johnson 1985, Eq. 3.25), see :func:`roughfe.reference.uniform_cell_displacement_grid`.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Optional

import numpy as np
import scipy.fft

from ..errors import InputError, check_real_array
from .fft import (WORKERS, FFTWorkspace, _backward, _convolve, _copy, _forward,  # noqa: F401
                  _irfftn_owned, _multiply, _pocketfft, _spectral_energy, fast_length)
from ..reference import uniform_cell_displacement_grid, uniform_strip_displacement
from ..surfaces.stats import angular_wavevectors, rfft_full_sum

KERNELS = ("spectral", "strip", "thesis", "love")

_KERNEL_REFERENCES = {
    "spectral": ("Stanley H.M., Kato T. (1997) J. Tribol. 119:481-485",),
    "strip": ("Johnson K.L. (1985) Contact Mechanics, Eq. 2.25",),
    "thesis": ("Borri-Brunetto M., Chiaia B., Ciavarella M. (2001) Comput. Methods Appl. "
               "Mech. Eng. 190:6053-6073", "thesis Eq. 2.4"),
    "love": ("Love A.E.H. (1929) Phil. Trans. R. Soc. A 228:377-420",
             "Liu S., Wang Q., Liu G. (2000) Wear 243:101-111 (DC-FFT)"),
}


@dataclass(frozen=True, eq=False)
class InfluenceOperator:
    """The linear map u = H p (m per Pa) on a grid of ``shape`` cells.

    Attributes
    ----------
    name : str
        One of ``KERNELS``.
    shape : tuple
        Grid shape of pressure and displacement.
    spacing : tuple
        Cell size per axis (m).
    periodic : bool
        True for the circulant (spectral) operator; its q = 0 mode is zero.
    e_star : float
        E* (Pa).
    spectrum : ndarray
        ``rfftn(kernel)``: the multiplier of ``rfftn(p)`` (m/Pa).
    padded_kernel : ndarray or None
        The real-space kernel of a non-periodic operator on its zero-padded grid (m/Pa);
        None for the periodic one, whose real-space kernel (:attr:`kernel`) is made from
        the spectrum only when asked for (it would be one more full grid in memory).
    """

    name: str
    shape: tuple
    spacing: tuple
    periodic: bool
    e_star: float
    spectrum: np.ndarray
    padded_kernel: Optional[np.ndarray] = None

    @functools.cached_property
    def kernel(self) -> np.ndarray:
        """Real-space kernel on ``fft_shape`` (m/Pa), read-only."""
        if self.padded_kernel is not None:
            return self.padded_kernel
        kern = scipy.fft.irfftn(self.spectrum, s=self.shape)
        kern.setflags(write=False)
        return kern

    @property
    def fft_shape(self) -> tuple:
        return self.shape if self.padded_kernel is None else self.padded_kernel.shape

    @property
    def diagonal(self) -> float:
        """Self-influence H_ii (m/Pa): the kernel at zero offset, for the periodic
        operator the mean of the full spectrum (from the rfft half: interior columns
        stand for two modes)."""
        if self.padded_kernel is not None:
            return float(self.padded_kernel.flat[0])
        return rfft_full_sum(self.spectrum, self.shape[-1]) / float(np.prod(self.shape))

    @property
    def references(self) -> tuple:
        return _KERNEL_REFERENCES[self.name]

    def apply(self, p, single=False, out=None, work=None, workers=None):
        """Displacement u = H p (m) of the pressure ``p`` (Pa, array_like of ``shape``, or
        a stack ``(..., *shape)`` of them: one product over the trailing axes).

        ``p`` is taken as float64 (a float32 ``p`` too: single precision only with
        ``single``); its trailing axes must be ``shape`` (an InputError otherwise: the
        FFT would zero-pad a smaller grid and crop a larger one without a word), and
        masked or complex arrays are refused. ``single``: in single precision (``p``
        rounded to float32, float32 result, relative error ~1e-7 of max |u|; half the
        FFT work), for iterates far from convergence (:func:`roughfe.bem.pk.polonsky_keer`).
        ``out`` (an array of ``p``'s shape and the result's dtype) receives the result;
        with an :class:`FFTWorkspace` ``work`` a periodic product allocates nothing.
        ``workers``: threads per FFT (default ``WORKERS``; the batched solvers of
        :mod:`roughfe.bem.batch` take 1). The solvers call :meth:`apply_unchecked`.
        """
        if np.ma.isMaskedArray(p) or np.iscomplexobj(p):
            p = check_real_array("pressure p", p, unit="Pa")   # names the mask / complex
        p = np.asarray(p) if single else np.asarray(p, dtype=float)
        if p.shape[max(p.ndim - len(self.shape), 0):] != self.shape:
            raise InputError(f"the pressure's trailing axes must be the operator's grid "
                             f"{self.shape} (a stack (..., {', '.join(map(str, self.shape))}) "
                             f"allowed), got shape {p.shape}")
        return self.apply_unchecked(p, single, out, work, workers)

    def apply_unchecked(self, p, single=False, out=None, work=None, workers=None):
        """:meth:`apply` without its input checks, for the solvers' inner loops: ``p``
        must be an ndarray whose trailing axes are ``shape`` (a smaller one would be
        zero-padded, a larger one cropped) and a float32 ``p`` gives a float32 result."""
        if single and p.dtype != np.float32:
            if out is not None and work is not None and self.periodic:
                _copy(out, p)                     # the float32 input, in out
                p = out
            else:
                p = p.astype(np.float32, copy=False)
        u = _convolve(p, self.spectrum, self.fft_shape, out if self.periodic else None,
                      work, workers)
        if self.periodic:
            return u
        u = u[(Ellipsis,) + self._surface]
        if out is None:         # with a workspace u is its padded output: copied
            return u if work is None else np.array(u)
        out[...] = u
        return out

    def split_product(self, p, single=False, out=None, work=None, workers=None):
        """The product u = H p in its two halves: returns the energy ``p . H p`` (m Pa:
        sum over the grid of p u) read from the forward transform, and ``finish()``,
        which completes the product (the inverse transform) into ``out`` and returns it.

        By Parseval, p . H p = (1/N) sum_q S(q) |p(q)|^2 (S the kernel's multiplier,
        ``spectrum``, N the FFT grid's points; the interior columns of the rfft
        half-spectrum stand for two modes), summed in float64. On the zero-padded grid
        of a non-periodic kernel the same sum is p . H p too: p is zero off the
        surface. A caller that needs the energy only, as the exact line search of the
        Polonsky-Keer CG does (tau = g.t / t.H t) whenever its step is then clipped
        and u recomputed, skips the inverse half of the FFT work. ``finish`` must be
        called before ``work`` is used again. ``single``, ``out`` and ``workers`` as
        in :meth:`apply`; needs a ``work`` (:class:`FFTWorkspace`).
        """
        if work is None or _pocketfft is None:
            raise InputError("split_product needs an FFTWorkspace")
        workers = WORKERS if workers is None else workers
        dtype = np.float32 if single else np.float64
        if out is None:
            out = np.empty(self.shape, dtype)
        if p.dtype != dtype and self.periodic:
            _copy(out, p)
            p = out
        shape = self.fft_shape
        xh = _forward(p, shape, work, workers, dtype)
        energy = _spectral_energy(xh, self.spectrum, shape[-1]) / float(np.prod(shape))

        def finish():
            _multiply(xh, self.spectrum)
            if self.periodic:
                return _backward(xh, shape, work, workers, out)
            out[...] = _backward(xh, shape, work, workers)[self._surface]
            return out

        return energy, finish

    @property
    def _surface(self) -> tuple:
        """The slices of the surface's grid in a padded (or torus) grid: its corner."""
        return tuple(slice(0, n) for n in self.shape)

    def circulant_kernel(self, shape) -> np.ndarray:
        """The real-space kernel (m/Pa) of a non-periodic operator laid out as a circulant
        on a grid of ``shape``: at index k the kernel at the periodic-image offset
        min(k, m - k), clamped to the largest offset of the padded grid (offsets up to
        n - 1 are exact). The preconditioner's Strang circulant (:meth:`inverse_spectrum`)
        and the two-level correction's torus (:mod:`roughfe.bem.padded_deflation`)."""
        index = []
        for m, M in zip(shape, self.fft_shape):
            k = np.arange(m)
            index.append(np.minimum(np.minimum(k, m - k), M // 2))
        return self.kernel[np.ix_(*index)]

    @property
    def precond_shape(self) -> tuple:
        """Grid of the preconditioner's circular convolution (:meth:`precondition`): the
        grid itself when periodic; otherwise the first fast FFT length >= n per axis."""
        if self.periodic:
            return self.shape
        last = len(self.shape) - 1
        return tuple(fast_length(n, real=a == last) for a, n in enumerate(self.shape))

    def inverse_spectrum(self):
        """Spectrum (Pa/m) of an approximate inverse of H on the :attr:`precond_shape` grid.

        Periodic: the exact stiffness E*|q|/2 (zero at q = 0). Non-periodic: the inverse
        of Strang's circulant approximation of the Toeplitz operator on the grid of
        :attr:`precond_shape`, m >= n points per axis (offsets up to m/2 kept, floored at
        1e-12 of its maximum). Used as the CG preconditioner through :meth:`precondition`.
        The circulant was built on the n-point grid itself until round 2 session 15. On
        the fast grid of m >= n points (257^2 -> 264 x 270, 563 x 484 -> 567 x 486) it
        is cheaper where n has a large prime factor, and it needs fewer iterations where
        m > n (the few zero-padded points keep the wrap-around coupling of opposite edges
        out of the preconditioner): 6-step sweeps on RMD 257^2 284 -> 268 iterations, on
        the 563 x 484 Digital Surf file 571 -> 461 (02b, session 15).
        """
        if self.periodic:
            spec = self.spectrum
        else:
            spec = scipy.fft.rfftn(self.circulant_kernel(self.precond_shape)).real
            spec = np.maximum(spec, 1e-12 * spec.max())
        return reciprocal_or_zero(spec)

    def precondition(self, v, spectrum, out=None, work=None, workers=None):
        """M v: the preconditioner of multiplier ``spectrum`` (:meth:`inverse_spectrum`,
        float64 or float32) applied to ``v`` (``shape``, or a stack ``(..., *shape)``).
        Periodic: :meth:`convolve_spectrum`. Non-periodic: ``v`` zero-padded to
        :attr:`precond_shape`, the circular convolution there, cropped back to
        ``shape`` (into ``out`` when given). ``work`` and ``workers`` as in
        :meth:`apply`."""
        pshape = self.precond_shape
        if pshape == self.shape:
            return self.convolve_spectrum(v, spectrum, out, work, workers)
        if spectrum.dtype == np.float32:
            v = v.astype(np.float32, copy=False)
        y = _convolve(v, spectrum, pshape, None, work, workers)
        crop = (Ellipsis,) + self._surface
        if out is None:
            return np.ascontiguousarray(y[crop])
        out[...] = y[crop]
        return out

    def convolve_spectrum(self, v, spectrum, out=None, work=None, workers=None):
        """Circular convolution of ``v`` (``shape``, or a stack ``(..., *shape)``) with a
        multiplier on its rFFT over the ``shape`` grid.

        A ``float32`` multiplier makes it a single-precision product (``v`` is rounded
        to float32, the result is float32): half the FFT work, for preconditioners,
        whose rounding only perturbs the search direction, never the residual.
        ``out``, ``work`` and ``workers`` as in :meth:`apply`.
        """
        if spectrum.dtype == np.float32:
            v = v.astype(np.float32, copy=False)
        return _convolve(v, spectrum, v.shape[v.ndim - len(self.shape):], out, work,
                         workers)

    def dense(self, index=None):
        """The dense matrix H (m/Pa), rows and columns in C order of the grid.

        ``index`` (flat indices) restricts it to those cells. Memory: 8 N^2 bytes.
        """
        idx = np.indices(self.shape).reshape(len(self.shape), -1)
        if index is not None:
            idx = idx[:, np.asarray(index)]
        diff = [(idx[a][:, None] - idx[a][None, :]) % self.fft_shape[a]
                for a in range(len(self.shape))]
        return self.kernel[tuple(diff)]


def check_kernel_name(kernel: str) -> str:
    """Return ``kernel`` or raise :class:`InputError` unless it is ``"auto"`` or one of
    :data:`KERNELS` (the vocabulary only; which kernel fits a surface is decided when the
    surface is known, :func:`roughfe.bem.solve_contact`)."""
    if kernel != "auto" and kernel not in KERNELS:
        raise InputError(f"kernel must be 'auto' or one of {KERNELS}, got {kernel!r}")
    return kernel


def periodic_spectrum(shape, size, e_star, columns=slice(None)) -> np.ndarray:
    """The multiplier 2 / (E* |q|) (m/Pa) of the periodic (``"spectral"``) operator on
    the rfft half-spectrum of a grid ``shape`` of ``size`` (m): q the angular wavevector
    (rad/m, :func:`~roughfe.surfaces.stats.angular_wavevectors`), zero at q = 0 (zero
    mean displacement, module docstring). ``columns`` (a slice of the half-spectrum's
    last axis, whose full length is ``shape[-1] // 2 + 1``): only those columns, for a
    process that holds a slab of the spectrum (:mod:`roughfe.bem.distributed`); each
    entry is the one of the full multiplier, bit for bit."""
    shape, ndim = tuple(shape), len(shape)
    qs = angular_wavevectors(shape, size)
    qs = [q[..., : shape[-1] // 2 + 1][..., columns] if a == ndim - 1 else q
          for a, q in enumerate(qs)]
    qmod = np.sqrt(sum(q ** 2 for q in qs))
    with np.errstate(divide="ignore"):
        return np.where(qmod > 0, 2.0 / (e_star * qmod), 0.0)


def reciprocal_or_zero(spec) -> np.ndarray:
    """1 / S where the multiplier S > 0, else 0: the preconditioner's spectrum of an
    operator's (:meth:`InfluenceOperator.inverse_spectrum`; E* |q| / 2 of the periodic
    one, zero at q = 0)."""
    with np.errstate(divide="ignore"):
        return np.where(spec > 0, 1.0 / np.where(spec > 0, spec, 1.0), 0.0)


def padded_length(n: int, real: bool = True) -> int:
    """Points per axis of the DC-FFT padded grid of an ``n``-point axis: the first fast
    length (:func:`fast_length`) >= 2n - 1, the least grid of an exact linear
    convolution."""
    return fast_length(2 * int(n) - 1, real)


def _offsets(n, d, m):
    """Signed offsets (m) of the ``m``-point padded grid of an ``n``-point axis of spacing
    ``d``: index k holds offset k for k <= m // 2 and k - m above, so that 0..n-1 and
    -(n-1)..-1 are exact (m >= 2n - 1) and the unused middle holds the periodic-image
    distance."""
    k = np.arange(m)
    return np.where(k <= m // 2, k, k - m) * d


#: largest cell aspect ratio max(dx, dy) / min(dx, dy) of the ``"thesis"`` kernel: its
#: patch of diameter sqrt(dx dy) overlaps the nearer neighbours of a long cell, and the
#: zero-padded circulant loses positive definiteness near 3 (measured on 8^2-128^2: its
#: smallest eigenvalue over the largest +1.3e-2..+5.9e-4 at 2.5, -2.8e-3 at 3 on 8^2)
THESIS_MAX_ASPECT = 2.5


def influence_operator(shape, size, e_star, kernel="spectral") -> InfluenceOperator:
    """Build the influence operator of a grid ``shape`` of physical ``size`` (m).

    Parameters
    ----------
    shape : tuple of int
        ``(n,)`` for a profile, ``(nx, ny)`` for a surface.
    size : tuple of float
        Physical size per axis (m), ``n * spacing``.
    e_star : float
        Composite modulus E* (Pa).
    kernel : str
        ``"spectral"`` (periodic), ``"strip"`` (profile), ``"thesis"`` (Eq. 2.4),
        ``"love"`` (surface); see the module docstring.
    """
    shape = tuple(int(n) for n in shape)
    size = tuple(float(s) for s in size)
    ndim = len(shape)
    spacing = tuple(s / n for s, n in zip(size, shape))
    if kernel not in KERNELS:
        raise InputError(f"kernel must be one of {KERNELS} or 'auto', got {kernel!r}")
    if kernel == "spectral":
        return InfluenceOperator(kernel, shape, spacing, True, e_star,
                                 periodic_spectrum(shape, size, e_star))
    padded = [padded_length(n, real=a == ndim - 1) for a, n in enumerate(shape)]
    if kernel == "strip":
        if ndim != 1:
            raise InputError("kernel 'strip' is for profiles (1D); use 'love' or 'spectral' "
                             "for surfaces")
        r = _offsets(shape[0], spacing[0], padded[0])
        kern = uniform_strip_displacement(r, spacing[0] / 2, e_star, 1.0, size[0])
    elif kernel == "thesis":
        aspect = max(spacing) / min(spacing)
        if aspect > THESIS_MAX_ASPECT:
            raise InputError(
                f"kernel 'thesis' (Eq. 2.4: patches of diameter sqrt(dx dy)) is not positive "
                f"definite on cells of aspect ratio {aspect:.3g} (dx = {spacing[0]:.4g} m, "
                f"dy = {spacing[-1]:.4g} m; at most {THESIS_MAX_ASPECT:g}): the contact "
                f"problem would not be convex; use kernel 'love' (exact for rectangles)")
        grids = np.meshgrid(*[_offsets(n, d, m) for n, d, m in zip(shape, spacing, padded)],
                            indexing="ij")
        r = np.sqrt(sum(g ** 2 for g in grids))
        delta = float(np.prod(spacing)) ** (1.0 / ndim)
        arg = np.where(r > 0, np.minimum(1.0, delta / (2 * np.where(r > 0, r, 1.0))), 1.0)
        # force on a patch p * delta^2 -> displacement 2 F / (pi E* delta) arcsin(...)
        kern = 2 * delta / (np.pi * e_star) * np.arcsin(arg)
    else:  # love
        if ndim != 2:
            raise InputError("kernel 'love' is for surfaces (2D); use 'strip' or 'thesis' "
                             "for profiles")
        k0, k1 = (np.abs(np.rint(_offsets(n, 1.0, m)).astype(np.intp))
                  for n, m in zip(shape, padded))
        kern = uniform_cell_displacement_grid(k0.max() + 1, k1.max() + 1, *spacing,
                                              e_star)[np.ix_(k0, k1)]
    # the padded kernel is even in every offset, so its spectrum is real (the imaginary
    # parts are rounding): kept real, as the periodic one (half the memory, and the
    # Parseval energy of split_product needs a real multiplier)
    spec = np.ascontiguousarray(scipy.fft.rfftn(kern).real)
    return InfluenceOperator(kernel, shape, spacing, False, e_star, spec, kern)
