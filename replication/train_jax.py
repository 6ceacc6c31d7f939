"""The JAX training loop (equinox + optax). Mirrors `train_torch.py` line for line.

`train(spec, params, protocol, seed, stream, on_log=None) -> TrainOutcome` runs `protocol.steps`
Adam steps (optax.scale_by_adam, scaled by the learning rate the neutral schedule gives for the
step), records loss and global gradient norm every `log_every` steps (and at step 0 and the last),
and stops at the first non-finite loss or gradient, keeping the parameters from before that step.
"""
from __future__ import annotations

import time

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optax

import models.jax
from replication.objective import loss_value, predict
from replication.outcome import TrainOutcome, nonfinite_failure
from replication.schedules import learning_rate


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
    loss_fn = make_loss(spec, protocol)
    opt = optax.scale_by_adam(b1=protocol.b1, b2=protocol.b2, eps=protocol.eps)

    @eqx.filter_jit
    def step(model, opt_state, batch, lr):
        loss, grads = eqx.filter_value_and_grad(loss_fn)(model, batch)
        gnorm = optax.global_norm(grads)
        updates, opt_state = opt.update(grads, opt_state)
        updates = jax.tree_util.tree_map(lambda u: -lr * u, updates)
        return eqx.apply_updates(model, updates), opt_state, loss, gnorm

    return opt, step


def train(spec, params, protocol, stream, on_log=None) -> TrainOutcome:
    dtype = jnp.dtype(protocol.dtype)
    model = models.jax.build(spec, params)
    opt, step = make_step(spec, protocol)
    opt_state = opt.init(eqx.filter(model, eqx.is_inexact_array))
    log, failure, t0 = [], None, time.perf_counter()
    for k in range(protocol.steps):
        lr = learning_rate(protocol, k)
        batch = _to_jax(stream.batch(k), dtype)
        new_model, new_state, loss, gnorm = step(model, opt_state, batch, jnp.asarray(lr, dtype))
        loss, gnorm = float(loss), float(gnorm)
        if not (np.isfinite(loss) and np.isfinite(gnorm)):
            failure = nonfinite_failure(k, loss, gnorm)
            break
        model, opt_state = new_model, new_state
        if k % protocol.log_every == 0 or k == protocol.steps - 1:
            row = {"step": k, "loss": loss, "grad_norm": gnorm, "lr": lr, "wall_s": time.perf_counter() - t0}
            log.append(row)
            if on_log:
                on_log(row)
    wall = time.perf_counter() - t0
    return TrainOutcome(params=models.jax.to_params(model), log=log, failure=failure, train_time_s=wall,
                        steps_done=k + 1 if failure is None else k, batch=protocol.batch)
