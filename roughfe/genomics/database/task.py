"""The per-genome database computation (pure: runs in a worker or in the study runner)."""
from __future__ import annotations

import numpy as np

from ...errors import InputError
from ..genome import Genome, chromosome_range
from ..macro_micro import macro_micro
from .settings import DatabaseSettings, settings_from


def genome_entry_task(gamma=None, hurst=None, phases=None, *, label, source="sobol",
                      amplitude=1.0, lambda1=None, genome_json=None, **settings) -> dict:
    """Realise one genome, run Alg. 2 on it and return its database record (JSON-safe).

    Parameters
    ----------
    gamma, hurst : float, optional
        Genes gamma (-) and H (-) of Eq. (3.1).
    phases : int or array_like, optional
        A phase vector phi_{1,n} (rad; the first n_c entries are used, M = 1) or an
        int seed that draws uniform phases with ``numpy.random.default_rng(seed)``.
    label : str
        Unique name of the genome in the database.
    amplitude, lambda1 : float
        Genes A (-) and lambda (m); ``lambda1=None`` means lambda = L (thesis).
    genome_json : dict, optional
        A complete Genome JSON (e.g. a sequenced genome for ``db extend``); then
        gamma/hurst/phases are not needed.
    **settings
        :class:`DatabaseSettings` fields as keywords (``length``, ``n_nodes``,
        ``youngs_modulus``, ...; so a study runner can pass them), the missing ones from
        :data:`THESIS_SETTINGS`.

    Returns
    -------
    dict
        ``label, source, genome, p_max, curve, chromosome_curves, corr_k, corr_a,
        macro, micro, settings`` (all JSON-safe).
    """
    settings = settings_from(settings)
    if genome_json is not None:
        genome = Genome.from_dict(genome_json)
    elif gamma is None or hurst is None or phases is None:
        raise InputError("genome_entry_task needs gamma, hurst and phases, or genome_json")
    else:
        genome = make_genome(gamma, hurst, phases, settings, amplitude=amplitude,
                             lambda1=lambda1)
    mm = macro_micro(genome, settings)
    genome = _with_metadata(genome, label=str(label), source=str(source))
    return {"label": str(label), "source": str(source), "genome": genome.to_dict(),
            "p_max": mm.curve.p_max, "curve": mm.curve.to_dict(),
            "chromosome_curves": [c.to_dict() for c in mm.chromosome_curves],
            "corr_k": mm.corr_k.tolist(), "corr_a": mm.corr_a.tolist(),
            "macro": list(mm.macro), "micro": list(mm.micro), "settings": settings.to_dict()}


def _with_metadata(genome, **facts):
    d = genome.to_dict()
    d["metadata"] = {**d.get("metadata", {}), **facts}
    return Genome.from_dict(d)


def make_genome(gamma, hurst, phases, settings: DatabaseSettings, *, amplitude=1.0,
                lambda1=None):
    """A one-ridge (M = 1) genome with the chromosomes realised at ``settings`` (Eq. 3.5).

    ``phases`` is a vector (its first n_c entries are used) or an int seed.
    """
    lam = settings.length if lambda1 is None else float(lambda1)
    n_s, n_f = chromosome_range(float(gamma), lam, settings.length, settings.n_nodes)
    n_c = n_f - n_s + 1
    if np.isscalar(phases) and float(phases) == int(phases):
        phi = np.random.default_rng(int(phases)).uniform(0, 2 * np.pi, n_c)
    else:
        phi = np.asarray(phases, dtype=float).ravel()
        if phi.size < n_c:
            raise InputError(f"gamma = {gamma:.4g} needs {n_c} phases at N = {settings.n_nodes}, "
                             f"got a phase vector of {phi.size}")
        phi = phi[:n_c]
    return Genome(A=float(amplitude), H=float(hurst), gamma=float(gamma), lambda1=lam,
                  phases=phi[None, :], n_first=n_s)
