"""Learning rate as a pure function of the step: the same float for JAX and PyTorch.

A schedule is a record holding every value its shape uses (and none it does not):
- `Constant(lr)`:                  lr.
- `StepDecay(lr, every, gamma)`:   lr * gamma ** (step // every).
- `OneCycle(lr, start, min_ratio)`: the original LNN code's cosine one-cycle. With fraction f = step / steps,
  the phase is p = start + (1 - start) * f and lr(p) = low + (high - low) * (1 - cos(2 pi p)) / 2,
  high = lr, low = lr * min_ratio. It starts part-way up (p = 0.2 in the code), peaks at p = 0.5 and falls
  back to `low` at the end.
`learning_rate(protocol, step)` -> float reads the protocol's schedule over its `steps`.
"""
from __future__ import annotations

import dataclasses
import math
import numbers
from dataclasses import dataclass
from typing import ClassVar


def _real(v) -> bool:
    return isinstance(v, numbers.Real) and not isinstance(v, bool)


def _check_lr(lr) -> float:
    if not (_real(lr) and math.isfinite(lr) and lr > 0):
        raise ValueError(f"learning rate must be positive and finite, got {lr!r}")
    return float(lr)


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
        if not (_real(self.every) and math.isfinite(self.every) and self.every == int(self.every) and self.every >= 1):
            raise ValueError(f"step schedule every must be a positive integer, got {self.every!r}")
        if not (_real(self.gamma) and math.isfinite(self.gamma) and 0 < self.gamma):
            raise ValueError(f"step schedule gamma must be a finite number > 0, got {self.gamma!r}")
        object.__setattr__(self, "every", int(self.every))
        object.__setattr__(self, "gamma", float(self.gamma))

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
        if not (_real(self.start) and 0 <= self.start < 1):
            raise ValueError(f"one-cycle start must be a number in [0, 1) (the cycle's starting phase), got {self.start!r}")
        if not (_real(self.min_ratio) and math.isfinite(self.min_ratio) and self.min_ratio >= 0):
            raise ValueError(f"one-cycle min_ratio must be a finite number >= 0, got {self.min_ratio!r}")
        object.__setattr__(self, "start", float(self.start))
        object.__setattr__(self, "min_ratio", float(self.min_ratio))

    def rate(self, step: int, steps: int) -> float:
        phase = self.start + (1.0 - self.start) * (step / max(steps, 1))
        low = self.lr * self.min_ratio
        return low + (self.lr - low) * (1.0 - math.cos(2.0 * math.pi * phase)) / 2.0


SCHEDULES = {s.kind: s for s in (Constant, StepDecay, OneCycle)}
Schedule = Constant | StepDecay | OneCycle


def schedule_to_dict(s: Schedule) -> dict:
    return {"kind": s.kind, **dataclasses.asdict(s)}


def schedule_from_dict(d: dict) -> Schedule:
    d = dict(d)
    kind = d.pop("kind", None)
    if kind not in SCHEDULES:
        raise ValueError(f"unknown schedule {kind!r}; valid: {', '.join(SCHEDULES)}")
    return SCHEDULES[kind](**d)


def learning_rate(protocol, step: int) -> float:
    if not (_real(step) and math.isfinite(step) and step >= 0):
        raise ValueError(f"the step must be a finite number >= 0, got {step!r}")
    return protocol.schedule.rate(step, protocol.steps)
