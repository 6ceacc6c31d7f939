"""What a Ray worker does for one unit (`replication.run.executor_ray` submits it); no Ray import here, and
nothing heavy at import (the progress `Board` actor's process imports this module alone).

`run_unit_task(ref, prev, board) -> payload`: runs the unit named by `ref` (`chains.ref`) in a scratch
results folder of its own, under the worker's folder, and returns
{"name", "failure", "error", "files": {path: bytes} written by this unit (its unit folder and, if it
trained, the training-cache entry), "cache": {path: bytes} the training-cache entries now in the scratch
folder (for the next unit of its chain)}. `prev` is the previous unit's payload of the chain (Ray passes
it once that unit is done), or {"cache": ...} from the driver's own cache for the first: the model a
chain shares is trained once, wherever its units run. `board` (a Ray actor or None) is told the unit has
started, for the driver's progress bar.

The worker's folder: `$LAGBENCH_WORKER_DIR`, default `<tmp>/lagbench-ray-<uid>` on the worker's node. It
holds the worker's generated-code and dataset cache (`cache/`, set as LAGBENCH_CACHE for the unit, built
on first use, kept for the next runs on that node) and the scratch folders (`scratch/`, removed after
each unit). The unit runs with that scratch folder as its working directory, so nothing it writes lands
in the driver's working directory, which a local Ray worker would otherwise share.
"""
from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

from lagbench.replication.run import unit_files
from lagbench.replication.run.chains import run_one, unit_of
from lagbench.replication.run.environment import one_thread_jax


class Board:
    """Names of units whose task has started (a Ray actor of the driver's, on no CPU); the driver takes
    them for its progress bar."""

    def __init__(self):
        self.started = []

    def start(self, name):
        self.started.append(name)

    def take(self):
        out, self.started = self.started, []
        return out


def worker_dir() -> Path:
    uid = os.getuid() if hasattr(os, "getuid") else "user"
    return Path(os.environ.get("LAGBENCH_WORKER_DIR") or Path(tempfile.gettempdir()) / f"lagbench-ray-{uid}")


def run_unit_task(ref, prev, board=None) -> dict:
    one_thread_jax()   # XLA's pool at one thread, as a local worker's (the first task of a Ray worker starts it)
    unit = unit_of(ref)
    if board is not None:
        board.start.remote(unit.name)
    root = worker_dir()
    (root / "scratch").mkdir(parents=True, exist_ok=True)
    os.environ["LAGBENCH_CACHE"] = str(root / "cache")
    scratch = Path(tempfile.mkdtemp(prefix="unit-", dir=root / "scratch"))
    cwd = os.getcwd()
    os.chdir(scratch)
    try:
        seeded = dict((prev or {}).get("cache") or {})
        unit_files.write(scratch, seeded)
        failure, error = run_one(unit, scratch)
        files = unit_files.collect(scratch, skip=seeded)
        cache = {k: v for k, v in {**seeded, **files}.items() if k.startswith("trained/")}
        return {"name": unit.name, "failure": failure, "error": error, "files": files, "cache": cache}
    finally:
        os.chdir(cwd)
        shutil.rmtree(scratch, ignore_errors=True)
