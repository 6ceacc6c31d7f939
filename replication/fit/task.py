"""`lagbench fit`: train a model on a user's data file and write the same result records as a claim.

The run is one unit of a synthetic claim "fit" evaluated by `replication.fit.evaluate` (one-step errors
per component, rollouts of whole held-out or test trajectories, energies, DeLaN's decomposition), so its
folder (`OUT/units/fit/<framework>/<model>/seed<k>/`) has result.json, train_log.csv, checkpoint.npz and
the evaluation's tables like every other unit; `replication.fit.load.load_fitted` loads the model back.

Data: a state file or a trajectory file (`replication.fit.userdata`); derivatives a trajectory file lacks are
estimated (`replication.fit.trajectories`), rows are split into train / held-out (`replication.fit.rows`:
`split` by-trajectory, the default for trajectory files, random, the default for state files, or none;
fraction `heldout`), and an optional `test` file is evaluated as a whole. The prepared rows are written
to OUT/data/ and the protocol records the sha256 of that file's bytes, so the training cache and the
unit's result are keyed by the data's content and every option: an edited file or option is trained
afresh, never served a stale model. A verified earlier fit of the same data and options is returned as
is; one of other data or options is kept, renamed `superseded-<time>-seed<k>` (as `lagbench run` does).

Torques: with tau columns, delan and baseline learn the inverse dynamics tau(q, qdot, qddot); an LNN or
HNN here learns unforced dynamics, so a file with tau is refused for them (a ValueError saying so)
rather than its torques silently ignored.

Contracts: every option is checked before the file is read or anything is trained, and the output
folder before training (a ValueError naming the option and its valid values).
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from models import ACTIVATIONS
from replication import results as R
from replication.claims.base import Claim, ModelEntry
from replication.fit import rows as fit_data
from replication.fit import trajectories, userdata
from replication.run.units import Unit, run_unit
from replication.training.protocol import Protocol

MODELS = ("lnn", "hnn", "delan", "baseline")
FRAMEWORKS = ("jax", "torch")
LOSSES = ("l1", "mse")
SCHEDULES = ("onecycle", "constant")
LOSS_NAMES = {"l1": "L1", "mse": "MSE"}
SET_NAMES = {"heldout": "held-out", "test": "test"}


def check_options(model, framework, steps, hidden, batch, lr, seed, loss, activation="softplus", weight_decay=0.0,
                  schedule="onecycle", lr_min_ratio=1e-4, delan_eps=0.01, delan_offset=2.0, input_scale=None,
                  substeps=2, system=None, horizon=None) -> None:
    """ValueError naming the first bad option and what it accepts."""
    checks = [
        ("--model", model in MODELS, f"one of {', '.join(MODELS)}", model),
        ("--framework", framework in FRAMEWORKS, f"one of {', '.join(FRAMEWORKS)}", framework),
        ("--loss", loss in LOSSES, f"one of {', '.join(LOSSES)}", loss),
        ("--steps", _count(steps, 1), "an integer >= 1", steps),
        ("--batch", _count(batch, 1), "an integer >= 1", batch),
        ("--seed", _count(seed, 0), "an integer >= 0", seed),
        ("--lr", _real(lr) and lr > 0, "a finite number > 0", lr),
        ("--hidden", len(hidden) > 0 and all(_count(h, 1) for h in hidden),
         "comma-separated layer widths >= 1 such as 128,128", ",".join(map(str, hidden))),
        ("--activation", activation in ACTIVATIONS, f"one of {', '.join(ACTIVATIONS)}", activation),
        ("--weight-decay", _real(weight_decay) and weight_decay >= 0, "a finite number >= 0", weight_decay),
        ("--schedule", schedule in SCHEDULES, f"one of {', '.join(SCHEDULES)}", schedule),
        ("--lr-final", _real(lr_min_ratio) and 0 < lr_min_ratio <= 1, "a fraction in (0, 1]", lr_min_ratio),
        ("--delan-eps", _real(delan_eps) and delan_eps >= 0, "a finite number >= 0", delan_eps),
        ("--delan-offset", _real(delan_offset), "a finite number", delan_offset),
        ("--input-scale", input_scale in (None, "auto") or (isinstance(input_scale, tuple) and all(
            _real(v) and v > 0 for v in input_scale)), "none, auto or positive numbers such as 1,1,0.3,0.3",
         input_scale),
        ("--substeps", _count(substeps, 1), "an integer >= 1", substeps),
        ("--horizon", horizon is None or (_real(horizon) and horizon > 0), "a number of seconds > 0", horizon),
    ]
    for option, ok, valid, value in checks:
        if not ok:
            raise ValueError(f"{option}: {value!r} is not valid; expected {valid}")
    if system is not None:
        import systems

        if system not in systems.names():
            raise ValueError(f"--system: unknown {system!r}; valid: {', '.join(systems.names())}")


def _count(v, low) -> bool:
    return isinstance(v, int) and not isinstance(v, bool) and v >= low


def _real(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def task_of(model: str, has_tau: bool, path) -> str:
    if has_tau and model in ("lnn", "hnn"):
        raise ValueError(f"{path}: has tau columns, but an {model.upper()} here learns unforced dynamics and would ignore "
                         f"them; drop the tau columns, or fit delan or baseline to learn the inverse dynamics")
    if model == "hnn":
        return "hamiltonian"
    return "inverse_dynamics" if has_tau else "acceleration"


def auto_scale(reference: str, task: str, kind: str) -> tuple:
    """1 / the standard deviation of each MLP input over the training rows (1 where it is 0), 6 digits."""
    b = userdata.batch_of(userdata.rows(reference, "train"), task)
    x = b["q"] if kind == "delan" else np.concatenate([b[k] for k in ("q", "qdot", "extra") if k in b], 1)
    sd = np.std(x, axis=0)
    return tuple(float(f"{1.0 / s:.6g}") if s > 0 else 1.0 for s in sd)


def metric_of(counts: dict, has_test: bool, loss: str) -> tuple[str, str]:
    """(metric, label) the fit reports: the loss on the test file, else on the held-out rows."""
    where = "test" if has_test else "heldout" if counts.get("heldout") else None
    if where is None:
        return "final_train_loss", f"training {LOSS_NAMES[loss]} (no held-out or test rows)"
    return f"{where}_{loss}", f"{SET_NAMES[where]} {LOSS_NAMES[loss]}"


@R.writes
def fit(data, model="lnn", out="results/fit", framework="jax", steps=2000, hidden=(128, 128), batch=256,
        lr=1e-3, seed=0, loss="l1", dtype="float32", activation="softplus", weight_decay=0.0, schedule="onecycle",
        lr_min_ratio=1e-4, delan_eps=0.01, delan_offset=2.0, angle_wrap=False, input_scale=None, split=None,
        heldout=fit_data.HELDOUT, test=None, window=trajectories.WINDOW, polyorder=trajectories.POLYORDER,
        system=None, substeps=2, energy=None, horizon=None, on_log=None, on_progress=None) -> dict:
    hidden = tuple(hidden)
    input_scale = tuple(input_scale) if isinstance(input_scale, (list, tuple)) else input_scale
    check_options(model, framework, steps, hidden, batch, lr, seed, loss, activation, weight_decay, schedule,
                  lr_min_ratio, delan_eps, delan_offset, input_scale, substeps, system, horizon)
    if split is not None:
        fit_data.check_options(split, heldout)
    trajectories.check_options(window, polyorder)
    out = R.output_folder(out, "--out")
    path = str(Path(data).resolve())
    raw = userdata.read(path)[1]
    task = task_of(model, "tau" in raw, path)
    if isinstance(input_scale, tuple):
        dof = raw["q"].shape[1]
        width = dof if model == "delan" else 3 * dof if task == "inverse_dynamics" else 2 * dof
        if len(input_scale) != width:
            names = "q" if model == "delan" else "q, qdot, qddot" if task == "inverse_dynamics" else "q, qdot"
            raise ValueError(f"--input-scale: {len(input_scale)} numbers given; this {model}'s MLP takes {width} "
                             f"inputs ({names}, {dof} each)")
    if energy:  # importable and of the right shape, before any work
        from replication.fit.evaluate import energy_function

        energy_function({"energy": energy}, raw["q"].shape[1])
    if test is not None:
        test_tau = "tau" in userdata.read(str(Path(test).resolve()))[1]
        if test_tau != (task == "inverse_dynamics"):
            task_of(model, test_tau, test)  # an LNN / HNN given tau: refused with the reason
            raise ValueError(f"--test {test}: {'has' if test_tau else 'lacks'} tau columns, the training data "
                             f"{'lacks' if test_tau else 'has'} them; give both files the same columns")
    prep = fit_data.prepare(out, path, split, heldout, window, polyorder, dtype)
    tprep = fit_data.prepare(out, test, window=window, polyorder=polyorder, dtype=dtype, kind="test") if test else None
    if tprep is not None and tprep.dof != prep.dof:
        raise ValueError(f"--test {test}: has {tprep.dof} degrees of freedom, the training data {prep.dof}")
    spec = {"kind": model, "dof": prep.dof, "activation": activation, "angle_wrap": bool(angle_wrap),
            "init": "cranmer2020" if model == "lnn" else "xavier"}
    if model == "delan":
        spec.update(delan_eps=float(delan_eps), delan_diag_offset=float(delan_offset))
    if task == "inverse_dynamics" and model == "baseline":
        spec["extra_inputs"] = prep.dof
    if input_scale is not None:
        spec["input_scale"] = auto_scale(prep.reference, task, model) if input_scale == "auto" else input_scale
    n_train = prep.counts["train"]
    protocol = Protocol(data=prep.reference, task=task, coords="qqdot", steps=steps, batch=min(batch, n_train),
                        n_train=n_train, n_heldout=max(1, prep.counts.get("heldout", 0)),  # the file's split decides
                        loss=loss, lr=lr, schedule=schedule, lr_min_ratio=lr_min_ratio, l2=weight_decay, dtype=dtype,
                        log_every=max(1, steps // 100))
    metric, label = metric_of(prep.counts, tprep is not None, loss)
    cfg = {"heldout": prep.counts.get("heldout", 0) > 0, "test": tprep.reference if tprep else None,
           "system": system, "energy": energy, "substeps": substeps, "source": prep.source,
           "derivatives": {"window": window, "polyorder": polyorder}, "rows": prep.counts,
           "trajectories": prep.trajectories}
    if horizon is not None:   # recorded only when given: fits without it keep their keys
        cfg["horizon"] = float(horizon)
    if tprep is not None:  # the user's test file and its rows, for the report
        cfg.update(test_source=tprep.source, test_rows=tprep.counts["test"], test_trajectories=tprep.trajectories["test"])
    entry = ModelEntry(model, spec, hidden=hidden)
    claim = Claim(id="fit", number=0, paper="user", section="-", title=f"{model} on {Path(data).name}",
                  system=system or Path(data).name, models=(entry,), protocols={"quick": protocol}, evaluate="fit",
                  metric=metric, metric_label=label, published={}, verdict_rule="none",
                  parts=(), eval_config={"quick": cfg})
    unit = Unit(claim, entry, framework, seed, "quick")
    from replication.run.runner import is_current

    if is_current(unit, out):
        return dict(R.load_result(unit.folder(out)), reused=True, metric=metric, metric_label=label)
    return dict(run_unit(unit, out, on_log=on_log, on_progress=on_progress), metric=metric, metric_label=label)
