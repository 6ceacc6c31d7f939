"""`--device`: resolving a request per framework, the clear one-line error when a GPU is asked for and a
framework sees none (nothing written), the environment variable that carries the request to workers, the
context that places a training, what results record, and the Ray resources a device asks for."""
import subprocess
import sys

import numpy as np
import pytest

from lagbench.replication.training import device

NO_GPU = not any(device.gpu_seen(fw)[0] for fw in ("jax", "torch"))


def test_cpu_is_always_cpu_and_a_bad_request_is_refused(monkeypatch):
    assert device.resolve("cpu", "jax") == "cpu" and device.resolve("cpu", "torch") == "cpu"
    with pytest.raises(device.DeviceError, match="not a device"):
        device.resolve("tpu", "jax")
    monkeypatch.setenv(device.ENV, "tpu")
    with pytest.raises(device.DeviceError, match="LAGBENCH_DEVICE='tpu' is not a device"):
        device.request()
    monkeypatch.setenv(device.ENV, "cpu")
    assert device.request() == "cpu"
    monkeypatch.delenv(device.ENV)
    assert device.request() == "auto"


@pytest.mark.skipif(not NO_GPU, reason="this machine has a GPU")
def test_without_a_gpu_auto_takes_the_cpu_and_gpu_names_what_is_missing():
    assert device.check("auto", ("jax", "torch")) == {"jax": "cpu", "torch": "cpu"}
    with pytest.raises(device.DeviceError) as e:
        device.check("gpu", ("jax", "torch"))
    msg = str(e.value)
    assert "\n" not in msg and "JAX" in msg and "PyTorch" in msg and msg.endswith("use --device cpu or auto")


@pytest.mark.skipif(not NO_GPU, reason="this machine has a GPU")
@pytest.mark.parametrize("argv, framework", [
    (["run", "--profile", "smoke", "--frameworks", "torch", "--device", "gpu"], "PyTorch"),
    (["run", "--profile", "smoke", "--frameworks", "jax", "--device", "gpu"], "JAX"),
    (["fit", "--data", "none.csv", "--model", "lnn", "--frameworks", "torch", "--device", "gpu"], "PyTorch"),
    (["train-target", "--device", "gpu"], "JAX"),
    (["evaluate", "--fitted", "{fit}", "--data", "{data}", "--frameworks", "torch", "--device", "gpu"], "PyTorch"),
])
def test_a_gpu_asked_for_where_none_is_seen_is_one_line_and_writes_nothing(tmp_path, argv, framework, fitted):
    out = tmp_path / "out"
    argv = [a.format(fit=fitted["fit"], data=fitted["data"]) for a in argv]
    r = subprocess.run([sys.executable, "-m", "lagbench", *argv, "--out", str(out)], capture_output=True,
                       text=True, cwd=tmp_path, timeout=300)
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("lagbench: error: --device gpu: ") and framework in lines[0]
    assert not out.exists() and list(tmp_path.iterdir()) == []


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    """A tiny fit of simulated data (for `evaluate`), made on the CPU."""
    from lagbench.replication.fit.simulate import simulate
    from lagbench.replication.fit.task import fit

    root = tmp_path_factory.mktemp("fitted")
    data = root / "pendulum.csv"
    simulate("pendulum", trajectories=3, duration=1.0, rate=20.0, seed=0).to_csv(data, index=False)
    fit(str(data), model="baseline", out=str(root / "fit"), framework="torch", steps=3, hidden=(8,), batch=8)
    return {"fit": str(root / "fit"), "data": str(data)}


def test_placed_on_the_cpu_leaves_both_frameworks_where_they_were():
    import jax.numpy as jnp
    import torch

    before = torch.get_default_device()
    with device.placed("torch", "cpu"):
        assert torch.zeros(1).device.type == "cpu"
    with device.placed("jax", "cpu"):
        x = jnp.ones(3)
        assert {d.platform for d in x.devices()} == {"cpu"}
    assert torch.get_default_device() == before


def test_describe_records_the_device():
    d = device.describe("torch", "cpu")
    assert d["device"] == "cpu" and d["float32_matmul"] == "full float32"


def test_a_training_records_where_it_computed(tmp_path, monkeypatch):
    from lagbench.models import ModelSpec
    from lagbench.replication.training.protocol import Data, Protocol
    from lagbench.replication.training.train import train_cached

    monkeypatch.setenv(device.ENV, "cpu")
    spec = ModelSpec(kind="baseline", dof=1, hidden=(8,), activation="tanh", init="xavier")
    p = Protocol(data=Data("spring_iid", n_train=16, n_heldout=8), steps=3, batch=4, log_every=1)
    for fw in ("jax", "torch"):
        out = train_cached(tmp_path, fw, spec, p, 0)
        assert out.device["device"] == "cpu" and np.isfinite(out.log[-1]["loss"])
        again = train_cached(tmp_path, fw, spec, p, 0)     # from the cache, with its record
        assert again.device == out.device


def test_ray_tasks_ask_for_a_gpu_share_in_either_framework_unless_the_cpu_is_asked_for():
    from lagbench.replication.run.executor_ray import resources
    from lagbench.replication.run.runner import plan

    for unit in plan("smoke", claims=["dp_loss"]):
        assert resources(unit, 1.0)["num_gpus"] > 0
        assert resources(unit, 1.0, "cpu")["num_gpus"] == 0
        assert resources(unit, 0.0)["num_gpus"] == 0
