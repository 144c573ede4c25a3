"""Progress of long library loops, for whoever listens (the command line draws tqdm bars).

A loop reports its progress by iterating through :func:`iterate`::

    for step in progress.iterate(steps, "BEM load steps"):
        ...

Nothing is drawn or printed by the library: :func:`iterate` calls the listener installed
by :func:`listening` (a context manager; the ``roughfe`` command installs one that draws a
bar on a terminal, see ``roughfe.cli.options``), and without a listener it is the plain
iterable (no cost). The listener lives in a ``contextvars.ContextVar``, so it is scoped
to the ``with`` block and to the thread or task that set it.
"""
from __future__ import annotations

import contextlib
import contextvars

_LISTENER = contextvars.ContextVar("roughfe_progress_listener", default=None)


def iterate(iterable, description: str, total: int | None = None):
    """Yield from ``iterable``; after each item tell the listener ``(description, done,
    total)``. ``total`` defaults to ``len(iterable)`` when it has one."""
    listener = _LISTENER.get()
    if listener is None:
        yield from iterable
        return
    if total is None and hasattr(iterable, "__len__"):
        total = len(iterable)
    listener(description, 0, total)
    for done, item in enumerate(iterable, 1):
        yield item
        listener(description, done, total)


@contextlib.contextmanager
def listening(listener):
    """Install ``listener(description, done, total)`` for the ``with`` block."""
    token = _LISTENER.set(listener)
    try:
        yield listener
    finally:
        _LISTENER.reset(token)
