"""What a scripting user of the library meets (round 2 API review, /tmp/api_review scripts):
results that stay read-only (also after pickling), one-line reprs, ``__all__`` of the
reference and genome modules, and the hint when a Material is passed as E*.

Before: ``pickle.loads(pickle.dumps(surface)).heights`` was writable (the docstring says
"a Surface never changes"); the arrays of PerssonResult, PowerSpectrum, ReynoldsResult,
NetworkResult, DirectionalNetwork and CriticalConstriction were writable inside their
frozen dataclasses; ``repr`` of one 128^2 ContactResult printed 3 kB, a LeakageResult
18 kB, a SequencingResult 83 kB.
"""
import dataclasses
import pickle

import numpy as np
import pytest

from roughfe.errors import InputError
from roughfe.genomics.genome import table1_genome
from roughfe.leakage import critical_constriction, leakage_of_contact, reynolds_flow
from roughfe.model import Loading, Material
from roughfe.response import response
from roughfe.surfaces import power_spectrum, spectral_surface
from roughfe.theory import persson


@pytest.fixture(scope="module")
def case():
    surface = spectral_surface(n=16, size=1e-4, hurst=0.8, rms_height=1e-6, rng=0)
    material = Material(E=1e9, nu=0.3)
    sweep = response(surface, material, Loading(pressures=(1e6, 1e7, 3e7)))
    return surface, material, sweep


def _arrays(obj):
    return {f.name: getattr(obj, f.name) for f in dataclasses.fields(obj)
            if isinstance(getattr(obj, f.name), np.ndarray)}


def _assert_read_only(obj):
    arrays = _arrays(obj)
    assert arrays, f"{type(obj).__name__} holds no array to check"
    for name, arr in arrays.items():
        assert not arr.flags.writeable, f"{type(obj).__name__}.{name} is writable"
        with pytest.raises(ValueError):
            arr.flat[0] = arr.flat[0]


def _results(case):
    surface, material, sweep = case
    step = sweep.results[1]
    leak = leakage_of_contact(step, mu=1e-3, pressure_drop=1e5)
    return {
        "Surface": surface,
        "Genome": table1_genome(rng=0),
        "PowerSpectrum": power_spectrum(surface),
        "PerssonResult": persson(surface, material.E_star, [1e6, 1e7]),
        "ReynoldsResult": reynolds_flow(step.gap, surface.spacing, pressure_drop=1e5),
        "NetworkResult": leak.network,
        "DirectionalNetwork": leak.network.directions["x"],
        "CriticalConstriction": critical_constriction(step.gap, surface.spacing),
    }


def test_result_arrays_are_read_only_and_stay_so_after_pickling(case):
    for name, obj in _results(case).items():
        _assert_read_only(obj)
        _assert_read_only(pickle.loads(pickle.dumps(obj)))


def test_unpickled_surface_keeps_its_metadata_containers(case):
    """The re-freezing after unpickling touches the arrays only: lists stay lists."""
    surface = case[0].with_heights(case[0].heights, levels=[1, 2])
    back = pickle.loads(pickle.dumps(surface))
    assert back.metadata == surface.metadata
    assert isinstance(back.metadata["levels"], list)


def test_persson_does_not_freeze_the_callers_pressures(case):
    surface, material, _ = case
    p = np.array([1e6, 1e7])
    result = persson(surface, material.E_star, p)
    p[0] = 2e6                                  # the caller's array is still theirs
    assert result.mean_pressure[0] == pytest.approx(1e6, rel=0, abs=1e-9)


def test_reprs_are_one_short_line(case):
    surface, material, sweep = case
    step = sweep.results[0]
    text = repr(step)
    assert "\n" not in text and len(text) < 2000
    assert "pressure=array(shape=(16, 16), dtype=float64)" in text
    assert "plastic_area_fraction" not in text          # optional fields not computed
    sweep_text = repr(sweep)
    assert "results=<3 x ContactResult>" in sweep_text and "\n" not in sweep_text
    assert "mean_pressure=array([ 1000000., 10000000., 30000000.])" in sweep_text
    leak = leakage_of_contact(step, mu=1e-3, pressure_drop=1e5)
    for obj in (leak, leak.network, persson(surface, material.E_star, 1e6)):
        assert "\n" not in repr(obj) and len(repr(obj)) < 2500, type(obj).__name__
    assert "flows={'x': <ReynoldsResult>, 'y': <ReynoldsResult>}" in repr(leak)


def test_reference_and_genome_modules_declare_their_public_names():
    import roughfe.genomics.genome as genome
    import roughfe.reference as reference

    for module, names in ((reference, ("hertz_sphere", "westergaard", "HertzSolution")),
                          (genome, ("Genome", "realize", "table1_genome", "load_genome"))):
        assert set(names) <= set(module.__all__)
        assert all(hasattr(module, n) for n in module.__all__)
        defined = {n for n, o in vars(module).items() if not n.startswith("_")
                   and callable(o) and getattr(o, "__module__", None) == module.__name__}
        assert defined <= set(module.__all__), defined - set(module.__all__)


def test_material_for_e_star_says_to_pass_its_modulus(case):
    surface, material, _ = case
    with pytest.raises(InputError, match=r"pass its \.E_star"):
        persson(surface, material, 1e6)


def test_hertz_stiffness_doc_states_its_unit_against_the_contact_result():
    from roughfe.reference import HertzSolution

    assert "nominal_area" in HertzSolution.__doc__ and "N/m" in HertzSolution.__doc__


def test_power_spectra_compare_and_hash_like_the_other_results(case):
    """eq=False as every result holding arrays: ``a == b`` raised numpy's "truth value of
    an array is ambiguous" ValueError and ``hash(a)`` a TypeError."""
    a, b = power_spectrum(case[0]), power_spectrum(case[0])
    assert a == a and a != b
    assert len({a, b}) == 2


def test_sphere_cap_is_found_beside_the_other_generators():
    import roughfe.surfaces as surfaces
    from roughfe.surfaces.shapes import sphere_cap

    assert "sphere_cap" in surfaces.__all__ and surfaces.sphere_cap is sphere_cap


def test_leakage_of_contact_names_an_unknown_option_and_the_viscosity(case):
    """It raised Python's TypeError naming analyse_leakage, which the user never called;
    theory.critical_junction's ``viscosity`` is ``mu`` here."""
    step = case[2].results[1]
    with pytest.raises(InputError, match=r"\['viscosity'\] for leakage_of_contact.*is mu"):
        leakage_of_contact(step, viscosity=1e-3, pressure_drop=1e5)
    assert leakage_of_contact(step, mu=1e-3, pressure_drop=1e5).leak_rate > 0
