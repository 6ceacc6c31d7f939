"""The training loop of the train-to-target study (`replication.bench.train_target`): one run from one
init, or restarts over several inits, with a held-out evaluation at evenly spaced steps.

`run_protocol(name, spec, protocol, seed=0, on_eval=None, seeds=1) -> (log, final model)`;
`scout_steps(protocol, seeds)`: the steps of each scout of a restarts run; `heldout_l1(spec, protocol)`:
model -> held-out L1. Every phase is a run of the suite's one training loop (`replication.loop.train`
with `train_jax.Stepper`, one compiled step shared by the phases); the held-out evaluations are its hook,
and its step-only timing is the loop's `step_seconds`.
"""
from __future__ import annotations

import equinox as eqx
import jax.numpy as jnp
import numpy as np

import models.jax
from models import ModelSpec, init_params
from replication import loop, train_jax
from replication.data import BatchStream, heldout
from replication.objective import loss_value, predict
from replication.schedules import learning_rate

N_EVALS = 20
SCOUT_SAMPLES = 500_000  # restarts: samples per scout (at most half the budget over all scouts)


def scout_steps(protocol, seeds: int) -> int:
    """Steps of each scouting run of a restarts protocol: SCOUT_SAMPLES samples, at most half the budget
    over all seeds together, at least 3 steps."""
    per = min(SCOUT_SAMPLES, protocol.steps * protocol.batch // (2 * seeds))
    return max(per // protocol.batch, 3)


def heldout_l1(spec, protocol):
    data = {k: jnp.asarray(v, protocol.dtype) for k, v in heldout(protocol).items()}

    @eqx.filter_jit
    def l1(model):
        return loss_value(predict(model, spec.kind, protocol.task, data, jnp.concatenate), data["target"],
                          None, "l1")
    return lambda model: float(l1(model))


class _Loop:
    """The phases of one protocol (one compiled step): `phase(...)` trains a model for a protocol's steps
    from its own stream and appends a log row at each held-out evaluation; samples, steps, step-only wall
    seconds and skipped steps accumulate over phases."""

    def __init__(self, name, spec, protocol, on_eval=None):
        self.name, self.on_eval, self.batch, self.spec = name, on_eval, protocol.batch, spec
        self.step = train_jax.make_step(spec, protocol)
        self.evaluate = heldout_l1(spec, protocol)
        self.log, self.steps, self.wall, self.skipped, self.compiled = [], 0, 0.0, 0, False

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
        stepper = train_jax.Stepper(self.spec, models.jax.to_params(model), protocol, step=self.step)

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
        return self.steps * self.batch


def run_protocol(name: str, spec: ModelSpec, protocol, seed: int = 0, on_eval=None,
                 seeds: int = 1) -> tuple[list[dict], object]:
    """Train for protocol.steps in all: (log with the held-out L1 at N_EVALS evenly spaced steps and the
    last, the final model: the last one with a finite loss); on_eval(log) after each evaluation.
    seeds = 1: one run from the init of `seed`. seeds > 1: restarts: the inits seed .. seed + seeds - 1
    each train for `scout_steps` (a one-cycle over the scout, evaluated once at its end), the one with the
    lowest training loss over its last 5 % of batches (the held-out set plays no part in the choice) then
    continues for the rest of the steps with a new one-cycle and fresh Adam state, from batches of its own
    stream (seed + 1000). Every scout's samples count."""
    loop = _Loop(name, spec, protocol, on_eval)
    if seeds == 1:
        model = models.jax.build(spec, init_params(spec, seed=seed))
        loop.row(model, "train", seed, learning_rate(protocol, 0), np.nan)
        return loop.log, loop.phase(model, protocol, seed, "train", seed, N_EVALS)[0]
    scout = protocol.replace(steps=scout_steps(protocol, seeds))
    best = None
    for s in range(seed, seed + seeds):
        model = models.jax.build(spec, init_params(spec, seed=s))
        if s == seed:
            loop.row(model, "scout", s, learning_rate(scout, 0), np.nan)
        model, tail = loop.phase(model, scout, s, "scout", s, 1)
        loop.log[-1]["scout_loss"] = tail
        if best is None or tail < best[0]:
            best = (tail, s, model)
    rest = protocol.replace(steps=max(protocol.steps - seeds * scout.steps, 1))
    return loop.log, loop.phase(best[2], rest, best[1] + 1000, "continue", best[1], N_EVALS)[0]
