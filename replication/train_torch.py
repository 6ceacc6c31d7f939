"""The PyTorch training loop (torch.optim.Adam). Mirrors `train_jax.py` line for line.

`train(spec, params, protocol, seed, stream, on_log=None) -> TrainOutcome`: the same steps, the same
learning rate per step (set on the optimiser before each step), the same logging, and the same
stop at the first non-finite loss or gradient (checked before the update is applied), and the same
velocity-Hessian probe at logged steps.
"""
from __future__ import annotations

import time

import torch

import models.torch
from replication import hessian_probe
from replication.objective import loss_value, predict
from replication.outcome import TrainOutcome, nonfinite_failure
from replication.schedules import learning_rate
from replication.spike_guard import SpikeGuard


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


def train(spec, params, protocol, stream, on_log=None) -> TrainOutcome:
    dtype = getattr(torch, protocol.dtype)
    model = models.torch.build(spec, params)
    loss_fn = make_loss(spec, protocol)
    look = make_probe(spec, protocol)
    opt = torch.optim.Adam(model.parameters(), lr=protocol.lr, betas=(protocol.b1, protocol.b2),
                           eps=protocol.eps, weight_decay=0.0, foreach=False)
    guard = SpikeGuard(protocol)
    log, failure, t0, t_probe = [], None, time.perf_counter(), 0.0
    for k in range(protocol.steps):
        lr = learning_rate(protocol, k)
        batch = _to_torch(stream.batch(k), dtype)
        for group in opt.param_groups:
            group["lr"] = lr
        opt.zero_grad(set_to_none=True)
        loss = loss_fn(model, batch)
        loss.backward()
        bound = guard.threshold(protocol.dtype)
        grads = [p.grad for p in model.parameters() if p.grad is not None]
        gnorm_t = torch.sqrt(sum((g * g).sum() for g in grads))
        gnorm, loss = float(gnorm_t), float(loss.detach())
        if guard.fails(loss, gnorm):
            failure = nonfinite_failure(k, loss, gnorm)
            break
        if guard.record(gnorm, bound):
            if guard.clip_scale(gnorm) != 1.0:
                for g in grads:
                    g.mul_(guard.clip / gnorm_t)
            opt.step()
        if k % protocol.log_every == 0 or k == protocol.steps - 1:
            row = {"step": k, "loss": loss, "grad_norm": gnorm, "lr": lr,
                   "wall_s": time.perf_counter() - t0 - t_probe}
            if guard.active:
                row["skipped_steps"] = guard.skipped
            if look is not None:
                tp = time.perf_counter()
                row.update(look(model, batch))
                t_probe += time.perf_counter() - tp
            log.append(row)
            if on_log:
                on_log(row)
    wall = time.perf_counter() - t0 - t_probe
    return TrainOutcome(params=models.torch.to_params(model), log=log, failure=failure, train_time_s=wall,
                        steps_done=k + 1 if failure is None else k, batch=protocol.batch)
