"""Where a verdict is decided: ``judge(claim, units, profile)``, shared by the runner and the report.

``units`` is the table of summary/units.csv (``frame(records)`` builds it from result.json records):
one row per unit with claim, framework, model, seed, status, its metrics and ``final_train_loss``.
Per framework, on the units whose status is "ok":

1. a model the claim runs in ``profile`` whose every unit failed makes the verdict "inconclusive"
   (failed units never count; the reason names them); a model with no unit at all, "not run";
2. the competence bars (``claims.bars``): a model below its bar -> "inconclusive", with the numbers;
3. the claim's rule (``claims.rules``) on the seed statistics; then on every seed alone: a mean that
   reproduces while some seed does not is only "partly" (not for a ``pooled`` claim, whose rule reads
   the seeds as one sample: a share with its interval).

The frameworks' verdicts combine into one: equal -> that one; any "inconclusive" -> "inconclusive";
otherwise "partly".
"""
from __future__ import annotations

import math
from pathlib import Path

import pandas as pd

from replication import results as R
from replication.claims import CLAIMS
from replication.claims.bars import competence
from replication.claims.rules import Stat

KEYS = ("claim", "framework", "model", "seed", "status")


def frame(records) -> pd.DataFrame:
    """summary/units.csv rows from result.json records (dicts)."""
    rows = []
    for d in records:
        rows.append({**{k: d.get(k) for k in KEYS}, "profile": d.get("profile"),
                     "train_time_s": d.get("train_time_s"), "train_samples_per_s": d.get("train_samples_per_s"),
                     "wall_time_s": d.get("wall_time_s"), "final_train_loss": d.get("final_train_loss"),
                     "failure": (d.get("failure") or {}).get("kind"),
                     **{k: v for k, v in (d.get("metrics") or {}).items()},
                     **{f"counter_{k}": v for k, v in (d.get("counters") or {}).items()}})
    return pd.DataFrame(rows, columns=None if rows else [*KEYS, "profile"])


def collect_units(out) -> pd.DataFrame:
    records = []
    for f in sorted(Path(out).glob("units/*/*/*/seed*/result.json")):
        try:
            records.append(R.load_result(f.parent))
        except R.CorruptResult:
            continue
    return frame(records)


def _numeric(x):
    try:
        v = float(x)
    except (TypeError, ValueError):
        return None
    return None if math.isnan(v) else v


def model_stats(units: pd.DataFrame) -> dict:
    """{model: {metric: Stat}} over the rows of ``units`` (one framework), numeric columns only."""
    out = {}
    skip = set(KEYS) | {"profile", "failure"}
    for label, g in units.groupby("model", sort=False):
        stats = {}
        for col in g.columns:
            if col in skip:
                continue
            vals = [v for v in map(_numeric, g[col]) if v is not None]
            if vals:
                stats[col] = Stat.of(vals)
        out[str(label)] = stats
    return out


def _decide(claim, v: dict, failed: dict) -> tuple[str, str, dict]:
    """(verdict, reason, {label: (passed, why)}) for one framework's (or one seed's) statistics."""
    if failed:
        why = "; ".join(f"{m}: every unit failed ({k})" for m, k in failed.items())
        return "inconclusive", f"no usable model: {why}", {}
    ok, why, per = competence(claim.bars, v)
    if not ok:
        return "inconclusive", "below the competence bar: " + "; ".join(why), per
    verdict, reason = claim.verdict(v)
    return verdict, reason, per


def _combine(verdicts) -> str:
    run = set(verdicts)
    if len(run) == 1:
        return run.pop()
    return "inconclusive" if "inconclusive" in run else "partly"


def judge(claim, units: pd.DataFrame, profile: str | None = None) -> dict:
    """The claim's verdict from ``units`` (rows of any claims; see the module docstring)."""
    sub = units[units["claim"] == claim.id] if len(units) else units
    entry = {"id": claim.id, "verdict": "not run", "reason": "no finished units", "by_framework": {},
             "values": {}, "by_seed": {}, "competence": {}, "failed_units": {}}
    labels = claim.labels(profile)
    reasons = []
    for fw in sorted(set(sub["framework"])) if len(sub) else []:
        s = sub[sub["framework"] == fw]
        ok = s[s["status"] == "ok"]
        bad = s[s["status"] != "ok"]
        failed = {m: ", ".join(sorted({k for k in g.get("failure", ()) if isinstance(k, str)})) or "failed"
                  for m, g in bad.groupby("model") if m in labels and m not in set(ok["model"])}
        v = model_stats(ok)
        verdict, reason, per = _decide(claim, v, failed)
        seeds = sorted(set(ok["seed"]))
        per_seed = [_decide(claim, model_stats(ok[ok["seed"] == k]), failed)[0] for k in seeds]
        entry["by_seed"][fw] = {f"seed{k}": x for k, x in zip(seeds, per_seed, strict=True)}
        if len(seeds) > 1 and verdict not in ("inconclusive", "not run") and not claim.pooled:
            agree = sum(x == verdict for x in per_seed)
            reason += f" [seeds: {agree}/{len(seeds)} give '{verdict}' alone]"
            if verdict == "reproduced" and agree < len(seeds):
                verdict, reason = "partly", reason + "; only partly: not every seed reproduces"
        if len(bad):
            entry["failed_units"][fw] = len(bad)
            reason += f" ({len(bad)} failed unit{'s' if len(bad) > 1 else ''} excluded)"
        entry["by_framework"][fw] = verdict
        entry["competence"][fw] = {m: {"passed": p, "why": w} for m, (p, w) in per.items()}
        entry["values"][fw] = {m: {"mean": st[claim.metric].mean, "std": st[claim.metric].std,
                                   "n": st[claim.metric].n} for m, st in v.items() if claim.metric in st}
        reasons.append(f"{fw}: {reason}")
    if entry["by_framework"]:
        entry["verdict"] = _combine(entry["by_framework"].values())
        entry["reason"] = " | ".join(reasons)
    return entry


def judge_all(units: pd.DataFrame, profile: str | None) -> list:
    return [judge(c, units, profile) for c in CLAIMS.values()]


def write_summary(out, profile: str) -> dict:
    df = collect_units(out)
    R.write_csv(Path(out) / "summary" / "units.csv", df)
    verdicts = {"schema": R.SCHEMA, "profile": profile, "claims": judge_all(df, profile)}
    return R.write_json(Path(out) / "summary" / "verdicts.json", verdicts)
