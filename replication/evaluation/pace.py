"""Training pace: whether, and after how many samples, a model left the q-double-dot ~ 0 plateau and
reached the competence bar (claims 6 and 7).

`eval_pace(ctx)` adds to the held-out metrics (`routines.eval_heldout`), per level (`LEVELS`: a fraction
of the null predictor's held-out L1):
- ``left_plateau`` / ``reached_bar``: 1 if the held-out L1 is at most that level after the budget, else 0.
  Over a claim's seeds their mean is a share (`rules.faster` reports it with a Wilson interval);
- ``samples_to_leave`` / ``samples_to_bar``: training samples until the logged training loss first stays
  at or below the level for `RUN` consecutive log rows (one lucky batch does not count); +inf if never
  (`rules.faster` compares them between models).
"""
from __future__ import annotations

import math

from lagbench.replication.claims.bars import FRACTION
from lagbench.replication.evaluation.routines import eval_heldout

PLATEAU = 0.5   # off the plateau: at most half the null predictor's error (the plateau sits at the null's)
LEVELS = {"left_plateau": ("samples_to_leave", PLATEAU), "reached_bar": ("samples_to_bar", FRACTION)}
RUN = 3         # consecutive logged training losses at or below the level


def samples_to_level(log, level: float, batch: int) -> float:
    """Samples (step x batch) at the first of `RUN` consecutive log rows with loss <= level; inf if none."""
    rows = [r for r in log or () if r.get("loss") is not None]
    for i in range(len(rows) - RUN + 1):
        if all(float(r["loss"]) <= level for r in rows[i:i + RUN]):
            return float(rows[i]["step"] * batch)
    return math.inf


def eval_pace(ctx):
    out = eval_heldout(ctx)
    m = out.metrics
    for share, (pace, fraction) in LEVELS.items():
        level = fraction * m["null_heldout_l1"]
        m[share] = float(m["heldout_l1"] <= level)
        m[pace] = samples_to_level(ctx.log, level, ctx.protocol.batch)
    return out
