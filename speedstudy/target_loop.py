"""The training loop of the train-to-target study (`speedstudy.train_target`): one run from one
init, or restarts over several inits, with a held-out evaluation at evenly spaced steps.

`run_protocol(name, spec, protocol, seed=0, on_eval=None, heldout_seed=HELDOUT_SEED) -> (log, final model)`;
`heldout_l1(spec, protocol, seed=HELDOUT_SEED)`: model -> L1 on the held-out draw of generator `seed` (the
development draw unless a test-split study asks for its own, `replication.run.splits`). The held-out L1 only
fills the log: no training step, scout choice or stop reads it. Every phase is a run of the suite's one training loop (`replication.training.loop`:
the scouts of a restarts protocol side by side through `replication.training.scouting`, a single run and the
continuation with `train_jax.Stepper`); the held-out evaluations are its hook, and its step-only timing is
the loop's `step_seconds`.
"""
from __future__ import annotations

import equinox as eqx
import jax.numpy as jnp
import numpy as np

import lagbench.models.jax
from lagbench.models import ModelSpec, init_params
from lagbench.replication.training import data as datamod
from lagbench.replication.training import loop, scouting, train_jax
from lagbench.replication.training.data import HELDOUT_SEED, BatchStream
from lagbench.replication.training.objective import loss_value, predict
from lagbench.replication.training.schedules import learning_rate

N_EVALS = 20


def heldout_l1(spec, protocol, seed: int = HELDOUT_SEED):
    data = {k: jnp.asarray(v, protocol.dtype) for k, v in datamod.heldout(protocol, seed).items()}

    @eqx.filter_jit
    def l1(model):
        return loss_value(predict(model, spec.kind, protocol.task, data, jnp.concatenate), data["target"],
                          None, "l1")
    return lambda model: float(l1(model))


class _Loop:
    """The phases of one protocol (one compiled step): `phase(...)` trains a model for a protocol's steps
    from its own stream and appends a log row at each held-out evaluation; samples, steps, step-only wall
    seconds and skipped steps accumulate over phases."""

    def __init__(self, name, spec, protocol, on_eval=None, heldout_seed=HELDOUT_SEED):
        self.name, self.on_eval, self.batch, self.spec = name, on_eval, protocol.batch, spec
        self.step = train_jax.make_step(spec, protocol)
        self.evaluate = heldout_l1(spec, protocol, heldout_seed)
        self.log, self.steps, self.wall, self.skipped, self.compiled = [], 0, 0.0, 0, False
        self.extra = 0   # samples beyond steps x batch: scouts at a batch of their own

    def row(self, model, phase, seed, lr, loss):
        self.log.append({"protocol": self.name, "phase": phase, "seed": seed, "step": self.steps,
                         "samples": self.samples, "lr": lr, "train_loss": loss,
                         "heldout_l1": self.evaluate(model), "wall_s": self.wall, "skipped_steps": self.skipped})
        if self.on_eval and self.steps:
            self.on_eval(self.log)

    def phase(self, model, protocol, stream_seed, phase, seed, n_evals):
        """Train for protocol.steps: (model, mean training loss over the last 5 % of the steps, inf if none).
        Stops at a non-finite loss, keeping the last model with a finite one; the phase always ends with a
        row of the log."""
        every, losses = max(protocol.steps // n_evals, 1), []
        steps0, wall0, skipped0 = self.steps, self.wall, self.skipped
        stepper = train_jax.Stepper(self.spec, lagbench.models.jax.to_params(model), protocol, step=self.step)

        def evaluate(k, st, info):
            self.steps, self.wall = steps0 + k + 1, wall0 + info["step_seconds"]
            self.skipped = skipped0 + info["skipped_steps"]
            losses.append(info["loss"])
            if (k + 1) % every == 0 or k == protocol.steps - 1:
                self.row(st.model, phase, seed, info["lr"], info["loss"])

        out = loop.train(stepper, protocol, BatchStream(protocol, stream_seed), hooks=(evaluate,),
                         compiled=self.compiled)
        self.compiled = True
        if out.failure is not None:   # the row shows where it stopped, with the last good model
            k = out.failure["step"]
            self.row(stepper.model, f"{phase} (stopped: non-finite loss)", seed, learning_rate(protocol, k), np.nan)
        return stepper.model, float(np.mean(losses[-max(len(losses) // 20, 1):])) if losses else np.inf

    @property
    def samples(self) -> int:
        return self.steps * self.batch + self.extra


def run_protocol(name: str, spec: ModelSpec, protocol, seed: int = 0, on_eval=None,
                 heldout_seed: int = HELDOUT_SEED) -> tuple[list[dict], object]:
    """Train for `scouting.budget_samples(protocol)` samples in all: (log with the held-out L1 at N_EVALS evenly spaced steps and the
    last, the final model: the last one with a finite loss); on_eval(log) after each evaluation;
    heldout_seed: the generator seed of the held-out draw those evaluations read.
    Without `protocol.scouting`: one run from the init of `seed`. With K scouts: restarts (`replication.training.scouting`)
    over the inits seed .. seed + K - 1, trained side by side for the scouting's steps (a one-cycle over
    the scout, each evaluated once at its end), the one with the lowest training loss over its last 5 % of
    batches (the held-out set plays no part) then continued for protocol.steps with a new one-cycle
    and fresh Adam state, from batches of its own stream (seed + 1000). Every scout's samples count; the
    scouts' wall time is the one program's."""
    loop = _Loop(name, spec, protocol, on_eval, heldout_seed)
    if not protocol.scouting:
        model = lagbench.models.jax.build(spec, init_params(spec, seed=seed))
        loop.row(model, "train", seed, learning_rate(protocol, 0), np.nan)
        return loop.log, loop.phase(model, protocol, seed, "train", seed, N_EVALS)[0]
    seeds, scout = list(range(seed, seed + protocol.scouting.count)), scouting.scout_protocol(protocol)
    loop.row(lagbench.models.jax.build(spec, init_params(spec, seed=seed)), "scout", seed, learning_rate(scout, 0), np.nan)
    outcomes, tails = scouting.scout(train_jax, spec, protocol, seeds)
    loop.wall += max(o.step_seconds for o in outcomes)   # the kept scouts' time runs on past a cut
    steps, extra = divmod(scouting.scouting_samples(protocol), protocol.batch)
    loop.steps, loop.extra = loop.steps + steps, loop.extra + extra
    for s, out, tail in zip(seeds, outcomes, tails, strict=True):
        loop.skipped += out.skipped_steps
        model = lagbench.models.jax.build(spec, out.params)
        if out.failure is None:
            loop.row(model, "scout", s, learning_rate(scout, out.steps_done - 1), out.log[-1]["loss"])   # a cut scout: at the cut
        else:
            loop.row(model, "scout (stopped: non-finite loss)", s, learning_rate(scout, out.failure["step"]), np.nan)
        loop.log[-1]["scout_loss"] = tail
    best = scouting.choose(tails) or 0
    model = lagbench.models.jax.build(spec, outcomes[best].params)
    rest = scouting.continuation_protocol(protocol)
    return loop.log, loop.phase(model, rest, seeds[best] + scouting.CONTINUATION_STREAM, "continue", seeds[best],
                                N_EVALS)[0]
