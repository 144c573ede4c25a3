"""Periodic 2D realisations of a surface genome (Eq. 3.17 on a torus) for the surface database.

The 2D genome database and surface design (issue 15 Sec. 3) solve contact with the
periodic spectral BEM on an N x N grid of period L (spacing ``delta = L / N``, node
(i, j) at ``(i delta, j delta)``, node (0, 0) at the origin where Z = 0 exactly). A
plane wave is periodic on that torus only when its wavevector lies on the reciprocal
lattice ``(2 pi / L) (k, l)``, with integers k, l. The MWM wavevectors of Eq. (3.17),
``q_n (cos theta_m, sin theta_m)`` with ``q_n = (2 pi / lambda1) gamma^(n-1)``, are not on
it for a non-integer gamma, so the periodic realisation rounds each one to the nearest
lattice vector:

    Z(x) = sum_m sum_n a_{m,n} [cos(phi_{m,n}) - cos(2 pi (k_{m,n} x + l_{m,n} y) / L
                                                    + phi_{m,n})],
    (k, l)_{m,n} = rint(L q_n (cos theta_m, sin theta_m) / (2 pi)),
    a_{m,n} = alpha_m G gamma^((1-n) H)                                   (Eq. 3.1, 3.17).

The rounding moves a wavevector by at most ``(2 pi / L) / sqrt(2)``: relative to q_n that
is at most ``lambda_n / (L sqrt 2)``, i.e. up to 71 % (in angle up to 45 deg) for the
longest wave ``lambda_n = L`` and ``lambda_n / (1.41 L)`` below; the short waves, which
carry the contact, keep their direction and length to a few percent. This is a modelling
choice of the periodic database, not the continuous genome: the database curves, the
designs and the independent re-scoring all use this same realisation, so a score is
reproduced exactly by a BEM run of the saved heights. Waves that round to (0, 0) (only
when lambda_n > L sqrt 2) are constant and dropped.

Chromosome range: ``n`` with ``2 pi / L <= q_n <= pi / delta`` (from the period to the
Nyquist wavenumber), i.e. ``n_s = ceil(log_gamma(lambda1 / L)) + 1`` and
``n_f = floor(log_gamma(lambda1 / (2 delta))) + 1`` (Eq. 3.5 keeps wavelengths down to
delta, beyond Nyquist; on a periodic grid those alias onto other lattice vectors, so they
are left out). Sums are built in Fourier space (one inverse FFT), exact on the nodes.

The Nyquist wavenumber itself is in the range, and kept: a wave whose lattice vector is
(N/2, 0), (0, N/2) or (N/2, N/2) (e.g. the chromosome q_n = pi/delta of a ridge along an
axis) is on the nodes (-1)^i cos(phi) a, its sine part invisible there, so its realised
amplitude is a |cos phi| (gamma = 2, lambda1 = L, theta = 0, N = 32, phi = pi/2: the last
chromosome realises as rms 5e-24 m, not a/sqrt 2; a chromosome alone can then be flat).
That is the exact node sampling of the wave, which is what the BEM solves, and what the
profile realisation does too: Eq. 3.5 (:mod:`roughfe.genomics.genome`) keeps chromosomes
down to wavelength delta and evaluates them exactly at the nodes, aliased, and a profile
wave at q = pi/delta is (-1)^j a cos(phi) on its nodes likewise. Leaving the Nyquist
chromosome out would drop node content of the surface; waves on other Nyquist-row
vectors (N/2, l != 0) keep both parts.
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import InputError, check_finite_positive
from ..surfaces.surface import Surface
from .genome import Genome, chromosome_indices, realize

_TOL = 1e-9


def periodic_chromosome_range(gamma, lambda1, length, n_nodes):
    """(n_s, n_f): chromosomes with 2 pi/L <= q_n <= pi/delta on an N x N torus of period L."""
    length = check_finite_positive("length (period, m)", length)
    lambda1 = check_finite_positive("lambda1 (m)", lambda1)
    if int(n_nodes) != n_nodes or int(n_nodes) < 8:
        raise InputError(f"n_nodes must be an integer >= 8, got {n_nodes!r}")
    lg = math.log(float(gamma))
    n_s = math.ceil(math.log(lambda1 / length) / lg - _TOL) + 1
    n_f = math.floor(math.log(lambda1 * int(n_nodes) / (2 * length)) / lg + _TOL) + 1
    if n_f < n_s:
        raise InputError(f"no chromosome of gamma = {gamma:g}, lambda1 = {lambda1:g} m fits "
                         f"between the period L = {length:g} m and Nyquist at N = {n_nodes}")
    return int(n_s), int(n_f)


def lattice_wavevectors(genome: Genome, n, length):
    """Integer lattice indices ``(k, l)`` of every wave (m, n), each shape (M, len(n))."""
    if genome.angles is None:
        raise InputError("a surface genome needs ridge angles (one per row of phases)")
    n = np.atleast_1d(np.asarray(n, dtype=int))
    qL = genome.wavenumber(n)[None, :] * float(length) / (2 * np.pi)
    return (np.rint(qL * np.cos(genome.angles)[:, None]).astype(int),
            np.rint(qL * np.sin(genome.angles)[:, None]).astype(int))


def _amplitudes(genome: Genome, n):
    amps = np.broadcast_to(genome.wave_amplitude(n), (genome.M, n.size)).copy()
    if genome.anisotropy is not None:
        amps *= genome.anisotropy[:, None]
    return amps


def _held(genome: Genome, length, n_nodes) -> np.ndarray:
    """The chromosomes of the periodic range that the genome holds (band-limited genome)."""
    n_s, n_f = periodic_chromosome_range(genome.gamma, genome.lambda1, length, n_nodes)
    lo, hi = max(n_s, genome.n_first), min(n_f, genome.n_last)
    if lo > hi:
        raise InputError(f"the periodic window shows chromosomes {n_s}..{n_f}, the genome "
                         f"holds {genome.n_first}..{genome.n_last}")
    return np.arange(lo, hi + 1)


def periodic_heights(genome: Genome, length, n_nodes, chromosomes=None, *, rows=None,
                     phase_shift=0.0) -> np.ndarray:
    """Heights (m) of the periodic realisation (module notes), shape (N, N).

    ``chromosomes``: indices n to sum (default the whole periodic range the genome holds);
    ``rows``: ridges m to sum (default all); ``phase_shift`` is added to every phase, so
    ``phase_shift = pi/2`` gives d Z / d phi of the selected waves (a[-sin phi +
    sin(k.x + phi)] is the wave shifted by pi/2).
    """
    n_nodes = int(n_nodes)
    if chromosomes is None:
        chromosomes = _held(genome, length, n_nodes)
    n = np.atleast_1d(np.asarray(chromosomes, dtype=int))
    rows = np.arange(genome.M) if rows is None else np.atleast_1d(np.asarray(rows, dtype=int))
    phi = genome.phase_columns(n)[rows] + float(phase_shift)
    amps = _amplitudes(genome, n)[rows]
    k, l_ = (v[rows] for v in lattice_wavevectors(genome, n, length))
    keep = (k != 0) | (l_ != 0)
    # -a cos(k.x + phi) = -(a/2) (e^{i(k.x+phi)} + e^{-i(k.x+phi)}); ifft2 has 1/N^2
    spec = np.zeros((n_nodes, n_nodes), dtype=complex)
    c = -0.5 * amps[keep] * np.exp(1j * phi[keep]) * n_nodes ** 2
    np.add.at(spec, (k[keep] % n_nodes, l_[keep] % n_nodes), c)
    np.add.at(spec, (-k[keep] % n_nodes, -l_[keep] % n_nodes), np.conj(c))
    z = np.fft.ifft2(spec).real
    return z + float(np.sum(amps[keep] * np.cos(phi[keep])))


def realize_periodic_surface(genome: Genome, length, n_nodes, chromosomes=None) -> Surface:
    """The periodic N x N realisation of a surface genome (module notes) as a periodic
    :class:`Surface` of size L x L; metadata ``n_s``, ``n_f``, ``chromosomes``, ``length``."""
    n_s, n_f = periodic_chromosome_range(genome.gamma, genome.lambda1, length, n_nodes)
    if chromosomes is None:
        chromosomes = _held(genome, length, n_nodes)
    n = chromosome_indices(chromosomes)
    z = periodic_heights(genome, length, n_nodes, n)
    meta = {"generator": "genome (periodic)", "length": float(length), "n_nodes": int(n_nodes),
            "x0": 0.0, "n_s": n_s, "n_f": n_f, "chromosomes": [int(i) for i in n]}
    return Surface(z, float(length), periodic=True, metadata=meta)


#: dimensions of a genome database / design: 1 = profiles (Eq. 3.1, non-periodic, thesis),
#: 2 = periodic surfaces (this module)
DIMS = (1, 2)


def check_dim(dim) -> int:
    if dim not in DIMS:
        raise InputError(f"dim must be 1 (profiles) or 2 (periodic surfaces), got {dim!r}")
    return int(dim)


def realized_chromosomes(genome: Genome, length, n_nodes, dim=1) -> np.ndarray:
    """The chromosome numbers n a :func:`realization` sums by default: the held part of
    Eq. (3.5)'s range (dim 1) or of the periodic range (dim 2)."""
    if dim == 1:
        lo, hi = genome.held_range(length, n_nodes)
        return np.arange(lo, hi + 1)
    return _held(genome, length, n_nodes)


def realization(genome: Genome, length, n_nodes, dim=1, chromosomes=None) -> Surface:
    """The one realisation of databases and designs: a profile (:func:`realize`, dim 1) or
    the periodic surface of this module (dim 2), optionally of some chromosomes only."""
    if check_dim(dim) == 1:
        return realize(genome, length, n_nodes, chromosomes=chromosomes)
    return realize_periodic_surface(genome, length, n_nodes, chromosomes)
