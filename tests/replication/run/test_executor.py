"""Units in parallel worker processes: the same numbers as one after another, and a model shared by two
claims trained once (its units form one chain)."""
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest
from inline_workers import inline_workers

from lagbench.replication.run import executor, runner
from lagbench.replication.run.environment import one_thread_env
from lagbench.replication.run.same_numbers import TIMING

CLAIMS = ["dp_loss", "dp_energy", "appendix_b"]


def test_units_sharing_a_model_form_one_chain():
    todo = runner.plan("smoke", claims=CLAIMS, frameworks=("jax", "torch"))
    chains = executor.chains(todo)
    assert sorted(u.name for c in chains for u in c) == sorted(u.name for u in todo)
    shared = [c for c in chains if len(c) > 1]
    assert shared and all({u.claim.id for u in c} == {"dp_loss", "dp_energy"} for c in shared)
    assert all(len({(u.framework, u.entry.label, u.seed) for u in c}) == 1 for c in shared)
    assert [executor._cost(c) for c in chains] == sorted((executor._cost(c) for c in chains), reverse=True)


def test_a_unit_named_across_processes_keeps_its_own_models():
    """A search's configuration (a claim whose models are not the written ones) reaches a worker as itself; a
    run's unit as the claim resolves it."""
    import dataclasses

    from lagbench.replication.claims import get
    from lagbench.replication.run.chains import ref, unit_of
    from lagbench.replication.run.units import Unit
    from lagbench.replication.tuning import search

    todo = runner.plan("smoke", claims=["dp_loss"], frameworks=("jax",))
    u = todo[0]
    back = unit_of(ref(u))
    assert ref(u)[-1] is None and back.entry == u.entry and back.name == u.name
    claim = get("dp_loss")
    models = tuple(search.apply(e, claim.protocol("smoke"), "smoke", {"lr": 3.0, "width": 2.0}) for e in claim.models)
    variant = Unit(dataclasses.replace(claim, models=models), models[0], "jax", 0, "smoke")
    back = unit_of(ref(variant))
    assert back.entry == models[0] != claim.models[0] and back.claim.models == models
    assert back.protocol() == variant.protocol() and back.entry.widths("smoke") == models[0].widths("smoke")


# a scouted training and untrained evaluations: two kinds of chain, three chains for two workers
CLAIMS_2, MODELS_2 = ["dp_loss", "appendix_b"], ["baseline", "lnn_exact_fast", "lnn_exact_paper"]


def _jax_rows(df, claims, models):
    df = df[df["claim"].isin(claims) & df["model"].isin(models) & (df["framework"] == "jax")]
    return df.sort_values(["claim", "model", "seed"]).reset_index(drop=True)


def test_two_workers_give_the_serial_numbers(smoke_results, tmp_path):
    """Against the session's serial smoke run (every claim, one after another in this process)."""
    runner.run(profile="smoke", out=tmp_path / "two", claims=CLAIMS_2, frameworks=("jax",), models=MODELS_2,
               progress=False, jobs=2)
    a, b = (_jax_rows(pd.read_csv(d / "summary" / "units.csv"), CLAIMS_2, MODELS_2)
            for d in (smoke_results[0], tmp_path / "two"))
    timing = list(TIMING)   # the wall-clock columns (not, e.g., the Lyapunov time)
    a = a.drop(columns=timing).dropna(axis="columns", how="all")   # the serial run's table has every claim's columns
    pd.testing.assert_frame_equal(a, b.drop(columns=timing)[a.columns])
    assert len(a) == len(runner.plan("smoke", claims=CLAIMS_2, frameworks=("jax",), models=MODELS_2)) == 3


def test_a_lone_unit_at_two_jobs_trains_in_a_worker(monkeypatch, tmp_path):
    """A single unit left at jobs 2 (a resumed search's last one) keeps the workers' one-thread rounding."""
    seen = []
    monkeypatch.setattr(executor, "_serial", lambda *a: pytest.fail("trained in this process"))
    monkeypatch.setattr(executor, "_parallel", lambda todo, *a: seen.append(len(todo)) or ([], []))
    unit = runner.plan("smoke", claims=["appendix_b"], frameworks=("jax",))[:1]
    assert executor.run_units(unit, tmp_path, "smoke", progress=False, jobs=2) == ([], [])
    assert seen == [1]
    monkeypatch.setattr(executor, "_serial", lambda *a: seen.append("serial") or ([], []))
    executor.run_units(unit, tmp_path, "smoke", progress=False, jobs=1)
    assert seen == [1, "serial"]


def test_jobs_must_be_a_positive_integer(tmp_path):
    with pytest.raises(ValueError, match="--jobs"):
        runner.run(profile="smoke", out=tmp_path, claims=["appendix_b"], jobs=0)
    assert not (tmp_path / "run.json").exists()


def test_workers_run_on_one_thread_and_the_parent_keeps_its_settings(monkeypatch):
    """The workers start (on demand, as chains are submitted) with one-thread settings; the parent's
    environment is as it was afterwards."""
    import os

    monkeypatch.delenv("OMP_NUM_THREADS", raising=False)
    monkeypatch.delenv("XLA_FLAGS", raising=False)
    seen = {}

    monkeypatch.setattr(executor, "_Workers",   # noting the environment a worker would start with
                        inline_workers(lambda: seen.update({k: os.environ.get(k) for k in one_thread_env({})})))
    todo = runner.plan("smoke", claims=["appendix_b", "dp_loss"], frameworks=("jax",))
    failures, errors = executor.run_units(todo, "unused", "smoke", progress=False, jobs=2)
    assert failures == [] and errors == []
    assert seen == one_thread_env({})
    assert "OMP_NUM_THREADS" not in os.environ


def _children(pid):
    out = []
    for d in Path("/proc").iterdir():
        try:
            if d.name.isdigit() and int((d / "stat").read_text().rsplit(")", 1)[1].split()[1]) == pid:
                out.append(int(d.name))
        except (OSError, ValueError, IndexError):
            continue
    return out


def _workers(pid) -> list[int]:
    """The process pool's workers among `pid`'s children; a child that exits while it is read (a short-lived
    helper) is not one."""
    out = []
    for c in _children(pid):
        try:
            if b"spawn_main" in Path(f"/proc/{c}/cmdline").read_bytes():
                out.append(c)
        except OSError:
            continue
    return out


def _running(pid) -> bool:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except (OSError, IndexError):
        return False


@pytest.mark.skipif(not Path("/proc").is_dir(), reason="reads /proc to find the driver's workers")
def test_workers_exit_when_their_driver_is_killed(tmp_path):
    """SIGKILL on the driver (a scheduler's time limit, `kill -9`) as soon as its two workers exist: they
    exit, and write no unit (left alone, each would finish its chain first)."""
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "lagbench", "run", "--profile", "smoke", "--claims", "dp_loss,appendix_b",
           "--frameworks", "jax", "--jobs", "2", "--quiet", "--out", str(out)]
    driver = subprocess.Popen(cmd, start_new_session=True)
    try:
        deadline, workers = time.time() + 120, []
        while time.time() < deadline and len(workers) < 2 and driver.poll() is None:
            workers = _workers(driver.pid)
            time.sleep(0.05)
        assert len(workers) == 2, "the driver's two workers never started"
    finally:   # the driver never outlives the test, whatever it asserts
        driver.kill()
        driver.wait()
    deadline = time.time() + 60
    while time.time() < deadline and any(_running(w) for w in workers):
        time.sleep(0.1)
    alive = [w for w in workers if _running(w)]
    for w in alive:
        os.kill(w, signal.SIGKILL)
    assert not alive, "workers kept running after their driver was killed"
    assert not list(out.glob("units/*/*/*/seed*/result.json")), "a worker went on to finish a unit"


@pytest.mark.skipif(not Path("/proc").is_dir(), reason="reads /proc to find the workers")
def test_a_dead_worker_loses_only_its_chain(tmp_path):
    """SIGKILL on one worker (as the out-of-memory killer would) while it holds its first chain: that
    chain's unit is an error naming the worker's end, a new worker takes the remaining chains, and every
    other unit is written."""
    import threading

    todo = runner.plan("smoke", claims=CLAIMS_2, frameworks=("jax",), models=MODELS_2)
    killed = []

    def kill_first_worker():
        deadline = time.time() + 120
        while time.time() < deadline:
            workers = _workers(os.getpid())
            if workers:
                time.sleep(1.0)   # it holds its first chain from the start; importing JAX alone takes longer
                os.kill(workers[0], signal.SIGKILL)
                killed.append(workers[0])
                return
            time.sleep(0.05)

    t = threading.Thread(target=kill_first_worker, daemon=True)
    t.start()
    failures, errors = executor.run_units(todo, tmp_path, "smoke", progress=False, jobs=2)
    t.join(timeout=5)
    assert killed, "no worker started"
    assert failures == [] and len(errors) == 1 and "worker stopped (exit code -9)" in errors[0], errors
    lost = errors[0].split(":", 1)[0]
    written = {f"{p.parts[-5]}/{p.parts[-4]}/{p.parts[-3]}/{p.parts[-2]}"
               for p in tmp_path.glob("units/*/*/*/seed*/result.json")}
    assert written == {u.name for u in todo} - {lost}


_XLA_POOL = """
import os, sys
from lagbench.replication.run import environment as env
if sys.argv[1] == "held":
    env.one_thread_jax()
import jax, jax.numpy as jnp
x = jnp.ones((256, 256))
jax.jit(lambda x: jnp.tanh(x @ x) @ x)(x).block_until_ready()
pool = sum("XLAEigen" in open(f"/proc/self/task/{t}/comm").read() for t in os.listdir("/proc/self/task"))
print(pool, env.hardware()["jax_threads"], sorted(os.sched_getaffinity(0)) == sorted(range(os.cpu_count())))
"""


@pytest.mark.skipif(not hasattr(os, "sched_getaffinity") or len(os.sched_getaffinity(0)) < 2,
                    reason="needs Linux and two CPUs")
def test_a_worker_start_gives_xla_one_thread_on_every_core():
    """XLA sizes its CPU pool to the CPUs a process may use when JAX's backend starts, whatever XLA_FLAGS say
    (the control: a process started with `ONE_CORE_XLA` alone has a thread a CPU); `one_thread_jax`, which a
    worker's start calls, leaves one, and gives the process every CPU back."""
    env = {**os.environ, **one_thread_env(os.environ)}
    out = {how: subprocess.run([sys.executable, "-c", _XLA_POOL, how], capture_output=True, text=True, env=env,
                               check=True).stdout.split() for how in ("held", "flags")}
    cpus = len(os.sched_getaffinity(0))
    if out["flags"][0] == "0":
        pytest.skip("XLA's pool threads are not named XLAEigen in this jaxlib")
    assert out["flags"][:2] == [str(cpus), str(cpus)]
    assert out["held"] == ["1", "1", "True"]
