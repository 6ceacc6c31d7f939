"""What a result was computed with: package versions, hardware, commit, time."""
from __future__ import annotations

import importlib.metadata
import os
import platform
import subprocess
import sys
from contextlib import contextmanager
from functools import lru_cache
from pathlib import Path

from lagbench.files.clock import now  # noqa: F401  (the time results record)

PACKAGES = ("numpy", "sympy", "jax", "jaxlib", "equinox", "optax", "diffrax", "torch", "pandas")
ONE_CORE_XLA = "--xla_cpu_multi_thread_eigen=false intra_op_parallelism_threads=1"
WORKER_THREADS = 1   # PyTorch / OpenMP / MKL threads of a worker process or Ray task (and XLA's, above)


def one_thread_env(env) -> dict:
    """The environment variables of a new process at one thread: PyTorch/OpenMP and MKL, and XLA's Eigen pool
    off (appended to any XLA_FLAGS already in `env` unless there; XLA's own pool is held by the process's
    start, `one_thread_jax`)."""
    flags = env.get("XLA_FLAGS", "")
    xla = flags if ONE_CORE_XLA in flags else f"{flags} {ONE_CORE_XLA}".strip()
    return {"XLA_FLAGS": xla, "OMP_NUM_THREADS": str(WORKER_THREADS),
            "MKL_NUM_THREADS": str(WORKER_THREADS)}


@contextmanager
def one_thread_children():
    """Processes started inside the block run JAX, PyTorch/OpenMP and MKL on one thread: `one_thread_env` is
    set in this process's environment, which they inherit before they import either; put back afterwards
    (processes already started keep theirs)."""
    one = one_thread_env(os.environ)
    saved = {k: os.environ.get(k) for k in one}
    os.environ.update(one)
    try:
        yield
    finally:
        for k, v in saved.items():
            os.environ.pop(k, None) if v is None else os.environ.__setitem__(k, v)


def one_thread_jax() -> bool:
    """Hold this process's JAX to one thread, as a worker's: True if its XLA runs on one thread (JAX's backend
    started here on one CPU, `_start_jax_on_one_cpu`), False once the backend has started on more. Sets
    `ONE_CORE_XLA` in XLA_FLAGS before the start, as the workers' environment has it."""
    from lagbench.models.jax.compiled import _backend_started

    if _backend_started():
        return jax_threads() == 1
    os.environ["XLA_FLAGS"] = one_thread_env(os.environ)["XLA_FLAGS"]
    _start_jax_on_one_cpu()
    return jax_threads() == 1


_JAX_THREADS = None   # XLA's CPU threads where this process started JAX's backend itself (`_start_jax_on_one_cpu`)


def _start_jax_on_one_cpu():
    """Start JAX's backend with one CPU thread. XLA's CPU client sizes its thread pool to the CPUs this
    process may run on when the backend starts, and reads no flag for it (`ONE_CORE_XLA` leaves a thread a
    core, each busy: two workers on two cores then run four threads and slow each other, measured in
    `docs/decisions/run_estimate.md`). So the backend starts with this thread pinned to one CPU, and then every
    thread of the process gets the whole set back: the pool has one thread, which the OS places on any core."""
    global _JAX_THREADS
    import jax

    cpus = os.sched_getaffinity(0) if hasattr(os, "sched_getaffinity") else None
    pinned = bool(cpus) and len(cpus) > 1   # else no affinity to set (not Linux), or one CPU already
    if pinned:
        os.sched_setaffinity(0, {min(cpus)})
    try:
        jax.devices()
    except RuntimeError:   # no backend JAX can start (a platform asked for and missing): a JAX unit says so
        return
    finally:
        for task in os.listdir("/proc/self/task") if pinned else ():
            try:
                os.sched_setaffinity(int(task), cpus)
            except OSError:   # a thread that ended meanwhile
                pass
    _JAX_THREADS = 1 if cpus else None


def jax_threads() -> int | None:
    """XLA's CPU threads in this process: one where `_start_jax_on_one_cpu` started JAX's backend, else the
    CPUs the process may run on (what XLA sizes its pool to when the backend starts); None before it starts."""
    from lagbench.models.jax.compiled import _backend_started

    if _JAX_THREADS is not None:
        return _JAX_THREADS
    if "jax" not in sys.modules or not _backend_started():
        return None
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()


def _exit_with(parent: int, every: float = 1.0):
    """Exit this process once its parent is no longer `parent` (the driver died; we were re-parented)."""
    import time

    while os.getppid() == parent:
        time.sleep(every)
    os._exit(1)


def worker_start(driver: int):
    """A worker process's start: JAX (`one_thread_jax`) and PyTorch at `WORKER_THREADS` with subnormal floats
    flushed (`models.torch.subnormals`, before PyTorch computes), and an exit of its own once its driver (the
    process `driver`) is gone."""
    import threading

    import torch

    import lagbench.models.torch  # noqa: F401  (flushes subnormals)

    one_thread_jax()
    torch.set_num_threads(WORKER_THREADS)
    threading.Thread(target=_exit_with, args=(driver,), daemon=True, name="lagbench-driver-watch").start()


def worker_torch_threads(executor: str, jobs: int) -> int | None:
    """PyTorch's intra-op threads in the processes that will train a run's units: one in each worker
    process (`--jobs` > 1; `one_thread_env` and the worker's start) and in each Ray task; None with one
    local job, where the units train in this process at its own setting."""
    return WORKER_THREADS if executor == "ray" or jobs > 1 else None


@contextmanager
def torch_threads(n: int | None):
    """Temporarily set PyTorch's intra-op threads (None: leave as is, without importing PyTorch)."""
    if n is None:
        yield
        return
    import torch

    old = torch.get_num_threads()
    torch.set_num_threads(n)
    try:
        yield
    finally:
        torch.set_num_threads(old)


@lru_cache(maxsize=1)
def versions() -> dict:
    out = {"python": platform.python_version()}
    for name in PACKAGES:
        try:
            out[name] = importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            out[name] = None
    return out


# the vector instruction sets that decide which CPU kernels XLA and PyTorch compile or pick, and so their
# float rounding: the same code on hosts that differ here can train to other numbers (a run's seeds may
# then choose other scouts; `docs/train_target_trials.md` section 12)
CPU_FEATURES = ("sse4_2", "avx", "avx2", "fma", "avx512f", "avx512bw", "avx512vl", "avx512_bf16", "avx512_fp16",
                "avx_vnni", "amx_tile")


def cpu_description(cpuinfo: str) -> dict:
    """From /proc/cpuinfo's text: {"cpu": model name ("" if absent), "cpu_model": "family F model M" ("" if
    absent), "cpu_features": the CPU_FEATURES its first processor lists, space-separated}."""
    fields = {}
    for line in cpuinfo.splitlines():
        if not line.strip():
            break   # the first processor's block only
        key, _, value = line.partition(":")
        fields.setdefault(key.strip(), value.strip())
    flags = set(fields.get("flags", "").split())
    family, model = fields.get("cpu family", ""), fields.get("model", "")
    return {"cpu": fields.get("model name", ""),
            "cpu_model": f"family {family} model {model}" if family and model else "",
            "cpu_features": " ".join(f for f in CPU_FEATURES if f in flags)}


@lru_cache(maxsize=1)
def _machine() -> dict:
    try:
        cpuinfo = Path("/proc/cpuinfo").read_text()
    except OSError:
        cpuinfo = ""   # no /proc: every field empty, the model name from `platform` below
    cpu = cpu_description(cpuinfo)
    cpu["cpu"] = cpu["cpu"] or platform.processor() or platform.machine()
    gpu = None
    try:
        import jax  # noqa: PLC0415 - only if present

        devs = [d for d in jax.devices() if d.platform != "cpu"]
        gpu = devs[0].device_kind if devs else None
    except Exception:
        gpu = None
    return {**cpu, "cores": os.cpu_count(), "gpu": gpu, "platform": platform.platform()}


def hardware() -> dict:
    """The machine (read once) and how this process computes now: JAX's and PyTorch's threads (each sums in
    its own order, so they are part of what its numbers are) and whether PyTorch keeps subnormal floats
    (`models.torch.subnormals`; None where PyTorch is not imported)."""
    torch = sys.modules.get("torch")
    flushed = sys.modules.get("lagbench.models.torch.subnormals")
    return {**_machine(), "jax_threads": jax_threads(), "torch_threads": torch.get_num_threads() if torch else None,
            "torch_subnormals": flushed.mode() if flushed else ("kept" if torch else None)}


@lru_cache(maxsize=1)
def commit() -> str | None:
    """git's short HEAD; LAGBENCH_COMMIT, where set, instead (a copy of the tree run elsewhere, whose .git,
    if any, is not the checkout's)."""
    if os.environ.get("LAGBENCH_COMMIT"):
        return os.environ["LAGBENCH_COMMIT"]
    try:
        root = Path(__file__).resolve().parents[2]  # the project root
        r = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=root, capture_output=True,
                           text=True, timeout=5)
        return r.stdout.strip() or None
    except (OSError, subprocess.SubprocessError):
        return None


