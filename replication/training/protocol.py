"""The training protocol: everything that must be identical across JAX and PyTorch, in one frozen record.

A `Protocol` fixes the data (system, distribution, pool size, held-out size, coordinates), the loss,
the optimiser (Adam; b1, b2, eps), the learning rate as a pure function of the step (see
`replication.training.schedules`), the L2 penalty, the number of steps, the batch size, the dtype and the
seed. The batch order is drawn once in NumPy from the seed (`replication.training.data.BatchStream`) and fed
to both frameworks, so two frameworks given one protocol see the same numbers in the same order.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import numbers
from dataclasses import dataclass, field

LOSSES = ("l1", "mse", "l1_gamma")
SCHEDULES = ("constant", "step", "onecycle")
DTYPES = ("float32", "float64")
TASKS = ("acceleration", "hamiltonian", "inverse_dynamics")
COORDS = ("qqdot", "qp")
GUARD_FIELDS = ("grad_clip", "spike_skip")
SCOUT_FIELDS = ("scouts", "scout_steps", "scout_batch", "scout_lr", "scout_lr_start", "scout_keep")
OPTIONAL_FIELDS = GUARD_FIELDS + SCOUT_FIELDS + ("rollback", "cohort", "track_every")   # omitted from to_dict while 0 (off), so older keys hold


@dataclass(frozen=True)
class Protocol:
    """One training protocol. Sizes are in samples; `steps` optimiser steps of `batch` samples.

    data:      name of a data recipe in `replication.training.data.RECIPES` (e.g. "double_pendulum_iid").
    system_params: system parameter overrides as sorted (name, value) pairs.
    n_train:   size of the training pool; with `resample` a fresh pool is drawn every epoch
               (the original double-pendulum protocol), else one pool is shuffled every epoch.
    task:      what the model predicts (see `TASKS`); coords: inputs (q, qdot) or canonical (q, p).
    loss:      "l1" (per-sample sum of |error| over components, mean over the batch, as the
               original code), "mse" (per-sample sum of squares), "l1_gamma" (l1 weighted by 1+gamma,
               normalised by the sum of weights; the relativistic protocol).
    lr/schedule: peak learning rate and its shape; `lr_min_ratio` and `lr_start` parametrise the
               one-cycle cosine, `lr_step_every`/`lr_step_gamma` the step decay.
    l2:        coefficient of sum(theta^2) added to the loss (the original code's weight penalty).
    grad_clip/spike_skip: the gradient-spike guard (`replication.training.spike_guard`); 0 = off. grad_clip
               rescales a gradient whose global norm exceeds it; spike_skip skips a step (no update, Adam
               state kept) whose gradient norm is at least spike_skip x the median of the recent ones.
               Left out of `to_dict` (and so of `key`) while 0, so older protocols keep their keys.
    scouts/scout_steps/scout_batch/scout_lr/scout_lr_start: restarts over initialisations
               (`replication.training.scouting`); scouts <= 1 = off. With scouts = K > 1 the run first trains K
               initialisations side by side for scout_steps each (0: 5e5 samples) at batch scout_batch, peak
               rate scout_lr and one-cycle start scout_lr_start (0: the protocol's batch, lr and lr_start), then
               continues the one with the lowest training loss for `steps` steps of `batch` from `lr_start`:
               the budget is K * scout_steps * scout_batch + steps * batch samples. Left out of `to_dict`
               while 0, as the guard.
    scout_keep: successive halving of the scouts: 0 = off (every scout runs its scout_steps); k with
               1 <= k < scouts: all K run the first half of their schedule, the k lowest by training loss go
               on to its end, each as it would have without the cut (`scouting`); the budget's scout part is
               (K * half + k * (scout_steps - half)) * scout_batch, half = scout_steps // 2.
    rollback:  put back the parameters and Adam state of the best window so far when a window's mean training
               loss exceeds rollback x that best (`replication.training.rollback`); 0 = off, else > 1. One model
               at a time: the scouts run without it, a cohort may not use it. Left out of `to_dict` while 0.
    cohort:    train the seeds in groups of `cohort` as one vectorised program (`replication.training.train`:
               seeds g*cohort .. g*cohort + cohort - 1 side by side, each its own init, batches, guard and
               stop); each seed's numbers are those of its own run (up to floating-point reassociation).
               0 or 1 = one seed at a time; not combined with scouts. Left out of `to_dict` while 0.
    track_every: every so many steps, the held-out loss on a subset (`replication.training.tracking`), for
               work-precision curves; a multiple of log_every; 0 = off (left out of `to_dict`). It reads
               the model and changes no training number.
    """

    data: str
    steps: int
    batch: int
    n_train: int
    n_heldout: int = 10_000
    system_params: tuple = ()
    resample: bool = False
    task: str = "acceleration"
    coords: str = "qqdot"
    loss: str = "l1"
    lr: float = 1e-3
    schedule: str = "onecycle"
    lr_start: float = 0.2
    lr_min_ratio: float = 1e-4
    lr_step_every: int = 1000
    lr_step_gamma: float = 0.1
    b1: float = 0.9
    b2: float = 0.999
    eps: float = 1e-8
    l2: float = 0.0
    grad_clip: float = 0.0
    spike_skip: float = 0.0
    scouts: int = 0
    scout_steps: int = 0
    scout_batch: int = 0
    scout_lr: float = 0.0
    scout_lr_start: float = 0.0
    scout_keep: int = 0
    rollback: float = 0.0
    cohort: int = 0
    track_every: int = 0
    dtype: str = "float32"
    log_every: int = 50
    eval: dict = field(default_factory=dict, hash=False, compare=True)

    def __post_init__(self):
        checks = [("loss", LOSSES), ("schedule", SCHEDULES), ("dtype", DTYPES), ("task", TASKS),
                  ("coords", COORDS)]
        for name, valid in checks:
            if getattr(self, name) not in valid:
                raise ValueError(f"unknown {name} {getattr(self, name)!r}; valid: {', '.join(valid)}")
        for name in ("steps", "batch", "n_train", "n_heldout", "lr_step_every", "log_every"):
            if not _positive_integer(getattr(self, name)):
                raise ValueError(f"protocol {name} must be a positive integer, got {getattr(self, name)!r}")
        if self.batch > self.n_train:
            raise ValueError(f"batch {self.batch} exceeds the training pool n_train={self.n_train}")
        if not (_real(self.lr) and math.isfinite(self.lr) and self.lr > 0):
            raise ValueError(f"learning rate must be positive and finite, got {self.lr!r}")
        for name in GUARD_FIELDS:
            v = getattr(self, name)
            if not (_real(v) and math.isfinite(v) and v >= 0):
                raise ValueError(f"protocol {name} must be a finite number >= 0 (0 = off), got {v!r}")
        for name in ("scouts", "scout_steps", "scout_batch", "scout_keep", "cohort", "track_every"):
            v = getattr(self, name)
            if not (v == 0 or _positive_integer(v)):
                raise ValueError(f"protocol {name} must be an integer >= 0 (0 = off), got {v!r}")
        if not (_real(self.scout_lr) and math.isfinite(self.scout_lr) and self.scout_lr >= 0):
            raise ValueError(f"protocol scout_lr must be a finite number >= 0 (0 = lr), got {self.scout_lr!r}")
        for name in ("lr_start", "scout_lr_start"):
            v = getattr(self, name)
            if not (_real(v) and 0 <= v < 1):
                raise ValueError(f"protocol {name} must be a number in [0, 1) (the one-cycle's starting phase), got {v!r}")
        if not (_real(self.rollback) and math.isfinite(self.rollback) and (self.rollback == 0 or self.rollback > 1)):
            raise ValueError(f"protocol rollback must be 0 (off) or a factor > 1, got {self.rollback!r}")
        if self.rollback and self.cohort > 1:
            raise ValueError(f"protocol rollback {self.rollback} with cohort {self.cohort}: rollback restores one "
                             f"model's state; train the seeds one at a time")
        if self.cohort > 1 and self.scouts > 1:
            raise ValueError(f"protocol cohort {self.cohort} with scouts {self.scouts}: a cohort trains seeds side "
                             f"by side, scouts train initialisations side by side; use one of them")
        if self.scout_keep and not self.scout_keep < self.scouts:
            raise ValueError(f"protocol scout_keep {self.scout_keep} must be below scouts {self.scouts} (the scouts "
                             f"that go on after the first half of scouting; 0 = every scout goes on)")
        if self.scout_keep and self.scout_steps == 1:
            raise ValueError("protocol scout_keep needs scout_steps >= 2: the cut is at half the scouts' steps")
        if self.scout_batch > self.n_train:
            raise ValueError(f"scout_batch {self.scout_batch} exceeds the training pool n_train={self.n_train}")

    def objective_key(self) -> tuple:
        """What one optimiser step depends on besides the model: the loss and its target (task, loss, l2),
        Adam's constants, the clip, the dtype (a compiled step serves every protocol sharing them)."""
        return self.task, self.loss, self.l2, self.b1, self.b2, self.eps, self.grad_clip, self.dtype

    def to_dict(self) -> dict:
        d = dataclasses.asdict(self)
        d["system_params"] = [list(p) for p in self.system_params]
        for name in OPTIONAL_FIELDS:
            if not d[name]:
                del d[name]
        return d

    @classmethod
    def from_dict(cls, d: dict) -> Protocol:
        d = dict(d)
        d["system_params"] = tuple(tuple(p) for p in d.get("system_params", ()))
        return cls(**d)

    def replace(self, **changes) -> Protocol:
        return dataclasses.replace(self, **changes)

    def key(self) -> str:
        """A short stable hash of everything in the protocol."""
        blob = json.dumps(self.to_dict(), sort_keys=True, default=str).encode()
        return hashlib.sha256(blob).hexdigest()[:16]


def _real(v) -> bool:
    return isinstance(v, numbers.Real) and not isinstance(v, bool)


def _positive_integer(v) -> bool:
    """An int (or an integral finite float, as JSON may give) >= 1."""
    return _real(v) and math.isfinite(v) and v == int(v) and v >= 1
