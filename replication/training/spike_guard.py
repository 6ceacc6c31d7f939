"""The gradient-spike guard of a training loop, the same bookkeeping for JAX and PyTorch.

Why: an LNN's accelerations are H^-1 (dL/dq - J qdot) with H = d2L/dqdot2 learned. Where a batch holds a
state at which the learned H is nearly singular, the gradient norm jumps by 4 to 9 orders of magnitude
(measured on the double pendulum, 3 x 128: median about 60, single batches up to 4e10). Adam bounds the
step size but not its direction, and a run of such steps throws the model off (held-out L1 16 -> 176).

Two knobs, the protocol's `guard` (`protocol.Guard`; the guard or either knob None = off):
  clip: the gradient is scaled by min(1, clip / ||g||) (global norm over all parameters), as
        optax.clip_by_global_norm does;
  skip: a step whose ||g|| (before clipping) is at least skip x the median of the last `WINDOW`
        gradient norms (skipped ones included) is not taken: parameters and Adam state stay as they are.
        No step is skipped before `MIN_HISTORY` norms are recorded. With skip on, a step whose gradient
        norm is not finite (but whose loss is) is skipped instead of ending the run.

`SpikeGuard(guard)` (a `protocol.Guard` or None): `threshold(dtype)` -> the skip bound for the next step (inf when off or warming up);
`record(gnorm, threshold)` -> True if that step is taken (gnorm < threshold), counting skips in
`skipped`; `fails(loss, gnorm)` -> whether the loop stops there; `clip_scale(gnorm)` -> the factor the
gradient is multiplied by; `restore(history, skipped)` puts a snapshot's window back. The window is also
kept sorted, so that its median (numpy's: the middle value, or the mean of the two middle ones) costs a
lookup a step instead of a sort, K times a step when K members train side by side.
"""
from __future__ import annotations

import math
from bisect import bisect_left, insort
from collections import deque

import numpy as np

WINDOW, MIN_HISTORY = 200, 20


class SpikeGuard:
    def __init__(self, guard):
        self.clip = guard.clip if guard and guard.clip else 0.0
        self.factor = guard.skip if guard and guard.skip else 0.0
        self.history: deque = deque(maxlen=WINDOW)
        self._sorted: list[float] = []   # the history's values in increasing order
        self.skipped = 0

    @property
    def active(self) -> bool:
        return self.factor > 0

    def threshold(self, dtype: str = "float64") -> float:
        """The bound rounded to the training dtype, so that JAX (comparing in that dtype inside its step)
        and PyTorch (comparing Python floats) take the same decision."""
        if not self.active or len(self.history) < MIN_HISTORY:
            return math.inf
        return float(np.asarray(self.factor * self._median(), dtype=dtype))

    def _median(self) -> float:
        """np.median(self.history), read off the sorted window."""
        s, n = self._sorted, len(self._sorted)
        return s[n // 2] if n % 2 else (s[n // 2 - 1] + s[n // 2]) / 2

    def _push(self, gnorm: float) -> None:
        if len(self.history) == WINDOW:   # the oldest leaves the window
            del self._sorted[bisect_left(self._sorted, self.history[0])]
        self.history.append(gnorm)
        insort(self._sorted, gnorm)

    def restore(self, history, skipped: int) -> None:
        """A snapshot's window (oldest first) and skip count, on a fresh guard."""
        for gnorm in history:
            self._push(float(gnorm))
        self.skipped = int(skipped)

    def record(self, gnorm: float, threshold: float) -> bool:
        """Whether the step is taken; a non-finite norm is never taken and stays out of the history."""
        if math.isfinite(gnorm):
            self._push(float(gnorm))
        taken = bool(gnorm < threshold)
        self.skipped += not taken
        return taken

    def fails(self, loss: float, gnorm: float) -> bool:
        """Whether the loop must stop: a non-finite loss always; a non-finite gradient norm only when the
        guard is off (on, it is a spike: the step is skipped)."""
        return not math.isfinite(loss) or (not math.isfinite(gnorm) and not self.active)

    def clip_scale(self, gnorm: float) -> float:
        return self.clip / gnorm if self.clip > 0 and gnorm > self.clip else 1.0
