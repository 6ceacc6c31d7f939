"""The report's GPU section reads ROOT/bench_gpu/ (`lagbench bench --gpu`); fed here the H100 measurements
kept in docs/speed/gpu_h100/, so that they stay loadable."""
import shutil
from pathlib import Path

import pandas as pd
import pytest

from lagbench.reports.compare import gpu_vs_cpu_table
from lagbench.reports.load import load_results
from lagbench.reports.sections_speed import speed_sections

MEASURED = Path(__file__).resolve().parents[2] / "docs" / "speed" / "gpu_h100"


def _cpu_inference(root):
    (root / "bench").mkdir(parents=True)
    rows = [{"system": "double_pendulum", "model": "lnn", "formulation": "fast", "framework": fw, "mode": mode,
             "dtype": "float32", "batch": b, "samples_per_s": rate, "error": 1.0}
            for fw, mode, b, rate in (("jax", "jit", 4096, 1e5), ("torch", "eager", 4096, 5e4),
                                      ("torch", "aoti", 4096, 8e4), ("jax", "jit", 256, 1e4))]
    pd.DataFrame(rows).to_csv(root / "bench" / "inference.csv", index=False)


def test_measured_gpu_results_load_and_make_their_section(tmp_path):
    root = tmp_path / "res"
    shutil.copytree(MEASURED, root / "bench_gpu")
    _cpu_inference(root)
    res = load_results(root)
    assert {"inference", "training", "scaling", "ratios", "fast_paper"} <= set(res.bench_gpu)
    assert res.machine_gpu["device"] == "cuda" and "H100" in res.machine_gpu["gpu"]
    assert not [p for p in res.problems if "bench_gpu" in p]
    sections = speed_sections(res, tmp_path / "rep")
    gpu = next(s for s in sections if s.title.startswith("Speed study on a GPU"))
    titles = [getattr(b, "title", "") for b in gpu.blocks]
    assert "GPU: training throughput" in titles
    assert (tmp_path / "rep" / "figures" / "bench_gpu_inference.png").stat().st_size > 0
    both = next(b for b in gpu.blocks if getattr(b, "title", "").startswith("Inference on the GPU against"))
    assert set(both.df["framework"]) == {"jax", "torch"} and set(both.df["batch"]) == {4096}


def test_gpu_over_cpu_uses_each_frameworks_fastest_mode(tmp_path):
    root = tmp_path / "res"
    _cpu_inference(root)
    (root / "bench_gpu").mkdir()
    pd.DataFrame([{"system": "double_pendulum", "model": "lnn", "formulation": "fast", "framework": fw,
                   "mode": "jit" if fw == "jax" else "eager", "dtype": "float32", "batch": 4096,
                   "samples_per_s": rate, "error": 1.0} for fw, rate in (("jax", 2e6), ("torch", 4e5))]
                 ).to_csv(root / "bench_gpu" / "inference.csv", index=False)
    t = gpu_vs_cpu_table(load_results(root)).set_index("framework")
    assert float(t.loc["jax", "GPU / CPU"]) == pytest.approx(20.0)
    assert float(t.loc["torch", "GPU / CPU"]) == pytest.approx(5.0)  # against the CPU's aoti, its fastest mode


def test_no_gpu_section_without_the_folder(tmp_path):
    root = tmp_path / "res"
    _cpu_inference(root)
    res = load_results(root)
    assert gpu_vs_cpu_table(res) is None
    assert not any(s.title.startswith("Speed study on a GPU") for s in speed_sections(res, tmp_path / "rep"))
