"""Evaluation of a fitted model on a user's rows: the routine `fit` (EVALUATIONS["fit"]) that both
`lagbench fit` (its held-out rows and its `--test` file) and `lagbench evaluate` run.

ctx.cfg: {"heldout": bool (evaluate the protocol file's held-out rows), "test": a prepared file's
`user_data.reference` or None, "system": a `systems` name or None, "energy": "module:function" (a user's
E(q, qdot), in place of the system's) or None, "substeps": RK4 steps per sample
interval, "horizon": seconds of each trajectory rolled out (absent: all), "model": a fit's unit folder (evaluate: the model is loaded from it by `load.load_fitted`)}.
Every evaluation set S ("heldout", "test") gives, as NumPy arrays and alike for both frameworks:

one step   S_l1, S_mse (as the training loss: per-sample sum over components, mean over samples) and the
           null predictor's (`metrics.null_errors`); per component (`one_step.csv`: set, quantity,
           component, mae, rmse, null_mae, rel_mae = mae / null_mae) in the quantity trained: qddot,
           (qdot, qddot) for an HNN, tau for inverse dynamics.
rollouts   (sets with whole trajectories) every trajectory from its first state over its own times (to
           cfg["horizon"] seconds when set) by the shared RK4 in the model's framework (`Fitted.rollout`,
           `rollout_native`: step = sample spacing / substeps; an HNN by its own flow, with qdot in the place
           of p as it was trained), under the recorded torques when the model is a forward model given tau
           (DeLaN; linear interpolation in t); cfg["progress"](set, intervals done, intervals) as it goes. State error:
           `metrics.bounded_relative_error` of (q, qdot) against the data per time; S_rollout_gmean_err
           is its geometric mean over time (`geometric_mean_over_time`), averaged over trajectories;
           S_rollout_final_err the mean final-time error (a diverged rollout counts 1). S_n_diverged of
           S_n_trajectories rollouts diverged: their state error normalised by the set's spread turned
           non-finite or exceeded `evaluation.diverged.DIVERGED` (rollouts.csv: diverged).
           S_vpt_s (S_vpt_nmse_s): the median over trajectories of the time from its start until the error
           normalised by the set's spread first exceeds normalised RMSE 0.4 (MSE 0.025), `valid_time`.
energy     (no torques) the model's own energy along its rollout (`Fitted.energy`): S_learned_energy_drift
           = mean over trajectories of max_t |E(t) - E(0)| / scale, scale = the mean learned kinetic energy
           E(q, qdot) - E(q, 0) over S's states (energy offsets cancel). With a system: its energy along the
           rollout against along the data (or the user's energy function's), `metrics.energy_errors` with scale = its mean kinetic
           energy over S: S_energy_err_final, S_energy_err_max, ...
dissipation (spec.dissipation) dissipation_b<k>, the learned Rayleigh coefficients; an LNN's or a DeLaN's with a
           system, and a DeLaN's fitted to torques, S_dissipation_coefficient_<k> in the system's units where the
           checks of `replication.fit.dissipation` read it (on the set's rollouts where it has them).
DeLaN      M, c, g on S's states; with a system, S_{mass_matrix,coriolis,gravity}_rel_err = mean over states
           of |pred - true| / |true| (Frobenius / Euclidean), and S_mass_matrix_min_eig. Trained on
           accelerations, a Lagrangian is fixed only up to a constant factor: the terms are then compared at
           the least-squares factor over all three, recorded as S_decomposition_scale.
Tables: one_step.csv, rollouts.csv (set, traj, ...), timeseries.csv (set, traj, t, quantity, value);
arrays.npz: parity data (target, pred) and the first test trajectories (t, q_true, q_pred; M/c/g pairs).
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from lagbench.files import user_data
from lagbench.replication.evaluation.diverged import diverged_trajectories
from lagbench.replication.evaluation.metrics import (
    bounded_relative_error,
    energy_errors,
    geometric_mean_over_time,
    heldout_errors,
    null_errors,
)
from lagbench.replication.evaluation.routines import Evaluation
from lagbench.replication.evaluation.valid_time import VPT_NMSE, VPT_NRMSE, normalised_rmse, valid_time
from lagbench.replication.fit.dissipation import dissipation_metrics
from lagbench.replication.fit.load import Fitted, Padded, load_fitted
from lagbench.replication.fit.rollout_groups import by_time_grid

KEEP = 2000   # rows kept for the parity and decomposition figures


def _quantities(task, dof):
    return {"acceleration": ["qddot"] * dof, "hamiltonian": ["qdot"] * dof + ["qddot"] * dof,
            "inverse_dynamics": ["tau"] * dof}[task]


def _one_step(f: Fitted, r, name, out: Evaluation, rows: list):
    b, pred = f.one_step(r)
    e, null = heldout_errors(pred, b["target"]), null_errors(b["target"])
    out.metrics.update({f"{name}_l1": e["l1"], f"{name}_mse": e["mse"], f"null_{name}_l1": null["l1"],
                        f"null_{name}_mse": null["mse"]})
    err, dev = pred - b["target"], b["target"] - b["target"].mean(0)
    for j, qty in enumerate(_quantities(f.task, f.spec.dof)):
        mae, null_mae = float(np.mean(np.abs(err[:, j]))), float(np.mean(np.abs(dev[:, j])))
        rows.append({"set": name, "quantity": qty, "component": j % f.spec.dof, "mae": mae,
                     "rmse": float(np.sqrt(np.mean(err[:, j] ** 2))), "null_mae": null_mae,
                     "rel_mae": mae / null_mae if null_mae > 0 else float("nan")})
    out.arrays[f"{name}_target"], out.arrays[f"{name}_pred"] = b["target"][:KEEP], pred[:KEEP]


def _forward(f: Fitted, r) -> str | None:
    """Why the model cannot be rolled out on these rows, or None if it can."""
    if f.task == "inverse_dynamics" and f.spec.kind != "delan":
        return "an inverse-dynamics baseline has no forward model"
    if "traj" not in r or "t" not in r:
        return "the rows are state samples, not whole trajectories"
    return None


def energy_function(cfg, dof):
    """E(q, qdot) (arrays (..., dof) -> (...)) from cfg["energy"] ("module:function", imported) or the named
    system's, or None; a ValueError naming --energy if it cannot be imported or does not return one value per
    state."""
    spec = cfg.get("energy")
    if not spec:
        if not cfg.get("system"):
            return None
        from lagbench import systems

        return systems.get(cfg["system"]).energy
    from lagbench.files.user_functions import array_of, call, import_function, wrong

    fn = import_function(spec, "--energy")
    what = f"{getattr(fn, '__name__', 'the function')}(q, qdot)"
    probe = array_of("--energy", spec, what, call("--energy", spec, what, fn, np.zeros((2, dof)), np.zeros((2, dof))))
    if probe.shape != (2,):
        raise wrong("--energy", spec, f"must map q, qdot of shape (N, {dof}) to (N,), gave shape {probe.shape}")

    def energy(q, qdot):
        q, qdot = np.asarray(q), np.asarray(qdot)
        out = call("--energy", spec, what, fn, q.reshape(-1, dof), qdot.reshape(-1, dof))
        return array_of("--energy", spec, what, out).reshape(q.shape[:-1])
    return energy


def _rollouts(f: Fitted, r, name, cfg, out: Evaluation, rows: list, series: list, true_energy):
    d = f.spec.dof
    forced = f.task == "inverse_dynamics"
    groups = by_time_grid(r, cfg.get("horizon"))
    total, done = sum(len(g) - 1 for g in groups), [0]
    progress = cfg.get("progress")

    def advanced(n):
        if progress is not None:
            progress(name, done[0] + n, total)
    errs, finals, drifts, e_sys, vpts, blown = [], [], [], [], [], []
    spread = np.var(np.concatenate([r["q"], r["qdot"]], 1), axis=0)   # the set's, over all its rows
    for k, (tgrid, members) in enumerate(groups.items()):
        t = np.asarray(tgrid)
        z_data = np.stack([np.concatenate([r["q"][i], r["qdot"][i]], 1) for i in members])
        tau = np.stack([r["tau"][i] for i in members]) if forced else None
        z = f.rollout(z_data[:, 0], t, (t[1] - t[0]) / cfg["substeps"], tau, advanced)
        done[0] += t.size - 1
        err = bounded_relative_error(z, z_data)
        errs.append(geometric_mean_over_time(err))
        finals.append(err[:, -1])
        nrmse = normalised_rmse(z, z_data, spread)
        blown.append(diverged_trajectories(nrmse))
        vpts.append([valid_time(nrmse, t - t[0], VPT_NRMSE), valid_time(nrmse, t - t[0], np.sqrt(VPT_NMSE))])
        sub = np.unique(np.linspace(0, t.size - 1, min(t.size, 200)).astype(int))
        for b, i in enumerate(members):
            series.append(pd.DataFrame({"set": name, "traj": r["traj"][i[0]], "t": t[sub], "quantity": "state_err",
                                        "value": err[b, sub]}))
        qp, qdp = z[..., :d], z[..., d:]
        if not forced and f.has_energy:
            drifts.append(_learned_drift(f, r, qp, qdp))
        if true_energy is not None:
            e_sys.append((true_energy(np.nan_to_num(qp), np.nan_to_num(qdp)) * np.where(np.isfinite(qp[..., 0]), 1, np.nan),
                          true_energy(z_data[..., :d], z_data[..., d:]), t, members))
        if k == 0 and name == cfg.get("primary"):
            out.arrays.update(t=t, q_true=z_data[:3, :, :d], q_pred=qp[:3])
    ids = [r["traj"][i[0]] for m in groups.values() for i in m]
    table = pd.DataFrame({"set": name, "traj": ids, "gmean_err": np.concatenate(errs), "final_err": np.concatenate(finals)})
    out.metrics[f"{name}_rollout_gmean_err"] = float(table["gmean_err"].mean())
    out.metrics[f"{name}_rollout_final_err"] = float(table["final_err"].mean())
    table["diverged"] = np.concatenate(blown)
    out.metrics[f"{name}_n_diverged"] = int(table["diverged"].sum())
    out.metrics[f"{name}_n_trajectories"] = len(table)
    table["vpt_s"], table["vpt_nmse_s"] = (np.concatenate([v[j] for v in vpts]) for j in (0, 1))
    out.metrics[f"{name}_vpt_s"] = float(table["vpt_s"].median())
    out.metrics[f"{name}_vpt_nmse_s"] = float(table["vpt_nmse_s"].median())
    if drifts:
        table["learned_energy_drift"] = np.concatenate(drifts)
        out.metrics[f"{name}_learned_energy_drift"] = float(table["learned_energy_drift"].mean())
    if e_sys:
        _true_energy(true_energy, r, name, e_sys, table, out, series)
    rows.append(table)


def _learned_drift(f: Fitted, r, qp, qdp):
    energy = f.energy
    kinetic = energy(r["q"], r["qdot"]) - energy(r["q"], np.zeros_like(r["qdot"]))
    scale = float(np.mean(np.abs(kinetic)))
    ok = np.isfinite(qp).all(axis=(1, 2))
    e = np.full(qp.shape[:2], np.nan)
    if ok.any():
        e[ok] = energy(qp[ok].reshape(-1, qp.shape[-1]), qdp[ok].reshape(-1, qp.shape[-1])).reshape(int(ok.sum()), -1)
    with np.errstate(invalid="ignore", divide="ignore"):
        drift = np.max(np.abs(e - e[:, :1]), axis=1) / scale
    return np.where(ok, drift, np.inf)


def _true_energy(energy, r, name, e_sys, table, out, series):
    kinetic = energy(r["q"], r["qdot"]) - energy(r["q"], np.zeros_like(r["qdot"]))
    scale = float(np.mean(np.abs(kinetic)))
    finals, maxes = [], []
    for e_pred, e_true, t, members in e_sys:
        sub = np.unique(np.linspace(0, t.size - 1, min(t.size, 200)).astype(int))
        for b, i in enumerate(members):
            one = energy_errors(e_pred[b:b + 1], e_true[b:b + 1], scale)
            finals.append(one["energy_err_final"])
            maxes.append(one["energy_err_max"])
            series.append(pd.DataFrame({"set": name, "traj": r["traj"][i[0]], "t": t[sub], "quantity": "energy_err",
                                        "value": (e_pred[b, sub] - e_true[b, sub]) / scale}))
    table["energy_err_final"], table["energy_err_max"] = finals, maxes
    out.metrics.update({f"{name}_energy_err_final": float(np.mean(finals)),
                        f"{name}_energy_err_max": float(np.mean(maxes)),
                        f"{name}_energy_err_final_median": float(np.median(finals)),
                        f"{name}_energy_scale": scale})


def _decomposition(f: Fitted, r, name, system, out: Evaluation):
    q, qd = r["q"][:KEEP], r["qdot"][:KEEP]
    m = f.model
    pred = {"M": m.mass_matrix(q), "c": m.coriolis(q, qd), "g": m.gravity(q)}
    out.metrics[f"{name}_mass_matrix_min_eig"] = float(np.min(np.linalg.eigvalsh(pred["M"])))
    if system is None:
        return
    true = {"M": system.mass_matrix(q), "c": system.coriolis(q, qd), "g": system.gravity(q)}
    if f.task != "inverse_dynamics":  # accelerations fix L only up to a factor: compare at the best one
        a = np.concatenate([pred[k].ravel() for k in pred])
        scale = float(a @ np.concatenate([true[k].ravel() for k in pred]) / (a @ a))
        pred = {k: scale * v for k, v in pred.items()}
        out.metrics[f"{name}_decomposition_scale"] = scale
    for k, label in (("M", "mass_matrix"), ("c", "coriolis"), ("g", "gravity")):
        axes = (1, 2) if k == "M" else (1,)
        num = np.sqrt(np.sum((pred[k] - true[k]) ** 2, axis=axes))
        den = np.sqrt(np.sum(true[k] ** 2, axis=axes))
        with np.errstate(invalid="ignore", divide="ignore"):
            out.metrics[f"{name}_{label}_rel_err"] = float(np.mean(num[den > 0] / den[den > 0])) if (den > 0).any() else float("nan")
        if name == out.counters.get("primary"):
            out.arrays[f"{k}_true"], out.arrays[f"{k}_pred"] = true[k], pred[k]


def eval_fit(ctx) -> Evaluation:
    from lagbench import systems

    cfg = ctx.cfg
    if ctx.model is not None:
        f = Fitted(ctx.spec, ctx.protocol, ctx.framework, cfg.get("model") or "this fit", {}, Padded(ctx.model),
                   ctx.params)
    else:
        f = load_fitted(cfg["model"], ctx.framework)
    system = systems.get(cfg["system"]) if cfg.get("system") else None
    if system is not None and system.dof != f.spec.dof:
        raise ValueError(f"--system {cfg['system']}: has {system.dof} degrees of freedom, the model {f.spec.dof}")
    true_energy = energy_function(cfg, f.spec.dof)
    sets = {}
    if cfg.get("heldout"):
        sets["heldout"] = user_data.rows(ctx.protocol.data.recipe, "heldout")
    if cfg.get("test"):
        sets["test"] = user_data.rows(cfg["test"], "test")
    sets = {k: v for k, v in sets.items() if len(v["q"])}
    out = Evaluation()
    cfg = {**cfg, "primary": "test" if "test" in sets else "heldout", "progress": ctx.progress}
    out.counters["primary"] = cfg["primary"]
    one, roll, series = [], [], []
    for name, r in sets.items():
        if f.task == "inverse_dynamics" and "tau" not in r:
            raise ValueError(f"the {name} rows have no tau, but this {f.spec.kind} predicts torques")
        _one_step(f, r, name, out, one)
        why = _forward(f, r)
        if why is None:
            _rollouts(f, r, name, cfg, out, roll, series, true_energy)
        else:
            out.counters[f"{name}_rollouts"] = f"not run: {why}"
        if f.spec.kind == "delan":
            _decomposition(f, r, name, system, out)
        if f.spec.dissipation:   # its friction checked on the rollouts where the set has them
            rolled = {"horizon": cfg.get("horizon"), "substeps": cfg["substeps"]}
            dissipation_metrics(f, r, name, system, out, rolled if why is None and f.task != "inverse_dynamics" else None)
    if one:
        out.tables["one_step.csv"] = pd.DataFrame(one)
    if roll:
        out.tables["rollouts.csv"] = pd.concat(roll, ignore_index=True)
    if series:
        out.tables["timeseries.csv"] = pd.concat(series, ignore_index=True)
    return out
