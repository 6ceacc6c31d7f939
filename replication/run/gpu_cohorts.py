"""Seeds packed into cohorts for a GPU: which of a run's trainings can train side by side as one program.

On a GPU one training at batch 512 leaves most of the device idle, while the seeds of one model trained as
one vectorised program (`training.train.train_cohort`: vmap over stacked parameters in JAX, stacked
parameters and batched products in PyTorch) take little longer than one of them. Packing is a choice for
the device, made when the run is planned: it is never written into a protocol, so a claim's protocols,
registrations and training keys are those of every device, and each seed's numbers are those of its run
alone (float64, to rounding: `tests/replication/training/test_paper_cohorts.py`, every `paper` protocol at
a small size, in both frameworks).

`blocker(protocol, spec=None) -> str | None`: why a protocol's seeds (of `spec`'s model, where given) cannot
train side by side (None: they can).
`programs(units, out, members=MAX_MEMBERS) -> [Program]`: the training programs `units` still need (a seed
whose training OUT/trained holds needs none): a packable model's seeds in ascending order, up to `members`
a program; a protocol with a `blocker` keeps its own programs (`training.group_key`: one seed, or the
protocol's own cohort). Units sharing a training (claims 1 and 2 train the same models) share its program.

The estimate (`replication.run.estimate`) times these programs on the device with `--device gpu`, and the run
trains them so (`replication.run.packing`, `lagbench run --pack-seeds`). Memory
does not bound `MAX_MEMBERS` for the `paper` protocols: their largest model, the 3 x 600 LNN at batch 512,
holds about 12 MB of parameters and Adam state and under 0.1 GB of activations a member in float32.
"""
from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from lagbench.models.spec import USER_KIND

MAX_MEMBERS = 8   # seeds a program: every `paper` model's seeds (at most 8) train as one


@dataclass(frozen=True)
class Program:
    """One training program: `seeds` of one model and protocol, side by side when `packed`."""

    framework: str
    spec: object        # models.ModelSpec
    protocol: object    # training.protocol.Protocol, as the claim registers it (no cohort written in)
    seeds: tuple
    units: tuple        # the units that read its trainings
    packed: bool        # False: a protocol with a `blocker`, trained as it registers

    @property
    def members(self) -> int:
        return len(self.seeds) if self.packed else (self.protocol.cohort or 1)


def blocker(protocol, spec=None) -> str | None:
    """Why `protocol`'s seeds (of `spec`'s model, where given) cannot be packed into a cohort; None where they can."""
    if spec is not None and spec.kind == USER_KIND:
        return "a user's model (`--add-model`): its code is not known to train stacked, so each seed trains alone"
    if protocol.scouting:
        return "restarts (scouting): its scouts already train side by side, and a Protocol refuses both"
    if protocol.early_stop:
        return "early stop: each seed stops at its own step, a cohort's members stop together"
    if protocol.cohort:
        return f"a cohort of {protocol.cohort} already (its protocol's own)"
    return None


def _model_key(u) -> str:
    return json.dumps([u.framework, u.spec().to_dict(), u.protocol().to_dict()], sort_keys=True, default=str)


def programs(units, out, members: int = MAX_MEMBERS) -> list[Program]:
    from lagbench.replication.training.train import group_key, train_key

    if members < 1:
        raise ValueError(f"members must be at least 1, got {members!r}")
    by_model: dict = {}   # model key -> {seed: [units]}, in the units' order
    for u in units:
        if not u.entry.train:
            continue
        p, spec = u.protocol(), u.spec()
        if (Path(out) / "trained" / u.framework / train_key(u.framework, spec, p, u.seed) / "result.json").exists():
            continue
        by_model.setdefault(_model_key(u), {}).setdefault(u.seed, []).append(u)
    found = []
    for seeds in by_model.values():
        u0 = next(iter(seeds.values()))[0]
        p, spec = u0.protocol(), u0.spec()
        if blocker(p, spec):   # its own programs, as `training.group_key` groups them
            groups: dict = {}
            for s, us in seeds.items():
                groups.setdefault(group_key(u0.framework, spec, p, s), []).append((s, us))
            found += [Program(u0.framework, spec, p, tuple(s for s, _ in g), tuple(x for _, us in g for x in us),
                              packed=False) for g in groups.values()]
            continue
        order = sorted(seeds)
        for i in range(0, len(order), members):
            chunk = order[i:i + members]
            found.append(Program(u0.framework, spec, p, tuple(chunk), tuple(x for s in chunk for x in seeds[s]),
                                 packed=True))
    return found
