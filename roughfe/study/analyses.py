"""The explicit registry of analyses a study can run.

``ANALYSES`` maps a name to an :class:`Analysis`: the dotted path ``"module:function"``
of a task function, a version string, a one-line description and, optionally, the
dotted path of its input check. Nothing is imported until a task runs (or the runner
checks the parameters before submitting), so a missing or not-yet-installed analysis
gives a clear error at run time, not at import time.

The input check is the first part of the task itself (it builds the task's inputs and
refuses bad values), so a study whose fixed or grid values are out of range (``E = -1``,
``D = 3.5``, an unknown kernel) is refused by :func:`check_parameters` before anything
is submitted, naming the task's parameters, instead of failing every task on the
workers. It never does the expensive work (no surface is generated, nothing solved).

A task function is called as ``function(**params, seed=seed)`` and returns one JSON-safe
record (a dict) or a list of them; each record becomes one row of the collected table,
next to the task's parameters and seed. Bump ``version`` when an analysis changes its
results: the version is part of each task's content key, so old results are not reused.
The key also holds every parameter as the task runs it, the function's defaults
included (:func:`parameter_defaults`), so changing a default needs no version bump.
"""
from __future__ import annotations

import importlib
import inspect
import os
import time
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..genomics.database.settings import THESIS_SETTINGS as _THESIS
from ..model import DEFAULT_E, DEFAULT_NU
from ..writers import to_jsonable


@dataclass(frozen=True)
class Analysis:
    """One registered analysis.

    Attributes
    ----------
    target : str
        ``"package.module:function"`` of the task function.
    version : str
        Part of every task key; change it when the results change.
    description : str
        One line for ``roughfe study run --help``.
    inputs : str
        ``"package.module:function"`` of the input check, called with the task's
        keywords (defaults applied, without ``seed``): raises InputError for bad values,
        cheaply; the task calls the same function first. Empty: names are checked only.
    """

    target: str
    version: str
    description: str
    inputs: str = ""


ANALYSES = {
    "selftest": Analysis(
        "roughfe.study.analyses:selftest_task", "1",
        "analytic function of x, y (cheap; options to sleep and to fail) for testing the runner"),
    "contact_sweep": Analysis(
        "roughfe.study.analyses:contact_sweep_task", "1",
        "generate a random surface, run the BEM load sweep (roughfe.response.response)",
        "roughfe.study.analyses:contact_sweep_inputs"),
    "leakage": Analysis(
        "roughfe.leakage.study:leakage_task", "1",
        "leakage of one surface over approach steps (thesis Sec. 2.4)",
        "roughfe.leakage.study:leakage_inputs"),
    "genome_db": Analysis(
        "roughfe.study.analyses:genome_db_task", "2",   # 2: labels name the genes
        "one entry of the genome database: WM genome, Alg. 2 macro/micro, BEM sweep "
        "(roughfe.genomics.database.genome_entry_task)",
        "roughfe.study.analyses:genome_db_inputs"),
    "genome_entry": Analysis(
        "roughfe.study.analyses:genome_entry_study_task", "1",
        "one given genome (Sobol design or a genome JSON) of a genome database: Alg. 2, BEM "
        "sweep; what `roughfe db build|extend` run",
        "roughfe.study.analyses:genome_entry_study_inputs"),
}


def resolve(name: str, what: str = "target"):
    """Import and return the task function of analysis ``name`` (``what="inputs"``: its
    input check, None when it has none).

    Raises :class:`InputError` naming the analysis and the module when it cannot be
    imported (for example when that part of roughfe is not installed yet).
    """
    if name not in ANALYSES:
        raise InputError(f"analysis {name!r} is unknown; choose from {sorted(ANALYSES)}")
    path = getattr(ANALYSES[name], what)
    if not path:
        return None
    module_name, _, attr = path.partition(":")
    try:
        module = importlib.import_module(module_name)
    except ImportError as exc:
        raise InputError(f"analysis {name!r} needs {path}, which cannot be "
                         f"imported here: {exc}") from None
    try:
        return getattr(module, attr)
    except AttributeError:
        raise InputError(f"analysis {name!r}: {module_name} has no function {attr!r}") from None


def parameter_defaults(name: str) -> dict:
    """The keyword defaults of analysis ``name``'s task function (``seed`` aside), as
    JSON values: what a task runs with for each parameter its spec does not give.

    They are part of every task key (:meth:`roughfe.study.StudySpec.tasks`): a default
    that changes (say E) gives new keys, so results computed with the old one are not
    reused, and a value written in the spec that equals the default gives the same key
    as leaving it out.
    """
    sig = inspect.signature(resolve(name))
    return {p: to_jsonable(v.default) for p, v in sig.parameters.items()
            if p != "seed" and v.default is not inspect.Parameter.empty}


def check_parameters(name: str, params) -> None:
    """Raise :class:`InputError` unless ``function(**params, seed=...)`` can bind and
    the analysis' input check (:class:`Analysis` ``inputs``) accepts the values.

    Run by the driver on every distinct parameter set before any task is submitted, so
    that a typo or an out-of-range value in a spec fails at once, naming the allowed
    names or the bad value and the task's parameters, instead of failing every task on
    the workers.
    """
    func = resolve(name)
    sig = inspect.signature(func)
    try:
        bound = sig.bind(**params, seed=0)
    except TypeError as exc:
        allowed = [p for p in sig.parameters if p != "seed"]
        required = [p for p, v in sig.parameters.items()
                    if p != "seed" and v.default is inspect.Parameter.empty]
        missing = [p for p in required if p not in params]
        if missing:          # a name the spec did not give ([grid] or [fixed] missing it)
            raise InputError(f"analysis {name!r} needs {missing} (in [grid] or [fixed]); "
                             f"the spec gives {sorted(params) or 'no parameter'}; its "
                             f"parameters are {allowed}") from None
        raise InputError(f"analysis {name!r} does not accept the parameters "
                         f"{sorted(params)}: {exc}; its parameters are {allowed}") from None
    check = resolve(name, "inputs")
    if check is None:
        return
    bound.apply_defaults()
    values = {k: v for k, v in bound.arguments.items() if k != "seed"}
    try:
        check(**values)
    except InputError as exc:     # the reason first; a task's 30-phase lists cut short
        task = repr(dict(params))  # (the line was the whole task, then the reason)
        task = task if len(task) <= 240 else task[:240] + " ...}"
        # the same kind (a MemoryShortage stays one: the runner tells it apart)
        raise type(exc)(f"{exc} (analysis {name!r}, task {task})") from None


def as_records(value, name: str) -> list[dict]:
    """Normalise a task's return value to a list of dicts (one table row each)."""
    if isinstance(value, dict):
        return [value]
    if isinstance(value, (list, tuple)) and all(isinstance(v, dict) for v in value):
        return list(value)
    to_records = getattr(value, "to_records", None)
    if callable(to_records):
        return as_records(to_records(), name)
    raise TypeError(f"analysis {name!r} returned {type(value).__name__}; a task must return "
                    "a dict, a list of dicts or an object with to_records()")


def selftest_task(*, x, seed, y=0.0, n_records=3, sleep=0.0, fail_x=(), crash_x=()):
    """Cheap deterministic task to test executors, resume and failure handling.

    Parameters
    ----------
    x, y : float
        Inputs of the analytic value ``f = x**2 + y * step``.
    seed : int
        Seeds ``u``, a uniform draw per record (checks that seeds are passed through).
    n_records : int
        Number of records (rows) returned.
    sleep : float
        Seconds to sleep first (to make a study slow enough to interrupt).
    fail_x : float or list of float
        Raise ``ValueError`` when ``x`` equals one of these (a task that always fails).
    crash_x : float or list of float
        Kill the worker process (``os._exit(3)``, like a segfault) when ``x`` equals one
        of these, after ``sleep``.

    Returns
    -------
    list of dict
        ``{"step", "f", "u"}`` per record.
    """
    fails = fail_x if isinstance(fail_x, (list, tuple)) else [fail_x]
    if x in fails:
        raise ValueError(f"selftest asked to fail at x={x!r}")
    if sleep:
        time.sleep(float(sleep))
    if x in (crash_x if isinstance(crash_x, (list, tuple)) else [crash_x]):
        os._exit(3)
    rng = np.random.default_rng(seed)
    u = rng.random(int(n_records))
    return [{"step": k, "f": float(x) ** 2 + float(y) * k, "u": float(u[k])}
            for k in range(int(n_records))]


def contact_sweep_task(*, seed, generator="rmd", fractal_dimension=2.3, m=6, length=1.0e-3,
                       rms_height=1.0e-6, E=DEFAULT_E, nu=DEFAULT_NU, n_steps=10,
                       kernel="auto", solver="auto", tol=1e-10):
    """Generate one random surface and run the BEM loading sweep on it.

    Parameters
    ----------
    seed : int
        Seed of the surface generator (recorded in the rows).
    generator : {"rmd", "spectral"}
        ``rmd``: :func:`roughfe.surfaces.rmd_surface` (thesis Sec. 2.1.1, ``2**m + 1``
        nodes over ``length``, not periodic); ``spectral``: the periodic Fourier-filtered
        :func:`roughfe.surfaces.spectral_surface` with ``2**m`` points over ``length``.
    fractal_dimension : float
        D in (2, 3); Hurst exponent H = 3 - D.
    m : int
        Resolution level, 1 <= m <= 13 for both generators (2**13 points per side hold
        0.5 GB of heights; m = 16 asked numpy for tens of GB on the worker).
    length : float
        Lateral size (m).
    rms_height : float
        Rms height the surface is scaled to (m).
    E, nu : float
        Young's modulus (Pa) and Poisson's ratio (-) of the elastic solid against the
        rigid surface (default: the one CLI default, :data:`roughfe.model.DEFAULT_E`; the
        spellings ``youngs_modulus``/``poisson`` of older specs are
        renamed with a warning by :func:`roughfe.study.spec.spec_from_mapping`).
    n_steps, kernel, solver, tol
        As in :func:`roughfe.bem.contact_sweep` (run through :func:`roughfe.response.response`).

    Returns
    -------
    list of dict
        One record per approach step: ``step`` and :data:`roughfe.bem.RECORD_KEYS` (SI).
    """
    from ..response import response
    from ..surfaces import rmd_surface, spectral_surface

    material, loading = contact_sweep_inputs(
        generator=generator, fractal_dimension=fractal_dimension, m=m, length=length,
        rms_height=rms_height, E=E, nu=nu, n_steps=n_steps, kernel=kernel, solver=solver,
        tol=tol)
    if generator == "rmd":
        surface = rmd_surface(m, fractal_dimension, length, rng=seed, rms_height=rms_height)
    else:
        surface = spectral_surface(_grid_side(generator, m), length,
                                   3.0 - float(fractal_dimension), rms_height=rms_height,
                                   rng=seed)
    sweep = response(surface, material, loading, kernel=kernel, solver=solver, tol=tol)
    return [{"step": k, **record} for k, record in enumerate(sweep.to_records())]


def contact_sweep_inputs(*, generator, fractal_dimension, m, length, rms_height, E, nu,
                         n_steps, kernel, solver, tol):
    """The input check of :func:`contact_sweep_task` (its keywords without ``seed``):
    the generator's parameters, the BEM vocabulary and tolerance checked, the memory of
    the sweep's fields on the generator's grid (:func:`roughfe.bem.memory.check_sweep_memory`),
    and the ``(Material, Loading)`` of the sweep returned; no surface is generated."""
    from ..bem.contact import check_solver_name
    from ..bem.operators import check_kernel_name
    from ..errors import check_finite_positive, check_in_open_interval
    from ..model import Loading, Material
    from ..surfaces.rmd import _check_m

    if generator not in ("rmd", "spectral"):
        raise InputError(f"generator must be 'rmd' or 'spectral', got {generator!r}")
    check_in_open_interval("fractal_dimension D of a surface", fractal_dimension, 2.0, 3.0)
    _check_m(m, grid="2**m + 1" if generator == "rmd" else "2**m")
    check_finite_positive("length (m)", length)
    check_finite_positive("rms_height (m)", rms_height)
    check_in_open_interval("tol (relative KKT residual)", tol, 0.0, 1.0)
    check_solver_name(solver)
    # the kernel on the generator's kind of surface (rmd: non-periodic, spectral:
    # periodic; 2D), by the solver's own rules on a 4 x 4 stand-in
    from ..bem.contact import _choose_kernel, _operator
    from ..surfaces.surface import Surface
    probe = Surface(np.zeros((4, 4)), float(length), periodic=generator == "spectral")
    _operator(probe.shape, probe.size, 1.0, _choose_kernel(probe, check_kernel_name(kernel)))
    material, loading = Material(E, nu), Loading(n_steps=n_steps)
    # the fields the sweep keeps, on the generator's grid (n_steps = 1e8 on m = 2 failed
    # the task on the worker after the study started)
    from ..bem.memory import check_sweep_memory
    check_sweep_memory((_grid_side(generator, m),) * 2, loading.n_steps,
                       periodic=generator == "spectral" and kernel in ("auto", "spectral"))
    return material, loading


def _grid_side(generator, m) -> int:
    """Points per side of :func:`contact_sweep_task`'s surface: 2^m + 1 for ``rmd``
    (:func:`~roughfe.surfaces.rmd_surface`), 2^m for ``spectral`` (one rule for the
    generation and the memory check of :func:`contact_sweep_inputs`)."""
    return 2 ** int(m) + (generator == "rmd")


def genome_db_task(*, gamma, hurst, seed, amplitude=1.0, lambda1=None, label=None,
                   length=_THESIS.length, n_nodes=_THESIS.n_nodes, E=DEFAULT_E,
                   nu=DEFAULT_NU, n_steps=_THESIS.n_steps, threshold=_THESIS.threshold,
                   kernel=_THESIS.kernel):
    """One genome-database entry: the study seed draws the WM phases.

    Calls :func:`roughfe.genomics.database.genome_entry_task` with ``phases=seed`` and
    ``label`` (default :func:`genome_label`: the seed and the genes, so that tasks that
    share a seed through ``seed_from`` but differ in a gene are distinct genomes of a
    database); ``E`` (Pa) and ``nu`` (-) are the material
    (default: the one CLI default :data:`roughfe.model.DEFAULT_E`, 210 MPa, nu = 0; the
    thesis database used E = 1 MPa: give ``E = 1e6``). The full entry (genome, curves,
    chromosome curves, correlations) is stored in the task's result file; the table
    shows its scalars and the macro/micro chromosome lists as JSON text.

    Returns
    -------
    dict
        The database record of ``genome_entry_task``.
    """
    from ..genomics.database import genome_entry_task

    return genome_entry_task(
        gamma, hurst, seed,
        label=label if label is not None else genome_label(seed, gamma, hurst, amplitude,
                                                            lambda1),
        source="study", amplitude=amplitude, lambda1=lambda1, length=length, n_nodes=n_nodes,
        youngs_modulus=E, poisson=nu, n_steps=n_steps, threshold=threshold, kernel=kernel)


def genome_label(seed, gamma, hurst, amplitude=1.0, lambda1=None) -> str:
    """The default database label of a ``genome_db`` task: ``genome-<seed>-gamma<g>-
    hurst<H>``, with ``-amplitude<A>`` and ``-lambda1<l>`` where they are not the defaults
    (1 and None). One label per genome: the seed draws the phases, the rest are genes.
    (Up to analysis version 1 it was ``genome-<seed>``, and tasks sharing a seed shared
    a label: the database kept one of them.)"""
    label = f"genome-{seed}-gamma{gamma!r}-hurst{hurst!r}"
    if amplitude != 1.0:
        label += f"-amplitude{amplitude!r}"
    if lambda1 is not None:
        label += f"-lambda1{lambda1!r}"
    return label


def genome_db_inputs(*, gamma, hurst, amplitude, lambda1, label, length, n_nodes, E, nu,
                     n_steps, threshold, kernel):
    """The input check of :func:`genome_db_task` (its keywords without ``seed``): the
    database settings and the genome of seed 0
    (:func:`~roughfe.genomics.database.task.genome_entry_inputs`); nothing realised or
    solved."""
    from ..genomics.database.task import genome_entry_inputs

    return genome_entry_inputs(gamma, hurst, 0, amplitude=amplitude, lambda1=lambda1,
                               length=length, n_nodes=n_nodes, youngs_modulus=E, poisson=nu,
                               n_steps=n_steps, threshold=threshold, kernel=kernel)


def genome_entry_study_inputs(*, entry, **settings):
    """The input check of :func:`genome_entry_study_task` (its keywords without ``seed``):
    :func:`~roughfe.genomics.database.task.genome_entry_inputs` of the entry (``label``
    and ``source`` aside) and the database settings."""
    from ..genomics.database.task import genome_entry_inputs

    if not isinstance(entry, dict):
        raise InputError(f"entry must be a table of genome_entry_task keywords, "
                         f"got {type(entry).__name__}")
    genes = {k: v for k, v in entry.items() if k not in ("label", "source")}
    return genome_entry_inputs(**genes, **settings)


def genome_entry_study_task(*, entry, seed, length=_THESIS.length, n_nodes=_THESIS.n_nodes,
                            youngs_modulus=_THESIS.youngs_modulus, poisson=_THESIS.poisson,
                            n_steps=_THESIS.n_steps, threshold=_THESIS.threshold,
                            kernel=_THESIS.kernel, stiffness=_THESIS.stiffness,
                            correlation=_THESIS.correlation, dim=_THESIS.dim,
                            top_fraction=_THESIS.top_fraction):
    """One genome-database entry of a given genome (``roughfe db build|extend``).

    Parameters
    ----------
    entry : dict
        Keyword arguments of :func:`roughfe.genomics.database.genome_entry_task` for one
        genome: ``label``, ``source`` and ``gamma``, ``hurst``, ``phases`` (a Sobol
        genome, :func:`~roughfe.genomics.database.sobol_tasks`) or ``genome_json``
        (:func:`~roughfe.genomics.database.extend_tasks`).
    seed : int
        Not used: the genome is given (the runner records it).
    length, n_nodes, youngs_modulus, poisson, n_steps, threshold, kernel, stiffness, correlation, dim, top_fraction
        The :class:`~roughfe.genomics.database.DatabaseSettings` of the database
        (``dim = 2``: a periodic surface database, issue 15).

    Returns
    -------
    dict
        The database record of ``genome_entry_task``.
    """
    from ..genomics.database import genome_entry_task

    return genome_entry_task(**entry, length=length, n_nodes=n_nodes,
                             youngs_modulus=youngs_modulus, poisson=poisson, n_steps=n_steps,
                             threshold=threshold, kernel=kernel, stiffness=stiffness,
                             correlation=correlation, dim=dim, top_fraction=top_fraction)
