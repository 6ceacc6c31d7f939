"""JAX's persistent compilation cache (`replication.run.jax_cache`): a private folder per host and install
under LAGBENCH_CACHE, refused where it is not this user's own, and read back by a second process."""
import json
import os
import subprocess
import sys

import pytest

from lagbench.replication.run import jax_cache

# One process: point JAX at the cache as `lagbench` does, compile one program, say whether it was read back.
PROBE = """
import json, sys
from lagbench.replication.run import jax_cache
jax_cache.MIN_COMPILE_S = 0.0   # keep even this small program
on = jax_cache.private()
import jax, jax.numpy as jnp, jax.monitoring as mon
hits = []
mon.register_event_listener(lambda ev, **kw: hits.append(ev) if ev.endswith("cache_hits") else None)
y = jax.jit(lambda x: jnp.sin(x) * jnp.cos(x) + x ** 3)(jnp.arange(5.0))
print(json.dumps({"on": on, "hit": bool(hits), "dir": jax.config.jax_compilation_cache_dir, "y": float(y.sum())}))
"""


def _probe(cache, **env) -> dict:
    base = {k: v for k, v in os.environ.items() if not k.startswith(("JAX_", "LAGBENCH_"))}
    out = subprocess.run([sys.executable, "-c", PROBE], env={**base, "LAGBENCH_CACHE": str(cache), **env},
                         capture_output=True, text=True, timeout=120, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_a_second_process_reads_the_programs_the_first_compiled(tmp_path):
    first, second = _probe(tmp_path), _probe(tmp_path)
    folder = tmp_path / "jax-compiled" / jax_cache.host_digest()
    assert first["on"] and first["dir"] == str(folder) and not first["hit"]
    assert any(folder.iterdir())
    assert second["hit"] and second["y"] == first["y"]
    assert oct(folder.stat().st_mode & 0o777) == oct(0o700)


def test_off_or_set_by_the_user_writes_nothing_there(tmp_path):
    off = _probe(tmp_path, LAGBENCH_JAX_CACHE="0")
    assert not off["on"] and not off["dir"] and not (tmp_path / "jax-compiled").exists()
    mine = tmp_path / "mine"
    mine.mkdir()
    kept = _probe(tmp_path, JAX_COMPILATION_CACHE_DIR=str(mine))
    assert kept["on"] and kept["dir"] == str(mine) and not (tmp_path / "jax-compiled").exists()


@pytest.mark.parametrize("how", ["others_may_write", "symlink"])
def test_a_folder_that_is_not_this_users_own_is_not_used(tmp_path, monkeypatch, how):
    monkeypatch.setenv("LAGBENCH_CACHE", str(tmp_path / "cache"))
    root = tmp_path / "cache" / "jax-compiled"
    if how == "symlink":
        (tmp_path / "elsewhere").mkdir(mode=0o700)
        root.parent.mkdir()
        root.symlink_to(tmp_path / "elsewhere")
    else:
        root.mkdir(parents=True)
        root.chmod(0o777)
    assert jax_cache.folder() is None
    assert not any((tmp_path / "elsewhere" if how == "symlink" else root).iterdir())   # nothing made inside it


def test_the_folder_is_named_by_the_install_and_the_cpu(monkeypatch):
    here = jax_cache.host_digest()
    monkeypatch.setattr(jax_cache, "cpu_description", lambda text: {"cpu": "x", "cpu_model": "y", "cpu_features": "avx"})
    other_cpu = jax_cache.host_digest()
    monkeypatch.setattr(jax_cache.importlib.metadata, "version", lambda name: "0.0.1")
    other_jax = jax_cache.host_digest()
    assert len({here, other_cpu, other_jax}) == 3


def test_a_command_that_compiles_nothing_makes_no_cache_folder(tmp_path, monkeypatch, capsys):
    from lagbench.cli import main

    monkeypatch.delenv("JAX_COMPILATION_CACHE_DIR")   # set for the test run by conftest.py
    monkeypatch.setenv("LAGBENCH_CACHE", str(tmp_path))
    assert main(["list"]) == 0
    assert not (tmp_path / "jax-compiled").exists() and "JAX_COMPILATION_CACHE_DIR" not in os.environ
