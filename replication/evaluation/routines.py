"""Evaluation routines named by claims: each maps a trained model to metrics, tables and arrays.

`EVALUATIONS[name](ctx) -> Evaluation`. `ctx` is a `Context` (claim, entry, framework, spec,
params, protocol, profile, evaluation config, `split` (`replication.run.splits`: the held-out draw and
the seeds of the routine's own draws, through `heldout_of` and `truth_key`), and `model`: a NumPy adapter
of the trained model, see `replication.evaluation.adapters`). Everything here is NumPy and framework-neutral, so both frameworks
are judged by the same code; ground truth comes from `systems` in float64.
"""
from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
import pandas as pd

import lagbench.systems.trajectories
from lagbench import systems
from lagbench.replication.evaluation.canonical import canonical_rollout, state_velocity
from lagbench.replication.evaluation.metrics import (
    bounded_relative_error,
    energy_errors,
    geometric_mean_over_time,
    heldout_errors,
    null_errors,
)
from lagbench.replication.evaluation.rollout import hamiltonian_field, lagrangian_field, rollout, steps
from lagbench.replication.evaluation.valid_time import (
    PERTURBATION,
    VPT_NRMSE,
    normalised_rmse,
    valid_time,
    valid_times,
)
from lagbench.replication.run.splits import DEV
from lagbench.replication.training import data as datamod
from lagbench.replication.training.objective import predict


@dataclass
class Context:
    claim: object
    entry: object
    framework: str
    spec: object
    params: dict
    protocol: object
    profile: str
    cfg: dict
    model: object = None
    log: list | None = None   # the training log rows (`TrainOutcome.log`), for routines that read the pace
    split: object = DEV   # `replication.run.splits.Split`: the held-out draw and the draws' seeds evaluated on
    progress: object = None   # progress(label, done, total) or None: a routine's long work, for a progress bar
    tracked: dict | None = None   # the training's kept checkpoints (`Tracking.keep`; `evaluation.matched`)
    seed: int = 0   # the unit's seed (a routine that builds its own model from it: `evaluation.online_claim`)


# what the matched checkpoint's evaluation records (`evaluation.matched`)
MATCHED = ("heldout_l1", "energy_err_final", "energy_err_final_median", "rollout_gmean_err")


@dataclass
class Evaluation:
    metrics: dict = field(default_factory=dict)
    counters: dict = field(default_factory=dict)
    tables: dict = field(default_factory=dict)   # file name -> DataFrame
    arrays: dict = field(default_factory=dict)   # name -> ndarray (written to arrays.npz)


def system_of(protocol, **extra):
    name = protocol.data.recipe.removesuffix("_iid")
    return systems.get(name, **{**dict(protocol.data.system_params), **extra})


def heldout_of(ctx, protocol=None, **kw) -> dict:
    """The held-out set of `protocol` (default the unit's) in the unit's split."""
    return datamod.heldout(protocol or ctx.protocol, seed=ctx.split.heldout_seed, **kw)


def truth_key(ctx) -> tuple:
    """The arguments of `_truth` for this unit: its system, and its evaluation config with the rollout
    initial conditions' seed (`ic_seed`, default 0) moved by the split's offset."""
    cfg = dict(ctx.cfg)
    cfg["ic_seed"] = cfg.get("ic_seed", 0) + ctx.split.draw_offset
    return ctx.protocol.data.recipe.removesuffix("_iid"), tuple(sorted(ctx.protocol.data.system_params)), tuple(sorted(cfg.items()))


def pdot_to_qddot(protocol, q, qdot, pdot):
    """q-double-dot from a predicted pdot along the motion, pdot = dp/dq qdot + dp/dqdot qdd: with the
    truth's own rate r = dp/dq qdot + dp/dqdot qdd_true, qdd = qdd_true + (d2L/dqdot2)^-1 (pdot - r)."""
    s = system_of(protocol)
    gap = (pdot - s.canonical_momentum_rate(q, qdot))[..., None]
    return s.acceleration(q, qdot) + np.linalg.solve(s.velocity_hessian(q, qdot), gap)[..., 0]


def qddot_of_prediction(p, batch, pred):
    """q-double-dot from a model's prediction of `batch`'s target, as the verdicts read it: the prediction
    itself for an acceleration model, the y-rate of an HNN on (q, qdot), the pdot of an HNN on (q, p) mapped
    through dp/dqdot; None for an inverse model (it predicts torques)."""
    if p.task == "hamiltonian":
        ydot = pred[:, batch["q"].shape[-1]:]
        return ydot if p.data.coords == "qqdot" else pdot_to_qddot(p, batch["q"], _qdot(batch, p), ydot)
    return pred if p.task == "acceleration" else None


def eval_heldout(ctx) -> Evaluation:
    p, m = ctx.protocol, ctx.model
    batch = heldout_of(ctx)
    pred = predict(m, ctx.spec.kind, p.task, batch, np.concatenate)
    w = batch.get("weight")
    e = heldout_errors(pred, batch["target"], w)
    null = null_errors(batch["target"], w)
    out = Evaluation(metrics={"heldout_l1": e["l1"], "heldout_mse": e["mse"],
                              "null_heldout_l1": null["l1"], "null_heldout_mse": null["mse"]})
    qdd = qddot_of_prediction(p, batch, pred)
    if qdd is not None:
        out.metrics["heldout_l1_qddot"] = heldout_errors(qdd, batch["qddot"], w)["l1"]
        out.metrics["null_heldout_l1_qddot"] = null_errors(batch["qddot"], w)["l1"]
    if ctx.spec.kind == "lnn":
        _, n_fb = m.acceleration_info(batch["q"], batch["qdot"], batch.get("extra"))
        out.counters["hessian_fallbacks"] = int(n_fb)
        out.counters["hessian_fallback_fraction"] = float(n_fb) / len(batch["q"])
        eig = np.linalg.eigvalsh(m.velocity_hessian(batch["q"], batch["qdot"], batch.get("extra")))
        out.counters["hessian_indefinite_fraction"] = float(np.mean((eig[:, 0] < 0) & (eig[:, -1] > 0)))
    return out


def _qdot(batch, p):
    """The true velocity of a held-out batch (for canonical coordinates the batch holds p)."""
    return batch["target"][:, : batch["q"].shape[-1]] if p.task == "hamiltonian" else batch["qdot"]


def _initial_states(s, cfg, rng):
    n = cfg["n_ics"]
    st = s.sample_states(n, rng)
    q, qdot = st["q"], st["qdot"]
    if cfg.get("near_rest", s.name == "double_pendulum"):
        qdot = rng.uniform(0.0, 0.1, size=qdot.shape)
    return q, qdot


@lru_cache(maxsize=16)
def _truth(name, params, cfg_items):
    cfg = dict(cfg_items)
    s = systems.get(name, **dict(params))
    rng = np.random.default_rng(cfg.get("ic_seed", 0))
    q0, qd0 = _initial_states(s, cfg, rng)
    t = np.linspace(0.0, cfg["t_end"], cfg["n_t"])
    q, qd = lagbench.systems.trajectories.integrate(s, q0, qd0, t)
    qc, qdc = lagbench.systems.trajectories.integrate(s, q0 + 1e-4, qd0, t)
    return s, t, q, qd, qc, qdc


@lru_cache(maxsize=16)
def _floor(name, params, cfg_items):
    """The truth from the truth's initial states with PERTURBATION added to every angle: the chaos floor."""
    s, t, q, qd, _, _ = _truth(name, params, cfg_items)
    return lagbench.systems.trajectories.integrate(s, q[:, 0] + PERTURBATION, qd[:, 0], t)


def truth_rk4(name, params, cfg_items, dtype: str, step: str = "split"):
    """The exact equations of motion through the suite's RK4 in `dtype` (state, step and equations), from the
    truth's initial states at the evaluation's dt (step rule `step`): what a perfect model rolled out in that
    dtype gives. Not cached: its callers cache what they derive from it."""
    s, t, q, qd, _, _ = _truth(name, params, cfg_items)
    accel = lambda a, b: s.acceleration(a, b, backend="numpy").astype(dtype)  # noqa: E731
    y0 = np.concatenate([q[:, 0], qd[:, 0]], -1)
    return rollout(lagrangian_field(accel, s.dof), y0, t, dict(cfg_items)["dt"], dtype=dtype, step=step)


@lru_cache(maxsize=8)
def _float32_truth(name, params, cfg_items):
    return truth_rk4(name, params, cfg_items, "float32")


def _model_rollout(ctx, s, q0, qd0, t):
    p, m, d = ctx.protocol, ctx.model, s.dof
    if p.task == "hamiltonian" and p.data.coords == "qp":
        # in (q, p) by its own H; the true system's velocity at each predicted state (q, p), so that its energy
        # is H_true(q, p), as the HNN paper measures it
        q, pp = canonical_rollout(m.time_derivative, s, q0, qd0, t, ctx.cfg["dt"])
        return q, state_velocity(s, q, pp)
    if p.task == "hamiltonian":
        f = hamiltonian_field(lambda x, y: m.time_derivative(x, y, None), d)
    else:
        f = lagrangian_field(lambda q, qd: m.acceleration(q, qd, None), d)
    z = rollout(f, np.concatenate([q0, qd0], 1), t, ctx.cfg["dt"])
    return z[..., :d], z[..., d:]


def eval_energy_rollout(ctx) -> Evaluation:
    out = eval_heldout(ctx)
    cfg = ctx.cfg
    s, t, q, qd, qc, qdc = _truth(*truth_key(ctx))
    t0 = time.perf_counter()
    qp, qdp = _model_rollout(ctx, s, q[:, 0], qd[:, 0], t)
    # wall-clock microseconds per RK4 step of one trajectory (the rollout batched over its initial conditions,
    # the model called from NumPy in its own framework; beside other workers on a shared CPU: a guide, the
    # speed study times inference properly)
    n_steps = sum(steps(b - a, cfg["dt"], "split", np.float64)[0] for a, b in zip(t[:-1], t[1:], strict=True))
    out.metrics["rollout_us_per_step"] = 1e6 * (time.perf_counter() - t0) / max(n_steps * q.shape[0], 1)
    with np.errstate(over="ignore", invalid="ignore"):   # a diverged rollout's energy is inf or nan: counted as such
        E_true, E_pred = s.energy(q, qd, backend="numpy"), s.energy(qp, qdp, backend="numpy")
    out.metrics.update(energy_errors(E_pred, E_true, cfg["energy_scale"]))
    z_true, z_pred = np.concatenate([q, qd], -1), np.concatenate([qp, qdp], -1)
    err = bounded_relative_error(z_pred, z_true)
    floor = bounded_relative_error(np.concatenate([qc, qdc], -1), z_true)
    out.metrics["rollout_gmean_err"] = float(np.nanmean(geometric_mean_over_time(err)))
    out.metrics["chaos_floor_gmean_err"] = float(np.mean(geometric_mean_over_time(floor)))
    vpt, vpt_columns = valid_times(t, z_pred, z_true, np.concatenate(_floor(*truth_key(ctx)), -1))
    out.metrics.update(vpt)
    if cfg.get("float32_truth"):   # the second floor: the exact model rolled out in float32
        with np.errstate(all="ignore"):
            err32 = normalised_rmse(_float32_truth(*truth_key(ctx)), z_true)
        out.metrics["float32_truth_vpt_s"] = float(np.median(valid_time(err32, t, VPT_NRMSE)))
    idx = np.unique(np.linspace(0, t.size - 1, min(t.size, 200)).astype(int))
    rows = []
    for b in range(q.shape[0]):
        for qty, series in (("energy_err", (E_pred[b] - E_true[b]) / cfg["energy_scale"]),
                            ("state_err", err[b]), ("chaos_floor", floor[b])):
            rows.append(pd.DataFrame({"traj": b, "t": t[idx], "quantity": qty, "value": series[idx]}))
    out.tables["timeseries.csv"] = pd.concat(rows, ignore_index=True)
    out.tables["rollouts.csv"] = pd.DataFrame({
        "traj": np.arange(q.shape[0]), "energy_err_final": np.abs(E_pred[:, -1] - E_true[:, -1]) / cfg["energy_scale"],
        "energy_err_max": np.max(np.abs(E_pred - E_true), 1) / cfg["energy_scale"],
        "diverged": ~np.all(np.isfinite(E_pred), axis=1),
        "gmean_err": geometric_mean_over_time(err), "chaos_floor_gmean_err": geometric_mean_over_time(floor),
        **vpt_columns})
    out.arrays = {"t": t, "q_true": q[:3], "q_pred": qp[:3]}
    if cfg.get("match_heldout_l1"):   # the same evaluation at the checkpoint nearest a registered accuracy
        from lagbench.replication.evaluation.matched import at_level

        plain = {k: v for k, v in cfg.items() if k not in ("match_heldout_l1", "float32_truth")}
        out.metrics.update(at_level(ctx, cfg["match_heldout_l1"],
                                    lambda c: {k: v for k, v in eval_energy_rollout(dataclasses.replace(c, cfg=plain)).metrics.items()
                                               if k in MATCHED}))
    return out
