"""`heldout_trajectories`: the held-out evaluation plus short rollouts of the model against the truth, for
a figure of trajectories (the LNN paper's Fig. 3: the relativistic particle over t in [0, 1], 50 points).

The initial states (and any per-sample system input, e.g. the relativistic field g) are drawn from the
system's declared distribution with the rollout seed of the unit's split. A per-sample input rides in
the integrated state with rate 0, so the suite's RK4 (`replication.evaluation.rollout`) keeps it with its
trajectory. Model and truth are integrated by the same RK4 (the truth at the exact equations of motion,
at step `dt`); a model on (q, qdot) by its q-double-dot as the verdict reads it (`qddot_of_prediction`),
an HNN on canonical (q, p) in (q, p) by its own H from the true initial momentum, its velocity the true
system's at each predicted state (q, p) (`replication.evaluation.canonical.state_velocity`). Adds `arrays.npz`: t, q_true, qdot_true, q_pred, qdot_pred
(n_ics, n_t, d); nothing a verdict reads.
"""
from __future__ import annotations

import numpy as np

from lagbench.replication.evaluation.canonical import canonical_rollout, state_velocity
from lagbench.replication.evaluation.rollout import rollout
from lagbench.replication.evaluation.routines import Evaluation, eval_heldout, qddot_of_prediction, system_of
from lagbench.replication.training import data as datamod
from lagbench.replication.training.objective import predict


def _states(ctx, s):
    cfg = ctx.cfg
    rng = np.random.default_rng(cfg.get("ic_seed", 0) + ctx.split.draw_offset)
    st = s.sample_states(cfg["n_ics"], rng)
    names = datamod.sample_inputs(st, ctx.protocol.data.system_params)
    return st["q"], st["qdot"], names, [np.asarray(st[k], float).reshape(len(st["q"]), -1) for k in names]


def admitted(s, accel):
    """`accel` on the rows the system admits (|qdot| below its speed limit, if it has one); NaN on the
    others, so a rollout that leaves the system's domain is marked diverged rather than raising."""
    c = s.definition.max_speed

    def f(q, qdot, inputs):
        out = np.full_like(q, np.nan)
        ok = np.all(np.abs(qdot) < c, axis=1) if c is not None else np.ones(len(q), bool)
        if ok.any():
            out[ok] = accel(q[ok], qdot[ok], inputs[ok])
        return out
    return f


def model_qddot(ctx, s, names):
    """accel(q, qdot, inputs) -> the trained model's q-double-dot, inputs (B, len(names)) the per-sample
    system inputs in `names` order (the order of the training data's extra inputs)."""
    p = ctx.protocol

    def accel(q, qdot, inputs):
        kw = {k: inputs[:, i] for i, k in enumerate(names)}
        # the true q-double-dot is a placeholder: no target is read
        batch = datamod._with_coords(s, {"q": q, "qdot": qdot, **kw}, p, np.zeros_like(q),
                                     extra=inputs if names else None)
        return qddot_of_prediction(p, batch, predict(ctx.model, ctx.spec.kind, p.task, batch, np.concatenate))
    return admitted(s, accel)


def _field(accel, d, n_in):
    def f(z):
        q, qdot, inputs = z[:, :d], z[:, d:2 * d], z[:, 2 * d:]
        return np.concatenate([qdot, accel(q, qdot, inputs), np.zeros((len(z), n_in))], 1)
    return f


def eval_heldout_trajectories(ctx) -> Evaluation:
    out = eval_heldout(ctx)
    cfg, s = ctx.cfg, system_of(ctx.protocol)
    q0, qd0, names, inputs = _states(ctx, s)
    d, n_in = q0.shape[1], len(names)
    z0 = np.concatenate([q0, qd0, *inputs], 1)
    t = np.linspace(0.0, cfg["t_end"], cfg["n_t"])

    def truth(q, qdot, inp):
        return s.acceleration(q, qdot, backend="numpy", **{k: inp[:, i] for i, k in enumerate(names)})
    with np.errstate(all="ignore"):
        zt = rollout(_field(admitted(s, truth), d, n_in), z0, t, cfg["dt"])
        q, qdot = _model_rollout(ctx, s, q0, qd0, names, inputs, t)
    out.arrays = {"t": t, "q_true": zt[..., :d], "qdot_true": zt[..., d:2 * d], "q_pred": q, "qdot_pred": qdot}
    return out


def _model_rollout(ctx, s, q0, qd0, names, inputs, t):
    """(q, qdot) (n_ics, n_t, d) of the trained model from (q0, qd0) and the per-sample system inputs."""
    p, d = ctx.protocol, q0.shape[1]
    if p.task == "hamiltonian" and p.data.coords == "qp":   # in (q, p) by its own H; the true velocity there
        kw = {k: inputs[i][:, 0] for i, k in enumerate(names)}
        q, pp = canonical_rollout(ctx.model.time_derivative, s, q0, qd0, t, ctx.cfg["dt"],
                                     extra=np.concatenate(inputs, 1) if names else None, momentum_kw=kw)
        return q, state_velocity(s, q, pp, kw)
    z0 = np.concatenate([q0, qd0, *inputs], 1)
    zp = rollout(_field(model_qddot(ctx, s, names), d, len(names)), z0, t, ctx.cfg["dt"])
    return zp[..., :d], zp[..., d:2 * d]
