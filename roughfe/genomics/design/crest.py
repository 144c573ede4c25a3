"""The highest peak of a surface design (issue 15, beyond the thesis): its crest factor
lowered by the phases alone, every wave's amplitude kept.

A periodic surface design is a sum of lattice plane waves (:mod:`..periodic`),

    Z(x) = sum_w a_w [cos(phi_w) - cos(2 pi (k_w x + l_w y) / L + phi_w)],

and the height of its highest node over the mean, in rms units, ``z_max = (max Z - mean
Z) / rms Z``, is set by the phases phi_w (the rms by the amplitudes a_w alone, Parseval).
A design is loaded to ``top_fraction x (max Z - mean Z)`` and scored at pressures scaled
by its own p_max (Eq. 4.2), so session 7 read z_max as what sets the level of A(p) at
every target pressure. Measured in session 8 (``docs/theory/surface-design.md``): lowering
z_max of the x3p-2 M-CCO designs this way (or by a penalty in the global stage) did not
raise A(p_max) and cost K, so the validation study does not use it; it stays a tool for
the crest factor of a design. :func:`crest_phases` lowers z_max with
the multisine crest-factor reduction by clipping and projection (Van der Ouderaa, Schoukens
and Renneboog 1988, IEEE Trans. Instrum. Meas. 37(2) 207; the Gerchberg-Saxton step):
clip the heights at a level, take the FFT, keep every lattice mode's modulus and the
clipped surface's phase, repeat.
"""
from __future__ import annotations

import numpy as np

from ...errors import InputError, check_real_array
from ..periodic import lattice_wavevectors
from .model import Design


def peak_height(heights) -> float:
    """z_max = (max Z - mean Z) / rms Z (-): the highest node over the mean in rms heights."""
    h = check_real_array("heights", heights)
    return float((h.max() - h.mean()) / h.std())


def wave_modes(design: Design):
    """The lattice mode of every wave whose phase moves its realised mode: keys ``(part,
    ridge m, chromosome n)`` (:meth:`Design.keys`), the FFT index ``(i, j)`` of the mode of
    the half lattice that carries it (of ``(k, l)`` and ``(-k, -l)`` mod N, the smaller
    tuple) and ``sign`` +1 when the wave sits on that index, -1 when on its conjugate
    (a phase rotation delta of the mode is then -delta of the wave). Left out: waves on
    (0, 0) (constant, dropped by the realisation) and on the self-conjugate Nyquist
    modes, whose phase sets the realised amplitude a |cos phi|."""
    if design.dim != 2:
        raise InputError("wave modes need a surface design (dim 2)")
    n_nodes = design.n_nodes
    keys, index, sign = [], [], []
    for p, part in enumerate(design.parts):
        kk, ll = lattice_wavevectors(part.genome, part.chromosomes, design.length)
        for m in range(part.genome.M):
            for j, n in enumerate(part.chromosomes):
                own = (int(kk[m, j]) % n_nodes, int(ll[m, j]) % n_nodes)
                conj = (-int(kk[m, j]) % n_nodes, -int(ll[m, j]) % n_nodes)
                if own == conj:
                    continue
                keys.append((p, m, int(n)))
                index.append(min(own, conj))
                sign.append(1.0 if own <= conj else -1.0)
    return keys, np.array(index, dtype=int).reshape(-1, 2), np.array(sign)


def clipped_phases(heights, modes, level, n_iter):
    """``n_iter`` clipping-and-projection steps on a periodic field (m): each clips the
    heights above ``level`` (m, over the mean), takes the FFT and sets every mode of
    ``modes`` (FFT indices of the half lattice, shape (K, 2)) to its *original* modulus
    with the phase of the clipped field (the conjugate mode to match); the other modes
    keep their values. Returns the heights after every step (list, mean removed) and the
    phase rotation (rad) of every mode after every step (list of shape (K,) arrays)."""
    z = check_real_array("heights", heights, 2)
    z = z - z.mean()
    spec = np.fft.fft2(z)
    i, j = modes[:, 0], modes[:, 1]
    ci, cj = -i % z.shape[0], -j % z.shape[1]
    modulus, start = np.abs(spec[i, j]), np.angle(spec[i, j])
    fields, rotations = [], []
    for _ in range(int(n_iter)):
        clipped = np.fft.fft2(np.minimum(z, level))
        new = modulus * np.exp(1j * np.angle(clipped[i, j]))
        spec[i, j], spec[ci, cj] = new, np.conj(new)
        z = np.fft.ifft2(spec).real
        fields.append(z)
        rotations.append(np.angle(new) - start)
    return fields, rotations


def crest_phases(design: Design, z_max: float, clip: float = 1.0, n_iter: int = 100
                 ) -> Design:
    """``design`` with phases that lower its highest peak to ``z_max`` rms heights above
    the mean (or as near as ``n_iter`` steps come), every wave's amplitude, wavevector and
    so the power spectrum unchanged (a stage beyond the thesis, surfaces).

    :func:`clipped_phases` with the level ``clip * z_max * rms``; the result is the first
    step whose ``(max Z - mean Z) / rms Z <= z_max``, else the step of the lowest. Waves
    that share a lattice mode (two parts, or a wave and its conjugate) are rotated
    together (their relative phases, hence the mode's modulus, kept). Built to test
    session 7's reading that a design's A(p) level hinges on z_max (Eq. 4.2 normalises p
    by the design's own p_max, reached at ``top_fraction x (max Z - mean Z)``); measured
    in session 8 on x3p-2 M-CCO: it lowers z_max but not the level of A(p), and costs K
    (``docs/theory/surface-design.md``).
    """
    if not (np.isfinite(z_max) and z_max > 0 and clip > 0 and int(n_iter) >= 1):
        raise InputError(f"crest_phases: z_max > 0, clip > 0 and n_iter >= 1 needed, got "
                         f"{z_max!r}, {clip!r}, {n_iter!r}")
    keys, modes, sign = wave_modes(design)
    z = design.surface().heights
    rms = float(np.std(z))
    if not keys or rms == 0 or peak_height(z) <= z_max:
        return design
    fields, rotations = clipped_phases(z, modes, clip * z_max * rms, n_iter)
    peaks = np.array([peak_height(f) for f in fields])
    below = np.flatnonzero(peaks <= z_max)
    step = int(below[0]) if below.size else int(np.argmin(peaks))
    phases = design.phase_values(keys) + sign * rotations[step]
    return design.with_phases(keys, phases)

