"""Timing helpers and the size presets of the speed study.

`best_time(fn, min_time, min_reps, max_reps) -> seconds`: calls `fn()` (which must block until its
result is ready) repeatedly and returns the FASTEST call (one call if it takes LONG_CALL_S or more). On
shared cores noise only ever slows a call down, so the minimum is the most reproducible estimate; every
figure of the study is a throughput or a ratio of two such minima taken in the same run, never an
absolute timing compared across runs.
`interleaved_best(fns, min_rounds, budget_s, max_rounds, first) -> {name: seconds}`: the fastest call of
each of several fns timed round by round (every fn once per round), for figures compared with each other
(fast/paper/matmul, the sizes of a scaling fit).
`jax_ready(fn)` / `torch_ready(fn)` wrap a framework call so that it blocks and returns nothing.
`Sizes`: what the tiny / quick / full studies measure. Their measured wall times, stage by stage
(each run writes its own to timings.json): `docs/decisions/speed_study_sizes.md`.
"""
from __future__ import annotations

import os
import time
from dataclasses import dataclass

import jax

from lagbench.replication.run.environment import torch_threads  # noqa: F401 - read as timing.torch_threads

LONG_CALL_S = 5.0  # a call this long is timed once: other processes' noise is small against it


def best_time(fn, min_time: float = 0.3, min_reps: int = 2, max_reps: int = 50) -> float:
    """Fastest wall time of fn() over at least min_reps calls, more while the total is under min_time;
    a single call when it takes LONG_CALL_S or more."""
    best, total, reps = float("inf"), 0.0, 0
    while reps < min_reps or (total < min_time and reps < max_reps):
        t0 = time.perf_counter()
        fn()
        dt = time.perf_counter() - t0
        best, total, reps = min(best, dt), total + dt, reps + 1
        if dt >= LONG_CALL_S:
            break
    return best


def interleaved_best(fns: dict, min_rounds: int = 2, budget_s: float = 0.0, max_rounds: int = 50,
                     first: dict | None = None) -> dict:
    """{name: fastest seconds} over rounds that call every fn once in turn: at least min_rounds, more while
    the rounds' total is under budget_s (at most max_rounds). A slow drift or a burst in how much CPU other
    processes leave us then hits every fn alike, so ratios and fitted exponents stay fair on shared cores.
    A fn whose timed call, or whose `first` (seconds of an earlier representative call, where there was
    one), took LONG_CALL_S or more sits out further rounds."""
    first = first or {}
    best = {k: (first[k] if first.get(k, 0.0) >= LONG_CALL_S else float("inf")) for k in fns}
    spent, rounds = 0.0, 0
    while rounds < min_rounds or (spent < budget_s and rounds < max_rounds):
        live = [k for k in fns if best[k] < LONG_CALL_S or best[k] == float("inf")]
        if not live:
            break
        for k in live:
            t0 = time.perf_counter()
            fns[k]()
            dt = time.perf_counter() - t0
            best[k], spent = min(best[k], dt), spent + dt
        rounds += 1
    return best


def jax_ready(fn, *args):
    """A no-argument callable that runs fn(*args) and blocks on the result."""
    return lambda: jax.block_until_ready(fn(*args))


def torch_ready(fn, *args):
    import torch

    def run():
        with torch.no_grad():
            fn(*args)
    return run


TORCH_THREADS = 1  # PyTorch intra-op threads during the study (see run_bench)


@dataclass(frozen=True)
class Sizes:
    """The study's sizes. The fast/paper ratios and the roofline always use 3 x 600 (but tiny)."""

    name: str
    hidden: tuple                  # inference-plane MLP (quick: the quick profile's 3 x 128)
    batches: tuple                 # inference batch sizes
    dtypes: tuple
    lgn_hidden: tuple
    lgn_n: tuple                   # LGN scaling grid sizes
    chain_d: tuple                 # LNN fast vs paper scaling degrees of freedom
    chain_batch: int
    ratio_batch: int               # the fast/paper target batch (4096)
    ratio_hidden: tuple            # the fast/paper target MLP (3 x 600), also the chain scaling's
    ratio_dofs: tuple
    ratio_reps: int                # interleaved rounds of the fast/paper/matmul timing
    train_hidden: tuple
    train_batch: int               # the protocol's batch (training rows also at each of train_extra_batches)
    train_steps: int
    rollout_solvers: tuple
    rollout_rtols: tuple
    rollout_dts: tuple
    rollout_t_end: float
    rollout_ics: int
    min_time: float
    torch_compile: bool
    structure_batch: int
    wave_n: int                    # grid of the wave inference rows
    latency_s: float = 0.5         # seconds per single-sample latency case (`speedstudy.latency`)
    latency_dtypes: tuple = ("float32",)
    latency_methods: tuple = ("inverse_dynamics", "acceleration")
    target_budget: int = 0         # samples per protocol of the train-to-target study (0: skip it)
    target_hidden: tuple = (64, 64, 64)
    scaling_s: float = 0.5         # seconds of interleaved timing rounds per scaling case (`speedstudy.scaling`)
    rollout_learned: bool = True   # roll out learned double-pendulum models in the solver study
    stages: tuple = ()             # the stages run (empty: all of STAGES); the rest are skipped
    train_extra_batches: tuple = ()
    members_hidden: tuple = (128, 128, 128)   # members vs one model (`speedstudy.members`)
    members_steps: int = 0         # steps per timing round (0: skip the stage)
    members_rounds: int = 3
    control_s: float = 0.0         # simulated seconds per control-rate run (`speedstudy.control_rate`; 0: skip)


STAGES = ("inference", "single-sample latency", "control rate", "training", "rollouts", "scaling", "fast vs paper",
          "structure", "train to target", "members")
GPU_STAGES = ("inference", "training", "scaling", "fast vs paper")  # `lagbench bench --gpu`
_SOLVERS = ("tsit5", "dopri5", "dopri8")
TINY = Sizes("tiny", hidden=(16, 16), batches=(8,), dtypes=("float32",), lgn_hidden=(8, 8),
             lgn_n=(16, 32), chain_d=(1, 2), chain_batch=16, ratio_batch=64, ratio_hidden=(16, 16),
             ratio_dofs=(2,), ratio_reps=1, train_hidden=(16, 16), train_batch=32, train_steps=3,
             rollout_solvers=("tsit5",), rollout_rtols=(1e-6,), rollout_dts=(0.01,), rollout_t_end=1.0,
             rollout_ics=2, min_time=0.0, torch_compile=False, structure_batch=64, wave_n=16, latency_s=0.02,
             latency_methods=("inverse_dynamics",), target_budget=2048, target_hidden=(8, 8), scaling_s=0.0,
             members_hidden=(8, 8), members_steps=5, members_rounds=1)
QUICK = Sizes("quick", hidden=(128, 128, 128), batches=(1, 256, 4096), dtypes=("float32", "float64"),
              lgn_hidden=(64, 64, 64), lgn_n=(16, 64, 256, 1024), chain_d=(1, 4, 16), chain_batch=256,
              ratio_batch=4096, ratio_hidden=(600, 600, 600), ratio_dofs=(2, 16), ratio_reps=4,
              train_hidden=(600, 600, 600), train_batch=512, train_steps=3, rollout_solvers=_SOLVERS,
              rollout_rtols=(1e-4, 1e-6, 1e-8, 1e-10), rollout_dts=(0.01, 0.003), rollout_t_end=10.0,
              rollout_ics=8, min_time=0.05, torch_compile=True, structure_batch=1024, wave_n=32, latency_s=2.0,
              target_budget=500_000, target_hidden=(64, 64, 64), members_steps=1000, control_s=6.0)
FULL = Sizes("full", hidden=(600, 600, 600), batches=(1, 16, 256, 4096, 65536), dtypes=("float32", "float64"),
             lgn_hidden=(64, 64, 64), lgn_n=(16, 64, 256, 1024, 4096), chain_d=(1, 2, 4, 8, 16, 32),
             chain_batch=512, ratio_batch=4096, ratio_hidden=(600, 600, 600), ratio_dofs=(2, 16), ratio_reps=3,
             train_hidden=(600, 600, 600), train_batch=512, train_steps=10, rollout_solvers=_SOLVERS,
             rollout_rtols=(1e-4, 1e-6, 1e-8, 1e-10, 1e-12), rollout_dts=(0.01, 0.003, 0.001),
             rollout_t_end=20.0, rollout_ics=16, min_time=1.0, torch_compile=True, structure_batch=4096,
             wave_n=64, latency_s=2.0, latency_dtypes=("float32", "float64"), target_budget=5_000_000,
             target_hidden=(128, 128, 128), members_steps=3000, control_s=20.0)
# `lagbench bench --gpu`: the inference plane up to batch 65536, training at the protocol's batch and at 4096, the
# scaling studies to n = 4096 and the fast/paper timing; PyTorch eager (no AOTInductor: its CUDA build is not
# part of this study) against JAX jit, both on the GPU. The latency subprocesses, rollouts, structure and
# train-to-target stay CPU studies.
GPU = Sizes("gpu", hidden=(128, 128, 128), batches=(1, 256, 4096, 65536), dtypes=("float32", "float64"),
            lgn_hidden=(64, 64, 64), lgn_n=(16, 64, 256, 1024, 4096), chain_d=(1, 4, 16, 32), chain_batch=4096,
            ratio_batch=4096, ratio_hidden=(600, 600, 600), ratio_dofs=(2, 16), ratio_reps=10,
            train_hidden=(600, 600, 600), train_batch=512, train_steps=20, rollout_solvers=_SOLVERS,
            rollout_rtols=(1e-6,), rollout_dts=(0.01,), rollout_t_end=1.0, rollout_ics=2, min_time=0.2,
            torch_compile=False, structure_batch=1024, wave_n=64, stages=GPU_STAGES, train_extra_batches=(4096,))
GPU_TINY = Sizes("gpu-tiny", hidden=(16, 16), batches=(8, 64), dtypes=("float32",), lgn_hidden=(8, 8),
                 lgn_n=(16, 32), chain_d=(1, 2), chain_batch=16, ratio_batch=64, ratio_hidden=(16, 16),
                 ratio_dofs=(2,), ratio_reps=1, train_hidden=(16, 16), train_batch=32, train_steps=3,
                 rollout_solvers=("tsit5",), rollout_rtols=(1e-6,), rollout_dts=(0.01,), rollout_t_end=1.0,
                 rollout_ics=2, min_time=0.0, torch_compile=False, structure_batch=64, wave_n=16, scaling_s=0.0,
                 stages=GPU_STAGES, train_extra_batches=(64,), members_steps=3000)


TORCH_THREAD_CHOICES = tuple(sorted({1, os.cpu_count() or 1}))
PAIRED_ROUNDS = 5  # interleaved rounds (at least) of a PyTorch row and its JAX twin, per thread count (inference)


def torch_thread_choices() -> tuple:
    """The intra-op thread counts a PyTorch row is timed at: TORCH_THREAD_CHOICES on the CPU; on a GPU only
    TORCH_THREADS (the host threads only launch kernels there)."""
    from lagbench.speedstudy.device import on_gpu

    return (TORCH_THREADS,) if on_gpu() else TORCH_THREAD_CHOICES
