"""The distributed (MPI) periodic BEM solve, roughfe.bem.distributed: slab-decomposed FFT
products equal to the serial operator's, the 2-rank and 1-rank solves equal to the
serial solve_contact, slabs read from a memory-mapped .npy, and the refusals.

The MPI checks run one ``mpirun -n 2`` script (skipped without mpirun or mpi4py; this
process never imports mpi4py: MPI_Init here would leak OMPI_* variables to mpirun, as
tests/test_study_runner.py notes). Budget: a few seconds.
"""
import importlib.util
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from roughfe.bem.operators import influence_operator, periodic_spectrum
from roughfe.bem.pk import polonsky_keer
from roughfe.bem.reductions import CommReductions
from roughfe.bem.slab_fft import even_splits, slab_rows
from roughfe.errors import InputError

ROOT = Path(__file__).resolve().parents[1]

SCRIPT = r'''
import json, sys
import numpy as np
from mpi4py import MPI
from roughfe.bem import Material, solve_contact
from roughfe.bem.distributed import read_slab, solve_contact_distributed
from roughfe.bem.operators import influence_operator
from roughfe.bem.slab_fft import SlabOperator
from roughfe.errors import InputError
from roughfe.surfaces import Surface
from roughfe.surfaces.spectral import spectral_surface

world = MPI.COMM_WORLD
out = {"ranks": world.gather(world.Get_size(), root=0)}
# products: an even and an uneven split (45 rows, 20 half-spectrum columns on 2 ranks)
errors = []
for shape, size in (((64, 64), (1.0, 1.0)), ((45, 38), (2e-3, 1.5e-3))):
    x = np.random.default_rng(3).standard_normal(shape) * 1e6
    op = influence_operator(shape, size, 2e9)
    slab = SlabOperator(world, shape, size, 2e9)
    a, b = slab.rows
    u, m = slab.apply(x[a:b]), slab.precondition(x[a:b])
    ru, rm = op.apply(x), op.precondition(x, op.inverse_spectrum())
    errors.append([float(np.abs(u - ru[a:b]).max() / np.abs(ru).max()),
                   float(np.abs(m - rm[a:b]).max() / np.abs(rm).max()), slab.rows])
out["products"] = world.gather(errors, root=0)

surf = spectral_surface(64, 1e-3, 0.8, rms_slope=0.1, rng=4)
np.save(sys.argv[1], surf.heights) if world.rank == 0 else None
world.Barrier()
h, shape, rows = read_slab(sys.argv[1], world)
out["slab"] = world.gather(bool(np.array_equal(h, surf.heights[rows[0]:rows[1]])), root=0)
pm, e_star = 0.02 * 1e9, 1e9
serial = solve_contact(surf, Material(E=e_star, nu=0.0), mean_pressure=pm, tol=1e-10,
                       compute_stiffness=False)
pmax = float(serial.pressure.max())
for name, comm in (("two", world), ("one", MPI.COMM_SELF)):
    r0, r1 = (rows if comm is world else (0, 64))
    r = solve_contact_distributed(surf.heights[r0:r1], shape, surf.size, e_star, pm, comm,
                                  tol=1e-10)
    dp = world.allreduce(float(np.abs(r.pressure - serial.pressure[r0:r1]).max()),
                         op=MPI.MAX)
    dg = world.allreduce(float(np.abs(r.gap - serial.gap[r0:r1]).max()), op=MPI.MAX)
    out[name] = {"A": r.area_fraction, "gap": r.mean_gap, "pm": r.mean_pressure,
                 "delta": r.delta, "dp": dp / pmax, "dgap": dg, "nit": r.nit,
                 "products": r.n_products, "residual": r.residual, "ranks": r.ranks,
                 "rows": r.rows, "shape": list(r.shape)}
out["serial"] = {"A": serial.area_fraction, "gap": serial.mean_gap, "delta": serial.delta,
                 "rms": serial.rms_height}
try:
    solve_contact_distributed(h[1:], shape, surf.size, e_star, pm, world)
except InputError as exc:
    out["refused"] = str(exc)
if world.rank == 0:
    print(json.dumps(out))
'''


def _mpirun():
    exe = shutil.which("mpirun")
    if exe is None:
        pytest.skip("mpirun is not installed")
    if importlib.util.find_spec("mpi4py") is None:   # not imported here (module docstring)
        pytest.skip("mpi4py is not installed")
    return exe


@pytest.fixture(scope="module")
def two_ranks(tmp_path_factory):
    exe = _mpirun()
    tmp = tmp_path_factory.mktemp("mpi")
    (tmp / "run.py").write_text(SCRIPT)
    env = dict(os.environ, OMPI_MCA_rmaps_base_oversubscribe="1", ROUGHFE_THREADS="1",
               OMPI_MCA_mpi_yield_when_idle="1")   # a waiting rank yields its core
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")]).rstrip(
        os.pathsep)
    proc = subprocess.run([exe, "--allow-run-as-root", "-n", "2", sys.executable,
                           str(tmp / "run.py"), str(tmp / "h.npy")], capture_output=True,
                          text=True, timeout=300, env=env, cwd=tmp)
    assert proc.returncode == 0, proc.stderr[-3000:]
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("{")]
    assert len(lines) == 1, proc.stdout[-2000:]   # two singletons would print two lines
    return json.loads(lines[0])


def test_each_rank_runs_in_a_two_rank_world(two_ranks):
    # a launcher that starts two singletons (an mpi4py of another MPI) reports [1] / 1
    assert two_ranks["ranks"] == [2, 2]
    assert two_ranks["two"]["ranks"] == 2 and two_ranks["one"]["ranks"] == 1


def test_the_slab_products_are_the_serial_operators(two_ranks):
    # H p and M g of a random field on an even (64^2) and an uneven (45 x 38: rows 23/22,
    # half-spectrum columns 10/10) split: the same per-line transforms as the serial
    # rfftn, so equal to rounding (measured: 0); 1e-12 of max |u| allowed
    per_rank = two_ranks["products"]
    assert [[rows for _, _, rows in r] for r in per_rank] == [[[0, 32], [0, 23]],
                                                                [[32, 64], [23, 45]]]
    for rank in per_rank:
        for du, dm, _ in rank:
            assert du <= 1e-12 and dm <= 1e-12


def test_a_rank_reads_only_its_rows_of_the_file(two_ranks):
    assert two_ranks["slab"] == [True, True]


@pytest.mark.parametrize("run", ["two", "one"])
def test_the_distributed_solve_is_the_serial_solve(two_ranks, run):
    # both solve Eq. 2.5-2.6 to a KKT residual of 1e-10 (the serial one from its coarse
    # start with its float32 products early): the same contact set and mean gap, the
    # pressures equal to the tolerance's level (measured 3.2e-11 of max p here, 64^2)
    r, s = two_ranks[run], two_ranks["serial"]
    assert r["residual"] <= 1e-10
    assert r["A"] == s["A"]
    assert abs(r["gap"] - s["gap"]) <= 1e-8 * s["gap"]           # m
    assert abs(r["delta"] - s["delta"]) <= 1e-8 * s["delta"]     # m
    assert abs(r["pm"] - 0.02e9) <= 1e-12 * 0.02e9                # Pa
    assert r["dp"] <= 1e-8 and r["dgap"] <= 1e-8 * s["rms"]
    assert r["shape"] == [64, 64] and r["products"] >= 2 * r["nit"]


def test_both_decompositions_take_the_same_iterations(two_ranks):
    # the reductions are global: the rank count changes only their rounding
    assert two_ranks["two"]["nit"] == two_ranks["one"]["nit"]
    assert two_ranks["two"]["rows"] in ([0, 32], [32, 64])   # rank 0's (printed) rows


def test_a_slab_of_the_wrong_shape_is_refused(two_ranks):
    assert "rows 0..31" in two_ranks["refused"] and "(32, 64)" in two_ranks["refused"]


# -- without MPI -----------------------------------------------------------------------
def test_uneven_splits_and_too_many_ranks():
    assert even_splits(7, 3) == [(0, 3), (3, 5), (5, 7)]
    assert slab_rows((45, 38), 2, 1) == (23, 45)
    with pytest.raises(InputError, match="3 rows .* over 4 MPI ranks"):
        even_splits(3, 4)
    # 40 rows but a half-spectrum of 2 columns (n1 = 3): 3 ranks cannot share it
    with pytest.raises(InputError, match="2 rows \\(or half-spectrum columns\\)"):
        slab_rows((40, 3), 3, 0)
    with pytest.raises(InputError, match="2D grid shape"):
        slab_rows((64,), 2, 0)


def test_a_column_slab_of_the_multiplier_is_the_operators():
    op = influence_operator((12, 10), (1e-3, 2e-3), 3e9)
    cols = slice(2, 5)
    np.testing.assert_array_equal(periodic_spectrum((12, 10), (1e-3, 2e-3), 3e9, cols),
                                  op.spectrum[:, cols])
    assert op.spectrum[0, 0] == 0.0 and op.inverse_spectrum()[0, 0] == 0.0


class _NoComm:
    """Stands for a communicator the refusals never reach."""

    def allreduce(self, *args, **kwargs):     # pragma: no cover - must not be called
        raise AssertionError("a refused solve communicated")


@pytest.mark.parametrize("kw, said", [({"hardness": 1.0}, "a hardness"),
                                      ({"delta": 0.0, "mean_pressure": None},
                                       "displacement control"),
                                      ({"precond": None}, "no preconditioner"),
                                      ({"deflation": object()}, "a deflation")])
def test_the_distributed_solver_refuses_what_it_does_not_run(kw, said):
    args = {"mean_pressure": 1.0, "precond": lambda x, out=None, work=None: x, **kw}
    with pytest.raises(InputError, match=said):
        polonsky_keer(lambda x, out=None, work=None: x, np.zeros((4, 4)), 1.0,
                      reduce=CommReductions(_NoComm()), **args)
