"""One progress bar for a fit's whole training: its restarts and its main training as one count of steps.

`TrainingBar(desc, quiet)`: `start(protocol)` before a training (`fit`'s `on_train`; `--tune` trains one per
configuration, each its own bar), `row(log_row)` for each training log row (`fit`'s `on_log`), `close()`.
The bar counts optimiser steps: the restarts' steps (they train side by side, so a step of theirs advances
every restart) and then the main training's, in one total, `total_steps(protocol)`. A row of the restarts
carries its own step as `restart_step` (`training.scouting.train_scouted`); a main training's row its step
after the restarts' samples in main steps (`scouting.progress_steps`).

The time left is measured, not assumed from the count: the seconds per training sample of the part under
way (from this process's clock between its log rows, from its second row on: its first step compiles, and
so does the first held-out evaluation of an early stop, after the first row)
times the samples each part still has (`scouting.scout_parts`: restarts x their batch per step, then the
main batch). A restarts' fallback (`Scouting.fallback`: the next restart's main training, where the first
lost its restart's loss) lengthens the bar by a main training as it starts, and a bar that may still see one
is closed by its caller, and its time shown as the most it takes ("<="). Before a part starts, its time per sample is the part before's; once it runs, its own (the
first step of each part compiles, which no estimate foresees). With an early stop (`Protocol.early_stop`) the
main training may end sooner (it stops and anneals), so the time shown is the most it takes ("<="); where it
ends before its total, the bar says at which step.
"""
from __future__ import annotations

import time

from lagbench.replication.training.scouting import progress_steps, scout_parts

FORMAT = "{desc}: {percentage:3.0f}%|{bar}| {n_fmt}/{total_fmt} steps [{elapsed}{postfix}]"   # tqdm puts ", " before a postfix


def parts(protocol) -> list[tuple[int, int]]:
    """The training's parts as (samples per step, steps): each restarts part (`scout_parts`), then the main
    training."""
    s = protocol.scouting
    return [(m * s.batch, n) for m, n in scout_parts(protocol)] + [(protocol.batch, protocol.steps)]


def total_steps(protocol) -> int:
    """The bar's total: the restarts' steps and the main training's."""
    return sum(n for _, n in parts(protocol))


def position(protocol, row: dict) -> int:
    """Steps done after a log row: a restarts row's `restart_step` + 1, or the restarts' steps and the main
    training's step + 1 (its logged step less the restarts' samples in main steps)."""
    if "restart_step" in row:
        return int(row["restart_step"]) + 1
    before = progress_steps(protocol) - protocol.steps   # the restarts' samples, in main steps
    restarts = protocol.scouting.steps if protocol.scouting else 0
    return restarts + int(row["step"]) - before + 1


def fallbacks(protocol, at: int) -> int:
    """The fallbacks under way at position `at` (`Scouting.fallback`: a main training after the first, each
    `protocol.steps` more): 0 until the first main training's end."""
    over = at - total_steps(protocol)
    return -(-over // protocol.steps) if over > 0 else 0


def seconds_left(protocol, done: int, per_sample: float) -> float:
    """The time the steps after `done` take at `per_sample` seconds per training sample."""
    left, start = 0.0, 0
    for samples, steps in parts(protocol):
        left += max(0, min(steps, start + steps - done)) * samples * per_sample
        start += steps
    return left


def _clock(seconds: float) -> str:
    m, s = divmod(int(round(seconds)), 60)
    return f"{m // 60}:{m % 60:02d}:{s:02d}" if m >= 60 else f"{m}:{s:02d}"


class TrainingBar:
    def __init__(self, desc: str, quiet: bool = False):
        self.desc, self.quiet = desc, quiet
        self.protocol, self.bar = None, None

    def start(self, protocol) -> None:
        self.close()
        self.protocol, self.part, self.rows, self.mark, self.per_sample = protocol, None, 0, None, None

    def _part(self, done: int) -> int:
        start = 0
        for i, (_, steps) in enumerate(parts(self.protocol)):
            start += steps
            if done <= start:
                return i
        return len(parts(self.protocol)) - 1

    def row(self, row: dict) -> None:
        if self.protocol is None:
            return
        p, at = self.protocol, position(self.protocol, row)
        extra = fallbacks(p, at)
        total = total_steps(p) + extra * p.steps
        if self.bar is None:
            from tqdm.auto import tqdm

            self.bar = tqdm(total=total, desc=self.desc, unit="step", bar_format=FORMAT, disable=self.quiet)
        elif self.bar.total != total:   # a fallback's main training goes on past the first one's end
            self.bar.total = total
        done, now = min(at, total), time.perf_counter()
        part = self._part(done - extra * p.steps)
        self.rows = self.rows + 1 if part == self.part else 1
        self.part = part
        if self.rows <= 2:   # a part's first two rows: its steps until then include compiling
            self.mark = (done, now)
        elif done > self.mark[0]:
            samples = parts(self.protocol)[part][0] * (done - self.mark[0])
            self.per_sample = (now - self.mark[1]) / samples
        left = seconds_left(p, done - extra * p.steps, self.per_sample) if self.per_sample is not None else None
        early = "<=" if p.early_stop or (p.scouting and p.scouting.fallback and not extra) else "about"
        phase = "restarts" if part < len(parts(p)) - 1 else f"fallback {extra}" if extra else "main"
        self.bar.set_postfix_str(f"{phase}, {'estimating' if left is None else f'{early} {_clock(left)} left'}, "
                                 f"training loss {row['loss']:.4g}", refresh=False)
        self.bar.update(done - self.bar.n)
        if done >= self.bar.total and not (p.scouting and p.scouting.fallback):   # else the caller closes it
            self.close()

    def close(self) -> None:
        """Ends the bar; one that ended before its total (an early stop) says at which step."""
        if self.bar is not None:
            if self.bar.n < self.bar.total:
                self.bar.set_postfix_str(f"ended at step {self.bar.n} of {self.bar.total}", refresh=False)
            self.bar.close()
        self.bar = None
