"""Running the units of a plan: one after another in this process, or in parallel worker processes.
A full disk (`results.DiskFull`) stops either at once: every later unit would fail to store its result.

`run_units(todo, out, profile, progress=True, jobs=1, seconds=None, on_done=None, members=None) -> (failures,
errors)`; failures: "<unit>: <reason>" of units whose training failed (a result is written), errors: "<unit>:
<exception>" of units that raised (no result; a rerun retries them). `members` ({framework: N},
`replication.run.packing.members`): a model's seeds packed N to a program (`--pack-seeds`), trained as one
before the first of its units runs; None or 1: each seed alone.

The run's progress bar advances by each unit's estimated seconds (`replication.run.unit_seconds`, given as
`seconds`), credited as the unit runs (`unit_seconds.InFlight`), so that its remaining time is the work left
at the run's pace; `on_done(unit)` is told of each unit whose run ended
(a store trims the unit's folder: `replication.run.store`).
`check_jobs(jobs)`: the one check of a worker count (`lagbench run`, `tune`, `verify`).

jobs = 1: in this process, a progress bar per unit's training. jobs = N > 1: N worker processes (spawned,
so each starts clean), each given one CPU thread for JAX (its backend started on one CPU:
`environment.one_thread_jax`) and for PyTorch and
OpenMP, so that N workers share N cores instead of each spreading over all of them. Units that train the
same model (a claim pair sharing a trained model; a cohort of seeds trained as one program: `training.group_key`)
form one *chain* (`replication.run.chains`, shared with the Ray executor, `replication.run.executor_ray`; a packed
program's units one chain too, `replication.run.packing.chains`) run by one worker in order, so the model is
trained once and the others read it from the cache; chains go out
longest first (estimated from the training budget in samples, the model's width and the framework), so
that the long ones do not start last. Every unit writes its own files as in a serial run, so a run is
resumable and gives the same numbers either way up to float32 rounding (training is deterministic given the
seed and the thread count; a worker's one thread sums in another order than this process's threads), and at
N > 1 every unit trains in a worker, a lone one too, so that a run keeps one rounding. Each worker holds one
chain at a time; one that dies (the out-of-memory killer, a `kill`) loses that chain's units alone, each named
as an error (no result; a rerun retries it), and a new worker takes the next chain. Ctrl-C cancels the chains
not yet started and stops the workers. A worker whose driver is gone (killed, SIGTERM from a scheduler or
`timeout`) exits within a second: it would otherwise finish its chain, hours in the long profiles, writing into
a folder that a resumed run may be writing too.
"""
from __future__ import annotations

import os
import queue
import signal
from multiprocessing import get_context

from tqdm.auto import tqdm

from lagbench.files.results import DiskFull
from lagbench.replication.run import packing
from lagbench.replication.run.chains import TORCH_COST, chains, release_compiled  # noqa: F401 - TORCH_COST, chains, release_compiled: re-exported
from lagbench.replication.run.chains import cost as _cost  # noqa: F401 - re-exported for the tests
from lagbench.replication.run.chains import ref as _ref
from lagbench.replication.run.chains import run_one as _one
from lagbench.replication.run.environment import one_thread_children, worker_start
from lagbench.replication.run.unit_seconds import InFlight
from lagbench.replication.training.scouting import progress_steps


def _bar(seconds, desc, progress):
    """The run's bar: it advances by each unit's estimated seconds (`unit_seconds`, credited as the unit runs:
    `InFlight`), so that its remaining time is the work left at the run's own pace; the units done are
    counted in its postfix."""
    return tqdm(total=sum(seconds), desc=desc, disable=not progress, smoothing=0,
                bar_format="{desc}: {percentage:3.0f}%|{bar}| [{elapsed}<{remaining}{postfix}]")


def _serial(todo, out, profile, progress, seconds, on_done, members):
    failures, errors = [], []
    packs = packing.by_unit(todo, out, members)
    bar = _bar(seconds, f"lagbench {profile}", progress)
    credit = InFlight(bar)
    try:
        for i, (u, weight) in enumerate(zip(todo, seconds, strict=True)):
            bar.set_postfix_str(f"{i}/{len(todo)} units; {u.name}")
            credit.start(i, weight)
            steps = progress_steps(u.protocol()) if u.entry.train else 0
            inner = tqdm(total=steps, desc=u.name, unit="step", leave=False, disable=not progress or steps == 0)
            last = {"step": -1}

            def on_log(row, inner=inner, last=last):
                credit.tick()
                inner.update(row["step"] - last["step"])
                last["step"] = row["step"]
                inner.set_postfix(loss=f"{row['loss']:.3g}")
            try:
                error = packing.program_error(u, out, packs.get(u.name), on_log)
                failure, error = (None, error) if error else _one(u, out, on_log)
            finally:
                inner.close()
            failures += [failure] if failure else []
            errors += [error] if error else []
            credit.end(i)
            on_done(u)
        bar.set_postfix_str(f"{len(todo)}/{len(todo)} units")
    finally:
        bar.close()
    return failures, errors


def _worker_loop(driver: int, tasks, results):
    """A worker process: chains from `tasks` (None: stop), each answered on `results` as (chain id, done,
    error); a chain's packed programs (`members`) train before its first unit that reads them."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)   # Ctrl-C is the driver's: it stops the workers
    worker_start(driver)
    while (item := tasks.get()) is not None:
        cid, refs, out, members = item
        try:
            results.put((cid, packing.run_chain(refs, out, members), None, None))
        except DiskFull as e:   # the driver stops the run
            results.put((cid, None, None, (e.errno, e.strerror, e.filename)))
        except Exception as e:  # noqa: BLE001 - reported for this chain; the worker goes on
            results.put((cid, None, f"{type(e).__name__}: {e}", None))


class _Workers:
    """`jobs` worker processes (spawned on demand), each with its own task queue and one chain at a time.
    A worker that dies (the out-of-memory killer, a `kill`) loses only the chain it held: `dead()` names it
    and the next `assign` starts a replacement."""

    def __init__(self, jobs):
        self.ctx, self.jobs = get_context("spawn"), jobs
        self.results = self.ctx.Queue()
        self.slots = []   # [process, task queue, chain id or None]

    def idle(self):
        self.slots = [s for s in self.slots if s[2] is not None or s[0].is_alive()]   # an idle one that died
        free = [s for s in self.slots if s[2] is None]
        if not free and len(self.slots) < self.jobs:
            q = self.ctx.Queue()
            proc = self.ctx.Process(target=_worker_loop, args=(os.getpid(), q, self.results), daemon=True)
            proc.start()
            self.slots.append([proc, q, None])
            free = [self.slots[-1]]
        return free[0] if free else None

    def assign(self, slot, cid, refs, out, members=None):
        slot[2] = cid
        slot[1].put((cid, refs, out, members))

    def busy(self) -> bool:
        return any(s[2] is not None for s in self.slots)

    def finished(self, cid):
        for s in self.slots:
            if s[2] == cid:
                s[2] = None

    def dead(self) -> list:
        """[(chain id, exit code)] of busy workers that died; their slots are freed for a replacement."""
        out = []
        for s in list(self.slots):
            if s[2] is not None and not s[0].is_alive():
                out.append((s[2], s[0].exitcode))
                self.slots.remove(s)
        return out

    def close(self, wait: bool):
        for proc, q, _ in self.slots:
            if wait and proc.is_alive():
                q.put(None)
            else:
                proc.terminate()
        for proc, _, _ in self.slots:
            proc.join(timeout=10 if wait else 2)


def _parallel(todo, out, profile, progress, jobs, seconds, on_done, members):
    work = packing.chains(todo, out, members)
    failures, errors, count = [], [], 0
    weight = {id(u): w for u, w in zip(todo, seconds, strict=True)}
    # the spawned workers start on demand as chains are handed out, each on one thread
    with one_thread_children():
        workers = _Workers(jobs)
        bar = _bar(seconds, f"lagbench {profile} ({jobs} workers)", progress)
        credit = InFlight(bar)
        pending, held = list(enumerate(work)), {}

        def record(done, cid, chain):
            """A chain's outcomes; the rest of its units' estimated seconds on the bar; `on_done` told of each
            unit (one that finished before its worker stopped has its result)."""
            nonlocal failures, errors, count
            for _name, failure, error in done:
                failures += [failure] if failure else []
                errors += [error] if error else []
            count += len(chain)
            credit.end(cid)
            bar.set_postfix_str(f"{count}/{len(todo)} units; {chain[-1].name}")
            for u in chain:
                on_done(u)
        try:
            while pending or held:
                while pending and (slot := workers.idle()) is not None:
                    cid, chain = pending.pop(0)
                    held[cid] = chain
                    credit.start(cid, sum(weight[id(u)] for u in chain))
                    workers.assign(slot, cid, [_ref(u) for u in chain], out, members)
                credit.tick()
                try:
                    cid, done, error, full = workers.results.get(timeout=0.5)
                except queue.Empty:
                    # a worker that died loses the chain it held, not the run
                    for cid, code in workers.dead():
                        lost = held.pop(cid)
                        record([(u.name, None, f"{u.name}: worker stopped (exit code {code}); a rerun retries it")
                                for u in lost], cid, lost)
                    continue
                if full is not None:
                    raise DiskFull(*full)
                chain = held.pop(cid, None)
                workers.finished(cid)
                if chain is not None:
                    record(done if error is None else [(u.name, None, f"{u.name}: worker error: {error}") for u in chain],
                           cid, chain)
        except BaseException:
            workers.close(wait=False)
            raise
        finally:
            bar.close()
    workers.close(wait=True)
    return failures, errors


def check_jobs(jobs) -> None:
    """Refuse a worker count that is not an integer >= 1, in one line naming --jobs."""
    from lagbench.validate import is_integer

    if not is_integer(jobs) or jobs < 1:
        raise ValueError(f"--jobs: {jobs!r} is not valid; expected an integer >= 1 (worker processes)")


def run_units(todo, out, profile, progress=True, jobs=1, seconds=None, on_done=None, members=None, workers=False):
    """`seconds`: each unit's estimated seconds (`unit_seconds`), what the bar advances by (default: one each);
    `on_done(unit)`: called in this process once a unit's run has ended (its result written, or not);
    `workers`: train in worker processes at one job too (`lagbench verify`: units a run trained in workers)."""
    check_jobs(jobs)
    seconds = list(seconds) if seconds is not None else [1.0] * len(todo)
    on_done = on_done or (lambda u: None)
    # jobs > 1 trains even a single unit in a worker: its one CPU thread rounds float32 otherwise than this
    # process's threads, and a search or run at N workers keeps one rounding for every unit (nothing to train
    # opens no workers)
    if (jobs == 1 and not workers) or not todo:
        return _serial(todo, out, profile, progress, seconds, on_done, members)
    return _parallel(todo, out, profile, progress, jobs, seconds, on_done, members)
