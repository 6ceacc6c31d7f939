"""Train one (framework, spec, protocol, seed), with a cache so that claims sharing a model train it once.

`train_cached(out, framework, spec, protocol, seed)` -> TrainOutcome. The cache folder
`OUT/trained/<framework>/<key>/` holds checkpoint.npz (last good parameters), train_log.csv, tracked.npz
(the parameters at the tracked steps, where the protocol keeps them) and result.json (timings, failure,
file checksums); a corrupt entry is retrained, never trusted. While it
trains, `inflight/` there holds its snapshots (`replication.training.snapshots`): a run killed mid-training
resumes each training from its last one, and they are removed once the training is stored.
"""
from __future__ import annotations

import logging
from pathlib import Path

import pandas as pd

from lagbench.files import results as R
from lagbench.models import init_params
from lagbench.replication.training import device as dev
from lagbench.replication.training.data import BatchStream, targets_version
from lagbench.replication.training.early_stop import EarlyStopper, train_stopping
from lagbench.replication.training.outcome import TrainOutcome, log_frame
from lagbench.replication.training.protocol import canonical_hash
from lagbench.replication.training.scouting import train_scouted
from lagbench.replication.training.snapshots import Snapshots
from lagbench.replication.training.tracking import Tracker

log = logging.getLogger("lagbench")


def train_key(framework, spec, protocol, seed) -> str:
    """The training's cache key: framework, spec, protocol (a user file by its content, not its path) and seed;
    for PyTorch also its handling of subnormal floats (`models.torch.subnormals`: flushed), so that a training
    made while PyTorch kept them is not taken up again."""
    from lagbench.files.user_data import content_only

    key = {"fw": framework, "spec": spec.to_dict(), "protocol": content_only(protocol.to_dict()), "seed": seed}
    if framework == "torch":
        key["subnormals"] = "flushed"
    targets = targets_version(protocol)
    if targets:
        key["targets"] = targets
    return canonical_hash(key, 20)


def trainer(framework):
    """The framework's training module (`train_jax` or `train_torch`: `train`, `train_members`)."""
    if framework == "jax":
        from lagbench.replication.training import train_jax as module
    elif framework == "torch":
        from lagbench.replication.training import train_torch as module
    else:
        raise ValueError(f"unknown framework {framework!r}; valid: jax, torch")
    return module


def tracker_for(framework, spec):
    """`make(protocol, offset_steps=0, offset_samples=0, offset_seconds=0) -> Tracker | None`: the tracking hook of a
    protocol with `tracking` (`replication.training.tracking`), else None."""
    def make(protocol, offset_steps=0, offset_samples=0, offset_seconds=0.0):
        if not protocol.tracking:
            return None
        return Tracker(framework, spec, protocol, offset_steps, offset_samples, offset_seconds)
    return make


def stopper_for(framework, spec):
    """`make(protocol, offset_steps=0) -> EarlyStopper | None`: the early-stop hook of a protocol with
    `early_stop` (`replication.training.early_stop`), else None."""
    def make(protocol, offset_steps=0):
        return EarlyStopper(framework, spec, protocol, offset_steps) if protocol.early_stop else None
    return make


def run_training(framework, spec, protocol, seed, on_log=None, snapshot=None) -> TrainOutcome:
    """One run of a protocol from the init of `seed`; with `protocol.scouting`, restarts over inits
    (`replication.training.scouting`); with `protocol.early_stop`, it ends when the held-out error stops
    improving. `snapshot`: where it keeps snapshots and resumes from them."""
    track, stop = tracker_for(framework, spec), stopper_for(framework, spec)
    if protocol.scouting:
        return train_scouted(trainer(framework), spec, protocol, seed, on_log=on_log, track=track,
                             snapshot=snapshot, stop=stop)
    t, s = track(protocol), stop(protocol)
    out = train_stopping(trainer(framework), spec, init_params(spec, seed=seed), protocol, BatchStream(protocol, seed),
                         on_log=on_log, hooks=(t,) if t else (), snapshot=snapshot, stop=s)
    if t:
        t.merge([out])
    if s:
        s.merge(out)
    return out


def cohort_seeds(protocol, seed: int) -> list[int]:
    """The seeds trained together with `seed` (`protocol.cohort`: groups g*K .. g*K + K - 1; else itself)."""
    k = protocol.cohort
    if not k:
        return [seed]
    return list(range(seed // k * k, seed // k * k + k))


def group_key(framework, spec, protocol, seed) -> str:
    """The key of the training program that makes `seed`'s model: units sharing it run in one chain."""
    return train_key(framework, spec, protocol, cohort_seeds(protocol, seed)[0])


def train_cohort(framework, spec, protocol, seeds, on_log=None, snapshot=None) -> list[TrainOutcome]:
    """The seeds' runs of `protocol` as one vectorised program (`train_members`): each its own init and
    batch stream, as when run alone. `on_log` sees the first seed's rows; every outcome's `train_time_s` is
    the program's (shared by the cohort)."""
    def first(row):
        if on_log and row.get("member", 0) == 0:
            on_log(row)
    t = tracker_for(framework, spec)(protocol)
    outcomes = trainer(framework).train_members(spec, [init_params(spec, seed=s) for s in seeds], protocol,
                                                [BatchStream(protocol, s) for s in seeds], on_log=first,
                                                hooks=(t,) if t else (), snapshot=snapshot)
    if t:
        t.merge(outcomes)
    for o in outcomes:
        o.cohort = {"seeds": list(seeds)}
    return outcomes


def _cached(folder: Path) -> TrainOutcome | None:
    try:
        meta = R.load_result(folder) if (folder / "result.json").exists() else None
    except R.CorruptResult as e:
        log.warning("retraining: %s", e)
        return None
    if meta is None:
        return None
    return TrainOutcome(params=R.load_npz(folder / "checkpoint.npz"),
                        log=pd.read_csv(folder / "train_log.csv").to_dict("records"),
                        failure=meta["failure"], train_time_s=meta["train_time_s"], steps_done=meta["steps_done"],
                        batch=meta["batch"], scouting=meta.get("scouting"), samples=meta.get("samples"),
                        cohort=meta.get("cohort"), step_mode=meta.get("step_mode"), device=meta.get("device"),
                        early_stop=meta.get("early_stop"),
                        tracked=R.load_npz(folder / "tracked.npz") if "tracked.npz" in meta["files"] else None)


def _store(folder: Path, outcome: TrainOutcome, spec, protocol, seed) -> None:
    files = {"checkpoint.npz": R.write_npz(folder / "checkpoint.npz", outcome.params),
             "train_log.csv": R.write_csv(folder / "train_log.csv", log_frame(outcome.log))}
    if outcome.tracked:
        files["tracked.npz"] = R.write_npz(folder / "tracked.npz", outcome.tracked)
    R.write_json(folder / "result.json", {"failure": outcome.failure, "train_time_s": outcome.train_time_s,
                                          "steps_done": outcome.steps_done, "batch": outcome.batch, "files": files,
                                          "scouting": outcome.scouting, "samples": outcome.samples,
                                          "cohort": outcome.cohort, "step_mode": outcome.step_mode,
                                          "device": outcome.device,
                                          **({"early_stop": outcome.early_stop} if outcome.early_stop else {}),
                                          "spec": spec.to_dict(),
                                          "protocol": protocol.to_dict(), "seed": seed},
                 checksum=True)


def train_cached(out, framework, spec, protocol, seed, on_log=None) -> TrainOutcome:
    """`seed`'s training, from `OUT/trained/` when it is there; a cohort protocol trains (and stores) its
    whole group of seeds at once, on the device asked for (`device.request()`; the key does not hold it)."""
    def folder(s):
        return Path(out) / "trained" / framework / train_key(framework, spec, protocol, s)
    done = _cached(folder(seed))
    if done is not None:
        return done
    seeds = cohort_seeds(protocol, seed)
    snapshot = Snapshots(folder(seeds[0]) / "inflight", train_key(framework, spec, protocol, seeds[0]))
    where = dev.resolve(dev.request(), framework)
    with dev.placed(framework, where):
        if len(seeds) > 1:
            outcomes = train_cohort(framework, spec, protocol, seeds, on_log=on_log, snapshot=snapshot)
        else:
            outcomes = [run_training(framework, spec, protocol, seed, on_log=on_log, snapshot=snapshot)]
    for s, o in zip(seeds, outcomes, strict=True):
        o.device = dev.describe(framework, where)
        _store(folder(s), o, spec, protocol, s)
    snapshot.clear()
    return outcomes[seeds.index(seed)]
