"""The report's output folder: a build replaces the previous report as a whole, and the tool replaces and
removes only what it wrote there itself.

``prepare(out_dir) -> Path`` checks the folder before any work: it is created if absent, must be a
folder, and its ``figures/`` must not be a symlink (the report never writes outside ``out_dir``). It
removes what a killed build left (its temporaries, its staging folder) and returns a fresh staging
folder inside ``out_dir`` (``.lagbench-build-<random>/``, with ``figures/``): the build writes every output
there, so an interrupted or failed build leaves the previous report as it was, never a new REPORT.md
beside the previous build's REPORT.pdf. Every output is written with
``lagbench.files.results.atomic_write_bytes`` (a temporary file and a rename).

``finish(out_dir, paths)`` moves this build's outputs (``paths``, inside the staging folder) into
``out_dir``, each by a rename (a symlink at a name is replaced, never written through), with SIGINT and
SIGTERM held off until all are moved (a kill by SIGKILL in those milliseconds is not covered); records them in ``.lagbench-report.json`` (relative path ->
sha256); and removes the files the previous build recorded that this one did not write, and only those
still byte-identical to what was recorded: a user's own file in the folder (say ``figures/my_plot.png``),
or a recorded one the user has since edited, is never deleted. ``discard()`` removes the staging folder of
a build that did not finish.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import re
import shutil
import signal
import tempfile
import threading
from pathlib import Path

from lagbench.files.results import atomic_write_bytes, output_folder, read_nofollow

MANIFEST = ".lagbench-report.json"
STAGE = ".lagbench-build-"   # the staging folder's name prefix


# a temporary file of `atomic_write_bytes` that a killed build left: ".<name>.<8 random characters>.tmp"
_TEMPORARY = re.compile(r"^\..+\.[A-Za-z0-9_]{8}\.tmp$")
_BUILD: dict = {}   # the build in progress: its folder, its staging folder and the previous build's record


def prepare(out_dir) -> Path:
    """Check ``out_dir``, remove what a killed build left there, and return a fresh staging folder in it."""
    out_dir = output_folder(out_dir, "--out")
    figures = out_dir / "figures"
    if figures.is_symlink() or (os.path.lexists(figures) and not figures.is_dir()):
        raise ValueError(f"--out {out_dir}: figures/ is a symlink or a file; the report writes only into "
                         f"real folders inside --out (remove or rename it)")
    output_folder(figures, "--out")
    for folder in (out_dir, figures):   # what a killed build left half-written
        for p in folder.iterdir():
            if _TEMPORARY.match(p.name) and p.is_file() and not p.is_symlink():
                p.unlink()
    for p in out_dir.iterdir():   # a killed build's staging folder
        if p.name.startswith(STAGE) and p.is_dir() and not p.is_symlink():
            shutil.rmtree(p, ignore_errors=True)
    discard()
    stage = Path(tempfile.mkdtemp(prefix=STAGE, dir=out_dir))
    (stage / "figures").mkdir()
    _BUILD.update(dir=out_dir.resolve(), stage=stage.resolve(), recorded=_recorded(out_dir))
    return stage


def write(path: Path, data: bytes | str) -> Path:
    """Write one output atomically."""
    raw = data.encode("utf-8") if isinstance(data, str) else data
    atomic_write_bytes(Path(path), raw)
    return Path(path)


def discard() -> None:
    """Remove the staging folder of the build in progress (one that failed or was interrupted) and forget it."""
    stage = _BUILD.get("stage")
    if stage is not None and stage.is_dir() and not stage.is_symlink():
        shutil.rmtree(stage, ignore_errors=True)
    _BUILD.clear()


@contextlib.contextmanager
def _signals_held():
    """SIGINT and SIGTERM wait until the block ends, then arrive at their own handlers: the report is moved in
    whole. Python runs signal handlers in the main thread only, so elsewhere the block runs as it is."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught = []
    old = {s: signal.signal(s, lambda signum, frame: caught.append(signum)) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for s, handler in old.items():
            signal.signal(s, handler if handler is not None else signal.SIG_DFL)
        for s in dict.fromkeys(caught):
            signal.raise_signal(s)


def _sha(path: Path) -> str | None:
    try:
        return hashlib.sha256(read_nofollow(path)).hexdigest()
    except OSError:
        return None


def _recorded(out_dir: Path) -> dict:
    try:
        files = json.loads(read_nofollow(out_dir / MANIFEST)).get("files", {})
        return {k: v for k, v in files.items() if isinstance(k, str) and isinstance(v, str)}
    except (OSError, ValueError, AttributeError):
        return {}


def finish(out_dir: Path, paths: list) -> tuple[list, list]:
    """Move ``paths`` (this build's outputs, in the staging folder) into ``out_dir``, record them and remove
    the previous build's leftovers; returns (the outputs' paths in ``out_dir``, the removed paths)."""
    out_dir = Path(out_dir)
    root = out_dir.resolve()
    stage = _BUILD.get("stage")
    if stage is None or _BUILD.get("dir") != root:
        raise RuntimeError("reports.output.finish: no build of this folder in progress (call prepare first)")
    rel = [Path(p).resolve().relative_to(stage).as_posix() for p in paths]
    now = {r: _sha(stage / r) for r in rel}
    removed = []
    with _signals_held():
        for r in rel:
            (out_dir / r).parent.mkdir(parents=True, exist_ok=True)
            os.replace(stage / r, out_dir / r)
        for r, digest in _BUILD["recorded"].items():
            p = out_dir / r
            inside = ".." not in Path(r).parts and not Path(r).is_absolute()
            if r in now or not inside or p.is_symlink() or p.parent.resolve() != (root / r).parent:
                continue
            if _sha(p) == digest:
                p.unlink()
                removed.append(p)
        write(out_dir / MANIFEST, json.dumps({"files": {k: v for k, v in now.items() if v}}, indent=1,
                                             sort_keys=True))
        discard()
    return [out_dir / r for r in rel], removed
