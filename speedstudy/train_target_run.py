"""`lagbench train-target`: the train-to-target study alone, written to a folder as it goes.

`run_study(folder, budget, hidden, n_heldout, names=None, seed=0, progress=True, heldout_seed=HELDOUT_SEED,
desc=..., leave=True) -> DataFrame` writes FOLDER/train_target.csv (one row per protocol and threshold;
written last, so its presence marks a finished run), FOLDER/train_target_log.csv (every held-out
evaluation, rewritten after each one, so an interrupted run keeps its curve) and each protocol's final model
(FOLDER/<protocol>.npz + .spec.json, loadable by both frameworks). seed: one init seed, or {protocol: init
seed}; heldout_seed: the held-out draw the evaluations read (the split's). Several runs of it, on either
split, and their distribution: `speedstudy.target_distribution`.
"""
from __future__ import annotations

from pathlib import Path

import pandas as pd
from tqdm.auto import tqdm

from lagbench.files.results import write_csv, write_json, write_npz
from lagbench.replication.training.data import HELDOUT_SEED
from lagbench.speedstudy import train_target


def check_names(names) -> None:
    """Unknown protocol names -> ValueError naming the valid ones (before any folder is made)."""
    table = train_target.protocols(1000, 1)
    unknown = sorted(set(names or ()) - set(table))
    if unknown:
        raise ValueError(f"unknown train-target protocol(s) {', '.join(unknown)}; valid: {', '.join(table)}")


def run_study(folder: Path, budget: int, hidden, n_heldout: int, names=None, seed=0,
              progress: bool = True, heldout_seed: int = HELDOUT_SEED, desc: str = "lagbench train-target",
              leave: bool = True) -> pd.DataFrame:
    check_names(names)
    table = train_target.protocols(1000, 1)
    n = sum(train_target.n_evaluations(table[k]) for k in (names or table) if k in table)
    bar = tqdm(total=n, desc=desc, unit="eval", disable=not progress, leave=leave)

    def on_eval(log):
        write_csv(folder / "train_target_log.csv", pd.DataFrame(log))
        bar.n = min(sum(r["step"] > 0 for r in log), bar.total)
        bar.set_postfix_str(f"{log[-1]['protocol']}: held-out L1 {log[-1]['heldout_l1']:.4g}")

    def on_model(name, spec, model):
        import lagbench.models.jax

        write_npz(folder / f"{name}.npz", lagbench.models.jax.to_params(model))
        write_json(folder / f"{name}.spec.json", spec.to_dict())

    rows, log = train_target.study(budget, hidden, n_heldout, names=names, on_eval=on_eval, seed=seed,
                                   on_model=on_model, heldout_seed=heldout_seed)
    bar.close()
    df = pd.DataFrame(rows)
    write_csv(folder / "train_target.csv", df)
    write_csv(folder / "train_target_log.csv", pd.DataFrame(log))
    return df
