"""Whether XLA's CPU pool size changes a training's numbers: the full profile's JAX model of a claim (its
protocol without scouting, early stop or tracking; seed 1000) trained STEPS steps in two processes, one with
JAX's backend started on every CPU (a pool of `cores` threads) and one on one CPU (a pool of one), and their
parameters compared:

    python docs/lab/xla_pool/pool_rounding.py MODEL CLAIM STEPS

Prints each process's pool threads and the largest difference between the two sets of parameters."""
import dataclasses
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np


def train(model, claim, steps, one_cpu, out):
    import jax

    from lagbench.replication.run.runner import plan
    from lagbench.replication.training.train import run_training

    if one_cpu:
        os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})
    jax.devices()
    u = plan("full", claims=[claim], frameworks=["jax"], models=[model])[0]
    p = dataclasses.replace(u.protocol(), steps=steps, scouting=None, early_stop=None, tracking=None)
    leaves = [np.asarray(x) for x in jax.tree_util.tree_leaves(run_training("jax", u.spec(), p, 1000).params)]
    np.savez(out, *leaves)
    names = [open(f"/proc/self/task/{t}/comm").read() for t in os.listdir("/proc/self/task")]
    print(f"{'one CPU' if one_cpu else 'every CPU'}: XLA pool threads {sum('XLAEigen' in n for n in names)}")


def main(model, claim, steps):
    with tempfile.TemporaryDirectory() as tmp:
        files = [Path(tmp) / f"{k}.npz" for k in ("every", "one")]
        for one_cpu, f in zip((False, True), files, strict=True):
            subprocess.run([sys.executable, __file__, "--train", model, claim, str(steps), str(int(one_cpu)), str(f)],
                           check=True)
        a, b = (np.load(f) for f in files)
        diff = max(float(np.abs(a[k] - b[k]).max()) for k in a)
        print(f"identical: {all(np.array_equal(a[k], b[k]) for k in a)}; largest difference {diff:.3g}")


if __name__ == "__main__":
    if sys.argv[1] == "--train":
        train(sys.argv[2], sys.argv[3], int(sys.argv[4]), sys.argv[5] == "1", sys.argv[6])
    else:
        main(sys.argv[1], sys.argv[2], int(sys.argv[3]))
