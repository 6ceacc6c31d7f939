"""`lagbench fit --tune N`: the suite's declared search (`replication.tuning.search`) on a user's data.

`tune_fit(data, out, n_configs, on_log, on_progress, on_train, **options) -> (record, ledger)`: the first `n_configs`
configurations of the search (the given options first, then other combinations of peak rate x 1/3, 1, 3
and hidden widths x 1/2, 1, 2; the same list as every claim's) are each fitted to the training rows with no
test file, and scored by the fit's loss on its held-out rows (the development split of the user's data: the
test file is never read while choosing). The lowest is fitted again with the test file, if any, into `out`,
as a plain `fit` with those options. The configurations' fits go to OUT/tune/config<k>/, the ledger to
OUT/tune/ledger.json and ledger.csv (per configuration its knobs, options and score, the chosen one).
"""
from __future__ import annotations

import math
from pathlib import Path

import pandas as pd

from lagbench.files import results as R
from lagbench.replication.tuning import search


def _score(record: dict) -> float | None:
    v = (record.get("metrics") or {}).get(record.get("metric", ""))
    return float(v) if record.get("status") == "ok" and isinstance(v, int | float) and math.isfinite(v) else None


def tune_fit(data, out="results/fit", n_configs: int = 4, on_log=None, on_progress=None, on_train=None, **options):
    from lagbench.replication.fit.resolve import resolved
    from lagbench.replication.fit.task import fit

    o = resolved(data, options)[0]   # the model kind's defaults where not given
    if not o.heldout or o.split == "none":
        raise ValueError("--tune: needs held-out rows of the training data to choose by (--holdout-fraction > 0 "
                         "and --holdout other than none); the test file is never read while choosing")
    try:
        grid = search.configs(n_configs)
    except ValueError:
        raise ValueError(f"--tune: {n_configs!r} is not valid; expected 1 to {search.SIZE} "
                         "configurations (the search's combinations)") from None
    out = R.output_folder(out, "--out")
    rows = []
    for k, knobs in enumerate(grid):
        chosen = {**options, "lr": o.lr * knobs["lr"], "test": None,
                  "hidden": search.scaled_widths(o.hidden, knobs["width"])}
        record = fit(data, out=out / "tune" / f"config{k}", on_log=on_log, on_progress=on_progress, on_train=on_train,
                     **chosen)
        rows.append({"config": k, **{f"knob_{n}": v for n, v in knobs.items()}, "lr": chosen["lr"],
                     "hidden": ",".join(map(str, chosen["hidden"])), "metric": record.get("metric"),
                     "score": _score(record), "status": record.get("status")})
    df = pd.DataFrame(rows)
    scored = df.dropna(subset=["score"])
    if not len(scored):
        raise ValueError("--tune: no configuration finished with a held-out score; see OUT/tune/config*/")
    best = int(scored.loc[scored["score"].idxmin(), "config"])
    final = {**options, "lr": float(df.loc[best, "lr"]),
             "hidden": tuple(int(x) for x in str(df.loc[best, "hidden"]).split(","))}
    R.write_csv(out / "tune" / "ledger.csv", df)
    ledger = {"schema": R.SCHEMA, "split": "held-out rows of the training data", "configs": grid,
              "search": {n: list(v) for n, v in search.KNOBS.items()}, "chosen": best, "chosen_knobs": grid[best],
              "options": {"lr": final["lr"], "hidden": list(final["hidden"])},
              "scores": {int(r.config): (None if pd.isna(r.score) else float(r.score)) for r in df.itertuples()}}
    R.write_json(Path(out) / "tune" / "ledger.json", ledger)
    record = fit(data, out=out, on_log=on_log, on_progress=on_progress, on_train=on_train, **final)
    return record, ledger
