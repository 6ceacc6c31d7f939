"""`lagbench bench --gpu` without a GPU, presets that name their stages, training at extra batches, and JAX's
row blocking (CPU only). The GPU run itself needs a CUDA machine; its measured results are checked in
tests/reports/test_gpu_section.py."""
import json
from dataclasses import replace

import jax
import jax.numpy as jnp
import numpy as np
import pytest
import torch

from lagbench.cli import main
from lagbench.models.jax import blocking
from lagbench.speedstudy import run_bench
from lagbench.speedstudy.device import NoGPUError
from lagbench.speedstudy.timing import GPU, GPU_TINY, STAGES, TINY


@pytest.mark.skipif(torch.cuda.is_available(), reason="this machine has a GPU")
def test_gpu_run_without_a_gpu_is_refused_before_writing(tmp_path, capsys):
    with pytest.raises(NoGPUError, match="PyTorch .* sees no CUDA device"):
        run_bench(tmp_path, gpu=True, progress=False)
    assert not (tmp_path / "bench_gpu").exists()
    assert main(["bench", "--gpu", "--out", str(tmp_path)]) == 2
    assert "needs a CUDA GPU" in capsys.readouterr().err
    assert not (tmp_path / "bench_gpu").exists()


def test_gpu_presets_name_known_stages():
    for sizes in (GPU, GPU_TINY):
        assert sizes.stages and set(sizes.stages) <= set(STAGES)
        assert not sizes.torch_compile


def test_unknown_stage_is_an_error(tmp_path):
    with pytest.raises(ValueError, match="unknown stages"):
        run_bench(tmp_path, sizes=replace(TINY, stages=("inferance",)), progress=False)
    assert not (tmp_path / "bench").exists()


def test_only_the_preset_stages_run(tmp_path):
    targets = run_bench(tmp_path, sizes=replace(TINY, stages=("training",), train_extra_batches=(64,)),
                        progress=False)
    bench = tmp_path / "bench"
    assert (bench / "training.csv").is_file()
    assert not any((bench / f"{f}.csv").exists() for f in ("inference", "rollout", "scaling", "fast_paper"))
    import pandas as pd
    tr = pd.read_csv(bench / "training.csv")
    assert sorted(set(tr["batch"])) == [TINY.train_batch, 64]
    assert len(tr) == 2 * 2 * 2  # 2 models x (jax, torch eager) x 2 batches
    assert set(targets["training_samples_per_s"]) == {f"{m}/{fw}/batch {b}" for m in ("lnn", "baseline")
                                                      for fw in ("jax/jit", "torch/eager") for b in (32, 64)}
    ratios = pd.read_csv(bench / "ratios.csv")
    assert ratios["operation"].str.contains("batch 64 \\(steps/s\\)").sum() == 2
    machine = json.loads((bench / "machine.json").read_text())
    assert machine["stages"] == ["training"] and machine["device"] == "cpu"


def test_row_blocks_only_on_the_cpu(monkeypatch):
    calls = []

    def fn(x):
        calls.append(x.shape[0])
        return x * 2.0
    x = jnp.arange(10_000.0)[:, None]
    out = blocking.in_row_blocks(fn, [x], rows_per_sample=1)
    assert len(set(calls)) == 1 and calls[0] < 10_000  # lax.map traces one block
    calls.clear()
    monkeypatch.setattr(jax, "default_backend", lambda: "gpu")
    out_gpu = blocking.in_row_blocks(fn, [x], rows_per_sample=1)
    assert calls == [10_000]
    np.testing.assert_array_equal(np.asarray(out), np.asarray(out_gpu))


def test_stages_argument_runs_only_those_stages_and_refuses_unknown_names(tmp_path, capsys):
    run_bench(tmp_path, sizes=TINY, stages=["fast-vs_paper"], progress=False)
    bench = tmp_path / "bench"
    assert (bench / "fast_paper.csv").is_file() and (bench / "matmul.csv").is_file()
    assert not any((bench / f"{f}.csv").exists() for f in ("inference", "latency", "training", "rollout", "scaling"))
    assert json.loads((bench / "machine.json").read_text())["stages"] == ["fast vs paper"]
    other = tmp_path / "other"
    assert main(["bench", "--stages", "control-rate,inferance", "--out", str(other)]) == 2
    assert "unknown stages ['inferance']" in capsys.readouterr().err
    assert not (other / "bench").exists()
