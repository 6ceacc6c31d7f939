"""Early stopping: a run ends when its held-out error stops improving (`Protocol.early_stop`), closing with an
anneal of its learning rate.

`EarlyStopper(framework, spec, protocol, offset_steps=0)` is a loop hook (`replication.training.loop`) for
one model: every `early_stop.every` steps (from step 0) and at the last, it evaluates the model's data loss
(the protocol's own loss, no L2 term: `tracking.data_loss`) on the protocol's held-out rows, at most
`MAX_ROWS` of them. A value below best x (1 - `min_improvement`) is a new best; the hook returns True (the
loop stops after that step) at the evaluation that makes `patience` in a row without one. A non-finite
value is never a best. The parameters the run ends with are the last step's: the held-out rows choose when
the run stops and nothing else (a minimum over many evaluations of one set would understate the error that
set then reports).

`train_stopping(trainer, spec, params, protocol, stream, on_log, hooks, snapshot, stop)`: `trainer.train` with
the hook `stop` (None: a plain `trainer.train`); where it stopped, the run goes on from its exact state (model,
Adam, guard, batch stream: `scouting.HeldState`) for `early_stop.anneal` steps (at most to the protocol's
steps) under `anneal_protocol`: the rate falls along a half cosine from the schedule's rate at the stop to
the rate the schedule ends at (a one-cycle's final rate; a constant rate stays), as the schedule would have
closed the run. Why: a stop in the middle of a one-cycle leaves the model at its peak rate, and on a pendulum
recording its rollouts were twice as far off as a run's that annealed (`docs/decisions/fit_budget.md`).

`record()`: {every, patience, min_improvement, anneal, evaluations, best_step, best_heldout_loss,
last_heldout_loss, stopped_at (the step it stopped after, None: it ran its steps)}, steps of the protocol it watches (from 0; a
continuation's after its restarts); `merge(outcome)` writes `heldout_loss` into the outcome's log rows of the
evaluated steps (an evaluation step is a log step: `every` is a multiple of `log_every`; those rows' steps
shifted by `offset_steps`, as a continuation's log is after its restarts) and sets `outcome.early_stop` to
the record. Its state travels in snapshots.
"""
from __future__ import annotations

import math

import numpy as np

from lagbench.replication.training import data as datamod
from lagbench.replication.training.schedules import Anneal, learning_rate
from lagbench.replication.training.scouting import HeldState
from lagbench.replication.training.tracking import data_loss

MAX_ROWS = 10_000   # held-out rows an evaluation reads (more cost time and change a mean of that size little)


class EarlyStopper:
    def __init__(self, framework, spec, protocol, offset_steps: int = 0):
        held = datamod.heldout(protocol)
        self.batch = {k: v[:MAX_ROWS] if hasattr(v, "shape") and v.ndim else v for k, v in held.items()}
        self.framework, self.spec, self.protocol, self.offset = framework, spec, protocol, offset_steps
        self.rows: list[dict] = []   # {"step", "heldout_loss"} per evaluation
        self.best, self.best_step, self.since, self.stopped = math.inf, None, 0, None

    def __call__(self, k, stepper, info) -> bool:
        e, p = self.protocol.early_stop, self.protocol
        if k % e.every and k != p.steps - 1:
            return False
        with np.errstate(all="ignore"):
            loss = data_loss(self.framework, self.spec, p, self.batch, stepper.params())
        self.rows.append({"step": k + self.offset, "heldout_loss": loss})
        if math.isfinite(loss) and loss < self.best * (1 - e.min_improvement):
            self.best, self.best_step, self.since = loss, k, 0
            return False
        self.since += 1
        if self.since >= e.patience and k != p.steps - 1:
            self.stopped = k
            return True
        return False

    def record(self) -> dict:
        e = self.protocol.early_stop
        return {"every": e.every, "patience": e.patience, "min_improvement": e.min_improvement, "anneal": e.anneal,
                "evaluations": len(self.rows), "best_step": self.best_step,
                "best_heldout_loss": self.best if math.isfinite(self.best) else None,
                "last_heldout_loss": self.rows[-1]["heldout_loss"] if self.rows else None, "stopped_at": self.stopped}

    def merge(self, outcome) -> None:
        at = {r["step"]: r["heldout_loss"] for r in self.rows}
        for row in outcome.log:
            if row["step"] in at:
                row["heldout_loss"] = at[row["step"]]
        outcome.early_stop = self.record()

    def snapshot_state(self):
        return {"rows": self.rows, "best": self.best if math.isfinite(self.best) else None,
                "best_step": self.best_step, "since": self.since, "stopped": self.stopped}, {}

    def restore_snapshot(self, meta, arrays):
        self.rows = [dict(r) for r in meta["rows"]]
        self.best = math.inf if meta["best"] is None else float(meta["best"])
        self.best_step, self.since, self.stopped = meta["best_step"], int(meta["since"]), meta["stopped"]


def anneal_protocol(protocol, stopped: int):
    """The protocol a run stopped after step `stopped` closes under: its steps end `early_stop.anneal` later (at
    most the protocol's), the rate falling from the schedule's at the next step to its rate at the end."""
    steps = min(stopped + 1 + protocol.early_stop.anneal, protocol.steps)
    schedule = Anneal(lr=learning_rate(protocol, stopped + 1), final=learning_rate(protocol, protocol.steps),
                      begin=stopped + 1)
    return protocol.replace(steps=steps, schedule=schedule, early_stop=None)


def train_stopping(trainer, spec, params, protocol, stream, on_log=None, hooks=(), snapshot=None, stop=None):
    if stop is None:
        return trainer.train(spec, params, protocol, stream, on_log=on_log, hooks=hooks, snapshot=snapshot)
    held = HeldState(snapshot)
    out = trainer.train(spec, params, protocol, stream, on_log=on_log, hooks=(*hooks, stop), snapshot=held)
    if stop.stopped is None or out.failure is not None or not protocol.early_stop.anneal:
        return out
    return trainer.train(spec, out.params, anneal_protocol(protocol, stop.stopped), stream, on_log=on_log,
                         hooks=hooks, snapshot=snapshot.phase("anneal") if snapshot else None, start_state=held.state)
