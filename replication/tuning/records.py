"""A search's finished units as small rows in one CSV file: a search longer than one sitting accumulates.

`lagbench tune --record FILE` appends a row for every unit it finishes (its key, model, configuration,
knob values, seed, status, the metric it is scored by and its score, and training seconds; no weights), and a later run, on this machine or on
a fresh one with the file committed, reads the score of a unit whose key is in the file instead of training
it again.

`unit_key(unit) -> str`: the hash of everything a unit's score depends on: the claim, framework, seed and
split, the protocol, the model spec, the evaluation config and the evaluation version. A unit whose protocol
or evaluation changed has another key, so a stale row is never reused.
`read(path) -> {key: row}`: the rows of FILE (none if it does not exist); an unreadable file is an error.
`append(path, rows)`: FILE rewritten with the new rows after the old ones (written atomically).
"""
from __future__ import annotations

import math
from pathlib import Path

import pandas as pd

from lagbench.files import results as R
from lagbench.replication.evaluation.registry import EVALUATION_VERSION
from lagbench.replication.training.protocol import canonical_hash

COLUMNS = ["key", "claim", "profile", "model", "config", "knob_lr", "knob_width", "framework", "seed", "split",
           "status", "metric", "score", "train_time_s", "train_samples", "cpu"]


def unit_key(unit) -> str:
    return canonical_hash({"claim": unit.claim.id, "framework": unit.framework, "seed": unit.seed,
                           "split": unit.split, "protocol": unit.protocol().to_dict(), "spec": unit.spec().to_dict(),
                           "eval_config": unit.claim.evaluation_config(unit.profile),
                           "evaluation_version": EVALUATION_VERSION}, 20)


def read(path) -> dict[str, dict]:
    path = Path(path)
    if not path.exists():
        return {}
    try:
        df = pd.read_csv(path, dtype={"key": str})
    except (OSError, ValueError) as e:
        raise ValueError(f"--record {path}: cannot read it as a search record ({e})") from None
    missing = [c for c in COLUMNS if c not in df.columns]
    if missing:
        raise ValueError(f"--record {path}: not a search record (no column {', '.join(missing)})")
    rows = {}
    for r in df.to_dict("records"):
        score = r["score"]
        r["score"] = None if score is None or (isinstance(score, float) and math.isnan(score)) else float(score)
        rows[str(r["key"])] = r
    return rows


def append(path, rows: list[dict]) -> None:
    if not rows:
        return
    path = Path(path)
    old = pd.read_csv(path, dtype={"key": str}) if path.exists() else pd.DataFrame(columns=COLUMNS)
    new = pd.DataFrame(rows, columns=COLUMNS)
    R.write_csv(path, pd.concat([old, new], ignore_index=True) if len(old) else new)
