"""The JAX training loop (equinox + optax). Mirrors `train_torch.py` line for line.

`train(spec, params, protocol, seed, stream, on_log=None) -> TrainOutcome` runs `protocol.steps`
Adam steps (optax.scale_by_adam, scaled by the learning rate the neutral schedule gives for the
step; optionally clipped and spike-skipped, `replication.spike_guard`), records loss and global
gradient norm every `log_every` steps (and at step 0 and the last; for LNN/LGN also the
velocity-Hessian health of `replication.hessian_probe`, timed apart), and stops at the first
non-finite loss or gradient (a non-finite gradient is skipped instead while the spike guard skips),
keeping the parameters from before that step.
"""
from __future__ import annotations

import time

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optax

import models.jax
from replication import hessian_probe
from replication.objective import loss_value, predict
from replication.outcome import TrainOutcome, nonfinite_failure
from replication.schedules import learning_rate
from replication.spike_guard import SpikeGuard


def _to_jax(batch: dict, dtype) -> dict:
    return {k: jnp.asarray(v, dtype=dtype) for k, v in batch.items()}


def make_loss(spec, protocol):
    def loss_fn(model, batch):
        pred = predict(model, spec.kind, protocol.task, batch, jnp.concatenate)
        loss = loss_value(pred, batch["target"], batch.get("weight"), protocol.loss)
        if protocol.l2:
            leaves = jax.tree_util.tree_leaves(eqx.filter(model, eqx.is_inexact_array))
            loss = loss + protocol.l2 * sum(jnp.sum(p * p) for p in leaves)
        return loss
    return loss_fn


def make_step(spec, protocol):
    """(optax transform, step). step(model, opt_state, batch, lr, skip_above=inf) -> (model, opt_state, loss,
    gnorm): one Adam step on the gradient clipped to protocol.grad_clip (if set); not taken (model and state
    returned unchanged) when gnorm >= skip_above (`replication.spike_guard`)."""
    loss_fn = make_loss(spec, protocol)
    opt = optax.scale_by_adam(b1=protocol.b1, b2=protocol.b2, eps=protocol.eps)
    clip = protocol.grad_clip

    @eqx.filter_jit
    def step(model, opt_state, batch, lr, skip_above=jnp.inf):
        loss, grads = eqx.filter_value_and_grad(loss_fn)(model, batch)
        gnorm = optax.global_norm(grads)
        if clip > 0:
            scale = jnp.where(gnorm > clip, clip / gnorm, 1.0)
            grads = jax.tree_util.tree_map(lambda g: g * scale.astype(g.dtype), grads)
        updates, new_state = opt.update(grads, opt_state)
        take = gnorm < skip_above
        updates = jax.tree_util.tree_map(lambda u: jnp.where(take, -lr * u, jnp.zeros_like(u)), updates)
        new_state = jax.tree_util.tree_map(lambda a, b: jnp.where(take, a, b), new_state, opt_state)
        return eqx.apply_updates(model, updates), new_state, loss, gnorm

    return opt, step


def make_probe(spec, protocol):
    """batch -> the `hessian_probe` columns (None for models without a velocity Hessian)."""
    if not hessian_probe.wanted(spec, protocol):
        return None

    @eqx.filter_jit
    def look(model, batch):
        q, qdot, extra = batch["q"], batch["qdot"], batch.get("extra")
        hess = model.velocity_hessian(q, qdot, extra) if hasattr(model, "velocity_hessian") else None
        return (*model.acceleration_info(q, qdot, extra), hess)

    def run(model, batch):
        qdd, n_fb, hess = look(model, batch)
        return hessian_probe.probe(np.asarray(qdd), int(n_fb), None if hess is None else np.asarray(hess),
                                   protocol.dtype)
    return run


def train(spec, params, protocol, stream, on_log=None) -> TrainOutcome:
    dtype = jnp.dtype(protocol.dtype)
    model = models.jax.build(spec, params)
    opt, step = make_step(spec, protocol)
    look = make_probe(spec, protocol)
    opt_state = opt.init(eqx.filter(model, eqx.is_inexact_array))
    guard = SpikeGuard(protocol)
    log, failure, t0, t_probe = [], None, time.perf_counter(), 0.0
    for k in range(protocol.steps):
        lr = learning_rate(protocol, k)
        batch = _to_jax(stream.batch(k), dtype)
        bound = guard.threshold(protocol.dtype)
        new_model, new_state, loss, gnorm = step(model, opt_state, batch, jnp.asarray(lr, dtype),
                                                 jnp.asarray(bound, dtype))
        loss, gnorm = float(loss), float(gnorm)
        if guard.fails(loss, gnorm):
            failure = nonfinite_failure(k, loss, gnorm)
            break
        guard.record(gnorm, bound)
        model, opt_state = new_model, new_state
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
    return TrainOutcome(params=models.jax.to_params(model), log=log, failure=failure, train_time_s=wall,
                        steps_done=k + 1 if failure is None else k, batch=protocol.batch)
