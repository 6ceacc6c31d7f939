"""The training loop of the train-to-target study (`replication.bench.train_target`): one run from one
init, or restarts over several inits, with a held-out evaluation at evenly spaced steps.

`run_protocol(name, spec, protocol, seed=0, on_eval=None, seeds=1) -> (log, final model)`;
`scout_steps(protocol, seeds)`: the steps of each scout of a restarts run; `heldout_l1(spec, protocol)`:
model -> held-out L1. The optimiser step, batches, schedule and loss are the suite's
(`train_jax.make_step`, `data.BatchStream`, `schedules.learning_rate`, `objective`); this loop adds the
held-out evaluations and step-only timing, for which `train_jax.train` has no hook.
"""
from __future__ import annotations

import time

import equinox as eqx
import jax.numpy as jnp
import numpy as np

import models.jax
from models import ModelSpec, init_params
from replication import train_jax
from replication.data import BatchStream, heldout
from replication.objective import loss_value, predict
from replication.schedules import learning_rate
from replication.spike_guard import SpikeGuard

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
    """The training loop of one protocol, shared by its phases (one compiled step): `phase(...)` trains a
    model for a protocol's steps from its own stream and appends a log row at each held-out evaluation;
    samples, steps, wall seconds and skipped steps accumulate over phases."""

    def __init__(self, name, spec, protocol, on_eval=None):
        self.name, self.on_eval, self.batch = name, on_eval, protocol.batch
        self.opt, self.step = train_jax.make_step(spec, protocol)
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
        state = self.opt.init(eqx.filter(model, eqx.is_inexact_array))
        stream, guard, dtype = BatchStream(protocol, stream_seed), SpikeGuard(protocol), protocol.dtype
        every, losses, skipped0 = max(protocol.steps // n_evals, 1), [], self.skipped
        for k in range(protocol.steps):
            lr = learning_rate(protocol, k)
            batch = {key: jnp.asarray(v, dtype) for key, v in stream.batch(k).items()}
            bound = guard.threshold(dtype)
            t0 = time.perf_counter()
            new_model, new_state, loss, gnorm = self.step(model, state, batch, jnp.asarray(lr, dtype),
                                                          jnp.asarray(bound, dtype))
            loss, gnorm = float(loss), float(gnorm)
            if self.compiled:  # the first step compiles: samples_per_s counts the steps after it
                self.wall += time.perf_counter() - t0
            self.compiled = True
            if guard.fails(loss, gnorm):  # the row shows where it stopped, with the last good model
                self.row(model, f"{phase} (stopped: non-finite loss)", seed, lr, loss)
                break
            guard.record(gnorm, bound)
            model, state, self.steps, self.skipped = new_model, new_state, self.steps + 1, skipped0 + guard.skipped
            losses.append(loss)
            if (k + 1) % every == 0 or k == protocol.steps - 1:
                self.row(model, phase, seed, lr, loss)
        return model, float(np.mean(losses[-max(len(losses) // 20, 1):])) if losses else np.inf

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
