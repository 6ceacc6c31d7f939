"""The per-step training parity on a GPU, where both frameworks see one (skipped cleanly otherwise): every
default float64 row of the parity table (`parity_rows`) trained on the GPU in JAX and in PyTorch agrees at
every step as on the CPU, and each framework's GPU run agrees with its own CPU run."""
import pytest
from parity_kit import compare, trace, within
from parity_rows import F64

from lagbench.replication.training import device

GPU = all(device.gpu_seen(fw)[0] for fw in ("jax", "torch"))
pytestmark = pytest.mark.skipif(not GPU, reason="needs a GPU that both JAX and PyTorch see")
ROWS = [r for r in F64 if not r.slow]


def _on(framework, row, where="gpu"):
    with device.placed(framework, where):
        return trace(framework, row)


def _on_gpu(framework, row):
    return _on(framework, row)


@pytest.mark.parametrize("row", ROWS, ids=[r.name for r in ROWS])
def test_frameworks_agree_at_every_step_on_the_gpu(row):
    diffs, mismatches = compare(_on_gpu("jax", row), _on_gpu("torch", row))
    assert not mismatches, mismatches[:5]
    assert within(row, diffs), f"{diffs} beyond {row.tolerance}"


@pytest.mark.parametrize("framework", ["jax", "torch"])
def test_the_gpu_trains_as_the_cpu_does(framework):
    row = ROWS[0]
    diffs, mismatches = compare(_on(framework, row, "cpu"), _on_gpu(framework, row))
    assert not mismatches, mismatches[:5]
    assert within(row, diffs), f"{diffs} beyond {row.tolerance}"


@pytest.mark.parametrize("framework", ["jax", "torch"])
def test_a_unit_trains_and_is_evaluated_on_the_gpu(tmp_path, monkeypatch, framework):
    # the evaluation's model is built on the run's device, where its inputs are made (a PyTorch model built
    # outside it kept its parameters on the CPU and failed on CUDA inputs)
    from lagbench.replication.run.runner import plan
    from lagbench.replication.run.units import run_unit

    monkeypatch.setenv(device.ENV, "gpu")
    unit = next(u for u in plan("smoke", claims=["dp_loss"], frameworks=(framework,), models=["lnn"]))
    record = run_unit(unit, tmp_path)
    assert record["status"] == "ok" and record["metrics"]["heldout_l1"] > 0
    assert record["train_device"]["device"] == record["eval_device"]["device"] == "gpu"
