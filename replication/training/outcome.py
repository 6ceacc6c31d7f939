"""What a training loop returns, the same record for both frameworks."""
from __future__ import annotations

from dataclasses import dataclass

import pandas as pd

LOG_COLUMNS = ["step", "loss", "grad_norm", "lr", "wall_s"]   # then any `hessian_probe` columns


@dataclass
class TrainOutcome:
    params: dict            # last good parameters, init_params layout (NumPy)
    log: list               # rows: step, loss, grad_norm, lr, wall_s [, hessian_probe.COLUMNS]
    failure: dict | None    # None, or {"kind", "step", "message"}
    train_time_s: float
    steps_done: int
    batch: int
    step_seconds: float = 0.0   # time in the optimiser steps after the first (compiling) one
    skipped_steps: int = 0      # steps the spike guard skipped
    scouting: dict | None = None  # restarts (`replication.training.scouting`): init seeds, tail losses, the chosen one
    samples: int | None = None    # training samples, where not steps_done x batch (scouts at their own batch)
    cohort: dict | None = None    # trained side by side with other seeds (`Protocol.cohort`): {"seeds": [...]}
    step_mode: str | None = None  # "jit" (JAX); "compiled" or "eager" (PyTorch, `compile_torch`); phases joined by " + "
    device: dict | None = None    # where it computed (`replication.training.device.describe`)
    tracked: dict | None = None   # kept parameters at the tracked steps (`Tracking.keep`, `tracking.Tracker.checkpoints`)
    early_stop: dict | None = None  # `Protocol.early_stop`'s record (`early_stop.EarlyStopper.record`): when it stopped

    @property
    def samples_per_s(self) -> float:
        n = self.samples if self.samples is not None else self.steps_done * self.batch
        return n / self.train_time_s if self.train_time_s > 0 else float("nan")


def joined_modes(*modes) -> str | None:
    """The step modes of a run's phases, each once, in order ("compiled", or "eager + compiled")."""
    seen = [m for m in dict.fromkeys(x for mode in modes if mode for x in mode.split(" + "))]
    return " + ".join(seen) or None


def nonfinite_failure(step: int, loss: float, gnorm: float) -> dict:
    what = "loss" if loss != loss or abs(loss) == float("inf") else "gradient"
    return {"kind": f"non_finite_{what}", "step": int(step),
            "message": f"non-finite {what} at step {step} (loss={loss}, grad_norm={gnorm}); "
                       f"kept the parameters from before step {step}"}


def log_frame(log: list) -> pd.DataFrame:
    """The train log as the train_log.csv table: LOG_COLUMNS first, then the probe columns present."""
    df = pd.DataFrame(log)
    extra = [c for c in df.columns if c not in LOG_COLUMNS]
    return df.reindex(columns=LOG_COLUMNS + extra)
