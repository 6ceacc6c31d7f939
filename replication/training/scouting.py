"""Restarts over initialisations ("scouting"): a protocol part (`Protocol.scouting`), both frameworks.

Why: which initialisation of a black-box Lagrangian finds a near-physical L (a learned velocity Hessian
close to the mass matrix) is luck, a run that found one trains on without gradient spikes, and its
training loss tells which it is (`docs/train_target_trials.md`, section 5). So a protocol
with `scouting` (`protocol.Scouting`, K = its count):
  1. trains the K initialisations `init_seeds(protocol, seed)` side by side for `scout_steps(protocol)`
     steps each, as one program (`loop.train_members`; each member's numbers are its own run's), at
     the scouting's batch, peak rate and one-cycle start, a schedule over the scout (the protocol's shape
     over its steps), batches from a stream per init seed.
     With `keep` = k (successive halving), all K stop at `cut_step` (half the schedule) and only the k
     lowest by training loss over the last `TAIL` of those steps go on to its end, from their exact state:
     a near-physical scout leads by then (`docs/train_target_trials.md` section 8), so more inits are
     tried for the samples of fewer whole scouts (`scouting_samples`);
  2. chooses the scout with the lowest training loss over its last `TAIL` of steps (a scout that stopped
     on a non-finite loss, or was left at the cut, is never chosen); the held-out set plays no part;
  3. continues the chosen one for `protocol.steps` steps of `protocol.batch`: a new schedule over those
     steps (from `protocol.lr_start`: a fresh Adam's first steps at a high rate can throw a near-physical
     Lagrangian away, so a continuation may start lower than its scouts did), fresh Adam state, batches
     from a stream of its own (seed + 1000);
  4. with `fallback` = f: a continuation whose training loss over its last TAIL of steps ends above its
     scout's tail loss lost what the scout found (a fresh Adam thrown off a near-physical L); the next scout
     by tail loss is continued likewise, up to f more, until one ends at or below its scout's; the lowest
     continuation tail is the run (`docs/decisions/double_pendulum_protocol.md`).
Every scout's and every continuation's samples count (`budget_samples` before fallbacks; the outcome's
`samples`). The original code
has no restarts: the report says so where a claim uses them.

`train_scouted(trainer, spec, protocol, seed, on_log=None) -> TrainOutcome` (trainer: `train_jax` or
`train_torch`): the continuation's parameters and log (its steps shifted by the scouts' samples in
continuation steps, `progress_steps`; `on_log` sees the first scout's rows so too, with the scouts' own
step as `restart_step`), steps_done and samples counting every scout, its `scouting` record
{init_seeds, tail_loss, chosen, scout_steps; with a cut also cut_step, cut_tail_loss, kept; with fallbacks
also continued (the init seeds continued, in order) and continuation_tail_loss}. `scout(...)`,
`choose` and `continuation_protocol` are its parts, for callers that watch them (`speedstudy.target_loop`).
"""
from __future__ import annotations

import math

import numpy as np

from lagbench.replication.training.loop_state import narrow
from lagbench.replication.training.outcome import joined_modes

TAIL = 0.05               # the share of a scout's last steps whose mean training loss chooses
CONTINUATION_STREAM = 1000  # the chosen init seed + this: the continuation's batch stream


def scout_steps(protocol) -> int:
    """Steps of each scout."""
    return protocol.scouting.steps


def cut_step(protocol) -> int | None:
    """The step after which only `scouting.keep` scouts go on (half their schedule); None: no cut."""
    s = protocol.scouting
    return s.steps // 2 if s and s.keep else None


def scout_parts(protocol) -> list[tuple[int, int]]:
    """The scouting as (members side by side, steps) parts: [(K, steps)], with a cut
    [(K, half), (keep, the rest)]; [] without scouting. The budget and the duration estimate read it."""
    s = protocol.scouting
    if not s:
        return []
    half = cut_step(protocol)
    return [(s.count, s.steps)] if half is None else [(s.count, half), (s.keep, s.steps - half)]


def scouting_samples(protocol) -> int:
    """Samples of every scout, at the scout batch (`scout_parts`)."""
    return sum(m * n for m, n in scout_parts(protocol)) * protocol.scouting.batch if protocol.scouting else 0


def budget_samples(protocol) -> int:
    """Training samples of a run: every scout's and the continuation's (steps x batch without scouts)."""
    return protocol.steps * protocol.batch + scouting_samples(protocol)


def progress_steps(protocol) -> int:
    """The run's length for a progress bar, in continuation steps (the scouts' samples converted)."""
    return -(-budget_samples(protocol) // protocol.batch)


def init_seeds(protocol, seed: int) -> list[int]:
    """The K initialisations scouted for a run of `seed`: seed * K .. seed * K + K - 1 (disjoint per seed)."""
    k = protocol.scouting.count
    return [seed * k + i for i in range(k)]


def scout_protocol(protocol):
    """The protocol each scout trains under: the scouting's steps, batch and schedule, no scouting and no
    early stop (the training loss chooses among scouts; an early stop is the continuation's)."""
    s = protocol.scouting
    return protocol.replace(steps=s.steps, batch=s.batch, schedule=s.schedule, scouting=None, early_stop=None)


def continuation_protocol(protocol):
    return protocol.replace(scouting=None)


class _Losses:
    """The loop hook that keeps each scout's training loss at every step (NaN once it stopped)."""

    def __init__(self):
        self.losses = []

    def __call__(self, k, stepper, info):
        self.losses.append(np.where(info["live"], info["loss"], np.nan))

    def snapshot_state(self):
        return None, {"losses": np.asarray(self.losses, np.float64)}

    def restore_snapshot(self, meta, arrays):
        self.losses = list(arrays["losses"])


class _ScalarLosses(_Losses):
    """`_Losses` for a one-model run (its hooks see a scalar loss)."""

    def __call__(self, k, stepper, info):
        self.losses.append(np.asarray([info["loss"]], np.float64))


class _StopAt:
    """The loop hook that ends a run after `steps` steps (the scouts' cut)."""

    def __init__(self, steps: int):
        self.steps = steps

    def __call__(self, k, stepper, info):
        return k + 1 >= self.steps


class HeldState:
    """A snapshot store (or none) that also keeps in memory the last state saved or loaded: the scouts'
    state at the cut, from which the kept ones go on (and a run's at its early stop, from which it anneals:
    `early_stop.train_stopping`)."""

    def __init__(self, store):
        self.store, self.state = store, None
        self.folder = store.folder if store else None

    def due(self) -> bool:
        return self.store.due() if self.store else False

    def save(self, meta, arrays):
        self.state = (meta, arrays)
        if self.store:
            self.store.save(meta, arrays)

    def load(self, members, steps):
        got = self.store.load(members, steps) if self.store else None
        if got:
            self.state = got
        return got


def _tails(losses, outcomes) -> list[float]:
    """Each member's mean training loss over the last TAIL of the steps so far (inf: it stopped)."""
    rows = np.asarray(losses) if losses else np.full((1, len(outcomes)), np.inf)
    tail = rows[-max(len(rows) // round(1 / TAIL), 1):]
    tails = [float(np.mean(tail[:, i])) if o.failure is None else math.inf for i, o in enumerate(outcomes)]
    return [t if math.isfinite(t) else math.inf for t in tails]


def scout(trainer, spec, protocol, seeds, on_log=None, hooks=(), snapshot=None, record=None):
    """Phase 1: (outcomes, tail losses), one per init seed in `seeds`, trained as one program for
    `scout_protocol(protocol).steps`; the tail loss is inf for a scout that stopped. With
    `protocol.scouting.keep` = k, every scout runs to `cut_step` (snapshot phase `snapshot`), then the k
    lowest tails there go on from their exact state (optimiser, guard, log, batch stream) to the end
    (phase "scouts-kept"): each kept scout's numbers are those of its uncut run. The scouts left behind
    keep their outcome at the cut and the tail inf (they are never chosen); `record` (a dict) gets
    {cut_step, cut_tail_loss, kept}. The callers' `hooks` see both parts; their state is not carried
    across the cut."""
    from lagbench.models import init_params  # here, not at import: claims read scout_protocol without
    from lagbench.replication.training.data import (
        BatchStream,  # the models or the data (reports import the claims)
    )

    p, half = scout_protocol(protocol), cut_step(protocol)
    keep = _Losses()
    streams = [BatchStream(p, s) for s in seeds]
    held = HeldState(snapshot) if half is not None else snapshot
    outcomes = trainer.train_members(spec, [init_params(spec, seed=s) for s in seeds], p, streams, on_log=on_log,
                                     hooks=(keep, *((_StopAt(half),) if half is not None else ()), *hooks),
                                     snapshot=held)
    tails = _tails(keep.losses, outcomes)
    if half is None:
        return outcomes, tails
    go_on = sorted(sorted((i for i, t in enumerate(tails) if math.isfinite(t)), key=lambda i: tails[i])
                   [:protocol.scouting.keep])
    if record is not None:
        record.update({"cut_step": half, "cut_tail_loss": tails, "kept": [seeds[i] for i in go_on]})
    if not go_on:
        return outcomes, tails
    keep2 = _Losses()   # the kept scouts' losses so far (replaced by its own if the part resumes from a snapshot)
    keep2.losses = [row[go_on] for row in keep.losses]
    kept = trainer.train_members(spec, [outcomes[i].params for i in go_on], p, [streams[i] for i in go_on],
                                 on_log=on_log, hooks=(keep2, *hooks),
                                 snapshot=snapshot.phase("scouts-kept") if snapshot else None,
                                 start_state=narrow(held.state, go_on))
    tails = [math.inf] * len(seeds)
    for i, o, t in zip(go_on, kept, _tails(keep2.losses, kept), strict=True):
        o.step_mode = joined_modes(outcomes[i].step_mode, o.step_mode)
        outcomes[i], tails[i] = o, t
    return outcomes, tails


def choose(tails) -> int | None:
    """The index of the lowest finite tail loss (None: every scout stopped)."""
    finite = [i for i, t in enumerate(tails) if math.isfinite(t)]
    return min(finite, key=lambda i: tails[i]) if finite else None


def train_scouted(trainer, spec, protocol, seed: int, on_log=None, track=None, snapshot=None, stop=None):
    """Scouts, then the chosen one's continuation; `track(protocol, offset_steps, offset_samples,
    offset_seconds)` may give a held-out tracking hook for the continuation (`training.tracker_for`): the
    scouts' samples and step time count; `stop(protocol, offset_steps)` an early-stop hook for it
    (`training.stopper_for`). `snapshot` (`snapshots.Snapshots`): each phase snapshots under
    its own name ("scouts", "continuation"), so that a run killed in its continuation does not scout again."""
    seeds, per = init_seeds(protocol, seed), scout_steps(protocol)
    done = progress_steps(protocol) - protocol.steps   # the scouts' samples, in continuation steps

    def scout_log(row):   # progress in continuation steps (the scouts advance together); the scouts' own step too
        if on_log and row.get("member", 0) == 0:
            on_log({**row, "step": row["step"] * done // per, "restart_step": row["step"]})
    record = {}
    outcomes, tails = scout(trainer, spec, protocol, seeds, on_log=scout_log,
                            snapshot=snapshot.phase("scouts") if snapshot else None, record=record)
    best = choose(tails)
    record = {"init_seeds": seeds, "tail_loss": tails, "scout_steps": per, **record,
              "chosen": None if best is None else seeds[best]}
    if best is None:   # every scout stopped: the first failure stands for the run (not a scout left at the cut)
        o = next((x for x in outcomes if x.failure), outcomes[0])
        o.scouting, o.steps_done = record, sum(x.steps_done for x in outcomes)
        o.samples = o.steps_done * o.batch
        return o
    p = continuation_protocol(protocol)
    finite = sorted((i for i, t in enumerate(tails) if math.isfinite(t)), key=lambda i: tails[i])
    fallback = protocol.scouting.fallback
    runs, steps, samples, seconds = [], done, scouting_samples(protocol), outcomes[best].train_time_s
    step_seconds = outcomes[best].step_seconds
    for n, i in enumerate(finite[:1 + fallback]):
        out, tail = _continue(trainer, spec, p, seeds[i], outcomes[i], n, steps, samples, step_seconds,
                              on_log, track, stop, snapshot, watch=fallback > 0)
        runs.append((tail, n, i, out))
        steps, samples = steps + out.steps_done, samples + out.steps_done * out.batch
        seconds, step_seconds = seconds + out.train_time_s, step_seconds + out.step_seconds
        if not fallback or tail <= tails[i]:   # the continuation kept what its scout found
            break
    tail, _, i, out = min(runs, key=lambda r: (r[0], r[1]))
    if fallback:
        record.update({"chosen": seeds[i], "continued": [seeds[r[2]] for r in runs],
                       "continuation_tail_loss": [r[0] for r in runs]})
    out.samples = samples
    out.steps_done = (samples - scouting_samples(protocol)) // out.batch + scouting_samples(protocol) // outcomes[0].batch
    out.train_time_s = seconds
    out.step_mode = joined_modes(outcomes[best].step_mode, *(r[3].step_mode for r in runs))
    out.scouting = record
    return out


def _continue(trainer, spec, p, init_seed, scouted, n, steps, samples, seconds, on_log, track, stop, snapshot,
              watch):
    """The `n`-th continuation (0: the chosen scout's; then fallbacks), of the scout `scouted` trained from
    init seed `init_seed`, after `steps` continuation steps, `samples` samples and `seconds` of optimiser
    steps in the run so far: (its outcome, its tail training loss: inf when it failed, None unless `watch`).
    Its log's steps are the run's; its tracking counts the run's samples and time before it."""
    from lagbench.replication.training.data import BatchStream
    from lagbench.replication.training.early_stop import train_stopping

    def shifted(row):
        if on_log:
            on_log({**row, "step": row["step"] + steps})
    t = track(p, steps, samples, seconds) if track else None
    s = stop(p, steps) if stop else None
    losses = _ScalarLosses() if watch else None
    phase = "continuation" if n == 0 else f"continuation-{n + 1}"
    out = train_stopping(trainer, spec, scouted.params, p, BatchStream(p, init_seed + CONTINUATION_STREAM),
                         on_log=shifted, hooks=tuple(h for h in (losses, t) if h is not None),
                         snapshot=snapshot.phase(phase) if snapshot else None, stop=s)
    out.log = [{**row, "step": row["step"] + steps} for row in out.log]
    if t:
        t.merge([out])
    if s:
        s.merge(out)
    return out, _tails(losses.losses, [out])[0] if watch else None
