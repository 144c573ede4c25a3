"""Full-grid numpy passes of the BEM solvers over the cores (issue 16 §2).

The FFT products of :mod:`roughfe.bem.operators` run on ``THREADS`` threads (pocketfft's
``workers``); the passes between them (the gap ``u - h``, the penetration test, the
gathers and scatters on the free set, axpys, the multiply by the kernel spectrum) are
single numpy calls, i.e. one core. numpy's ufuncs, ``take``, fancy-index assignment,
``flatnonzero`` and the reductions release the GIL for numeric arrays, so the same calls
on contiguous blocks of the arrays, one block per thread, run in parallel. This module
is that one idea: :func:`blocks` splits ``range(n)`` into contiguous blocks and calls a
function on each, in a small persistent thread pool (created on first use, the calling
thread does one block itself); :func:`take`, :func:`put` and :func:`flatnonzero` are
the gather, scatter and index passes built on it. Below ``MIN_BLOCK`` elements per
thread a pass stays serial (the hand-over costs ~10-50 us). A forked child makes its
own pool on first use.

Thread count: ``THREADS`` = the environment variable ``ROUGHFE_THREADS`` (a positive
integer) if set, else the number of CPUs, at most 4. It is read once, at import, and is
also the FFT's ``workers`` (:data:`roughfe.bem.operators.WORKERS`). ``ROUGHFE_THREADS=1``
makes every pass serial.

Results: a block-wise reduction (a sum split into per-block partial sums) rounds
differently from numpy's single pairwise sum, at the 1e-16 relative level; gathers,
scatters and elementwise passes are bit-identical to the serial calls. A function run by
:func:`blocks` must not call :func:`blocks` itself (the pool has ``THREADS - 1``
workers; a nested call could wait for itself).
"""
from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from ..errors import InputError

#: elements per thread below which a pass is not split (a 2^16-element float64 block is
#: 0.5 MB, ~0.05-0.1 ms of a memory-bound ufunc: more than the hand-over to a thread)
MIN_BLOCK = 1 << 16


def _thread_count() -> int:
    env = os.environ.get("ROUGHFE_THREADS")
    if env is None or not env.strip():
        return max(1, min(4, os.cpu_count() or 1))
    try:
        k = int(env)
    except ValueError:
        k = 0
    if k < 1:
        raise InputError(f"environment variable ROUGHFE_THREADS must be a positive integer "
                         f"(threads of the FFTs and full-grid passes), got {env!r}")
    return k


THREADS = _thread_count()

_pool = None
_pool_lock = threading.Lock()


def _forget_pool():
    """In a forked child the pool's threads do not exist: start afresh (a new pool on
    first use), or a split pass would wait for a thread that never runs."""
    global _pool, _pool_lock
    _pool = None
    _pool_lock = threading.Lock()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forget_pool)


def _executor() -> ThreadPoolExecutor:
    global _pool
    with _pool_lock:
        if _pool is None:
            _pool = ThreadPoolExecutor(max(1, THREADS - 1), thread_name_prefix="roughfe-pass")
        return _pool


def edges(n: int, min_block: int = None) -> list:
    """Block boundaries ``[0, ..., n]`` of :func:`blocks`: ``THREADS`` contiguous blocks
    of nearly equal size, fewer when a block would hold less than ``min_block``
    (default ``MIN_BLOCK``)."""
    min_block = MIN_BLOCK if min_block is None else min_block
    k = max(1, min(THREADS, n // max(1, min_block)))
    return [n * i // k for i in range(k + 1)]


def blocks(n: int, fn, min_block: int = None) -> list:
    """Call ``fn(a, b)`` on contiguous blocks ``[a, b)`` covering ``range(n)``, one per
    thread, in parallel; the results in block order.

    ``fn`` works on views ``x[a:b]`` of flat arrays (numpy releases the GIL inside each
    call); blocks are disjoint, so elementwise writes do not race.
    """
    e = edges(n, min_block)
    if len(e) == 2:
        return [fn(0, n)]
    futures = [_executor().submit(fn, e[i], e[i + 1]) for i in range(1, len(e) - 1)]
    first = fn(e[0], e[1])
    return [first] + [f.result() for f in futures]


def take(a, index, out=None):
    """``a[index]`` (flat ``a``, integer ``index`` of valid positions ``0 <= i <
    a.size``: they are not checked) gathered in parallel blocks of ``index``; into
    ``out`` if given (a 1D array of ``index``'s length)."""
    if out is None:
        out = np.empty(index.size, a.dtype)
    # mode="wrap": the same values for valid indices, without the temporary that
    # mode="raise" copies through when ``out`` is given (measured 2.1 vs 3.4-3.8 ms for
    # 15 % of a 2048^2 grid)
    blocks(index.size, lambda i, j: np.take(a, index[i:j], out=out[i:j], mode="wrap"))
    return out


def put(a, index, values):
    """``a[index] = values`` (flat ``a``, integer ``index`` without repeats, ``values``
    a scalar or an array of ``index``'s length, cast to ``a.dtype``) in parallel."""
    if np.ndim(values) == 0:
        def one(i, j):
            a[index[i:j]] = values
    else:
        def one(i, j):
            a[index[i:j]] = values[i:j]
    blocks(index.size, one)


def flatnonzero(mask):
    """``np.flatnonzero(mask)`` of a flat array, per block in parallel (sorted)."""
    def one(i, j):
        idx = np.flatnonzero(mask[i:j])
        idx += i
        return idx

    parts = blocks(mask.size, one)
    return parts[0] if len(parts) == 1 else np.concatenate(parts)
