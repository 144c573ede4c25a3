"""The FFT machinery of the BEM products (:mod:`roughfe.bem.operators`): the workspace
of a solve, the one convolution (periodic, or zero-padded for the DC-FFT grid of a
non-periodic kernel), in place through scipy's pocketfft binding where it can be, and the
spectral energy of a field (Parseval)."""
from __future__ import annotations

import numpy as np
import scipy.fft

from . import _parallel

try:        # scipy's pocketfft binding: its transforms take ``out=`` (scipy.fft's do not)
    from scipy.fft._pocketfft import pypocketfft as _pocketfft
except ImportError:     # pragma: no cover - a scipy without it takes the allocating path
    _pocketfft = None

WORKERS = _parallel.THREADS  # threads per FFT (ROUGHFE_THREADS, see roughfe.bem._parallel)


def _irfftn_owned(vh, shape, workers=None):
    """``irfftn(vh, s=shape)`` over the trailing ``len(shape)`` axes of a half-spectrum
    the caller gives up (it is destroyed; leading axes are a batch): in-place inverse
    c2c transforms over the leading grid axes, then one c2r along the last. pocketfft's
    multi-axis c2r would allocate a full complex temporary (one more grid in memory,
    measured +134 MB at 4096^2) and is slower (0.35 s vs 0.19 s CPU there)."""
    workers = WORKERS if workers is None else workers
    for axis in range(vh.ndim - len(shape), vh.ndim - 1):
        vh = scipy.fft.ifft(vh, axis=axis, overwrite_x=True, workers=workers)
    return scipy.fft.irfft(vh, n=shape[-1], axis=-1, overwrite_x=True, workers=workers)


class FFTWorkspace:
    """The complex buffer of the FFT products of a solve, reused by every product, and
    the real buffers of its zero-padded (non-periodic) products.

    A solve makes two to three full-grid products per iteration; each used to allocate
    its half-spectrum and its result afresh. Arrays of more than 32 MB come from the
    kernel (mmap) and every page of a fresh one costs a page fault on its first touch:
    at 8192^2 that was 216 s of system time in a 716 s solve. With a workspace (and an
    ``out`` array) a product runs scipy's pocketfft transforms in place in this
    buffer and writes its result into the caller's array. Between products the buffer
    is free scratch memory (:meth:`array`). It grows on demand and is never shared
    between threads (one per solve).

    A zero-padded product (the DC-FFT grid of a non-periodic operator, the padded
    preconditioner) keeps one input grid per padded shape and dtype, zero except in the
    corner the field is copied to (:meth:`padded`), and one output grid
    (:meth:`padded_output`): measured at 1025^2 / 2049^2 (Love kernel, FFT grid 2160^2 /
    4320^2), 41 -> 31 ms and 147 -> 117 ms a product, no page faults (9.7k / 36k a
    product before).
    """

    def __init__(self):
        self._raw = np.empty(0, np.uint8)
        self._out = np.empty(0, np.uint8)
        self._zero = {}

    def _grown(self, name, shape, dtype) -> np.ndarray:
        """A C-contiguous view of ``shape`` and ``dtype`` of the raw buffer ``name``,
        grown if needed (the old buffer is released first)."""
        shape = tuple(int(n) for n in shape)
        nbytes = int(np.prod(shape)) * np.dtype(dtype).itemsize
        raw = getattr(self, name)
        if raw.nbytes < nbytes:
            setattr(self, name, None)
            raw = np.empty(nbytes, np.uint8)
            setattr(self, name, raw)
        return raw[:nbytes].view(dtype).reshape(shape)

    def array(self, shape, dtype) -> np.ndarray:
        """A C-contiguous view of the buffer of ``shape`` and ``dtype`` (grown if
        needed): valid until the next product or call."""
        return self._grown("_raw", shape, dtype)

    def padded(self, shape, dtype) -> np.ndarray:
        """The input grid of ``shape`` and ``dtype`` of a zero-padded product: zero
        wherever no caller wrote (callers write one corner, always the same one)."""
        key = (tuple(int(n) for n in shape), np.dtype(dtype))
        if key not in self._zero:
            self._zero[key] = np.zeros(*key)
        return self._zero[key]

    def padded_output(self, shape, dtype) -> np.ndarray:
        """The output grid of a zero-padded product (scratch, valid until the next)."""
        return self._grown("_out", shape, dtype)


def _convolve(x, spectrum, fft_shape, out=None, work=None, workers=None):
    """``irfftn(rfftn(x, s=fft_shape) * spectrum)`` over the trailing ``len(fft_shape)``
    axes of ``x`` (leading axes are a batch of independent fields; ``x`` is zero-padded
    to ``fft_shape`` and the result has the padded shape): the one FFT convolution of
    the BEM, for single fields and stacks. float32 in, float32 out; float64 otherwise.
    With ``work`` in place in its buffer: r2c into it, multiply, inverse c2c over the
    leading grid axes, c2r into ``out`` (allocated if None); a padded single field goes
    through the workspace's padded grids (:meth:`FFTWorkspace.padded`) and the result is
    the workspace's padded output, valid until its next product.
    ``workers``: threads per transform (default ``WORKERS``)."""
    fft_shape = tuple(fft_shape)
    workers = WORKERS if workers is None else workers
    axes = list(range(x.ndim - len(fft_shape), x.ndim))
    full = x.shape[:x.ndim - len(fft_shape)] + fft_shape
    padded = x.shape != full
    if work is None or _pocketfft is None or (padded and x.ndim != len(fft_shape)):
        xh = scipy.fft.rfftn(x, s=fft_shape, axes=axes, workers=workers)
        _multiply(xh, spectrum)
        y = _irfftn_owned(xh, fft_shape, workers)
        if out is None:
            return y
        out[...] = y
        return out
    xh = _forward(x, fft_shape, work, workers)
    _multiply(xh, spectrum)
    if not padded and out is None:
        out = np.empty(full, np.float32 if xh.dtype == np.complex64 else np.float64)
    return _backward(xh, fft_shape, work, workers, None if padded else out)


def _forward(x, fft_shape, work, workers, dtype=None):
    """The half-spectrum of ``x`` (zero-padded to ``fft_shape`` through the workspace's
    padded grid when smaller) in the workspace's complex buffer; ``dtype`` (default:
    float32 for a float32 ``x``, else float64) the precision of the transform."""
    axes = list(range(x.ndim - len(fft_shape), x.ndim))
    if dtype is None:
        dtype = np.float32 if x.dtype == np.float32 else np.float64
    full = x.shape[:x.ndim - len(fft_shape)] + fft_shape
    if x.shape != full:
        grid = work.padded(fft_shape, dtype)
        grid[tuple(slice(0, n) for n in x.shape)] = x
        x = grid
    elif x.dtype != dtype:
        x = x.astype(dtype)
    xh = work.array(full[:-1] + (fft_shape[-1] // 2 + 1,),
                    np.complex64 if dtype == np.float32 else np.complex128)
    _pocketfft.r2c(x, axes, True, 0, xh, workers)
    return xh


def _backward(xh, fft_shape, work, workers, out=None):
    """The real field of the half-spectrum ``xh`` (destroyed), into ``out`` or, when
    None, the workspace's padded output grid."""
    axes = list(range(xh.ndim - len(fft_shape), xh.ndim))
    for axis in axes[:-1]:          # normalised by 1/n per axis, as irfftn
        _pocketfft.c2c(xh, [axis], False, 2, xh, workers)
    dtype = np.float32 if xh.dtype == np.complex64 else np.float64
    if out is None:
        out = work.padded_output(xh.shape[:-1] + fft_shape[-1:], dtype)
    _pocketfft.c2r(xh, [axes[-1]], fft_shape[-1], False, 2, out, workers)
    return out


#: rows of the half-spectrum per chunk of :func:`_spectral_energy` (its squares' buffer)
_ENERGY_ROWS = 32


def _spectral_energy(xh, spectrum, n_last):
    """sum over all modes of S |x|^2 from the half-spectrum ``xh`` (complex, the rfft
    over the last axis of a real grid with ``n_last`` points there) and the real
    multiplier ``spectrum`` (S) of its shape: |x|^2 in the precision of ``xh``, summed
    in float64 over cache-sized row chunks, over the threads."""
    x2 = xh.reshape(-1, xh.shape[-1])
    s2 = spectrum.reshape(-1, spectrum.shape[-1])
    even = n_last % 2 == 0

    def one(i, j):
        total = 0.0
        buf = np.empty((min(_ENERGY_ROWS, j - i), 2 * x2.shape[1]), x2.real.dtype)
        for k in range(i, j, _ENERGY_ROWS):
            e = min(j, k + _ENERGY_ROWS)
            c = np.multiply(x2[k:e].view(buf.dtype), x2[k:e].view(buf.dtype),
                            out=buf[:e - k])
            a = c[:, 0::2] + c[:, 1::2]       # |x|^2 (rounded as x: float32 or 64)
            s = s2[k:e]
            part = 2.0 * float(np.vdot(s, a)) - float(np.dot(s[:, 0], a[:, 0]))
            if even:
                part -= float(np.dot(s[:, -1], a[:, -1]))
            total += part
        return total

    return float(sum(_parallel.blocks(x2.shape[0], one, min_block=_ENERGY_ROWS)))


def _flat(a):
    """The flat view of a C-contiguous array, or None."""
    return a.reshape(-1) if a.flags.c_contiguous else None


def _copy(out, x):
    """``out[...] = x`` (cast to ``out``'s dtype) over the threads when both are
    contiguous."""
    fo, fx = _flat(out), _flat(x)
    if fo is None or fx is None or fo.size != fx.size:
        np.copyto(out, x, casting="same_kind")
        return
    _parallel.blocks(fo.size, lambda a, b: np.copyto(fo[a:b], fx[a:b],
                                                     casting="same_kind"))


def _multiply(xh, spectrum):
    """``xh *= spectrum`` (half-spectrum by the kernel's multiplier) over the threads."""
    fx, fs = _flat(xh), _flat(spectrum)
    if fx is None or fs is None or fx.size != fs.size:
        np.multiply(xh, spectrum, out=xh)
        return
    _parallel.blocks(fx.size, lambda a, b: np.multiply(fx[a:b], fs[a:b], out=fx[a:b]))



def fast_length(target: int, real: bool = True) -> int:
    """The first length >= ``target`` whose FFT is fast (``scipy.fft.next_fast_len``:
    factors 2, 3, 5 for the real transform's axis, ``real``, the last one; 7 and 11 too
    for the complex axes)."""
    return int(scipy.fft.next_fast_len(int(target), real=real))
