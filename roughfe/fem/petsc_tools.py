"""PETSc/dolfinx helpers shared by every dolfinx solver of roughfe.fem (contact, Reynolds).

Solver options are plain data (dicts) applied under a unique options prefix, so two
solvers in one process never see each other's options (STYLE.md habit 8), and every
solve ends with a check of the converged reason that raises
:class:`~roughfe.errors.NoConvergenceError` naming the PETSc reason.
"""
from __future__ import annotations

import itertools
import os
import sys
import tempfile
from pathlib import Path
from typing import Mapping

from ..errors import NoConvergenceError

_COUNTER = itertools.count()

#: Direct solve with MUMPS (superlu_dist crashed inside the SNES VI with PETSc error 98).
LU_MUMPS = {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}


def ensure_jit_cache() -> None:
    """Point ``XDG_CACHE_HOME`` to a temporary folder if the default cache is not writable.

    dolfinx compiles forms into ``$XDG_CACHE_HOME/fenics`` (default ``~/.cache``) and reads
    the location when it is first imported, so call this before importing dolfinx.
    Nothing is changed when the cache is writable or dolfinx is already loaded.
    """
    if "dolfinx" in sys.modules:
        return
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    try:
        base.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=base):
            pass
    except OSError:
        os.environ["XDG_CACHE_HOME"] = tempfile.mkdtemp(prefix="roughfe-jit-cache-")


def unique_prefix(name: str) -> str:
    """A PETSc options prefix unique in this process, e.g. ``roughfe_vi_3_``."""
    return f"roughfe_{name}_{next(_COUNTER)}_"


def apply_options(obj, prefix: str, options: Mapping | None) -> None:
    """Set ``options`` under ``prefix``, call ``obj.setFromOptions()``, remove them again.

    ``obj`` is a PETSc SNES, KSP or similar. Values are converted to strings; ``None``
    means a flag without value. The global options database is left as it was.
    """
    from petsc4py import PETSc

    options = dict(options or {})
    db = PETSc.Options()
    obj.setOptionsPrefix(prefix)
    for key, value in options.items():
        db.setValue(f"{prefix}{key}", "" if value is None else str(value))
    try:
        obj.setFromOptions()
    finally:
        for key in options:
            db.delValue(f"{prefix}{key}")


def reason_name(cls, reason: int) -> str:
    """Name of a PETSc converged reason (``cls`` is e.g. ``PETSc.SNES.ConvergedReason``)."""
    for name in dir(cls):
        if not name.startswith("_") and getattr(cls, name) == reason:
            return name
    return f"reason {reason}"


def check_snes(snes, what: str, result=None) -> int:
    """Return the SNES iteration count; raise NoConvergenceError if it did not converge.

    The message names the SNES converged reason (e.g. ``DIVERGED_MAX_IT``), the
    iterations and the final residual norm, and ``what`` was being solved.
    """
    from petsc4py import PETSc

    reason = snes.getConvergedReason()
    nit = snes.getIterationNumber()
    if reason <= 0:
        name = reason_name(PETSc.SNES.ConvergedReason, reason)
        raise NoConvergenceError(
            f"{what}: PETSc SNES did not converge: reason {name} ({reason}) after {nit} "
            f"iterations, residual norm {snes.getFunctionNorm():.3e}", result=result)
    return nit
