"""The training protocol: everything that must be identical across JAX and PyTorch, in one frozen record.

A `Protocol` is made of small records (`replication.training.protocol_parts`): the data (`Data`: recipe,
pool sizes, coordinates), the optimiser (`Adam`) and the learning rate as a pure function of the step (a
schedule record of `replication.training.schedules`), beside the loss, the L2 penalty, the number of steps,
the batch size, the dtype and the seed. The batch order is drawn once in NumPy from the seed
(`replication.training.data.BatchStream`) and fed to both frameworks, so two frameworks given one protocol
see the same numbers in the same order. The optional parts, each `None` when the run does without it:
`guard` (`Guard`), `scouting` (`Scouting`), `cohort` (seeds trained side by side), `tracking`
(`Tracking`), `early_stop` (`EarlyStop`), `trajectory_loss` (`TrajectoryLoss`: train on positions over
windows of a recording) and `filter_loss` (`FilterLoss`: train on q-double-dot seen through the derivative
filter); with either loss part the held-out rows stay the task's.

`to_dict()` is the canonical form: every field (but `data.fixed` while empty, `tracking.keep` while off and
`early_stop`, `trajectory_loss`, `filter_loss` while None, so the protocols without them keep their keys), records as nested
dicts, and `version` (`KEY_VERSION`), so
every cache key built from it changes when the form does; `from_dict` reads it, and the forms of earlier
versions (`replication.training.protocol_versions`), so that older result folders still load.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
from dataclasses import dataclass

from lagbench.replication.training.protocol_parts import (
    COORDS,
    Adam,
    Data,
    EarlyStop,
    FilterLoss,
    Guard,
    Scouting,
    Tracking,
    TrajectoryLoss,
)
from lagbench.replication.training.schedules import (
    SCHEDULES,
    OneCycle,
    Schedule,
    schedule_from_dict,
    schedule_to_dict,
)
from lagbench.validate import check, integer, is_integer, one_of, real

__all__ = ["LOSSES", "DTYPES", "TASKS", "COORDS", "KEY_VERSION", "Protocol", "Data", "Adam", "Guard", "Scouting",
           "Tracking", "EarlyStop", "TrajectoryLoss", "FilterLoss", "canonical_hash"]

LOSSES = ("l1", "mse", "l1_gamma")
DTYPES = ("float32", "float64")
TASKS = ("acceleration", "hamiltonian", "inverse_dynamics")
KEY_VERSION = 3
PARTS = {"guard": Guard, "tracking": Tracking, "early_stop": EarlyStop,   # optional parts stored as their fields
         "trajectory_loss": TrajectoryLoss, "filter_loss": FilterLoss}
UNSTORED_WHEN_OFF = ("early_stop", "trajectory_loss", "filter_loss")   # parts no claim has: out of `to_dict` while None


@dataclass(frozen=True)
class Protocol:
    """One training protocol. Sizes are in samples; `steps` optimiser steps of `batch` samples.

    data:      `Data`: recipe, training pool, held-out size, system parameters, coordinates.
    task:      what the model predicts (see `TASKS`).
    loss:      "l1" (per-sample sum of |error| over components, mean over the batch, as the
               original code), "mse" (per-sample sum of squares), "l1_gamma" (l1 weighted by 1+gamma,
               normalised by the sum of weights; the relativistic protocol).
    l2:        coefficient of sum(theta^2) added to the loss (the original code's weight penalty).
    optimiser: `Adam`'s constants; schedule: the learning rate (`Constant`, `StepDecay`, `OneCycle`).
    guard, scouting, tracking, early_stop: the optional parts (`Guard`, `Scouting`, `Tracking`, `EarlyStop`),
               None when off.
    trajectory_loss: a `TrajectoryLoss` (None: off): the training loss compares positions integrated over
               windows of a recording (a user's file, task acceleration or hamiltonian) instead of the task's
               target; the held-out rows and everything evaluated stay the task's.
    filter_loss: a `FilterLoss` (None: off): the training loss compares the estimated q-double-dot with the
               model's seen through the filter that estimated it (a user's recording, task acceleration); the
               held-out rows and everything evaluated stay the task's.
    cohort:    train the seeds in groups of `cohort` (>= 2) as one vectorised program
               (`replication.training.train`: seeds g*cohort .. g*cohort + cohort - 1 side by side, each its
               own init, batches, guard and stop); each seed's numbers are those of its own run (up to
               floating-point reassociation). None: one seed at a time; not combined with scouting.
    """

    data: Data
    steps: int
    batch: int
    task: str = "acceleration"
    loss: str = "l1"
    l2: float = 0.0
    optimiser: Adam = Adam()
    schedule: Schedule = OneCycle(lr=1e-3)
    guard: Guard | None = None
    scouting: Scouting | None = None
    cohort: int | None = None
    tracking: Tracking | None = None
    dtype: str = "float32"
    log_every: int = 50
    early_stop: EarlyStop | None = None   # out of `to_dict` while None: the protocols without it keep their keys
    trajectory_loss: TrajectoryLoss | None = None   # likewise
    filter_loss: FilterLoss | None = None   # likewise

    def __post_init__(self):
        for name, valid in (("loss", LOSSES), ("dtype", DTYPES), ("task", TASKS)):
            one_of(name, getattr(self, name), valid)
        for name, kind in (("data", Data), ("optimiser", Adam), ("schedule", tuple(SCHEDULES.values()))):
            check(isinstance(getattr(self, name), kind), f"protocol {name} must be a record, got {getattr(self, name)!r}")
        for name in ("steps", "batch", "log_every"):
            object.__setattr__(self, name, integer(f"protocol {name}", getattr(self, name), low=1))
        object.__setattr__(self, "l2", float(real("protocol l2", self.l2)))
        n_train = self.data.n_train
        check(self.batch <= n_train, f"batch {self.batch} exceeds the training pool n_train={n_train}")
        for name, kind in (*PARTS.items(), ("scouting", Scouting)):
            v = getattr(self, name)
            check(v is None or isinstance(v, kind), f"protocol {name} must be a {kind.__name__} or None, got {v!r}")
        check(self.cohort is None or (is_integer(self.cohort) and self.cohort >= 2),
              f"protocol cohort must be an integer >= 2 (None: one seed at a time), got {self.cohort!r}")
        if self.cohort is not None:
            object.__setattr__(self, "cohort", int(self.cohort))
        if self.cohort and self.scouting:
            raise ValueError(f"protocol cohort {self.cohort} with scouting: a cohort trains seeds side by side, "
                             f"scouts train initialisations side by side; use one of them")
        if self.scouting and self.scouting.batch > n_train:
            raise ValueError(f"scouting batch {self.scouting.batch} exceeds the training pool n_train={n_train}")
        for name in ("tracking", "early_stop"):
            part = getattr(self, name)
            if part and part.every % self.log_every:
                raise ValueError(f"protocol {name.replace('_', ' ')} every {part.every} is not a multiple of log_every "
                                 f"{self.log_every}")
        if self.trajectory_loss is not None:
            check(self.task in ("acceleration", "hamiltonian"),
                  f"protocol trajectory_loss integrates the model's motion: a task of acceleration or hamiltonian, "
                  f"got {self.task}")
            check(self.data.recipe.startswith("file:"),
                  f"protocol trajectory_loss trains on windows of a recording: a file recipe, got {self.data.recipe!r}")
            check(self.data.coords == "qqdot", "protocol trajectory_loss starts each window from (q, qdot): coords qqdot, "
                                               f"got {self.data.coords}")
        if self.filter_loss is not None:
            check(self.trajectory_loss is None, "protocol filter_loss with trajectory_loss: each replaces the task's "
                                                "training loss; use one of them")
            check(self.task == "acceleration", f"protocol filter_loss filters the model's q-double-dot: task "
                                               f"acceleration, got {self.task}")
            check(self.data.recipe.startswith("file:"), f"protocol filter_loss trains on the frames of a recording: "
                                                        f"a file recipe, got {self.data.recipe!r}")
        if self.cohort and self.early_stop:
            raise ValueError(f"protocol cohort {self.cohort} with early_stop: the seeds of a cohort train as one "
                             f"program and stop together; give each seed its own run")

    def objective_key(self) -> tuple:
        """What one optimiser step depends on besides the model: the loss and its target (task, loss, l2, the
        trajectory or filter loss), Adam's constants, the clip, the dtype (a compiled step serves every protocol
        sharing them)."""
        return (self.task, self.loss, self.l2, self.optimiser, self.grad_clip, self.dtype, self.trajectory_loss,
                self.filter_loss)

    @property
    def grad_clip(self) -> float | None:
        """The guard's clip (None: no clip)."""
        return self.guard.clip if self.guard else None

    def to_dict(self) -> dict:
        d = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        d["data"] = {**dataclasses.asdict(self.data), "system_params": [list(p) for p in self.data.system_params],
                     "fixed": list(self.data.fixed)}
        if not d["data"]["fixed"]:
            del d["data"]["fixed"]   # only a protocol that keeps entries stores them: other protocols keep their keys
        d["optimiser"] = dataclasses.asdict(self.optimiser)
        d["schedule"] = schedule_to_dict(self.schedule)
        for name in PARTS:
            d[name] = dataclasses.asdict(d[name]) if d[name] is not None else None
        for name in UNSTORED_WHEN_OFF:
            if d[name] is None:
                del d[name]   # only a protocol that has the part stores it: other protocols keep their keys
        if d["tracking"] is not None and not d["tracking"]["keep"]:
            del d["tracking"]["keep"]   # only a kept tracking is stored: other protocols keep their keys
        if self.scouting is not None:
            d["scouting"] = {**dataclasses.asdict(self.scouting), "schedule": schedule_to_dict(self.scouting.schedule)}
            if not self.scouting.fallback:
                del d["scouting"]["fallback"]   # only a protocol with fallbacks stores it: others keep their keys
        return {"version": KEY_VERSION, **d}

    @classmethod
    def from_dict(cls, d: dict) -> Protocol:
        from lagbench.replication.training.protocol_versions import upgraded
        d = upgraded(dict(d), KEY_VERSION)
        d.pop("version", None)
        d["data"] = Data(**d["data"])
        d["optimiser"] = Adam(**d["optimiser"])
        d["schedule"] = schedule_from_dict(d["schedule"])
        for name, kind in PARTS.items():
            if d.get(name) is not None:
                d[name] = kind(**d[name])
        if d.get("scouting") is not None:
            d["scouting"] = Scouting(**{**d["scouting"], "schedule": schedule_from_dict(d["scouting"]["schedule"])})
        return cls(**d)

    def replace(self, **changes) -> Protocol:
        """A copy with fields changed; a dotted name changes one field of a record ("data.n_train",
        "schedule.lr", "scouting.schedule.lr"): the record must be there (a part that is on)."""
        return _replace(self, changes, "")

    def key(self) -> str:
        """A short stable hash of everything in the protocol (its canonical `to_dict`)."""
        return canonical_hash(self.to_dict(), 16)


def _replace(record, changes: dict, where: str):
    direct, nested = {}, {}
    for key, v in changes.items():
        head, dot, rest = key.partition(".")
        (nested.setdefault(head, {}).__setitem__(rest, v) if dot else direct.__setitem__(key, v))
    names = {f.name for f in dataclasses.fields(record)}
    unknown = sorted((set(direct) | set(nested)) - names)
    if unknown:
        raise ValueError(f"cannot set {where}{unknown[0]}: no such field; valid: {', '.join(sorted(names))}")
    for head, sub in nested.items():
        child = direct.get(head, getattr(record, head))
        if not dataclasses.is_dataclass(child):
            raise ValueError(f"cannot set {where}{head}.{next(iter(sub))}: the protocol has no {where}{head}")
        direct[head] = _replace(child, sub, f"{where}{head}.")
    return dataclasses.replace(record, **direct)


def canonical_hash(obj, digits: int) -> str:
    """The first `digits` hex digits of the sha256 of `obj` as canonical JSON (sorted keys, no spaces)."""
    blob = json.dumps(obj, sort_keys=True, separators=(",", ":"), default=str).encode()
    return hashlib.sha256(blob).hexdigest()[:digits]
