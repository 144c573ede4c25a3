"""Per-step checkpoints of a FEM sweep: resume an interrupted load stepping where it stopped.

:func:`roughfe.fem.fem_contact_sweep` with ``checkpoint=path`` writes, after every finished
step, one ``.npz`` file (arrays only, never a pickle) through
:func:`roughfe.writers.atomic_path` (a temporary file renamed onto ``path``, mode
``0o666 & ~umask``: an interrupted write leaves the previous checkpoint, never a partial
one). It holds

* every field of the finished steps' :class:`roughfe.model.ContactResult`, exactly;
* the state the next step starts from: the body's displacement vector (non-dimensional,
  in the DOF order of its mesh) and the last mean pressure (Pa, the half-plane Newton's
  start);
* the identity of the sweep: control (``pressures``, ``deltas`` or ``applied_deltas``) and
  values, the start guesses, the kept steps, material, solver options, the profile
  (SHA-256 of its heights; width, depth, formulation) and the DOF layout (SHA-256 of the
  DOF coordinates and the cell-to-DOF map), and the CPU seconds spent on the finished
  steps.

Every step of a sweep starts its Newton from the previous step's displacement (a warm
start; the contact problem has one solution, but the iterates, and so the last bits and
the SNES iteration counts, depend on the start). With that state restored a resumed sweep
takes the uninterrupted sweep's iterations: its results are equal bit for bit
(``tests/test_fem_checkpoint.py``). A file that does not belong to the sweep (other loads,
mesh, material, options, or not a checkpoint) is not used: the sweep starts from its first
step and overwrites it. The sweep leaves the file in place; its caller deletes it once
the results are stored. Serial only.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import time
import zipfile
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..model import ContactResult
from ..writers import atomic_path

#: Format of the file; a checkpoint of another version is not used.
VERSION = 1
_KINDS = ("array", "scalar", "tuple", "mapping", "none")


def _entries(k: int, result: ContactResult) -> dict:
    """The ``.npz`` entries of step ``k``: ``s<k>:<kind>:<field>[:<key>]`` -> array."""
    out = {}
    for f in dataclasses.fields(ContactResult):
        if not f.init:
            continue
        value = getattr(result, f.name)
        if value is None:
            out[f"s{k}:none:{f.name}"] = np.zeros(0)
        elif isinstance(value, Mapping):
            out.update({f"s{k}:mapping:{f.name}:{key}": np.asarray(v)
                        for key, v in value.items()})
        else:
            kind = ("array" if isinstance(value, np.ndarray)
                    else "tuple" if isinstance(value, tuple) else "scalar")
            out[f"s{k}:{kind}:{f.name}"] = np.asarray(value)
    return out


def _value(array: np.ndarray):
    """A stored array back as the value it was: 0-d -> Python scalar, else the array."""
    return array.item() if array.ndim == 0 else array


def _results(data, n: int) -> list:
    """The ``n`` ContactResult of the entries :func:`_entries` wrote."""
    fields = [{} for _ in range(n)]
    for name in data.files:
        step, kind, *rest = name.split(":") + [""]
        if not step.startswith("s") or kind not in _KINDS:
            continue
        k, array = int(step[1:]), data[name]
        if kind == "mapping":
            fields[k].setdefault(rest[0], {})[rest[1]] = _value(array)
        elif kind == "none":
            fields[k][rest[0]] = None
        else:
            fields[k][rest[0]] = (tuple(array.tolist()) if kind == "tuple"
                                  else array if kind == "array" else array.item())
    return [ContactResult(**f) for f in fields]


def layout_digest(V) -> str:
    """SHA-256 of a dolfinx function space's DOF layout: its DOF coordinates and its
    cell-to-DOF map (a displacement vector is meaningful only in that layout)."""
    h = hashlib.sha256()
    h.update(np.ascontiguousarray(V.tabulate_dof_coordinates()).tobytes())
    h.update(np.ascontiguousarray(V.dofmap.list.array).tobytes())
    return h.hexdigest()


def sweep_key(problem, control: str, values, guesses, keep) -> str:
    """The identity of a sweep (JSON text; floats exact): what its results depend on (the
    profile's heights and the body's size too: the mesh of a ``"flat"`` body does not
    depend on the heights, and its coordinates are in units of W)."""
    pm = problem.pmesh
    options = dataclasses.asdict(problem.options)
    options["petsc_options"] = dict(problem.options.petsc_options or {})
    heights = hashlib.sha256(np.ascontiguousarray(pm.heights, dtype=float).tobytes())
    return json.dumps({
        "version": VERSION, "control": control, "values": np.asarray(values).tolist(),
        "guesses": None if guesses is None else np.asarray(guesses).tolist(),
        "keep": sorted(keep), "material": [problem.material.E, problem.material.nu],
        "options": options, "n_dofs": int(problem.x.getSize()),
        "body": [heights.hexdigest(), float(pm.width), float(pm.depth),
                 float(pm.length_scale), pm.formulation],
        "layout": layout_digest(problem.V)}, sort_keys=True, default=str)


class SweepCheckpoint:
    """The checkpoint file of one sweep (see the module docstring).

    After :func:`roughfe.fem.fem_contact_sweep` returns (or raises), ``resumed_steps``
    is the number of steps taken from the file (0: none), ``resumed_cpu_seconds`` the CPU
    seconds the earlier runs spent on them, and ``not_used`` why an existing file was
    not used (None when it was, or when there was none).
    """

    def __init__(self, path):
        try:
            self.path = Path(path)
        except TypeError:
            raise InputError(f"checkpoint must be a file path (.npz) or a SweepCheckpoint, "
                             f"got {path!r}") from None
        self.resumed_steps, self.resumed_cpu_seconds, self.not_used = 0, 0.0, None
        self._start = time.process_time()

    def restore(self, problem, key: str) -> list:
        """The finished steps of the file, with ``problem`` set to the state after the
        last of them; [] (``problem`` untouched) when the file is missing or not this
        sweep's."""
        if problem.K.getComm().size > 1:
            raise InputError("checkpoint: a FEM sweep is checkpointed in serial runs only, "
                             f"got {problem.K.getComm().size} MPI processes")
        self.resumed_steps, self.resumed_cpu_seconds, self.not_used = 0, 0.0, None
        self._start = time.process_time()
        if not self.path.is_file():
            return []
        try:
            with np.load(self.path, allow_pickle=False) as data:
                if str(data["key"].item()) != key:
                    self.not_used = "it belongs to another sweep (loads, mesh or options)"
                    return []
                n = int(data["steps"])
                x, last_pressure = data["x"], float(data["last_pressure"])
                results, cpu = _results(data, n), float(data["cpu_seconds"])
        except (OSError, ValueError, KeyError, TypeError, zipfile.BadZipFile) as exc:
            self.not_used = f"it is not a readable checkpoint ({exc})"
            return []
        if x.shape != problem.x.array.shape:
            self.not_used = f"its state has {x.size} DOFs, the mesh {problem.x.array.size}"
            return []
        problem.x.array[:] = x
        problem.last_pressure = last_pressure
        self.resumed_steps, self.resumed_cpu_seconds = n, cpu
        return results

    def save(self, problem, key: str, results) -> Path:
        """Write the finished ``results`` and the state of ``problem`` after the last."""
        arrays = {"key": np.asarray(key), "steps": np.asarray(len(results)),
                  "x": np.array(problem.x.array_r), "last_pressure":
                  np.asarray(float(problem.last_pressure)),
                  "cpu_seconds": np.asarray(self.resumed_cpu_seconds
                                            + time.process_time() - self._start)}
        for k, r in enumerate(results):
            arrays.update(_entries(k, r))
        with atomic_path(self.path) as tmp, open(tmp, "wb") as fh:
            np.savez(fh, **arrays)
        return self.path
