"""Shared by the loss-part tests (`test_trajectory_loss.py`, `test_filter_loss.py`): one protocol's loss and
gradient on one set of weights in each framework, and an exact model."""
import equinox as eqx
import jax.numpy as jnp
import torch

import lagbench.models.jax
import lagbench.models.torch
from lagbench.replication.training import train_jax, train_torch


def jax_loss(spec, params, protocol, batch):
    """(loss, {name: gradient}) of the JAX training loss."""
    loss, grads = eqx.filter_value_and_grad(train_jax.make_loss(spec, protocol))(
        lagbench.models.jax.build(spec, params), {k: jnp.asarray(v) for k, v in batch.items()})
    return float(loss), lagbench.models.jax.to_params(grads)


def torch_loss(spec, params, protocol, batch):
    """(loss, {name: gradient}) of the PyTorch training loss."""
    model = lagbench.models.torch.build(spec, params)
    loss = train_torch.make_loss(spec, protocol)(model, {k: torch.as_tensor(v) for k, v in batch.items()})
    loss.backward()
    return float(loss.detach()), {k: p.grad.numpy() for k, p in model.named_parameters()}


class Exact:
    """A system's true q-double-dot, as a model (NumPy arrays in and out)."""

    def __init__(self, system):
        self.s = system

    def acceleration(self, q, qdot, extra=None):
        return self.s.acceleration(q, qdot, backend="numpy")
