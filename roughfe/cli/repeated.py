"""An option given twice with different values is refused (one line, exit 2).

argparse keeps the last value of a repeated option in silence: ``roughfe contact S.npz
--pressure 1e6 --pressure 2e6`` solved 2e6 Pa only, ``--size 1e-4 --size 2e-4`` read the
second size (found by the command-line audit of round 2, session 37). Every
:class:`~roughfe.cli.options.RoughfeParser` stores with :class:`StoreOnce`; the old
spellings (``--youngs-modulus`` for ``--E``) call :func:`refuse_repeated` too. The same
value given twice passes; ``append`` options (``db extend --label``) are meant to repeat.
:class:`Distinct` refuses a value listed twice in one option whose values name runs
(``genome mechanics --kernels strip strip`` ran the strip sweeps twice).
"""
from __future__ import annotations

import argparse

#: the namespace attribute that records the options given (removed after parsing)
GIVEN = "_roughfe_given"


def _shown(values) -> str:
    items = values if isinstance(values, list) else [values]
    return " ".join(format(v, "g") if isinstance(v, float) else str(v) for v in items)


def refuse_repeated(parser, namespace, dest, option_string, values) -> None:
    """``parser.error`` when ``dest`` was already given another value on this command line."""
    seen = vars(namespace).setdefault(GIVEN, {})
    if option_string and dest in seen and seen[dest][1] != values:
        first, before = seen[dest]
        parser.error(f"{first} {_shown(before)} and {option_string} {_shown(values)}: the "
                     "option is given twice; give it once (with all its values)")
    seen[dest] = (option_string, values)


class StoreOnce(argparse._StoreAction):
    """argparse's ``store`` action, refusing an option given twice with different values."""

    def __call__(self, parser, namespace, values, option_string=None):
        refuse_repeated(parser, namespace, self.dest, option_string, values)
        super().__call__(parser, namespace, values, option_string)


class Distinct(StoreOnce):
    """:class:`StoreOnce` for a list of choices that each start a run: a value listed twice
    is refused (it ran twice and wrote the same files twice)."""

    def __call__(self, parser, namespace, values, option_string=None):
        twice = sorted({v for v in values if values.count(v) > 1})
        if twice:
            parser.error(f"argument {option_string}: lists {', '.join(map(repr, twice))} "
                         "more than once; give each value once")
        super().__call__(parser, namespace, values, option_string)
