"""The records a `Protocol` (`replication.training.protocol`) is made of, each validating itself.

Always there: `Data` (what is trained on), `Adam` (the optimiser's constants) and a schedule
(`replication.training.schedules`). Optional, `None` when a run does without them: `Guard` (the
gradient-spike guard), `Scouting` (restarts over initialisations), `Tracking` (held-out error during
training), `EarlyStop` (stop when the held-out error stops improving; `lagbench fit` only) and
`TrajectoryLoss` (train on positions integrated over windows of a recording; `lagbench fit` only) and
`FilterLoss` (train on q-double-dot seen through the derivative filter; `lagbench fit` only). Every value
a part uses is written in it: nothing is inherited from the protocol.
"""
from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass

from lagbench.replication.training.schedules import SCHEDULES, Schedule
from lagbench.validate import check, flag, integer, is_integer, one_of, positive, real

COORDS = ("qqdot", "qp")


HELDOUT_SEED = 1_000_000_000  # the held-out draw's generator seed: the original code's PRNGKey(int(1e9)) test set, by analogy


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
            object.__setattr__(self, name, integer(f"data {name}", getattr(self, name), low=1))
        flag("data resample", self.resample)
        one_of("coords", self.coords, COORDS)
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
            object.__setattr__(self, name, float(real(f"Adam {name}", getattr(self, name), low=0, below=1)))
        object.__setattr__(self, "eps", float(positive("Adam eps", self.eps)))


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
                object.__setattr__(self, name, float(positive(f"guard {name}", v)))


@dataclass(frozen=True)
class Scouting:
    """Restarts over initialisations (`replication.training.scouting`).

    count scouts (>= 2) train side by side for `steps` steps of `batch` samples under `schedule` (over the
    scout's steps); with `keep` = k (successive halving, 1 <= k < count) all stop at half their steps and the
    k lowest by training loss go on to the end. The chosen scout is continued under the protocol's steps,
    batch and schedule. The budget is count x steps x batch (with a cut: (count x half + keep x (steps -
    half)) x batch) plus the continuation's samples. `fallback` = f: a continuation that ends with a higher
    training loss than its scout had (it lost what the scout found) is followed by the next scout's, up to f
    more; the lowest ends the run, and every continuation's samples count. Stored only when f > 0, so
    protocols without it keep their keys."""

    count: int
    steps: int
    batch: int
    schedule: Schedule
    keep: int | None = None
    fallback: int = 0

    def __post_init__(self):
        check(is_integer(self.count) and self.count >= 2,
              f"scouting count must be an integer >= 2 (a protocol without restarts has scouting None), got {self.count!r}")
        for name in ("steps", "batch"):
            integer(f"scouting {name}", getattr(self, name), low=1)
        check(isinstance(self.schedule, tuple(SCHEDULES.values())),
              f"scouting schedule must be a schedule record ({', '.join(SCHEDULES)}), got {self.schedule!r}")
        if self.keep is not None:
            check(is_integer(self.keep) and 1 <= self.keep < self.count,
                  f"scouting keep {self.keep!r} must be an integer from 1 to below count {self.count} (the scouts "
                  f"that go on after the first half; None = every scout goes on)")
            check(self.steps >= 2, "scouting keep needs steps >= 2: the cut is at half the scouts' steps")
        check(is_integer(self.fallback) and 0 <= self.fallback < (self.keep or self.count),
              f"scouting fallback {self.fallback!r} must be an integer from 0 to below the scouts that reach the "
              f"end ({self.keep or self.count}): the further scouts continued when a continuation loses its scout's loss")
        for name in ("count", "steps", "batch", "fallback") + (("keep",) if self.keep is not None else ()):
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
        object.__setattr__(self, "every", integer("tracking every", self.every, low=1))
        flag("tracking keep", self.keep)


@dataclass(frozen=True)
class EarlyStop:
    """Stop a training when its held-out error stops improving (`replication.training.early_stop`): every
    `every` steps (a multiple of the protocol's log_every) and at the last, the data loss on the held-out
    rows; at the evaluation that makes `patience` in a row without a new best lower than the best so far by
    at least `min_improvement` (a fraction of it), the run closes: its learning rate falls along a half cosine
    from where it is to where the schedule ends, over `anneal` more steps (0: it ends there), within the
    protocol's steps. The parameters it ends with are the last step's (the held-out rows choose when to stop,
    never which parameters are kept). A restarts' protocol applies it to the continuation only. `lagbench
    fit` sets it; no claim does."""

    every: int
    patience: int
    min_improvement: float = 0.01
    anneal: int = 0

    def __post_init__(self):
        for name in ("every", "patience"):
            object.__setattr__(self, name, integer(f"early stop {name}", getattr(self, name), low=1))
        object.__setattr__(self, "min_improvement", float(real("early stop min_improvement", self.min_improvement,
                                                               low=0, below=1)))
        object.__setattr__(self, "anneal", integer("early stop anneal", self.anneal, low=0))


TRAJECTORY_SCALES = ("acceleration", "none")


@dataclass(frozen=True)
class TrajectoryLoss:
    """The trajectory loss: the training rows are windows of a recording (`replication.fit.windows`), each a
    start state, its frame step h and the recorded positions of the next `frames` frames; the model's motion
    from the start state, integrated by RK4 with `substeps` steps a frame, is compared with them by the
    protocol's loss (`replication.training.objective.positions`). The held-out rows stay the task's own (the
    one-step error), so early stops and evaluations read what they read without it.

    frames:   K >= 1, the frames a window spans after its start.
    substeps: S >= 1, RK4 steps per frame.
    scale:    "acceleration": each window's displacements divided by those that a constant q-double-dot error
              of 1 gives over it, so that the loss reads in q-double-dot units, as the acceleration loss does;
              "none": the displacements as recorded."""

    frames: int
    substeps: int
    scale: str = "acceleration"

    def __post_init__(self):
        for name in ("frames", "substeps"):
            object.__setattr__(self, name, integer(f"trajectory loss {name}", getattr(self, name), low=1))
        one_of("trajectory loss scale", self.scale, TRAJECTORY_SCALES)


@dataclass(frozen=True)
class FilterLoss:
    """The filtered acceleration loss: the model's q-double-dot seen through the derivative filter that estimated
    the target. A Savitzky-Golay second derivative of `window` points and order `polyorder` is a linear filter
    c of the positions; since c annihilates constants and lines, c = k * (1, -2, 1) for a kernel k of
    window - 2 taps summing to 1 (`kernel`), so the estimate at a frame equals k applied to the central second
    differences of its neighbours, each q-double-dot up to h^2 q''''/12. The loss compares the estimate with k
    applied to the model's q-double-dot at those frames (`replication.training.objective.filtered`; the rows:
    `replication.fit.filter_rows`), so the filter's smoothing is on both sides and the model does not learn
    the filter's bias. The held-out rows stay the task's own (the one-step error).

    window:    the filter's odd window (the training file's, as its derivatives record it), >= polyorder + 2.
    polyorder: the filter's polynomial order, >= 2."""

    window: int
    polyorder: int

    def __post_init__(self):
        object.__setattr__(self, "polyorder", integer("filter loss polyorder", self.polyorder, low=2))
        object.__setattr__(self, "window", integer("filter loss window", self.window, low=self.polyorder + 2))
        check(self.window % 2 == 1, f"filter loss window must be odd, got {self.window}")

    @property
    def kernel(self) -> tuple[float, ...]:
        """The window - 2 taps k, for the frames -(window - 3)/2 .. (window - 3)/2 about the row."""
        return filter_kernel(self.window, self.polyorder)


@functools.lru_cache(maxsize=16)
def filter_kernel(window: int, polyorder: int) -> tuple[float, ...]:
    """k with c = k * (1, -2, 1) for c the Savitzky-Golay second-derivative coefficients at unit spacing
    (`scipy.signal.savgol_coeffs`, applied as a dot product): the double cumulative sum of c, its last two
    entries (0 up to rounding) dropped; Python floats."""
    import numpy as np
    from scipy.signal import savgol_coeffs

    c = savgol_coeffs(window, polyorder, deriv=2, delta=1.0, use="dot")
    return tuple(float(x) for x in np.cumsum(np.cumsum(c))[:-2])
