"""The on-disk marker texture cache returns bit-identical levels and survives bad files."""

import numpy as np
import pytest

from mobigrasp.mcu_sim.world import markers as mk
from mobigrasp.mcu_sim.world import texture_cache as tc


def _levels(fn, n, monkeypatch, folder):
    monkeypatch.setenv("MOBIGRASP_CACHE_DIR", str(folder))
    fn.cache_clear()
    try:
        return fn(n).levels
    finally:
        fn.cache_clear()


@pytest.mark.parametrize("fn", [mk.radial_symbol_texture, mk.double_cross_texture])
def test_cached_texture_is_bit_identical(fn, tmp_path, monkeypatch):
    fresh = _levels(fn, 64, monkeypatch, "off")
    first = _levels(fn, 64, monkeypatch, tmp_path)  # builds and stores
    files = list(tmp_path.glob("*.npz"))
    assert len(files) == 1
    again = _levels(fn, 64, monkeypatch, tmp_path)  # loads
    assert len(fresh) == len(first) == len(again) > 1
    for a, b, c in zip(fresh, first, again, strict=True):
        assert a.dtype == c.dtype == np.uint8 and np.array_equal(a, b) and np.array_equal(a, c)


def test_a_corrupt_entry_is_rebuilt(tmp_path, monkeypatch):
    fn = mk.radial_symbol_texture
    fresh = _levels(fn, 32, monkeypatch, "off")
    _levels(fn, 32, monkeypatch, tmp_path)
    (path,) = tmp_path.glob("*.npz")
    path.write_bytes(b"not a zip file")
    again = _levels(fn, 32, monkeypatch, tmp_path)
    assert all(np.array_equal(a, b) for a, b in zip(fresh, again, strict=True))
    assert tc._load(path) is not None  # rewritten


def test_key_depends_on_arguments_and_name():
    src = mk.__file__
    keys = {tc.cache_key(src, "radial_symbol", 64), tc.cache_key(src, "radial_symbol", 32),
            tc.cache_key(src, "double_cross", 64)}
    assert len(keys) == 3
