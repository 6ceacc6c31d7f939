"""Learning rate as a pure function of the step: the same float for JAX and PyTorch.

`learning_rate(protocol, step)` -> float. Schedules:
- constant: lr.
- step:     lr * gamma ** (step // every).
- onecycle: the original LNN code's cosine one-cycle. With fraction f = step / steps, the phase is
            p = lr_start + (1 - lr_start) * f and lr(p) = low + (high - low) * (1 - cos(2 pi p)) / 2,
            high = lr, low = lr * lr_min_ratio. It starts part-way up (p = 0.2 in the code), peaks at
            p = 0.5 and falls back to `low` at the end.
"""
from __future__ import annotations

import math
import numbers


def learning_rate(protocol, step: int) -> float:
    if not (isinstance(step, numbers.Real) and math.isfinite(step) and step >= 0):
        raise ValueError(f"the step must be a finite number >= 0, got {step!r}")
    lr = float(protocol.lr)
    if protocol.schedule == "constant":
        return lr
    if protocol.schedule == "step":
        return lr * protocol.lr_step_gamma ** (step // protocol.lr_step_every)
    if protocol.schedule == "onecycle":
        frac = step / max(protocol.steps, 1)
        phase = protocol.lr_start + (1.0 - protocol.lr_start) * frac
        low = lr * protocol.lr_min_ratio
        return low + (lr - low) * (1.0 - math.cos(2.0 * math.pi * phase)) / 2.0
    raise ValueError(f"unknown schedule {protocol.schedule!r}")
