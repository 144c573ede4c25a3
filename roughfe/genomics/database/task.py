"""The per-genome database computation (pure: runs in a worker or in the study runner)."""
from __future__ import annotations

import numpy as np

from ...bem.memory import check_sweep_memory
from ...errors import InputError, check_int
from ..genome import Genome, chromosome_range
from ..macro_micro import macro_micro
from ..periodic import periodic_chromosome_range
from .settings import DatabaseSettings, settings_from


def genome_entry_task(gamma=None, hurst=None, phases=None, *, label, source="sobol",
                      amplitude=1.0, lambda1=None, genome_json=None, angles=None,
                      anisotropy=None, **settings) -> dict:
    """Realise one genome, run Alg. 2 on it and return its database record (JSON-safe).

    Parameters
    ----------
    gamma, hurst : float, optional
        Genes gamma (-) and H (-) of Eq. (3.1).
    phases : int or array_like, optional
        A phase vector phi_{1,n} (rad; the first n_c entries are used, M = 1), for a
        surface database (``dim = 2``) a phase matrix (M rows), or an int seed that draws
        uniform phases with ``numpy.random.default_rng(seed)``.
    angles, anisotropy : sequence of float, optional
        Surface databases: ridge angles theta_m (rad) and amplitude factors alpha_m
        (Eq. 3.17), one per ridge.
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
    settings, genome = genome_entry_inputs(
        gamma, hurst, phases, amplitude=amplitude, lambda1=lambda1, genome_json=genome_json,
        angles=angles, anisotropy=anisotropy, **settings)
    mm = macro_micro(genome, settings)
    genome = _with_metadata(genome, label=str(label), source=str(source))
    return {"label": str(label), "source": str(source), "genome": genome.to_dict(),
            "p_max": mm.curve.p_max, "curve": mm.curve.to_dict(),
            "chromosome_curves": [c.to_dict() for c in mm.chromosome_curves],
            "corr_k": mm.corr_k.tolist(), "corr_a": mm.corr_a.tolist(),
            "macro": list(mm.macro), "micro": list(mm.micro), "settings": settings.to_dict()}


def genome_entry_inputs(gamma=None, hurst=None, phases=None, *, amplitude=1.0, lambda1=None,
                        genome_json=None, angles=None, anisotropy=None, **settings):
    """``(DatabaseSettings, Genome)`` of :func:`genome_entry_task`'s keywords (``label``
    and ``source`` aside): the settings and the genes checked (and the memory of a BEM
    sweep's fields on the database's grid), the genome built, nothing realised or
    solved. The task's first step, and the input check of the study analyses that run
    it (:mod:`roughfe.study.analyses`)."""
    settings = settings_from(settings)
    if genome_json is not None:
        genome = _fits_window(Genome.from_dict(genome_json), settings)
    elif gamma is None or hurst is None or phases is None:
        raise InputError("genome_entry_task needs gamma, hurst and phases, or genome_json")
    else:
        genome = make_genome(gamma, hurst, phases, settings, amplitude=amplitude,
                             lambda1=lambda1, angles=angles, anisotropy=anisotropy)
    # the fields every BEM sweep of Alg. 2 keeps, on the database's grid; last, after
    # every check of the values (a study on a remote scheduler notes this machine's
    # shortage and goes on: roughfe.study.runner.run_study)
    check_sweep_memory((settings.n_nodes,) * settings.dim, settings.n_steps,
                       periodic=settings.dim == 2 and settings.kernel in ("auto", "spectral"))
    return settings, genome


def _fits_window(genome: Genome, settings: DatabaseSettings) -> Genome:
    """``genome`` when the database's window can realise it: a surface database (dim 2)
    needs ridge angles, a profile database (dim 1) takes no genome with ridge angles
    (its realisation would ignore them), and the window must show chromosomes the genome
    holds (InputError naming what is missing otherwise)."""
    from ..periodic import realized_chromosomes
    if settings.dim == 2 and genome.angles is None:
        raise InputError("a surface database (dim 2) takes surface genomes: this genome has "
                         "no ridge angles (a profile genome)")
    if settings.dim == 1 and genome.angles is not None:
        raise InputError(f"a profile database (dim 1) takes profile genomes: this genome has "
                         f"{genome.M} ridge(s) with angles (a surface genome, dim 2), which "
                         "a profile would ignore; add it to a surface database (--dim 2)")
    realized_chromosomes(genome, settings.length, settings.n_nodes, settings.dim)
    return genome


def _with_metadata(genome, **facts):
    d = genome.to_dict()
    d["metadata"] = {**d.get("metadata", {}), **facts}
    return Genome.from_dict(d)


def realised_range(gamma, settings: DatabaseSettings, lambda1=None):
    """``(n_s, n_f)``: the chromosomes a genome of ``gamma`` (and ``lambda1``, m; default
    the length L) realises at ``settings``: Eq. (3.5) for profiles (``dim == 1``), the
    periodic range (:func:`roughfe.genomics.periodic.periodic_chromosome_range`) for
    surfaces. :func:`make_genome` needs ``n_f - n_s + 1`` phases per ridge."""
    lam = settings.length if lambda1 is None else float(lambda1)
    window = periodic_chromosome_range if settings.dim == 2 else chromosome_range
    return window(float(gamma), lam, settings.length, settings.n_nodes)


def make_genome(gamma, hurst, phases, settings: DatabaseSettings, *, amplitude=1.0,
                lambda1=None, angles=None, anisotropy=None):
    """A genome with exactly the chromosomes realised at ``settings``.

    Profiles (``settings.dim == 1``): one ridge (M = 1), the chromosomes of Eq. (3.5).
    Surfaces (``dim == 2``): one ridge per entry of ``angles`` (rad) with the amplitude
    factors ``anisotropy`` (default 1), the chromosomes of the periodic range
    (:func:`roughfe.genomics.periodic.periodic_chromosome_range`). ``phases`` is a
    vector (M = 1) or a matrix with M rows (their first n_c entries are used), or an int
    seed >= 0 (uniform phases in [0, 2 pi) from ``numpy.random.default_rng(seed)``; a
    Python or numpy integer). A scalar that is not an integer (3.0, 3.5, a bool) is
    refused: until round 2, session 35 a float 3.0 ran as seed 3.
    """
    lam = settings.length if lambda1 is None else float(lambda1)
    if settings.dim == 2 and angles is None:
        raise InputError("a surface database genome (dim 2) needs ridge angles")
    m = len(np.atleast_1d(angles)) if settings.dim == 2 else 1
    n_s, n_f = realised_range(gamma, settings, lam)
    n_c = n_f - n_s + 1
    seed = _seed_or_none(phases)
    if seed is not None:
        phi = np.random.default_rng(seed).uniform(0, 2 * np.pi, (m, n_c))
    else:
        phi = np.atleast_2d(np.asarray(phases, dtype=float))
        if phi.shape[0] != m or phi.shape[1] < n_c:
            raise InputError(f"gamma = {gamma:.4g} needs {m} x {n_c} phases at "
                             f"N = {settings.n_nodes}, got a phase array of shape {phi.shape}")
        phi = phi[:, :n_c]
    return Genome(A=float(amplitude), H=float(hurst), gamma=float(gamma), lambda1=lam,
                  phases=phi, n_first=n_s, angles=angles, anisotropy=anisotropy)



def _seed_or_none(phases):
    """The int seed that a scalar ``phases`` is, None for a phase vector or matrix;
    InputError for a scalar that is no integer >= 0 (:func:`~roughfe.errors.check_int`):
    a float (3.0 is no seed, and one phase is no vector), a bool, text."""
    if np.ndim(phases) != 0:
        return None
    return check_int("phases (an int seed; else a phase vector in rad, M = 1, or a matrix "
                     "of M rows)", phases, 0)
