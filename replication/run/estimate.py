"""How long a run will take, told before it starts: each distinct training is probed for a few steps.

`estimate(units, out, jobs, torch_threads=None)` counts every training the run still has to do once
(units that share a trained model, such as claims 1 and 2, train it once; a training already in
`OUT/trained/` costs nothing), times seven steps of each distinct configuration on this machine after one
step to compile and takes their median (the scouts of a protocol with restarts, and a cohort of seeds, are
timed as they run: K members side by side), and scales up by the protocol's steps. Evaluation time is not
included. The wall time replays the executor's schedule (`scheduled_wall`): the chains of
`replication.run.chains.chains`, longest first by its cost, each to the first of `jobs` workers to come free
(spreading the trainings evenly would call three trainings of 0.33 h on two workers 0.5 h, where the run
takes two rounds).

The probes run on the device the units will train on (`replication.training.device`, from LAGBENCH_DEVICE),
and PyTorch at `torch_threads` intra-op threads: the setting of the processes that will train
the units (`environment.worker_torch_threads`: one per worker or Ray task; None: this process's own, where
one local job trains them here): probed at another thread count than the workers', a step on busy cores
can take many times as long (measurements: `docs/decisions/run_estimate.md`). Where the workers run on one
thread, JAX is probed on one too (`environment.one_thread_jax`, which starts this process's JAX backend on
one CPU). What the estimate leaves out: two workers slow each other down (two JAX LNNs of claim 1 on one
thread each: 1.05-1.12 x the step of one alone), evaluation, and the first step of a PyTorch phase under
torch.compile (`compile_torch.like`: the probe compiles as the phase will), which compiles.

Where the run packs seeds (`members`: {framework: seeds a program}, `replication.run.packing.members`, more than
one for some framework), or where every framework of the run trains on a GPU (then at up to
`gpu_cohorts.MAX_MEMBERS`, what `--pack-seeds` gives there by default), the estimate also holds "cohorts": the
run with each model's seeds packed into programs (`gpu_cohorts.programs`). A packed program's seconds are the
probed seconds per step of its k members side by side (one member: the plain probe) x its protocol's steps; a
program whose protocol cannot be packed (`gpu_cohorts.blocker`) costs what the plain estimate gives its training
program; their sum is "train_s", and "wall_s" hands the programs, longest first, each to the first of `jobs`
workers to come free (`scheduled_wall`).

`describe(units, todo)`: one line per claim, with its models, seeds and how many units remain.
"""
from __future__ import annotations

import json
from collections import Counter, defaultdict
from pathlib import Path

import numpy as np

from lagbench.files import results as R
from lagbench.replication.run import environment as env
from lagbench.replication.run import gpu_cohorts
from lagbench.replication.run.chains import chains
from lagbench.replication.run.environment import torch_threads as threads_of_torch
from lagbench.replication.training import compile_torch
from lagbench.replication.training import device as dev
from lagbench.replication.training.schedules import Constant
from lagbench.replication.training.scouting import continuation_protocol, scout_parts, scout_protocol
from lagbench.replication.training.train import group_key, run_training, train_cohort, train_key

PROBE_STEPS = 8   # the first is discarded (compilation); the median of the other seven steps' times


def _per_step(rows) -> float:
    """The median time of a step after the first: on a shared machine one step can take several times
    the others, and the mean of three let it move an estimate."""
    walls = [r["wall_s"] for r in rows if r.get("member", 0) == 0]
    return float(np.median(np.diff(walls))) if len(walls) > 1 else 0.0


def _plain_step(framework, spec, protocol) -> float:
    phase = continuation_protocol(protocol)
    p = phase.replace(steps=PROBE_STEPS, log_every=1, schedule=Constant(phase.schedule.lr), tracking=None,
                      **{"data.n_train": protocol.batch * PROBE_STEPS})
    # PyTorch's probe steps compiled where the phase's are, on the device the run trains on
    with compile_torch.like(spec, phase), dev.placed(framework, dev.resolve(dev.request(), framework)):
        return _per_step(run_training(framework, spec, p, 0).log)


def _members_step(framework, spec, protocol, k: int) -> float:
    """Seconds per step of `k` members side by side (scouts, or a cohort of seeds)."""
    p = protocol.replace(steps=PROBE_STEPS, log_every=1, schedule=Constant(protocol.schedule.lr), cohort=None,
                         tracking=None, **{"data.n_train": protocol.batch * PROBE_STEPS})
    rows = []
    with compile_torch.like(spec, protocol, k), dev.placed(framework, dev.resolve(dev.request(), framework)):
        train_cohort(framework, spec, p, list(range(k)), on_log=rows.append)
    return _per_step(rows)


# what does not change the cost of a step: the init, the step counts, the rates and the pool sizes (the
# probes leave held-out tracking off: its evaluations, the first one compiling, would count as step time)
_FREE = ("steps", "log_every", "n_train", "n_heldout", "schedule", "tracking")


def _shape(framework, spec, protocol) -> str:
    p = {k: v for k, v in protocol.to_dict().items() if k not in _FREE}
    p["data"] = {k: v for k, v in p["data"].items() if k not in _FREE}
    if p["scouting"]:   # the scouts' count and batch set the cost of their steps
        p["scouting"] = {k: v for k, v in p["scouting"].items() if k not in _FREE}
    return json.dumps([framework, {**spec.to_dict(), "init": ""}, p], sort_keys=True, default=str)


def estimate(units, out, jobs: int = 1, torch_threads: int | None = None, keep: bool = False,
             members: dict | None = None) -> dict:
    """{"train_s": summed seconds, "wall_s": with `jobs` workers, "trainings": to do, "cached": reused,
    "probes": configurations timed, "probes_reused": of those, read from OUT's `PROBES` file, "by_claim":
    {claim id: seconds}, "by_group": {training program: seconds}}. A training that several claims share
    (claims 1, 2 and 11 train the same double-pendulum models) counts for the first claim planned with it.
    `keep`: write this machine's probes to OUT/`PROBES`, so that a resumed run on the same machine reuses them
    rather than probing again. `members`: {framework: seeds a program} of a packed run (module docstring).
    `torch_threads` given (the units train in workers): JAX is probed on one thread as well."""
    threads = torch_threads if any(u.framework == "torch" for u in units) else None
    jax_threads = None   # this process's own, where one local job trains the units here
    if torch_threads is not None and any(u.framework == "jax" for u in units):
        jax_threads = env.WORKER_THREADS if env.one_thread_jax() else "every core"
    known = _read_probes(out, threads, jax_threads)
    with threads_of_torch(threads):
        est = _estimate(units, out, jobs, known)
        packs = _packs(units, members)
        if packs:
            est["cohorts"] = _packed(units, out, jobs, known, est["by_group"], packs)
    if keep:
        R.write_json(Path(out) / PROBES, {"machine": _machine(threads, jax_threads), "per_step": {
            k: [plain, {str(m): s for m, s in members.items()}] for k, (plain, members) in known.items()}})
    return est


# OUT's record of the probes (seconds per step of each configuration's shape), with the machine they ran on
PROBES = "estimate_probes.json"


# each framework's threads in the record: a change to one probes that framework's configurations again
THREADS = {"torch": "torch_threads", "jax": "jax_threads"}


def _machine(torch_threads, jax_threads=None) -> dict:
    """What a probe's time depends on besides the configuration: the hardware, the device the run trains
    on, PyTorch's and JAX's threads and the versions of the frameworks."""
    hw = env.hardware()
    return {**{k: hw.get(k) for k in ("cpu", "cpu_model", "cpu_features", "cores", "gpu")},
            "device": dev.request(), "torch_threads": torch_threads, "jax_threads": jax_threads,
            "probe_steps": PROBE_STEPS,
            **{k: v for k, v in env.versions().items() if k in ("python", "jax", "jaxlib", "torch")}}


def _read_probes(out, torch_threads, jax_threads=None) -> dict:
    """The probes of OUT's record when they ran on this machine as it is now (else none), of the frameworks
    whose threads are as they are now."""
    try:
        rec = json.loads((Path(out) / PROBES).read_text())
        was, now = rec["machine"], json.loads(json.dumps(_machine(torch_threads, jax_threads)))
        if {k: v for k, v in was.items() if k not in THREADS.values()} != \
                {k: v for k, v in now.items() if k not in THREADS.values()}:
            return {}
        same = {fw for fw, key in THREADS.items() if was.get(key) == now[key]}
        return {k: (float(plain), {int(m): float(x) for m, x in members.items()})
                for k, (plain, members) in rec["per_step"].items() if json.loads(k)[0] in same}
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return {}   # none, unreadable or of another form: probed again


def _estimate(units, out, jobs: int, per_step: dict) -> dict:
    """`per_step` {shape: (plain, {members: seconds})}: probes already known; the new ones are added to it."""
    todo, cached, owner, reused, used = {}, 0, {}, set(), set()
    for u in units:
        if not u.entry.train:
            continue
        p, spec = u.protocol(), u.spec()
        group = _group(u)   # a cohort of seeds trains as one program
        if group in todo:
            continue
        owner[group] = (u.claim.id, u.entry.label, u.framework)
        if (Path(out) / "trained" / u.framework / train_key(u.framework, spec, p, u.seed) / "result.json").exists():
            cached += 1
            todo[group] = 0.0
            continue
        shape = _shape(u.framework, spec, p)   # the same step for another seed, init or budget costs the same
        reused |= {shape} if shape in per_step and shape not in used else set()
        used.add(shape)
        if shape not in per_step:
            if p.cohort:
                per_step[shape] = (_members_step(u.framework, spec, p, p.cohort), {})
            else:   # a step of each scouting part's member count (`scout_parts`)
                per_step[shape] = (_plain_step(u.framework, spec, p),
                                   {m: _members_step(u.framework, spec, scout_protocol(p), m) for m, _ in scout_parts(p)})
        plain, members = per_step[shape]
        todo[group] = plain * p.steps + sum(members[m] * n for m, n in scout_parts(p))
    total = sum(todo.values())
    in_order = [todo.get(_group(c[0]), 0.0) for c in chains(units)]
    by_claim, by_model = {}, {}
    for group, seconds in todo.items():
        claim, label, framework = owner[group]
        by_claim[claim] = by_claim.get(claim, 0.0) + seconds
        by_model[(claim, label, framework)] = by_model.get((claim, label, framework), 0.0) + seconds
    return {"train_s": total, "wall_s": scheduled_wall(in_order, jobs),
            "trainings": sum(1 for v in todo.values() if v > 0), "cached": cached,
            "probes": len(used), "probes_reused": len(reused),
            "by_claim": dict(sorted(by_claim.items(), key=lambda kv: -kv[1])),
            "by_model": dict(sorted(by_model.items(), key=lambda kv: -kv[1])),   # (claim, model, framework)
            "by_group": todo}   # seconds per training program (`training.group_key`): the progress bar's weights


def _on_gpu(units) -> bool:
    """Whether every framework that trains a unit trains on a GPU (`replication.training.device`)."""
    fws = {u.framework for u in units if u.entry.train}
    return bool(fws) and all(dev.resolve(dev.request(), fw) == "gpu" for fw in fws)


def _packs(units, members: dict | None) -> dict:
    """{framework: seeds a program} the estimate packs: the run's own where it packs more than one seed of
    some framework, else `gpu_cohorts.MAX_MEMBERS` where every framework trains on a GPU, else none."""
    fws = sorted({u.framework for u in units if u.entry.train})
    if members and any(members.get(fw, 1) > 1 for fw in fws):
        return {fw: members.get(fw, 1) for fw in fws}
    return {fw: gpu_cohorts.MAX_MEMBERS for fw in fws} if _on_gpu(units) else {}


def _packed(units, out, jobs: int, per_step: dict, alone: dict, packs: dict) -> dict:
    """{"train_s", "wall_s", "programs", "members": the most seeds a program, "seconds": per program, longest
    first} of the run with seeds packed (`gpu_cohorts.programs`, each framework at its `packs` seeds a
    program); `per_step` as `_estimate`'s, the probes of k members side by side added to each shape's members;
    `alone`: `_estimate`'s seconds per training program."""
    seconds, most = [], 0
    progs = [p for fw, k in packs.items() for p in gpu_cohorts.programs([u for u in units if u.framework == fw], out, k)]
    for prog in progs:
        if not prog.packed:
            seconds.append(alone[group_key(prog.framework, prog.spec, prog.protocol, prog.seeds[0])])
            continue
        k, shape = len(prog.seeds), _shape(prog.framework, prog.spec, prog.protocol)
        plain, members = per_step[shape]   # `_estimate` probed every shape of the run's trainings
        if k > 1 and k not in members:
            members[k] = _members_step(prog.framework, prog.spec, prog.protocol, k)
        seconds.append((members[k] if k > 1 else plain) * prog.protocol.steps)
        most = max(most, k)
    seconds.sort(reverse=True)
    return {"train_s": sum(seconds), "wall_s": scheduled_wall(seconds, jobs), "programs": len(seconds),
            "members": most, "seconds": seconds}


def _group(u):
    return group_key(u.framework, u.spec(), u.protocol(), u.seed) if u.entry.train else None


def scheduled_wall(seconds, jobs: int) -> float:
    """When the last of these jobs ends, given in the order they are handed out, each to the first of `jobs`
    workers to come free (as a process pool takes them)."""
    free = [0.0] * max(jobs, 1)
    for s in seconds:
        i = free.index(min(free))
        free[i] += s
    return max(free)


def describe(units, todo) -> str:
    """One line per claim: models, seeds and frameworks planned, and how many units remain to run."""
    left = Counter(u.claim.id for u in todo)
    by = defaultdict(list)
    for u in units:
        by[u.claim.id].append(u)
    lines = []
    for cid, us in by.items():
        models = sorted({u.entry.label for u in us})
        fws = sorted({u.framework for u in us})
        seeds = len({u.seed for u in us})
        lines.append(f"  {cid:<17} {len(us):>3} units ({left[cid]} to run): {', '.join(models)}; "
                     f"{seeds} seed{'s' if seeds != 1 else ''}; {', '.join(fws)}")
    return "\n".join(lines)
