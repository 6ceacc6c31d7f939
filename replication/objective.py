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


def loss_value(pred, target, weight, loss: str):
    """Per-sample error summed over components, then averaged over the batch.

    "l1"/"l1_gamma": sum |err|; "mse": sum err^2. With a weight: sum(w * e) / sum(w).
    """
    err = pred - target
    per = (err * err).sum(-1) if loss == "mse" else abs(err).sum(-1)
    if weight is None:
        return per.mean()
    return (per * weight).sum() / weight.sum()
