"""Milliseconds per training step of one model of the full profile (its protocol without scouting, early stop
or tracking; seed 1000), after compilation, in this process started one of three ways:

    python docs/lab/xla_pool/step_rate.py FRAMEWORK MODEL CLAIM STEPS none|pin|release

none: as a worker before the fix (XLA_FLAGS alone); pin: the whole process on one CPU; release: JAX started
on one CPU, then every thread given every CPU back (what `environment.one_thread_jax` does). Run two at once
(`&`) to see two workers side by side. Prints the XLA pool threads (named XLAEigen) and the affinity.
Run it with the workers' environment: XLA_FLAGS="--xla_cpu_multi_thread_eigen=false
intra_op_parallelism_threads=1" OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 JAX_PLATFORMS=cpu."""
import dataclasses
import os
import sys
import time

import jax
import torch

from lagbench.replication.run.environment import one_thread_jax
from lagbench.replication.run.runner import plan
from lagbench.replication.training.train import run_training


def main(fw, model, claim, steps, mode):
    if mode == "release":
        one_thread_jax()
    elif mode == "pin":   # the whole process on one CPU
        full = sorted(os.sched_getaffinity(0))
        os.sched_setaffinity(0, {full[os.getpid() % len(full)]})
    jax.devices()
    torch.set_num_threads(1)
    u = plan("full", claims=[claim], frameworks=[fw], models=[model])[0]
    p = dataclasses.replace(u.protocol(), steps=steps, scouting=None, early_stop=None, tracking=None, log_every=50)
    marks = []
    run_training(fw, u.spec(), p, 1000, on_log=lambda row: marks.append((row["step"], time.perf_counter())))
    (s0, t0), (s1, t1) = marks[1], marks[-1]
    names = [open(f"/proc/self/task/{t}/comm").read().strip() for t in os.listdir("/proc/self/task")]
    print(f"{fw} {model} {mode}: {1000 * (t1 - t0) / (s1 - s0):.2f} ms/step over {s1 - s0} steps; XLA pool "
          f"threads {sum('Eigen' in n for n in names)}; affinity {sorted(os.sched_getaffinity(0))}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4]), sys.argv[5])
