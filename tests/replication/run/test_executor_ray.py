"""Units as tasks on a real local Ray instance (2 CPUs, started once for this module): the local executor's
numbers; marked slow: a killed worker retried, an interrupted driver resumed, past its retries a unit
recorded as an error and redone by a rerun, and Ctrl-C on the command line joining with --address.
Three PyTorch smoke units, two sharing one trained model (a chain). A worker's first unit costs seconds
(imports, first compilations), and every killed worker is a new one."""
import json
import os
import signal
import subprocess
import sys
import threading
import time
import warnings
from pathlib import Path

import pandas as pd
import pytest

from lagbench.replication.run import executor_ray, runner

ray = pytest.importorskip("ray", reason="Ray is an optional extra (pip install 'lagbench[ray]')")

KW = dict(profile="smoke", claims=["dp_loss", "dp_energy", "appendix_b"], models=["baseline", "lnn_exact_fast"],
          frameworks=("torch",), progress=False)


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    """A local Ray instance; its workers start in an empty folder (`cwd`, the driver's working directory
    when Ray started) and keep their caches under `worker` (LAGBENCH_WORKER_DIR)."""
    worker, cwd = tmp_path_factory.mktemp("ray-worker"), tmp_path_factory.mktemp("driver-cwd")
    saved = os.environ.get("LAGBENCH_WORKER_DIR"), os.getcwd()
    os.environ["LAGBENCH_WORKER_DIR"] = str(worker)
    os.chdir(cwd)
    try:
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message=".*os.fork", category=RuntimeWarning)
            ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, logging_level="WARNING")
    finally:
        os.chdir(saved[1])
    yield {"address": ray.get_runtime_context().gcs_address, "worker": worker, "cwd": cwd}
    ray.shutdown()
    os.environ.pop("LAGBENCH_WORKER_DIR") if saved[0] is None else os.environ.__setitem__("LAGBENCH_WORKER_DIR", saved[0])


def table(out):
    df = pd.read_csv(Path(out) / "summary" / "units.csv").sort_values(["claim", "model", "seed"])
    return df.drop(columns=[c for c in df.columns if "time" in c or "per_s" in c]).reset_index(drop=True)


@pytest.fixture(scope="module")
def local(tmp_path_factory):
    """The local executor's table, with PyTorch on one thread as in a Ray task, so that the numbers are
    the same to the last bit."""
    import torch

    out, threads = tmp_path_factory.mktemp("local"), torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        runner.run(out=out, **KW)
    finally:
        torch.set_num_threads(threads)
    return table(out)


def same(local, out):
    pd.testing.assert_frame_equal(local, table(out), check_exact=True)


def unit_tasks(worker, name_part):
    """pids of Ray workers of this module's instance running a unit task whose name holds `name_part`."""
    pids = []
    for d in Path("/proc").iterdir():
        try:
            title = (d / "cmdline").read_bytes()
            mine = f"LAGBENCH_WORKER_DIR={worker}\0".encode() in (d / "environ").read_bytes()
        except OSError:
            continue
        if mine and title.startswith(b"ray::lagbench ") and name_part.encode() in title:
            pids.append(int(d.name))
    return pids


def title(pid):
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes()
    except OSError:
        return b""


def stop_one(worker, name_part, stopped, done, proc=None):
    """Stop (SIGSTOP) the first worker seen running the unit; a stopped task cannot finish meanwhile.
    Gives up when `done` is set or `proc` (a driver) has exited."""
    while not done.is_set() and not stopped and (proc is None or proc.poll() is None):
        for pid in unit_tasks(worker, name_part):
            os.kill(pid, signal.SIGSTOP)
            if title(pid).startswith(b"ray::lagbench "):   # still on that task once stopped: hold it
                stopped.append(pid)
                return
            os.kill(pid, signal.SIGCONT)
        time.sleep(0.01)


def kill_one(worker, name_part, killed, done):
    stop_one(worker, name_part, killed, done)
    for pid in killed:
        os.kill(pid, signal.SIGKILL)


def run_killing(worker, out, name_part="dp_loss"):
    killed, done = [], threading.Event()
    t = threading.Thread(target=kill_one, args=(worker, name_part, killed, done))
    t.start()
    try:
        return runner.run(out=out, executor="ray", **KW), killed
    finally:
        done.set()
        t.join()


def units_run(out):
    return json.loads((Path(out) / "run.json").read_text())["units_run"]


def test_ray_gives_the_local_numbers_and_writes_only_where_told(cluster, local, tmp_path):
    s = runner.run(out=tmp_path, executor="ray", **KW)
    assert s["errors"] == []
    same(local, tmp_path)
    assert len(local) == 3
    assert json.loads((tmp_path / "run.json").read_text())["executor"] == "ray"
    assert list(cluster["cwd"].iterdir()) == []                      # the workers' working directory
    assert list((cluster["worker"] / "scratch").iterdir()) == []     # scratch folders removed
    assert any((cluster["worker"] / "cache").rglob("*.py"))          # the generated code, built there


@pytest.mark.slow
def test_a_killed_worker_is_retried(cluster, local, tmp_path):
    s, killed = run_killing(cluster["worker"], tmp_path)
    assert killed, "no worker was seen running the unit"
    assert s["errors"] == []
    same(local, tmp_path)


@pytest.mark.slow
def test_past_its_retries_a_unit_is_an_error_and_a_rerun_redoes_it(cluster, local, tmp_path, monkeypatch):
    """With no retries, a killed unit is an error, and the unit after it in its chain is not run."""
    monkeypatch.setattr(executor_ray, "RETRIES", 0)
    s, killed = run_killing(cluster["worker"], tmp_path)
    assert killed, "no worker was seen running the unit"
    errors = sorted(s["errors"])
    assert len(errors) == 2, errors
    assert errors[0].startswith("dp_energy/torch/baseline/seed1000: not run: dp_loss/torch/baseline/seed1000")
    assert errors[1].startswith("dp_loss/torch/baseline/seed1000: worker stopped (1 attempts): ")
    assert not (tmp_path / "units" / "dp_loss").exists()
    monkeypatch.undo()
    s = runner.run(out=tmp_path, executor="ray", **KW)
    assert s["errors"] == [] and units_run(tmp_path) == 2
    same(local, tmp_path)


def interrupt_when_written(worker, out, target, held, done):
    """Hold the chain's first unit stopped; once the untrained unit is written, Ctrl-C this process."""
    stop_one(worker, "dp_loss", held, done)
    written = Path(out) / "units" / "appendix_b" / "torch" / "lnn_exact_fast" / "seed1000" / "result.json"
    while not done.is_set() and not written.exists():
        time.sleep(0.02)
    if not done.is_set():
        signal.pthread_kill(target, signal.SIGINT)


@pytest.mark.slow   # on a loaded machine Ray's keepalive watchdog declares the held (stopped) worker dead and
# retries its unit before the interrupt lands (seen once: 458 s, no KeyboardInterrupt)
def test_an_interrupted_driver_leaves_a_folder_that_resumes(cluster, local, tmp_path):
    held, done = [], threading.Event()
    t = threading.Thread(target=interrupt_when_written,
                         args=(cluster["worker"], tmp_path, threading.main_thread().ident, held, done))
    t.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            runner.run(out=tmp_path, executor="ray", **KW)
    finally:
        done.set()
        t.join()
        release(held)
    assert held, "no worker was seen running the unit"
    assert json.loads((tmp_path / "run.json").read_text())["interrupted"]
    assert not (tmp_path / "units" / "dp_loss").exists()
    s = runner.run(out=tmp_path, executor="ray", **KW)
    assert s["errors"] == [] and units_run(tmp_path) == 2
    same(local, tmp_path)


def release(held):
    for pid in held:   # the driver's cancellation killed it; if not, let it go on
        if title(pid).startswith(b"ray::"):
            os.kill(pid, signal.SIGCONT)


@pytest.mark.slow
def test_ctrl_c_on_a_driver_joining_with_address(cluster, local, tmp_path):
    """The command line, as another process joining the instance with --address, interrupted (SIGINT)
    while the chain's first unit is held stopped and once the untrained unit is written."""
    env = {**os.environ, "LAGBENCH_WORKER_DIR": str(cluster["worker"])}
    cmd = [sys.executable, "-m", "lagbench", "run", "--profile", "smoke", "--claims", ",".join(KW["claims"]),
           "--models", ",".join(KW["models"]), "--frameworks", "torch", "--out", str(tmp_path), "--quiet",
           "--executor", "ray", "--address", cluster["address"]]
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    held, done = [], threading.Event()
    try:
        stop_one(cluster["worker"], "dp_loss", held, done, proc)
        assert held, f"no worker was seen running the unit; the driver said: {proc.communicate()[1]}"
        written = tmp_path / "units" / "appendix_b" / "torch" / "lnn_exact_fast" / "seed1000" / "result.json"
        while not written.exists() and proc.poll() is None:
            time.sleep(0.05)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=120)
    finally:
        release(held)
    assert proc.returncode == 130, err
    assert "interrupted; finished units are kept" in err
    assert json.loads((tmp_path / "run.json").read_text())["interrupted"]
    assert not (tmp_path / "units" / "dp_loss").exists()
    s = runner.run(out=tmp_path, executor="ray", **KW)
    assert s["errors"] == [] and units_run(tmp_path) == 2
    same(local, tmp_path)


def test_without_ray_the_error_says_how_to_install_it(monkeypatch, tmp_path):
    monkeypatch.setitem(sys.modules, "ray", None)   # import ray -> ImportError
    with pytest.raises(ValueError, match=r"pip install 'lagbench\[ray\]'"):
        runner.run(out=tmp_path / "out", executor="ray", **KW)
    assert not (tmp_path / "out").exists()


def test_options_of_the_wrong_executor_are_refused(tmp_path):
    with pytest.raises(ValueError, match="--address is for --executor ray"):
        runner.run(out=tmp_path, address="auto", **KW)
    with pytest.raises(ValueError, match="--jobs is for the local executor"):
        runner.run(out=tmp_path, executor="ray", jobs=2, **KW)
    assert list(tmp_path.iterdir()) == []
