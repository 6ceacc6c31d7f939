"""Held-out error during training, for work-precision curves (error against samples and training time).

`Tracker(framework, spec, protocol)` is a loop hook (`replication.training.loop`): every `protocol.tracking.every`
steps and at the last, it evaluates each member's data loss (the protocol's own loss, no L2 term) on the
first `TRACK_STATES` held-out states through a NumPy adapter (`replication.evaluation.adapters`; JAX compiles it once
per spec). It records step, samples, the training seconds so far (the loop's `step_seconds`: optimiser
steps only, the first compiling step and these evaluations left out) and `heldout_loss`. With
`tracking.keep` it also keeps each member's parameters at those steps. `merge(outcomes)` writes the rows into
the outcomes' training logs as the columns `heldout_loss`, `train_s` and `samples` on the rows of the same
step (a tracking step is also a log step: `tracking.every` is a multiple of `log_every`) and, when kept, the
parameters as `outcome.tracked` (`checkpoints(i)`: {"step": (n,), "p/<name>": (n, ...) stacked}).
`data_loss(framework, spec, protocol, batch, params)`: that loss of one model on a set (`early_stop` reads it
too). The offsets shift steps, samples and seconds (a continuation after its scouts, whose samples and time count).
Its rows and kept parameters travel in a training's snapshots (`snapshot_state`, `restore_snapshot`;
`replication.training.snapshots`).
"""
from __future__ import annotations

import numpy as np

from lagbench.replication.evaluation.adapters import adapter
from lagbench.replication.training import data as datamod
from lagbench.replication.training.objective import loss_value, predict

TRACK_STATES = 2000


class Tracker:
    def __init__(self, framework, spec, protocol, offset_steps: int = 0, offset_samples: int = 0,
                 offset_seconds: float = 0.0):
        held = datamod.heldout(protocol)
        self.batch = {k: v[:TRACK_STATES] if hasattr(v, "shape") and v.ndim else v for k, v in held.items()}
        self.framework, self.spec, self.protocol = framework, spec, protocol
        self.offset_steps, self.offset_samples, self.offset_seconds = offset_steps, offset_samples, offset_seconds
        self.rows: list[list[dict]] = []
        self.keep = bool(protocol.tracking.keep)
        self.kept: list[list[dict]] = []   # per member, the parameters at each tracked step (with keep)

    def _loss(self, params) -> float:
        return data_loss(self.framework, self.spec, self.protocol, self.batch, params)

    def __call__(self, k, stepper, info) -> bool:
        p = self.protocol
        if k % p.tracking.every and k != p.steps - 1:
            return False
        params = stepper.params()
        members = params if isinstance(params, list) else [params]
        while len(self.rows) < len(members):
            self.rows.append([])
            self.kept.append([])
        for i, theta in enumerate(members):
            with np.errstate(all="ignore"):
                loss = self._loss(theta)
            self.rows[i].append({"step": k + self.offset_steps, "heldout_loss": loss,
                                 "train_s": float(info["step_seconds"]) + self.offset_seconds,
                                 "samples": (k + 1) * p.batch + self.offset_samples})
            if self.keep:
                self.kept[i].append({n: np.array(a, copy=True) for n, a in theta.items()})
        return False

    def checkpoints(self, i: int) -> dict | None:
        """Member i's kept parameters: {"step": (n,) int, "p/<name>": (n, ...)}; None without keep or rows."""
        if not self.keep or i >= len(self.kept) or not self.kept[i]:
            return None
        kept = self.kept[i]
        steps = np.array([r["step"] for r in self.rows[i][:len(kept)]], np.int64)
        return {"step": steps, **{f"p/{n}": np.stack([c[n] for c in kept]) for n in kept[0]}}

    def snapshot_state(self):
        arrays = {}
        for i in range(len(self.kept)):
            for name, a in (self.checkpoints(i) or {}).items():
                arrays[f"m{i}/{name}"] = a
        return self.rows, arrays

    def restore_snapshot(self, meta, arrays):
        self.rows = [[dict(r) for r in member] for member in meta]
        self.kept = [unstack({k.split("/", 1)[1]: v for k, v in arrays.items() if k.startswith(f"m{i}/")})
                     for i in range(len(self.rows))]

    def merge(self, outcomes) -> None:
        """Add the tracked columns to each member's log rows of the same step (in place); with keep, set each
        outcome's `tracked` to its member's kept parameters."""
        for i, (out, rows) in enumerate(zip(outcomes, self.rows, strict=False)):
            at = {r["step"]: r for r in rows}
            for row in out.log:
                row.update({k: v for k, v in at.get(row["step"], {}).items() if k != "step"})
            if self.keep:
                out.tracked = self.checkpoints(i)


def data_loss(framework, spec, protocol, batch: dict, params) -> float:
    """The protocol's own loss (no L2 term) of the model `params` on `batch` (a held-out set's arrays)."""
    m = adapter(framework, spec, params)
    pred = predict(m, spec.kind, protocol.task, batch, np.concatenate)
    return float(loss_value(np.asarray(pred, np.float64), batch["target"], batch.get("weight"), protocol.loss))


def unstack(checkpoints: dict | None) -> list[dict]:
    """`checkpoints(i)`'s arrays back to one parameter dict per kept step (init_params layout)."""
    if not checkpoints or "step" not in checkpoints:
        return []
    names = [k for k in checkpoints if k.startswith("p/")]
    return [{n[2:]: checkpoints[n][j] for n in names} for j in range(len(checkpoints["step"]))]
