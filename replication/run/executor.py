"""Running the units of a plan: one after another in this process, or in parallel worker processes.

`run_units(todo, out, profile, progress=True, jobs=1) -> (failures, errors)`; failures: "<unit>: <reason>"
of units whose training failed (a result is written), errors: "<unit>: <exception>" of units that raised
(no result; a rerun retries them).

jobs = 1: in this process, a progress bar per unit's training. jobs = N > 1: N worker processes (spawned,
so each starts clean), each given one CPU thread for JAX (XLA's Eigen pool off) and for PyTorch and
OpenMP, so that N workers share N cores instead of each spreading over all of them. Units that train the
same model (a claim pair sharing a trained model; a cohort of seeds trained as one program: `training.group_key`)
form one *chain* (`replication.run.chains`, shared with the Ray executor, `replication.run.executor_ray`) run by one worker in order, so the model is trained once and the others read it from the cache; chains go out
longest first (estimated from the training budget in samples, the model's width and the framework), so
that the long ones do not start last. Every unit writes its own files as in a serial run, so a run is
resumable and gives the same numbers either way (training is deterministic given the seed; only wall
times differ). Ctrl-C cancels the chains not yet started and stops the workers. A worker whose driver is
gone (killed, SIGTERM from a scheduler or `timeout`) exits within a second: it would otherwise finish its
chain, hours in the long profiles, writing into a folder that a resumed run may be writing too.
"""
from __future__ import annotations

import os
import threading
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from multiprocessing import get_context

from tqdm.auto import tqdm

from replication.run.chains import TORCH_COST, chains, release_compiled  # noqa: F401 - TORCH_COST, release_compiled: re-exported
from replication.run.chains import cost as _cost  # noqa: F401 - re-exported for the tests
from replication.run.chains import ref as _ref
from replication.run.chains import run_chain as _run_chain
from replication.run.chains import run_one as _one
from replication.run.environment import WORKER_THREADS, one_thread_env
from replication.training.scouting import progress_steps


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


def _exit_with(parent: int, every: float = 1.0):
    """Exit this process once its parent is no longer `parent` (the driver died; we were re-parented)."""
    while os.getppid() == parent:
        time.sleep(every)
    os._exit(1)


def _worker_start(driver: int):
    import torch

    torch.set_num_threads(WORKER_THREADS)
    threading.Thread(target=_exit_with, args=(driver,), daemon=True, name="lagbench-driver-watch").start()


def _parallel(todo, out, profile, progress, jobs):
    work = chains(todo)
    failures, errors = [], []
    one = one_thread_env(os.environ)
    saved = {k: os.environ.get(k) for k in one}
    # inherited by the spawned workers before they import JAX or PyTorch; kept while the pool lives, as
    # the pool starts its processes on demand as chains are submitted
    os.environ.update(one)
    pool = ProcessPoolExecutor(max_workers=jobs, mp_context=get_context("spawn"), initializer=_worker_start,
                               initargs=(os.getpid(),))
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
