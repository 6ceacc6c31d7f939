"""Losing nothing: a run killed mid-unit resumes and ends with the same numbers as an uninterrupted one;
the same seed gives the same numbers twice; a corrupt result is rerun, not trusted."""
import json
import os
import signal
import subprocess
import sys
import time

from lagbench.files import results as R
from lagbench.replication.run.runner import run

ARGS = ["--profile", "smoke", "--claims", "dp_loss", "--quiet"]


def _metrics(out):
    return {str(p.relative_to(out)): json.loads(p.read_text())["metrics"]
            for p in sorted(out.glob("units/*/*/*/seed*/result.json"))}


def test_killed_run_resumes_to_the_same_numbers(smoke_results, tmp_path):
    """Killed between its two units, resumed: the numbers of the session's uninterrupted smoke run."""
    killed = tmp_path / "killed"
    cmd = [sys.executable, "-m", "lagbench", "run", *ARGS, "--frameworks", "jax", "--out"]
    proc = subprocess.Popen([*cmd, str(killed)], start_new_session=True)
    deadline = time.time() + 300
    while time.time() < deadline and not list(killed.glob("units/*/*/*/seed*/result.json")):
        time.sleep(0.2)
    os.killpg(proc.pid, signal.SIGKILL)  # mid-run: the first unit is done, the second is not
    proc.wait()
    done = list(killed.glob("units/*/*/*/seed*/result.json"))
    assert len(done) == 1, "expected the kill to land between the two units"
    subprocess.run([*cmd, str(killed)], check=True)
    a = _metrics(killed)
    b = {k: v for k, v in _metrics(smoke_results[0]).items() if k.startswith("units/dp_loss/jax/")}
    assert len(a) == 2 and a == b


def test_same_seed_same_numbers_in_torch(tmp_path):
    run(profile="smoke", out=tmp_path / "a", claims=["dp_loss"], frameworks=("torch",), models=["baseline"],
        progress=False)
    run(profile="smoke", out=tmp_path / "b", claims=["dp_loss"], frameworks=("torch",), models=["baseline"],
        progress=False)
    assert _metrics(tmp_path / "a") == _metrics(tmp_path / "b")


def test_corrupt_result_is_detected_and_rerun(tmp_path):
    run(profile="smoke", out=tmp_path, claims=["dp_loss"], frameworks=("jax",), models=["baseline"], progress=False)
    (f,) = tmp_path.glob("units/*/*/*/seed*/result.json")
    good = _metrics(tmp_path)
    d = json.loads(f.read_text())
    d["metrics"]["heldout_l1"] = 0.0  # tampered: the checksum no longer matches
    f.write_text(json.dumps(d))
    assert not R.is_finished(f.parent)
    (f.parent / "train_log.csv").write_text("truncated")
    run(profile="smoke", out=tmp_path, claims=["dp_loss"], frameworks=("jax",), models=["baseline"], progress=False)
    assert R.is_finished(f.parent) and _metrics(tmp_path) == good


def test_a_changed_protocol_reruns_and_keeps_the_old_result(tmp_path, monkeypatch):
    from lagbench.replication.claims import get

    kw = dict(profile="smoke", out=tmp_path, claims=["dp_loss"], frameworks=("jax",), models=["baseline"],
              progress=False)
    run(**kw)
    claim = get("dp_loss")
    monkeypatch.setitem(claim.protocols, "smoke", claim.protocols["smoke"].replace(steps=7))
    run(**kw)
    (new,) = tmp_path.glob("units/dp_loss/jax/baseline/seed1000/result.json")
    assert R.load_result(new.parent)["protocol"]["steps"] == 7
    (old,) = tmp_path.glob("units/dp_loss/jax/baseline/superseded-*-seed1000/result.json")
    assert R.load_result(old.parent)["protocol"]["steps"] == 20
    # train_steps counts every scout's steps as well (the smoke protocol scouts)
    assert R.load_result(new.parent)["train_steps"] - R.load_result(old.parent)["train_steps"] == 7 - 20


def test_a_dry_run_of_a_finished_folder_says_so_and_writes_nothing(tmp_path, monkeypatch, capsys):
    from lagbench.replication.claims import get

    kw = dict(profile="smoke", out=tmp_path, claims=["dp_loss"], frameworks=("jax",), models=["baseline"],
              progress=False)
    run(**kw)
    snapshot = lambda: sorted((str(p), p.stat().st_mtime_ns) for p in tmp_path.rglob("*"))  # noqa: E731
    before = snapshot()
    capsys.readouterr()
    assert run(**kw, dry_run=True) == {"dry_run": True, "units": 1, "todo": 0, "estimate": None}
    assert "1 units, every one finished" in capsys.readouterr().out
    claim = get("dp_loss")   # a changed protocol: the dry run counts the unit as to run, and still writes nothing
    monkeypatch.setitem(claim.protocols, "smoke", claim.protocols["smoke"].replace(steps=7))
    monkeypatch.setattr("lagbench.replication.run.runner.announce", lambda *a, **k: {"probed": True})
    assert run(**kw, dry_run=True)["todo"] == 1
    assert "nothing to run" not in capsys.readouterr().out
    assert snapshot() == before


def test_a_changed_evaluation_config_reruns_too(tmp_path, monkeypatch):
    from lagbench.replication.claims import get

    kw = dict(profile="smoke", out=tmp_path, claims=["dp_energy"], frameworks=("jax",), models=["baseline"],
              progress=False)
    run(**kw)
    claim = get("dp_energy")
    monkeypatch.setitem(claim.eval_config, "smoke", {**claim.eval_config["smoke"], "n_ics": 2})
    run(**kw)
    (new,) = tmp_path.glob("units/dp_energy/jax/baseline/seed1000/result.json")
    assert R.load_result(new.parent)["eval_config"]["n_ics"] == 2
    assert len(list(tmp_path.glob("units/dp_energy/jax/baseline/superseded-*-seed1000/result.json"))) == 1


def _release_calls(monkeypatch, tmp_path, budget):
    """(clear_caches calls, functions traced for compilation by each unit) of a JAX smoke run of a cohort of
    two seeds (one training, two units) releasing above `budget` mappings."""
    import jax
    import jax.monitoring

    from lagbench.replication.run import chains, runner, units
    calls, traced, per_unit = [], [], []
    real_clear, real_unit = jax.clear_caches, units.run_unit
    monkeypatch.setattr(jax, "clear_caches", lambda: (calls.append(1), real_clear()))
    monkeypatch.setattr(chains, "MAP_BUDGET", budget)

    def counted(*a, **k):
        before = len(traced)
        try:
            return real_unit(*a, **k)
        finally:
            per_unit.append(len(traced) - before)
    monkeypatch.setattr(units, "run_unit", counted)
    jax.monitoring.register_event_duration_secs_listener(
        lambda name, *a, **k: traced.append(1) if name == "/jax/core/compile/jaxpr_trace_duration" else None)
    runner.run(profile="smoke", out=tmp_path, claims=["init_study"], frameworks=("jax",),
               models=["lnn_init-kaiming"], progress=False)
    return len(calls), per_unit


def test_compiled_code_is_released_once_the_memory_map_is_crowded(tmp_path, monkeypatch):
    """JAX's compiled executables are dropped after a unit once the process holds more memory mappings than
    `MAP_BUDGET`: kept forever, they pile up until a long run dies at the kernel's per-process limit (a
    220-unit quick run did, at unit 202, when nothing was released). Below the budget they are kept, and
    the cohort's second member, whose training is the first's, compiles nothing: it reuses the first's
    evaluation programs; released, it compiles them again."""
    import os

    import pytest

    if not os.path.exists("/proc/self/maps"):
        pytest.skip("no /proc/self/maps on this system")
    released, per_unit = _release_calls(monkeypatch, tmp_path / "a", 0)
    assert released == len(per_unit) == 2
    assert per_unit[1] > 0
    kept, per_unit = _release_calls(monkeypatch, tmp_path / "b", 10**9)
    assert kept == 0
    assert per_unit[0] > 0 and per_unit[1] == 0, per_unit


def test_released_compilations_keep_the_memory_map_count_flat():
    """The mechanism behind the release, measured: adapters compiled one after another, released after
    each, leave the process's memory-map count where it was."""
    import os

    import numpy as np
    import pytest

    from lagbench.models import ModelSpec, init_params
    from lagbench.replication.evaluation.adapters import adapter
    from lagbench.replication.run.chains import map_count
    from lagbench.replication.run.executor import release_compiled

    if not os.path.exists("/proc/self/maps"):
        pytest.skip("no /proc/self/maps on this system")
    spec = ModelSpec(kind="lnn", dof=2, hidden=(8, 8), dtype="float32")
    q = np.random.default_rng(0).normal(size=(16, 2))
    counts = []
    for seed in range(6):
        adapter("jax", spec, init_params(spec, seed=seed)).acceleration(q, q, None)
        release_compiled()
        counts.append(map_count())
    assert max(counts[2:]) - min(counts[2:]) < 50, counts
