"""What share of a run each unit is, in estimated seconds: what the run's progress bar advances by, so that
its remaining time follows the work left, not the count of units (a run's first units are often its
shortest or its longest).

`unit_seconds(todo, out, by_group=None) -> [seconds]`, in `todo`'s order. A unit's training counts once, on
the first unit of its training program (`training.group_key`: the units after it, a second claim on the same
model or a cohort's other seeds, read it from the cache), and nothing where OUT/trained holds it already;
every unit adds `EVAL_S` for its evaluation. A training's seconds are the run's estimate where the run made
one (`estimate.estimate`'s "by_group": the long profiles probe each training before they start), else a
proxy: the training budget in samples (`scouting.budget_samples`) x the model's summed width x the kind's
nanoseconds per sample and unit of width (`KIND_NS`) x `chains.TORCH_COST` for PyTorch x the cohort's seeds.

`InFlight(bar)`: the bar's credit for the work under way. A unit (or a worker's chain of units) in flight is
credited with its estimated seconds as its wall time passes, at most its estimate, and the rest when it ends.
So from the first minute the bar advances by the work being done (N workers at the estimate's pace: N
estimated seconds a second) and its remaining time is the estimate's at the run's measured pace, not a rate
read off the few units finished (a run's first finished units are often ones whose training another unit
holds: 5 estimated seconds, minutes of wall time, hundreds of hours "remaining").
"""
from __future__ import annotations

import time
from pathlib import Path

from lagbench.replication.run.chains import TORCH_COST

# nanoseconds per training sample and unit of summed width, by model kind: the medians of a quick run's
# trainings on a 2-core Xeon with 2 workers (train_time_s / (train_samples x width x cohort seeds)); a kind not
# listed costs as an LNN
KIND_NS = {"baseline": 34.0, "hnn": 38.0, "delan": 44.0, "lnn": 90.0, "lgn": 1400.0}
EVAL_S = 5.0   # a unit's evaluation (the same run's median: 2 to 30 s)


def proxy_seconds(unit) -> float:
    from lagbench.replication.training.scouting import budget_samples

    p, spec = unit.protocol(), unit.spec()
    ns = KIND_NS.get(spec.kind, KIND_NS["lnn"]) * (TORCH_COST if unit.framework == "torch" else 1.0)
    return budget_samples(p) * (sum(spec.hidden) or 1) * (p.cohort or 1) * ns * 1e-9


def unit_seconds(todo, out, by_group: dict | None = None) -> list[float]:
    from lagbench.replication.training.train import group_key, train_key

    seen, seconds = set(), []
    for u in todo:
        train = 0.0
        if u.entry.train:
            p, spec = u.protocol(), u.spec()
            group = group_key(u.framework, spec, p, u.seed)
            if group not in seen:
                seen.add(group)
                if by_group is not None and group in by_group:
                    train = float(by_group[group])
                elif not (Path(out) / "trained" / u.framework / train_key(u.framework, spec, p, u.seed)
                          / "result.json").exists():
                    train = proxy_seconds(u)
        seconds.append(train + EVAL_S)
    return seconds


class InFlight:
    """`start(key, seconds)` as a unit or chain goes out; `tick()` as often as convenient (it credits each one
    held with its wall time so far, at most its estimate); `end(key)` when it ends (the rest of its estimate)."""

    def __init__(self, bar, clock=time.monotonic):
        self.bar, self.clock, self.held = bar, clock, {}

    def start(self, key, seconds: float) -> None:
        self.held[key] = [self.clock(), float(seconds), 0.0]   # [started, estimate, credited]

    def tick(self) -> None:
        now = self.clock()
        for h in self.held.values():
            due = min(h[1], now - h[0])
            if due > h[2]:
                self.bar.update(due - h[2])
                h[2] = due

    def end(self, key) -> None:
        _, seconds, credited = self.held.pop(key)
        if seconds > credited:
            self.bar.update(seconds - credited)
