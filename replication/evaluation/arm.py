"""Two-link-arm evaluation (claim 9): torque error on held-out training-like and unseen trajectories,
per joint, and the decomposition into gravity, Coriolis and inertial torques against the truth.

The decomposition is read from any inverse model the way the DeLaN code did: g = tau(q, 0, 0),
c = tau(q, qdot, 0) - g, M qdd = tau(q, 0, qdd) - g; for DeLaN the mass matrix's smallest eigenvalue
over the test states is also recorded (it must be positive)."""
from __future__ import annotations

import numpy as np

from lagbench.replication.evaluation.metrics import null_errors
from lagbench.replication.evaluation.routines import Evaluation, heldout_of, system_of
from lagbench.replication.training.objective import predict


def _mse(a, b):
    return float(np.mean(np.sum((a - b) ** 2, -1)))


def eval_arm(ctx) -> Evaluation:
    p, m, kind = ctx.protocol, ctx.model, ctx.spec.kind
    out = Evaluation()
    s = system_of(p)
    for fam in ("train", "test"):
        b = heldout_of(ctx, kind=fam)
        tau = predict(m, kind, p.task, b, np.concatenate)
        out.metrics[f"torque_mse_{fam}"] = _mse(tau, b["target"])
        out.metrics[f"null_torque_mse_{fam}"] = null_errors(b["target"])["mse"]
        for j in range(tau.shape[-1]):
            out.metrics[f"torque_mse_{fam}_joint{j}"] = float(np.mean((tau[:, j] - b["target"][:, j]) ** 2))
    q, qd, qdd = b["q"], b["qdot"], b["extra"]
    z = np.zeros_like(q)

    def inv(a, v, acc):
        return predict(m, kind, p.task, {"q": a, "qdot": v, "extra": acc}, np.concatenate)

    g_hat = inv(q, z, z)
    c_hat = inv(q, qd, z) - g_hat
    mq_hat = inv(q, z, qdd) - g_hat
    g_true = s.gravity(q, backend="numpy")
    c_true = s.coriolis(q, qd, backend="numpy")
    mq_true = np.einsum("nij,nj->ni", s.mass_matrix(q, backend="numpy"), qdd)
    out.metrics.update({"gravity_mse": _mse(g_hat, g_true), "coriolis_mse": _mse(c_hat, c_true),
                        "inertial_mse": _mse(mq_hat, mq_true)})
    if kind == "delan":
        M = m.mass_matrix(q)
        out.metrics["mass_matrix_min_eig"] = float(np.min(np.linalg.eigvalsh(0.5 * (M + np.swapaxes(M, -1, -2)))))
    k = min(500, len(q))
    out.arrays = {"tau_true": b["target"][:k], "tau_pred": predict(m, kind, p.task, {x: v[:k] for x, v in b.items()},
                                                                     np.concatenate),
                  "g_true": g_true[:k], "g_pred": g_hat[:k], "c_true": c_true[:k], "c_pred": c_hat[:k],
                  "Mqdd_true": mq_true[:k], "Mqdd_pred": mq_hat[:k]}
    return out
