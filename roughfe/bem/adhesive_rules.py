"""The rules of an adhesive run (the solver of :mod:`roughfe.bem.adhesion`), in one place
for every front end: :func:`roughfe.response.response` with ``adhesion=``, ``roughfe
contact --adhesion`` and ``roughfe leak --adhesion`` check them before any work, each in
its own words."""
from __future__ import annotations

import numpy as np

from ..errors import InputError


def check_adhesive_run(*, hardness=None, solver="auto", coarse_correction=None,
                       pressure_control=False, deltas=None, words=None) -> None:
    """Raise :class:`InputError` unless the run keeps the rules: no hardness (the
    adhesive solver has no pressure cap), no choice of the non-adhesive solver or of its
    two-level correction (the adhesive one is its own minimiser on the gap),
    displacement control (the load-approach curve has unstable parts), and ``deltas``
    (the approaches of the loading branch, m), when given, strictly increasing: the
    continuation labels every one a loading step and the unloading branch retraces them
    in reverse.

    ``words`` maps the names used in the messages (``hardness``, ``adhesion``,
    ``solver``, ``coarse_correction``, ``approaches``, ``mean pressures``, ``deltas``,
    ``unload``) to the front end's own (the command line's flags); by default they are
    the library's keyword arguments."""
    say = {"approaches": "approaches (delta, deltas, n_steps)", "unload": "unload=True",
           **(words or {})}

    def word(name):
        return say.get(name, name)

    if hardness is not None:
        raise InputError(f"{word('hardness')} and {word('adhesion')} together are not "
                         f"supported (the adhesive solver has no pressure cap); give one "
                         f"of them")
    for name, value, default in (("solver", solver, "auto"),
                                 ("coarse_correction", coarse_correction, None)):
        if value != default:
            raise InputError(f"{word(name)} does not apply with {word('adhesion')} (its own "
                             f"minimiser on the gap)")
    if pressure_control:
        raise InputError(f"{word('adhesion')} runs in displacement control (the "
                         f"load-approach curve has unstable parts): give "
                         f"{word('approaches')}, not {word('mean pressures')}")
    steps = None if deltas is None else np.asarray(deltas, float).ravel()
    if steps is not None and np.any(np.diff(steps) <= 0):
        raise InputError(f"{word('deltas')} (the approaches of the {word('adhesion')} loading "
                         f"branch, m) must be strictly increasing ({word('unload')} traces "
                         f"the unloading branch), got {steps.tolist()}")
