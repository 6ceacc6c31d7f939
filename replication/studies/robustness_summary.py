"""The robustness study's table for people: one row per scene, from OUT/scenes.csv and recommendation.csv.

`summary_frame(scenes, rec) -> DataFrame` (the report's table) and `summary_markdown(scenes, rec) -> str`: per
scene and framework the median over seeds of each learned model's
torque nMSE (the null's is 1), the DeLaN / ff ratios of torque and tracking error with and without the
dissipation term (median, then each seed's in brackets), the dissipative DeLaN's learned b per joint
(median) and the recommended model. `lagbench robustness` writes it to OUT/summary.md and prints it.
"""
from __future__ import annotations

import pandas as pd

RATIOS = (("torque_ratio_to_ff", "delan", "torque DeLaN/ff"), ("torque_ratio_to_ff", "delan_dissipation",
          "torque +diss./ff"), ("track_ratio_to_ff", "delan", "track DeLaN/ff"),
          ("track_ratio_to_ff", "delan_dissipation", "track +diss./ff"))


def _g(x: float) -> str:
    return f"{x:.3g}"


def summary_frame(scenes: pd.DataFrame, rec: pd.DataFrame) -> pd.DataFrame:
    """One row per scene and framework, the cells as text (the columns of summary_markdown)."""
    learned = scenes[~scenes["model"].isin(("zero_torque", "exact"))].copy()
    learned["seed"] = learned["seed"].astype(str)
    head = ["scene", "framework", "DeLaN nMSE", "+diss. nMSE", "ff nMSE", *(r[2] for r in RATIOS), "b learned", "pick"]
    picks = {(r.scene, r.framework): r.recommended for r in rec.itertuples()}
    rows = []
    for (scene, fw), g in learned.groupby(["scene", "framework"], sort=False):
        by = {m: gm.sort_values("seed") for m, gm in g.groupby("model")}
        cells = [scene, fw, *(_g(by[m]["torque_nmse"].median()) for m in ("delan", "delan_dissipation", "ff"))]
        for col, m, _ in RATIOS:
            v = by[m][col]
            cells.append(f"{_g(v.median())} ({', '.join(_g(x) for x in v)})")
        d = by["delan_dissipation"]
        cells.append(f"{_g(d['b0'].median())}, {_g(d['b1'].median())}")
        cells.append(str(picks.get((scene, fw), "–")))
        rows.append(cells)
    return pd.DataFrame(rows, columns=head)


def summary_markdown(scenes: pd.DataFrame, rec: pd.DataFrame) -> str:
    df = summary_frame(scenes, rec)
    lines = ["| " + " | ".join(df.columns) + " |", "|" + "---|" * len(df.columns)]
    lines += ["| " + " | ".join(row) + " |" for row in df.itertuples(index=False)]
    return "\n".join(lines) + "\n"
