"""The JAX optimiser step (equinox + optax) for the one training loop `replication.training.loop`. Mirrors
`train_torch.py` line for line.

`Stepper(spec, params, protocol, step=None)`: an Adam step (optax.scale_by_adam, scaled by the learning
rate the loop passes; clipped to the guard's clip (`protocol.grad_clip`) and skipped above the spike guard's bound inside the
compiled step, `replication.training.spike_guard`); `step` reuses the (optax transform, compiled step) pair of
`make_step` across models of one protocol, so that scouts compile once. `train(spec, params, protocol,
stream, on_log=None, hooks=(), snapshot=None, start_state=None) -> TrainOutcome`: `replication.training.loop.train`
with this stepper. Both steppers give their model and Adam state as arrays for snapshots (`state_arrays`).

`Members(spec, params_list, protocol, step=None)`: K models of one spec trained as one program (the
stepper of `replication.training.loop.train_members`): the parameters and Adam states stacked along a leading axis
and the same compiled step `eqx.filter_vmap`-ed over them and over the K batches (`make_members_step`);
each member's numbers are those of its own `Stepper` run (`tests/replication/training/test_members_parity.py`).
`train_members(spec, params_list, protocol, streams, on_log=None, hooks=(), snapshot=None) -> [TrainOutcome]`.
"""
from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optax

import lagbench.models.jax
from lagbench.replication.training import hessian_probe, loop
from lagbench.replication.training.objective import loss_value, predict
from lagbench.replication.training.outcome import TrainOutcome


def _to_jax(batch: dict, dtype) -> dict:
    return {k: jnp.asarray(v, dtype=dtype) for k, v in batch.items()}


def make_loss(spec, protocol):
    def loss_fn(model, batch):
        pred = predict(model, spec.kind, protocol.task, batch, jnp.concatenate, protocol.trajectory_loss,
                       protocol.filter_loss)
        loss = loss_value(pred, batch["target"], batch.get("weight"), protocol.loss)
        if protocol.l2:
            leaves = jax.tree_util.tree_leaves(eqx.filter(model, eqx.is_inexact_array))
            loss = loss + protocol.l2 * sum(jnp.sum(p * p) for p in leaves)
        return loss
    return loss_fn


def _compiled_per_objective(make):
    """`make(spec, protocol)` memoised on what the compiled function depends on: the spec and the
    protocol's objective and optimiser fields (`Protocol.objective_key`). A process that trains or probes
    several models of one spec (seeds, cohorts, claims sharing a model) compiles once, not once per model:
    equinox keeps the compiled program per function object, so a new closure would compile again."""
    memo: dict = {}

    def cached(spec, protocol):
        key = (spec, protocol.objective_key())
        if key not in memo:
            memo[key] = make(spec, protocol)
        return memo[key]
    cached.__doc__, cached.__name__ = make.__doc__, make.__name__
    return cached


@_compiled_per_objective
def make_step(spec, protocol):
    """(optax transform, step). step(model, opt_state, batch, lr, skip_above=inf) -> (model, opt_state, loss,
    gnorm): one Adam step on the gradient clipped to protocol.grad_clip (unless None); not taken (model and state
    returned unchanged) when gnorm >= skip_above (`replication.training.spike_guard`)."""
    loss_fn = make_loss(spec, protocol)
    opt = optax.scale_by_adam(b1=protocol.optimiser.b1, b2=protocol.optimiser.b2, eps=protocol.optimiser.eps)
    clip = protocol.grad_clip

    @eqx.filter_jit
    def step(model, opt_state, batch, lr, skip_above=jnp.inf):
        loss, grads = eqx.filter_value_and_grad(loss_fn)(model, batch)
        gnorm = optax.tree.norm(grads)
        if clip is not None:
            scale = jnp.where(gnorm > clip, clip / gnorm, 1.0)
            grads = jax.tree_util.tree_map(lambda g: g * scale.astype(g.dtype), grads)
        updates, new_state = opt.update(grads, opt_state)
        take = gnorm < skip_above
        updates = jax.tree_util.tree_map(lambda u: jnp.where(take, -lr * u, jnp.zeros_like(u)), updates)
        new_state = jax.tree_util.tree_map(lambda a, b: jnp.where(take, a, b), new_state, opt_state)
        return eqx.apply_updates(model, updates), new_state, loss, gnorm

    return opt, step


@_compiled_per_objective
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


def _state_arrays(stepper) -> list[np.ndarray]:
    """The arrays of a stepper's model and Adam state, in pytree order (`loop`'s snapshots)."""
    return [np.asarray(a) for a in jax.tree_util.tree_leaves((eqx.filter(stepper.model, eqx.is_array),
                                                              stepper.opt_state))]


def _load_state_arrays(stepper, arrays) -> None:
    leaves, treedef = jax.tree_util.tree_flatten((eqx.filter(stepper.model, eqx.is_array), stepper.opt_state))
    if [np.shape(a) for a in arrays] != [a.shape for a in leaves]:
        raise ValueError("a training snapshot's arrays do not fit this model and optimiser")
    model, stepper.opt_state = jax.tree_util.tree_unflatten(
        treedef, [jnp.asarray(a, dtype=leaf.dtype) for a, leaf in zip(arrays, leaves, strict=True)])
    stepper.model = eqx.combine(model, eqx.filter(stepper.model, eqx.is_array, inverse=True))


class Stepper:
    def __init__(self, spec, params, protocol, step=None):
        self.dtype = jnp.dtype(protocol.dtype)
        self.model = lagbench.models.jax.build(spec, params)
        self.opt, self.step = step or make_step(spec, protocol)
        self.look = make_probe(spec, protocol)
        self.opt_state = self.opt.init(eqx.filter(self.model, eqx.is_inexact_array))
        self._next = None

    def propose(self, batch, lr, bound):
        batch = self._batch = _to_jax(batch, self.dtype)
        model, state, loss, gnorm = self.step(self.model, self.opt_state, batch, jnp.asarray(lr, self.dtype),
                                              jnp.asarray(bound, self.dtype))
        self._next = (model, state)
        return float(loss), float(gnorm)

    def commit(self, taken, scale):
        # the compiled step has clipped, and left model and state unchanged where the bound skipped it
        self.model, self.opt_state = self._next

    mode = "jit"

    def probe(self):
        return None if self.look is None else self.look(self.model, self._batch)

    def params(self) -> dict:
        return lagbench.models.jax.to_params(self.model)

    def state_arrays(self) -> list[np.ndarray]:
        return _state_arrays(self)

    def load_state_arrays(self, arrays) -> None:
        _load_state_arrays(self, arrays)


def train(spec, params, protocol, stream, on_log=None, hooks=(), snapshot=None, start_state=None) -> TrainOutcome:
    return loop.train(Stepper(spec, params, protocol), protocol, stream, on_log, hooks, snapshot=snapshot,
                      start_state=start_state)


def _stack(trees):
    return jax.tree_util.tree_map(lambda *a: jnp.stack(a), *trees)


@_compiled_per_objective
def make_members_step(spec, protocol):
    """(optax transform, the `make_step` step vmapped over stacked models, states, batches and bounds)."""
    opt, step = make_step(spec, protocol)
    return opt, eqx.filter_jit(eqx.filter_vmap(step, in_axes=(0, 0, 0, None, 0)))


class Members:
    def __init__(self, spec, params_list, protocol, step=None):
        self.dtype = jnp.dtype(protocol.dtype)
        built = [lagbench.models.jax.build(spec, p) for p in params_list]
        self.static = eqx.filter(built[0], eqx.is_array, inverse=True)
        self.model = eqx.combine(_stack([eqx.filter(m, eqx.is_array) for m in built]), self.static)
        self.opt, self.step = step or make_members_step(spec, protocol)
        self.look = make_probe(spec, protocol)
        self.opt_state = eqx.filter_vmap(self.opt.init)(eqx.filter(self.model, eqx.is_inexact_array))
        self.n, self._next = len(built), None

    def member(self, i: int):
        return eqx.combine(jax.tree_util.tree_map(lambda a: a[i], eqx.filter(self.model, eqx.is_array)),
                           self.static)

    def propose(self, batches, lr, bounds):
        batch = self._batch = _to_jax({k: np.stack([b[k] for b in batches]) for k in batches[0]}, self.dtype)
        model, state, loss, gnorm = self.step(self.model, self.opt_state, batch, jnp.asarray(lr, self.dtype),
                                              jnp.asarray(bounds, self.dtype))
        self._next = (model, state)
        return np.asarray(loss, np.float64), np.asarray(gnorm, np.float64)

    def commit(self, taken, scale):
        # as Stepper: the compiled step has clipped each member and skipped those above their bound
        self.model, self.opt_state = self._next

    mode = "jit"

    def probe(self):
        if self.look is None:
            return None
        return [self.look(self.member(i), {k: v[i] for k, v in self._batch.items()})
                for i in range(self.n)]

    def params(self) -> list[dict]:
        return [lagbench.models.jax.to_params(self.member(i)) for i in range(self.n)]

    def state_arrays(self) -> list[np.ndarray]:
        return _state_arrays(self)

    def load_state_arrays(self, arrays) -> None:
        _load_state_arrays(self, arrays)


def train_members(spec, params_list, protocol, streams, on_log=None, hooks=(), snapshot=None,
                  start_state=None) -> list[TrainOutcome]:
    return loop.train_members(Members(spec, params_list, protocol), protocol, streams, on_log, hooks,
                              snapshot=snapshot, start_state=start_state)
