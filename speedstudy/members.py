"""Many seeds for the price of one: K models trained side by side as one program (`loop.train_members`:
JAX `eqx.filter_vmap` over stacked parameters; PyTorch one model whose parameters are stacked, its
products batched over the members, `models.torch.build_stacked`) against one model alone.

The case is the restarts protocol's scouting phase: the double-pendulum LNN (softplus, the code's init,
angles wrapped, velocity inputs x 0.3) at `sizes.members_hidden` (quick: 3 x 128), batch 32, the spike
guard on, `sizes.members_steps` steps per round. Per framework and step mode (JAX "jit"; PyTorch "eager" and,
where `sizes.torch_compile`, "compiled": the training loss under torch.compile as the runs' long phases train
it, `compile_torch`), rounds alternate one model and K members (`members_rounds` of each, interleaved, so that
load on the shared machine falls on both alike); each keeps its fastest round. The JAX step is built once per
case and warmed up before the first round; every round's first step (a capture, under torch.compile) is left
out of its times.

`members_rows(sizes) -> rows` {framework, mode, members, hidden, batch, steps, wall_s, step_s, samples_per_s,
cost_vs_one, step_cost_vs_one}: wall_s is the whole loop after the first step (batches drawn in NumPy, the
guard, the step) for `steps` - 1 steps, step_s the optimiser steps alone (`TrainOutcome.step_seconds`);
cost_vs_one = the K members' wall over one model's in the same mode (K scouts run one after another would
cost K). A third row per framework and mode: one model at K x the batch, the same samples per step as the K
members, for scale (what batching alone costs). The issue's bound, K = 8 at most 2.5x one model's wall time
per framework, is checked in `speedstudy.targets`.
"""
from __future__ import annotations

from lagbench.models import ModelSpec, init_params
from lagbench.replication.claims.double_pendulum import MODELS, RESTARTS
from lagbench.replication.training import compile_torch, loop, scouting, train_jax, train_torch
from lagbench.replication.training.data import BatchStream

MEMBERS = 8
MODES = {"jax": ("jit",), "torch": ("eager", "compiled")}   # "compiled": only where `sizes.torch_compile`


def _modes(sizes) -> list[tuple[str, str]]:
    return [(fw, m) for fw, modes in MODES.items() for m in modes if m != "compiled" or sizes.torch_compile]


def _case(sizes):
    lnn = next(m for m in MODELS if m.label == "lnn")
    spec = ModelSpec(dof=2, hidden=tuple(sizes.members_hidden), dtype="float32", **lnn.spec_fields("quick"))
    scout = scouting.scout_protocol(RESTARTS)   # a scout of the double pendulum's restarts protocol
    return spec, scout.replace(steps=sizes.members_steps, data=scout.data.replace(n_train=scout.batch * 1000),
                               log_every=10**9, tracking=None)


def _make_step(framework, spec, protocol, k):
    if framework != "jax":
        return None
    return train_jax.make_step(spec, protocol) if k == 1 else train_jax.make_members_step(spec, protocol)


def _round(framework, spec, protocol, k, step):
    """(wall, step seconds) of one round after its first step: one model through its own stepper (what a
    lone scout runs), or k members as one program."""
    module = train_jax if framework == "jax" else train_torch
    kw = {"step": step} if framework == "jax" else {}
    first = []   # the first log row is step 0's: its wall_s is the first step's time (a capture, compiled)
    on_log = lambda row: first.append(row["wall_s"]) if not first else None  # noqa: E731
    if k == 1:
        out = loop.train(module.Stepper(spec, init_params(spec, seed=0), protocol, **kw), protocol,
                         BatchStream(protocol, 0), on_log=on_log)
    else:
        out = loop.train_members(module.Members(spec, [init_params(spec, seed=s) for s in range(k)], protocol, **kw),
                                 protocol, [BatchStream(protocol, s) for s in range(k)], on_log=on_log)[0]
    return out.train_time_s - first[0], out.step_seconds, out.step_mode


def _cases(protocol):
    """(members, protocol): one model, MEMBERS members, and one model at MEMBERS x the batch (the same samples
    per step as the members: what batching alone costs, the floor of what vectorising can reach)."""
    wide = protocol.batch * MEMBERS
    return [(1, protocol), (MEMBERS, protocol), (1, protocol.replace(batch=wide, data=protocol.data.replace(n_train=wide * 1000)))]


def _mode_rows(fw, mode, spec, protocol, rounds) -> list[dict]:
    cases = _cases(protocol)
    steps = [_make_step(fw, spec, p, k) for k, p in cases]
    best = [(float("inf"), float("inf"))] * len(cases)
    ran = [mode] * len(cases)   # what each case's steps ran: "eager (torch.compile failed: ...)" if so
    for (k, p), step in zip(cases, steps, strict=True):   # warm-up: compile, first batches
        _round(fw, spec, p.replace(steps=2), k, step)
    for _ in range(rounds):
        for i, ((k, p), step) in enumerate(zip(cases, steps, strict=True)):
            wall, step_s, ran[i] = _round(fw, spec, p, k, step)
            best[i] = (min(best[i][0], wall), min(best[i][1], step_s))
    return [{"framework": fw, "mode": how, "members": k, "hidden": "x".join(map(str, spec.hidden)),
             "batch": p.batch, "steps": p.steps, "wall_s": wall, "step_s": step_s,
             "samples_per_s": k * (p.steps - 1) * p.batch / wall,
             "cost_vs_one": wall / best[0][0], "step_cost_vs_one": step_s / best[0][1]}
            for (k, p), (wall, step_s), how in zip(cases, best, ran, strict=True)]


def members_rows(sizes, bar=None) -> list[dict]:
    spec, protocol = _case(sizes)
    rows = []
    for fw, mode in _modes(sizes):
        with compile_torch.setting_as("on" if mode == "compiled" else "off"):   # PyTorch's; JAX jits always
            rows += _mode_rows(fw, mode, spec, protocol, sizes.members_rounds)
        if bar is not None:
            bar.update(1)
    return rows


def n_cases(sizes) -> int:
    return len(_modes(sizes)) if sizes.members_steps else 0
