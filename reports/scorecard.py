"""The scorecard that opens the report, and the per-claim competence table.

``scorecard_section(res)``: one row per claim: the verdict (recomputed from the unit files), the key
model's reproduced number per framework beside its published number, marked "like for like" only when
the published value is of the same kind and measured under the same conditions (else "context"), and a
one-sentence reason. ``competence_table(res, claim)``: each model's competence bar per framework.
"""

from __future__ import annotations

import pandas as pd

from reports.document import NOT_RUN, Para, Section, Table
from reports.fmt import cell, stat, summarise
from reports.load import Results
from reports.tables import published_cell, published_entry

REASON_CHARS = 240


def _metric_of(u, name: str):
    if name == "final_train_loss":
        v = u.result.get("final_train_loss")
        return float(v) if isinstance(v, int | float) and not isinstance(v, bool) else None
    return u.metric(name)


def _reproduced(res: Results, claim: dict, model: str, metric: str) -> str:
    parts = []
    for fw in res.frameworks:
        us = [u for u in res.usable(claim["id"]) if u.model == model and u.framework == fw]
        vals = [_metric_of(u, metric) for u in us]
        s = summarise(vals)
        n_inf = sum(v is not None and v == float("inf") for v in vals)
        text = "inf" if n_inf == len(vals) and vals else (stat(**s) if s["n"] else NOT_RUN)
        if n_inf and n_inf < len(vals):
            text = f"inf ({n_inf} of {len(vals)} seeds diverged; finite: {stat(**s)})"
        parts.append(f"{fw} {text}")
    return "; ".join(parts) if parts else NOT_RUN


def _reason(v: dict | None) -> str:
    if not v:
        return "no verdict"
    text = str(v.get("reason") or "")
    first = text.split(" | ")[0]
    return first if len(first) <= REASON_CHARS else first[: REASON_CHARS - 1] + "…"


def scorecard_table(res: Results) -> pd.DataFrame:
    rows = []
    for claim in res.claims:
        cid = claim["id"]
        key = claim.get("key") or next(iter(claim.get("models") or []), "")
        p = published_entry(claim, key)
        metric = (p or {}).get("metric") or claim.get("metric") or ""
        published = published_cell(claim, key, [u for u in res.usable(cid) if u.model == key])
        v = res.verdicts.get(cid)
        rows.append({"#": cell(claim.get("number"), "–"), "claim": cid,
                     "verdict": cell((v or {}).get("verdict"), NOT_RUN),
                     "key number": f"{key} {metric}: {_reproduced(res, claim, key, metric)}" if key else NOT_RUN,
                     "published": published, "why": _reason(v)})
    return pd.DataFrame(rows) if rows else pd.DataFrame({"claim": [NOT_RUN], "verdict": [NOT_RUN]})


def scorecard_section(res: Results) -> Section:
    s = Section("Scorecard")
    s.add(Para("One line per claim. The verdict is recomputed from the unit files by the runner's own rule "
               "(replication/claims/verdicts.py): a model below its competence bar (held-out error at most a set "
               "fraction of a null predictor's, rollouts that do not diverge) makes a claim 'inconclusive'; "
               "an ordering needs the seed ranges apart. A published number is 'like for like' only when it "
               "is the same kind of number (training loss, held-out error, energy error) measured under the "
               "same conditions; otherwise it is context, not a target."))
    if res.unfinished or res.planned_missing:
        s.add(Para(f"This run is unfinished: {len(res.planned_missing)} planned unit(s) have no result "
                   "(see Run status); the verdicts below rest on the units present."))
    s.add(Table("Scorecard", scorecard_table(res), ["claims.json", "units/*/*/*/seed*/result.json"]))
    return s


def competence_table(res: Results, claim: dict) -> pd.DataFrame | None:
    v = res.verdicts.get(claim["id"]) or {}
    comp = v.get("competence") or {}
    rows = []
    for fw, per in comp.items():
        for model, r in (per or {}).items():
            rows.append({"model": model, "framework": fw, "passed": "yes" if r.get("passed") else "no",
                         "bar": cell(r.get("why"), "")})
    return pd.DataFrame(rows) if rows else None
