"""PETSc/dolfinx helpers shared by every dolfinx solver of roughfe.fem (contact, Reynolds).

Solver options are plain data (dicts) applied under a unique options prefix, so two
solvers in one process never see each other's options (STYLE.md habit 8), and every
solve ends with a check of the converged reason that raises
:class:`~roughfe.errors.NoConvergenceError` naming the PETSc reason.
"""
from __future__ import annotations

import functools
import itertools
import os
import re
import sys
import tempfile
import time
from pathlib import Path
from typing import Mapping

import numpy as np

from ..errors import InputError, NoConvergenceError
from .warning_capture import warnings_back_from_logging

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
        return warnings_back_from_logging()
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    try:
        base.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=base):
            pass
    except OSError:
        os.environ["XDG_CACHE_HOME"] = tempfile.mkdtemp(prefix="roughfe-jit-cache-")
    warnings_back_from_logging()     # ffcx's import hands warnings to logging: undone


def unique_prefix(name: str) -> str:
    """A PETSc options prefix unique in this process, e.g. ``roughfe_vi_3_``."""
    return f"roughfe_{name}_{next(_COUNTER)}_"


@functools.cache
def _petsc_options_used():
    """PETSc's ``PetscOptionsUsed(options, name, &used)`` through ctypes (petsc4py 3.18
    wraps no query of the used flag); the symbol is found through the loaded petsc4py
    extension, which links the PETSc library."""
    import ctypes

    from petsc4py import PETSc

    used = ctypes.CDLL(PETSc.__file__).PetscOptionsUsed
    used.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.POINTER(ctypes.c_int)]
    used.restype = ctypes.c_int
    return used


def option_used(name: str) -> bool:
    """Whether PETSc has read the option ``name`` (with its prefix, without the leading
    ``-``) from the global options database (PETSc marks an option used when any object
    queries it)."""
    import ctypes

    flag = ctypes.c_int(0)
    if _petsc_options_used()(None, name.encode(), ctypes.byref(flag)) != 0:
        raise RuntimeError(f"PetscOptionsUsed failed for the option {name!r}")
    return bool(flag.value)


def _refused_message(options: Mapping, what: str, exc) -> str:
    """InputError text for a PETSc error of ``setFromOptions``: the option(s) whose value
    PETSc's last message line names (else all of them) and that line."""
    lines = [line.split("] ", 1)[-1].strip() for line in str(exc).splitlines()]
    reason = next((line for line in reversed(lines) if line), str(exc))
    bad = {k: v for k, v in options.items()
           if v and re.search(rf"(?<![\w.-]){re.escape(v)}(?![\w.-])", reason)} or options
    given = ", ".join(f"{k}={v!r}" for k, v in bad.items())
    return f"PETSc refused the option(s) {given} of {what}: {reason}"


class PrefixedOptions:
    """PETSc options of one solver object, held in the global options database under a
    unique prefix for the object's life (STYLE.md habit 8).

    ``obj`` (a PETSc SNES, KSP, PC) gets ``prefix`` and reads them in
    ``setFromOptions()``; they stay in the database until :meth:`release` because PETSc
    reads some only at set-up (the MUMPS ``mat_mumps_*`` keys at every factorization,
    the multigrid levels' ``mg_levels_*``): removed right after ``setFromOptions`` they
    were dropped without a word. Values are converted to strings; ``None`` means a flag
    without value. A value PETSc refuses (an unknown type, text for a number) raises
    :class:`~roughfe.errors.InputError` naming the option and its value; after the
    object's first solve, :meth:`check_used` raises one naming the ``checked`` options
    PETSc never read (a misspelled key, or one the chosen types do not use, e.g.
    ``ksp_rtol`` with ``ksp_type preonly``).

    Parameters
    ----------
    obj : petsc4py object with ``setOptionsPrefix`` and ``setFromOptions``
    prefix : str
        From :func:`unique_prefix`.
    options : mapping or None
        Option names without prefix -> values.
    what : str
        The solver's name in messages.
    checked : iterable of str, optional
        The keys :meth:`check_used` requires to be read (default all; the caller's own
        keys, not defaults that a caller's choice of type may leave unused).
    """

    def __init__(self, obj, prefix: str, options: Mapping | None, what: str,
                 checked=None):
        from petsc4py import PETSc

        self.prefix, self.what = prefix, what
        self.options = {str(k): "" if v is None else str(v)
                        for k, v in dict(options or {}).items()}
        self.checked = list(self.options if checked is None else checked)
        self._db = PETSc.Options()
        obj.setOptionsPrefix(prefix)
        for key, value in self.options.items():
            self._db.setValue(f"{prefix}{key}", value)
        try:
            obj.setFromOptions()
        except PETSc.Error as exc:
            message = _refused_message(self.options, what, exc)
            self.release()
            raise InputError(message) from None

    def check_used(self) -> None:
        """Raise InputError naming the checked options PETSc has not read (call after the
        object's first solve, when everything read at set-up has been read)."""
        unused = [k for k in self.checked
                  if k in self.options and not option_used(f"{self.prefix}{k}")]
        self.checked = []                      # once
        if unused:
            raise InputError(
                f"PETSc option(s) {unused} of {self.what} were never read by PETSc: "
                f"misspelled, or not used by the chosen solver types (e.g. ksp_rtol with "
                f"ksp_type preonly); given {dict(self.options)}")

    def set(self, key: str, value) -> None:
        """Hold ``key`` = ``value`` instead (e.g. a type the caller set by hand)."""
        self.options[key] = "" if value is None else str(value)
        self._db.setValue(f"{self.prefix}{key}", self.options[key])

    def release(self) -> None:
        """Remove the options from the database (idempotent)."""
        for key in self.options:
            self._db.delValue(f"{self.prefix}{key}")
        self.options = {}


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


class FreshOnResize:
    """A PETSc ``python`` preconditioner context that builds its inner PC from scratch
    whenever the operator changes size (e.g. ``PCGAMG`` inside SNES ``vinewtonrsls``).

    The VI Newton solver hands its KSP the stiffness restricted to the inactive set, whose
    size changes with the contact set; PETSc 3.18's GAMG then re-uses its coarse levels
    on the new size and stops with error 60 ("Cannot change local size of Amat after use",
    PCSetUp_GAMG -> KSPSetOperators of a level). Here the inner PC (configured by
    ``options``: the ``pc_*``, ``mg_*``, ``mat_*`` keys) is destroyed and created anew when
    the size changes and set up as usual otherwise. After each set-up, every key the inner
    PC read is marked read under ``outer_prefix`` too, so the outer KSP's
    :meth:`PrefixedOptions.check_used` refuses only keys nobody read. Install with
    :func:`fresh_pc_on_resize`.
    """

    def __init__(self, options: Mapping, outer_prefix: str = ""):
        self.options = dict(options)
        self.outer_prefix = outer_prefix
        self.inner = self.inner_options = None
        self.size = None

    def setUp(self, pc):                       # noqa: N802 (petsc4py's name)
        from petsc4py import PETSc

        A, P = pc.getOperators()
        if self.inner is None or P.getSize() != self.size:
            self.destroy(pc)
            self.inner = PETSc.PC().create(pc.getComm())
            self.inner.setOperators(A, P)
            self.inner_options = PrefixedOptions(self.inner, unique_prefix("inner"),
                                                 self.options, "the rebuilt preconditioner")
            self.size = P.getSize()
        else:
            self.inner.setOperators(A, P)
        self.inner.setUp()
        for key in self.options:              # (mg_* and mat_* are read at set-up)
            if option_used(f"{self.inner_options.prefix}{key}"):   # hasName marks it read
                PETSc.Options().hasName(f"{self.outer_prefix}{key}")

    def apply(self, pc, x, y):
        self.inner.apply(x, y)

    def destroy(self, pc):
        if self.inner is not None:
            self.inner.destroy()
            self.inner_options.release()
            self.inner = self.inner_options = None


def fresh_pc_on_resize(ksp, options: PrefixedOptions) -> None:
    """Give ``ksp`` a :class:`FreshOnResize` preconditioner built from every key of its
    ``options`` but the KSP's own ``ksp_*`` (``pc_*``, the multigrid levels' ``mg_*``,
    ``mat_*``); those the inner PC reads count as read by ``options``.

    The held ``pc_type`` becomes ``python`` as well: the VI solver resets its KSP from the
    options database whenever the active set changes (``KSPResetFromOptions``), which
    would otherwise turn the PC back into the inner type.
    """
    pc = ksp.getPC()
    inner = {k: v for k, v in options.options.items() if not k.startswith("ksp_")}
    pc.setType("python")
    pc.setPythonContext(FreshOnResize(inner, options.prefix))
    options.set("pc_type", "python")


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


#: Fewest iterations a solve with a kept preconditioner is allowed before
#: :class:`KrylovSolver` builds a fresh one (otherwise: 2 more than the solve that built it).
REUSE_MIN_IT = 8


class KrylovSolver:
    """A PETSc KSP for a sequence of linear systems, optionally keeping its preconditioner.

    With ``reuse_preconditioner=True`` a system whose matrix has the size and the sparsity
    pattern of the one the preconditioner was built on (e.g. the Reynolds operator of
    every iteration of a fluid-structure coupling loop, whose gap changes a little) is
    solved with that preconditioner (an AMG hierarchy is not set up again): the Krylov
    iteration runs on the new matrix, so the answer meets the same tolerance; only the
    iteration count can grow. A solve that has not converged with a kept preconditioner
    after 2 iterations more than the solve that built it took (at least ``reuse_min_it``)
    builds a fresh one on its matrix and continues from its last iterate (the stopping
    test stays relative to the right-hand side), so a poor kept hierarchy costs at most
    that many iterations. Measured on the 23 Reynolds solves of a 256^2 coupling loop
    (every solve against every kept hierarchy): the hierarchies of the first 2-3 solves
    fit no later matrix (hundreds of iterations), those built later give the fresh
    iteration count to +-1; this rule builds 6 hierarchies instead of 23 (20 % fewer
    CG-iteration equivalents, a set-up costing ~9 iterations).

    Parameters
    ----------
    name : str
        Options prefix stem and the name in messages.
    options : mapping, optional
        PETSc options overriding ``defaults``; a value PETSc refuses raises InputError,
        and so does, after the first solve, a key PETSc never read (a misspelling, or a
        key the chosen types do not use; :class:`PrefixedOptions`).
    reuse_preconditioner : bool
        Keep the preconditioner across solves with an unchanged sparsity pattern.
    reuse_min_it : int
        Iterations always allowed with a kept preconditioner before it is rebuilt.
    defaults : mapping
        The solver's own options (default :data:`CG_AMG`), not checked for use (a
        ``pc_type`` in ``options`` leaves e.g. ``pc_hypre_type`` unread).

    Attributes
    ----------
    setups : int
        Preconditioner set-ups so far.
    reason : int
        PETSc converged reason of the last solve (``PETSc.KSP.ConvergedReason``; 0 before).
    """

    def __init__(self, name: str, options: Mapping | None = None, *,
                 reuse_preconditioner: bool = False, reuse_min_it: int = REUSE_MIN_IT,
                 defaults: Mapping = CG_AMG):
        from petsc4py import PETSc

        self.name = name
        self.reuse = bool(reuse_preconditioner)
        self.reuse_min_it = int(reuse_min_it)
        self.setups = self.reason = 0
        self._cap = self.reuse_min_it
        self._ksp = PETSc.KSP().create(PETSc.COMM_SELF)
        options = dict(options or {})
        try:
            self._options = PrefixedOptions(self._ksp, unique_prefix(name),
                                            {**defaults, **options}, f"the {name} KSP",
                                            checked=options)
        except InputError:
            self._ksp.destroy()
            raise
        self._rtol, _, _, self._max_it = self._ksp.getTolerances()
        self._A = self._own = self._pattern = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self) -> None:
        """Destroy the KSP (and the last matrix if the solver owns it)."""
        self._release()
        self._ksp.destroy()
        self._options.release()

    def _release(self):
        if self._own and self._A is not None:
            self._A.destroy()
        self._A = None

    @property
    def types(self) -> str:
        """KSP and PC type, e.g. ``"cg/hypre"`` (``"preonly/lu"``: a direct solve)."""
        return f"{self._ksp.getType()}/{self._ksp.getPC().getType()}"

    @property
    def rtol(self) -> float:
        """The relative tolerance of a solve (its options' ``ksp_rtol``)."""
        return self._rtol

    def solve(self, matrix, rhs, x0=None, *, own: bool = False, rtol: float | None = None):
        """Solve ``A x = b``; see :func:`ksp_solve` for the arguments and the return value.

        ``own=True`` hands the PETSc matrix to the solver, which destroys it when the next
        matrix arrives or at :meth:`close` (a scipy matrix is always copied and owned).
        ``rtol`` replaces the relative tolerance for this solve only. The matrix of the
        previous solve again (unchanged, e.g. a continuation from its answer to a tighter
        ``rtol``) keeps its preconditioner and its owner.
        """
        from petsc4py import PETSc

        same = matrix is self._A
        if not isinstance(matrix, PETSc.Mat):
            matrix, own = petsc_aij(matrix), True
        pattern = None
        if self.reuse and not same:
            indptr, indices, _ = matrix.getValuesCSR()
            pattern = (matrix.getSize(), indptr, indices)
        keep = same or (self.reuse and self._pattern is not None
                        and pattern[0] == self._pattern[0]
                        and np.array_equal(pattern[1], self._pattern[1])
                        and np.array_equal(pattern[2], self._pattern[2]))
        ksp, pc = self._ksp, self._ksp.getPC()
        if not same:
            if self._A is not None and matrix.getSize() != self._A.getSize():
                ksp.reset()                    # PETSc refuses new sizes on a used KSP
            pc.setReusePreconditioner(keep)
            ksp.setOperators(matrix)
            self._release()
            self._A, self._own = matrix, own
        b = matrix.createVecLeft()
        b.setArray(np.asarray(rhs, dtype=PETSc.ScalarType))
        x = matrix.createVecRight()
        if ksp.getType() == "preonly":         # a direct solve: no start (PETSc refuses one)
            x0 = None
        if x0 is not None:
            x.setArray(np.asarray(x0, dtype=PETSc.ScalarType))
        ksp.setInitialGuessNonzero(x0 is not None)
        ksp.setTolerances(rtol=self._rtol if rtol is None else float(rtol),
                          max_it=min(self._cap, self._max_it) if keep and not same
                          else self._max_it)
        t0 = time.process_time()
        ksp.setUp()
        t1 = time.process_time()
        ksp.solve(b, x)
        self._options.check_used()             # (after the first set-up; then a no-op)
        nit = int(ksp.getIterationNumber())
        kept = keep
        failed = ksp.getConvergedReason()
        if keep and not same and failed < 0:
            # the kept hierarchy no longer fits (a cell of the Reynolds film opening or
            # closing changes its conductance by ~1e9 on the same pattern): build one on
            # this matrix. After a stall (DIVERGED_MAX_IT) go on from x; after any other
            # failure (DIVERGED_DTOL, an indefinite preconditioner) x is garbage: restart
            # from the caller's start
            pc.setReusePreconditioner(False)
            if failed != PETSc.KSP.ConvergedReason.DIVERGED_MAX_IT:
                if x0 is not None:
                    x.setArray(np.asarray(x0, dtype=PETSc.ScalarType))
                else:
                    x.set(0.0)
            ksp.setInitialGuessNonzero(
                x0 is not None or failed == PETSc.KSP.ConvergedReason.DIVERGED_MAX_IT)
            ksp.setTolerances(max_it=self._max_it)
            t1 -= time.process_time()
            pc.setUp()                         # (the KSP counts itself set up)
            t1 += time.process_time()
            ksp.solve(b, x)
            built = int(ksp.getIterationNumber())
            nit += built
            keep = False
        t2 = time.process_time()
        if not keep:
            self.setups += 1
            self._pattern = pattern
            self._cap = max((built if kept else nit) + 2, self.reuse_min_it)
        reason = self.reason = int(ksp.getConvergedReason())
        message = (f"KSP {ksp.getType()}/{pc.getType()} "
                   f"{reason_name(PETSc.KSP.ConvergedReason, reason)} in {nit} iterations, "
                   f"residual norm {ksp.getResidualNorm():.3e}, "
                   f"set-up {t1 - t0:.3g} s + solve {t2 - t1:.3g} s CPU"
                   + (", kept preconditioner" if keep else
                      ", preconditioner rebuilt after the kept one failed" if kept else ""))
        out = x.array.copy()
        x.destroy()
        b.destroy()
        return out, nit, reason > 0, message


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
        iterations when ``x0`` is close. Ignored by ``ksp_type preonly`` (a direct solve).

    Returns
    -------
    (ndarray, int, bool, str)
        Solution, iterations, converged flag and a one-line report (KSP/PC type, PETSc
        converged reason, iterations, residual norm, process CPU time of the
        preconditioner set-up and of the iterations).
    """
    with KrylovSolver(name, options) as solver:
        return solver.solve(matrix, rhs, x0)
