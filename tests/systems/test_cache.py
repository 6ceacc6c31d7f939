"""Caches: generated code and datasets are reused, and a corrupt file is regenerated, never trusted."""

import numpy as np
import pytest

import systems
from systems import cache, datasets
from systems import system as system_mod


@pytest.fixture()
def fresh_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("LAGBENCH_CACHE", str(tmp_path))
    monkeypatch.setattr(system_mod, "_SOURCES", {})
    monkeypatch.setattr(system_mod, "_FUNCS", {})
    return tmp_path


def _codegen_file(tmp_path, what):
    (path,) = (tmp_path / "codegen").glob(f"spring-{what}-*.py")
    return path


@pytest.mark.parametrize("damage", ["flip", "truncate", "header"])
def test_corrupt_generated_source_is_regenerated(fresh_cache, damage):
    s = systems.get("spring", k=4.0)
    q, v = np.array([[0.5]]), np.array([[0.0]])
    np.testing.assert_allclose(s.acceleration(q, v), [[-2.0]])
    path = _codegen_file(fresh_cache, "acceleration")
    good = path.read_text()
    if damage == "flip":  # a plausible but wrong program: checksum must catch it
        bad = good.replace("-", "+", 1)
    elif damage == "truncate":
        bad = good[: len(good) // 2]
    else:
        bad = good.split("\n", 1)[1]
    assert bad != good
    path.write_text(bad)
    system_mod._SOURCES.clear()
    system_mod._FUNCS.clear()
    assert cache.load_text("codegen", path.stem) is None
    np.testing.assert_allclose(s.acceleration(q, v), [[-2.0]])
    assert path.read_text() == good


def test_corrupt_dataset_is_regenerated(fresh_cache):
    first = datasets.iid_dataset("double_pendulum", 50, 7)
    (path,) = (fresh_cache / "datasets").glob("iid-double_pendulum-*.npz")
    again = datasets.iid_dataset("double_pendulum", 50, 7)
    for k in first:
        np.testing.assert_array_equal(first[k], again[k])
    raw = bytearray(path.read_bytes())
    path.write_bytes(bytes(raw[: len(raw) // 2]))  # truncated
    assert cache.load_arrays(path.stem) is None
    third = datasets.iid_dataset("double_pendulum", 50, 7)
    np.testing.assert_array_equal(third["qddot"], first["qddot"])
    # a well-formed archive with altered numbers fails the checksum
    data = dict(np.load(path))
    data["qddot"] = data["qddot"] + 1.0
    np.savez(path, **data)
    assert cache.load_arrays(path.stem) is None
    np.testing.assert_array_equal(datasets.iid_dataset("double_pendulum", 50, 7)["qddot"], first["qddot"])


def test_dataset_key_depends_on_everything_that_defines_it(fresh_cache):
    a = datasets.iid_dataset("double_pendulum", 10, 0)
    b = datasets.iid_dataset("double_pendulum", 10, 1)
    c = datasets.iid_dataset("double_pendulum", 10, 0, g=9.81)
    assert not np.array_equal(a["q"], b["q"])
    np.testing.assert_array_equal(a["q"], c["q"])
    assert not np.array_equal(a["qddot"], c["qddot"])
    assert len(list((fresh_cache / "datasets").glob("*.npz"))) == 3
