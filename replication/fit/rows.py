"""The rows `lagbench fit` trains and evaluates on: derivatives, the split, and the prepared file.

`prepare(out, path, split, heldout, window, polyorder, dtype, kind, gaps, time_unit)` reads the user's file
(`lagbench.files.user_data`), reads its times in `time_unit` (`replication.fit.time_base`), turns a trajectory file into state samples (`replication.fit.trajectories`),
assigns every row to "train" or "heldout" (kind "fit") or to "test" (kind "test", a `--test` or
`lagbench evaluate --data` file), and writes the rows to `OUT/data/<name>-<kind>-<hash>.csv` (columns
split, [traj, t,] q0.., qdot0.., qddot0..[, tau0..]; loadable with `pandas.read_csv`). The hash covers
the source file's sha256 and every option, and the file's bytes follow from them, so the prepared file
(and with it the training cache key: the protocol records `user_data.reference` of the prepared file)
changes exactly when the data or an option does. Returns a `Prepared` record.

Splits (`SPLITS`):
  by-trajectory  whole trajectories are held out: round(heldout x trajectories), at least one, at least
                 one left to train on; drawn with a fixed seed (0). The default for trajectory files:
                 rows of one trajectory are strongly correlated, so held-out rows between training rows
                 would measure interpolation, not generalisation.
  random         a random fraction `heldout` of the rows (at least one; seed 0); the default for state files.
  none           every row trains (evaluate on a `--test` file instead).
"""
from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from lagbench.files import results as R
from lagbench.files import user_data
from lagbench.replication.fit import time_base, trajectories
from lagbench.validate import is_real

SPLITS = ("by-trajectory", "random", "none")
HELDOUT = 0.1


@dataclass(frozen=True)
class Prepared:
    reference: str          # user_data.reference of the prepared file
    dof: int
    counts: dict            # split -> rows
    trajectories: dict      # split -> whole trajectories (0 for a state file)
    has_tau: bool
    source: str             # user_data.reference of the user's own file


def check_options(split, heldout) -> None:
    if split not in SPLITS:
        raise ValueError(f"--holdout: {split!r} is not valid; expected one of {', '.join(SPLITS)}")
    if not (is_real(heldout) and 0 < heldout < 1):
        raise ValueError(f"--holdout-fraction: {heldout!r} is not valid; expected a fraction between 0 and 1 (default "
                         f"{HELDOUT})")


def _assign(path, d, split, heldout) -> np.ndarray:
    n = len(d["q"])
    labels = np.full(n, "train", dtype=object)
    rng = np.random.default_rng(0)
    if split == "random":
        labels[rng.permutation(n)[:max(1, round(heldout * n))]] = "heldout"
    elif split == "by-trajectory":
        if "traj" not in d:
            raise ValueError(f"{path}: --holdout by-trajectory needs a trajectory file (columns traj, t, q0..); "
                             f"use --holdout random or none for state samples")
        ids = np.unique(d["traj"])
        if ids.size < 2:
            raise ValueError(f"{path}: one trajectory only, so none can be held out whole; give more trajectories, "
                             f"a --test file with --holdout none, or --holdout random")
        k = min(ids.size - 1, max(1, round(heldout * ids.size)))
        labels[np.isin(d["traj"], rng.choice(ids, size=k, replace=False))] = "heldout"
    return labels


def _frame(d: dict, labels) -> pd.DataFrame:
    cols = {"split": labels}
    for k in ("traj", "t"):
        if k in d:
            cols[k] = d[k]
    for k in user_data.ARRAYS:
        if k in d:
            cols.update({f"{k}{j}": d[k][:, j] for j in range(d[k].shape[1])})
    return pd.DataFrame(cols)


def prepare(out, path, split=None, heldout=HELDOUT, window=trajectories.WINDOW, polyorder=trajectories.POLYORDER,
            dtype="float32", kind="fit", gaps="interpolate", time_unit="s") -> Prepared:
    path = str(Path(path).resolve())
    digest, d = user_data.read(path)
    is_traj = "t" in d
    if is_traj:
        d = time_base.in_seconds(d, time_unit)
        d = trajectories.with_derivatives(d, path, window, polyorder, gaps)
    user_data.check_range(path, d, dtype)
    if kind == "test":
        labels = np.full(len(d["q"]), "test", dtype=object)
        options = {}
    else:
        split = split or ("by-trajectory" if is_traj else "random")
        check_options(split, heldout)
        labels = _assign(path, d, split, heldout)
        options = {"split": split, "heldout": heldout}
        if not np.any(labels == "train"):
            raise ValueError(f"{path}: no rows left to train on")
    if is_traj:
        options.update(window=window, polyorder=polyorder)
        if gaps != "interpolate":   # a file without dropped frames gives the same rows under any
            options["gaps"] = gaps
        if time_unit != "s":   # named only when not seconds: the files prepared in seconds keep their names
            options["time_unit"] = time_unit
    tag = hashlib.sha256(json.dumps({"source": digest, "kind": kind, **options}, sort_keys=True).encode())
    target = Path(out) / "data" / f"{Path(path).stem}-{kind}-{tag.hexdigest()[:12]}.csv"
    prepared_digest = R.write_csv(target, _frame(d, labels))
    names, counts = np.unique(labels, return_counts=True)
    traj = {str(s): int(np.unique(d["traj"][labels == s]).size) if is_traj else 0 for s in names}
    return Prepared(user_data.reference(str(target.resolve()), prepared_digest), d["q"].shape[1],
                    {str(s): int(c) for s, c in zip(names, counts, strict=True)}, traj, "tau" in d,
                    user_data.reference(path, digest))
