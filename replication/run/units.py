"""Units of work: claim x framework x model x seed, and how one unit is run and written.

A unit reads four things of what it belongs to (`UnitSource`): its id, the profile's protocol, the
evaluation routine's name and the profile's evaluation config. A claim (`replication.claims.base.Claim`)
is one; a user's fit (`replication.fit.task.FitSource`) is another.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import numpy as np

from lagbench.files import results as R
from lagbench.files.user_functions import nonfinite_failure, nonfinite_rows
from lagbench.models import ModelSpec
from lagbench.models.spec import USER_KIND
from lagbench.replication.evaluation.adapters import adapter
from lagbench.replication.evaluation.registry import EVALUATION_VERSION, EVALUATIONS
from lagbench.replication.evaluation.routines import Context, heldout_of, system_of
from lagbench.replication.run import environment as env
from lagbench.replication.run import splits
from lagbench.replication.run.store import registration_hash
from lagbench.replication.training import device as dev
from lagbench.replication.training import hessian_probe
from lagbench.replication.training.objective import predict
from lagbench.replication.training.outcome import log_frame
from lagbench.replication.training.scouting import budget_samples
from lagbench.replication.training.train import train_cached


class UnitSource(Protocol):
    id: str
    evaluate: str   # a name in `replication.evaluation.registry.EVALUATIONS`

    def protocol(self, profile: str): ...

    def evaluation_config(self, profile: str) -> dict: ...


@dataclass(frozen=True)
class Unit:
    claim: UnitSource
    entry: object
    framework: str
    seed: int
    profile: str

    @property
    def split(self) -> str:
        """"dev" or "test" (`replication.run.splits`): a claim unit's split follows from its seed."""
        return splits.of_seed(self.seed).name

    @property
    def name(self) -> str:
        return f"{self.claim.id}/{self.framework}/{self.entry.label}/seed{self.seed}"

    def protocol(self):
        return self.entry.protocol(self.claim.protocol(self.profile), self.profile)

    def spec(self):
        p = self.protocol()
        fields = self.entry.spec_fields(self.profile)
        dof = fields.pop("dof", None) or system_of(p).dof
        return ModelSpec(dof=dof, hidden=self.entry.widths(self.profile) or (8,), dtype=p.dtype, **fields)

    def folder(self, out) -> Path:
        return R.unit_dir(out, self.claim.id, self.framework, self.entry.label, self.seed)


def _nonfinite(ctx) -> dict | None:
    """The failure of a model whose prediction is non-finite on any of the unit's held-out states (or None)."""
    batch = heldout_of(ctx)
    pred = predict(ctx.model, ctx.spec.kind, ctx.protocol.task, batch, np.concatenate)
    return nonfinite_failure(nonfinite_rows(pred), len(pred))


def run_unit(unit: Unit, out, on_log=None, on_progress=None) -> dict:
    """Train (or reuse the cached training), evaluate, and write the unit's files; result.json last.
    on_log(row): each training log row; on_progress(label, done, total): the evaluation's long work."""
    t0 = time.perf_counter()
    protocol, spec = unit.protocol(), unit.spec()
    folder = unit.folder(out)
    files, failure, outcome = {}, None, None
    if unit.entry.train:
        outcome = train_cached(out, unit.framework, spec, protocol, unit.seed, on_log=on_log)
        failure, params = outcome.failure, outcome.params
        files["train_log.csv"] = R.write_csv(folder / "train_log.csv", log_frame(outcome.log))
        files["checkpoint.npz"] = R.write_npz(folder / "checkpoint.npz", params)
    else:
        params = None
    ctx = Context(claim=unit.claim, entry=unit.entry, framework=unit.framework, spec=spec, params=params,
                  protocol=protocol, profile=unit.profile, cfg=unit.claim.evaluation_config(unit.profile),
                  split=splits.of_seed(unit.seed), progress=on_progress, seed=unit.seed)
    where = dev.resolve(dev.request(), unit.framework)
    with dev.placed(unit.framework, where):   # the model (its parameters too) and its evaluation on the run's device
        if params is not None:
            ctx.model = adapter(unit.framework, spec, params)
            ctx.log = outcome.log
            ctx.tracked = outcome.tracked
        ev = EVALUATIONS[unit.claim.evaluate](ctx)
        if spec.kind == USER_KIND and failure is None:   # a user's model: a non-finite prediction is never "ok"
            failure = _nonfinite(ctx)
    for name, df in ev.tables.items():
        files[name] = R.write_csv(folder / name, df)
    if ev.arrays:
        files["arrays.npz"] = R.write_npz(folder / "arrays.npz", ev.arrays)
    record = {
        "schema": R.SCHEMA, "claim": unit.claim.id, "framework": unit.framework, "model": unit.entry.label,
        "seed": unit.seed, "split": unit.split, "profile": unit.profile, "status": "ok" if failure is None else "failed",
        "failure": failure, "metrics": ev.metrics, "counters": {**ev.counters, **(hessian_probe.summarize(outcome.log) if outcome else {})},
        "model_spec": spec.to_dict(),
        "protocol": protocol.to_dict(), "eval_config": ctx.cfg, "evaluation_version": EVALUATION_VERSION, "dtype": protocol.dtype, "wall_time_s": time.perf_counter() - t0,
        "train_time_s": outcome.train_time_s if outcome else 0.0,
        "train_steps": outcome.steps_done if outcome else 0,
        # the budget; a run its early stop ended, or that continued a fallback scout: the samples it trained
        # (`Protocol.early_stop`, `Scouting.fallback`)
        "train_samples": (outcome.samples or outcome.steps_done * outcome.batch
                          if (outcome.early_stop and outcome.early_stop["stopped_at"] is not None)
                          or len((outcome.scouting or {}).get("continued", ())) > 1
                          else budget_samples(protocol)) if outcome else 0,
        **({"early_stop": outcome.early_stop} if outcome and outcome.early_stop else {}),
        "train_samples_per_s": outcome.samples_per_s if outcome else None,
        "final_train_loss": outcome.log[-1]["loss"] if outcome and outcome.log else None,
        "scouting": outcome.scouting if outcome else None,
        "cohort": outcome.cohort if outcome else None,
        "train_step_mode": outcome.step_mode if outcome else None,
        "train_device": outcome.device if outcome else None, "eval_device": dev.describe(unit.framework, where),
        "protocol_hash": registration_hash(unit.claim, unit.profile),   # its claim's registration (`run.store`)
        "versions": env.versions(), "commit": env.commit(), "hardware": env.hardware(), "created": env.now(),
        "arrays": {"arrays.npz": sorted(ev.arrays)} if ev.arrays else {}, "files": files,
    }
    return R.write_json(folder / "result.json", record, checksum=True)
