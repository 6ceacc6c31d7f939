"""`lagbench fit`: train a model on a user's data file and write the same result records as a claim.

The run is one unit of a synthetic claim "fit" evaluated by `replication.fit.evaluate` (one-step errors
per component, rollouts of whole held-out or test trajectories, energies, DeLaN's decomposition), so its
folder (`OUT/units/fit/<framework>/<model>/seed<k>/`) has result.json, train_log.csv, checkpoint.npz and
the evaluation's tables like every other unit; `replication.fit.load.load_fitted` loads the model back.

Data: a state file or a trajectory file (`lagbench.files.user_data`); derivatives a trajectory file lacks are
estimated (`replication.fit.trajectories`), rows are split into train / held-out (`replication.fit.rows`:
`split` by-trajectory, the default for trajectory files, random, the default for state files, or none;
fraction `heldout`), and an optional `test` file is evaluated as a whole. With `window` "auto" (the default)
each file's derivative window is chosen from its own noise and motion (`replication.fit.derivative_window`),
recorded with the estimated noise and predicted errors in eval_config["derivatives"] (the test file's in
"test_derivatives"). The prepared rows are written
to OUT/data/ and the protocol records the sha256 of that file's bytes, so the training cache and the
unit's result are keyed by the data's content and every option: an edited file or option is trained
afresh, never served a stale model. A verified earlier fit of the same data and options is returned as
is; one of other data or options is kept, renamed `superseded-<time>-seed<k>` (as `lagbench run` does).

Budget: the model kind's defaults, sized to the data's coordinates (`replication.fit.kind_defaults`);
with `patience` (a small system's default, or given) the training stops early when its held-out error stops
improving (`replication.training.early_stop`: evaluated at each of the log's rows, `HELDOUT_CHECKS` over
the steps), the record's `early_stop` saying when.

Loss target: `loss_target` "trajectory" (a trajectory file) trains on windows of the training trajectories
(`replication.fit.windows`: the model's motion integrated over `horizon_frames` frames from each recorded
frame, against the recorded positions; the protocol's `trajectory_loss` records it, so a fit says which loss
trained it), while the early stop and the evaluation score the held-out rows as every fit does; the
`horizon_*` options, set to other than their defaults, are refused without it. `loss_target` "filtered" (a
trajectory file whose derivatives are estimated, the acceleration task) trains on the rows whose frames the
derivative filter spans (`replication.fit.filter_rows`: the estimate against the model's q-double-dot at those
frames, smoothed by the filter's kernel; the protocol's `filter_loss` records the window and order).

Choices from the data and the system, recorded in eval_config["periodic"] and ["dissipation"] and passed to
`on_choices` before any training: `periodic` "auto" takes the coordinates in which the `system`'s Lagrangian is
2 pi-periodic (`replication.fit.periodic_coords`); `dissipation` "auto" learns a dissipation where the training
trajectories lose energy (`replication.fit.energy_trend`), its folder then `<model>_dissipative` as with "on";
`even_velocity` "auto" makes an LNN's Lagrangian even in q-dot where it learns a dissipation on a noisy
recording, with half the default steps (`replication.fit.even_velocity`; recorded in eval_config["even_velocity"]
where on, and passed to `on_choices` for an LNN).

Torques: with tau columns, delan and baseline learn the inverse dynamics tau(q, qdot, qddot); an LNN or
HNN here learns unforced dynamics, so a file with tau is refused for them (a ValueError saying so)
rather than its torques silently ignored.

Contracts (the checks in `replication.fit.resolve`): every option is checked before the file is read or anything is trained, and the output
folder before training (a ValueError naming the option and its valid values).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lagbench.files import results as R
from lagbench.files import user_data
from lagbench.replication.claims.base import ModelEntry
from lagbench.replication.fit import (
    energy_trend,
    even_velocity,
    filter_rows,
    kind_defaults,
    loss_target,
    time_base,
    trajectories,
    windows,
)
from lagbench.replication.fit import rows as fit_data
from lagbench.replication.fit.dissipation import GATE as FRICTION_GATE
from lagbench.replication.fit.resolve import resolved
from lagbench.replication.run.units import Unit, run_unit
from lagbench.replication.training.protocol import (
    Data,
    EarlyStop,
    FilterLoss,
    Guard,
    Protocol,
    Scouting,
    TrajectoryLoss,
)
from lagbench.replication.training.schedules import Constant, OneCycle

LOSS_NAMES = {"l1": "L1", "mse": "MSE"}
SET_NAMES = {"heldout": "held-out", "test": "test"}


def auto_scale(reference: str, task: str, kind: str, periodic: tuple = ()) -> tuple:
    """1 / the standard deviation of each MLP input over the training rows (1 where it is 0), 6 digits; the
    periodic coordinates' inputs are their cos and sin, in the MLP's layout (`models.spec`)."""
    b = user_data.batch_of(user_data.rows(reference, "train"), task)
    q = np.concatenate([np.stack([np.cos(c), np.sin(c)], 1) if k in periodic else c[:, None]
                        for k, c in enumerate(b["q"].T)], 1)
    x = q if kind == "delan" else np.concatenate([q, *(b[k] for k in ("qdot", "extra") if k in b)], 1)
    sd = np.std(x, axis=0)
    return tuple(float(f"{1.0 / s:.6g}") if s > 0 else 1.0 for s in sd)


def metric_of(counts: dict, has_test: bool, loss: str) -> tuple[str, str]:
    """(metric, label) the fit reports: the loss on the test file, else on the held-out rows."""
    where = "test" if has_test else "heldout" if counts.get("heldout") else None
    if where is None:
        return "final_train_loss", f"training {LOSS_NAMES[loss]} (no held-out or test rows)"
    return f"{where}_{loss}", f"{SET_NAMES[where]} {LOSS_NAMES[loss]}"


@dataclass(frozen=True, eq=False)
class FitSource:
    """What a fit's unit belongs to (`replication.run.units.UnitSource`): the id "fit", the fit's protocol
    and evaluation config (the same under any profile), the "fit" evaluation routine."""
    base: Protocol
    cfg: dict
    id: str = "fit"
    evaluate: str = "fit"

    def protocol(self, profile: str) -> Protocol:
        return self.base

    def evaluation_config(self, profile: str) -> dict:
        return self.cfg


@R.writes
def fit(data, out="results/fit", dtype="float32", on_log=None, on_progress=None, on_train=None, on_choices=None,
        **options) -> dict:
    """Train and evaluate one model on `data`; `options` by keyword (`replication.fit.options.OPTIONS`,
    their defaults where not given). `on_choices({"periodic": record, "dissipation": record})` (and for an LNN
    "even_velocity"): called once they are chosen, before anything is trained; `on_train(protocol)`: called
    before a training starts (not when an earlier fit is returned), `on_log(row)` then with each training log
    row (`replication.fit.progress`)."""
    o, task, recording, dof, periodic, noise, target = resolved(data, options)   # every check that needs no work, before the output folder is made
    path = str(Path(data).resolve())
    out = R.output_folder(out, "--out")
    deriv = file_derivatives(path, o.window, o.polyorder, o.gaps, o.time_unit)
    prep = fit_data.prepare(out, path, o.split, o.heldout, deriv["window"], o.polyorder, dtype, gaps=o.gaps,
                            time_unit=o.time_unit)
    tderiv = file_derivatives(o.test, o.window, o.polyorder, o.gaps, o.time_unit) if o.test else None
    tprep = fit_data.prepare(out, o.test, window=tderiv["window"], polyorder=o.polyorder, dtype=dtype, kind="test",
                             gaps=o.gaps, time_unit=o.time_unit) if o.test else None
    if tprep is not None and tprep.dof != prep.dof:
        raise ValueError(f"--test {o.test}: has {tprep.dof} degrees of freedom, the training data {prep.dof}")
    dissipation = energy_trend.for_fit(o, prep)
    o.dissipation = dissipation["chosen"]   # the form trained (and its folder's label) follows the choice
    o, even = even_velocity.for_fit(o, options, task, recording, dof, noise)
    if on_choices:
        on_choices({"periodic": periodic, "dissipation": dissipation, "loss_target": target}
                   | ({"even_velocity": even} if o.model == "lnn" else {}))
    n_train = prep.counts["train"]
    trajectory_loss = TrajectoryLoss(frames=o.horizon_frames, substeps=o.horizon_substeps, scale=o.horizon_scale) \
        if o.loss_target == "trajectory" else None
    if trajectory_loss is not None:   # the training rows are the recording's windows
        n_train = len(windows.training_windows(prep.reference, trajectory_loss, o.loss)["q"])
    # the filter that estimated the training file's q-double-dot: its window as its derivatives record it
    filter_loss = FilterLoss(window=deriv["window"], polyorder=o.polyorder) if o.loss_target == "filtered" else None
    if filter_loss is not None:   # the training rows whose frames the filter spans are all rows
        n_train = len(filter_rows.training_rows(prep.reference, filter_loss)["q"])
    data = Data(recipe=prep.reference, n_train=n_train, n_heldout=max(1, prep.counts.get("heldout", 0)))  # the file's split
    schedule = OneCycle(lr=o.lr, start=o.lr_start, min_ratio=o.lr_min_ratio) if o.schedule == "onecycle" else Constant(lr=o.lr)
    batch = min(o.batch, n_train)
    scouting = Scouting(count=o.restarts, steps=o.restart_steps, batch=min(o.restart_batch, n_train),
                        schedule=OneCycle(lr=o.restart_lr, min_ratio=o.lr_min_ratio) if o.schedule == "onecycle"
                        else Constant(lr=o.restart_lr), keep=o.restart_keep,
                        fallback=o.restart_fallback or 0) if o.restarts else None
    guard = Guard(clip=o.guard_clip, skip=o.guard_skip) if (o.guard_clip or o.guard_skip) else None
    log_every = max(1, o.steps // kind_defaults.HELDOUT_CHECKS)
    patience = o.patience if prep.counts.get("heldout") else 0
    if o.patience and not patience and "patience" in options:
        raise ValueError(f"--patience {o.patience}: the early stop reads held-out rows, and this split has none "
                         f"(--holdout, --holdout-fraction); give --patience 0")
    # a stopped run anneals over as many steps as its patience spans (`replication.training.early_stop`)
    early_stop = EarlyStop(every=log_every, patience=patience, min_improvement=kind_defaults.MIN_IMPROVEMENT,
                           anneal=patience * log_every) if patience else None
    protocol = Protocol(data=data, task=task, steps=o.steps, batch=batch, loss=o.loss, l2=o.weight_decay,
                        schedule=schedule, scouting=scouting, guard=guard, dtype=dtype, log_every=log_every,
                        early_stop=early_stop, trajectory_loss=trajectory_loss, filter_loss=filter_loss)
    metric, label = metric_of(prep.counts, tprep is not None, o.loss)
    cfg = {"heldout": prep.counts.get("heldout", 0) > 0, "test": tprep.reference if tprep else None,
           "system": o.system, "energy": o.energy, "substeps": o.substeps, "source": prep.source,
           "derivatives": {**deriv, **({"gaps": o.gaps} if o.gaps != "interpolate" else {}),
                           **({"time_unit": o.time_unit} if o.time_unit != "s" else {})}, "rows": prep.counts,
           "trajectories": prep.trajectories, "periodic": periodic, "dissipation": dissipation}
    if even["chosen"]:   # recorded only when on: the other fits keep their keys
        cfg["even_velocity"] = even
    if loss_target.auto_departed(target):   # likewise: a loss auto chose
        cfg["loss_target"] = target
    if o.horizon is not None:   # recorded only when given: fits without it keep their keys
        cfg["horizon"] = float(o.horizon)
    if o.dissipation:   # how its friction is checked: a fit checked by another rule is evaluated again
        cfg["friction_gate"] = FRICTION_GATE
    if tprep is not None:  # the user's test file and its rows, for the report
        cfg.update(test_source=tprep.source, test_rows=tprep.counts["test"], test_trajectories=tprep.trajectories["test"])
        if tderiv.get("rule") == trajectories.AUTO:   # its own window, by the same rule
            cfg["test_derivatives"] = tderiv
    # a dissipative fit has its own folder beside the conservative one of the same kind: the two compare
    entry = ModelEntry(o.model + ("_dissipative" if o.dissipation else ""), _model_spec(o, prep, task), hidden=o.hidden)
    unit = Unit(FitSource(protocol, cfg), entry, o.framework, o.seed, "quick")
    from lagbench.replication.run.runner import is_current

    if is_current(unit, out):
        return dict(R.load_result(unit.folder(out)), reused=True, metric=metric, metric_label=label)
    if on_train:
        on_train(protocol)
    return dict(run_unit(unit, out, on_log=on_log, on_progress=on_progress), metric=metric, metric_label=label)


def file_derivatives(path, window, polyorder, gaps, time_unit) -> dict:
    """What a fit records of the derivatives of the data file `path` (`trajectories.derivative_record`): with
    `window` "auto", the window chosen from that file's own noise and motion, and why."""
    path = str(Path(path).resolve())
    d = time_base.in_seconds(user_data.read(path)[1], time_unit)
    return trajectories.derivative_record(d, path, window, polyorder, gaps)


def _model_spec(o, prep, task: str) -> dict:
    """The model's spec fields from the options and the prepared data."""
    spec = {"kind": o.model, "dof": prep.dof, "activation": o.activation, "angle_wrap": bool(o.angle_wrap),
            "init": "cranmer2020" if o.model == "lnn" else "xavier"}
    if o.model == "delan":
        spec.update(delan_eps=float(o.delan_eps), delan_diag_offset=float(o.delan_offset))
    if o.dissipation:
        spec["dissipation"] = True
    if o.even_velocity:
        spec["even_velocity"] = True
    if task == "inverse_dynamics" and o.model == "baseline":
        spec["extra_inputs"] = prep.dof
    if o.periodic:
        spec["periodic"] = tuple(o.periodic)
    if o.input_scale is not None:
        spec["input_scale"] = (auto_scale(prep.reference, task, o.model, tuple(o.periodic)) if o.input_scale == "auto"
                               else o.input_scale)
    return spec
