"""Research scripts: every ``polonsky_keer`` call of :mod:`roughfe.bem.contact` logged.

``CALLS`` receives ``(grid points, operator products, iterations)`` per call once
:func:`install` has wrapped the solver (a research script's counting, never the package's):
the convolution-equivalents of a solve are ``sum(points / n^2 * products)``.
"""
import roughfe.bem.contact as _contact

CALLS = []
_ORIGINAL = _contact.polonsky_keer


def _logged(apply, b, *args, **kw):
    out = _ORIGINAL(apply, b, *args, **kw)
    CALLS.append((b.size, out.n_products, out.nit))
    return out


def install():
    """Wrap ``roughfe.bem.contact.polonsky_keer`` (idempotent); returns ``CALLS``."""
    _contact.polonsky_keer = _logged
    return CALLS
