"""The training protocol: everything that must be identical across JAX and PyTorch, in one frozen record.

A `Protocol` fixes the data (system, distribution, pool size, held-out size, coordinates), the loss,
the optimiser (Adam; b1, b2, eps), the learning rate as a pure function of the step (see
`replication.training.schedules`), the L2 penalty, the number of steps, the batch size, the dtype and the
seed. The batch order is drawn once in NumPy from the seed (`replication.training.data.BatchStream`) and fed
to both frameworks, so two frameworks given one protocol see the same numbers in the same order.

The optional parts of a run are records of their own, each `None` when the run does without it:
`guard` (`Guard`, the gradient-spike guard), `scouting` (`Scouting`, restarts over initialisations),
`cohort` (seeds trained side by side) and `tracking` (`Tracking`, held-out error during training). Every
value a part uses is written in it: nothing is inherited from the protocol by a zero.

`to_dict()` is the canonical form: every field, records as nested dicts, and `version` (`KEY_VERSION`), so
every cache key built from it changes when the form does; `from_dict` reads it, and also the flat form of
version 1 (whose optional parts were flat fields, 0 = off or "the protocol's"), so that older result
folders still load.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import numbers
from dataclasses import dataclass

LOSSES = ("l1", "mse", "l1_gamma")
SCHEDULES = ("constant", "step", "onecycle")
DTYPES = ("float32", "float64")
TASKS = ("acceleration", "hamiltonian", "inverse_dynamics")
COORDS = ("qqdot", "qp")
KEY_VERSION = 2
V1_SCOUT_SAMPLES = 500_000   # a version-1 protocol's samples per scout when it gave no scout_steps


@dataclass(frozen=True)
class Guard:
    """The gradient-spike guard (`replication.training.spike_guard`); a part left `None` is off.

    clip: a gradient whose global norm exceeds it is rescaled to it.
    skip: a step whose gradient norm is at least skip x the median of the recent ones is not taken (no
          update, Adam state kept)."""

    clip: float | None = None
    skip: float | None = None

    def __post_init__(self):
        if self.clip is None and self.skip is None:
            raise ValueError("a guard needs clip or skip (or both); a protocol without one has guard None")
        for name in ("clip", "skip"):
            v = getattr(self, name)
            if v is not None:
                _check(_real(v) and math.isfinite(v) and v > 0, f"guard {name} must be a finite number > 0, got {v!r}")
                object.__setattr__(self, name, float(v))


@dataclass(frozen=True)
class Scouting:
    """Restarts over initialisations (`replication.training.scouting`).

    count scouts (>= 2) train side by side for `steps` steps of `batch` samples at peak rate `lr` from the
    one-cycle phase `lr_start` (the protocol's schedule shape over the scout); with `keep` = k (successive
    halving, 1 <= k < count) all stop at half their steps and the k lowest by training loss go on to the
    end. The chosen scout is continued for the protocol's `steps` of its `batch` from its `lr_start`.
    The budget is count x steps x batch (with a cut: (count x half + keep x (steps - half)) x batch) plus
    the continuation's samples."""

    count: int
    steps: int
    batch: int
    lr: float
    lr_start: float
    keep: int | None = None

    def __post_init__(self):
        _check(_integer(self.count) and self.count >= 2,
               f"scouting count must be an integer >= 2 (a protocol without restarts has scouting None), got {self.count!r}")
        for name in ("steps", "batch"):
            _check(_integer(getattr(self, name)) and getattr(self, name) >= 1,
                   f"scouting {name} must be a positive integer, got {getattr(self, name)!r}")
        _check(_real(self.lr) and math.isfinite(self.lr) and self.lr > 0,
               f"scouting lr must be positive and finite, got {self.lr!r}")
        _check(_real(self.lr_start) and 0 <= self.lr_start < 1,
               f"scouting lr_start must be a number in [0, 1) (the one-cycle's starting phase), got {self.lr_start!r}")
        if self.keep is not None:
            _check(_integer(self.keep) and 1 <= self.keep < self.count,
                   f"scouting keep {self.keep!r} must be an integer from 1 to below count {self.count} (the scouts "
                   f"that go on after the first half; None = every scout goes on)")
            _check(self.steps >= 2, "scouting keep needs steps >= 2: the cut is at half the scouts' steps")
        for name in ("count", "steps", "batch") + (("keep",) if self.keep is not None else ()):
            object.__setattr__(self, name, int(getattr(self, name)))
        object.__setattr__(self, "lr", float(self.lr))
        object.__setattr__(self, "lr_start", float(self.lr_start))


@dataclass(frozen=True)
class Tracking:
    """Held-out loss every `every` steps (`replication.training.tracking`), for work-precision curves; a
    multiple of the protocol's log_every. It reads the model and changes no training number."""

    every: int

    def __post_init__(self):
        _check(_integer(self.every) and self.every >= 1, f"tracking every must be a positive integer, got {self.every!r}")
        object.__setattr__(self, "every", int(self.every))


PARTS = {"guard": Guard, "scouting": Scouting, "tracking": Tracking}
_FLOATS = ("lr", "lr_start", "lr_min_ratio", "lr_step_gamma", "b1", "b2", "eps", "l2")
_INTS = ("steps", "batch", "n_train", "n_heldout", "lr_step_every", "log_every")


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
    guard, scouting, tracking: the optional parts (`Guard`, `Scouting`, `Tracking`), None when off.
    cohort:    train the seeds in groups of `cohort` (>= 2) as one vectorised program
               (`replication.training.train`: seeds g*cohort .. g*cohort + cohort - 1 side by side, each its
               own init, batches, guard and stop); each seed's numbers are those of its own run (up to
               floating-point reassociation). None: one seed at a time; not combined with scouting.
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
    guard: Guard | None = None
    scouting: Scouting | None = None
    cohort: int | None = None
    tracking: Tracking | None = None
    dtype: str = "float32"
    log_every: int = 50

    def __post_init__(self):
        checks = [("loss", LOSSES), ("schedule", SCHEDULES), ("dtype", DTYPES), ("task", TASKS),
                  ("coords", COORDS)]
        for name, valid in checks:
            if getattr(self, name) not in valid:
                raise ValueError(f"unknown {name} {getattr(self, name)!r}; valid: {', '.join(valid)}")
        for name in _INTS:
            _check(_integer(getattr(self, name)) and getattr(self, name) >= 1,
                   f"protocol {name} must be a positive integer, got {getattr(self, name)!r}")
        _check(self.batch <= self.n_train, f"batch {self.batch} exceeds the training pool n_train={self.n_train}")
        _check(_real(self.lr) and math.isfinite(self.lr) and self.lr > 0,
               f"learning rate must be positive and finite, got {self.lr!r}")
        _check(_real(self.lr_start) and 0 <= self.lr_start < 1,
               f"protocol lr_start must be a number in [0, 1) (the one-cycle's starting phase), got {self.lr_start!r}")
        for name in ("lr_min_ratio", "lr_step_gamma", "b1", "b2", "eps", "l2"):
            _check(_real(getattr(self, name)) and math.isfinite(getattr(self, name)),
                   f"protocol {name} must be a finite number, got {getattr(self, name)!r}")
        for name, kind in PARTS.items():
            v = getattr(self, name)
            _check(v is None or isinstance(v, kind), f"protocol {name} must be a {kind.__name__} or None, got {v!r}")
        _check(self.cohort is None or (_integer(self.cohort) and self.cohort >= 2),
               f"protocol cohort must be an integer >= 2 (None: one seed at a time), got {self.cohort!r}")
        if self.cohort and self.scouting:
            raise ValueError(f"protocol cohort {self.cohort} with scouting: a cohort trains seeds side by side, "
                             f"scouts train initialisations side by side; use one of them")
        if self.scouting and self.scouting.batch > self.n_train:
            raise ValueError(f"scouting batch {self.scouting.batch} exceeds the training pool n_train={self.n_train}")
        if self.tracking and self.tracking.every % self.log_every:
            raise ValueError(f"protocol tracking every {self.tracking.every} is not a multiple of log_every "
                             f"{self.log_every}")
        # one canonical value per number, so that 1 and 1.0 give one key
        for name in _FLOATS:
            object.__setattr__(self, name, float(getattr(self, name)))
        for name in _INTS + (("cohort",) if self.cohort else ()):
            object.__setattr__(self, name, int(getattr(self, name)))

    def objective_key(self) -> tuple:
        """What one optimiser step depends on besides the model: the loss and its target (task, loss, l2),
        Adam's constants, the clip, the dtype (a compiled step serves every protocol sharing them)."""
        return self.task, self.loss, self.l2, self.b1, self.b2, self.eps, self.grad_clip, self.dtype

    @property
    def grad_clip(self) -> float | None:
        """The guard's clip (None: no clip)."""
        return self.guard.clip if self.guard else None

    def to_dict(self) -> dict:
        d = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        for name in PARTS:
            d[name] = dataclasses.asdict(d[name]) if d[name] is not None else None
        d["system_params"] = [list(p) for p in self.system_params]
        return {"version": KEY_VERSION, **d}

    @classmethod
    def from_dict(cls, d: dict) -> Protocol:
        d = dict(d)
        version = d.pop("version", 1)
        if version == 1:
            d = _from_flat(d)
        elif version != KEY_VERSION:
            raise ValueError(f"protocol version {version!r} is not known; this suite reads 1 and {KEY_VERSION}")
        d["system_params"] = tuple(tuple(p) for p in d.get("system_params", ()))
        for name, kind in PARTS.items():
            if d.get(name) is not None:
                d[name] = kind(**d[name])
        return cls(**d)

    def replace(self, **changes) -> Protocol:
        """A copy with fields changed; "part.field" (e.g. "scouting.lr") changes one field of a part that is on."""
        direct = {k: v for k, v in changes.items() if "." not in k}
        for key, v in changes.items():
            if "." in key:
                part, name = key.split(".", 1)
                record = direct.get(part, getattr(self, part, None)) if part in PARTS else None
                if record is None:
                    raise ValueError(f"cannot set {key}: the protocol has no {part}")
                direct[part] = dataclasses.replace(record, **{name: v})
        return dataclasses.replace(self, **direct)

    def key(self) -> str:
        """A short stable hash of everything in the protocol (its canonical `to_dict`)."""
        return canonical_hash(self.to_dict(), 16)


def canonical_hash(obj, digits: int) -> str:
    """The first `digits` hex digits of the sha256 of `obj` as canonical JSON (sorted keys, no spaces)."""
    blob = json.dumps(obj, sort_keys=True, separators=(",", ":"), default=str).encode()
    return hashlib.sha256(blob).hexdigest()[:digits]


def _from_flat(d: dict) -> dict:
    """A version-1 protocol dict (optional parts as flat fields: 0 = off, 0 = the protocol's value) in the
    fields of this version."""
    d = dict(d)
    d.pop("eval", None)
    if d.pop("rollback", 0):
        raise ValueError("a protocol with rollback (version 1) cannot be read: rollback is no longer a protocol part")
    clip, skip = d.pop("grad_clip", 0), d.pop("spike_skip", 0)
    d["guard"] = {"clip": clip or None, "skip": skip or None} if (clip or skip) else None
    flat = {k: d.pop(f"scout{k}", 0) for k in ("s", "_steps", "_batch", "_lr", "_lr_start", "_keep")}
    if flat["s"] > 1:
        batch = flat["_batch"] or d["batch"]
        d["scouting"] = {"count": flat["s"], "steps": flat["_steps"] or max(V1_SCOUT_SAMPLES // batch, 1), "batch": batch,
                         "lr": flat["_lr"] or d.get("lr", _default("lr")),
                         "lr_start": flat["_lr_start"] or d.get("lr_start", _default("lr_start")),
                         "keep": flat["_keep"] or None}
    cohort = d.pop("cohort", 0)
    d["cohort"] = cohort if cohort and cohort > 1 else None
    every = d.pop("track_every", 0)
    d["tracking"] = {"every": every} if every else None
    return d


def _default(name: str):
    return Protocol.__dataclass_fields__[name].default


def _check(ok: bool, message: str) -> None:
    if not ok:
        raise ValueError(message)


def _real(v) -> bool:
    return isinstance(v, numbers.Real) and not isinstance(v, bool)


def _integer(v) -> bool:
    """An int (or an integral finite float, as JSON may give)."""
    return _real(v) and math.isfinite(v) and v == int(v)
