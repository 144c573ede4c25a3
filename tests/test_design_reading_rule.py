"""The reading rule below a design curve's first computed pressure p_1
(similarity.read_curve, the power law through (0, 0) and the first two points) against
the profile solved there, beside its two limits, the chord from (0, 0) (alpha = 1)
and the held first value (np.interp's clamp, alpha = 0), in K and in A. Genomes of the
thesis database's genes (N = 512 profiles, 20 steps); the study's 60-genome table is
benchmarks/design_reading_rule.py (docs/theory/06_design.md)."""
import numpy as np

from roughfe.genomics import database as db
from roughfe.genomics import design as de
from roughfe.genomics.similarity import ResponseCurve
from roughfe.model import Loading, Material
from roughfe.response import response

SETTINGS = db.DatabaseSettings()
GENES = [(1.2, 0.6, 1), (1.4, 0.8, 2), (1.6, 0.7, 3), (1.8, 0.9, 4), (2.0, 0.65, 5),
         (1.3, 0.85, 6), (1.5, 0.75, 7), (1.7, 0.6, 8)]


def _errors():
    mat = Material(SETTINGS.youngs_modulus, SETTINGS.poisson)
    fine = np.linspace(0.05, 1.2, 47)
    err = {r: {"K": [], "A": []} for r in ("chord", "clamp", "rule")}
    for gamma, hurst, seed in GENES:
        g = db.make_genome(gamma, hurst, seed, SETTINGS)
        d = de.Design((de.DesignPart(g, tuple(range(g.n_first, g.n_last + 1))),), 1.0,
                      SETTINGS.length, SETTINGS.n_nodes)
        c = de.Evaluator(SETTINGS)(d)
        p1 = c.pressure[0]
        sw = response(d.surface(), mat, Loading(pressures=tuple(fine * p1)),
                      kernel=SETTINGS.kernel, compute_stiffness=False)
        ps = np.asarray(sw.mean_pressure)
        np.testing.assert_allclose(ps, fine * p1, rtol=1e-6)     # load control reached them
        solved = {"K": np.gradient(ps, np.asarray(sw.delta)), "A": np.asarray(sw.area_fraction)}
        assert isinstance(c, ResponseCurve)
        for q in ("K", "A"):
            for f in (0.25, 0.5, 0.75):
                truth = np.interp(f * p1, ps, solved[q])
                if truth <= 0:
                    continue
                y1 = c.values(q)[0]
                for rule, read in (("chord", y1 * f), ("clamp", y1),
                                   ("rule", float(c.at(f * p1, q)))):
                    err[rule][q].append(abs(read - truth) / truth)
    return err


def test_the_power_law_below_p1_follows_the_better_of_its_limits():
    """Which limit is closer depends on the curve: on these 8 genomes the chord (mean
    |error| K 0.34, A 0.37) beats the clamp (K 0.46, A 0.50; A up to 4x over where one
    node stays in contact), on the design study's 60 genomes the clamp wins for K (median
    0.15 against the chord's 0.43). The rule reads each curve's own log-slope: here mean
    |error| K 0.32, A 0.39 -- within 10 % of the better limit and below the worse one
    for both (on the 60 genomes it is the best of the three in both)."""
    err = _errors()
    for q in ("K", "A"):
        mean = {r: float(np.mean(err[r][q])) for r in err}
        assert len(err["rule"][q]) >= 18, q
        better, worse = sorted([mean["chord"], mean["clamp"]])
        assert mean["rule"] <= 1.1 * better and mean["rule"] < worse, (q, mean)
    assert max(err["clamp"]["A"]) > 2 > 1 > max(err["rule"]["A"])   # no 4x over-reading
