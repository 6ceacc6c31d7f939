"""The PyTorch optimiser step (torch.optim.Adam) for the one training loop `replication.loop`. Mirrors
`train_jax.py` line for line.

`Stepper(spec, params, protocol)`: the gradient and its global norm in `propose` (the learning rate set on
the optimiser there); in `commit`, if the spike guard takes the step, the gradient scaled by the clip
factor and one Adam step. `train(spec, params, protocol, stream, on_log=None, hooks=()) -> TrainOutcome`:
`replication.loop.train` with this stepper.
"""
from __future__ import annotations

import torch

import models.torch
from replication import hessian_probe, loop
from replication.objective import loss_value, predict
from replication.outcome import TrainOutcome


def _to_torch(batch: dict, dtype) -> dict:
    return {k: torch.as_tensor(v, dtype=dtype) for k, v in batch.items()}


def make_loss(spec, protocol):
    def loss_fn(model, batch):
        pred = predict(model, spec.kind, protocol.task, batch, torch.cat)
        loss = loss_value(pred, batch["target"], batch.get("weight"), protocol.loss)
        if protocol.l2:
            loss = loss + protocol.l2 * sum((p * p).sum() for p in model.parameters())
        return loss
    return loss_fn


def make_probe(spec, protocol):
    """batch -> the `hessian_probe` columns (None for models without a velocity Hessian)."""
    if not hessian_probe.wanted(spec, protocol):
        return None

    def run(model, batch):
        q, qdot, extra = batch["q"], batch["qdot"], batch.get("extra")
        with torch.no_grad():
            hess = model.velocity_hessian(q, qdot, extra) if hasattr(model, "velocity_hessian") else None
            qdd, n_fb = model.acceleration_info(q, qdot, extra)
        return hessian_probe.probe(qdd.numpy(), int(n_fb), None if hess is None else hess.numpy(),
                                   protocol.dtype)
    return run


class Stepper:
    def __init__(self, spec, params, protocol):
        self.dtype = getattr(torch, protocol.dtype)
        self.model = models.torch.build(spec, params)
        self.loss_fn = make_loss(spec, protocol)
        self.look = make_probe(spec, protocol)
        self.opt = torch.optim.Adam(self.model.parameters(), lr=protocol.lr, betas=(protocol.b1, protocol.b2),
                                    eps=protocol.eps, weight_decay=0.0, foreach=False)
        self.clip_to, self._grads = float(protocol.grad_clip), []

    def propose(self, batch, lr, bound):
        batch = self._batch = _to_torch(batch, self.dtype)
        for group in self.opt.param_groups:
            group["lr"] = lr
        self.opt.zero_grad(set_to_none=True)
        loss = self.loss_fn(self.model, batch)
        loss.backward()
        self._grads = [p.grad for p in self.model.parameters() if p.grad is not None]
        self._gnorm = torch.sqrt(sum((g * g).sum() for g in self._grads))
        return float(loss.detach()), float(self._gnorm)

    def commit(self, taken, scale):
        if not taken:
            return
        if scale != 1.0:   # clip: the norm as a tensor, as the JAX step scales inside its graph
            for g in self._grads:
                g.mul_(self.clip_to / self._gnorm)
        self.opt.step()

    def probe(self):
        return None if self.look is None else self.look(self.model, self._batch)

    def params(self) -> dict:
        return models.torch.to_params(self.model)


def train(spec, params, protocol, stream, on_log=None, hooks=()) -> TrainOutcome:
    return loop.train(Stepper(spec, params, protocol), protocol, stream, on_log, hooks)
