"""A model at a chosen held-out accuracy: the tracked checkpoint nearest a registered level (claim 2).

The LNN paper's point in Fig. 2(b) is energy conservation at equal loss; a comparison at the end of
training compares models of different accuracy as well. `Tracking(keep=True)` keeps a training's
parameters at its tracked steps, with their held-out loss on the development draw (the tracker's states).
`at_level(ctx, level, evaluate) -> metrics`: the kept checkpoint whose tracked loss is nearest `level` (in
log; the later one on a tie), evaluated by `evaluate(ctx of that checkpoint)` on the unit's own split; its
metrics come back prefixed "matched_" with `matched_tracked_l1` (the tracked loss it was chosen by),
`matched_samples` (training samples up to it) and `match_level`. The choice reads only the development
draw and the registered level, never the split the verdict reads. Empty without kept checkpoints or
a finite tracked loss.
"""
from __future__ import annotations

import dataclasses
import math

from lagbench.replication.evaluation.adapters import adapter
from lagbench.replication.training.tracking import unstack


def nearest(losses, level: float) -> int | None:
    """Index of the loss nearest `level` in log (the later on a tie); None if none is finite and positive."""
    best, gap = None, math.inf
    for i, v in enumerate(losses):
        if v is None or not math.isfinite(v) or v <= 0:
            continue
        d = abs(math.log(v) - math.log(level))
        if d <= gap:
            best, gap = i, d
    return best


def at_level(ctx, level: float, evaluate) -> dict:
    tracked = getattr(ctx, "tracked", None)
    params = unstack(tracked)
    if not params:
        return {}
    rows = {int(r["step"]): r for r in (ctx.log or []) if r.get("heldout_loss") is not None}
    losses = [float(rows[int(s)]["heldout_loss"]) if int(s) in rows else None for s in tracked["step"]]
    i = nearest(losses, level)
    if i is None:
        return {}
    there = dataclasses.replace(ctx, params=params[i], model=adapter(ctx.framework, ctx.spec, params[i]), tracked=None)
    metrics = evaluate(there)
    out = {f"matched_{k}": v for k, v in metrics.items()}
    samples = rows[int(tracked["step"][i])].get("samples")
    out.update({"matched_tracked_l1": losses[i], "match_level": float(level),
                "matched_samples": float(samples) if samples is not None else math.nan})
    return out
