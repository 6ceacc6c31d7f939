"""The prediction and the loss, written once for both frameworks.

The functions use only operations that JAX arrays and PyTorch tensors share (`.sum(-1)`, `.mean()`,
`clip`, `.shape`, slicing, arithmetic), plus a `cat(list, axis)` function the caller passes in, so the JAX
and the PyTorch training loops evaluate literally the same expression. The trajectory loss's RK4 step is
the evaluation's own (`replication.evaluation.rollout.rk4_step`, plain arithmetic).
"""
from __future__ import annotations

from lagbench.replication.evaluation.rollout import rk4_step


def predict(model, kind: str, task: str, batch: dict, cat, trajectory_loss=None, filter_loss=None):
    """The model's prediction of batch["target"].

    acceleration:     q-double-dot from (q, qdot[, extra]); DeLaN's forward model takes extra = tau.
    hamiltonian:      concat(dH/dy, -dH/dx) from (x, y[, extra]) = (q, p) or (q, qdot).
    inverse_dynamics: tau from (q, qdot, qddot = extra): DeLaN's inverse model, or a feed-forward
                      baseline given qddot as its extra input.
    With a `TrajectoryLoss` (the protocol's `trajectory_loss`; a batch of windows): `positions`.
    With a `FilterLoss` (the protocol's `filter_loss`; a batch of rows with their neighbours): `filtered`.
    """
    if trajectory_loss is not None:
        return positions(model, task, batch, trajectory_loss.substeps, cat)
    if filter_loss is not None:
        return filtered(model, batch, filter_loss.kernel, cat)
    q, qdot, extra = batch["q"], batch["qdot"], batch.get("extra")
    if task == "acceleration":
        return model.acceleration(q, qdot, extra)
    if task == "hamiltonian":
        xdot, ydot = model.time_derivative(q, qdot, extra)
        return cat([xdot, ydot], -1)
    if task == "inverse_dynamics":
        if kind == "delan":
            return model.inverse_dynamics(q, qdot, extra)
        return model.acceleration(q, qdot, extra)
    raise ValueError(f"unknown task {task!r}")


def positions(model, task: str, batch: dict, substeps: int, cat):
    """The model's motion over each window of a batch of windows (`replication.fit.windows`), as the window's
    target holds the recorded one: (B, K*dof), frame k's displacement (q(t0 + k h) - q0) times the window's
    scale in columns (k - 1)*dof .. k*dof - 1, for k = 1..K.

    batch: q, qdot (B, dof) the start state (q recorded, qdot estimated), extra (optional), h (B, 1) the frame
    step, scale (B, 1) or (B, dof), target (B, K*dof) (its width gives K); stacked members add a leading axis.
    The state (d, v) = (q - q0, qdot) starts at (0, qdot) and takes `substeps` RK4 steps of h / substeps a
    frame under the model's own vector field: (v, model.acceleration(q0 + d, v, extra)) for the acceleration
    task (the call the one-step loss makes, so dissipation and periodic inputs included), the model's
    time_derivative of (q0 + d, v) for the hamiltonian task. Displacements rather than positions keep float32
    rounding at the scale of the motion within a window, not of q itself."""
    q0, extra, h = batch["q"], batch.get("extra"), batch["h"]
    dof = q0.shape[-1]

    def field(z):
        d, v = z[..., :dof], z[..., dof:]
        if task == "hamiltonian":
            return cat(list(model.time_derivative(q0 + d, v, extra)), -1)
        return cat([v, model.acceleration(q0 + d, v, extra)], -1)

    z, dt, out = cat([0.0 * q0, batch["qdot"]], -1), h / substeps, []
    for _ in range(batch["target"].shape[-1] // dof):
        for _ in range(substeps):
            z = rk4_step(field, z, dt)
        out.append(z[..., :dof] * batch["scale"])
    return cat(out, -1)


def filtered(model, batch: dict, kernel, cat):
    """The model's q-double-dot seen through the derivative filter (`FilterLoss`), as the estimate in the
    batch's target is: (B, dof), sum over taps j of kernel[j] x the model's q-double-dot at frame j.

    batch: q_taps, qdot_taps (B, T*dof), the T = len(kernel) frames about each row (q recorded, qdot
    estimated), frame after frame (`replication.fit.filter_rows`); stacked members add a leading axis. The
    T frames go through the model as one batch of T*B rows (frame-major), so a step makes one call."""
    dof = batch["q_taps"].shape[-1] // len(kernel)
    n = batch["q_taps"].shape[-2]

    def frames(x):
        return cat([x[..., j * dof:(j + 1) * dof] for j in range(len(kernel))], -2)

    a = model.acceleration(frames(batch["q_taps"]), frames(batch["qdot_taps"]), None)
    out = 0.0
    for j, c in enumerate(kernel):
        out = out + c * a[..., j * n:(j + 1) * n, :]
    return out


def loss_value(pred, target, weight, loss: str, axis=None):
    """Per-sample error summed over components, then averaged over the batch (axis None: over every sample;
    axis=-1 with stacked members' (K, B, ...) arrays: per member, (K,)).

    "l1"/"l1_gamma": sum |err|; "mse": sum err^2. With a weight: sum(w * e) / sum(w).
    |err| is written max(err, 0) - min(err, 0) (`clip`, a method of both array types): the same values as
    abs, and a derivative of 0 at err == 0 in both frameworks, where JAX's abs has 1 and PyTorch's 0 (an
    exact fit of one sample gave the frameworks different gradients in float64).
    """
    err = pred - target
    per = (err * err).sum(-1) if loss == "mse" else (err.clip(min=0) - err.clip(max=0)).sum(-1)
    if weight is None:
        return per.mean(axis)
    return (per * weight).sum(axis) / weight.sum(axis)
