"""Running the units of a plan: one after another in this process, or in parallel worker processes.

`run_units(todo, out, profile, progress=True, jobs=1) -> (failures, errors)`; failures: "<unit>: <reason>"
of units whose training failed (a result is written), errors: "<unit>: <exception>" of units that raised
(no result; a rerun retries them).

jobs = 1: in this process, a progress bar per unit's training. jobs = N > 1: N worker processes (spawned,
so each starts clean), each given one CPU thread for JAX (XLA's Eigen pool off) and for PyTorch and
OpenMP, so that N workers share N cores instead of each spreading over all of them. Units that train the
same model (a claim pair sharing a trained model, `training.train_key`) form one *chain* run by one
worker in order, so the model is trained once and the others read it from the cache; chains go out
longest first (estimated from the training budget in samples, the model's width and the framework), so
that the long ones do not start last. Every unit writes its own files as in a serial run, so a run is
resumable and gives the same numbers either way (training is deterministic given the seed; only wall
times differ). Ctrl-C cancels the chains not yet started and stops the workers.
"""
from __future__ import annotations

import gc
import logging
import os
import sys
from concurrent.futures import ProcessPoolExecutor, as_completed
from multiprocessing import get_context

from tqdm.auto import tqdm

from replication.environment import one_thread_env
from replication.scouting import budget_samples, progress_steps

log = logging.getLogger("lagbench")
TORCH_COST = 3.0   # PyTorch's eager LNN step against JAX's compiled one, per sample (measured, 3 x 64 and 3 x 128)


def release_compiled() -> None:
    """Drop JAX's compiled executables after a unit. Every unit compiles its own model's functions, and
    XLA's CPU code is mapped into memory piece by piece: about 190 mappings per model and unit, never
    given back, so a 220-unit quick run exceeded the kernel's 65 530 mappings per process at unit 202 and
    died in LLVM ("Cannot allocate memory"). Cleared, the count stays flat (measured); a unit never
    reuses another's compilations, so nothing is lost."""
    if "jax" in sys.modules:
        sys.modules["jax"].clear_caches()
    gc.collect()


def _one(unit, out, on_log=None):
    """(failure or None, error or None) of running one unit."""
    from replication.units import run_unit

    try:
        d = run_unit(unit, out, on_log=on_log)
    except Exception as e:  # noqa: BLE001 - one unit's error must not lose the rest of the run
        log.exception("%s failed", unit.name)
        return None, f"{unit.name}: {type(e).__name__}: {e}"
    finally:
        release_compiled()
    return (None if d["status"] == "ok" else f"{unit.name}: {d['failure']['message']}"), None


def _serial(todo, out, profile, progress):
    failures, errors = [], []
    bar = tqdm(todo, desc=f"lagbench {profile}", unit="unit", disable=not progress)
    for u in bar:
        bar.set_postfix_str(u.name)
        steps = progress_steps(u.protocol()) if u.entry.train else 0
        inner = tqdm(total=steps, desc=u.name, unit="step", leave=False, disable=not progress or steps == 0)
        last = {"step": -1}

        def on_log(row, inner=inner, last=last):
            inner.update(row["step"] - last["step"])
            last["step"] = row["step"]
            inner.set_postfix(loss=f"{row['loss']:.3g}")
        try:
            failure, error = _one(u, out, on_log)
        finally:
            inner.close()
        failures += [failure] if failure else []
        errors += [error] if error else []
    return failures, errors


def chains(todo) -> list[list]:
    """The units grouped by the model they train (untrained units alone), longest chain first."""
    from replication.training import train_key

    groups: dict = {}
    for u in todo:
        key = train_key(u.framework, u.spec(), u.protocol(), u.seed) if u.entry.train else u.name
        groups.setdefault(key, []).append(u)
    return sorted(groups.values(), key=_cost, reverse=True)


def _cost(chain) -> float:
    u = chain[0]
    if not u.entry.train:
        return 0.0
    width = sum(u.spec().hidden) or 1
    return budget_samples(u.protocol()) * width * (TORCH_COST if u.framework == "torch" else 1.0)


def _worker_start():
    import torch

    torch.set_num_threads(1)


def _ref(u) -> tuple:
    """What names a unit across processes (a claim's rules are closures: they do not pickle)."""
    return u.claim.id, u.entry.label, u.framework, u.seed, u.profile


def _unit(ref):
    from replication.claims import get as get_claim
    from replication.units import Unit

    claim_id, label, framework, seed, profile = ref
    claim = get_claim(claim_id)
    return Unit(claim, next(e for e in claim.models if e.label == label), framework, seed, profile)


def _run_chain(refs, out):
    """In a worker: the chain's units in order -> [(name, failure, error)]."""
    return [(u.name, *_one(u, out)) for u in map(_unit, refs)]


def _parallel(todo, out, profile, progress, jobs):
    work = chains(todo)
    failures, errors = [], []
    one = one_thread_env(os.environ)
    saved = {k: os.environ.get(k) for k in one}
    # inherited by the spawned workers before they import JAX or PyTorch; kept while the pool lives, as
    # the pool starts its processes on demand as chains are submitted
    os.environ.update(one)
    pool = ProcessPoolExecutor(max_workers=jobs, mp_context=get_context("spawn"), initializer=_worker_start)
    bar = tqdm(total=len(todo), desc=f"lagbench {profile} ({jobs} workers)", unit="unit", disable=not progress)
    try:
        futures = {pool.submit(_run_chain, [_ref(u) for u in c], out): c for c in work}
        for f in as_completed(futures):
            try:
                done = f.result()
            except Exception as e:  # noqa: BLE001 - a worker that died loses its chain's units, not the run
                done = [(u.name, None, f"{u.name}: worker stopped: {type(e).__name__}: {e}") for u in futures[f]]
            for name, failure, error in done:
                failures += [failure] if failure else []
                errors += [error] if error else []
                bar.update(1)
                bar.set_postfix_str(name)
    except BaseException:
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    finally:
        bar.close()
        for k, v in saved.items():
            os.environ.pop(k, None) if v is None else os.environ.__setitem__(k, v)
    pool.shutdown()
    return failures, errors


def run_units(todo, out, profile, progress=True, jobs=1):
    if jobs < 1:
        raise ValueError(f"--jobs: {jobs!r} is not valid; expected an integer >= 1")
    if jobs == 1 or len(todo) <= 1:
        return _serial(todo, out, profile, progress)
    return _parallel(todo, out, profile, progress, jobs)
