"""Wave-equation evaluation (claim 4): held-out error on the training grid, transfer to the larger
grid, and a Gaussian-pulse rollout on it (space-time field and energy over time)."""
from __future__ import annotations

import numpy as np
import pandas as pd

from lagbench.replication.evaluation.metrics import (
    bounded_relative_error,
    geometric_mean_over_time,
    heldout_errors,
)
from lagbench.replication.evaluation.rollout import lagrangian_field, rollout
from lagbench.replication.evaluation.routines import Evaluation, eval_heldout, heldout_of, system_of


def eval_wave(ctx) -> Evaluation:
    out = eval_heldout(ctx)
    p, cfg, m = ctx.protocol, ctx.cfg, ctx.model
    n_small = int(dict(p.data.system_params).get("n", 10))
    n_big = int(cfg["n_big"])
    out.metrics["heldout_l1_per_node"] = out.metrics["heldout_l1"] / n_small
    big = p.replace(**{"data.system_params": tuple(sorted({**dict(p.data.system_params), "n": n_big}.items())),
                    "data.n_heldout": min(p.data.n_heldout, 2000)})
    b = heldout_of(ctx, big)
    tl1 = heldout_errors(m.acceleration(b["q"], b["qdot"], None), b["target"])["l1"] / n_big
    out.metrics["transfer_l1_per_node"] = tl1
    out.metrics["transfer_ratio"] = tl1 / out.metrics["heldout_l1_per_node"]
    s = system_of(big)
    x = np.linspace(0.0, 1.0, n_big)
    q0 = np.exp(-((x - 0.5) ** 2) / (2 * 0.05**2))[None]
    qd0 = np.zeros_like(q0)
    t = np.linspace(0.0, cfg["t_end"], cfg["n_t"])
    import lagbench.systems.trajectories as tr

    q, qd = tr.integrate(s, q0, qd0, t)
    z = rollout(lagrangian_field(lambda a, v: m.acceleration(a, v, None), n_big),
                np.concatenate([q0, qd0], 1), t, cfg["dt"])
    qp, qdp = z[..., :n_big], z[..., n_big:]
    E_true, E_pred = s.energy(q, qd, backend="numpy")[0], s.energy(qp, qdp, backend="numpy")[0]
    scale = abs(E_true[0])
    finite = bool(np.all(np.isfinite(E_pred)))   # a diverged rollout's drift is +inf, never NaN
    out.metrics["energy_err_max"] = float(np.max(np.abs(E_pred - E_pred[0])) / scale) if finite else np.inf
    out.metrics["energy_err_vs_truth_max"] = float(np.max(np.abs(E_pred - E_true)) / scale) if finite else np.inf
    out.metrics["n_diverged"] = int(not finite)
    out.metrics["truth_energy_drift_max"] = float(np.max(np.abs(E_true - E_true[0])) / scale)
    err = bounded_relative_error(np.concatenate([qp, qdp], -1), np.concatenate([q, qd], -1))
    out.metrics["rollout_gmean_err"] = float(geometric_mean_over_time(err)[0])
    # the null rollout: a model that predicts nothing keeps the pulse where it started
    still = np.broadcast_to(np.concatenate([q0, qd0], -1)[:, None], (1, t.size, 2 * n_big))
    out.metrics["null_rollout_gmean_err"] = float(geometric_mean_over_time(
        bounded_relative_error(still, np.concatenate([q, qd], -1)))[0])
    idx = np.unique(np.linspace(0, t.size - 1, min(t.size, 300)).astype(int))
    out.tables["timeseries.csv"] = pd.concat([
        pd.DataFrame({"traj": 0, "t": t[idx], "quantity": "energy_true", "value": E_true[idx]}),
        pd.DataFrame({"traj": 0, "t": t[idx], "quantity": "energy_pred", "value": E_pred[idx]}),
        pd.DataFrame({"traj": 0, "t": t[idx], "quantity": "state_err", "value": err[0, idx]})], ignore_index=True)
    out.arrays = {"x": x, "t": t[idx], "field_true": q[0, idx], "field_pred": qp[0, idx]}
    return out
