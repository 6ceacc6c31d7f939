"""Per-claim verdicts from the finished units of a results folder (summary/units.csv, verdicts.json)."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd

from replication import results as R
from replication.claims import CLAIMS


def collect_units(out) -> pd.DataFrame:
    rows = []
    for f in sorted(Path(out).glob("units/*/*/*/seed*/result.json")):
        try:
            d = R.load_result(f.parent)
        except R.CorruptResult:
            continue
        rows.append({"claim": d["claim"], "framework": d["framework"], "model": d["model"], "seed": d["seed"],
                     "status": d["status"], "train_time_s": d.get("train_time_s"),
                     "train_samples_per_s": d.get("train_samples_per_s"), "wall_time_s": d.get("wall_time_s"),
                     **{k: v for k, v in (d.get("metrics") or {}).items()},
                     **{f"counter_{k}": v for k, v in (d.get("counters") or {}).items()}})
    return pd.DataFrame(rows)


def _stats(x):
    x = np.asarray([v for v in x if v is not None and not (isinstance(v, float) and math.isnan(v))], float)
    if x.size == 0:
        return None
    return {"mean": float(x.mean()), "std": float(x.std(ddof=1)) if x.size > 1 else 0.0, "n": int(x.size)}


def _inputs(claim, s: pd.DataFrame) -> tuple[dict, dict]:
    """({label: stats of the claim metric}, {label: what claim.verdict takes}) from the units in s."""
    vals, inputs = {}, {}
    for label, g in s.groupby("model"):
        st = _stats(g[claim.metric]) if claim.metric in g else None
        if st:
            vals[label] = st
        # a model whose units all ran but left no finite value (every rollout diverged) is the worst
        if claim.verdict_metrics:
            ms = [_stats(g[m]) if m in g else None for m in claim.verdict_metrics]
            inputs[label] = tuple(m["mean"] if m else math.inf for m in ms)
        else:
            inputs[label] = st["mean"] if st else math.inf
    return vals, inputs


def claim_verdict(claim, df: pd.DataFrame) -> dict:
    """The claim's rule applied to the seed means, then to every seed alone: a mean that reproduces
    while some seed does not is only "partly" (the seed spread decides, not one lucky seed)."""
    sub = df[df["claim"] == claim.id] if len(df) else df
    entry = {"id": claim.id, "verdict": "not run", "by_framework": {}, "reason": "no finished units", "values": {},
             "by_seed": {}}
    reasons = []
    for fw in sorted(set(sub["framework"])) if len(sub) else []:
        s = sub[sub["framework"] == fw]
        vals, inputs = _inputs(claim, s)
        verdict, reason = claim.verdict(inputs)
        seeds = sorted(set(s["seed"]))
        per_seed = [claim.verdict(_inputs(claim, s[s["seed"] == k])[1])[0] for k in seeds]
        entry["by_seed"][fw] = dict(zip((f"seed{k}" for k in seeds), per_seed, strict=True))
        if len(seeds) > 1:
            agree = sum(v == verdict for v in per_seed)
            reason += f" [seeds: {agree}/{len(seeds)} give '{verdict}' alone]"
            if verdict == "reproduced" and agree < len(seeds):
                verdict = "partly"
                reason += "; only partly: not every seed reproduces"
        entry["by_framework"][fw] = verdict
        entry["values"][fw] = vals
        reasons.append(f"{fw}: {reason}")
    run = {v for v in entry["by_framework"].values()}
    if run:
        entry["verdict"] = run.pop() if len(run) == 1 else "partly"
        entry["reason"] = " | ".join(reasons)
    return entry


def write_summary(out, profile: str) -> dict:
    df = collect_units(out)
    R.write_csv(Path(out) / "summary" / "units.csv", df)
    verdicts = {"schema": R.SCHEMA, "profile": profile, "claims": [claim_verdict(c, df) for c in CLAIMS.values()]}
    return R.write_json(Path(out) / "summary" / "verdicts.json", verdicts)
