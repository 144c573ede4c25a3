"""Caches bounded by bytes (roughfe.caching) and the BEM operator caches that use them."""
import numpy as np
import pytest

from roughfe.bem import Material, contact as bem_contact, solve_contact
from roughfe.caching import bytes_bounded_cache, nbytes
from roughfe.surfaces import Surface


def test_cache_keeps_recent_results_within_its_byte_budget():
    calls = []

    @bytes_bounded_cache(max_bytes=3 * 800)
    def zeros(n):
        calls.append(n)
        return np.zeros(n)           # 8 n bytes

    for n in (100, 100, 100):        # 800 bytes each: all three kept
        zeros(n)
    assert calls == [100] and zeros.cache_info().hits == 2
    for n in (50, 60, 70, 80):       # 400 + 480 + 560 + 640 bytes
        zeros(n)
    info = zeros.cache_info()
    assert info.bytes <= info.max_bytes == 2400
    assert info.bytes == 400 + 480 + 560 + 640 and info.entries == 4   # 100 evicted
    zeros(1000)                      # 8000 bytes > budget: returned, never kept
    assert zeros.cache_info().bytes == 400 + 480 + 560 + 640
    assert len(zeros(1000)) == 1000 and calls[-2:] == [1000, 1000]
    zeros.cache_clear()
    assert zeros.cache_info().entries == 0


def test_nbytes_sums_arrays_in_containers():
    assert nbytes((np.zeros(3), {"a": np.zeros((2, 2))}, "text", 1.0)) == 8 * 7


def test_dense_matrix_too_large_for_the_budget_is_not_pinned(monkeypatch):
    """With a budget below one dense matrix the BEM still solves, nothing is kept, and
    the answer equals the cached solve (same matrix, same pivoting)."""
    x = np.arange(64) / 64
    surf = Surface(1e-6 * np.cos(2 * np.pi * x), 1e-3, periodic=True)
    mat = Material(1e9, 0.3)
    bem_contact._dense.cache_clear()
    a = solve_contact(surf, mat, delta=3e-7, solver="dense")
    assert bem_contact._dense.cache_info().bytes == 8 * 64 ** 2
    bem_contact._dense.cache_clear()
    monkeypatch.setattr(bem_contact._dense, "max_bytes", 8 * 64 ** 2 - 1)
    b = solve_contact(surf, mat, delta=3e-7, solver="dense")
    assert bem_contact._dense.cache_info().entries == 0
    np.testing.assert_array_equal(a.pressure, b.pressure)
    assert a.stiffness == pytest.approx(b.stiffness, rel=1e-12)


def test_cached_operator_arrays_are_read_only():
    op = bem_contact._operator((16,), (1e-3,), 1e9, "spectral")
    for arr in (op.kernel, op.spectrum, bem_contact._inverse_spectrum(op),
                bem_contact._dense(op)):
        with pytest.raises(ValueError):
            arr[...] = 0


def test_frozen_mapping_is_read_only_and_picklable():
    import json
    import pickle

    from roughfe.frozen import FrozenMapping, freeze

    m = freeze({"a": [1, 2], "b": {"c": np.zeros(2)}})
    assert isinstance(m, FrozenMapping) and m["a"] == (1, 2)
    with pytest.raises(TypeError):
        m["a"] = 0
    with pytest.raises(TypeError):
        m.update(a=1)
    assert json.dumps(freeze({"a": [1, 2], "b": {"c": 1.5}})) == '{"a": [1, 2], "b": {"c": 1.5}}'
    assert not m["b"]["c"].flags.writeable
    back = pickle.loads(pickle.dumps(m))
    assert dict(back)["a"] == (1, 2) and isinstance(back["b"], FrozenMapping)


def test_frozen_list_equals_its_list_and_refuses_changes():
    import json
    import pickle

    from roughfe.frozen import FrozenList

    x = FrozenList([1, (2, 3)])
    assert x == [1, (2, 3)] and json.dumps(x) == "[1, [2, 3]]"
    for change in (lambda: x.append(4), lambda: x.__setitem__(0, 5), lambda: x.sort()):
        with pytest.raises(TypeError):
            change()
    assert pickle.loads(pickle.dumps(x)) == x and x == [1, (2, 3)]
