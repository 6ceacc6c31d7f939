"""Per-claim tables (pandas DataFrames of strings) computed from usable units only.

Numbers are recomputed here from the unit ``result.json`` files (corrupt and failed units excluded), so
they match the units actually listed; verdicts are recomputed from them too (``reports.load``). A claim with no
usable unit reads ``"not run"`` in every cell that would hold a number. A claim's metric reads as its seed mean
with the range over seeds (``fmt.seed_values``; a pooled claim's yes/no metric as "k/n seeds"), per framework
(``per_framework``).
"""

from __future__ import annotations

import pandas as pd

from lagbench.replication.claims.published import Published
from lagbench.replication.evaluation.diverged import SCALED, is_diverged
from lagbench.reports.document import NOT_RUN
from lagbench.reports.fmt import cell, num, seed_values, stat, summarise
from lagbench.reports.glossary import unit
from lagbench.reports.load import Results, Unit


def claim_models(res: Results, claim: dict) -> list[str]:
    declared = [str(m) for m in claim.get("models") or []]
    seen = sorted({u.model for u in res.claim_units(claim["id"])} - set(declared))
    return declared + seen


def values(units: list[Unit], metric: str | None) -> dict:
    """``{framework: {model: {"mean", "std", "n"}}}`` of ``metric`` over seeds of usable units."""
    out: dict[str, dict[str, dict]] = {}
    if not metric:
        return out
    groups: dict[tuple[str, str], list[float]] = {}
    for u in units:
        if u.status == "ok":
            groups.setdefault((u.framework, u.model), []).append(u.metric(metric))
    for (fw, model), vals in groups.items():
        s = summarise(vals)
        if s["n"]:
            out.setdefault(fw, {})[model] = s
    return out


def published_entry(claim: dict, model: str) -> dict | None:
    """The published record of ``model`` (a bare number from an older claims.json becomes one), or None."""
    pub = claim.get("published")
    p = pub.get(model) if isinstance(pub, dict) else None
    if isinstance(p, dict):
        return p
    return {"value": p, "kind": "unknown", "metric": ""} if isinstance(p, int | float) else None


def like_for_like(p: dict, units) -> tuple[bool, str]:
    """`Published.like_for_like` against every unit's recorded evaluation config, widths and training samples
    (all must match)."""
    pub = Published.from_dict(p)
    for u in units or [None]:
        r = u.result if u is not None else {}
        same, why = pub.like_for_like(r.get("eval_config"), (r.get("model_spec") or {}).get("hidden"),
                                      r.get("train_samples"))
        if not same:
            return False, why
    return True, ""


def published_cell(claim: dict, model: str, units, short: bool = False) -> str:
    """The published value of ``model``, what it is, and whether ``units`` measured the same thing (``short``:
    the value and "like for like" or "context" alone; the scorecard's published table says why)."""
    p = published_entry(claim, model)
    if p is None:
        return "none published"
    same, why = like_for_like(p, units)
    if short:
        return f"{num(p.get('value'))} ({'like for like' if same else 'context'})"
    note = f"; {p['note']}" if p.get("note") else ""
    return (f"{num(p.get('value'))} ({p.get('kind')}, like for like{note})" if same
            else f"{num(p.get('value'))} ({p.get('kind')}; context only: {why}{note})")


def verdict_text(res: Results, claim: dict) -> str:
    v = res.verdicts.get(claim["id"])
    usable = res.usable(claim["id"])
    if v is None:
        text = NOT_RUN if not usable else "not judged (no verdict in summary/verdicts.json)"
    else:
        text = cell(v.get("verdict"), "not judged")
        by_fw = v.get("by_framework") or {}
        if isinstance(by_fw, dict) and len(set(map(str, by_fw.values()))) > 1:
            text += " (" + ", ".join(f"{fw}: {x}" for fw, x in by_fw.items()) + ")"
    corrupt = sum(u.status == "corrupt" for u in res.claim_units(claim["id"]))
    if corrupt:
        text += f"; {corrupt} corrupt unit{'s' if corrupt > 1 else ''} excluded"
    return text


def claim_table(res: Results, claim: dict) -> pd.DataFrame:
    """Rows: models; columns: published value (in short: the scorecard's published table has it in full) and
    the claim metric per framework: the seed mean with the range
    over seeds (a yes/no metric of a pooled claim as "k/n seeds"), every seed's value where a seed of the
    model is below its competence bar."""
    metric = claim.get("metric")
    comp = (res.verdicts.get(claim["id"]) or {}).get("competence") or {}
    rows = []
    for model in claim_models(res, claim):
        units = [u for u in res.usable(claim["id"]) if u.model == model]
        added = any((u.result.get("model_spec") or {}).get("kind") == "user" for u in units)
        row = {"model": f"{model} (added: --add-model; no verdict reads it)" if added else model,
               "published": published_cell(claim, model, units, short=True)}
        for fw in res.frameworks or ["any framework"]:
            mine = [u for u in units if u.framework == fw or fw == "any framework"]
            vals = [u.metric(metric) for u in mine] if metric else []
            row[fw] = seed_values(vals, bool(claim.get("pooled"))) if any(v is not None for v in vals) else NOT_RUN
            if ((comp.get(fw) or {}).get(model) or {}).get("passed") is False and len(mine) > 1:
                row[fw] += "; per seed: " + ", ".join(f"{u.seed} {num(u.metric(metric))}" for u in mine)
        rows.append(row)
    return pd.DataFrame(rows) if rows else pd.DataFrame({"model": [NOT_RUN]})


def metric_names(units: list[Unit]) -> list[str]:
    names: dict[str, None] = {}
    for u in units:
        for k, v in (u.result.get("metrics") or {}).items():
            if u.metric(k) is not None or v is None:
                names.setdefault(k, None)
    return list(names)


def metric_cell(name: str, vals: list) -> str:
    """One metric over a model's seeds: mean ± std, a yes/no metric as k/n seeds; an error against the data's
    own scale (`diverged.SCALED`) that diverged on a seed is counted apart, never averaged in."""
    scaled = name in SCALED or name.split("_", 1)[-1] in SCALED
    blown = sum(map(is_diverged, vals)) if scaled else 0
    s = summarise([v for v in vals if not (scaled and is_diverged(v))])
    if unit(name) == "share":
        return seed_values(vals, share=True) if s["n"] else "not recorded"
    text = stat(s["mean"], s["std"]) if s["n"] else ""
    if blown:
        return "; ".join(x for x in (text, f"{blown} of {len(vals)} seeds diverged") if x)
    return text or "not recorded"


def metrics_table(res: Results, claim: dict, max_metrics: int = 7) -> pd.DataFrame | None:
    """Rows: (model, framework); columns: every recorded metric (mean ± std; a yes/no metric as k/n seeds),
    first ``max_metrics``."""
    units = res.usable(claim["id"])
    names = metric_names(units)
    if claim.get("metric") in names:
        names.remove(claim["metric"])
        names.insert(0, claim["metric"])
    names = names[:max_metrics]
    if not names:
        return None
    rows = []
    for model in claim_models(res, claim):
        for fw in res.frameworks:
            group = [u for u in units if u.model == model and u.framework == fw]
            if not group:
                continue
            row = {"model": model, "framework": fw, "n": str(len(group))}
            for name in names:
                row[name] = metric_cell(name, [u.metric(name) for u in group])
            rows.append(row)
    return pd.DataFrame(rows) if rows else None


def status_table(res: Results) -> pd.DataFrame:
    """Rows: claims; columns: per framework ``ok/failed/corrupt`` unit counts."""
    rows = []
    for claim in res.claims:
        row = {"claim": claim["id"]}
        for fw in res.frameworks or ["any framework"]:
            us = [u for u in res.claim_units(claim["id"]) if u.framework == fw]
            if not us:
                row[fw] = NOT_RUN
                continue
            counts = {s: sum(u.status == s for u in us) for s in ("ok", "failed", "corrupt")}
            row[fw] = ", ".join(f"{n} {s}" for s, n in counts.items() if n)
        rows.append(row)
    return pd.DataFrame(rows) if rows else pd.DataFrame({"claim": [NOT_RUN]})


PROBLEM_UNITS = "Failed, corrupt and missing units"


def excluded_note(reader: str) -> str:
    """What every reader of a results folder says of the units it leaves out (`reader`: "report", "table")."""
    return (f"Corrupt units failed checksum or schema checks and are excluded from every number in this {reader}; "
            f"failed units (the runner's status) are excluded too.")


def problem_units_table(res: Results) -> pd.DataFrame | None:
    rows = [
        {"unit": u.rel, "status": u.status, "reason": cell(u.reason, "unknown")}
        for u in res.units
        if u.status != "ok"
    ]
    rows += [{"unit": p, "status": "missing", "reason": "listed in summary/units.csv, no result.json"}
             for p in res.listed_missing]
    rows += [{"unit": p, "status": "missing", "reason": "planned in run.json, no result.json"}
             for p in res.planned_missing if p not in res.listed_missing]
    return pd.DataFrame(rows) if rows else None


FRAMEWORK_NAMES = {"jax": "JAX", "torch": "PyTorch"}


def metric_of(u, name: str):
    """A unit's metric, or its recorded final training loss (not among its metrics)."""
    if name == "final_train_loss":
        v = u.result.get("final_train_loss")
        return float(v) if isinstance(v, int | float) and not isinstance(v, bool) else None
    return u.metric(name)


def per_framework(res: Results, claim: dict, model: str, metric: str) -> str:
    """"JAX 0.141 (0.137 to 0.145, 2 seeds); PyTorch ..." ("" where no framework recorded it)."""
    share = bool(claim.get("pooled")) or unit(metric) == "share"
    per = []
    for fw in res.frameworks:
        vals = [metric_of(u, metric) for u in res.usable(claim["id"]) if u.model == model and u.framework == fw]
        if any(v is not None for v in vals):
            per.append(f"{FRAMEWORK_NAMES.get(fw, fw)} {seed_values(vals, share)}")
    return "; ".join(per)
