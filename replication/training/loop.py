"""The training loop, written once for both frameworks and for any number of stacked members.

A framework gives one optimiser step of K members (K >= 1 models trained side by side as one program) as
a stepper (`loop_state.MemberStepper`: `train_jax.Members`, `train_torch.Members`, mirrors). A one-model
stepper (`train_jax.Stepper`, `train_torch.Stepper`: scalars in, scalars out) runs through the same loop as
a member set of one (`train`).

`train_members(stepper, protocol, streams, on_log=None, hooks=(), compiled=False, snapshot=None,
start_state=None) -> [TrainOutcome]` runs `protocol.steps` steps, member i drawing its batches from
`streams[i]`: the learning rate of each step (`schedules.learning_rate`, the same for every member), one
spike guard per member (`spike_guard.SpikeGuard` of `protocol.guard`), a member's stop at its first
non-finite loss (its parameters from before that step kept, its later steps not taken; the run ends when
no member is left), a log row per member every `protocol.log_every` steps and at the first and last
(step, loss, grad_norm, lr, wall_s, and the probe's columns, timed apart), then `on_log(row)` (with
"member": i when K > 1). After every step each hook (`loop_state.Hook`) is called as
`hook(k, stepper, info)`, info = {loss (K,), lr, step_seconds, skipped_steps (K,), live (K,)}; a hook
returning True stops the run there (early stop). Held-out evaluations, checkpoints and scout selection are
hooks and callers of this one loop (`replication.training.scouting`, `tracking`, `speedstudy.target_loop`).
`step_seconds` is the time spent in propose + commit (of all members together), the first step of the
process left out (it compiles) unless `compiled` says the step already is.

All the loop carries from step to step is one `loop_state.TrainState`. With `snapshot` (a
`replication.training.snapshots.Snapshots`), the loop first puts back that store's snapshot if it has one
for this run and goes on from its step; it saves the state after a step when the store says it is due and
once at the end (an ended phase resumed returns its outcomes without a step). `start_state` (meta, arrays),
a snapshot's state held in memory (`loop_state.narrow` of another run's end state: the scouts that go on after a cut),
is where the loop begins when `snapshot` has none of its own.

`train(stepper, protocol, stream, on_log=None, hooks=(), compiled=False, snapshot=None, start_state=None)
-> TrainOutcome`: one model; its hooks see that stepper and scalar info.
"""
from __future__ import annotations

import logging
import time

import numpy as np

from lagbench.replication.training.loop_state import StatefulHook, TrainState, fits
from lagbench.replication.training.outcome import TrainOutcome, nonfinite_failure
from lagbench.replication.training.schedules import learning_rate

log = logging.getLogger("lagbench")


def train_members(stepper, protocol, streams, on_log=None, hooks=(), compiled=False,
                  snapshot=None, start_state=None) -> list[TrainOutcome]:
    state = _start(len(streams), protocol, stepper, hooks, snapshot, start_state)
    t0, t_probe, start = time.perf_counter() - state.wall, 0.0, state.step
    k = start
    for k in range(start, protocol.steps if not state.ended else start):
        lr = learning_rate(protocol, k)
        batches = [stream.batch(k) for stream in streams]
        ts = time.perf_counter()   # step time: propose + commit, not the batches' drawing
        loss, gnorm = _step(state, stepper, protocol, batches, lr, k)
        if loss is None:   # no member left
            break
        if k > start or compiled:   # the first step of a process compiles
            state.step_seconds += time.perf_counter() - ts
        if k % protocol.log_every == 0 or k == protocol.steps - 1:
            tp = time.perf_counter()
            _log(state, stepper, k, loss, gnorm, lr, tp - t0 - t_probe, on_log)
            t_probe += time.perf_counter() - tp
        info = {"loss": loss, "lr": lr, "step_seconds": state.step_seconds, "live": state.live.copy(),
                "skipped_steps": np.array([g.skipped for g in state.guards])}
        if any([hook(k, stepper, info) for hook in hooks]):
            break
        if snapshot and k + 1 < protocol.steps and snapshot.due():
            state.step, state.wall = k + 1, time.perf_counter() - t0 - t_probe
            snapshot.save(*state.snapshot(stepper, hooks, protocol.steps))
    total = time.perf_counter() - t0 - t_probe
    if snapshot and not state.ended:   # the end, so that a later phase resumes without redoing this one
        state.step, state.ended, state.wall = k + 1, True, total
        snapshot.save(*state.snapshot(stepper, hooks, protocol.steps))
    return [TrainOutcome(params=p, log=state.logs[i], failure=state.failures[i], train_time_s=total,
                         steps_done=int(state.done[i]), batch=protocol.batch, step_seconds=state.step_seconds,
                         skipped_steps=state.guards[i].skipped, step_mode=getattr(stepper, "mode", None))
            for i, p in enumerate(stepper.params())]


def _start(n, protocol, stepper, hooks, snapshot, start_state) -> TrainState:
    """The state the run begins from: its own snapshot, else `start_state`, else a fresh one."""
    saved = snapshot.load(n, protocol.steps) if snapshot else None
    if saved and not fits(saved[1], stepper):
        log.warning("training snapshot in %s not used, starting over: its arrays do not fit this model and "
                    "optimiser", snapshot.folder)
        saved = None
    if not saved and start_state is not None:
        if not fits(start_state[1], stepper):
            raise ValueError("the state to start from does not fit this model and optimiser")
        saved = ({**start_state[0], "ended": False}, start_state[1])
    if saved:
        return TrainState.restore(*saved, stepper, hooks, protocol.guard)
    return TrainState.fresh(n, protocol.guard)


def _step(state: TrainState, stepper, protocol, batches, lr, k):
    """One optimiser step of the live members, guarded -> (loss (K,), gnorm (K,)), or (None, None) when
    every member has stopped."""
    # a stopped member gets the bound -inf: no step of it is ever taken again
    bounds = np.array([g.threshold(protocol.dtype) if on else -np.inf
                       for g, on in zip(state.guards, state.live, strict=True)])
    loss, gnorm = stepper.propose(batches, lr, bounds)
    for i in np.flatnonzero(state.live):
        if state.guards[i].fails(loss[i], gnorm[i]):
            state.failures[i], state.live[i] = nonfinite_failure(k, loss[i], gnorm[i]), False
    if not state.live.any():
        return None, None
    taken = np.array([on and g.record(gnorm[i], bounds[i])
                      for i, (g, on) in enumerate(zip(state.guards, state.live, strict=True))])
    stepper.commit(taken, np.array([g.clip_scale(gnorm[i]) for i, g in enumerate(state.guards)]))
    state.done[state.live] = k + 1
    return loss, gnorm


def _log(state: TrainState, stepper, k, loss, gnorm, lr, wall, on_log) -> None:
    """A log row per live member (the probe's columns with it), passed on to `on_log`."""
    n = state.members
    probes = stepper.probe() or [None] * n
    for i in np.flatnonzero(state.live):
        row = {"step": k, "loss": float(loss[i]), "grad_norm": float(gnorm[i]), "lr": lr, "wall_s": wall}
        if state.guards[i].active:
            row["skipped_steps"] = state.guards[i].skipped
        row.update(probes[i] or {})
        state.logs[i].append(row)
        if on_log:
            on_log(row if n == 1 else {**row, "member": int(i)})


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

    @property
    def mode(self):
        return getattr(self.stepper, "mode", None)

    def state_arrays(self):
        return self.stepper.state_arrays()

    def load_state_arrays(self, arrays):
        self.stepper.load_state_arrays(arrays)


class _ScalarHook:
    """A one-model run's hook, seen by the loop: the one-model stepper and scalar info; its state (if it
    has any) travels in snapshots as the hook's own."""

    def __init__(self, hook, stepper):
        self.hook, self.stepper = hook, stepper

    def __call__(self, k, _, info):
        return self.hook(k, self.stepper, {"loss": float(info["loss"][0]), "lr": info["lr"],
                                           "step_seconds": info["step_seconds"],
                                           "skipped_steps": int(info["skipped_steps"][0])})

    def snapshot_state(self):
        return self.hook.snapshot_state() if isinstance(self.hook, StatefulHook) else (None, {})

    def restore_snapshot(self, meta, arrays):
        if isinstance(self.hook, StatefulHook):
            self.hook.restore_snapshot(meta, arrays)


def train(stepper, protocol, stream, on_log=None, hooks=(), compiled=False, snapshot=None,
          start_state=None) -> TrainOutcome:
    return train_members(_One(stepper), protocol, [stream], on_log,
                         [_ScalarHook(h, stepper) for h in hooks], compiled, snapshot, start_state)[0]
