"""The PyTorch optimiser step (torch.optim.Adam) for the one training loop `replication.training.loop`. Mirrors
`train_jax.py` line for line.

`Stepper(spec, params, protocol)`: the gradient and its global norm in `propose` (the learning rate set on
the optimiser there); in `commit`, if the spike guard takes the step, the gradient scaled by the clip
factor and one Adam step. `train(spec, params, protocol, stream, on_log=None, hooks=(), snapshot=None,
start_state=None) -> TrainOutcome`: `replication.training.loop.train` with this stepper. Both steppers give their parameters and
Adam state as arrays for snapshots (`state_arrays`).

`Members(spec, params_list, protocol)`: K models of one spec trained as one program (the stepper of
`replication.training.loop.train_members`). Where the model's maths takes stacked members
(`lagbench.models.torch.stacks(spec)`: the fast LNN, the feed-forward baseline) they are one model whose parameters
have a leading K axis (`lagbench.models.torch.build_stacked`): every product is one batched product over the members
and the K losses come out per member (`loss_value(..., axis=-1)`). Other kinds stack with
`torch.func.stack_module_state` and map `torch.func.functional_call` under `torch.func.vmap` over parameters
and batches. Either way one backward pass of the losses' sum (the members share nothing, so each gets its
own gradient), and Adam as one call of torch's fused Adam kernel over every taken member's slice of every
parameter (`_fused_adam`, what `Stepper`'s torch.optim.Adam(fused=True) runs), with a step count per
member; a member the guard skips is left out of the call, so it keeps its state exactly. Both run their loss
under torch.compile where `replication.training.compile_torch` says so (`mode`). Each member's
numbers are those of its own `Stepper` run (`tests/replication/training/test_members_parity.py`; compiled,
up to rounding: the two are different programs). `train_members(spec, params_list, protocol, streams,
on_log=None, hooks=(), snapshot=None) -> [TrainOutcome]`.
"""
from __future__ import annotations

import numpy as np
import torch
from torch import nn
from torch.func import functional_call, stack_module_state, vmap

import lagbench.models.torch
from lagbench.replication.training import hessian_probe, loop
from lagbench.replication.training.compile_torch import compiled_loss, step_mode
from lagbench.replication.training.objective import loss_value, predict
from lagbench.replication.training.outcome import TrainOutcome

_ADAM_STATE = ("step", "exp_avg", "exp_avg_sq")   # torch.optim.Adam's state of one parameter (no amsgrad)
# which torch.optim.Adam implementation trains (and the speed study times): the fused kernel, one pass over
# each tensor (the 3 x 128 LNN at batch 32, 2 threads: 0.45 ms a step against the single-tensor loop's
# 0.67-0.86 ms); the members' `_fused_adam` calls the same kernel
ADAM_KERNEL = {"fused": True}


def _to_torch(batch: dict, dtype) -> dict:
    return {k: torch.as_tensor(v, dtype=dtype) for k, v in batch.items()}


def make_loss(spec, protocol, per_member=False):
    """(model, batch) -> the protocol's loss; per_member: of stacked members, (K,)."""
    def loss_fn(model, batch):
        pred = predict(model, spec.kind, protocol.task, batch, torch.cat, protocol.trajectory_loss,
                       protocol.filter_loss)
        loss = loss_value(pred, batch["target"], batch.get("weight"), protocol.loss, -1 if per_member else None)
        if protocol.l2:
            loss = loss + protocol.l2 * sum((p * p).flatten(1).sum(1) if per_member else (p * p).sum()
                                            for p in model.parameters())
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
        return hessian_probe.probe(qdd.cpu().numpy(), int(n_fb), None if hess is None else hess.cpu().numpy(),
                                   protocol.dtype)
    return run


class Stepper:
    def __init__(self, spec, params, protocol):
        self.dtype = getattr(torch, protocol.dtype)
        self.model = lagbench.models.torch.build(spec, params)
        self.loss_fn = compiled_loss(make_loss(spec, protocol), spec, protocol)
        self.look = make_probe(spec, protocol)
        self.opt = torch.optim.Adam(self.model.parameters(), lr=protocol.schedule.lr, betas=(protocol.optimiser.b1, protocol.optimiser.b2),
                                    eps=protocol.optimiser.eps, weight_decay=0.0, **ADAM_KERNEL)
        self.clip_to, self._grads = protocol.grad_clip, []   # None: no clip (the guard's scale stays 1)

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

    @property
    def mode(self) -> str:
        return step_mode(self.loss_fn)

    def probe(self):
        return None if self.look is None else self.look(self.model, self._batch)

    def params(self) -> dict:
        return lagbench.models.torch.to_params(self.model)

    def state_arrays(self) -> list[np.ndarray]:
        """Per parameter: its values, whether Adam holds a state for it (none before its first gradient),
        and that state's step count and two moments (zeros when absent)."""
        out = []
        for p in self.model.parameters():
            state = self.opt.state.get(p) or {}
            out += [p.detach().cpu().numpy().copy(), np.asarray(bool(state))]
            out += [(state[k].detach().cpu().numpy().copy() if k in state else np.zeros(() if k == "step" else p.shape))
                    for k in _ADAM_STATE]
        return out

    def load_state_arrays(self, arrays) -> None:
        params = list(self.model.parameters())
        if len(arrays) != len(params) * (2 + len(_ADAM_STATE)):
            raise ValueError("a training snapshot's arrays do not fit this model and optimiser")
        with torch.no_grad():
            for j, p in enumerate(params):
                value, has, *state = arrays[j * (2 + len(_ADAM_STATE)):(j + 1) * (2 + len(_ADAM_STATE))]
                p.copy_(torch.as_tensor(value))
                self.opt.state.pop(p, None)
                if bool(has):
                    self.opt.state[p] = {k: torch.as_tensor(a).clone() for k, a in zip(_ADAM_STATE, state, strict=True)}


def train(spec, params, protocol, stream, on_log=None, hooks=(), snapshot=None, start_state=None) -> TrainOutcome:
    return loop.train(Stepper(spec, params, protocol), protocol, stream, on_log, hooks, snapshot=snapshot,
                      start_state=start_state)


class _Objective(nn.Module):
    """batch -> the protocol's loss of one model (what `Members` maps over the stacked parameters)."""

    def __init__(self, model, loss_fn):
        super().__init__()
        self.model, self.loss_fn = model, loss_fn

    def forward(self, batch):
        return self.loss_fn(self.model, batch)


def _fused_adam(params, grads, exp_avgs, exp_avg_sqs, steps, lr, protocol):
    """torch.optim.Adam(fused=True)'s kernel on lists of tensors, each with its step count after this step
    (0-d float32 tensors, as Adam's state holds them): one pass over each tensor."""
    torch._fused_adam_(params, grads, exp_avgs, exp_avg_sqs, [], steps, lr=lr, beta1=protocol.optimiser.b1, beta2=protocol.optimiser.b2,
                       weight_decay=0.0, eps=protocol.optimiser.eps, amsgrad=False, maximize=False)


class Members:
    def __init__(self, spec, params_list, protocol):
        self.dtype, self.protocol = getattr(torch, protocol.dtype), protocol
        self.spec, self.n = spec, len(params_list)
        if lagbench.models.torch.stacks(spec):
            self.model = lagbench.models.torch.build_stacked(spec, params_list)
            self.loss_fn = compiled_loss(make_loss(spec, protocol, True), spec, protocol, self.n)
            self.stacked = dict(self.model.named_parameters())
        else:   # no stacked model: the K losses come from vmap over the stacked parameters
            objectives = [_Objective(lagbench.models.torch.build(spec, p), make_loss(spec, protocol)) for p in params_list]
            self.model, self.base = None, objectives[0]
            self.stacked, self.buffers = stack_module_state(objectives)
        self.moments = {k: (torch.zeros_like(p), torch.zeros_like(p)) for k, p in self.stacked.items()}
        self.count = torch.zeros(self.n, dtype=torch.int64)
        self.look = make_probe(spec, protocol)
        self.clip_to, self._cache = protocol.grad_clip, {}

    def _views(self, key):
        """The members' slices of parameter `key` and of its two moments (cached: all three are only ever
        updated in place)."""
        if key not in self._cache:
            self._cache[key] = tuple(x.unbind(0) for x in (self.stacked[key], *self.moments[key]))
        return self._cache[key]

    def _loss(self, params, buffers, batch):
        return functional_call(self.base, (params, buffers), (batch,))

    def _losses(self, batch):
        """The K losses, (K,)."""
        if self.model is not None:
            return self.loss_fn(self.model, batch)
        return vmap(self._loss)(self.stacked, self.buffers, batch)

    def propose(self, batches, lr, bounds):
        batch = self._batch = _to_torch({k: np.stack([b[k] for b in batches]) for k in batches[0]}, self.dtype)
        for p in self.stacked.values():
            p.grad = None
        losses = self._losses(batch)
        losses.sum().backward()
        self._lr = lr
        # a parameter the loss does not reach (the LNN's last bias) has no gradient; Adam leaves it, as in Stepper
        self._with_grad = {k: p for k, p in self.stacked.items() if p.grad is not None}
        self._gnorm = torch.sqrt(sum((p.grad * p.grad).flatten(1).sum(1) for p in self._with_grad.values()))
        return losses.detach().double().cpu().numpy(), self._gnorm.double().cpu().numpy()

    def commit(self, taken, scale):
        members = np.flatnonzero(taken)
        if not len(members):
            return
        count = self.count + torch.as_tensor(np.asarray(taken, bool)).to(torch.int64)
        with torch.no_grad():
            clip = torch.as_tensor(scale != 1.0)
            if clip.any():   # unclipped members get the factor 1.0, which leaves their gradient exactly as it is
                factor = torch.where(clip, self.clip_to / self._gnorm, torch.ones_like(self._gnorm))
                for p in self._with_grad.values():
                    p.grad.mul_(factor.view((-1,) + (1,) * (p.dim() - 1)))
            # one fused Adam call over every taken member's slice of every parameter, each with its own step
            # count (a member the guard skips, or a stopped one, is not in it and keeps its state exactly)
            steps, every = count.to(torch.float32).unbind(0), len(members) == self.n
            lists = [[], [], [], [], []]
            for k, p in self._with_grad.items():
                values, m, v = self._views(k)
                parts = (values, p.grad.unbind(0), m, v, steps)
                for out, views in zip(lists, parts, strict=True):
                    out += views if every else [views[i] for i in members]
            _fused_adam(*lists, self._lr, self.protocol)
        self.count = count

    def _params_of(self, i: int) -> dict:
        return {k.removeprefix("model."): p[i].detach().cpu().numpy().copy() for k, p in self.stacked.items()}

    @property
    def mode(self) -> str:
        return step_mode(self.loss_fn) if self.model is not None else "eager"

    def probe(self):
        if self.look is None:
            return None
        return [self.look(lagbench.models.torch.build(self.spec, self._params_of(i)), {k: v[i] for k, v in self._batch.items()})
                for i in range(self.n)]

    def params(self) -> list[dict]:
        return [self._params_of(i) for i in range(self.n)]

    def state_arrays(self) -> list[np.ndarray]:
        """The stacked parameters, their two Adam moments (in `stacked` order) and the step counts."""
        out = []
        for k, p in self.stacked.items():
            out += [p.detach().cpu().numpy().copy(), *(m.cpu().numpy().copy() for m in self.moments[k])]
        return [*out, self.count.cpu().numpy().copy()]

    def load_state_arrays(self, arrays) -> None:
        if len(arrays) != 3 * len(self.stacked) + 1:
            raise ValueError("a training snapshot's arrays do not fit these models and optimiser")
        with torch.no_grad():
            for j, (k, p) in enumerate(self.stacked.items()):
                value, m, v = (torch.as_tensor(a) for a in arrays[3 * j:3 * j + 3])
                for x, new in zip((p, *self.moments[k]), (value, m, v), strict=True):
                    x.copy_(new)   # in place: the cached member views (`_views`) stay those of the live tensors
        self.count = torch.as_tensor(arrays[-1]).clone()


def train_members(spec, params_list, protocol, streams, on_log=None, hooks=(), snapshot=None,
                  start_state=None) -> list[TrainOutcome]:
    return loop.train_members(Members(spec, params_list, protocol), protocol, streams, on_log, hooks,
                              snapshot=snapshot, start_state=start_state)
