"""Whether two runs' `summary/units.csv` hold the same numbers, column by column: the check that a
refactor changed no result (rows matched on claim, framework, model and seed; the timing columns, which
differ from run to run, reported apart).

`python -m lagbench.replication.run.same_numbers A/summary/units.csv B/summary/units.csv` prints the rows and
columns compared and the columns that differ; exit status 0 when only timing columns differ, 1 otherwise.
"""
from __future__ import annotations

import argparse
import sys

import numpy as np
import pandas as pd

KEY = ("claim", "framework", "model", "seed")
TIMING = ("train_time_s", "train_samples_per_s", "wall_time_s")


def compare(a: pd.DataFrame, b: pd.DataFrame) -> dict:
    """{"rows", "columns", "only_in_one" (columns), "unmatched" (row keys in one only), "differ" (columns
    whose values differ, timing columns excluded), "timing_differ"}."""
    key = list(KEY)
    a, b = a.sort_values(key).reset_index(drop=True), b.sort_values(key).reset_index(drop=True)
    ka, kb = set(map(tuple, a[key].astype(str).values)), set(map(tuple, b[key].astype(str).values))
    unmatched = sorted(ka ^ kb)
    common = [c for c in a.columns if c in b.columns]
    differ = []
    if not unmatched:
        for c in common:
            x, y = a[c], b[c]
            if x.dtype.kind in "fiub" and y.dtype.kind in "fiub":
                same = np.array_equal(x.to_numpy(float), y.to_numpy(float), equal_nan=True)
            else:
                same = bool((x.astype(str) == y.astype(str)).all())
            if not same:
                differ.append(c)
    return {"rows": len(a), "columns": len(common), "only_in_one": sorted(set(a.columns) ^ set(b.columns)),
            "unmatched": unmatched, "differ": [c for c in differ if c not in TIMING],
            "timing_differ": [c for c in differ if c in TIMING]}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m lagbench.replication.run.same_numbers",
                                description="Compare two runs' summary/units.csv column by column.")
    p.add_argument("a", help="the first run's summary/units.csv")
    p.add_argument("b", help="the second run's summary/units.csv")
    args = p.parse_args(argv)
    try:
        r = compare(pd.read_csv(args.a), pd.read_csv(args.b))
    except (OSError, ValueError, KeyError) as e:
        print(f"same_numbers: cannot compare: {e}", file=sys.stderr)
        return 2
    print(f"{r['rows']} rows x {r['columns']} columns; columns in one file only: {r['only_in_one'] or 'none'}; "
          f"rows in one file only: {len(r['unmatched'])}")
    print(f"differing columns: {r['differ'] or 'none'}; timing columns differing: {r['timing_differ'] or 'none'}")
    return 0 if not (r["differ"] or r["unmatched"] or r["only_in_one"]) else 1


if __name__ == "__main__":
    raise SystemExit(main())
