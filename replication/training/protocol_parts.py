"""The records a `Protocol` (`replication.training.protocol`) is made of, each validating itself.

Always there: `Data` (what is trained on), `Adam` (the optimiser's constants) and a schedule
(`replication.training.schedules`). Optional, `None` when a run does without them: `Guard` (the
gradient-spike guard), `Scouting` (restarts over initialisations) and `Tracking` (held-out error during
training). Every value a part uses is written in it: nothing is inherited from the protocol.
"""
from __future__ import annotations

import dataclasses
import math
import numbers
from dataclasses import dataclass

from lagbench.replication.training.schedules import SCHEDULES, Schedule

COORDS = ("qqdot", "qp")


@dataclass(frozen=True)
class Data:
    """What a run trains and is judged on.

    recipe:    a data recipe (`replication.training.data.recipe_for`: "<system>_iid", "two_link_arm",
               "file:<path>" for a user's file).
    n_train:   size of the training pool; with `resample` a fresh pool is drawn every epoch (the original
               double-pendulum protocol), else one pool is shuffled every epoch.
    n_heldout: size of the held-out set.
    system_params: system parameter overrides as sorted (name, value) pairs.
    coords:    the inputs: (q, qdot) "qqdot" or canonical (q, p) "qp".
    fixed:     with `resample` and an "<system>_iid" recipe: the sampled state entries (names the system's
               `sample_states` gives, e.g. "qdot") kept from the epoch-0 draw every epoch while the others are
               redrawn (the original relativistic notebook draws qdot once from a fixed key and q, g every
               epoch). Left out of the canonical form while empty, so other protocols keep their keys."""

    recipe: str
    n_train: int
    n_heldout: int = 10_000
    resample: bool = False
    system_params: tuple = ()
    coords: str = "qqdot"
    fixed: tuple = ()

    def __post_init__(self):
        check(isinstance(self.recipe, str) and self.recipe != "", f"data recipe must be a name, got {self.recipe!r}")
        for name in ("n_train", "n_heldout"):
            check(integer(getattr(self, name)) and getattr(self, name) >= 1,
                  f"data {name} must be a positive integer, got {getattr(self, name)!r}")
            object.__setattr__(self, name, int(getattr(self, name)))
        check(isinstance(self.resample, bool), f"data resample must be True or False, got {self.resample!r}")
        check(self.coords in COORDS, f"unknown coords {self.coords!r}; valid: {', '.join(COORDS)}")
        object.__setattr__(self, "system_params", tuple(tuple(p) for p in self.system_params))
        fixed = self.fixed
        check(isinstance(fixed, (list, tuple)) and all(isinstance(k, str) and k for k in fixed)
              and list(fixed) == sorted(set(fixed)), f"data fixed must be sorted, unique state names, got {fixed!r}")
        check(not fixed or (self.resample and self.recipe.endswith("_iid")),
              f"data fixed {tuple(fixed)} needs resample and an <system>_iid recipe (got resample {self.resample}, "
              f"recipe {self.recipe!r})")
        object.__setattr__(self, "fixed", tuple(fixed))

    def replace(self, **changes) -> Data:
        return dataclasses.replace(self, **changes)


@dataclass(frozen=True)
class Adam:
    """Adam's constants (no weight decay: the protocol's `l2` is a term of the loss)."""

    b1: float = 0.9
    b2: float = 0.999
    eps: float = 1e-8

    def __post_init__(self):
        for name in ("b1", "b2"):
            check(real(getattr(self, name)) and 0 <= getattr(self, name) < 1,
                  f"Adam {name} must be a number in [0, 1), got {getattr(self, name)!r}")
        check(real(self.eps) and math.isfinite(self.eps) and self.eps > 0, f"Adam eps must be > 0, got {self.eps!r}")
        for name in ("b1", "b2", "eps"):
            object.__setattr__(self, name, float(getattr(self, name)))


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
                check(real(v) and math.isfinite(v) and v > 0, f"guard {name} must be a finite number > 0, got {v!r}")
                object.__setattr__(self, name, float(v))


@dataclass(frozen=True)
class Scouting:
    """Restarts over initialisations (`replication.training.scouting`).

    count scouts (>= 2) train side by side for `steps` steps of `batch` samples under `schedule` (over the
    scout's steps); with `keep` = k (successive halving, 1 <= k < count) all stop at half their steps and the
    k lowest by training loss go on to the end. The chosen scout is continued under the protocol's steps,
    batch and schedule. The budget is count x steps x batch (with a cut: (count x half + keep x (steps -
    half)) x batch) plus the continuation's samples."""

    count: int
    steps: int
    batch: int
    schedule: Schedule
    keep: int | None = None

    def __post_init__(self):
        check(integer(self.count) and self.count >= 2,
              f"scouting count must be an integer >= 2 (a protocol without restarts has scouting None), got {self.count!r}")
        for name in ("steps", "batch"):
            check(integer(getattr(self, name)) and getattr(self, name) >= 1,
                  f"scouting {name} must be a positive integer, got {getattr(self, name)!r}")
        check(isinstance(self.schedule, tuple(SCHEDULES.values())),
              f"scouting schedule must be a schedule record ({', '.join(SCHEDULES)}), got {self.schedule!r}")
        if self.keep is not None:
            check(integer(self.keep) and 1 <= self.keep < self.count,
                  f"scouting keep {self.keep!r} must be an integer from 1 to below count {self.count} (the scouts "
                  f"that go on after the first half; None = every scout goes on)")
            check(self.steps >= 2, "scouting keep needs steps >= 2: the cut is at half the scouts' steps")
        for name in ("count", "steps", "batch") + (("keep",) if self.keep is not None else ()):
            object.__setattr__(self, name, int(getattr(self, name)))


@dataclass(frozen=True)
class Tracking:
    """Held-out loss every `every` steps (`replication.training.tracking`), for work-precision curves; a
    multiple of the protocol's log_every. It reads the model and changes no training number. `keep`: the
    training also keeps the parameters at each of those steps (`TrainOutcome.tracked`), so that an evaluation
    can read the model at a chosen held-out error (claim 2 at matched accuracy); stored only when True, so
    protocols without it keep their keys."""

    every: int
    keep: bool = False

    def __post_init__(self):
        check(integer(self.every) and self.every >= 1, f"tracking every must be a positive integer, got {self.every!r}")
        check(isinstance(self.keep, bool), f"tracking keep must be True or False, got {self.keep!r}")
        object.__setattr__(self, "every", int(self.every))


def check(ok: bool, message: str) -> None:
    if not ok:
        raise ValueError(message)


def real(v) -> bool:
    return isinstance(v, numbers.Real) and not isinstance(v, bool)


def integer(v) -> bool:
    """An int (or an integral finite float, as JSON may give)."""
    return real(v) and math.isfinite(v) and v == int(v)
