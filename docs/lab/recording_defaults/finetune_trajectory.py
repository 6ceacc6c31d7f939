"""Pilot (not the fit's behaviour): a fitted LNN's parameters trained on under the trajectory loss for STEPS more
steps at a constant rate LR (its spec kept, no restarts, no early stop), and what it then reads of the friction
and its errors on the test file. The fit starts from the given parameters by standing in for the init.

    python docs/lab/recording_defaults/finetune_trajectory.py OUT/s0-lnn OUT/s0-lnn_ft STEPS LR [FRAMES] [--both]
    (run.sh's folder layout: the training and test files in OUT/data)

--both: every window also read backwards (the model integrated from the window's last frame to its first, h < 0).
A window's start velocity is a noisy estimate; matching the positions after it, a model with more damping
forgets that error sooner and so fits better (the friction read high), while integrated backwards more
damping amplifies it: the two directions pull the friction opposite ways, to first order equally.
"""
import glob
import sys
import time
from pathlib import Path

import numpy as np

from lagbench.replication.fit import task, windows
from lagbench.replication.fit.load import load_fitted
from lagbench.replication.training import train


def both_directions(r, part, loss):
    """`windows.windows`, with every window also read from its last frame to its first."""
    at = windows.window_rows(r, part.frames)
    return windows.windows_of(r, np.concatenate([at, at[:, ::-1]]), part, loss)


def main(folder: str, out: str, steps: int, lr: float, frames: int = 5, both: bool = False) -> None:
    if both:
        windows.windows = both_directions
    f = load_fitted(glob.glob(folder + "/units/fit/jax/*/seed0")[0])
    start = {k: np.asarray(v) for k, v in f.params.items()}
    fresh = train.init_params

    def warm(spec, seed=0):
        p = fresh(spec, seed=seed)
        if set(p) != set(start) or any(p[k].shape != start[k].shape for k in p):
            raise SystemExit("the fine-tune's model is not the fit's")
        return {k: start[k].astype(p[k].dtype) for k in p}

    train.init_params = warm
    data = Path(folder).parent / "data"
    t0 = time.time()
    r = task.fit(data=str(data / "train.csv"), test=str(data / "val.csv"), system="double_pendulum", model="lnn",
                 out=out, loss_target="trajectory", horizon_frames=frames, steps=steps, restarts=0,
                 schedule="constant", lr=lr, even_velocity="on", patience=0)
    m = r["metrics"]
    print(f"{time.time() - t0:.0f} s; friction {m.get('test_dissipation_coefficient_0'):.4f}, "
          f"{m.get('test_dissipation_coefficient_1'):.4f}; test L1 {m['test_l1']:.4g} (null {m['null_test_l1']:.4g}); "
          f"rollout error {m['test_rollout_gmean_err']:.4g}; Hessian residual {m.get('test_dissipation_hessian_residual'):.3f}")


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--both"]
    main(args[0], args[1], int(args[2]), float(args[3]), *(int(a) for a in args[4:5]), both="--both" in sys.argv)
