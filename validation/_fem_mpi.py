"""The MPI check of ``validation/bem_vs_fem.py``: the same small FEM sweep (Westergaard,
129 nodes) serially and with ``mpirun -n 2`` must give the same p, A* and K. A helper
module of the study, not a study of its own.
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np

from _fem_cases import rel_diff


_MPI_SCRIPT = """
import json, sys
import numpy as np
from mpi4py import MPI
from roughfe.bem import Material
from roughfe.fem import fem_contact_sweep, mesh_profile
from roughfe.surfaces import Surface
n, lam, g = 129, 1e-3, 1e-6
dx = lam / 2 / (n - 1)
x = np.arange(n) * dx
pm = mesh_profile(Surface(g * np.cos(2 * np.pi * x / lam), n * dx), growth=0.1)
sw = fem_contact_sweep(pm, Material(E=210e9, nu=0.3), applied_deltas=np.array([1.0, 2.0, 3.0]) * g)
if MPI.COMM_WORLD.rank == 0:
    print(json.dumps({"p": sw.mean_pressure.tolist(), "A": sw.area_fraction.tolist(),
                      "K": sw.stiffness.tolist(), "ranks": MPI.COMM_WORLD.size}))
"""


def mpi_case():
    """Run the same small FEM sweep serially and with ``mpirun -n 2``; max relative diff.

    Each run reports its ``MPI.COMM_WORLD.size``: a launcher that starts two singletons
    (an mpi4py built against another MPI) gives two serial runs, equal to the serial one
    by construction; such a run does not count as the check (not met, said why)."""
    mpirun = shutil.which("mpirun")
    if mpirun is None:
        return {"ok": None, "note": "mpirun not found on PATH: the MPI check did not run "
                                    "(it needs an MPI launcher)"}
    env = dict(os.environ, OMPI_MCA_rmaps_base_oversubscribe="1")
    root = str(Path(__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join([root, env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    out = {}
    for ranks in (1, 2):
        cmd = [sys.executable, "-c", _MPI_SCRIPT]
        if ranks > 1:
            cmd = [mpirun, "--allow-run-as-root", "-n", str(ranks), *cmd]
        proc = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)
        lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("{")]
        if proc.returncode != 0 or not lines:
            return {"ok": False, "note": f"{ranks} rank(s) failed: {proc.stderr[-500:]}"}
        out[ranks] = json.loads(lines[-1])
        if out[ranks].get("ranks") != ranks:
            return {"ok": False, "note": f"mpirun -n {ranks} ran on {out[ranks].get('ranks')} "
                                         f"rank(s): not a parallel run (mpi4py and mpirun "
                                         f"of different MPIs?)", "serial": out.get(1)}
    diff = max(float(np.max(rel_diff(out[2][k], out[1][k]))) for k in ("p", "A", "K"))
    return {"ok": diff < 1e-8, "max_rel_diff": diff, "serial": out[1], "two_ranks": out[2]}
