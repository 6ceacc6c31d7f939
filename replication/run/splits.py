"""The suite's two splits: what a run trains its seeds on and evaluates them against.

development ("dev")  seeds 0, 1, 2, ...; the held-out draw of generator seed `HELDOUT_SEED`; rollout
                     initial conditions from each claim's `ic_seed`. Every trial, study, speed target
                     (`lagbench train-target`, its default) and protocol choice reads this split and only
                     this one.
test ("test")        seeds 1000, 1001, ...; a held-out draw of another generator seed; initial conditions
                     and sampled states from other seeds (`ic_seed` + 1000). `lagbench run` decides its
                     verdicts on it (its default), and `lagbench train-target --split test` measures the
                     frozen protocols' time to the target on it; no choice of a protocol has seen it.

Training reads neither split's evaluation draws: the held-out rows a training tracks or a scouting round
selects by are always the development draw (its validation set), so a test run's trainings are those of
the frozen protocols on fresh seeds, and its verdicts come from data no choice has seen. A result records
its split (`result.json` "split"; results without one are development results); a results folder's
summary judges the units of one split.
"""
from __future__ import annotations

from dataclasses import dataclass

from lagbench.replication.training.protocol_parts import HELDOUT_SEED


@dataclass(frozen=True)
class Split:
    name: str
    first_seed: int      # training seeds: first_seed, first_seed + 1, ...
    heldout_seed: int    # generator seed of the held-out draw the evaluation reads
    draw_offset: int     # added to the seeds of an evaluation's own draws (rollout initial conditions, states)

    def seeds(self, n: int) -> list[int]:
        return [self.first_seed + i for i in range(n)]

    def holds(self, seed: int) -> bool:
        return self.first_seed <= int(seed) < self.first_seed + SEEDS_PER_SPLIT


SEEDS_PER_SPLIT = 1000
DEV = Split("dev", 0, HELDOUT_SEED, 0)
TEST = Split("test", SEEDS_PER_SPLIT, HELDOUT_SEED + 1, SEEDS_PER_SPLIT)
SPLITS = {s.name: s for s in (DEV, TEST)}
RUN_DEFAULT = "test"


def of_seed(seed: int) -> Split:
    """The split a claim unit's seed belongs to."""
    return next((s for s in SPLITS.values() if s.holds(seed)), DEV)


def get(name: str) -> Split:
    if name not in SPLITS:
        raise ValueError(f"--split: unknown {name!r}; valid: {', '.join(SPLITS)}")
    return SPLITS[name]
