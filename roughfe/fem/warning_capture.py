"""ffcx, dolfinx's form compiler, calls ``logging.captureWarnings(True)`` when it is first
imported: every warning then goes to the logging module, and the command line printed
roughfe's own as ``WARNING:py.warnings:FILE:LINE: ...`` with a source line instead of its
one line ``roughfe CMD: warning: ...`` (``contact --method fem``, round 2, session 33).
:func:`warnings_back_from_logging` undoes it; :func:`roughfe.fem.petsc_tools.ensure_jit_cache`
calls it before the first dolfinx import.
"""
from __future__ import annotations

import logging
import warnings


def warnings_back_from_logging() -> None:
    """Import ffcx (once: no later import turns the capture on again) and give warnings
    back the ``showwarning`` they had before its ``logging.captureWarnings(True)``."""
    try:
        import ffcx  # noqa: F401
    except ImportError:    # pragma: no cover - no dolfinx here: nothing captures
        return
    if getattr(warnings.showwarning, "__module__", None) == logging.__name__:
        logging.captureWarnings(False)
