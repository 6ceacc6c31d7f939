"""JAX's persistent compilation cache in this user's own folder: a program one lagbench process compiled (a
run's worker, a study, an earlier run) is read back by the next instead of compiled again.

    folder() -> Path | None   `$LAGBENCH_CACHE/jax-compiled/<host digest>`, made if missing; None where it
                              cannot be had or is not this user's own
    private() -> bool         point JAX (this process and every process it starts) at `folder()`

The cache holds compiled machine code that JAX loads and runs, so its folder must be this user's own, as
inductor's is (`models.torch.inductor_cache`): made mode 0700, and used only if it and the folder above it are
real directories (not symlinks) owned by this user that no one else may write; otherwise nothing is cached and
every program compiles as usual. The subfolder is named by a digest of the JAX and jaxlib versions, the machine
and the CPU's model and vector features (`host_digest`): XLA compiles CPU code for the host's instruction set,
so a host or an install that differs never reads another's programs. Within it JAX keys each entry by the
program, its XLA flags and compile options. Programs that compile in under `MIN_COMPILE_S` are not kept; the
folder holds at most `MAX_BYTES`, the least recently used going first; that limit also turns on JAX's file lock
around every read and write (the `filelock` package, which PyTorch brings; without it nothing is cached), so
that no process reads an entry another is still writing. A JAX_COMPILATION_CACHE_DIR already set
is the user's choice and is kept; LAGBENCH_JAX_CACHE=0 turns the cache off.
"""
from __future__ import annotations

import hashlib
import importlib.metadata
import importlib.util
import logging
import os
import platform
import sys
from pathlib import Path

from lagbench.files.results import make_own_folder
from lagbench.replication.run.environment import cpu_description

log = logging.getLogger("lagbench")

ENV = "JAX_COMPILATION_CACHE_DIR"
OFF = "LAGBENCH_JAX_CACHE"
MIN_COMPILE_S = 0.1
MAX_BYTES = 2 * 1024 ** 3


def host_digest() -> str:
    """A digest of what decides whether a compiled program runs here: JAX's and jaxlib's versions, the machine,
    the CPU's model and vector features."""
    try:
        cpuinfo = Path("/proc/cpuinfo").read_text()
    except OSError:
        cpuinfo = ""   # no /proc: the machine and `platform`'s processor name alone
    cpu = cpu_description(cpuinfo)
    parts = [platform.machine(), platform.processor(), cpu["cpu"], cpu["cpu_model"], cpu["cpu_features"]]
    for name in ("jax", "jaxlib"):
        try:
            parts.append(f"{name}={importlib.metadata.version(name)}")
        except importlib.metadata.PackageNotFoundError:
            parts.append(f"{name}=none")
    return hashlib.sha256("\x1f".join(parts).encode()).hexdigest()[:16]


def folder() -> Path | None:
    # the suite's cache root as `systems.cache.cache_dir` has it; importing `systems` would import JAX, whose
    # settings must be in the environment first
    root = Path(os.environ.get("LAGBENCH_CACHE") or ".cache") / "jax-compiled"
    sub = root / host_digest()
    why = make_own_folder(root) or make_own_folder(sub)   # the root checked before anything is made inside it
    if why:
        log.warning("JAX compilation cache off: %s", why)
        return None
    return sub.resolve()


def private() -> bool:
    """Point JAX's persistent cache at `folder()` through the environment (read by JAX when it is imported, and
    inherited by the processes this one starts) and, where JAX is imported already, through its config. False
    where the cache stays off."""
    if os.environ.get(ENV):
        return True
    if os.environ.get(OFF, "") == "0" or importlib.util.find_spec("filelock") is None:
        return False
    where = folder()
    if where is None:
        return False
    settings = {ENV: str(where), "JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS": str(MIN_COMPILE_S),
                "JAX_COMPILATION_CACHE_MAX_SIZE": str(MAX_BYTES)}
    os.environ.update(settings)
    if "jax" in sys.modules:   # imported already: its config was read from the environment before
        import jax  # noqa: PLC0415

        jax.config.update("jax_compilation_cache_dir", str(where))
        jax.config.update("jax_persistent_cache_min_compile_time_secs", MIN_COMPILE_S)
        jax.config.update("jax_compilation_cache_max_size", MAX_BYTES)
    return True
