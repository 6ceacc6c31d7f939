"""An inverse model that learns while it controls: the replay buffer and the per-framework learners of the online
study (`replication.studies.online`).

`ReplayBuffer(size, dof, seed)`: the last `size` executed samples (q, qdot, measured qddot, applied tau), each
(dof,) float64; `sample(batch)` draws `batch` of them uniformly with replacement (its own NumPy generator) as
the suite's training batch for task "inverse_dynamics": {"q", "qdot", "extra" = qddot, "target" = tau}, each
(batch, dof) float64.

`learner(kind, framework, seed, hidden=HIDDEN, lr=None, dof=2) -> JaxLearner | TorchLearner`: claim 9's model of
that kind ("delan", or "ff": the feed-forward baseline given qddot as extra input; 2-layer softplus, xavier,
float32) for an arm of `dof` joints (2: the two-link arm's, 4: the four-joint arm's) with fresh parameters (`models.init_params(spec, seed)`), trained by the suite's own optimiser step
(`replication.training.train_jax.Stepper` / `train_torch.Stepper`: Adam, torque MSE plus L2 1e-5, claim 9's
quick protocol) at learning rate `lr` (default the protocol's 1e-3; 0 is the null learner, whose steps change
no parameter). Each learner gives:
  tau(q, qdot, qddot) -> (dof,) float64   the current model's torque for one sample, (dof,) float64 inputs
                                          (the controller's feed-forward, timed as inference);
  warm(batch)                             compile (JAX) and run the step once for minibatches of `batch`
                                          without taking it (a proposed step left uncommitted changes neither
                                          model nor Adam state), so that no tick's timing holds a compile;
  learn(batch, steps)                     `steps` optimiser steps on the batch dict (`ReplayBuffer.sample`);
  inverse(q, qdot, qddot) -> (B, dof)     the current model on a batch, for scoring it frozen afterwards.
JAX's single-sample call is `models.jax.compiled.compile_single` (one XLA dispatch, the parameters passed as
arguments, so a learning step only swaps them in); PyTorch's is the eager method under `torch.no_grad`
(an AOTInductor library compiles the parameters in, so it would need rebuilding after every step). The
PyTorch loss runs eager (`LAGBENCH_TORCH_COMPILE=off` while the stepper is built): a capture takes tens of
seconds, and the study times every step from the first.
"""
from __future__ import annotations

import math

import numpy as np

KINDS = ("delan", "ff")
HIDDEN = (64, 64)   # claim 9's registered widths


class ReplayBuffer:
    def __init__(self, size: int, dof: int, seed: int):
        if size < 1:
            raise ValueError(f"a replay buffer holds at least 1 sample, got {size}")
        self.size, self.n, self.head = size, 0, 0
        self.data = np.zeros((4, size, dof))   # q, qdot, qddot, tau
        self.rng = np.random.default_rng(seed)

    def add(self, q, qdot, qddot, tau) -> None:
        self.data[:, self.head] = (q, qdot, qddot, tau)
        self.head = (self.head + 1) % self.size
        self.n = min(self.n + 1, self.size)

    def sample(self, batch: int) -> dict:
        if self.n == 0:
            raise ValueError("the replay buffer is empty")
        q, qdot, qddot, tau = self.data[:, self.rng.integers(0, self.n, batch)]
        return {"q": q, "qdot": qdot, "extra": qddot, "target": tau}


def claim_model(kind: str, hidden=HIDDEN, dof: int = 2):
    """(ModelSpec, Protocol) of claim 9's model `kind` for an arm of `dof` joints (claim 9's own: 2): its spec
    fields at `hidden` and its quick protocol (loss, L2, Adam, learning rate)."""
    from lagbench.models import ModelSpec
    from lagbench.replication.claims.delan_arm import CLAIM, PROTOCOLS

    if kind not in KINDS:
        raise ValueError(f"model {kind!r}: valid {', '.join(KINDS)}")
    fields = dict(CLAIM.entry(kind).spec)
    if "extra_inputs" in fields:   # the feed-forward net's qddot input: one per joint
        fields["extra_inputs"] = int(dof)
    spec = ModelSpec(dof=int(dof), dtype="float32", hidden=tuple(hidden), **fields)
    return spec, PROTOCOLS["quick"]


class _Learner:
    def warm(self, batch: int) -> None:
        zeros = {k: np.zeros((batch, self.spec.dof)) for k in ("q", "qdot", "extra", "target")}
        self.stepper.propose(zeros, self.lr, math.inf)


class JaxLearner(_Learner):
    framework = "jax"

    def __init__(self, spec, params, protocol, lr: float):
        from lagbench.models.jax.compiled import compile_single
        from lagbench.replication.training.train_jax import Stepper

        self.spec, self.lr = spec, lr
        self.stepper = Stepper(spec, params, protocol)
        self.method = "inverse_dynamics" if spec.kind == "delan" else "acceleration"
        self.fast = compile_single(self.stepper.model, self.method, n_inputs=3,
                                   compiler_options={"xla_cpu_multi_thread_eigen": False})
        self.keys = sorted(self.stepper.model.params)
        self.dtype = np.dtype(spec.dtype)

    def tau(self, q, qdot, qddot) -> np.ndarray:
        d = self.dtype
        return np.asarray(self.fast(q.astype(d), qdot.astype(d), qddot.astype(d)), np.float64)

    def learn(self, batch: dict, steps: int) -> None:
        for _ in range(steps):
            self.stepper.propose(batch, self.lr, math.inf)   # returns the loss as a float: the step has finished
            self.stepper.commit(True, 1.0)
        self.fast.leaves = [self.stepper.model.params[k] for k in self.keys]

    def inverse(self, q, qdot, qddot) -> np.ndarray:
        import jax.numpy as jnp

        d = self.spec.dtype
        out = getattr(self.stepper.model, self.method)(*(jnp.asarray(x, d) for x in (q, qdot, qddot)))
        return np.asarray(out, np.float64)


class TorchLearner(_Learner):
    framework = "torch"

    def __init__(self, spec, params, protocol, lr: float):
        import torch

        from lagbench.replication.training.compile_torch import setting_as
        from lagbench.replication.training.train_torch import Stepper

        self.torch, self.spec, self.lr = torch, spec, lr
        with setting_as("off"):
            self.stepper = Stepper(spec, params, protocol)
        self.method = "inverse_dynamics" if spec.kind == "delan" else "acceleration"
        self.dtype = getattr(torch, spec.dtype)

    def _call(self, *xs) -> np.ndarray:
        t = self.torch
        with t.no_grad():
            out = getattr(self.stepper.model, self.method)(*(t.as_tensor(x, dtype=self.dtype) for x in xs))
        return out.numpy().astype(np.float64)

    def tau(self, q, qdot, qddot) -> np.ndarray:
        return self._call(q[None], qdot[None], qddot[None])[0]

    def learn(self, batch: dict, steps: int) -> None:
        for _ in range(steps):
            self.stepper.propose(batch, self.lr, math.inf)
            self.stepper.commit(True, 1.0)

    def inverse(self, q, qdot, qddot) -> np.ndarray:
        return self._call(q, qdot, qddot)


def learner(kind: str, framework: str, seed: int, hidden=HIDDEN, lr: float | None = None, dof: int = 2):
    """A fresh learner of claim 9's model `kind` in `framework` ("jax" or "torch") for `dof` joints, initialised
    from `seed`."""
    from lagbench.models import init_params

    spec, protocol = claim_model(kind, hidden, dof)
    lr = protocol.schedule.lr if lr is None else float(lr)
    if not (math.isfinite(lr) and lr >= 0):
        raise ValueError(f"learning rate {lr!r}: must be finite and >= 0")
    cls = {"jax": JaxLearner, "torch": TorchLearner}.get(framework)
    if cls is None:
        raise ValueError(f"framework {framework!r}: valid jax, torch")
    return cls(spec, init_params(spec, seed=seed), protocol, lr)
