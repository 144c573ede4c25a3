"""Realisation and contact settings of a genome database, and the thesis values
(Sec. 4.1.2) in ONE constant, :data:`THESIS_SETTINGS`."""
from __future__ import annotations

from dataclasses import asdict, dataclass, fields, replace

from ...bem.operators import check_kernel_name
from ...errors import InputError, check_finite_positive, check_in_open_interval, check_int
from ...model import Material
from ..periodic import check_dim


@dataclass(frozen=True)
class DatabaseSettings:
    """Realisation and contact settings shared by every genome of a database (Sec. 4.1.2).

    Parameters
    ----------
    length : float
        Observation length L (m); thesis 849.42 um (= lambda).
    n_nodes : int
        Nodes N of each realisation; thesis 512.
    youngs_modulus : float
        E (Pa) of the deformable body against a rigid profile; thesis 1 MPa.
    poisson : float
        nu; the thesis gives none, 0 makes E* = E.
    n_steps : int
        n_t far-field displacements up to the peak-valley amplitude; thesis 20.
    threshold : float
        c_n above which a chromosome is macro-scale (Alg. 2); thesis 0.95.
    kernel : str
        BEM influence kernel passed to :func:`roughfe.bem.contact_sweep`: "auto" or one of
        :data:`roughfe.bem.operators.KERNELS`.
    stiffness : {"fd", "exact"}
        How K(p) is taken from the sweep (see :func:`roughfe.genomics.macro_micro.profile_response`).
    correlation : {"steps", "pressure"}
        How c_n pairs the curves (see :mod:`roughfe.genomics.macro_micro`).
    dim : {1, 2}
        1: profiles (Eq. 3.1, nodes spanning L, non-periodic BEM; the thesis). 2: periodic
        N x N surfaces of period L with M ridges (Eq. 3.17 on the torus,
        :mod:`roughfe.genomics.periodic`), periodic spectral BEM.
    top_fraction : float
        The n_t approaches end at ``top_fraction`` times the default top approach
        (peak-valley for profiles; max h - mean h, i.e. full contact, for periodic
        surfaces). 1 for profiles (thesis). A periodic surface's K(p) diverges at full
        contact (the mean displacement is free), so surface databases stop before it
        (``roughfe db build --dim 2``: 0.8, where A* is about 0.3-0.4).
    """

    length: float = 849.42e-6
    n_nodes: int = 512
    youngs_modulus: float = 1.0e6
    poisson: float = 0.0
    n_steps: int = 20
    threshold: float = 0.95
    kernel: str = "auto"
    stiffness: str = "fd"
    correlation: str = "steps"
    dim: int = 1
    top_fraction: float = 1.0

    def __post_init__(self):
        """Check every field (InputError naming it): numbers given as text or bools, and
        a non-integer n_nodes or n_steps (64.7 ran as 64), are refused, not truncated."""
        check_finite_positive("length (m)", self.length)
        check_finite_positive("youngs_modulus (Pa)", self.youngs_modulus)
        # Poisson's ratio in (-1, 0.5], checked before a database stores the settings
        Material(self.youngs_modulus, self.poisson)
        object.__setattr__(self, "n_nodes", check_int("n_nodes", self.n_nodes, 16))
        object.__setattr__(self, "n_steps", check_int("n_steps", self.n_steps, 3))
        if self.correlation not in ("steps", "pressure"):
            raise InputError(f"correlation must be 'steps' or 'pressure', got {self.correlation!r}")
        if self.stiffness not in ("fd", "exact"):
            raise InputError(f"stiffness must be 'fd' or 'exact', got {self.stiffness!r}")
        check_kernel_name(self.kernel)
        check_in_open_interval("threshold", self.threshold, 0.0, 1.0)
        object.__setattr__(self, "dim", check_dim(self.dim))
        top = check_finite_positive("top_fraction", self.top_fraction)
        if top > 1.0:
            raise InputError(f"top_fraction must lie in (0, 1], got {self.top_fraction!r}")
        object.__setattr__(self, "top_fraction", top)

    def to_dict(self) -> dict:
        """The fields as a dict; a thesis profile database (dim 1, top_fraction 1) omits
        ``dim`` and ``top_fraction``, so its records stay byte-identical to those of
        databases built before surfaces existed (an absent ``dim`` reads as 1)."""
        d = asdict(self)
        if self.dim == 1 and self.top_fraction == 1.0:
            del d["dim"], d["top_fraction"]
        return d

    def response_options(self) -> dict:
        """Keywords of :func:`roughfe.genomics.macro_micro.profile_response` (and
        ``profile_sweep``): E, nu, n_t, kernel, the K kind and the top approach."""
        return {"youngs_modulus": self.youngs_modulus, "poisson": self.poisson,
                "n_steps": self.n_steps, "kernel": self.kernel, "stiffness": self.stiffness,
                "top_fraction": self.top_fraction}

    @classmethod
    def from_dict(cls, d) -> "DatabaseSettings":
        return cls(**d)


#: the thesis database settings (Sec. 4.1.2): L = 849.42 um, N = 512, E = 1 MPa, nu = 0,
#: n_t = 20, threshold 0.95 -- every default elsewhere (task keywords, study analyses,
#: CLI options, designs) is read from here
THESIS_SETTINGS = DatabaseSettings()


def settings_from(values) -> DatabaseSettings:
    """:class:`DatabaseSettings` from a mapping of field values, :data:`THESIS_SETTINGS`
    for the missing ones (InputError naming an unknown field)."""
    allowed = [f.name for f in fields(DatabaseSettings)]
    unknown = sorted(set(values) - set(allowed))
    if unknown:
        raise InputError(f"unknown database setting(s) {unknown}; the settings are {allowed}")
    return replace(THESIS_SETTINGS, **values)
