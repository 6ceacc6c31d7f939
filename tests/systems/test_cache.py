"""Caches: generated code and datasets are reused, and a corrupt, planted or unauthenticated file is
regenerated, never trusted or executed (issue 25, case 3); files get the umask's mode (case 9)."""

import hashlib
import os

import numpy as np
import pytest

from lagbench import systems
from lagbench.systems import cache, cache_key, datasets
from lagbench.systems import system as system_mod


@pytest.fixture()
def fresh_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("LAGBENCH_CACHE", str(tmp_path))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "private"))
    cache_key._key.cache_clear()
    monkeypatch.setattr(system_mod, "_SOURCES", {})
    monkeypatch.setattr(system_mod, "_FUNCS", {})
    yield tmp_path
    cache_key._key.cache_clear()


def _forget():
    system_mod._SOURCES.clear()
    system_mod._FUNCS.clear()


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


def _planted(marker, header):
    body = (f"def acceleration(q, qdot, qddot, tau, params, _z):\n"
            f"    open({str(marker)!r}, 'w').write('ran')\n    return _z\n")
    return header(body) + body


@pytest.mark.parametrize("header", [
    lambda body: f"# lagbench-cache sha256={hashlib.sha256(body.encode()).hexdigest()}\n",  # the old format
    lambda body: f"# lagbench-cache hmac-sha256={hashlib.sha256(body.encode()).hexdigest()}\n",
    lambda body: f"# lagbench-cache hmac-sha256={cache_key.tag('codegen', 'other-name', body.encode())}\n",
])
def test_planted_generated_code_is_never_executed(fresh_cache, header):
    s = systems.get("spring", k=4.0)
    q, v = np.array([[0.5]]), np.array([[0.0]])
    s.acceleration(q, v)
    path = _codegen_file(fresh_cache, "acceleration")
    marker = fresh_cache / "ran"
    path.write_text(_planted(marker, header))
    _forget()
    np.testing.assert_allclose(s.acceleration(q, v), [[-2.0]])
    assert not marker.exists()
    assert "hmac-sha256=" in path.read_text() and "open(" not in path.read_text()  # regenerated in place


def test_a_symlinked_entry_is_not_followed(fresh_cache):
    s = systems.get("spring", k=4.0)
    q, v = np.array([[0.5]]), np.array([[0.0]])
    s.acceleration(q, v)
    path = _codegen_file(fresh_cache, "acceleration")
    target = fresh_cache / "elsewhere.py"
    target.write_text(path.read_text())  # a genuine entry, but reached through a link
    path.unlink()
    path.symlink_to(target)
    assert cache.load_text("codegen", path.stem) is None
    _forget()
    np.testing.assert_allclose(s.acceleration(q, v), [[-2.0]])
    assert not path.is_symlink() and target.read_text() == path.read_text()  # replaced, not written through


def test_without_a_private_key_nothing_is_loaded_or_stored(fresh_cache):
    key_dir = fresh_cache / "private" / "lagbench"
    key_dir.mkdir(parents=True)
    os.chmod(key_dir, 0o777)  # others could swap the key
    s = systems.get("spring", k=4.0)
    np.testing.assert_allclose(s.acceleration(np.array([[0.5]]), np.array([[0.0]])), [[-2.0]])
    assert not (fresh_cache / "codegen").exists() and not (key_dir / "key").exists()


def test_the_key_is_private(fresh_cache):
    assert cache_key.tag("codegen", "x", b"y") is not None
    key = fresh_cache / "private" / "lagbench" / "key"
    assert oct(key.stat().st_mode & 0o777) == "0o600" and oct(key.parent.stat().st_mode & 0o777) == "0o700"


@pytest.mark.parametrize("mask, mode", [(0o022, 0o644), (0o077, 0o600), (0o002, 0o664)])
def test_cache_and_result_files_follow_the_umask(fresh_cache, mask, mode):
    from lagbench.files import results as R
    old = os.umask(mask)
    try:
        written = [cache.store_text("codegen", "x", "pass\n"), cache.store_arrays("y", {"a": np.zeros(2)})]
        R.write_json(fresh_cache / "r" / "result.json", {"a": 1})
        written.append(fresh_cache / "r" / "result.json")
    finally:
        os.umask(old)
    assert [oct(p.stat().st_mode & 0o777) for p in written] == [oct(mode)] * 3


def test_an_unwritable_cache_warns_once_naming_it_and_work_goes_on(fresh_cache, monkeypatch, caplog):
    """A file where the cache's folder belongs (as a read-only or full cache, but failing for root too):
    the system's generated code and a dataset still come out, with one warning per folder naming it
    (issue 58, item 4)."""
    blocked = fresh_cache / "blocked"
    blocked.write_text("a file, not a folder")
    monkeypatch.setenv("LAGBENCH_CACHE", str(blocked / "cache"))
    monkeypatch.setattr(cache, "_UNWRITABLE", set())
    with caplog.at_level("WARNING"):
        s = systems.get("spring")
        qdd = s.acceleration(np.array([[0.5]]), np.array([[0.0]]), backend="numpy")
        data = datasets.iid_dataset("double_pendulum", 20, 3)
        datasets.iid_dataset("double_pendulum", 20, 4)
    np.testing.assert_allclose(qdd, [[-0.5]])
    assert len(data["qddot"]) == 20
    warned = [r.getMessage() for r in caplog.records if "cannot be written" in r.getMessage()]
    assert {str(blocked / "cache" / "codegen"), str(blocked / "cache" / "datasets")} == {
        w.split("the cache folder ", 1)[1].split(" cannot", 1)[0] for w in warned}
    assert len(warned) == 2, warned
