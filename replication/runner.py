"""`lagbench run`: enumerate units, skip finished ones, run the rest with progress bars, summarise.

A unit is finished when its result.json verifies (checksum and file hashes); anything else (absent,
half-written, corrupt) is (re)run. Units are independent and deterministic given their seed, so an
interrupted run resumes where it stopped and ends with the same numbers as an uninterrupted one.
"""
from __future__ import annotations

import gc
import json
import logging
import sys
import time
from pathlib import Path

from tqdm.auto import tqdm

from replication import environment as env
from replication import results as R
from replication.claims import CLAIMS, PROFILES
from replication.claims import get as get_claim
from replication.evaluations import EVALUATION_VERSION
from replication.units import Unit, run_unit
from replication.verdicts import write_summary

log = logging.getLogger("lagbench")
FRAMEWORKS = ("jax", "torch")


def plan(profile: str, claims=None, frameworks=FRAMEWORKS, seeds: int | None = None, models=None) -> list:
    if profile not in PROFILES:
        raise ValueError(f"unknown profile {profile!r}; valid: {', '.join(PROFILES)}")
    for fw in frameworks:
        if fw not in FRAMEWORKS:
            raise ValueError(f"unknown framework {fw!r}; valid: {', '.join(FRAMEWORKS)}")
    chosen = [get_claim(c) for c in claims] if claims else list(CLAIMS.values())
    units = []
    for claim in chosen:
        n = claim.seeds.get(profile, 1)
        if seeds is not None:  # claims that are deterministic (one seed everywhere) keep one
            n = seeds if max(claim.seeds.values()) > 1 else 1
        for entry in claim.models:
            if (models and entry.label not in models) or profile not in entry.profiles:
                continue
            for fw in frameworks:
                for seed in range(n):
                    units.append(Unit(claim, entry, fw, seed, profile))
    return units


def is_current(unit, out) -> bool:
    """True if the unit's folder holds a verified result of this very protocol, model spec, evaluation
    config and evaluation version. A verified result of another one (the claim or an evaluation routine
    was edited) is kept, renamed `superseded-<time>-seed<k>`, and the unit is rerun (its training comes
    from the cache when the protocol is unchanged): nothing finished is lost or silently overwritten."""
    folder = unit.folder(out)
    try:
        d = R.load_result(folder)
    except R.CorruptResult:
        return False
    cfg = unit.claim.eval_config.get(unit.profile, {})
    # a result that records no evaluation config or version predates them: stale, re-evaluated
    same_eval = (d.get("eval_config") == json.loads(json.dumps(cfg))
                 and d.get("evaluation_version") == EVALUATION_VERSION)
    if d.get("protocol") == unit.protocol().to_dict() and d.get("model_spec") == unit.spec().to_dict() and same_eval:
        return True
    kept = set_aside(folder)
    log.warning("%s: its result was made under another protocol, spec or data; kept as %s and rerun",
                unit.name, kept.name)
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


def release_compiled() -> None:
    """Drop JAX's compiled executables after a unit. Every unit compiles its own model's functions, and
    XLA's CPU code is mapped into memory piece by piece: about 190 mappings per model and unit, never
    given back, so a 220-unit quick run exceeded the kernel's 65 530 mappings per process at unit 202 and
    died in LLVM ("Cannot allocate memory"). Cleared, the count stays flat (measured); a unit never
    reuses another's compilations, so nothing is lost."""
    if "jax" in sys.modules:
        sys.modules["jax"].clear_caches()
    gc.collect()


def estimate_seconds(units, out) -> float:
    """Time 3 training steps of each distinct configuration (after one to compile) and scale up."""
    from replication.training import run_training

    seen, total = {}, 0.0
    for u in units:
        if not u.entry.train or is_current(u, out):
            continue
        p, spec = u.protocol(), u.spec()
        key = (u.framework, spec, p.replace(steps=1))
        if key not in seen:
            probe = p.replace(steps=4, log_every=1, schedule="constant", n_train=max(p.batch * 4, p.batch))
            o = run_training(u.framework, spec, probe, 0)
            walls = [r["wall_s"] for r in o.log]
            seen[key] = (walls[-1] - walls[0]) / max(len(walls) - 1, 1)
        total += seen[key] * p.steps
    return total


def run(profile="quick", out="results/quick", claims=None, frameworks=FRAMEWORKS, seeds=None, models=None,
        progress=True) -> dict:
    out = Path(out)
    units = plan(profile, claims, frameworks, seeds, models)
    R.write_json(out / "claims.json", {"schema": R.SCHEMA, "claims": [c.catalogue() for c in CLAIMS.values()]})
    manifest = {"schema": R.SCHEMA, "profile": profile, "frameworks": list(frameworks), "seeds": seeds,
                "claims": sorted({u.claim.id for u in units}), "models": sorted(models) if models else None,
                # the units this run plans: the report names any that have no result (an unfinished run)
                "planned_units": [u.name for u in units], "versions": env.versions(),
                "hardware": env.hardware(), "commit": env.commit(), "started": env.now(), "finished": None}
    if profile == "paper":
        est = estimate_seconds(units, out)
        print(f"lagbench: the paper profile's training is estimated at {est / 3600:.1f} h on this machine "
              f"({env.hardware()['cpu']}, GPU: {env.hardware()['gpu']}); it resumes if interrupted.", flush=True)
        manifest["estimated_train_s"] = est
    R.write_json(out / "run.json", manifest)
    todo = [u for u in units if not is_current(u, out)]
    log.info("%d units, %d finished, %d to run", len(units), len(units) - len(todo), len(todo))
    failures, errors, t0 = [], [], time.perf_counter()
    bar = tqdm(todo, desc=f"lagbench {profile}", unit="unit", disable=not progress)
    for u in bar:
        bar.set_postfix_str(u.name)
        steps = u.protocol().steps if u.entry.train else 0
        inner = tqdm(total=steps, desc=u.name, unit="step", leave=False, disable=not progress or steps == 0)
        last = {"step": -1}

        def on_log(row, inner=inner, last=last):
            inner.update(row["step"] - last["step"])
            last["step"] = row["step"]
            inner.set_postfix(loss=f"{row['loss']:.3g}")

        try:
            d = run_unit(u, out, on_log=on_log)
        except Exception as e:  # noqa: BLE001 - one unit's error must not lose the rest of the run
            log.exception("%s failed", u.name)
            errors.append(f"{u.name}: {type(e).__name__}: {e}")
            continue
        finally:
            inner.close()
            release_compiled()
        if d["status"] != "ok":
            failures.append(f"{u.name}: {d['failure']['message']}")
    summary = write_summary(out, profile)
    manifest.update(finished=env.now(), wall_time_s=time.perf_counter() - t0, units=len(units),
                    units_run=len(todo), failures=failures, errors=errors)
    R.write_json(out / "run.json", manifest)
    summary = dict(summary, errors=errors)
    return summary
