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
import time
from pathlib import Path
from typing import Mapping

import numpy as np

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


#: CG + BoomerAMG (hypre): the default for the symmetric positive definite Reynolds
#: systems (FE and FV). rtol 1e-10 relative to the right-hand side.
CG_AMG = {"ksp_type": "cg", "pc_type": "hypre", "pc_hypre_type": "boomeramg",
          "ksp_rtol": 1e-10, "ksp_atol": 0.0, "ksp_max_it": 2000}


def petsc_aij(matrix):
    """A scipy sparse matrix as a sequential PETSc AIJ matrix (values copied)."""
    from petsc4py import PETSc

    m = matrix.tocsr()
    m.sort_indices()
    return PETSc.Mat().createAIJ(
        size=m.shape, csr=(m.indptr.astype(PETSc.IntType, copy=False),
                           m.indices.astype(PETSc.IntType, copy=False),
                           m.data.astype(PETSc.ScalarType, copy=False)), comm=PETSc.COMM_SELF)


def petsc_aij_csr(shape, indptr, indices, data):
    """A sequential PETSc AIJ matrix on CSR arrays (rows with sorted column indices).

    The arrays are used in place when their types are PETSc's (``PetscInt``, ``PetscScalar``),
    else converted once; the matrix keeps a reference to them.
    """
    from petsc4py import PETSc

    return PETSc.Mat().createAIJWithArrays(
        shape, (np.asarray(indptr, dtype=PETSc.IntType), np.asarray(indices, dtype=PETSc.IntType),
                np.asarray(data, dtype=PETSc.ScalarType)), comm=PETSc.COMM_SELF)


def ksp_solve(matrix, rhs, *, name: str, options: Mapping | None = None, x0=None):
    """Solve ``A x = b`` with a PETSc KSP; options under a unique prefix.

    Parameters
    ----------
    matrix : petsc4py.PETSc.Mat or scipy.sparse matrix
        The operator (a scipy matrix is copied into PETSc AIJ and destroyed afterwards).
    rhs : ndarray
        Right-hand side.
    name : str
        Options prefix stem and the name in messages.
    options : mapping, optional
        PETSc options overriding :data:`CG_AMG`.
    x0 : ndarray, optional
        Initial guess (a nonzero start of the Krylov iteration). The stopping test stays
        PETSc's default, relative to the norm of the (preconditioned) right-hand side,
        not to the initial residual: the same accuracy as from x = 0, in fewer
        iterations when ``x0`` is close.

    Returns
    -------
    (ndarray, int, bool, str)
        Solution, iterations, converged flag and a one-line report (KSP/PC type, PETSc
        converged reason, iterations, residual norm, process CPU time of the
        preconditioner set-up and of the iterations).
    """
    from petsc4py import PETSc

    own = not isinstance(matrix, PETSc.Mat)
    A = petsc_aij(matrix) if own else matrix
    b = A.createVecLeft()
    b.setArray(np.asarray(rhs, dtype=PETSc.ScalarType))
    x = A.createVecRight()
    ksp = PETSc.KSP().create(PETSc.COMM_SELF)
    ksp.setOperators(A)
    apply_options(ksp, unique_prefix(name), {**CG_AMG, **dict(options or {})})
    if x0 is not None:
        x.setArray(np.asarray(x0, dtype=PETSc.ScalarType))
        ksp.setInitialGuessNonzero(True)
    t0 = time.process_time()
    ksp.setUp()
    t1 = time.process_time()
    ksp.solve(b, x)
    t2 = time.process_time()
    reason = ksp.getConvergedReason()
    nit = int(ksp.getIterationNumber())
    message = (f"KSP {ksp.getType()}/{ksp.getPC().getType()} "
               f"{reason_name(PETSc.KSP.ConvergedReason, reason)} in {nit} iterations, "
               f"residual norm {ksp.getResidualNorm():.3e}, "
               f"set-up {t1 - t0:.3g} s + solve {t2 - t1:.3g} s CPU")
    out = x.array.copy()
    for obj in (ksp, x, b) + ((A,) if own else ()):
        obj.destroy()
    return out, nit, reason > 0, message
