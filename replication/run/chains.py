"""What every executor shares: running one unit, chains of units that share a trained model, and naming
a unit across processes.

`run_one(unit, out, on_log=None) -> (failure or None, error or None)`: run and write one unit; an
exception becomes an error string ("<unit>: <Type>: <message>"), never lost to the rest of the run.
`chains(todo) -> [[Unit]]`: the units grouped by the training program they need (`training.group_key`: a
cohort of seeds is one program; untrained units alone), longest chain first by `cost` (training samples x model width x framework factor), so the
long ones do not start last. A chain runs in order: its first unit trains, the others read the training
from the cache.
`ref(unit) -> tuple` and `unit_of(ref) -> Unit`: a unit as plain values and back (a claim's rules are
closures: they do not pickle, so worker processes and Ray tasks receive refs).
`run_chain(refs, out) -> [(name, failure, error)]`: a chain's units in order, in a worker.
`release_if_crowded()`: after a unit, drop JAX's compiled executables once they crowd the process's memory map
(`release_compiled()`).
"""
from __future__ import annotations

import gc
import logging
import sys

from lagbench.files import results as R
from lagbench.models.spec import USER_KIND

log = logging.getLogger("lagbench")
TORCH_COST = 3.0   # PyTorch's eager LNN step against JAX's compiled one, per sample (measured, 3 x 64 and 3 x 128)


MAP_BUDGET = 20_000   # memory mappings a process may hold before its compiled code is dropped (limit 65 530)


def map_count() -> int | None:
    """This process's memory mappings (/proc/self/maps lines); None where the system does not tell."""
    try:
        with open("/proc/self/maps", "rb") as fh:
            return sum(1 for _ in fh)
    except OSError:
        return None


def release_compiled() -> None:
    """Drop JAX's compiled executables. XLA's CPU code is mapped into memory piece by piece: about 190
    mappings per model and unit, never given back, so a 220-unit quick run that kept them all exceeded the
    kernel's 65 530 mappings per process at unit 202 and died in LLVM ("Cannot allocate memory"). Cleared,
    the count stays flat (measured)."""
    if "jax" in sys.modules:
        sys.modules["jax"].clear_caches()
    gc.collect()


def release_if_crowded() -> bool:
    """After a unit: drop the compiled code only once the process holds more than `MAP_BUDGET` mappings (every
    unit where the count cannot be read). Kept, it serves the next units of the same model: a cohort's
    members, the other seeds of a model, a second claim on one trained model, which compiled their training
    step and evaluation again after every release (measured: 4 compilations, 3.5 s, per cohort member)."""
    n = map_count()
    if n is not None and n <= MAP_BUDGET:
        return False
    release_compiled()
    return True


def run_one(unit, out, on_log=None):
    """(failure or None, error or None) of running one unit."""
    from lagbench.files.user_functions import UserCodeError
    from lagbench.replication.run.units import run_unit

    try:
        d = run_unit(unit, out, on_log=on_log)
    except R.DiskFull:
        raise   # every later unit would fail the same way: the run stops (`runner.run`)
    except UserCodeError as e:   # the user's model failed: its one line, and its traceback with -v
        log.info("%s failed:\n%s", unit.name, e.details or e)
        return None, f"{unit.name}: {e}"
    except Exception as e:  # noqa: BLE001 - one unit's error must not lose the rest of the run
        log.exception("%s failed", unit.name)
        return None, f"{unit.name}: {type(e).__name__}: {e}"
    finally:
        release_if_crowded()
    return (None if d["status"] == "ok" else f"{unit.name}: {d['failure']['message']}"), None


def chains(todo) -> list[list]:
    """The units grouped by the model they train (untrained units alone), longest chain first."""
    from lagbench.replication.training.train import group_key

    groups: dict = {}
    for u in todo:   # a cohort's seeds (`Protocol.cohort`) train in one program: one chain
        key = group_key(u.framework, u.spec(), u.protocol(), u.seed) if u.entry.train else u.name
        groups.setdefault(key, []).append(u)
    return sorted(groups.values(), key=cost, reverse=True)


def cost(chain) -> float:
    from lagbench.replication.training.scouting import budget_samples

    u = chain[0]
    if not u.entry.train:
        return 0.0
    width = sum(u.spec().hidden) or 1
    return budget_samples(u.protocol()) * width * (TORCH_COST if u.framework == "torch" else 1.0)


def ref(u) -> tuple:
    """What names a unit across processes (a claim's rules are closures: they do not pickle); a user's model
    (`replication.run.added_models`) is not in its claim's list, so its entry travels with it, and so do the
    models of a claim whose models are not the written ones (a search's configuration, `lagbench tune`)."""
    from lagbench.replication.claims import get as get_claim

    user = u.entry if u.entry.spec.get("kind") == USER_KIND else None
    models = None if u.claim.models == get_claim(u.claim.id).models else u.claim.models
    return u.claim.id, u.entry.label, u.framework, u.seed, u.profile, user, models


def unit_of(r):
    """The unit a `ref` names: with models carried, the claim with those models and the entry among them;
    else the model as the claim resolves it under the profile (its adopted choice applied)."""
    import dataclasses

    from lagbench.replication.claims import get as get_claim
    from lagbench.replication.claims.resolved import resolved
    from lagbench.replication.run.units import Unit

    claim_id, label, framework, seed, profile, user, *rest = r
    models = rest[0] if rest else None
    claim = get_claim(claim_id)
    if models is not None:
        claim = dataclasses.replace(claim, models=models)
        entry = user or next(m for m in models if m.label == label)
    else:
        entry = user or resolved(claim, profile).model(label).entry
    return Unit(claim, entry, framework, seed, profile)


def run_chain(refs, out):
    """In a worker: the chain's units in order -> [(name, failure, error)]."""
    return [(u.name, *run_one(u, out)) for u in map(unit_of, refs)]
