"""The prediction and the loss, written once for both frameworks.

Both functions use only operations that JAX arrays and PyTorch tensors share (`.sum(-1)`,
`.mean()`, `abs`, arithmetic), plus a `cat(list, axis)` function the caller passes in, so the JAX
and the PyTorch training loops evaluate literally the same expression.
"""
from __future__ import annotations


def predict(model, kind: str, task: str, batch: dict, cat):
    """The model's prediction of batch["target"].

    acceleration:     q-double-dot from (q, qdot[, extra]); DeLaN's forward model takes extra = tau.
    hamiltonian:      concat(dH/dy, -dH/dx) from (x, y[, extra]) = (q, p) or (q, qdot).
    inverse_dynamics: tau from (q, qdot, qddot = extra): DeLaN's inverse model, or a feed-forward
                      baseline given qddot as its extra input.
    """
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
