"""models.torch.inductor_cache: inductor's generated code goes to this user's own folder under the suite's
cache, never /tmp; a folder that others may write, or a symlink, is refused, and then nothing compiles:
training goes on eager (`tests/replication/training/test_compile_torch.py`), an AOT compile raises before
it starts."""
import os

import pytest

import lagbench.models.torch
from lagbench.models import ModelSpec, init_params
from lagbench.models.torch import inductor_cache
from lagbench.models.torch.compiled import compile_batched

pytestmark = pytest.mark.skipif(not hasattr(os, "getuid"), reason="POSIX owners and modes")


def _fresh(monkeypatch, root):
    monkeypatch.setenv(inductor_cache.ENV, "unused")   # restored (removed) after the test
    monkeypatch.delenv(inductor_cache.ENV)
    monkeypatch.setenv("LAGBENCH_CACHE", str(root))


def _refused(tmp_path, how, good):
    root = tmp_path / how
    if how == "symlink":
        root.mkdir()
        (root / "torchinductor").symlink_to(good)
    else:
        (root / "torchinductor").mkdir(parents=True)
        (root / "torchinductor").chmod(0o775)
    return root


def test_private_folder_under_the_suite_cache(monkeypatch, tmp_path):
    _fresh(monkeypatch, tmp_path / "cache")
    assert inductor_cache.private()
    folder = tmp_path / "cache" / "torchinductor"
    assert os.environ[inductor_cache.ENV] == str(folder.resolve()) and not folder.stat().st_mode & 0o077
    with inductor_cache.scratch("lagbench_test_") as tmp:
        assert tmp.parent == folder.resolve() and tmp.name.startswith("lagbench_test_") and tmp.is_dir()
    assert not tmp.exists()
    # a folder the user names in the environment is kept
    monkeypatch.setenv(inductor_cache.ENV, str(tmp_path / "mine"))
    assert inductor_cache.private() and os.environ[inductor_cache.ENV] == str(tmp_path / "mine")
    with inductor_cache.scratch("x") as tmp:
        assert tmp.parent == tmp_path / "mine"


@pytest.mark.parametrize("how", ["group-writable", "symlink"])
def test_a_folder_others_may_write_is_refused(monkeypatch, tmp_path, caplog, how):
    good = tmp_path / "good"
    good.mkdir(mode=0o700)
    _fresh(monkeypatch, _refused(tmp_path, how, good))
    assert not inductor_cache.private()
    assert inductor_cache.ENV not in os.environ
    assert "is not a folder of this user's that no one else may write" in caplog.text
    with pytest.raises(inductor_cache.InductorCacheError, match="no private folder for inductor's generated code"):
        with inductor_cache.scratch("x"):
            pass
    # an AOT compile stops before it exports anything
    spec = ModelSpec(kind="lnn", dof=2, hidden=(8,), dtype="float64", init="xavier", formulation="fast")
    m = lagbench.models.torch.build(spec, init_params(spec, seed=0))
    with pytest.raises(inductor_cache.InductorCacheError):
        compile_batched(m.acceleration, n_inputs=2, width=2, dtype="float64", name="acceleration")
    assert not any(good.iterdir())
