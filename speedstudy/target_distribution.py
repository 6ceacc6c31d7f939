"""`lagbench train-target --runs N --split S`: the train-to-target study repeated over independent runs,
and the distribution of the samples and training time each run needs to reach the like-for-like target
(`train_target.CODE_HELDOUT_L1`, the original code's held-out L1 0.069).

`init_seeds(names, split, offset, runs) -> [{protocol: init seed} per run]`: run r of a protocol that scouts
K inits (its `scouting.count`; 1 without scouting) starts at split.first_seed + offset + r * K, so no two
runs share an init; a ValueError where an init would leave the split's seeds (`splits.SEEDS_PER_SPLIT`).

`run_many(folder, budget, hidden, n_heldout, names, split, offset, runs, progress) -> DataFrame` trains run r
into FOLDER/run<r>/ with `train_target_run.run_study` (train_target.csv, train_target_log.csv, the models)
beside inputs.json, the inputs that decide its numbers (budget, hidden, heldout_states, protocols, split,
heldout_seed, init_seeds). A folder whose train_target.csv is there (it is written last) and whose
inputs.json matches is read back, not retrained, so an interrupted command resumes where it stopped; a
folder with other inputs, or with files and no inputs.json, is a one-line ValueError naming it, checked for
every run before any training. The returned rows are every run's train_target.csv rows with run, init_seed
(the run's first init) and split columns.

Each run also writes load.json: the machine's 1- and 15-minute load averages when its training ends and its
CPU count, so that a time to the target says how busy the machine was (the 15-minute average over a run of
about that length is its mean load; the run's own training threads count in it).

`distribution(folder, rows, split, budget) -> (table, summary)` writes FOLDER/distribution.csv (DIST_COLUMNS:
one row per run and protocol at CODE_HELDOUT_L1) and FOLDER/distribution.json (per protocol: runs, reached,
median / min / max of samples_to_reach and wall_s_to_reach over the runs that reached the target, the split
and the budget). A run that did not reach it counts in runs and not in those statistics.

Every held-out evaluation reads the split's draw (`splits.Split.heldout_seed`) and only logs; no training
step or scout choice reads it.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pandas as pd
from tqdm.auto import tqdm

from lagbench.files.results import write_csv, write_json
from lagbench.replication.run import splits
from lagbench.replication.training.protocol import canonical_hash
from lagbench.speedstudy import train_target
from lagbench.speedstudy.train_target_run import run_study

TARGET = train_target.CODE_HELDOUT_L1
DIST_COLUMNS = ["protocol", "run", "init_seed", "chosen_seed", "split", "threshold", "reached", "samples_to_reach",
                "wall_s_to_reach", "best_l1", "final_l1", "hessian_rel_err", "samples_per_s", "budget",
                "load_1min_end", "load_15min_end", "cpus"]
STATS = ("samples_to_reach", "wall_s_to_reach")


def inits_per_run(name: str) -> int:
    """The inits one run of protocol `name` trains: its scouting's count, 1 without scouting."""
    p = train_target.protocols(1000, 1)[name].protocol
    return p.scouting.count if p.scouting else 1


def init_seeds(names, split: splits.Split, offset: int, runs: int) -> list[dict]:
    """[{protocol: first init seed} for each run]; a ValueError where the last run's inits leave the split."""
    if runs < 1:
        raise ValueError(f"--runs takes an integer >= 1; got {runs}")
    for name in names:
        last = offset + runs * inits_per_run(name) - 1
        if last >= splits.SEEDS_PER_SPLIT:
            raise ValueError(f"--seed {offset} with --runs {runs}: {name}'s inits reach offset {last}, past the "
                             f"{splits.SEEDS_PER_SPLIT} seeds of the {split.name} split; lower --seed or --runs")
    return [{name: split.first_seed + offset + r * inits_per_run(name) for name in names} for r in range(runs)]


def _finished(run_dir: Path, inputs: dict) -> bool:
    """True where run_dir holds a finished run of `inputs`; False where it is free (absent, empty, or an
    unfinished run of the same inputs); a ValueError naming it otherwise."""
    path = run_dir / "inputs.json"
    if path.exists():
        try:
            old = json.loads(path.read_text())
        except ValueError:
            old = {}
        if old != inputs:
            keys = sorted(k for k in set(old) | set(inputs) if old.get(k) != inputs.get(k))
            raise ValueError(f"{run_dir}: holds a run of other inputs (differs in {', '.join(keys)}); give "
                             f"another --out or remove that folder")
        return (run_dir / "train_target.csv").exists()
    if run_dir.exists() and any(run_dir.iterdir()):
        raise ValueError(f"{run_dir}: holds files but no inputs.json, so not a run of these inputs; give "
                         f"another --out or remove that folder")
    return False


def _load_record() -> dict:
    """The load averages now and the CPU count (NaN where the platform gives no load average)."""
    try:
        one, _, fifteen = os.getloadavg()
    except OSError:
        one = fifteen = float("nan")
    return {"load_1min_end": round(one, 2), "load_15min_end": round(fifteen, 2), "cpus": os.cpu_count()}


def _read_load(run_dir: Path) -> dict:
    path = run_dir / "load.json"
    if path.exists():
        return json.loads(path.read_text())
    return {"load_1min_end": float("nan"), "load_15min_end": float("nan"), "cpus": float("nan")}


def run_many(folder: Path, budget, hidden, n_heldout: int, names, split: splits.Split, offset: int, runs: int,
             progress: bool = True) -> pd.DataFrame:
    names = list(names or train_target.protocols(1000, 1))
    seeds = init_seeds(names, split, offset, runs)
    common = {"budget": int(budget), "hidden": [int(h) for h in hidden], "heldout_states": int(n_heldout),
              "protocols": names, "split": split.name, "heldout_seed": int(split.heldout_seed)}
    plan = [(folder / f"run{r}", {**common, "init_seeds": seeds[r]}) for r in range(runs)]
    done = [_finished(d, inputs) for d, inputs in plan]   # every folder checked before any training
    frames = []
    for r in tqdm(range(runs), desc="train-target runs", unit="run", disable=not progress):
        run_dir, inputs = plan[r]
        if done[r]:
            df = pd.read_csv(run_dir / "train_target.csv")
        else:
            run_dir.mkdir(parents=True, exist_ok=True)
            write_json(run_dir / "inputs.json", inputs)
            df = run_study(run_dir, budget, hidden, n_heldout, names=names, seed=inputs["init_seeds"],
                           progress=progress, heldout_seed=split.heldout_seed, desc=f"run {r}", leave=False)
            write_json(run_dir / "load.json", _load_record())
        frames.append(df.assign(**_read_load(run_dir), run=r, init_seed=df["protocol"].map(inputs["init_seeds"]), split=split.name))
    return pd.concat(frames, ignore_index=True)


def _stats(values) -> dict:
    v = np.asarray(values, float)
    if not v.size:
        return {"median": None, "min": None, "max": None}
    return {"median": float(np.median(v)), "min": float(v.min()), "max": float(v.max())}


def protocol_hash(name: str, budget, n_heldout: int, hidden) -> str:
    """16 hex digits identifying what protocol `name` trains at this budget, held-out size and width (its
    protocol dict and the widths), the same in every run of it: the record that the protocol did not change."""
    p = train_target.protocols(int(budget), int(n_heldout))[name].protocol
    return canonical_hash({"protocol": p.to_dict(), "hidden": [int(h) for h in hidden]}, 16)


def distribution(folder: Path, rows: pd.DataFrame, split: splits.Split, budget, n_heldout: int | None = None,
                 hidden=None) -> tuple[pd.DataFrame, dict]:
    at = rows[np.isclose(rows["threshold"].astype(float), TARGET)]
    table = at.assign(chosen_seed=at["seed"], threshold=TARGET, reached=at["samples_to_reach"].notna())
    table = table[DIST_COLUMNS].sort_values(["protocol", "run"], kind="stable").reset_index(drop=True)
    per = {}
    for name, g in table.groupby("protocol", sort=False):
        hit = g[g["reached"]]
        per[name] = {"runs": len(g), "reached": len(hit), "split": split.name, "budget": int(g["budget"].iloc[0]),
                     "init_seeds": [int(s) for s in g["init_seed"]],
                     "note": f"median over the runs that reached it; {len(hit)} of {len(g)} reached",
                     **{k: _stats(hit[k]) for k in STATS}}
        if n_heldout is not None and hidden is not None:
            per[name]["protocol_hash"] = protocol_hash(name, budget, n_heldout, hidden)
    summary = {"threshold": TARGET, "split": split.name, "heldout_seed": int(split.heldout_seed),
               "budget": int(budget), "protocols": per}
    write_csv(folder / "distribution.csv", table)
    write_json(folder / "distribution.json", summary)
    return table, summary


def summary_table(summary: dict) -> pd.DataFrame:
    """One printed row per protocol: reached of runs, and the reached runs' time and samples to the target."""
    out = []
    for name, p in summary["protocols"].items():
        w, s = p["wall_s_to_reach"], p["samples_to_reach"]
        out.append({"protocol": name, "split": p["split"], "reached": f"{p['reached']} of {p['runs']}",
                    "median_wall_s": w["median"], "min_wall_s": w["min"], "max_wall_s": w["max"],
                    "median_samples": s["median"], "min_samples": s["min"], "max_samples": s["max"]})
    return pd.DataFrame(out)
