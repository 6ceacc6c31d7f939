"""Control-loop rate on one core: how many ticks per second each learned inverse model sustains inside the DeLaN
paper's computed-torque loop, against the 500 Hz its robot ran at (`replication.studies.control.RATE`).

The loop is the online study's (`replication.studies.online.run_online`): the SymPy two-link arm tracking the
training reference family (`online.sequence("train", seconds)`) at 500 Hz, the feed-forward torque
tau_hat(q_d, qdot_d, qddot_d) computed once per tick by claim 9's model (`online_learner.learner`: "delan" or
"ff", JAX or PyTorch). Two modes per model and framework, on one learner: "inference" (the loop without learning:
the per-tick time is the feed-forward call alone) and then "inference+learning" (as `lagbench online`: every
`every` ticks `steps` optimiser steps on a minibatch of `batch` from the replay buffer; the per-tick time is the
feed-forward call plus the buffer write and the steps). The plant's simulation is not counted: it stands in for
the robot. The inference mode runs the untrained model: a call's cost does not depend on the weights' values, so
its timing is the trained model's.

Threads: one, as the online study holds them (`online.one_thread()`: XLA on one thread, its backend started on one
CPU, JAX's CPU programs run inline; PyTorch at 1 intra-op thread). `one_thread()` acts only before
JAX's backend starts, so the bench stage (`control_rate_stage`) measures in a fresh process
(`python -m lagbench.speedstudy.control_rate`), whose environment also holds OpenMP and MKL to one thread.

`control_rate_rows(models, frameworks, seconds, warmup, ...) -> rows`: one row per model, framework and mode:
model, framework, mode, ticks (the ticks measured: the run's first `warmup` ticks, WARMUP = 50 (0.1 s) by
default, are left out as the compiling and first-call costs; a diverged reference's rest does not run),
mean_us, median_us, p99_us (microseconds per tick of the measured part; NaN where no tick was measured),
rate_hz_mean = 1e6 / mean_us and rate_hz_p99 = 1e6 / p99_us (ticks per second the model's compute sustains),
fits_500hz_mean and fits_500hz_p99 (that compute below the 2 ms period), inference_us_mean and learning_us_mean
(the two parts' means; learning 0 in mode "inference"), hidden, batch, every, steps, seconds (simulated per
run), warmup, threads, jax_dispatch.
"""
from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

MODELS = ("delan", "ff")
FRAMEWORKS = ("jax", "torch")
MODES = ("inference", "inference+learning")
WARMUP = 50   # ticks left out at the start of each run: 0.1 s simulated
COLUMNS = ["model", "framework", "mode", "ticks", "mean_us", "median_us", "p99_us", "rate_hz_mean", "rate_hz_p99",
           "fits_500hz_mean", "fits_500hz_p99", "inference_us_mean", "learning_us_mean", "hidden", "batch", "every",
           "steps", "seconds", "warmup", "threads", "jax_dispatch"]


def _stat(f, x: np.ndarray) -> float:
    return float(f(x)) if len(x) else math.nan


def _row(inf_us: np.ndarray, learn_us: np.ndarray | None, period_us: float) -> dict:
    per_tick = inf_us if learn_us is None else inf_us + learn_us
    mean, p99 = _stat(np.mean, per_tick), _stat(lambda x: np.percentile(x, 99), per_tick)
    return {"ticks": int(len(per_tick)), "mean_us": mean, "median_us": _stat(np.median, per_tick), "p99_us": p99,
            "rate_hz_mean": 1e6 / mean, "rate_hz_p99": 1e6 / p99, "fits_500hz_mean": bool(mean < period_us),
            "fits_500hz_p99": bool(p99 < period_us), "inference_us_mean": _stat(np.mean, inf_us),
            "learning_us_mean": 0.0 if learn_us is None else _stat(np.mean, learn_us)}


def control_rate_rows(models=MODELS, frameworks=FRAMEWORKS, seconds: float = 2.0, warmup: int | None = None,
                      hidden=None, batch: int | None = None, every: int | None = None, steps: int | None = None,
                      buffer: int | None = None, seed: int = 0) -> list[dict]:
    """See the module docstring. `warmup`: default WARMUP ticks, at most half the run's. `hidden`, `batch`,
    `every`, `steps`, `buffer`: default the online study's (claim 9's widths; one Adam step on 64 samples at every
    tick, drawn from the last 10 s of samples). Runs in this process, at the thread settings that
    `online.one_thread()` can still set (all of them before JAX's backend starts)."""
    from lagbench.replication.run.environment import torch_threads
    from lagbench.replication.studies import online as O
    from lagbench.replication.studies import online_learner as OL

    hidden = tuple(hidden or OL.HIDDEN)
    batch, every = batch or O.BATCH, every or O.EVERY
    steps, buffer = O.STEPS if steps is None else steps, buffer or O.BUFFER
    total = int(round(seconds * O.C.RATE))
    warmup = min(WARMUP, total // 2) if warmup is None else warmup
    if not 0 <= warmup < total:
        raise ValueError(f"warmup {warmup} ticks: must be >= 0 and below the run's {total} ticks ({seconds:g} s)")
    threads = O.one_thread()
    refs = O.sequence("train", seconds)
    settings = {"hidden": "x".join(map(str, hidden)), "batch": batch, "every": every, "steps": steps,
                "seconds": seconds, "warmup": warmup, "threads": threads["torch_threads"],
                "jax_dispatch": threads["jax_dispatch"]}
    rows = []
    with torch_threads(1):
        for model in models:
            for fw in frameworks:
                ctrl = OL.learner(model, fw, seed, hidden)   # inference first: it leaves the weights as they are
                for mode in MODES:
                    learns = mode != "inference"
                    _, ticks = O.run_online(ctrl, refs, every, steps if learns else 0, batch, buffer,
                                            window=seconds, seed=seed, seconds=seconds)
                    inf = ticks["inference_us"][warmup:]
                    learn = ticks["learning_us"][warmup:] if learns else None
                    rows.append({"model": model, "framework": fw, "mode": mode, **_row(inf, learn, O.PERIOD_US),
                                 **settings})
    return [{c: r[c] for c in COLUMNS} for r in rows]


def control_rate_stage(sizes, notes: list | None = None) -> list[dict]:
    """The bench stage: `control_rate_rows` at `sizes.control_s` simulated seconds per run, in a fresh process
    held to one thread. A failed process adds a note (or raises, without `notes`) and gives no rows."""
    from lagbench.replication.run.environment import one_thread_env

    arg = json.dumps({"seconds": sizes.control_s})
    root = str(Path(__file__).resolve().parents[1])   # the project root, for an uninstalled checkout
    env = {**os.environ, **one_thread_env(os.environ),
           "PYTHONPATH": os.pathsep.join(p for p in (root, os.environ.get("PYTHONPATH", "")) if p)}
    proc = subprocess.run([sys.executable, "-m", "lagbench.speedstudy.control_rate", arg], env=env, capture_output=True,
                          text=True, timeout=1800)
    if proc.returncode != 0:
        msg = (proc.stderr.strip().splitlines() or ["no output"])[-1][:200]
        if notes is None:
            raise RuntimeError(f"control-rate study failed: {msg}")
        notes.append(f"control-rate study failed: {msg}")
        return []
    return json.loads(proc.stdout.strip().splitlines()[-1])


if __name__ == "__main__":
    print(json.dumps(control_rate_rows(**json.loads(sys.argv[1]))))
