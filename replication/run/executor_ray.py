"""Running the units of a plan on Ray (`lagbench run --executor ray [--address ADDR]`).

`run_units_ray(todo, out, profile, progress=True, address=None, retries=RETRIES, on_done=None) -> (failures,
errors)`, as `executor.run_units`: `on_done(unit)` is told of each unit once its files are written (a store
trims the unit's folder: `replication.run.store`). Without `address` it starts a local Ray instance on this
machine's cores (or uses this process's Ray connection, if it has one); with one it joins that cluster
(`ray start`).

Every unit is one Ray task (`ray_task.run_unit_task`) asking for one CPU, and, where the cluster has GPUs,
a unit of either framework for a share of one (`gpu_share`: a whole GPU for the paper-sized models, a
quarter for the others), unless the run asked for `--device cpu`; the device request reaches the task in
LAGBENCH_DEVICE. Tasks run with JAX, PyTorch
and OpenMP on one thread (`environment.one_thread_env`) and JAX told not to preallocate the GPU's memory.
Units that train the same model (`chains.chains`, as in the local executor) run one after another: each
task takes the previous one's result (which carries the trained model) as its argument, so Ray starts it
only once that one is done, and the model is trained once. Chains are submitted longest first.

No shared filesystem is assumed: a task returns its files' bytes, and this driver writes them into `out`
(`unit_files.write`: atomic writes, result.json last, verified), as soon as each unit is done. Finished
units were skipped before submission (`runner`), so a run resumes as with the local executor. A task whose
worker dies (killed, out of memory, node lost) is retried up to `retries` times by Ray, then recorded as an
error with the reason (no result written; a rerun retries it), and the units after it in its chain too.
Ctrl-C (or any error here) cancels the outstanding tasks and re-raises: what was written stays, and the
same command resumes. One progress bar: units running, finished and failed, with tqdm's ETA.
"""
from __future__ import annotations

import functools
import os
import socket
import warnings

from tqdm.auto import tqdm

from lagbench.replication.run.chains import chains, ref
from lagbench.replication.run.environment import commit, one_thread_env

INSTALL = "pip install 'lagbench[ray]'"
RETRIES = 2          # retries of a task whose worker died, before the unit is recorded as an error
POLL_S = 0.5         # how often the progress bar is refreshed
FORWARDED = ("LAGBENCH_WORKER_DIR", "PYTHONHASHSEED", "OMP_WAIT_POLICY", "LAGBENCH_DEVICE", "LAGBENCH_TF32")


def require_ray():
    """The `ray` module, or a ValueError saying how to install it."""
    try:
        import ray
    except ImportError:
        raise ValueError(f"--executor ray needs Ray, which is not installed in this environment; install it "
                         f"with: {INSTALL}") from None
    return ray


def task_env(environ) -> dict:
    """The environment variables of every task's worker process."""
    env = {**one_thread_env(environ), "XLA_PYTHON_CLIENT_PREALLOCATE": "false"}
    env.update({k: environ[k] for k in FORWARDED if environ.get(k)})
    if commit():   # a cluster node's copy of the code may have no .git: results record the driver's commit
        env["LAGBENCH_COMMIT"] = commit()
    return env


def gpu_share(unit) -> float:
    return 1.0 if sum(unit.spec().hidden) >= 1000 else 0.25


def resources(unit, cluster_gpus: float, device: str = "auto") -> dict:
    gpus = gpu_share(unit) if cluster_gpus > 0 and device != "cpu" else 0
    return {"num_cpus": 1, "num_gpus": gpus}


@functools.cache
def _remote(ray):
    """The Ray task and the progress board actor (defined here: Ray is an optional dependency)."""
    from lagbench.replication.run.ray_task import Board, run_unit_task

    return ray.remote(run_unit_task), ray.remote(num_cpus=0)(Board)


def check_address(address, timeout_s=10.0) -> None:
    """A ValueError naming --address if nothing answers at its host:port (Ray itself would wait on an
    unreachable address for ever); "auto", "local" and addresses without a port are left to Ray."""
    host, _, port = (address or "").removeprefix("ray://").rpartition(":")
    if not host or not port.isdigit():
        return
    try:
        socket.create_connection((host.strip("[]"), int(port)), timeout=timeout_s).close()
    except OSError as e:
        raise ValueError(f"--address {address}: no Ray cluster answers there ({e.strerror or e}); start one with "
                         f"`ray start --head` and give the address it prints") from None


def _connect(ray, address) -> bool:
    """Connect (or start a local instance); True if this call did, so that it shuts it down after."""
    if ray.is_initialized():
        return False
    check_address(address)
    try:
        with warnings.catch_warnings():
            # Ray starts its processes with subprocess (fork, then exec at once): not the fork JAX warns of
            warnings.filterwarnings("ignore", message=".*os.fork", category=RuntimeWarning)
            ray.init(address=address or "local", include_dashboard=False, log_to_driver=False,
                     logging_level="WARNING")
    except ConnectionError as e:
        raise ValueError(f"--address {address}: cannot connect to a Ray cluster there ({e})") from None
    return True


def _reason(ray, e, retries) -> str:
    if isinstance(e, ray.exceptions.RayTaskError):   # an exception in the task outside the unit's own code
        cause = e.cause if getattr(e, "cause", None) is not None else e
        return f"{type(cause).__name__}: {str(cause).strip().splitlines()[-1] if str(cause).strip() else ''}"
    first = str(e).strip().splitlines()[0] if str(e).strip() else ""
    return f"worker stopped ({retries + 1} attempts): {type(e).__name__}: {first}"


class _Bar:
    def __init__(self, total, desc, enabled):
        self.bar = tqdm(total=total, desc=desc, unit="unit", disable=not enabled)
        self.running, self.over, self.finished, self.failed = set(), set(), 0, 0

    def started(self, names):
        self.running.update(set(names) - self.over)
        self._show()

    def done(self, name, failed):
        self.running.discard(name)
        self.over.add(name)
        self.finished += not failed
        self.failed += failed
        self.bar.update(1)
        self._show()

    def _show(self):
        self.bar.set_postfix_str(f"running {len(self.running)}, finished {self.finished}, failed {self.failed}")


def _submit(ray, todo, out, retries, board):
    """Every unit's task, chain by chain -> {ObjectRef: (unit, the unit before it in its chain or None)}."""
    from lagbench.replication.run.unit_files import trained_entry

    task, _ = _remote(ray)
    gpus = ray.cluster_resources().get("GPU", 0)
    env = {"env_vars": task_env(os.environ)}
    refs = {}
    for chain in chains(todo):
        # what the driver's cache already holds of the chain's trainings (a cohort's seeds each have one)
        prev, before = {"cache": {k: v for u in chain for k, v in trained_entry(out, u).items()}}, None
        for u in chain:
            r = task.options(**resources(u, gpus, os.environ.get("LAGBENCH_DEVICE", "auto")), max_retries=retries, retry_exceptions=False,
                             runtime_env=env, name=f"lagbench {u.name}").remote(ref(u), prev, board)
            refs[r], prev, before = (u, before), r, u
    return refs


def _started(ray, board) -> list:
    """The units whose task started since the last call ([] if the board is gone: a lost node)."""
    try:
        return ray.get(board.take.remote(), timeout=60)
    except (ray.exceptions.RayError, TimeoutError):
        return []


def run_units_ray(todo, out, profile, progress=True, address=None, retries=None, on_done=None):
    from lagbench.files.results import CorruptResult
    from lagbench.replication.run.unit_files import write

    retries = RETRIES if retries is None else retries
    ray = require_ray()
    if not todo:
        return [], []
    started = _connect(ray, address)
    board = _remote(ray)[1].remote()
    pending, failures, errors, dead = [], [], [], set()
    bar = _Bar(len(todo), f"lagbench {profile} (ray, {ray.cluster_resources().get('CPU', 0):g} CPUs)", progress)
    try:
        refs = _submit(ray, todo, out, retries, board)
        order = {r: i for i, r in enumerate(refs)}
        pending = list(refs)
        while pending:
            ready, pending = ray.wait(pending, num_returns=len(pending), timeout=POLL_S)
            for r in sorted(ready, key=order.get):
                (u, before), d = refs.pop(r), None   # popped: Ray frees a result once no task needs it
                try:
                    d = ray.get(r)
                except ray.exceptions.RayError as e:
                    dead.add(u.name)
                    why = (f"not run: {before.name} (which trains its model first) did not finish"
                           if before is not None and before.name in dead else _reason(ray, e, retries))
                    errors.append(f"{u.name}: {why}")
                else:
                    try:
                        write(out, d["files"])
                    except CorruptResult as e:   # written, but not as sent: the rerun redoes the unit
                        d["error"] = f"{u.name}: its files arrived damaged: {e}"
                    failures += [d["failure"]] if d["failure"] else []
                    errors += [d["error"]] if d["error"] else []
                    if on_done:
                        on_done(u)
                bar.done(u.name, failed=d is None or bool(d["failure"] or d["error"]))
            bar.started(_started(ray, board))
    except BaseException:
        for r in pending:
            ray.cancel(r, force=True)
        raise
    finally:
        bar.bar.close()
        try:
            ray.kill(board)
        except ray.exceptions.RayError:
            pass
        if started:
            ray.shutdown()
    return failures, errors
