"""Restarts over initialisations ("scouting"): a protocol option (`Protocol.scouts`), both frameworks.

Why: which initialisation of a black-box Lagrangian finds a near-physical L (a learned velocity Hessian
close to the mass matrix) is luck, a run that found one trains on without gradient spikes, and its
training loss tells which it is (`docs/train_target_trials.md`, section 5). So a protocol
with `scouts` = K > 1:
  1. trains the K initialisations `init_seeds(protocol, seed)` side by side for `scout_steps(protocol)`
     steps each, as one program (`loop.train_members`; each member's numbers are its own run's), at
     `scout_batch`, peak rate `scout_lr` and one-cycle start `scout_lr_start` (0: the protocol's), a
     schedule over the scout (the protocol's shape over scout_steps), batches from a stream per init seed;
  2. chooses the scout with the lowest training loss over its last `TAIL` of steps (a scout that stopped
     on a non-finite loss is never chosen); the held-out set plays no part;
  3. continues the chosen one for `protocol.steps` steps of `protocol.batch`: a new schedule over those
     steps (from `protocol.lr_start`: a fresh Adam's first steps at a high rate can throw a near-physical
     Lagrangian away, so a continuation may start lower than its scouts did), fresh Adam state, batches
     from a stream of its own (seed + 1000).
Every scout's samples count in the budget (`budget_samples`; the outcome's `samples`). The original code
has no restarts: the report says so where a claim uses them.

`train_scouted(trainer, spec, protocol, seed, on_log=None) -> TrainOutcome` (trainer: `train_jax` or
`train_torch`): the continuation's parameters and log (its steps shifted by the scouts' samples in
continuation steps, `progress_steps`), steps_done and samples counting every scout, its `scouting` record {init_seeds, tail_loss, chosen, scout_steps}. `scout(...)` and `continuation(...)` are
the two phases, for callers that watch them (`speedstudy.target_loop`).
"""
from __future__ import annotations

import math

import numpy as np

SCOUT_SAMPLES = 500_000   # samples per scout when the protocol does not say (at most half the budget in all)
TAIL = 0.05               # the share of a scout's last steps whose mean training loss chooses
CONTINUATION_STREAM = 1000  # the chosen init seed + this: the continuation's batch stream


def scout_steps(protocol) -> int:
    """Steps of each scout: `protocol.scout_steps`, or SCOUT_SAMPLES samples at the scout batch."""
    return int(protocol.scout_steps) or max(SCOUT_SAMPLES // (protocol.scout_batch or protocol.batch), 1)


def budget_samples(protocol) -> int:
    """Training samples of a run: every scout's and the continuation's (steps x batch without scouts)."""
    scouts = protocol.scouts * scout_steps(protocol) * (protocol.scout_batch or protocol.batch)
    return protocol.steps * protocol.batch + (scouts if protocol.scouts > 1 else 0)


def progress_steps(protocol) -> int:
    """The run's length for a progress bar, in continuation steps (the scouts' samples converted)."""
    return -(-budget_samples(protocol) // protocol.batch)


def init_seeds(protocol, seed: int) -> list[int]:
    """The K initialisations scouted for a run of `seed`: seed * K .. seed * K + K - 1 (disjoint per seed)."""
    return [seed * protocol.scouts + i for i in range(protocol.scouts)]


_OFF = {"scouts": 0, "scout_steps": 0, "scout_batch": 0, "scout_lr": 0.0, "scout_lr_start": 0.0}


def scout_protocol(protocol):
    return protocol.replace(steps=scout_steps(protocol), batch=protocol.scout_batch or protocol.batch,
                            lr=protocol.scout_lr or protocol.lr, lr_start=protocol.scout_lr_start or protocol.lr_start,
                            rollback=0.0, **_OFF)   # rollback is one model's: the continuation's


def continuation_protocol(protocol):
    return protocol.replace(**_OFF)


class _Losses:
    """The loop hook that keeps each scout's training loss at every step (NaN once it stopped)."""

    def __init__(self):
        self.losses = []

    def __call__(self, k, stepper, info):
        self.losses.append(np.where(info["live"], info["loss"], np.nan))

    def snapshot_state(self):
        return None, {"losses": np.asarray(self.losses, np.float64)}

    def restore_snapshot(self, meta, arrays):
        self.losses = list(arrays["losses"])


def scout(trainer, spec, protocol, seeds, on_log=None, hooks=(), snapshot=None):
    """Phase 1: (outcomes, tail losses), one per init seed in `seeds`, trained as one program for
    `scout_protocol(protocol).steps`; the tail loss is inf for a scout that stopped."""
    from models import init_params  # here, not at import: claims read scout_protocol without
    from replication.training.data import BatchStream  # the models or the data (reports import the claims)

    p = scout_protocol(protocol)
    keep = _Losses()
    outcomes = trainer.train_members(spec, [init_params(spec, seed=s) for s in seeds], p,
                                     [BatchStream(p, s) for s in seeds], on_log=on_log, hooks=(keep, *hooks),
                                     snapshot=snapshot)
    losses = keep.losses
    tail = np.asarray(losses[-max(len(losses) // round(1 / TAIL), 1):]) if losses else np.full((1, len(seeds)), np.inf)
    tails = [float(np.mean(tail[:, i])) if o.failure is None else math.inf for i, o in enumerate(outcomes)]
    return outcomes, [t if math.isfinite(t) else math.inf for t in tails]


def choose(tails) -> int | None:
    """The index of the lowest finite tail loss (None: every scout stopped)."""
    finite = [i for i, t in enumerate(tails) if math.isfinite(t)]
    return min(finite, key=lambda i: tails[i]) if finite else None


def train_scouted(trainer, spec, protocol, seed: int, on_log=None, track=None, snapshot=None):
    """Scouts, then the chosen one's continuation; `track(protocol, offset_steps, offset_samples,
    offset_seconds)` may give a held-out tracking hook for the continuation (`training.tracker_for`): the
    scouts' samples and step time count. `snapshot` (`snapshots.Snapshots`): each phase snapshots under
    its own name ("scouts", "continuation"), so that a run killed in its continuation does not scout again."""
    from replication.training.data import BatchStream

    seeds, per = init_seeds(protocol, seed), scout_steps(protocol)
    done = progress_steps(protocol) - protocol.steps   # the scouts' samples, in continuation steps

    def scout_log(row):   # progress in continuation steps: the scouts advance together
        if on_log and row.get("member", 0) == 0:
            on_log({**row, "step": row["step"] * done // per})
    outcomes, tails = scout(trainer, spec, protocol, seeds, on_log=scout_log,
                            snapshot=snapshot.phase("scouts") if snapshot else None)
    best = choose(tails)
    record = {"init_seeds": seeds, "tail_loss": tails, "scout_steps": per,
              "chosen": None if best is None else seeds[best]}
    if best is None:   # every scout stopped: the first one's failure stands for the run
        o = outcomes[0]
        o.scouting, o.steps_done = record, sum(x.steps_done for x in outcomes)
        o.samples = o.steps_done * o.batch
        return o
    p = continuation_protocol(protocol)

    def shifted(row):
        if on_log:
            on_log({**row, "step": row["step"] + done})
    t = track(p, done, len(seeds) * per * outcomes[0].batch, outcomes[0].step_seconds) if track else None
    out = trainer.train(spec, outcomes[best].params, p, BatchStream(p, seeds[best] + CONTINUATION_STREAM),
                        on_log=shifted, hooks=(t,) if t else (),
                        snapshot=snapshot.phase("continuation") if snapshot else None)
    out.log = [{**row, "step": row["step"] + done} for row in out.log]
    if t:
        t.merge([out.log])
    out.samples = out.steps_done * out.batch + len(seeds) * per * outcomes[0].batch
    out.steps_done += len(seeds) * per
    out.train_time_s += outcomes[best].train_time_s
    out.scouting = record
    return out
