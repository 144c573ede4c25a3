"""How well a response curve read below its first computed pressure p_1 predicts the
solved K(p) and A(p) there: the first value held (``similarity.read_curve``, np.interp's
clamp), the chord from (0, 0) (session 26) and the power law through (0, 0) and the
first two points, ``y_1 (p / p_1)^alpha`` with alpha their log-slope clipped to [0, 1]
(session 27's trial: the best reading, but the optimiser reached worse designs with it,
docs/theory/06_design.md).

Every genome of the design study's database (``roughfe validate design``: 60 genomes,
N = 512 profiles; built here when no database is given, ~1-2 min) is solved at the
pressures ``c p_1`` (load control; c = 0.05 .. 1.2 on 47 points, K = dp/dDelta by
differences on that fine grid, A the exact node count) and each rule's reading of the
database curve at ``c = 0.25, 0.5, 0.75`` is compared with it (relative error). A
research script, not in ``make bench``; the table it prints is in
``docs/theory/06_design.md``.

Run: .venv/bin/python benchmarks/design_reading_rule.py [DB]
"""
import sys
import tempfile
from pathlib import Path

import numpy as np

from roughfe.genomics import database as gdb
from roughfe.genomics import design as de
from roughfe.model import Loading, Material
from roughfe.response import response
from roughfe.study import build_genome_db

FINE = np.linspace(0.05, 1.2, 47)
READ_AT = (0.25, 0.5, 0.75)


def leading_exponent(p, y):
    """alpha of the power-law reading: ln(y_2/y_1) / ln(p_2/p_1) clipped to [0, 1]."""
    if not (y[0] > 0 and y[1] > 0):
        return 1.0
    return float(np.clip(np.log(y[1] / y[0]) / np.log(p[1] / p[0]), 0.0, 1.0))


def rule_errors(entries, settings):
    """``{rule: {"K": [...], "A": [...]}}`` relative errors (read - solved) / solved."""
    mat = Material(settings.youngs_modulus, settings.poisson)
    err = {r: {"K": [], "A": []} for r in ("chord", "clamp", "power law")}
    for e in entries:
        surf = de.entry_design(e, settings, weight=1.0).surface()
        c = e.curve
        p1 = c.pressure[0]
        sw = response(surf, mat, Loading(pressures=tuple(FINE * p1)), kernel=settings.kernel,
                      compute_stiffness=False)
        ps = np.asarray(sw.mean_pressure)
        solved = {"K": np.gradient(ps, np.asarray(sw.delta)),
                  "A": np.asarray(sw.area_fraction)}
        for q in ("K", "A"):
            y = c.values(q)
            alpha = leading_exponent(c.pressure, y)
            for f in READ_AT:
                truth = float(np.interp(f * p1, ps, solved[q]))
                if truth <= 0:
                    continue
                for rule, read in (("chord", y[0] * f), ("clamp", y[0]),
                                   ("power law", y[0] * f ** alpha)):
                    err[rule][q].append((read - truth) / truth)
    return err


def main(db_path=None) -> int:
    settings = gdb.DatabaseSettings()
    if db_path is None:
        db_path = Path(tempfile.mkdtemp()) / "genomes.sqlite"
        build_genome_db(db_path, settings, workers=2, progress=False)
    entries = gdb.load_entries(db_path)
    err = rule_errors(entries, settings)
    print(f"{len(entries)} genomes, read at {', '.join(map(str, READ_AT))} p_1; relative error")
    print(f"{'rule':>10} {'':>2} {'n':>4} {'median':>7} {'90 %':>6} {'max':>6} {'mean signed':>12}")
    for rule, by_q in err.items():
        for q, v in by_q.items():
            a = np.abs(v)
            print(f"{rule:>10} {q:>2} {a.size:>4} {np.median(a):>7.3f} {np.quantile(a, 0.9):>6.3f} "
                  f"{a.max():>6.3f} {np.mean(v):>+12.3f}")
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from _report import script_args
    if len(sys.argv) > 1 and sys.argv[1] in ("-h", "--help"):
        script_args(__doc__)
    sys.exit(main(Path(sys.argv[1]) if len(sys.argv) > 1 else None))
