"""The report's output folder: the tool replaces and removes only what it wrote there itself.

``prepare(out_dir) -> Path`` checks the folder before any work: it is created if absent, must be a
folder, and its ``figures/`` must not be a symlink (the report never writes outside ``out_dir``).
Every output is written with ``replication.results.atomic_write_bytes`` (a temporary file and a
rename), so a symlink planted at ``REPORT.md`` or at a figure's name is replaced, never written through.

``finish(out_dir, paths)`` records what this build wrote in ``.lagbench-report.json`` (relative
path -> sha256) and removes the files the previous build recorded that this one did not write, and
only those still byte-identical to what was recorded: a user's own file in the folder (say
``figures/my_plot.png``), or a recorded one the user has since edited, is never deleted.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
from pathlib import Path

from replication.results import atomic_write_bytes, output_folder, read_nofollow

MANIFEST = ".lagbench-report.json"


# a temporary file of `atomic_write_bytes` that a killed build left: ".<name>.<8 random characters>.tmp"
_TEMPORARY = re.compile(r"^\..+\.[A-Za-z0-9_]{8}\.tmp$")
_BUILD: dict = {}   # the build in progress: its folder, the previous build's record and what it wrote so far


def prepare(out_dir) -> Path:
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
    _BUILD.clear()
    _BUILD.update(dir=out_dir.resolve(), recorded=_recorded(out_dir), written={})
    return out_dir


def write(path: Path, data: bytes | str) -> Path:
    """Write one output; its record is kept at once (with the previous build's), so that a build killed
    part-way leaves nothing the next build does not know to replace or remove."""
    raw = data.encode("utf-8") if isinstance(data, str) else data
    atomic_write_bytes(Path(path), raw)
    root = _BUILD.get("dir")
    if root is not None and Path(path).resolve().parent.is_relative_to(root):
        _BUILD["written"][Path(path).resolve().relative_to(root).as_posix()] = hashlib.sha256(raw).hexdigest()
        files = {**_BUILD["recorded"], **_BUILD["written"]}
        atomic_write_bytes(root / MANIFEST, json.dumps({"files": files}, indent=1, sort_keys=True).encode())
    return Path(path)


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


def finish(out_dir: Path, paths: list) -> list:
    """Record ``paths`` (this build's outputs) and remove the previous build's leftovers; returns
    the removed paths."""
    out_dir = Path(out_dir)
    root = out_dir.resolve()
    now = {Path(p).resolve().relative_to(root).as_posix(): _sha(Path(p)) for p in paths}
    previous = _BUILD.get("recorded") if _BUILD.get("dir") == root else None
    _BUILD.clear()
    removed = []
    for rel, digest in (_recorded(out_dir) if previous is None else previous).items():
        p = out_dir / rel
        inside = ".." not in Path(rel).parts and not Path(rel).is_absolute()
        if rel in now or not inside or p.is_symlink() or p.parent.resolve() != (root / rel).parent:
            continue
        if _sha(p) == digest:
            p.unlink()
            removed.append(p)
    write(out_dir / MANIFEST, json.dumps({"files": {k: v for k, v in now.items() if v}}, indent=1, sort_keys=True))
    return removed
