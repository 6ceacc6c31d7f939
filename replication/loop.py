"""The training loop, written once for both frameworks.

A framework gives one optimiser step as a *stepper* (`train_jax.Stepper`, `train_torch.Stepper`, mirrors):
  propose(batch, lr, bound) -> (loss, gnorm)   the loss and global gradient norm of the current model on
                                               `batch` (NumPy float64 arrays), the update prepared but
                                               not applied; `bound` is the spike guard's skip threshold
  commit(taken, scale)                          apply the prepared update if `taken`, the gradient scaled
                                               by `scale` (the guard's clip factor)
  probe() -> dict | None                        the velocity-Hessian health columns (`hessian_probe`) of
                                               the current model on the batch last proposed
  params() -> dict                              the current parameters, `models.params` layout (NumPy)

`train(stepper, protocol, stream, on_log=None, hooks=(), compiled=False) -> TrainOutcome` runs
`protocol.steps` steps:
the learning rate of each step (`schedules.learning_rate`), the spike guard (`spike_guard.SpikeGuard`),
the stop at the first non-finite loss (keeping the parameters from before that step), a log row every
`protocol.log_every` steps and at the first and last (step, loss, grad_norm, lr, wall_s, and the probe's
columns, timed apart), then `on_log(row)`. After every step each hook is called as
`hook(k, stepper, info)`, info = {loss, lr, step_seconds, skipped_steps} so far; a hook returning True
stops the run there (early stop). Held-out evaluations, checkpoints and scouting are hooks and callers of
this one loop (`bench.target_loop`), not loops of their own. `TrainOutcome.step_seconds` is the time spent
in propose + commit, the first step left out (it compiles) unless `compiled` says the step already is.
"""
from __future__ import annotations

import time

from replication.outcome import TrainOutcome, nonfinite_failure
from replication.schedules import learning_rate
from replication.spike_guard import SpikeGuard


def train(stepper, protocol, stream, on_log=None, hooks=(), compiled=False) -> TrainOutcome:
    guard = SpikeGuard(protocol)
    log, failure, t0, t_probe, t_steps, done = [], None, time.perf_counter(), 0.0, 0.0, 0
    for k in range(protocol.steps):
        lr = learning_rate(protocol, k)
        batch = stream.batch(k)
        bound = guard.threshold(protocol.dtype)
        ts = time.perf_counter()
        loss, gnorm = stepper.propose(batch, lr, bound)
        if guard.fails(loss, gnorm):
            failure = nonfinite_failure(k, loss, gnorm)
            break
        stepper.commit(guard.record(gnorm, bound), guard.clip_scale(gnorm))
        if k or compiled:
            t_steps += time.perf_counter() - ts
        done = k + 1
        if k % protocol.log_every == 0 or k == protocol.steps - 1:
            row = {"step": k, "loss": loss, "grad_norm": gnorm, "lr": lr,
                   "wall_s": time.perf_counter() - t0 - t_probe}
            if guard.active:
                row["skipped_steps"] = guard.skipped
            tp = time.perf_counter()
            row.update(stepper.probe() or {})
            t_probe += time.perf_counter() - tp
            log.append(row)
            if on_log:
                on_log(row)
        info = {"loss": loss, "lr": lr, "step_seconds": t_steps, "skipped_steps": guard.skipped}
        if any([hook(k, stepper, info) for hook in hooks]):
            break
    return TrainOutcome(params=stepper.params(), log=log, failure=failure,
                        train_time_s=time.perf_counter() - t0 - t_probe, steps_done=done, batch=protocol.batch,
                        step_seconds=t_steps, skipped_steps=guard.skipped)
