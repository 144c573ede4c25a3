"""``roughfe contact --grid-check``: the sweep solved again on the same surface 2x finer
(band-limited, :func:`roughfe.bem.grid_check.grid_check`), the relative change of A*,
K and the mean gap (with ``--adhesion``: A*, the load and, with ``--unload``, the
pull-off) in results.json (``derived.grid_check``) and the printout; a warning above
:data:`~roughfe.bem.grid_check.GRID_CHANGE_LIMIT`. Off by default: the default run
stays as fast as it was (the check costs 3-5x the sweep's CPU: 3.4-3.9x measured at
128^2-256^2, 3-4.6x adhesive)."""
from __future__ import annotations

import numpy as np

from ..bem.grid_check import GRID_CHANGE_LIMIT, GRID_CHECK_FACTOR, QUANTITIES
from .options import warn


def add_grid_check_option(group) -> None:
    """``--grid-check`` in the command's numerics group."""
    group.add_argument(
        "--grid-check", action="store_true",
        help=f"solve the sweep again on the same surface {GRID_CHECK_FACTOR}x finer "
             f"(band-limited Fourier refinement: no new roughness; a non-periodic window "
             f"through its mirror image) at the same mean pressures (with --adhesion at "
             f"the same rigid planes) and report the relative change of A*, K and the "
             f"mean gap (with --adhesion of A*, the load and, with --unload, the "
             f"pull-off): results.json "
             f"derived.grid_check; warns above {100 * GRID_CHANGE_LIMIT:g} %%. The grid's "
             f"own discretisation error, which patch_width does not bound (docs/theory/"
             f"02); costs 3-5x the sweep's CPU on a surface. BEM only")


def grid_check_of_args(args, surface, material, sweep, law, tol, options):
    """The :class:`~roughfe.bem.grid_check.GridCheck` of ``--grid-check`` (None without
    the flag): ``options``, the sweep's own solver options (``response``'s), on the
    refined surface; an adhesive sweep (``law``) with its kernel and tolerance."""
    if not getattr(args, "grid_check", False):
        return None
    # --method fem refuses --grid-check with the other BEM-only flags
    # (contact_options.method_options, before any solve)
    from ..bem.grid_check import grid_check
    if law is not None:
        return grid_check(surface, material, sweep, adhesion=law, unload=args.unload,
                          kernel=args.kernel, tol=tol,
                          max_unload_steps=args.max_unload_steps)
    return grid_check(surface, material, sweep,
                      **{k: v for k, v in options.items() if k != "unload"})


def print_grid_check(args, check) -> None:
    """The check's lines below the contact table, and its warning (stderr) when a
    quantity changed by more than the limit."""
    if check is None:
        return
    shape = " x ".join(str(n) for n in check.shape)
    names = [q for q in check.coarse if q != "pull_off_pressure"]
    print(f"grid check: the same surface {check.factor}x finer ({shape} points, "
          f"band-limited), change per compared step (fine / coarse - 1"
          + ("; p: fine - coarse over the largest |p|" if "mean_pressure" in names else "")
          + "; derived.grid_check):")
    print(f"{'step':>5s} {'p (Pa)':>12s} " + " ".join(f"{QUANTITIES[q]:>10s}" for q in names))
    for i, k in enumerate(check.steps):
        cells = " ".join(f"{_percent(check.change(q)[i]):>10s}" for q in names)
        print(f"{int(k):5d} {check.mean_pressure[i]:12.4e} {cells}")
    if "pull_off_pressure" in check.coarse:
        print(f"pull-off pressure {check.coarse['pull_off_pressure'][0]:.4e} Pa, "
              f"{check.fine['pull_off_pressure'][0]:.4e} Pa on the finer grid "
              f"({_percent(check.change('pull_off_pressure')[0])})")
    note = check.note()
    if note is not None:
        warn(args, note)
    else:
        print(f"every change within {100 * check.limit:g} % (the change to a 4x grid was "
              f"1.2-1.75x the change to the 2x grid, docs/theory/02)")


def _percent(v) -> str:
    return "-" if not np.isfinite(v) else f"{100 * v:+.2f} %"
