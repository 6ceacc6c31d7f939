"""Learning rate as a pure function of the step: the same float for JAX and PyTorch.

A schedule is a record holding every value its shape uses (and none it does not):
- `Constant(lr)`:                  lr.
- `StepDecay(lr, every, gamma)`:   lr * gamma ** (step // every).
- `OneCycle(lr, start, min_ratio)`: the original LNN code's cosine one-cycle. With fraction f = step / steps,
  the phase is p = start + (1 - start) * f and lr(p) = low + (high - low) * (1 - cos(2 pi p)) / 2,
  high = lr, low = lr * min_ratio. It starts part-way up (p = 0.2 in the code), peaks at p = 0.5 and falls
  back to `low` at the end.
- `Anneal(lr, final, begin)`:       lr until step `begin`, then a half cosine down to `final` at `steps`: the
  close of a run its early stop ended (`replication.training.early_stop`).
`learning_rate(protocol, step)` -> float reads the protocol's schedule over its `steps`.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import ClassVar

from lagbench.validate import integer, positive, real


def _check_lr(lr) -> float:
    return float(positive("learning rate", lr))


@dataclass(frozen=True)
class Constant:
    lr: float
    kind: ClassVar[str] = "constant"

    def __post_init__(self):
        object.__setattr__(self, "lr", _check_lr(self.lr))

    def rate(self, step: int, steps: int) -> float:
        return self.lr


@dataclass(frozen=True)
class StepDecay:
    lr: float
    every: int
    gamma: float
    kind: ClassVar[str] = "step"

    def __post_init__(self):
        object.__setattr__(self, "lr", _check_lr(self.lr))
        object.__setattr__(self, "every", integer("step schedule every", self.every, low=1))
        object.__setattr__(self, "gamma", float(positive("step schedule gamma", self.gamma)))

    def rate(self, step: int, steps: int) -> float:
        return self.lr * self.gamma ** (step // self.every)


@dataclass(frozen=True)
class OneCycle:
    lr: float
    start: float = 0.2
    min_ratio: float = 1e-4
    kind: ClassVar[str] = "onecycle"

    def __post_init__(self):
        object.__setattr__(self, "lr", _check_lr(self.lr))
        object.__setattr__(self, "start", float(real("one-cycle start (the cycle's starting phase)", self.start, low=0,
                                                     below=1)))
        object.__setattr__(self, "min_ratio", float(real("one-cycle min_ratio", self.min_ratio, low=0)))

    def rate(self, step: int, steps: int) -> float:
        phase = self.start + (1.0 - self.start) * (step / max(steps, 1))
        low = self.lr * self.min_ratio
        return low + (self.lr - low) * (1.0 - math.cos(2.0 * math.pi * phase)) / 2.0


@dataclass(frozen=True)
class Anneal:
    lr: float
    final: float
    begin: int
    kind: ClassVar[str] = "anneal"

    def __post_init__(self):
        object.__setattr__(self, "lr", _check_lr(self.lr))
        object.__setattr__(self, "final", float(real("anneal final rate", self.final, low=0)))
        object.__setattr__(self, "begin", integer("anneal begin", self.begin, low=0))

    def rate(self, step: int, steps: int) -> float:
        f = min(max(step - self.begin, 0) / max(steps - self.begin, 1), 1.0)
        return self.final + (self.lr - self.final) * (1.0 + math.cos(math.pi * f)) / 2.0


SCHEDULES = {s.kind: s for s in (Constant, StepDecay, OneCycle, Anneal)}
Schedule = Constant | StepDecay | OneCycle | Anneal


def schedule_to_dict(s: Schedule) -> dict:
    return {"kind": s.kind, **dataclasses.asdict(s)}


def schedule_from_dict(d: dict) -> Schedule:
    d = dict(d)
    kind = d.pop("kind", None)
    if kind not in SCHEDULES:
        raise ValueError(f"unknown schedule {kind!r}; valid: {', '.join(SCHEDULES)}")
    return SCHEDULES[kind](**d)


def learning_rate(protocol, step: int) -> float:
    real("the step", step, low=0)
    return protocol.schedule.rate(step, protocol.steps)
