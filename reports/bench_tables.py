"""The speed study's tables in a results folder: ``bench/`` (`lagbench bench`), ``bench_gpu/`` (`lagbench bench
--gpu`) and ``train_target/`` (`lagbench train-target`). ``load_bench(res)`` reads each CSV that exists and has
its columns (``BENCH_COLUMNS``, ``GPU_COLUMNS``, ``TRAIN_TARGET_COLUMNS``) into ``res``, and the machines'
records; a CSV that is unreadable or lacks columns is left out, the problem collected."""

from __future__ import annotations

import pandas as pd

from lagbench.reports.folder_files import read_json
from lagbench.reports.loaded import Results

BENCH_COLUMNS = {
    "inference": ["system", "model", "formulation", "framework", "dtype", "batch", "samples_per_s", "error"],
    "training": ["system", "model", "framework", "mode", "dtype", "batch", "steps_per_s", "samples_per_s"],
    "rollout": ["system", "solver", "rtol", "kind", "wall_s", "state_err", "energy_err"],
    "scaling": ["study", "formulation", "framework", "n", "seconds_per_eval", "samples_per_s"],
    "ratios": ["operation", "jax", "torch", "ratio", "note"],
    "latency": ["system", "model", "method", "framework", "dtype", "mode", "dispatch", "evals_per_s"],
    "control_rate": ["model", "framework", "mode", "ticks", "mean_us", "median_us", "p99_us", "rate_hz_mean",
                     "rate_hz_p99", "fits_500hz_mean", "fits_500hz_p99"],
    "train_target": ["protocol", "description", "budget", "threshold", "samples_to_reach", "reached", "best_l1",
                     "samples_per_s", "extrapolated_samples", "extrapolation"],
    "train_target_log": ["protocol", "samples", "heldout_l1"],
    "members": ["framework", "members", "hidden", "batch", "steps", "wall_s", "step_s", "samples_per_s",
                "cost_vs_one"],
}
# `lagbench bench --gpu --out ROOT` writes ROOT/bench_gpu/: the GPU preset's stages
GPU_COLUMNS = {**{k: BENCH_COLUMNS[k] for k in ("inference", "training", "scaling", "ratios")},
               "fast_paper": ["dof", "framework", "formulation", "mode", "batch", "samples_per_s"]}
# `lagbench train-target --out ROOT` writes ROOT/train_target/ with the bench stage's two files
# and, with --runs N > 1, distribution.csv (one row per run at the target held-out L1)
TRAIN_TARGET_COLUMNS = {**{k: BENCH_COLUMNS[k] for k in ("train_target", "train_target_log")},
                        "distribution": ["protocol", "run", "init_seed", "split", "reached", "samples_to_reach",
                                         "wall_s_to_reach", "final_l1"]}


def _load_csvs(res: Results, folder: str, wanted: dict, into: dict) -> None:
    """ROOT/folder/<name>.csv for each name of `wanted` that exists and has its columns, into `into`."""
    for name, columns in wanted.items():
        path = res.root / folder / f"{name}.csv"
        if not path.is_file():
            continue
        try:
            df = pd.read_csv(path)
        except (ValueError, OSError) as exc:
            res.problems.append(f"{folder}/{name}.csv unreadable: {exc}")
            continue
        missing = [c for c in columns if c not in df.columns]
        if missing:
            res.problems.append(f"{folder}/{name}.csv lacks columns {missing}; not used")
            continue
        into[name] = df


def load_bench(res: Results) -> None:
    res.machine = read_json(res.root / "bench" / "machine.json", res.problems, res.root)
    _load_csvs(res, "bench", BENCH_COLUMNS, res.bench)
    _load_csvs(res, "train_target", TRAIN_TARGET_COLUMNS, res.train_target)
    if (res.root / "bench_gpu").is_dir():
        res.machine_gpu = read_json(res.root / "bench_gpu" / "machine.json", res.problems, res.root)
        _load_csvs(res, "bench_gpu", GPU_COLUMNS, res.bench_gpu)
