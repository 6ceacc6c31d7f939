"""Seeds packed by the run: a model's trainings trained as one program (`lagbench run --pack-seeds N`).

`members(pack_seeds, frameworks, executor="local") -> {framework: N}`: the most seeds a program holds, per
framework: `pack_seeds` where given (an integer >= 1; 1: each seed alone), else `gpu_cohorts.MAX_MEMBERS`
where the framework trains on a GPU (`training.device`) and 1 on the CPU. Packing changes float32 rounding
(a seed's products run stacked with the others'), so on the CPU, where registrations are made, it is off
unless asked for. Ray's executor packs nothing: each of its units is a task of its own.
`by_unit(units, out, members) -> {unit name: Program}`: the packed programs of two seeds or more
(`gpu_cohorts.programs`) and the units that read them.
`chains(todo, out, members) -> [[Unit]]`: `replication.run.chains.chains` with each packed program's units in
one chain, so that one worker trains it and the others read it.
`train_program(program, out, on_log=None)`: the program's seeds not yet in OUT/trained trained as one
(`training.train.train_cohort`), on the run's device, each stored under the training key of its run alone
with "cohort": {"seeds": [...], "packed": true} in its result.json (and so in its units' records). The units
then read their trainings from the cache: a later unpacked run, a resume, `verify` and the report read a
packed training as any other. Protocols, registrations and keys do not hold the packing.
`program_error(unit, out, program, on_log=None) -> str | None`: the unit's program trained (where it has one
and it is not yet stored); an exception in it is returned as the unit's error, as `chains.run_one` does.
`run_chain(refs, out, members)`: `chains.run_chain`, each unit's program trained before the unit.

Interrupted: a program keeps its snapshots (`training.snapshots`, phase "packed", keyed by its seeds' training
keys) in its first seed's `inflight/` folder. A resumed run whose program holds the same seeds continues it
from the last snapshot (a cohort resumes bit for bit: `tests/replication/training/test_snapshots.py`); one
whose seeds differ (a seed stored since, another `--pack-seeds`) starts the program over. Once the seeds are
stored, each one's `inflight/` folder is cleared.
"""
from __future__ import annotations

import logging
from pathlib import Path

from lagbench.files import results as R
from lagbench.replication.run import chains as C
from lagbench.replication.run.gpu_cohorts import MAX_MEMBERS, programs
from lagbench.replication.training import device as dev
from lagbench.replication.training.protocol import canonical_hash
from lagbench.replication.training.snapshots import Snapshots
from lagbench.replication.training.train import _cached, _store, train_cohort, train_key
from lagbench.validate import is_integer

log = logging.getLogger("lagbench")
PHASE = "packed"   # the snapshots' phase name: a seed's own training ("run") never reads a program's


def members(pack_seeds, frameworks, executor: str = "local") -> dict:
    if pack_seeds is not None and (not is_integer(pack_seeds) or pack_seeds < 1):
        raise ValueError(f"--pack-seeds: {pack_seeds!r} is not valid; expected an integer >= 1 (1: each seed "
                         "trains alone)")
    if executor != "local":
        if pack_seeds not in (None, 1):
            raise ValueError("--pack-seeds is for the local executor; with --executor ray each unit is a task "
                             "of its own and trains alone")
        return {fw: 1 for fw in frameworks}
    if pack_seeds is not None:
        return {fw: int(pack_seeds) for fw in frameworks}
    return {fw: MAX_MEMBERS if dev.resolve(dev.request(), fw) == "gpu" else 1 for fw in frameworks}


def by_unit(units, out, members: dict | None) -> dict:
    found = {}
    for fw, n in (members or {}).items():
        if n < 2:
            continue
        for prog in programs([u for u in units if u.framework == fw], out, n):
            if prog.packed and len(prog.seeds) > 1:
                found.update({u.name: prog for u in prog.units})
    return found


def chains(todo, out, members: dict | None) -> list[list]:
    packs = by_unit(todo, out, members)
    merged, at = [], {}   # id(program) -> its chain's index in `merged`
    for chain in C.chains(todo):   # a packable training's chain holds one seed's units: one program's
        prog = next((packs[u.name] for u in chain if u.name in packs), None)
        if prog is None:
            merged.append(chain)
        elif id(prog) in at:
            merged[at[id(prog)]] += chain
        else:
            at[id(prog)] = len(merged)
            merged.append(list(chain))
    return sorted(merged, key=C.cost, reverse=True)


def _folder(out, prog, seed) -> Path:
    return Path(out) / "trained" / prog.framework / train_key(prog.framework, prog.spec, prog.protocol, seed)


def train_program(prog, out, on_log=None) -> None:
    todo = [s for s in prog.seeds if _cached(_folder(out, prog, s)) is None]
    if len(todo) < 2:   # a seed left alone trains as its units ask for it (`training.train.train_cached`)
        return
    key = canonical_hash({"packed": [train_key(prog.framework, prog.spec, prog.protocol, s) for s in todo]}, 20)
    snapshot = Snapshots(_folder(out, prog, todo[0]) / "inflight", key, phase=PHASE)
    where = dev.resolve(dev.request(), prog.framework)
    log.info("training %d seeds of one model as one program: %s", len(todo), todo)
    with dev.placed(prog.framework, where):
        outcomes = train_cohort(prog.framework, prog.spec, prog.protocol, todo, on_log=on_log, snapshot=snapshot)
    for s, o in zip(todo, outcomes, strict=True):
        o.device = dev.describe(prog.framework, where)
        o.cohort = {"seeds": list(todo), "packed": True}
        _store(_folder(out, prog, s), o, prog.spec, prog.protocol, s)
    for s in todo:   # the program's snapshots, and any a seed's own interrupted training left
        Snapshots(_folder(out, prog, s) / "inflight", key).clear()


def program_error(unit, out, program, on_log=None) -> str | None:
    """`unit`'s error if its program (None: none) raised while it trained, else None: the unit runs."""
    if program is None:
        return None
    try:
        train_program(program, out, on_log)
    except R.DiskFull:
        raise   # the run stops, as `chains.run_one` has it
    except Exception as e:  # noqa: BLE001 - as `chains.run_one`: one program's error is its units', not the run's
        log.exception("%s: its packed training failed", unit.name)
        return f"{unit.name}: {type(e).__name__}: {e}"
    return None


def run_chain(refs, out, members: dict | None):
    """In a worker: the chain's units in order -> [(name, failure, error)]."""
    units = [C.unit_of(r) for r in refs]
    packs = by_unit(units, out, members)
    done = []
    for u in units:
        error = program_error(u, out, packs.get(u.name))
        done.append((u.name, None, error) if error else (u.name, *C.run_one(u, out)))
    return done
