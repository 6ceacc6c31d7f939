"""Where a verdict is decided: ``judge(claim, units, profile)``, shared by the runner and the report.

``units`` is the table of summary/units.csv (``frame(records)`` builds it from result.json records):
one row per unit with claim, framework, model, seed, status, its metrics and ``final_train_loss``.
Each part of the claim (``claims.parts``) is decided per framework, on the units whose status is "ok":

1. a model the part reads (or controls) whose every unit failed makes the part "inconclusive" (failed
   units never count; the reason names them); a model with no unit at all, "not run";
2. the competence bars (``claims.bars``): a model the part reads below its bar -> "inconclusive", with
   the numbers; a positive control below its bar -> "inconclusive" (a failure says nothing then);
3. the part's rule (``claims.rules``) on the seed statistics, which reads an interval over seeds.

A part's frameworks combine by ``parts.combine_frameworks`` (decided verdicts that differ:
"inconclusive", flagged "frameworks disagree"); the claim's verdict is ``parts.claim_verdict`` of its
counted parts (sanity checks apart). Each variant (``parts.Variant``) is judged the same way with its
units in the paper model's place, on its own line.
"""
from __future__ import annotations

import math
from pathlib import Path

import pandas as pd

from replication import results as R
from replication.claims import CLAIMS, registration, tuned
from replication.claims.bars import added_competence, competence
from replication.claims.parts import claim_verdict, combine_frameworks
from replication.claims.rules import Outcome, Stat

KEYS = ("claim", "framework", "model", "seed", "status")


def frame(records) -> pd.DataFrame:
    """summary/units.csv rows from result.json records (dicts)."""
    rows = []
    for d in records:
        rows.append({**{k: d.get(k) for k in KEYS}, "split": d.get("split") or "dev", "profile": d.get("profile"),
                     "train_time_s": d.get("train_time_s"), "train_samples_per_s": d.get("train_samples_per_s"),
                     "wall_time_s": d.get("wall_time_s"), "final_train_loss": d.get("final_train_loss"),
                     "failure": (d.get("failure") or {}).get("kind"),
                     **{k: v for k, v in (d.get("metrics") or {}).items()},
                     **{f"counter_{k}": v for k, v in (d.get("counters") or {}).items()}})
    return pd.DataFrame(rows, columns=None if rows else [*KEYS, "split", "profile"])


def of_split(units: pd.DataFrame, split: str) -> pd.DataFrame:
    """The rows of one split (`replication.run.splits`): a summary never judges two splits' seeds together."""
    if not len(units) or "split" not in units.columns:
        return units
    return units[units["split"].fillna("dev") == split]


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
    skip = set(KEYS) | {"split", "profile", "failure"}
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


def _decide_part(part, v: dict, per: dict, failed: dict) -> Outcome:
    """One part's outcome in one framework: usable models, their bars, the positive controls, the rule."""
    needed = (*part.reads, *part.controls)
    gone = [m for m in needed if m in failed]
    if gone:
        return Outcome("inconclusive", "no usable model: " + "; ".join(f"{m}: every unit failed ({failed[m]})"
                                                                      for m in gone))
    missing = [m for m in needed if m not in v]
    if missing:
        return Outcome("not run", "missing " + ", ".join(missing))
    below = [per[m][1] for m in part.reads if m in per and not per[m][0]]
    if below:
        return Outcome("inconclusive", ("inconclusive: budget; " if part.budget else "")
                       + "below the competence bar: " + "; ".join(below) + (f" ({part.budget})" if part.budget else ""))
    weak = [per[m][1] if m in per else f"{m}: no bar" for m in part.controls if not per.get(m, (False, ""))[0]]
    if weak:
        return Outcome("inconclusive", "the positive control did not learn, so a failure says nothing: "
                       + "; ".join(weak))
    return part.rule(v)


def _framework(claim, s: pd.DataFrame, labels) -> tuple[dict, dict, dict, int]:
    """({part: Outcome}, competence {label: (passed, why)}, stats, failed units) of one framework's rows."""
    ok = s[s["status"] == "ok"]
    bad = s[s["status"] != "ok"]
    failed = {m: ", ".join(sorted({k for k in g.get("failure", ()) if isinstance(k, str)})) or "failed"
              for m, g in bad.groupby("model") if m in labels and m not in set(ok["model"])}
    v = model_stats(ok)
    _, _, per = competence(claim.bars, v)
    per.update(added_competence(claim.bars, v, {m.label for m in claim.models}))
    return {p.name: _decide_part(p, v, per, failed) for p in _active(claim, labels)}, per, v, len(bad)


def _active(claim, labels) -> list:
    """The parts whose models run in the profile."""
    return [p for p in claim.parts if p.runs_in(labels)]


def _parts(claim, per_fw: dict, labels) -> list:
    out = []
    for part in _active(claim, labels):
        res = {fw: o[part.name] for fw, o in per_fw.items()}
        verdict, flag = combine_frameworks({fw: o.verdict for fw, o in res.items()})
        out.append({**part.describe(), "verdict": verdict, "flag": flag,
                    "by_framework": {fw: o.verdict for fw, o in res.items()},
                    "reason": {fw: o.reason for fw, o in res.items()},
                    "interval": {fw: o.interval.to_dict() for fw, o in res.items() if o.interval is not None},
                    "sensitivity": {fw: dict(o.sensitivity) for fw, o in res.items() if o.sensitivity}})
    return out


def _counted(parts) -> dict:
    return {p["name"]: p["verdict"] for p in parts if not p["check"]}


def _judge_parts(claim, sub: pd.DataFrame, labels) -> tuple[dict, list, dict]:
    """(per-framework detail, the parts combined over frameworks, per-framework claim verdicts)."""
    detail, per_fw = {}, {}
    for fw in sorted(set(sub["framework"])) if len(sub) else []:
        outcomes, per, v, n_bad = _framework(claim, sub[sub["framework"] == fw], labels)
        per_fw[fw] = outcomes
        detail[fw] = (per, v, n_bad)
    parts = _parts(claim, per_fw, labels)
    by_fw = {fw: claim_verdict({p.name: o[p.name].verdict for p in _active(claim, labels) if not p.check})[0]
             for fw, o in per_fw.items()}
    return detail, parts, by_fw


def _variant(claim, var, sub: pd.DataFrame, labels) -> dict:
    """The claim judged with each variant model's units in its paper model's place."""
    line = {**var.describe(), "verdict": "not run", "reason": "the variant's models did not run", "parts": [],
            "by_framework": {}}
    if not len(sub) or not all(v in set(sub["model"]) for _, v in var.replaces):
        return line
    swap = dict((v, p) for p, v in var.replaces)
    rows = sub[~sub["model"].isin([p for p, _ in var.replaces])].copy()
    rows["model"] = rows["model"].map(lambda m: swap.get(m, m))
    _, parts, by_fw = _judge_parts(claim, rows, labels)
    verdict, why = claim_verdict(_counted(parts))
    return {**line, "verdict": verdict, "reason": why, "parts": parts, "by_framework": by_fw}


def judge(claim, units: pd.DataFrame, profile: str | None = None) -> dict:
    """The claim's verdict from ``units`` (rows of any claims; see the module docstring)."""
    sub = units[units["claim"] == claim.id] if len(units) else units
    entry = {"id": claim.id, "kind": claim.kind, "verdict": "not run", "reason": "no finished units",
             "by_framework": {}, "parts": [], "variants": [], "flags": [], "values": {}, "competence": {},
             "failed_units": {}}
    if profile is not None:
        tuning = tuned.tuning(claim, profile)
        entry["preregistration"] = {**registration.status(claim, profile), "tuning": tuning,
                                    "equal_tuning": tuned.equal(tuning)}
    if not len(sub):
        return entry
    entry["seeds"] = sorted({int(s) for s in sub["seed"]})
    # a profile's models; without one, the models that ran (a report of an unnamed profile)
    labels = claim.labels(profile) if profile is not None else [m for m in claim.labels() if m in set(sub["model"])]
    detail, parts, by_fw = _judge_parts(claim, sub, labels)
    for fw, (per, v, n_bad) in detail.items():
        if n_bad:
            entry["failed_units"][fw] = n_bad
        entry["competence"][fw] = {m: {"passed": p, "why": w} for m, (p, w) in per.items()}
        entry["values"][fw] = {m: {"mean": st[claim.metric].mean, "std": st[claim.metric].std,
                                   "n": st[claim.metric].n} for m, st in v.items() if claim.metric in st}
    verdict, why = claim_verdict(_counted(parts))
    lines = [f"{p['name']}{' (check)' if p['check'] else ''}: {p['verdict']}"
             + (f" ({p['flag']})" if p["flag"] else "") + " [" + " | ".join(f"{fw}: {r}" for fw, r in p["reason"].items())
             + "]" for p in parts]
    n_bad = sum(entry["failed_units"].values())
    entry.update(verdict=verdict, by_framework=by_fw, parts=parts,
                 reason=f"{why}. " + "; ".join(lines)
                 + (f" ({n_bad} failed unit{'s' if n_bad > 1 else ''} excluded)" if n_bad else ""),
                 flags=[f"{p['name']}: {p['flag']}" for p in parts if p["flag"]],
                 variants=[_variant(claim, var, sub, labels) for var in claim.variants])
    return entry


def judge_all(units: pd.DataFrame, profile: str | None) -> list:
    return [judge(c, units, profile) for c in CLAIMS.values()]


def headline(judged: list) -> dict:
    """The count of paper claims (checks apart) per verdict."""
    out = {}
    for kind in ("claim", "check"):
        counts = {}
        for v in judged:
            if v.get("kind", "claim") == kind:
                counts[v["verdict"]] = counts.get(v["verdict"], 0) + 1
        out[kind + "s"] = counts
    return out


def write_summary(out, profile: str, split: str = "dev") -> dict:
    """summary/units.csv and summary/verdicts.json of the units of `split` in `out`."""
    df = of_split(collect_units(out), split)
    R.write_csv(Path(out) / "summary" / "units.csv", df)
    judged = [{**v, "split": split} for v in judge_all(df, profile)]
    verdicts = {"schema": R.SCHEMA, "profile": profile, "split": split, "headline": headline(judged),
                "claims": judged}
    return R.write_json(Path(out) / "summary" / "verdicts.json", verdicts)
