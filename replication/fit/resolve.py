"""What a fit resolves before any work (`replication.fit.task.fit` and the console line of `lagbench fit` start
here): `resolved(data, options) -> Resolved`, the options with the model kind's defaults filled in
(`replication.fit.kind_defaults`, sized to the data's coordinates and, for a recording, to its position noise),
the task, whether the data are a recording, their coordinates, the periodic inputs chosen and the noise, after
every check that needs no work done. `task_of(model, has_tau, path)`: what a kind trains on a file with or
without torques (a kind without inverse dynamics refuses torques, naming the kinds that have it).
"""
from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace
from typing import NamedTuple

from lagbench.files import user_data
from lagbench.models.kinds import CAPABILITIES
from lagbench.replication.fit import (
    filter_rows,
    kind_defaults,
    loss_target,
    periodic_coords,
    time_base,
    trajectories,
    windows,
)
from lagbench.replication.fit import options as fit_options
from lagbench.replication.fit import rows as fit_data
from lagbench.systems.registry import definition


def task_of(model: str, has_tau: bool, path) -> str:
    """What a fit of the kind `model` trains on a file with torque columns (`has_tau`) or without: the kind's
    first task in the table of kinds, or its inverse dynamics given torques; a kind without inverse dynamics
    refuses torques, naming the kinds that have it."""
    tasks = CAPABILITIES[model].tasks
    if not has_tau:
        return tasks[0]
    if "inverse_dynamics" not in tasks:
        inverse = " or ".join(k for k, c in CAPABILITIES.items() if "inverse_dynamics" in c.tasks)
        raise ValueError(f"{path}: has tau columns, but an {model.upper()} here learns unforced dynamics and would ignore "
                         f"them; drop the tau columns, or fit {inverse} to learn the inverse dynamics")
    return "inverse_dynamics"


class Resolved(NamedTuple):
    """`resolved`'s answer: the options with the model kind's defaults filled in (`periodic` the indices chosen),
    the task the data and model give, whether the data are a trajectory file (a recording) rather than a file of
    state samples, the data's coordinates (the kind's defaults follow them: `kind_defaults.small`), what
    the fit records of its periodic inputs (`periodic_coords.choose`) and the recording's position noise where
    the kind's budget follows it (`kind_defaults.NOISY_RECORDINGS`; None otherwise), and what it records of its
    loss (`loss_target.choose`; `options.loss_target` is the loss chosen)."""
    options: SimpleNamespace
    task: str
    recording: bool
    dof: int
    periodic: dict
    noise: float | None = None
    loss_target: dict | None = None


def resolved(data, options: dict) -> Resolved:
    """The options with the model kind's defaults filled in (`replication.fit.kind_defaults`), the task and
    whether the data are a recording (a trajectory index column), after every check that needs no work done:
    the options, the input scale's width, the energy function, the test file's columns."""
    o = fit_options.resolve(options)
    path = str(Path(data).resolve())
    fit_options.check(vars(o))
    if o.split is not None:
        fit_data.check_options(o.split, o.heldout)
    if options.get("patience") and (o.split == "none" or not o.heldout):
        raise ValueError(f"--patience {options['patience']}: the early stop reads held-out rows, and --holdout "
                         f"{o.split or 'by-trajectory'} --holdout-fraction {o.heldout:g} holds none out; give --patience 0")
    trajectories.check_options(o.window, o.polyorder)
    digest, raw = user_data.read(path)
    time_base.check_unit(path, raw, o.system, o.time_unit)
    task, recording, dof = task_of(o.model, "tau" in raw, path), "traj" in raw, raw["q"].shape[1]
    noise = None
    if recording and (o.model, task) in kind_defaults.NOISY_RECORDINGS and o.loss_target != "trajectory":
        noise = trajectories.position_noise(time_base.in_seconds(raw, o.time_unit), path, o.polyorder, o.gaps)
    o = kind_defaults.fill(o, task, recording=recording, dof=dof, noise=noise)
    if o.system is not None and definition(o.system).dof != dof:   # its energy and angles are not the data's
        raise ValueError(f"--system {o.system}: has {definition(o.system).dof} coordinates, the data {path} {dof}")
    periodic = periodic_coords.choose(o.periodic, o.system, bool(o.angle_wrap))
    o.periodic = tuple(periodic["chosen"])
    derivatives = [k for k in ("qdot", "qddot") if k in raw]   # given in the file, not estimated by the fit
    target = loss_target.choose(o.loss_target, o.model, task, recording, derivatives)
    o.loss_target = target["chosen"]
    if o.loss_target == "trajectory":
        windows.check_fit(path, task, recording)
    if o.loss_target == "filtered":
        filter_rows.check_fit(path, task, recording, given=derivatives)
    if o.loss_target != "trajectory":
        given = [k for k in ("horizon_frames", "horizon_substeps", "horizon_scale")
                 if options.get(k, fit_options.BY_NAME[k].default) != fit_options.BY_NAME[k].default]
        if given:
            raise ValueError(f"{fit_options.BY_NAME[given[0]].cli}: an option of the trajectory loss; give it with "
                             f"--loss-target trajectory")
    if o.periodic:   # the spec's checks: indices within the data's coordinates, the kind, not with --angle-wrap
        from lagbench.models import ModelSpec
        try:
            ModelSpec(kind=o.model, dof=dof, periodic=tuple(o.periodic), angle_wrap=bool(o.angle_wrap))
        except ValueError as e:
            raise ValueError(f"--periodic: {e}") from None
    if isinstance(o.input_scale, tuple):
        width = dof if o.model == "delan" else 3 * dof if task == "inverse_dynamics" else 2 * dof
        width += len(o.periodic)
        if len(o.input_scale) != width:
            names = "q" if o.model == "delan" else "q, qdot, qddot" if task == "inverse_dynamics" else "q, qdot"
            trig = f"; cos and sin of q_{', q_'.join(map(str, o.periodic))} in place of each" if o.periodic else ""
            raise ValueError(f"--input-scale: {len(o.input_scale)} numbers given; this {o.model}'s MLP takes {width} "
                             f"inputs ({names}, {dof} each{trig})")
    if o.energy:  # importable and of the right shape, before any work
        from lagbench.replication.fit.evaluate import energy_function

        energy_function({"energy": o.energy}, dof)
    if o.test is not None:
        test_digest, test_raw = user_data.read(str(Path(o.test).resolve()))
        if test_digest == digest:   # its errors would be the training error, reported as a test error
            raise ValueError(f"--test {o.test}: byte for byte the training data (--data {data}); give a file of "
                             f"other trajectories (e.g. `lagbench simulate --seed 1`)")
        time_base.check_unit(o.test, test_raw, o.system, o.time_unit)
        test_tau = "tau" in test_raw
        if test_tau != (task == "inverse_dynamics"):
            task_of(o.model, test_tau, o.test)  # an LNN / HNN given tau: refused with the reason
            raise ValueError(f"--test {o.test}: {'has' if test_tau else 'lacks'} tau columns, the training data "
                             f"{'lacks' if test_tau else 'has'} them; give both files the same columns")
    return Resolved(o, task, recording, dof, periodic, noise, target)
