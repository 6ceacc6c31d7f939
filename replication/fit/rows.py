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

Training rows in a test file: `overlap(train_ref, d) -> Overlap | None` counts the rows of a test file's
arrays `d` (times in seconds) that are training rows ("train") of the prepared file `train_ref` (None where
that file is not readable with its recorded bytes): a row is shared when its values in every column both
files hold (t, q, and qdot, qddot, tau where both give them) are equal, a trajectory when it holds more than
half the training rows of one training trajectory (the prepared rows lack each trajectory's ends, which the
derivative filter drops, so a test trajectory is never compared with rows the fit did not keep).
`training_rows_check(...)` refuses a test file that is the training file itself, or whose every trajectory
(every row of a state file) is a training one (its errors would measure memory, not prediction), and returns
the `Overlap` of a test file that is partly training rows (then recorded and warned about: a log that
continues the training session is legitimate data, but its errors mix seen and unseen rows), or None.
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


@dataclass(frozen=True)
class Overlap:
    rows: int               # the test file's rows that are training rows
    of_rows: int
    trajectories: int       # its trajectories holding most of a training trajectory's rows (0 of 0: state file)
    of_trajectories: int

    @property
    def whole(self) -> bool:
        """Every trajectory (every row, for a state file) is a training one."""
        return (self.trajectories == self.of_trajectories if self.of_trajectories else self.rows == self.of_rows) \
            and self.of_rows > 0

    def words(self) -> str:
        rows = f"{self.rows} of its {self.of_rows} rows"
        return f"{self.trajectories} of its {self.of_trajectories} trajectories ({rows})" if self.of_trajectories else rows


def _keys(d: dict, cols) -> list[bytes]:
    """One key per row: the bytes of the row's values in `cols`, as float64."""
    m = np.concatenate([np.asarray(d[c], np.float64).reshape(len(d["q"]), -1) for c in cols], axis=1)
    return [row.tobytes() for row in np.ascontiguousarray(m)]


def _training_rows(train_ref: str, folder: Path | None) -> dict | None:
    """The "train" rows of the prepared file `train_ref`, read where it was written or, for a results folder
    moved since, from the folder's own data/; None where neither holds it with its recorded bytes."""
    path, digest = user_data.parse_reference(train_ref)
    for p in [Path(path)] + ([folder / "data" / Path(path).name] if folder is not None else []):
        if p.is_file():
            try:
                return user_data.rows(user_data.reference(str(p), digest) if digest else str(p), "train")
            except ValueError:
                continue
    return None


def overlap(train_ref: str, d: dict, folder: Path | None = None) -> Overlap | None:
    train = _training_rows(train_ref, folder)
    if train is None:
        return None
    cols = [c for c in ("t", *user_data.ARRAYS) if c in d and c in train]
    owner = dict(zip(_keys(train, cols), train.get("traj", np.zeros(len(train["q"]))).tolist(), strict=True))
    found = [owner.get(k) for k in _keys(d, cols)]   # the training trajectory each row is a row of, or None
    shared = np.array([j is not None for j in found], bool)
    if "traj" not in d and "t" not in d:
        return Overlap(int(shared.sum()), int(shared.size), 0, 0)
    sizes = dict(zip(*np.unique(train.get("traj", np.zeros(len(train["q"]))), return_counts=True), strict=True))
    traj = d.get("traj", np.zeros(len(d["q"])))
    most = 0
    for k in np.unique(traj):   # a training trajectory most of whose training rows are in this one
        ids, n = np.unique([j for j, t in zip(found, traj, strict=True) if t == k and j is not None],
                           return_counts=True)
        most += bool(ids.size and max(c / sizes[j] for j, c in zip(ids, n, strict=True)) > 0.5)
    return Overlap(int(shared.sum()), int(shared.size), most, int(np.unique(traj).size))


def training_rows_check(test_path: str, name: str, d: dict, digest: str, result: dict, folder: Path) -> Overlap | None:
    """`name` (the option and file the user gave) refused when it is the fit's training file or holds only its
    training rows; its `Overlap` when it holds some; None when it holds none (or the fit's rows are not readable).
    `result`: the fit's result.json; `folder`: its unit folder (OUT/units/fit/<framework>/<model>/seed<k>)."""
    cfg = result.get("eval_config") or {}
    source, source_digest = user_data.parse_reference(cfg.get("source") or "")
    fix = ("its errors would measure what the model memorised, not what it predicts: give a file of other "
           "trajectories (e.g. `lagbench simulate --seed 1`)")
    if source_digest == digest:
        same = "the same file as" if Path(source) == Path(test_path) else "byte for byte the same as"
        raise ValueError(f"{name}: {same} the training data of the fit in {folder} ({source}); {fix}")
    recipe = ((result.get("protocol") or {}).get("data") or {}).get("recipe") or ""
    parents = Path(folder).resolve().parents
    found = overlap(recipe, d, parents[4] if len(parents) > 4 else None)
    if found is None or found.rows == 0:
        return None
    if found.whole:
        raise ValueError(f"{name}: {found.words()} are training rows of the fit in {folder} (from {source}); {fix}")
    return found
