"""Rollback on a loss blow-up: a protocol option (`Protocol.rollback`, 0 = off) of the one-model loop.

Why: the spike guard (`spike_guard`) stops single steps, but a run of steps at a high learning rate can still
throw a learned Lagrangian off within a few hundred steps: the velocity Hessian turns indefinite and the
training loss jumps several-fold, from which the run rarely comes back in its budget (the double pendulum's
quick continuation at peak 1e-2 from phase 0.2, JAX seed 0: 3.9 -> 43 within 250 steps, held-out L1 8.1 at the
end instead of about 0.25; with rollback 2.5, 0.31). It cannot help a run that never held a near-physical
Lagrangian (PyTorch seed 1 there: 10.4 without, 7.4 with; `docs/train_target_trials.md` section 7).

The rule, per window of `WINDOW` steps (mean training loss over the window, the loss each step reports):
  - a window whose mean is the lowest so far keeps a copy of the model's parameters and optimiser state
    (the stepper's `state_arrays`, as the snapshots do);
  - a window whose mean exceeds `protocol.rollback` x that lowest mean puts the copy back
    (`load_state_arrays`); the run goes on from there with the schedule's current rate and the next batches.
The held-out set plays no part. `rollbacks` counts the restores; each is logged. The state travels with the
loop's snapshots (`snapshot_state` / `restore_snapshot`), so an interrupted run resumes bit for bit.

`Rollback(protocol)` is a loop hook (`loop.train_members`) of a member set of one: `hook(k, stepper, info)`.
"""
from __future__ import annotations

import logging
import math

import numpy as np

log = logging.getLogger("lagbench")

WINDOW = 50   # steps per window (at batch 256, 12 800 samples: the window mean is smooth enough to compare)


class Rollback:
    def __init__(self, protocol):
        self.factor = float(protocol.rollback)
        self.losses: list[float] = []
        self.best = math.inf
        self.saved: list[np.ndarray] | None = None
        self.rollbacks = 0

    def __call__(self, k, stepper, info):
        self.losses.append(float(np.asarray(info["loss"]).reshape(-1)[0]))
        if len(self.losses) < WINDOW:
            return False
        mean, self.losses = float(np.mean(self.losses)), []
        if self.saved is not None and mean > self.factor * self.best:
            stepper.load_state_arrays([a.copy() for a in self.saved])
            self.rollbacks += 1
            log.info("step %d: window loss %.4g > %g x the best %.4g: parameters and optimiser state put back "
                     "(rollback %d)", k, mean, self.factor, self.best, self.rollbacks)
        elif mean < self.best:
            self.best, self.saved = mean, [np.array(a, copy=True) for a in stepper.state_arrays()]
        return False

    def snapshot_state(self):
        saved = self.saved or []   # never empty once kept: a stepper has state
        meta = {"losses": self.losses, "best": self.best, "rollbacks": self.rollbacks, "n": len(saved)}
        return meta, {f"saved_{j:04d}": a for j, a in enumerate(saved)}

    def restore_snapshot(self, meta, arrays):
        self.losses, self.best, self.rollbacks = list(meta["losses"]), float(meta["best"]), int(meta["rollbacks"])
        self.saved = [arrays[f"saved_{j:04d}"] for j in range(int(meta["n"]))] or None
