"""One range checker (roughfe.errors.check_in_interval, round 2, session 34): the Hurst
exponents and frequency densities of the generators, the genome and the band analysis,
and Persson's gamma, were each checked by a hand-rolled copy (some took "0.5" as text,
some True as 1.0). The ends each one includes are kept."""
import re

import numpy as np
import pytest

from roughfe.errors import InputError, check_in_interval, check_in_open_interval
from roughfe.genomics.bands import genome_q1
from roughfe.genomics.genome import Genome
from roughfe.surfaces import spectral_profile, wm_profile


@pytest.mark.parametrize("closed, inside, outside", [
    ("neither", (0.5,), (0, 1)),
    ("left", (0, 0.5), (1,)),
    ("right", (0.5, 1), (0,)),
    ("both", (0, 0.5, 1), (-1e-300, 1.0000001)),
])
def test_the_ends_of_an_interval(closed, inside, outside):
    written = {"neither": r"\(0, 1\)", "left": r"\[0, 1\)", "right": r"\(0, 1\]",
               "both": r"\[0, 1\]"}[closed]
    for v in inside:
        assert check_in_interval("x", v, 0, 1, closed) == v
    for v in (*outside, np.nan, np.inf, -np.inf):
        with pytest.raises(InputError, match=rf"^x must lie in .*{written}, got "):
            check_in_interval("x", v, 0, 1, closed)
    for v in ("0.5", True, None, [0.5]):
        with pytest.raises(InputError, match=rf"^x must be a number in {written}, got "):
            check_in_interval("x", v, 0, 1, closed)
    assert type(check_in_interval("x", np.float32(0.5), 0, 1, closed)) is float


def test_the_open_interval_keeps_its_words():
    with pytest.raises(InputError, match=r"^tol must lie in the open interval \(0.0, 1.0\), "
                                         r"got 1.0$"):
        check_in_open_interval("tol", 1.0, 0.0, 1.0)
    with pytest.raises(ValueError, match="closed"):
        check_in_interval("x", 0.5, 0, 1, "open")


def test_each_model_keeps_its_own_interval():
    # spectral: H in (0, 1] (H = 1 is the smooth limit); WM: H in (0, 1), gamma > 1
    assert spectral_profile(16, 1.0, 1.0, rms_height=1.0, rng=0).metadata["hurst"] == 1.0
    with pytest.raises(InputError, match=r"hurst H must lie in \(0, 1\], got 0"):
        spectral_profile(16, 1.0, 0, rms_height=1.0)
    with pytest.raises(InputError, match=r"hurst H must lie in the open interval \(0, 1\), "
                                         r"got 1.0"):
        wm_profile(64, 1.0, 1.0)
    for gamma in (1.0, np.inf, "2"):
        with pytest.raises(InputError, match=r"gamma \(frequency density\) must .* in .*"
                                             r"\(1, inf\)"):
            wm_profile(64, 1.0, 0.5, gamma=gamma)
    # the genome: H in (0, 3], gamma in (1, 10]; the band analysis: gamma in (1, 10]
    g = Genome(A=1.0, H=3, gamma=10, lambda1=1e-3, phases=np.zeros((2, 3)))
    assert (g.H, g.gamma) == (3.0, 10.0) and type(g.H) is float
    for bad, match in (({"H": True}, r"H \(scaling exponent\) must be a number in \(0, 3\]"),
                       ({"H": 3.01}, r"H \(scaling exponent\) must lie in \(0, 3\]"),
                       ({"gamma": 1}, r"gamma \(frequency density, Eq. 3.6\) must lie in "
                                      r"\(1, 10\], got 1$")):
        with pytest.raises(InputError, match=match):
            Genome(**{"A": 1.0, "H": 0.7, "gamma": 1.5, "lambda1": 1e-3,
                      "phases": np.zeros((2, 3)), **bad})
    assert genome_q1(10, 1.0) == pytest.approx(2 * np.pi / np.sqrt(10))
    with pytest.raises(InputError, match=r"gamma \(band ratio\) must lie in \(1, 10\]"):
        genome_q1(10.5, 1.0)


# -- round 2, session 34 (helper "left"): Poisson's ratio, the MD smoothing, Sobol ranges ----
def test_poissons_ratio_is_a_number_of_an_isotropic_solid():
    # -1 < nu <= 1/2: shear and bulk moduli positive below 1/2, 1/2 the incompressible limit
    # (E* = 4E/3; the FEM body refuses it itself). Text ran as a number ("0.3" -> 0.3)
    from roughfe.model import Material, composite
    assert Material(1e9, 0.5).E_star == pytest.approx(4e9 / 3, rel=1e-15, abs=0)
    assert Material(1e9, -0.999).nu == -0.999 and type(Material(1e9, 0).nu) is float
    for bad in ("0.3", True, None):
        with pytest.raises(InputError, match=r"^nu \(Poisson's ratio\) must be a number in "
                                             r"\(-1, 0.5\], got "):
            Material(1e9, bad)
    for bad in (-1, 0.5000001, np.nan):
        with pytest.raises(InputError, match=r"^nu \(Poisson's ratio\) must lie in "
                                             r"\(-1, 0.5\], got "):
            Material(1e9, bad)
    with pytest.raises(InputError, match=r"^nu2 \(Poisson's ratio\) must be a number in "):
        composite(1e9, 0.3, 2e9, "0.2")


def test_maugis_dugdale_smoothing_in_its_interval():
    from roughfe.bem.interface_law import AdhesionLaw
    assert AdhesionLaw("md", 0.1, 1e-9, smoothing=0).smoothing == 0.0
    for bad in (1, -0.1, np.nan, "0.1"):
        with pytest.raises(InputError, match=r"^smoothing \(the Maugis-Dugdale ramp, a fraction "
                                             r"of the range\) must .*\[0, 1\), got "):
            AdhesionLaw("md", 0.1, 1e-9, smoothing=bad)


def test_sobol_ranges_lie_in_the_genomes_intervals():
    # gamma_range was not checked (a gamma <= 1 failed its tasks in the build), a text
    # end was a TypeError, one number a ValueError; each end is now checked as the Genome
    # checks it: gamma (1, 10], H (0, 3], anisotropy (0, inf); low == high is one value
    from roughfe.genomics.database import SobolDesign
    d = SobolDesign(hurst_range=[1, 1], gamma_range=(1.5, 10))
    assert d.hurst_range == (1.0, 1.0) and d.gamma_range == (1.5, 10.0)
    assert np.all(d.pairs()[:, 1] == 1.0)
    for kw, match in (({"gamma_range": (0.5, 2.0)},
                       r"^gamma_range low \(the genome's gamma\) must lie in \(1, 10\], got 0.5$"),
                      ({"gamma_range": (1.2, 11)}, r"^gamma_range high .* \(1, 10\], got 11$"),
                      ({"hurst_range": (1, 1e308)},
                       r"^hurst_range high \(the genome's H\) must lie in \(0, 3\], got 1e\+308"),
                      ({"hurst_range": ("0.5", 1.0)}, r"^hurst_range low .* must be a number in"),
                      ({"hurst_range": (0.5,)}, r"^hurst_range must be two numbers \(low, high\)"),
                      ({"hurst_range": (1.0, 0.2)}, r"^hurst_range must have low <= high"),
                      ({"anisotropy_range": (0.5, np.inf)},
                       r"^anisotropy_range high .* open interval \(0, inf\), got inf$")):
        with pytest.raises(InputError, match=match):
            SobolDesign(**kw)


# -- round 2, session 34 (helper "small"): numpy booleans, composite's E2, n_ridges ---------
@pytest.mark.parametrize("flag", [np.True_, np.bool_(False), np.array(True)])
def test_numpy_booleans_are_refused_as_bools_are(flag):
    # isinstance(np.True_, bool) is False: float(np.True_) = 1.0 passed every range check
    # (and operator.index(np.True_) = 1 the integer check) as a number
    from roughfe.errors import check_finite_nonnegative, check_finite_positive, check_int
    from roughfe.model import Material
    for check, match in ((lambda v: check_in_interval("x", v, 0, 1, "both"),
                          r"^x must be a number in \[0, 1\], got "),
                         (lambda v: check_finite_positive("x", v),
                          r"^x must be a positive number, got "),
                         (lambda v: check_finite_nonnegative("x", v),
                          r"^x must be a finite number >= 0, got "),
                         (lambda v: check_int("x", v, 0), r"^x must be an integer >= 0, got "),
                         (lambda v: Material(1e9, v), r"^nu \(Poisson's ratio\) must be a "
                                                      r"number in \(-1, 0.5\], got "),
                         (lambda v: Material(v, 0.3), r"^E \(Young's modulus, Pa\) must be "
                                                      r"a positive number, got ")):
        with pytest.raises(InputError, match=match + r".*" + re.escape(repr(flag)) + "$"):
            check(flag)
    # numpy numbers that are not bools still pass
    assert check_in_interval("x", np.float64(0.5), 0, 1) == 0.5
    assert check_int("x", np.int64(3), 0) == 3 and type(check_int("x", np.int64(3), 0)) is int


def test_composite_refuses_text_for_E2_as_material_does():
    # E2 went through float(): "7e10" ran as 7e10 (Material refuses text for E)
    from roughfe.model import composite
    for bad in ("7e10", True, np.True_, None):
        with pytest.raises(InputError, match=r"^E2 \(Young's modulus, Pa; inf: rigid\) must "
                                             r"be a number in \(0, inf\], got "):
            composite(1e9, 0.3, bad, 0.3)
    for bad in (0, -7e10, np.nan):
        with pytest.raises(InputError, match=r"^E2 .* must lie in \(0, inf\], got "):
            composite(1e9, 0.3, bad, 0.3)
    # Johnson Eq. 4.22, and the rigid limit E2 = inf: E* of the first body alone
    e1, e2 = 1e9, 7e10
    expected = 1.0 / ((1 - 0.3 ** 2) / e1 + (1 - 0.2 ** 2) / e2)
    assert composite(e1, 0.3, e2, 0.2).E_star == pytest.approx(expected, rel=1e-15, abs=0)
    assert composite(e1, 0.3, np.inf, 0.2).E_star == pytest.approx(e1 / (1 - 0.09), rel=1e-15,
                                                                   abs=0)


def test_sobol_n_ridges_is_an_integer():
    # int(self.n_ridges) took "3" (3 ridges, stored in the design as the text "3") and
    # ran 2.5 as 2 ridges (stored as 2.5); numpy integers are kept as Python ints
    from roughfe.genomics.database import SobolDesign
    d = SobolDesign(dim=2, n_ridges=np.int64(2), n_pairs=2, n_vectors=1)
    assert d.n_ridges == 2 and type(d.n_ridges) is int and d.genes().shape == (2, 6)
    for bad in ("3", 2.5, 3.0, True, np.True_, 0):
        with pytest.raises(InputError, match=r"^n_ridges \(ridges per genome, 1..100\) must be "
                                             r"an integer >= 1, got "):
            SobolDesign(dim=2, n_ridges=bad)
    with pytest.raises(InputError, match=r"^n_ridges must lie in 1..100, got 101$"):
        SobolDesign(dim=2, n_ridges=101)


# -- round 2, session 34 (helper "misc"): the other integers of SobolDesign, sobol_tasks --
def test_sobol_design_integers_and_task_limit_are_checked():
    # a float or text (n_pairs=2.5, 3.0, "3"; seed=3.0) passed the constructor and failed
    # in pairs()/phase_vectors() with a bare TypeError or ValueError, seed=-1 in numpy,
    # n_phases = n_extra = 0 with an OverflowError; dim=True ran as 1; limit=2.5 kept 2
    # genomes and limit="3" kept 3 (int(limit))
    from roughfe.genomics.database import SobolDesign, sobol_tasks
    for name, minimum, what in (("n_pairs", 1, r"\(gamma, H\) points"),
                                ("n_vectors", 1, "phase vectors"),
                                ("n_phases", 1, "phases per vector"),
                                ("n_extra", 0, "extra phases per vector"),
                                ("seed", 0, "Sobol scrambling seed")):
        for bad in (2.5, "3", 3.0, True, np.True_, None, minimum - 1):
            with pytest.raises(InputError, match=rf"^{name} \({what}\) must be an integer "
                                                 rf">= {minimum}, got {re.escape(repr(bad))}$"):
                SobolDesign(**{name: bad})
    for bad in (True, 1.0, 3, "1"):
        with pytest.raises(InputError, match=r"^dim must be 1 \(profiles\) or 2 \(surfaces\), "
                                             rf"got {re.escape(repr(bad))}$"):
            SobolDesign(dim=bad)
    with pytest.raises(InputError, match=r"^n_pairs must be at most 2\*\*30 = 1073741824 "):
        SobolDesign(n_pairs=2 ** 30 + 1)
    with pytest.raises(InputError, match=r"^n_vectors \* \(n_phases \+ n_extra\) \* ridges "
                                         r"must be at most 2\*\*30 .*got 1073741825$"):
        SobolDesign(dim=2, n_ridges=1, n_vectors=1, n_phases=2 ** 30, n_extra=1)
    # numpy integers are kept as Python ints; the smallest design runs: one pair, one
    # vector of one phase, no extra phases, seed 0 (the thesis' own pair count is 20)
    d = SobolDesign(n_pairs=np.int64(1), n_vectors=np.int32(1), n_phases=1, n_extra=0,
                    seed=np.uint8(0))
    assert all(type(getattr(d, k)) is int for k in ("n_pairs", "n_vectors", "seed"))
    assert d.pairs().shape == (1, 2) and d.phase_vectors().shape == (1, 1)
    tasks = sobol_tasks(SobolDesign(n_pairs=2, n_vectors=2))
    assert len(tasks) == 4
    assert [t["label"] for t in sobol_tasks(SobolDesign(n_pairs=2, n_vectors=2),
                                            np.int64(3))] == ["1-1", "1-2", "2-1"]
    for bad in (2.5, "3", 0, True, -1):
        with pytest.raises(InputError, match=r"^limit \(genomes to build\) must be an integer "
                                             rf">= 1, got {re.escape(repr(bad))}$"):
            sobol_tasks(SobolDesign(n_pairs=2, n_vectors=2), bad)
