"""The training loop, written once for both frameworks and for any number of stacked members.

A framework gives one optimiser step of K members (K >= 1 models trained side by side as one program:
`train_jax.Members`, `train_torch.Members`, mirrors) as a *stepper*:
  propose(batches, lr, bounds) -> (loss (K,), gnorm (K,))   each member's loss and global gradient norm on
                                 its own batch (a list of K dicts of NumPy float64 arrays), the update
                                 prepared but not applied; bounds (K,): the spike guard's skip thresholds
  commit(taken (K,) bool, scale (K,))   apply the prepared update of the members `taken`, each gradient
                                 scaled by its `scale` (the guard's clip factor); the others keep their
                                 parameters and optimiser state exactly
  probe() -> list[dict | None] | None   the velocity-Hessian health columns (`hessian_probe`) of each member
                                 on the batch last proposed
  params() -> list[dict]         the current parameters of each member, `models.params` layout (NumPy)
A one-model stepper (`train_jax.Stepper`, `train_torch.Stepper`: scalars in, scalars out) runs through
the same loop as a member set of one (`train`).

`train_members(stepper, protocol, streams, on_log=None, hooks=(), compiled=False) -> [TrainOutcome]`
runs `protocol.steps` steps, member i drawing its batches from `streams[i]`: the learning rate of each
step (`schedules.learning_rate`, the same for every member), one spike guard per member
(`spike_guard.SpikeGuard`), a member's stop at its first non-finite loss (its parameters from before that
step kept, its later steps not taken; the run ends when no member is left), a log row per member every
`protocol.log_every` steps and at the first and last (step, loss, grad_norm, lr, wall_s, and the probe's
columns, timed apart), then `on_log(row)` (with "member": i when K > 1). After every step each hook is
called as `hook(k, stepper, info)`, info = {loss (K,), lr, step_seconds, skipped_steps (K,), live (K,)};
a hook returning True stops the run there (early stop). Held-out evaluations, checkpoints and scout
selection are hooks and callers of this one loop (`replication.training.scouting`, `speedstudy.target_loop`).
`step_seconds` is the time spent in propose + commit (of all members together), the first step left out
(it compiles) unless `compiled` says the step already is.

`train(stepper, protocol, stream, on_log=None, hooks=(), compiled=False) -> TrainOutcome`: one model;
its hooks see that stepper and scalar info.
"""
from __future__ import annotations

import time

import numpy as np

from replication.training.outcome import TrainOutcome, nonfinite_failure
from replication.training.schedules import learning_rate
from replication.training.spike_guard import SpikeGuard


def train_members(stepper, protocol, streams, on_log=None, hooks=(), compiled=False) -> list[TrainOutcome]:
    n = len(streams)
    guards = [SpikeGuard(protocol) for _ in range(n)]
    logs, failures = [[] for _ in range(n)], [None] * n
    live, done = np.ones(n, bool), np.zeros(n, int)
    t0, t_probe, t_steps = time.perf_counter(), 0.0, 0.0
    for k in range(protocol.steps):
        lr = learning_rate(protocol, k)
        batches = [stream.batch(k) for stream in streams]
        # a stopped member gets the bound -inf: no step of it is ever taken again
        bounds = np.array([g.threshold(protocol.dtype) if on else -np.inf for g, on in zip(guards, live, strict=True)])
        ts = time.perf_counter()
        loss, gnorm = stepper.propose(batches, lr, bounds)
        for i in np.flatnonzero(live):
            if guards[i].fails(loss[i], gnorm[i]):
                failures[i], live[i] = nonfinite_failure(k, loss[i], gnorm[i]), False
        if not live.any():
            break
        taken = np.array([on and g.record(gnorm[i], bounds[i]) for i, (g, on) in enumerate(zip(guards, live, strict=True))])
        stepper.commit(taken, np.array([g.clip_scale(gnorm[i]) for i, g in enumerate(guards)]))
        if k or compiled:
            t_steps += time.perf_counter() - ts
        done[live] = k + 1
        if k % protocol.log_every == 0 or k == protocol.steps - 1:
            wall = time.perf_counter() - t0 - t_probe
            tp = time.perf_counter()
            probes = stepper.probe() or [None] * n
            t_probe += time.perf_counter() - tp
            for i in np.flatnonzero(live):
                row = {"step": k, "loss": float(loss[i]), "grad_norm": float(gnorm[i]), "lr": lr, "wall_s": wall}
                if guards[i].active:
                    row["skipped_steps"] = guards[i].skipped
                row.update(probes[i] or {})
                logs[i].append(row)
                if on_log:
                    on_log(row if n == 1 else {**row, "member": int(i)})
        info = {"loss": loss, "lr": lr, "step_seconds": t_steps, "live": live.copy(),
                "skipped_steps": np.array([g.skipped for g in guards])}
        if any([hook(k, stepper, info) for hook in hooks]):
            break
    total = time.perf_counter() - t0 - t_probe
    return [TrainOutcome(params=p, log=logs[i], failure=failures[i], train_time_s=total, steps_done=int(done[i]),
                         batch=protocol.batch, step_seconds=t_steps, skipped_steps=guards[i].skipped)
            for i, p in enumerate(stepper.params())]


class _One:
    """A one-model stepper seen as a member set of one (scalars <-> length-1 arrays)."""

    def __init__(self, stepper):
        self.stepper = stepper

    def propose(self, batches, lr, bounds):
        loss, gnorm = self.stepper.propose(batches[0], lr, float(bounds[0]))
        return np.array([loss]), np.array([gnorm])

    def commit(self, taken, scale):
        self.stepper.commit(bool(taken[0]), float(scale[0]))

    def probe(self):
        return [self.stepper.probe()]

    def params(self):
        return [self.stepper.params()]


def _scalar_hook(hook, stepper):
    def call(k, _, info):
        return hook(k, stepper, {"loss": float(info["loss"][0]), "lr": info["lr"],
                                 "step_seconds": info["step_seconds"],
                                 "skipped_steps": int(info["skipped_steps"][0])})
    return call


def train(stepper, protocol, stream, on_log=None, hooks=(), compiled=False) -> TrainOutcome:
    return train_members(_One(stepper), protocol, [stream], on_log,
                         [_scalar_hook(h, stepper) for h in hooks], compiled)[0]
