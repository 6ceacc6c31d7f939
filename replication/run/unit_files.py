"""A unit's files as bytes, for executors whose workers share no filesystem with the driver (Ray).

Paths are relative POSIX paths under a results folder: `units/<claim>/<framework>/<model>/seed<k>/<file>`
and the training cache `trained/<framework>/<key>/<file>` (`replication.training.train`).

`collect(root, skip=()) -> {path: bytes}`: every regular file under `root` (no symlinks), less `skip`.
`trained_entry(out, unit) -> {path: bytes}`: the verified training-cache entry of the unit's model in
`out`, or {} (untrained unit, absent, or failing its checksums: then it is retrained, never trusted).
`write(out, files) -> [folder]`: writes the files of every folder that holds a result.json with
`results.atomic_write_bytes`, its result.json last (a folder never shows a result whose files are not
there yet), then verifies it (`results.load_result`: CorruptResult on any mismatch). A folder without
a result.json (a unit that raised, a training cut short) is not written: the run redoes it. A path that
is absolute or climbs out of `out` is refused (ValueError): nothing is written outside `out`.
"""
from __future__ import annotations

import os
from pathlib import Path, PurePosixPath

from lagbench.files import results as R


def collect(root, skip=()) -> dict:
    root = Path(root)
    files = {}
    for dirpath, _dirs, names in os.walk(root):
        for name in names:
            path = Path(dirpath) / name
            rel = path.relative_to(root).as_posix()
            if rel not in skip and not name.startswith(".") and not path.is_symlink() and path.is_file():
                files[rel] = R.read_nofollow(path)
    return files


def trained_entry(out, unit) -> dict:
    if not unit.entry.train:
        return {}
    from lagbench.replication.training.train import train_key

    rel = f"trained/{unit.framework}/{train_key(unit.framework, unit.spec(), unit.protocol(), unit.seed)}"
    folder = Path(out) / rel
    try:
        R.load_result(folder)
    except R.CorruptResult:
        return {}
    return {f"{rel}/{f.name}": R.read_nofollow(f) for f in sorted(folder.iterdir())
            if f.is_file() and not f.is_symlink() and not f.name.startswith(".")}


def _checked(rel: str) -> PurePosixPath:
    p = PurePosixPath(rel)
    if p.is_absolute() or ".." in p.parts or not p.parts or p.parts[0] not in ("units", "trained"):
        raise ValueError(f"unit file {rel!r}: not a path under units/ or trained/; refused")
    return p


def write(out, files: dict) -> list:
    folders: dict = {}
    for rel, data in files.items():
        p = _checked(rel)
        folders.setdefault(p.parent, {})[p.name] = data
    written = []
    for parent, named in folders.items():
        if "result.json" not in named:
            continue
        folder = Path(out).joinpath(*parent.parts)
        for name in sorted(named, key=lambda n: n == "result.json"):
            R.atomic_write_bytes(folder / name, named[name])
        R.load_result(folder)
        written.append(folder)
    return written
