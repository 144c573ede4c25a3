"""The surface roughness genome and its realisations (thesis Chapter 3, Eq. 3.1-3.5).

A *genome* is the set of genes of the truncated multivariate Weierstrass-Mandelbrot
(MWM) function, Eq. (3.1):

    Z(x) = G * sum_{m=1}^{M} sum_{n=n_s}^{n_f} gamma^{(1-n) H}
                 [cos(phi_{m,n}) - cos(q_n x + phi_{m,n})],
    G    = A sqrt(ln(gamma) / M) (2 pi / lambda1)^(-H),
    q_n  = (2 pi / lambda1) gamma^(n-1)                    (rad/m).

Genes: the amplitude ``A`` (units m^(1-H), so that Z is in metres), the scaling exponent
``H``, the frequency density ``gamma > 1`` (Eq. 3.6), the reference wavelength
``lambda1`` (m, the wavelength of chromosome n = 1), the number of ridges ``M`` and the
phase matrix ``Phi`` (M rows; column j belongs to chromosome ``n = n_first + j``).
``ln`` is the natural logarithm (the thesis writes "log").

Observation window and nodes (Eq. 3.5)
--------------------------------------
A realisation at observation length ``L`` has ``N`` nodes (default 512) with the thesis
spacing ``delta = L / (N - 1)``: the nodes span ``L`` end to end. They are
``x_j = (j - N//2) * delta``, ``j = 0 .. N-1``: node ``N//2`` sits exactly at x = 0,
where Z(0) = 0 holds to the round-off of the sums (exactly with the reference BLAS;
OpenBLAS, which orders them differently, leaves ~3e-19 m, 2e-16 of max |Z|); for even N
the window is therefore shifted by delta/2 from symmetric: it covers
``[-L/2 - delta/2, L/2 - delta/2]``. With this choice nested
acquisitions whose lengths have an integer ratio (10x/20x = 2, 20x/100x = 5) share every
coarse node that lies in the fine window, so Z_d = Z_10x - Z_20x (Sec. 3.3.1) is an
exact node-by-node difference. The returned :class:`~roughfe.surfaces.Surface` follows
the package-wide cell convention ``size = N * spacing``, i.e. ``size = N L / (N - 1)``;
``metadata["x0"]`` is the coordinate of node 0 and ``metadata["length"]`` is L.

The chromosome range at length L (Eq. 3.5) is
``n_s = floor(log_gamma(lambda1 / L)) + 1`` and
``n_f = floor(log_gamma(lambda1 / delta)) + 1``. Note that Eq. 3.5 keeps wavelengths
down to ``delta``, below the Nyquist wavelength ``2 delta``: the last one or two
chromosomes of each realisation are aliased on the nodes (they are still evaluated
exactly at the nodes, as the thesis does). Table 1 (A = 1, H = 0.75, gamma = 1.5, M = 8,
lambda1 = L_10x = 1 mm; the caption's "1e-4 m" is a typo for 1e-3 m) gives n = 1..16
(10x, L = 1 mm), 2..18 (20x, 0.5 mm) and 6..22 (100x, 0.1 mm).

File format (``format = "roughfe-genome"``, ``version = 1``)
-----------------------------------------------------------
JSON object with ``format``, ``version``, ``A``, ``H``, ``gamma``, ``lambda1`` (m),
``M``, ``n_first``, ``phases`` (M lists of n_c angles in rad), optional ``angles``
(M in-plane ridge angles, rad) and ``anisotropy`` (M positive amplitude factors), and
``metadata`` (JSON-safe facts: seed, source, sequencing report).
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping, Optional

import numpy as np

from ..errors import (FileFormatError, InputError, check_finite_positive, check_in_interval,
                      check_int)
from ..frozen import FrozenMapping, ReadOnlyArrays
from ..surfaces.surface import Surface
from ..surfaces.wm import resolve_rng, wm_series
from ..writers import write_json

__all__ = ["Genome", "save_genome", "load_genome", "random_genome", "table1_genome", "realize",
           "realize_surface", "chromosome_range", "node_coordinates", "chromosome_heights",
           "profile_heights", "chromosome_indices", "surface_heights", "observation_coordinates",
           "GENOME_FORMAT", "GENOME_VERSION", "DEFAULT_NODES", "SCALES"]

GENOME_FORMAT = "roughfe-genome"
GENOME_VERSION = 1
DEFAULT_NODES = 512

#: Named observation scales of the thesis (Sec. 3.2, Fig. 26): length as a fraction of
#: lambda1 (the thesis sets lambda1 = L_10x, Table 1).
SCALES = {"10x": 1.0, "20x": 0.5, "100x": 0.1}

# Relative tolerance on log_gamma(.) before taking the floor in Eq. 3.5, so that an
# exact power (lambda1 = L gives log = 0) is not pushed to the wrong integer by round-off.
_FLOOR_TOL = 1e-9


def _as_angle_vector(name, value, m):
    if value is None:
        return None
    arr = np.array(value, dtype=float, copy=True).ravel()
    if arr.size != m:
        raise InputError(f"{name} must have one entry per ridge (M = {m}), got {arr.size}")
    if not np.all(np.isfinite(arr)):
        raise InputError(f"{name} must be finite, got {arr.tolist()}")
    arr.setflags(write=False)
    return arr


@dataclass(frozen=True, eq=False)
class Genome(ReadOnlyArrays):
    """Genes of a rough profile or surface: the truncated MWM function of Eq. (3.1).

    Parameters
    ----------
    A : float
        Amplitude gene (m^(1-H)); > 0.
    H : float
        Scaling (Hurst-like) exponent; 0 < H <= 3.
    gamma : float
        Frequency density, ratio of neighbouring wavenumbers (Eq. 3.6); 1 < gamma <= 10.
    lambda1 : float
        Reference wavelength of chromosome n = 1 (m); > 0.
    phases : array_like, shape (M, n_c)
        Phase matrix Phi (rad). Row m is a ridge, column j is chromosome n_first + j.
        M = phases.shape[0] is the number of ridges (1 <= M <= 100).
    n_first : int
        Chromosome index of the first column of ``phases`` (>= 1; default 1).
    angles : array_like, shape (M,), optional
        In-plane ridge angles theta_m (rad) for surfaces (Eq. 3.17); ignored by profiles.
    anisotropy : array_like, shape (M,), optional
        Positive amplitude factors alpha_m of the ridges (Eq. 3.17-3.18); default 1.
    metadata : mapping, optional
        JSON-safe facts (seed, source, sequencing report).
    """

    A: float
    H: float
    gamma: float
    lambda1: float
    phases: np.ndarray
    n_first: int = 1
    angles: Optional[np.ndarray] = None
    anisotropy: Optional[np.ndarray] = None
    metadata: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "A", check_finite_positive("A (amplitude gene, m^(1-H))", self.A))
        set_(self, "H", check_in_interval("H (scaling exponent)", self.H, 0, 3, "right"))
        set_(self, "gamma", check_in_interval("gamma (frequency density, Eq. 3.6)",
                                              self.gamma, 1, 10, "right"))
        set_(self, "lambda1", check_finite_positive("lambda1 (reference wavelength, m)", self.lambda1))
        try:
            phi = np.array(self.phases, dtype=float, copy=True)
        except (TypeError, ValueError):
            raise InputError("phases must be a numeric (M, n_c) matrix of angles in rad") from None
        if phi.ndim == 1:
            phi = phi[None, :]
        if phi.ndim != 2 or phi.shape[0] < 1 or phi.shape[1] < 1:
            raise InputError(f"phases must be an (M, n_c) matrix with M, n_c >= 1, got shape {phi.shape}")
        if phi.shape[0] > 100:
            raise InputError(f"M (rows of phases) must be <= 100, got {phi.shape[0]}")
        if not np.all(np.isfinite(phi)):
            raise InputError("phases must be finite angles in rad")
        phi.setflags(write=False)
        set_(self, "phases", phi)
        if int(self.n_first) != self.n_first or int(self.n_first) < 1:
            raise InputError(f"n_first (index of the first phase column) must be an integer >= 1, "
                             f"got {self.n_first!r}")
        set_(self, "n_first", int(self.n_first))
        set_(self, "angles", _as_angle_vector("angles", self.angles, phi.shape[0]))
        aniso = _as_angle_vector("anisotropy", self.anisotropy, phi.shape[0])
        if aniso is not None and not np.all(aniso > 0):
            raise InputError(f"anisotropy factors must be > 0, got {aniso.tolist()}")
        set_(self, "anisotropy", aniso)
        set_(self, "metadata", FrozenMapping(self.metadata or {}))

    # -- derived genes --------------------------------------------------------------
    @property
    def M(self) -> int:
        """Number of ridges (rows of the phase matrix)."""
        return int(self.phases.shape[0])

    @property
    def n_last(self) -> int:
        """Largest chromosome index with known phases."""
        return self.n_first + self.phases.shape[1] - 1

    @property
    def prefactor(self) -> float:
        """G = A sqrt(ln(gamma)/M) (2 pi/lambda1)^(-H) of Eq. (3.1) (m)."""
        return self.A * math.sqrt(math.log(self.gamma) / self.M) * (2 * math.pi / self.lambda1) ** (-self.H)

    def wavenumber(self, n):
        """q_n = (2 pi / lambda1) gamma^(n-1) (rad/m), Eq. (3.1)-(3.2)."""
        return 2 * np.pi / self.lambda1 * self.gamma ** (np.asarray(n, dtype=float) - 1.0)

    def wave_amplitude(self, n):
        """Amplitude of one elementary wave of chromosome n: G gamma^((1-n) H) (m)."""
        return self.prefactor * self.gamma ** ((1.0 - np.asarray(n, dtype=float)) * self.H)

    def phase_columns(self, n):
        """Phases phi_{m,n} (rad) of chromosomes ``n`` (array of indices): shape (M, len(n))."""
        n = np.atleast_1d(np.asarray(n, dtype=int))
        if n.size and (n.min() < self.n_first or n.max() > self.n_last):
            raise InputError(
                f"chromosomes {n.min()}..{n.max()} requested, but the genome knows phases only for "
                f"n = {self.n_first}..{self.n_last}; use a larger phase matrix (random_genome(n_max=...))")
        return self.phases[:, n - self.n_first]

    def chromosome_range(self, length, n_nodes=DEFAULT_NODES):
        """(n_s, n_f) at observation length ``length`` (m) with ``n_nodes`` nodes, Eq. (3.5)."""
        return chromosome_range(self.gamma, self.lambda1, length, n_nodes)

    def held_range(self, length, n_nodes=DEFAULT_NODES):
        """The chromosomes of Eq. (3.5) at this window that the genome holds (band-limited
        genome): ``(max(n_s, n_first), min(n_f, n_last))``. A genome carries chromosomes
        only over a finite band (a sequenced genome holds exactly those present in the
        data); a realisation sums those and never invents the ones beyond its phases.
        InputError when the window shows none of them."""
        n_s, n_f = self.chromosome_range(length, n_nodes)
        lo, hi = max(n_s, self.n_first), min(n_f, self.n_last)
        if lo > hi:
            raise InputError(f"a window of L = {length:g} m with {n_nodes} nodes shows chromosomes "
                             f"{n_s}..{n_f} (Eq. 3.5), but the genome holds only "
                             f"{self.n_first}..{self.n_last}")
        return lo, hi

    def length_of(self, scale) -> float:
        """Observation length (m) of a named scale ("10x", "20x", "100x"): fraction of lambda1."""
        if scale not in SCALES:
            raise InputError(f"scale must be one of {sorted(SCALES)}, got {scale!r}")
        return SCALES[scale] * self.lambda1

    # -- file format ----------------------------------------------------------------
    def to_dict(self) -> dict:
        """JSON-safe dict in the versioned ``roughfe-genome`` format."""
        out = {"format": GENOME_FORMAT, "version": GENOME_VERSION,
               "A": self.A, "H": self.H, "gamma": self.gamma, "lambda1": self.lambda1,
               "M": self.M, "n_first": self.n_first, "phases": self.phases.tolist()}
        if self.angles is not None:
            out["angles"] = self.angles.tolist()
        if self.anisotropy is not None:
            out["anisotropy"] = self.anisotropy.tolist()
        out["metadata"] = dict(self.metadata)
        return out

    @classmethod
    def from_dict(cls, data: Mapping) -> "Genome":
        """Inverse of :meth:`to_dict`; raises FileFormatError on a foreign or newer format."""
        if not isinstance(data, Mapping) or data.get("format") != GENOME_FORMAT:
            raise FileFormatError(f"not a {GENOME_FORMAT!r} object (format = "
                                  f"{data.get('format') if isinstance(data, Mapping) else type(data).__name__!r})")
        version = data.get("version")
        if not isinstance(version, int) or version < 1 or version > GENOME_VERSION:
            raise FileFormatError(f"{GENOME_FORMAT} version {version!r} is not readable by this roughfe "
                                  f"(reads versions 1..{GENOME_VERSION})")
        missing = [k for k in ("A", "H", "gamma", "lambda1", "phases") if k not in data]
        if missing:
            raise FileFormatError(f"{GENOME_FORMAT} object lacks the genes {missing}")
        for key in ("A", "H", "gamma", "lambda1"):
            _json_number(key, data[key])
        for key in ("M", "n_first"):
            if key in data:
                _json_number(key, data[key], integer=True)
        for key in ("phases", "angles", "anisotropy"):
            if data.get(key) is not None:
                _json_numbers(key, data[key])
        genome = cls(A=data["A"], H=data["H"], gamma=data["gamma"], lambda1=data["lambda1"],
                     phases=data["phases"], n_first=data.get("n_first", 1),
                     angles=data.get("angles"), anisotropy=data.get("anisotropy"),
                     metadata=data.get("metadata", {}))
        if "M" in data and data["M"] != genome.M:
            raise FileFormatError(f"M = {data['M']} disagrees with the {genome.M} rows of phases")
        return genome

    def to_json(self) -> str:
        from ..writers import to_json_text
        return to_json_text(self.to_dict())

    @classmethod
    def from_json(cls, text: str) -> "Genome":
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise FileFormatError(f"genome JSON cannot be parsed: {exc}") from None
        return cls.from_dict(data)

    def __repr__(self):
        return (f"Genome(A={self.A:.6g}, H={self.H:.4g}, gamma={self.gamma:.6g}, "
                f"lambda1={self.lambda1:.6g} m, M={self.M}, n={self.n_first}..{self.n_last})")


def _json_number(key, value, integer=False):
    """A gene read from JSON must be a JSON number (an integer where ``integer``):
    ``"0.75"``, ``true`` or ``8.5`` for M are format errors, not silent conversions."""
    ok = isinstance(value, int) if integer else isinstance(value, (int, float))
    if isinstance(value, bool) or not ok:
        kind = "an integer" if integer else "a number"
        raise FileFormatError(f"{key} must be {kind} in a {GENOME_FORMAT} file, got "
                              f"{json.dumps(value)} ({type(value).__name__})")
    return value


def _json_numbers(key, value):
    """``value`` must be a (nested) list of JSON numbers."""
    if isinstance(value, list):
        for v in value:
            _json_numbers(key, v)
        return value
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise FileFormatError(f"{key} must hold numbers only in a {GENOME_FORMAT} file, got "
                              f"{json.dumps(value)} ({type(value).__name__})")
    return value


def save_genome(genome: Genome, path) -> Path:
    """Write ``genome`` as versioned JSON, atomically (``roughfe.writers.write_json``)."""
    return write_json(path, genome.to_dict())


def load_genome(path) -> Genome:
    """Read a genome JSON file written by :func:`save_genome`."""
    path = Path(path)
    if path.is_dir():
        raise InputError(f"{path} is a folder, not a genome JSON file")
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputError(f"genome file {path} does not exist") from None
    except OSError as exc:
        raise FileFormatError(f"{path}: cannot read genome file ({exc.strerror})") from None
    except UnicodeDecodeError:
        raise FileFormatError(f"{path} is not a genome JSON file (binary content"
                              + (", a roughfe surface .npz?" if path.suffix == ".npz" else "")
                              + ")") from None
    try:
        return Genome.from_json(text)
    except FileFormatError as exc:
        raise FileFormatError(f"{path}: {exc}") from None


def random_genome(A, H, gamma, lambda1, M, n_max, *, rng, n_first=1, angles=None,
                  anisotropy=None) -> Genome:
    """A genome with phases drawn uniformly in [0, 2 pi) from ``rng``.

    Parameters
    ----------
    A, H, gamma, lambda1 : float
        Genes (see :class:`Genome`).
    M : int
        Number of ridges.
    n_max : int
        Largest chromosome index that gets a phase column (e.g. 22 for Table 1 at 100x).
    rng : numpy.random.Generator, int or None
        Source of the phases (an int is used as a seed; None draws a fresh one). The seed,
        when known (not for a Generator), is kept in ``metadata["seed"]``.
    """
    gen, seed = resolve_rng(rng)
    M = check_int("M (number of ridges)", M, 1)
    n_first = check_int("n_first (index of the first phase column)", n_first, 1)
    n_max = check_int(f"n_max (last chromosome index, >= n_first = {n_first})", n_max, n_first)
    phases = gen.uniform(0.0, 2 * np.pi, size=(M, n_max - n_first + 1))
    meta = {"generator": "random_genome"}
    if seed is not None:
        meta["seed"] = int(seed)
    return Genome(A=A, H=H, gamma=gamma, lambda1=lambda1, phases=phases, n_first=n_first,
                  angles=angles, anisotropy=anisotropy, metadata=meta)


def table1_genome(*, rng=0, n_max=22) -> Genome:
    """The worked example of thesis Table 1: A = 1, H = 0.75, gamma = 1.5, M = 8, lambda1 = 1 mm.

    The thesis does not give the phases: they are drawn from ``rng``. ``n_max = 22``
    covers the 100x realisation (n = 6..22).
    """
    return random_genome(1.0, 0.75, 1.5, 1e-3, 8, n_max, rng=rng)


# -- Eq. 3.5 and the nodes -------------------------------------------------------------
def _check_nodes(n_nodes):
    if int(n_nodes) != n_nodes or int(n_nodes) < 8:
        raise InputError(f"n_nodes must be an integer >= 8, got {n_nodes!r}")
    return int(n_nodes)


def chromosome_range(gamma, lambda1, length, n_nodes=DEFAULT_NODES):
    """First and last chromosome index (n_s, n_f) of a realisation, Eq. (3.5).

    Parameters
    ----------
    gamma : float
        Frequency density (> 1).
    lambda1 : float
        Reference wavelength (m).
    length : float
        Observation length L (m); the node spacing is ``delta = L / (N - 1)``.
    n_nodes : int
        Number of nodes N.

    Returns
    -------
    (int, int)
        ``n_s = floor(log_gamma(lambda1/L)) + 1`` and
        ``n_f = floor(log_gamma(lambda1/delta)) + 1``.

    Notes
    -----
    The count n_f - n_s + 1 is floor(log_gamma(N - 1)) + 1 or + 2 (by the fractional
    parts of log_gamma(lambda1/L) and log_gamma(N - 1)), never Eq. (3.4)'s
    n_c = floor(log_gamma(N - 1)): Table 1 (N = 512) has n_c = 15 by Eq. (3.4) and 16 /
    17 / 17 chromosomes at 10x / 20x / 100x by Eq. (3.5). The thesis's claim that n_c
    "will be the same at any realization" holds for neither equation's count across
    windows; Eq. (3.5), the range used, is followed.
    """
    n_nodes = _check_nodes(n_nodes)
    length = check_finite_positive("length (observation length, m)", length)
    lambda1 = check_finite_positive("lambda1 (m)", lambda1)
    gamma = float(gamma)
    if not gamma > 1.0:
        raise InputError(f"gamma must be > 1, got {gamma!r}")
    delta = length / (n_nodes - 1)
    lg = math.log(gamma)
    n_s = math.floor(math.log(lambda1 / length) / lg + _FLOOR_TOL) + 1
    n_f = math.floor(math.log(lambda1 / delta) / lg + _FLOOR_TOL) + 1
    return int(n_s), int(n_f)


def node_coordinates(length, n_nodes=DEFAULT_NODES):
    """Node abscissae x_j = (j - N//2) L/(N-1) (m): node N//2 is x = 0 (see module notes)."""
    n_nodes = _check_nodes(n_nodes)
    length = check_finite_positive("length (observation length, m)", length)
    delta = length / (n_nodes - 1)
    return (np.arange(n_nodes) - n_nodes // 2) * delta


def chromosome_heights(genome: Genome, x, n):
    """Chromosomes C_n(x) of Eq. (3.2) (m), one row per index in ``n``.

    Parameters
    ----------
    genome : Genome
    x : ndarray, shape (P,)
        Abscissae (m).
    n : int or sequence of int
        Chromosome indices.

    Returns
    -------
    ndarray, shape (len(n), P)
    """
    n = np.atleast_1d(np.asarray(n, dtype=int))
    x = np.asarray(x, dtype=float)
    phases = genome.phase_columns(n)
    amps = np.broadcast_to(genome.wave_amplitude(n), phases.shape)
    if genome.anisotropy is not None:
        amps = amps * genome.anisotropy[:, None]
    q = genome.wavenumber(n)
    return np.stack([wm_series(x, amps[:, [k]], q[[k]], phases[:, [k]]) for k in range(n.size)])


def profile_heights(genome: Genome, x, n):
    """Z(x) of Eq. (3.1) (m) summed over the chromosome indices ``n`` (Eq. 3.3)."""
    n = np.atleast_1d(np.asarray(n, dtype=int))
    phases = genome.phase_columns(n)
    amps = np.broadcast_to(genome.wave_amplitude(n), phases.shape)
    if genome.anisotropy is not None:
        amps = amps * genome.anisotropy[:, None]
    return wm_series(np.asarray(x, dtype=float), amps, genome.wavenumber(n), phases)


def chromosome_indices(chromosomes) -> np.ndarray:
    """The distinct chromosome indices n (sorted int array) named by ``chromosomes`` (an
    index or a sequence of them); :class:`InputError` for none, or for an index that is not
    an integer >= 1 (1.5 is refused, not truncated to 1)."""
    items = np.ravel(np.asarray(chromosomes, dtype=object))
    if items.size == 0:
        raise InputError("chromosomes must name at least one chromosome index")
    return np.unique([check_int(f"chromosomes[{k}] (a chromosome index n)", v, 1)
                      for k, v in enumerate(items)])


def realize(genome: Genome, length=None, n_nodes=DEFAULT_NODES, *, scale=None,
            chromosomes=None) -> Surface:
    """Realise a genome as a profile at observation length ``length`` (Eq. 3.1, 3.5).

    Parameters
    ----------
    genome : Genome
    length : float, optional
        Observation length L (m). Give either ``length`` or ``scale``.
    n_nodes : int
        Number of nodes N (default 512); spacing ``delta = L/(N-1)``.
    scale : {"10x", "20x", "100x"}, optional
        Named scale: L = lambda1, lambda1/2, lambda1/10 (Table 1 convention).
    chromosomes : sequence of int, optional
        Sum only these chromosome indices (a single chromosome, a top-down or bottom-up
        partial sum, Sec. 3.2.2), integers >= 1 (:func:`chromosome_indices`). Default:
        the chromosomes n_s..n_f of Eq. (3.5) that the genome holds
        (:meth:`Genome.held_range`: none beyond its phase matrix).

    Returns
    -------
    Surface
        Heights (m) at the nodes x_j = (j - N//2) delta; ``size = N delta`` (cell
        convention of :class:`Surface`); metadata: ``length``, ``x0``, ``n_s``, ``n_f``,
        ``chromosomes``, the genes and ``generator = "genome"``.
    """
    if (length is None) == (scale is None):
        raise InputError("give exactly one of length (m) or scale ('10x', '20x', '100x')")
    if scale is not None:
        length = genome.length_of(scale)
    n_nodes = _check_nodes(n_nodes)
    n_s, n_f = genome.chromosome_range(length, n_nodes)
    if chromosomes is None:
        idx = np.arange(*np.add(genome.held_range(length, n_nodes), (0, 1)))
    else:
        idx = chromosome_indices(chromosomes)
    x = node_coordinates(length, n_nodes)
    z = profile_heights(genome, x, idx)
    delta = length / (n_nodes - 1)
    meta = {"generator": "genome", "length": float(length), "n_nodes": n_nodes,
            "x0": float(x[0]), "n_s": n_s, "n_f": n_f,
            "chromosomes": [int(i) for i in idx],
            "genes": {"A": genome.A, "H": genome.H, "gamma": genome.gamma,
                      "lambda1": genome.lambda1, "M": genome.M}}
    if scale is not None:
        meta["scale"] = scale
    if "seed" in genome.metadata:
        meta["seed"] = genome.metadata["seed"]
    return Surface(z, n_nodes * delta, periodic=False, metadata=meta)


def surface_heights(genome: Genome, length, n_nodes, x, y):
    """``(z, n)``: heights (m) of a genome with ridge angles on the grid ``x`` (axis 0)
    by ``y`` (axis 1) (m), summing the chromosomes ``n`` of Eq. (3.5) at a window of
    ``length`` with ``n_nodes`` nodes that the genome holds, each ridge scaled by its
    anisotropy factor. The one sum of :func:`realize_surface` and of the 2D sequencer's
    misfit (each acquisition at its own node coordinates)."""
    n = np.arange(*np.add(genome.held_range(length, n_nodes), (0, 1)))
    phases = genome.phase_columns(n)
    amps = np.broadcast_to(genome.wave_amplitude(n), phases.shape)
    if genome.anisotropy is not None:
        amps = amps * genome.anisotropy[:, None]
    z = wm_series((np.asarray(x)[:, None], np.asarray(y)[None, :]), amps,
                  genome.wavenumber(n), phases, genome.angles)
    return z, n


def realize_surface(genome: Genome, length, n_nodes=DEFAULT_NODES) -> Surface:
    """Realise a genome with ridge ``angles`` as a 2D surface (Eq. 3.17, projected form).

    Eq. (3.17) writes the ridge coordinate as sqrt(x^2+y^2) cos(theta_m); the physically
    meaningful plane wave along direction theta_m is x cos(theta_m) + y sin(theta_m)
    (the two agree only on the ray of angle 0), which is what is used here
    (``roughfe.surfaces.wm.wm_series``). Nodes as for profiles on both axes.
    """
    if genome.angles is None:
        raise InputError("realize_surface needs a genome with ridge angles (one per row of phases)")
    n_nodes = _check_nodes(n_nodes)
    n_s, n_f = genome.chromosome_range(length, n_nodes)
    x = node_coordinates(length, n_nodes)
    z, n = surface_heights(genome, length, n_nodes, x, x)
    delta = length / (n_nodes - 1)
    meta = {"generator": "genome", "length": float(length), "n_nodes": n_nodes,
            "x0": float(x[0]), "n_s": n_s, "n_f": n_f, "chromosomes": [int(i) for i in n]}
    return Surface(z, n_nodes * delta, periodic=False, metadata=meta)


def observation_coordinates(surface: Surface):
    """Node abscissae (m) of a realisation: ``metadata["x0"] + j * spacing``.

    Without ``x0`` in the metadata the profile is taken to follow the genome node
    convention (node N//2 at x = 0).
    """
    if surface.ndim != 1:
        raise InputError(f"a profile (1D heights) is needed, got shape {surface.shape}")
    n = surface.shape[0]
    dx = surface.spacing[0]
    x0 = surface.metadata.get("x0")
    x0 = -(n // 2) * dx if x0 is None else float(x0)
    return x0 + np.arange(n) * dx
