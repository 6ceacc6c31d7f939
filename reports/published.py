"""Published numbers beside ours: the scorecard's short cell and the table that follows the scorecard.

``published_short(res, claim, model)``: "0.0689 (held-out; context)", like for like only for the same kind of
number under the same conditions (``tables.like_for_like``). ``published_table(res)``: every published number of
every claim's models, where it is printed, our seed mean of the same metric per framework, ours over it, and
why it is context where it is not like for like.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from lagbench.reports.document import NOT_RUN
from lagbench.reports.fmt import cell, num
from lagbench.reports.load import Results
from lagbench.reports.tables import like_for_like, metric_of, per_framework, published_entry


def published_short(res: Results, claim: dict, key: str) -> str:
    """The key model's published value and its kind, like for like or context (in full: `published_table`)."""
    p = published_entry(claim, key)
    if p is None:
        return "none published"
    same, _ = like_for_like(p, [u for u in res.usable(claim["id"]) if u.model == key])
    return f"{num(p.get('value'))} ({p.get('kind')}; {'like for like' if same else 'context'})"


def published_table(res: Results) -> pd.DataFrame | None:
    """Every published number of every claim's models beside ours of the same metric: what it is, where it is
    printed, whether it is like for like (else why it is context) and our seed mean over it."""
    rows = []
    for claim in res.claims:
        for model, p in (claim.get("published") or {}).items():
            p = published_entry(claim, model)
            if p is None or p.get("value") is None:
                continue
            units = [u for u in res.usable(claim["id"]) if u.model == model]
            same, why = like_for_like(p, units)
            metric = p.get("metric") or ""
            vals = [metric_of(u, metric) for u in units] if metric else []
            vals = [x for x in vals if x is not None and np.isfinite(x)]
            ratio = (f"{num(float(np.mean(vals)) / float(p['value']), 2)}x" if vals and float(p["value"]) > 0
                     else "–")
            rows.append({"#": cell(claim.get("number"), "–"), "claim": claim["id"], "model": model,
                         "published": f"{num(p.get('value'))} ({p.get('kind')}; from: {p.get('source') or 'not stated'})",
                         "ours, same metric": (f"{metric}: {per_framework(res, claim, model, metric) or NOT_RUN}"
                                               if metric else "we measure none"),
                         "ours / published": ratio,
                         "comparison": "like for like" if same else f"context only: {why}"})
    return pd.DataFrame(rows) if rows else None
