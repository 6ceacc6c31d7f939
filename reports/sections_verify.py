"""The re-verification section: ``RESULTS/verify/verify.csv`` from ``lagbench verify``.

``verify_sections(res) -> list[Section]``: how many of the folder's units were retrained from scratch and compared
with the stored ones, where and when (one row per verification), each unit's outcome (its worst value:
identical, within the stated tolerance, differs, error), and every value that is not identical (a metric of
wall time, "timing", is never compared). Nothing where
the folder holds no verify.csv.
"""

from __future__ import annotations

import pandas as pd

from lagbench.reports.document import Para, Section, Table
from lagbench.reports.fmt import num
from lagbench.reports.load import Results

OUTCOMES = ("timing", "identical", "within", "differs", "error")   # worst last, as `replication.run.verify` ranks them
SOURCE = "verify/verify.csv"


def _worst(values) -> str:
    return max((v if v in OUTCOMES else "error" for v in values), key=OUTCOMES.index)


def verify_sections(res: Results) -> list[Section]:
    try:
        df = pd.read_csv(res.root / SOURCE)
    except (OSError, ValueError):
        return []
    s = Section("Re-verification: units retrained from scratch")
    if not {"verified_at", "where", "unit", "value", "outcome"} <= set(df.columns) or df.empty:
        return [s.add(Para(f"{SOURCE} lacks the columns `lagbench verify` writes, or holds no row; not used."))]
    units = df.groupby(["verified_at", "where", "unit"], sort=False)["outcome"].agg(_worst).reset_index()
    rows = []
    for (at, where), g in units.groupby(["verified_at", "where"], sort=False):
        tol = sorted(df[(df["verified_at"] == at) & (df["where"] == where)]["tolerance"].dropna().unique())
        rows.append({"when": at, "where": where, "units": len(g),
                     **{k: int((g["outcome"] == k).sum()) for k in OUTCOMES[1:]},
                     "tolerance": ", ".join(num(t) for t in tol) or "–"})
    s.add(Para(f"{units['unit'].nunique()} distinct units of this folder were retrained from scratch by `lagbench "
               f"verify` ({len(rows)} verification{'s' if len(rows) != 1 else ''}) and compared value by value with "
               "the stored results: identical bit for bit, else held against a relative tolerance (the strict one "
               "where retrained on the same kind of CPU with the same library versions, a looser one elsewhere: "
               "float32 training is chaotic at the level of rounding)."))
    s.add(Table("Re-verifications: where and when, and each unit's outcome", pd.DataFrame(rows), [SOURCE]))
    off = df[~df["outcome"].isin(("identical", "timing"))]   # wall-clock metrics are shown by verify, not compared
    if len(off):
        cols = [c for c in ("verified_at", "unit", "value", "stored", "recomputed", "rel_diff", "tolerance", "outcome",
                            "note") if c in off.columns]
        shown = off[cols].astype(object).fillna("–").reset_index(drop=True)
        s.add(Table("Re-verified values that are not identical", shown, [SOURCE]))
    return [s]
