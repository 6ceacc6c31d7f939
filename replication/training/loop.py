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
  mode (optional)                how its step runs: "jit" (JAX), "compiled" or "eager" (PyTorch,
                                 `compile_torch`), recorded as the outcome's `step_mode`
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
`step_seconds` is the time spent in propose + commit (of all members together), the first step of the
process left out (it compiles) unless `compiled` says the step already is.

`start_state` (meta, arrays), a snapshot's state held in memory (`narrow` of another run's end state: the
scouts that go on after a cut, `scouting`), is where the loop begins when `snapshot` has none of its own.

With `snapshot` (a `replication.training.snapshots.Snapshots`), the loop first puts back that store's
snapshot if it has one for this run (the stepper's `load_state_arrays`, the guards, logs, failures, hooks
with a `restore_snapshot`) and goes on from its step; it saves one after a step when the store says it is
due and once at the end (an ended phase resumed returns its outcomes without a step). A stepper for
snapshots also gives `state_arrays() -> [np.ndarray]` (parameters and optimiser state, in a fixed order)
and `load_state_arrays(arrays)`.

`train(stepper, protocol, stream, on_log=None, hooks=(), compiled=False, snapshot=None) -> TrainOutcome`:
one model; its hooks see that stepper and scalar info.
"""
from __future__ import annotations

import logging
import time

import numpy as np

from replication.training.outcome import TrainOutcome, nonfinite_failure
from replication.training.schedules import learning_rate
from replication.training.spike_guard import SpikeGuard

log = logging.getLogger("lagbench")


def train_members(stepper, protocol, streams, on_log=None, hooks=(), compiled=False,
                  snapshot=None, start_state=None) -> list[TrainOutcome]:
    n = len(streams)
    guards = [SpikeGuard(protocol.guard) for _ in range(n)]
    logs, failures = [[] for _ in range(n)], [None] * n
    live, done = np.ones(n, bool), np.zeros(n, int)
    saved = snapshot.load(n, protocol.steps) if snapshot else None
    if saved and not _fits(saved[1], stepper):
        log.warning("training snapshot in %s not used, starting over: its arrays do not fit this model and "
                    "optimiser", snapshot.folder)
        saved = None
    if not saved and start_state is not None:
        if not _fits(start_state[1], stepper):
            raise ValueError("the state to start from does not fit this model and optimiser")
        saved = ({**start_state[0], "ended": False}, start_state[1])
    start, ended, wall, t_steps = 0, False, 0.0, 0.0
    if saved:
        start, ended, wall, t_steps = _restore(*saved, stepper, guards, logs, failures, live, done, hooks)
    t0, t_probe = time.perf_counter() - wall, 0.0
    k = start
    for k in range(start, protocol.steps if not ended else start):
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
        if k > start or compiled:   # the first step of a process compiles
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
        if snapshot and k + 1 < protocol.steps and snapshot.due():
            snapshot.save(*_state(k + 1, False, time.perf_counter() - t0 - t_probe, t_steps, stepper, guards,
                                  logs, failures, live, done, hooks, protocol.steps))
    total = time.perf_counter() - t0 - t_probe
    if snapshot and not ended:   # the end, so that a later phase resumes without redoing this one
        snapshot.save(*_state(k + 1, True, total, t_steps, stepper, guards, logs, failures, live, done, hooks,
                              protocol.steps))
    return [TrainOutcome(params=p, log=logs[i], failure=failures[i], train_time_s=total, steps_done=int(done[i]),
                         batch=protocol.batch, step_seconds=t_steps, skipped_steps=guards[i].skipped,
                         step_mode=getattr(stepper, "mode", None))
            for i, p in enumerate(stepper.params())]


def narrow(state, members) -> tuple[dict, dict]:
    """A snapshot's (meta, arrays) cut down to the stacked `members` (indices), to start a run of those
    alone from it (`start_state`): the stepper's arrays, logs, failures, guards, liveness and steps done of
    those members; the hooks' state is left behind (their owner carries what it needs)."""
    meta, arrays = state
    idx = np.asarray(members, int)
    each = {name: [meta[name][i] for i in idx] for name in ("logs", "failures", "guards")}
    return ({**meta, **each, "members": len(idx), "ended": False, "hooks": [],
             "live": np.asarray(meta["live"])[idx], "done": np.asarray(meta["done"])[idx]},
            {k: np.asarray(a)[idx] for k, a in arrays.items() if k.startswith("stepper_")})


def _fits(arrays, stepper) -> bool:
    mine = [np.shape(a) for a in stepper.state_arrays()]
    return [np.shape(arrays[k]) for k in sorted(arrays) if k.startswith("stepper_")] == mine


def _state(step, ended, wall, t_steps, stepper, guards, logs, failures, live, done, hooks,
           steps) -> tuple[dict, dict]:
    """(meta, arrays) of a snapshot (`replication.training.snapshots`): all the next step reads."""
    arrays = {f"stepper_{j:04d}": a for j, a in enumerate(stepper.state_arrays())}
    hook_meta = []
    for h, hook in enumerate(hooks):
        state = getattr(hook, "snapshot_state", None)
        meta, extra = state() if state else (None, {})
        hook_meta.append(meta)
        arrays.update({f"hook{h}_{name}": a for name, a in extra.items()})
    meta = {"step": step, "steps": steps, "ended": ended, "wall_s": wall, "step_seconds": t_steps,
            "members": len(guards),
            "logs": logs, "failures": failures, "live": live, "done": done, "hooks": hook_meta,
            "guards": [{"history": list(g.history), "skipped": g.skipped} for g in guards]}
    return meta, arrays


def _restore(meta, arrays, stepper, guards, logs, failures, live, done, hooks):
    """Put a snapshot's state back in place -> (next step, ended, wall seconds, step seconds)."""
    stepper.load_state_arrays([arrays[k] for k in sorted(arrays) if k.startswith("stepper_")])
    for g, saved in zip(guards, meta["guards"], strict=True):
        g.restore(saved["history"], saved["skipped"])
    for i in range(len(guards)):
        logs[i].extend(meta["logs"][i])
        failures[i] = meta["failures"][i]
    live[:], done[:] = meta["live"], meta["done"]
    for h, hook in enumerate(hooks[:len(meta["hooks"])]):   # none for a `narrow`ed state
        restore = getattr(hook, "restore_snapshot", None)
        if restore:
            prefix = f"hook{h}_"
            restore(meta["hooks"][h], {k[len(prefix):]: a for k, a in arrays.items() if k.startswith(prefix)})
    return int(meta["step"]), bool(meta["ended"]), float(meta["wall_s"]), float(meta["step_seconds"])


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


def _scalar_hook(hook, stepper):
    def call(k, _, info):
        return hook(k, stepper, {"loss": float(info["loss"][0]), "lr": info["lr"],
                                 "step_seconds": info["step_seconds"],
                                 "skipped_steps": int(info["skipped_steps"][0])})
    for name in ("snapshot_state", "restore_snapshot"):   # a hook's state travels through the wrapper
        if hasattr(hook, name):
            setattr(call, name, getattr(hook, name))
    return call


def train(stepper, protocol, stream, on_log=None, hooks=(), compiled=False, snapshot=None) -> TrainOutcome:
    return train_members(_One(stepper), protocol, [stream], on_log,
                         [_scalar_hook(h, stepper) for h in hooks], compiled, snapshot)[0]
