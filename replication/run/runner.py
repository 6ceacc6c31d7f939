"""`lagbench run`: enumerate units, skip finished ones, run the rest with progress bars, summarise.

A unit is finished when its result.json verifies (checksum and file hashes); anything else (absent,
half-written, corrupt) is (re)run. Units are independent and deterministic given their seed, so an
interrupted run resumes where it stopped and ends with the same numbers as an uninterrupted one.

Nothing is silent or lost: every option is checked (`plan`) and the output folder made before any
work; a unit redone because its folder held a damaged or half-written result is named in a warning
and in run.json's "repaired"; an earlier invocation's run.json is kept as `runs/run-<start>.json`;
Ctrl-C records "interrupted" in run.json before it propagates.

With `pack_seeds` (`--pack-seeds`; on a GPU by default) a model's seeds train as one program and each is stored
under its own training key (`replication.run.packing`).

With `store=True` (`--store`) OUT is kept as a store that git can carry (`replication.run.store`): each
finished unit trimmed, a .gitignore, a unit made under another registration of its claim redone.
"""
from __future__ import annotations

import json
import logging
import time
from pathlib import Path

from lagbench.files import results as R
from lagbench.files.user_data import content_only
from lagbench.models.spec import USER_KIND
from lagbench.replication.claims import CLAIMS, PROFILES, registration, tuned
from lagbench.replication.claims import get as get_claim
from lagbench.replication.claims.base import FRAMEWORKS, run_frameworks
from lagbench.replication.claims.resolved import catalogue, resolved
from lagbench.replication.claims.verdicts import write_summary
from lagbench.replication.evaluation.registry import EVALUATION_VERSION
from lagbench.replication.run import added_models, packing, splits
from lagbench.replication.run import environment as env
from lagbench.replication.run import store as S
from lagbench.replication.run.announce import announce
from lagbench.replication.run.executor import check_jobs, run_units
from lagbench.replication.run.unit_seconds import unit_seconds
from lagbench.replication.run.units import Unit
from lagbench.validate import is_integer

log = logging.getLogger("lagbench")
LONG_PROFILES = ("full", "paper")   # profiles that print their units and an estimated duration first


def _once(option: str, values) -> None:
    twice = sorted({v for v in values if list(values).count(v) > 1})
    if twice:
        raise ValueError(f"{option}: {', '.join(twice)} given more than once; name each at most once")


def plan(profile: str, claims=None, frameworks=None, seeds: int | tuple | None = None, models=None,
         split: str = "dev", added=()) -> list:
    """The units of a run: each claim's models as they run under the profile (`claims.resolved.resolved`); a
    ValueError naming the option if any is invalid or nothing would run. `frameworks`: None for the profile's
    (`PROFILE_FRAMEWORKS`). `seeds`: None for the profile's, a count (the split's first seeds) or the seeds
    themselves (a list of the split's). `added`: a user's models (`replication.run.added_models.Added`), each entering the
    claims it fits, in its own framework (named in `frameworks` where those are given)."""
    if profile not in PROFILES:
        raise ValueError(f"unknown profile {profile!r}; valid: {', '.join(PROFILES)}")
    given = frameworks is not None
    frameworks = run_frameworks(profile, frameworks)
    splits.get(split)
    for fw in frameworks:
        if fw not in FRAMEWORKS:
            raise ValueError(f"unknown framework {fw!r}; valid: {', '.join(FRAMEWORKS)}")
    if not frameworks:
        raise ValueError(f"--frameworks: none given; valid: {', '.join(FRAMEWORKS)}")
    _once("--frameworks", frameworks)
    _once("--claims", claims or ())
    _once("--models", models or ())
    listed = isinstance(seeds, list | tuple)   # the seeds themselves, else how many
    if listed:
        outside = [s for s in seeds if not (is_integer(s) and splits.get(split).holds(s))]
        first = splits.get(split).first_seed
        if not seeds or outside:
            raise ValueError(f"--seeds: {', '.join(map(str, outside)) or 'none given'}: not seeds of the {split} "
                             f"split; expected integers from {first} to {first + splits.SEEDS_PER_SPLIT - 1}")
    elif seeds is not None and (not is_integer(seeds) or not 1 <= seeds <= splits.SEEDS_PER_SPLIT):
        raise ValueError(f"--n-seeds: {seeds!r} is not valid; expected an integer from 1 to "
                         f"{splits.SEEDS_PER_SPLIT} (a split's seeds; or leave it out for the profile's)")
    chosen = [get_claim(c) for c in claims] if claims else list(CLAIMS.values())
    extra = {c.id: [e for a in added for e in added_models.entries(c, a, profile)] for c in chosen}
    for a in added if given else ():
        if a.framework not in frameworks:
            raise ValueError(f"--add-model {a.name}: it runs in {a.framework} (its own framework: PyTorch for a "
                             f"torch.nn.Module, JAX for an equinox Module); add {a.framework} to --frameworks")
    labels = sorted({e.label for c in chosen for e in (*c.models, *extra[c.id])})
    unknown = sorted(set(models or ()) - set(labels))
    if unknown:
        raise ValueError(f"--models: unknown {', '.join(unknown)} for the chosen claims; valid: {', '.join(labels)}")
    units = []
    for claim in chosen:
        run = resolved(claim, profile)
        n = run.seeds
        if seeds is not None:  # claims that are deterministic (one seed everywhere) keep one
            n = (len(seeds) if listed else seeds) if max(claim.seeds.values()) > 1 else 1
        numbers = list(dict.fromkeys(seeds))[:n] if listed else splits.get(split).seeds(n)
        for entry in (*(m.entry for m in run.models), *extra[claim.id]):
            if (models and entry.label not in models) or not entry.runs_in(profile):
                continue
            for fw in ((added_models.framework(entry),) if entry.spec.get("kind") == USER_KIND else frameworks):
                for seed in numbers:
                    units.append(Unit(claim, entry, fw, seed, profile))
    if not units:
        raise ValueError(f"nothing to run: no model of the chosen claims and --models runs under profile "
                         f"{profile!r}; see `lagbench list`")
    return units


def is_current(unit, out, repairs: list | None = None, set_stale_aside: bool = True,
               registration: dict | None = None) -> bool:
    """True if the unit's folder holds a verified result of this very protocol, model spec, evaluation
    config and evaluation version; with `registration` (a store's run: `replication.run.store`), made under
    its claim's registration of now too (the dict: the registration hashes computed so far). A folder that
    holds no verified result is redone; with `repairs`, one that exists (damaged or interrupted) is logged
    and listed there. A verified result of another one (the claim or an evaluation routine was edited) is
    kept, renamed `superseded-<time>-seed<k>`, and the unit is rerun (its training comes from the cache when
    the protocol is unchanged): nothing finished is lost or silently overwritten."""
    folder = unit.folder(out)
    try:
        d = R.load_result(folder)
    except R.CorruptResult as e:
        if folder.exists() and repairs is not None:  # half-written or damaged: named, then redone
            reason = str(e) if (folder / "result.json").exists() else "interrupted (no result.json)"
            log.warning("lagbench: redoing %s: %s", unit.name, reason)
            repairs.append(f"{unit.name}: {reason}")
        return False
    cfg = unit.claim.evaluation_config(unit.profile)
    # a result that records no evaluation config or version predates them: stale, re-evaluated; a user's
    # file counts by its content, not its path (a moved folder, a renamed copy)
    same_eval = (content_only(d.get("eval_config")) == content_only(json.loads(json.dumps(cfg)))
                 and d.get("evaluation_version") == EVALUATION_VERSION)
    if (d.get("split", "dev") == unit.split and content_only(d.get("protocol")) == content_only(unit.protocol().to_dict())
            and d.get("model_spec") == unit.spec().to_dict() and same_eval
            and (registration is None or S.same_registration(d, unit, registration))):
        return True
    if not set_stale_aside:   # a look only (--dry-run): nothing renamed
        return False
    kept = set_aside(folder)
    log.warning("lagbench: %s: its result was made under another protocol, spec or data; kept as %s "
                "and rerun", unit.name, kept.name)
    return False


def set_aside(folder: Path) -> Path:
    """Rename `folder` to `superseded-<time>-<name>` (with a counter if that exists): never clobbered."""
    stamp = env.now().replace(":", "").replace("-", "")
    for i in range(1000):
        target = folder.with_name(f"superseded-{stamp}{f'.{i}' if i else ''}-{folder.name}")
        if not target.exists():
            folder.rename(target)
            return target
    raise FileExistsError(f"{folder}: no free superseded-{stamp}.* name")


def keep_previous_record(out: Path) -> Path | None:
    """Copy an earlier invocation's run.json to `runs/run-<its start>.json` before it is replaced, so
    the record of every attempt (what it planned, repaired, failed, or that it was interrupted) stays."""
    try:
        raw = (out / "run.json").read_bytes()
        started = str(json.loads(raw).get("started") or env.now())
    except (OSError, ValueError, AttributeError):
        return None
    stamp = "".join(ch for ch in started if ch.isalnum())
    for i in range(1000):
        target = out / "runs" / f"run-{stamp}{f'.{i}' if i else ''}.json"
        if not target.exists():
            R.atomic_write_bytes(target, raw)
            return target
    return None


def executor_of(executor, jobs, address):
    """`(todo, out, profile, progress) -> (failures, errors)` of --executor (checked before any work)."""
    if executor == "local":
        if address is not None:
            raise ValueError("--address is for --executor ray; the local executor runs on this machine")
        return lambda todo, out, profile, progress, **kw: run_units(todo, out, profile, progress, jobs, **kw)
    if executor == "ray":
        from lagbench.replication.run.executor_ray import check_address, require_ray, run_units_ray

        if jobs != 1:
            raise ValueError("--jobs is for the local executor; with --executor ray every unit is a task on "
                             "the Ray cluster's CPUs")
        require_ray()
        check_address(address)
        return lambda todo, out, profile, progress, on_done=None, **kw: run_units_ray(todo, out, profile, progress,
                                                                                  address, on_done=on_done)
    raise ValueError(f"--executor: unknown {executor!r}; valid: local, ray")


@R.writes
def run(profile="quick", out="results/quick", claims=None, frameworks=None, seeds=None, models=None,
        progress=True, jobs=1, executor="local", address=None, dry_run=False, split=splits.RUN_DEFAULT,
        add_models=(), store=False, pack_seeds=None) -> dict:
    """`add_models`: "NAME=module:factory" strings (`replication.run.added_models`). `store`: keep OUT as a
    store git can carry (`replication.run.store`): trimmed units, a .gitignore, a unit made under another
    registration redone; its size printed at the end. `pack_seeds`: up to that many seeds of a model trained
    as one program (`replication.run.packing`; None: `gpu_cohorts.MAX_MEMBERS` on a GPU, 1 on the CPU)."""
    check_jobs(jobs)
    execute = executor_of(executor, jobs, address)
    if not dry_run:   # a folder another command is writing into is refused before the planning, not after it
        R.refuse_if_locked(out, "--out")
    added = added_models.parse(add_models, {e.label for c in CLAIMS.values() for e in c.models})
    units = plan(profile, claims, frameworks, seeds, models, split, added)
    members = packing.members(pack_seeds, sorted({u.framework for u in units}), executor)
    memo = {} if store else None   # a store's units: their registration hashes too
    if dry_run:   # the plan and the estimate only; nothing is written (the probes train in memory)
        todo = [u for u in units if not is_current(u, out, set_stale_aside=False, registration=memo)]
        if todo:
            estimate = announce(profile, units, todo, out, jobs, executor, members=members)
        else:   # said, not left to silence: a finished folder is an answer too
            estimate = None
            print(f"lagbench: profile {profile}: {len(units)} units, every one finished in {out}: "
                  "nothing to run", flush=True)
        return {"dry_run": True, "units": len(units), "todo": len(todo), "estimate": estimate}
    out = R.output_folder(out, "--out")
    if store:
        S.prepare(out)
    R.write_json(out / "claims.json", {"schema": R.SCHEMA, "claims": [catalogue(c, profile) for c in CLAIMS.values()]})
    manifest = {"schema": R.SCHEMA, "profile": profile, "split": split,
                "frameworks": list(run_frameworks(profile, frameworks)), "seeds": seeds,
                "claims": sorted({u.claim.id for u in units}), "models": sorted(models) if models else None,
                "added_models": [{"name": a.name, "factory": a.ref, "factory_source": a.source,
                                  "framework": a.framework} for a in added],
                # the units this run plans: the report names any that have no result (an unfinished run)
                "planned_units": [u.name for u in units], "jobs": jobs, "executor": executor,
                "pack_seeds": members, "versions": env.versions(),
                "hardware": env.hardware(), "commit": env.commit(), "started": env.now(), "finished": None}
    keep_previous_record(out)
    R.write_json(out / "run.json", manifest)
    repairs: list = []
    todo = [u for u in units if not is_current(u, out, repairs, registration=memo)]
    manifest["repaired"] = repairs
    by_group = None   # the estimate's seconds per training, what the progress bar advances by
    if profile in LONG_PROFILES and todo:
        manifest["estimate"] = announce(profile, units, todo, out, jobs, executor, keep=True, members=members)
        by_group = manifest["estimate"].pop("by_group", None)
        R.write_json(out / "run.json", manifest)
    log.info("%d units, %d finished, %d to run", len(units), len(units) - len(todo), len(todo))
    t0 = time.perf_counter()
    try:
        failures, errors = execute(todo, out, profile, progress, seconds=unit_seconds(todo, out, by_group),
                                   on_done=(lambda u: S.keep_unit(u.folder(out))) if store else None,
                                   members=members)
    except KeyboardInterrupt:
        manifest.update(interrupted=env.now(), wall_time_s=time.perf_counter() - t0)
        R.write_json(out / "run.json", manifest)
        raise
    except R.DiskFull as e:
        manifest.update(stopped={"reason": "no space left on device", "path": e.filename, "at": env.now()},
                        wall_time_s=time.perf_counter() - t0)
        try:   # it may not fit either; the message says what happened all the same
            R.write_json(out / "run.json", manifest)
        except OSError:
            pass
        raise
    finally:
        if store:   # whatever ended the run, its finished units are trimmed before a commit can take them
            S.prune(out)
    summary = write_summary(out, profile, split, registration.registrations(), tuned.records())
    manifest.update(finished=env.now(), wall_time_s=time.perf_counter() - t0, units=len(units),
                    units_run=len(todo), failures=failures, errors=errors)
    if store:
        manifest["store"] = {"bytes": S.size(out), "budget_mb": S.BUDGET_MB}
        print(S.size_line(out), flush=True)
    R.write_json(out / "run.json", manifest)
    return dict(summary, errors=errors, repaired=repairs)
