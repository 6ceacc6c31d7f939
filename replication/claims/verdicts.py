"""Where a verdict is decided: ``judge(claim, units, profile, registrations, adopted)``, shared by the runner and
the report: a function of its arguments alone (it reads no file; the caller loads the committed registrations,
``registration.registrations()``, and the adopted tuning, ``tuned.records()``, and passes them in).

``units`` is the table of summary/units.csv (``frame(records)`` builds it from result.json records):
one row per unit with claim, framework, model, seed, status, its metrics and ``final_train_loss``.
Each part of the claim (``claims.parts``) is decided per framework (its rule reads the units whose status is
"ok"; a failed unit is never dropped silently):

1. a model the part reads (or controls) with a failed unit makes the part "inconclusive" (a failed seed is
   a failing seed, never dropped; the reason names it); a model with no unit at all, "not run";
2. the competence bars (``claims.bars``), seed by seed: a model the part reads below its bar (any seed
   below it) -> "inconclusive", with every seed's number, and "inconclusive: budget" where the part says
   what the original needed; a positive control below its bar -> "inconclusive" (a failure says nothing);
3. the part's rule (``claims.rules``) on the seed statistics, which reads a confidence interval over seeds.

Each model's competence is recorded per seed (``competence.<framework>.<model>.per_seed``), and each part's
interval with its ``level``, ``seeds``, the thresholds it was read against and the distance to them.

A part's frameworks combine by ``parts.combine_frameworks`` (decided verdicts that differ:
"inconclusive", flagged "frameworks disagree"); the claim's verdict is ``parts.claim_verdict`` of its
counted parts (sanity checks apart). Each variant (``parts.Variant``) is judged the same way with its
units in the paper model's place, on its own line.

With a profile and ``registrations`` (then ``adopted`` too), the verdict carries its "preregistration": the
protocol's registration status (``registration.status``) and how each model was tuned (``resolved.tuning``).
``write_summary(out, profile, split, registrations, adopted)`` writes summary/units.csv and verdicts.json.
"""
from __future__ import annotations

import math
from pathlib import Path

import pandas as pd

from lagbench.files import results as R
from lagbench.replication.claims import registration, tuned
from lagbench.replication.claims.bars import added_competence, competence
from lagbench.replication.claims.parts import claim_verdict, combine_frameworks
from lagbench.replication.claims.resolved import tuning as tuning_of
from lagbench.replication.claims.rules import Outcome, Stat

KEYS = ("claim", "framework", "model", "seed", "status")


def frame(records) -> pd.DataFrame:
    """summary/units.csv rows from result.json records (dicts)."""
    rows = []
    for d in records:
        rows.append({**{k: d.get(k) for k in KEYS}, "split": d.get("split") or "dev", "profile": d.get("profile"),
                     "train_time_s": d.get("train_time_s"), "train_samples_per_s": d.get("train_samples_per_s"),
                     "train_samples": d.get("train_samples"),
                     "width": "x".join(str(h) for h in ((d.get("model_spec") or {}).get("hidden") or ())),
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
    """{model: {metric: Stat}} over the rows of ``units`` (one framework), numeric columns only; a seed whose
    value is NaN or missing where another seed has one is counted in the Stat's ``dropped``."""
    out = {}
    skip = set(KEYS) | {"split", "profile", "failure", "width"}
    for label, g in units.groupby("model", sort=False):
        stats = {}
        for col in g.columns:
            if col in skip:
                continue
            vals = list(map(_numeric, g[col]))
            if any(v is not None for v in vals):   # a seed without the value is counted (Stat.dropped), never lost
                stats[col] = Stat.of(vals)
        out[str(label)] = stats
    return out


def seed_rows(units: pd.DataFrame) -> dict:
    """{model: [row dict per seed, failed units included]} of one framework's rows, in seed order."""
    return {str(m): [r for _, r in g.sort_values("seed").iterrows()]
            for m, g in units.groupby("model", sort=False)} if len(units) else {}


def _decide_part(part, v: dict, per: dict, failed: dict, rows: dict) -> Outcome:
    """One part's outcome in one framework: usable models, their bars, the positive controls, the rule."""
    needed = (*part.reads, *part.controls)
    gone = [m for m in needed if m in failed]
    if gone:
        return Outcome("inconclusive", "a failed seed is a failing seed: "
                       + "; ".join(f"{m}: {failed[m]}" for m in gone))
    missing = [m for m in needed if m not in v]
    if missing:
        return Outcome("not run", "missing " + ", ".join(missing))
    below = [per[m][1] for m in part.reads if m in per and not per[m][0]]
    weak = [per[m][1] if m in per else f"{m}: no bar" for m in part.controls if not per.get(m, (False, ""))[0]]
    if below and part.budget is not None:
        return _budget(part, rows, per, weak, below)
    if below:
        return Outcome("inconclusive", "below the competence bar: " + "; ".join(below))
    if weak:
        return Outcome("inconclusive", "the positive control did not learn, so a failure says nothing: "
                       + "; ".join(weak))
    return part.rule(v)


def _budget(part, rows: dict, per: dict, weak: list, below: list) -> Outcome:
    """A part that says a paper model learns, with a model below its bar: "not reproduced" only when the
    model failed on every seed with the original's widths, budget and enough seeds, and the controls
    learned in the same pipeline (`parts.Budget`); else "inconclusive: pipeline" or ": budget"."""
    b, m = part.budget, part.budget.model
    text = "below the competence bar: " + "; ".join(below)
    if weak:
        return Outcome("inconclusive", "inconclusive: pipeline (the positive control did not learn: "
                       + "; ".join(weak) + "); " + text)
    seeds = per.get(m, (True, "", []))[2] or []
    if m not in per or any(x["passed"] for x in seeds):
        return Outcome("inconclusive", text)
    samples = min((_numeric(r.get("train_samples")) or 0.0 for r in rows.get(m, [])), default=0.0)
    widths = {str(r.get("width") or "") for r in rows.get(m, [])}
    width = tuple(int(x) for x in widths.pop().split("x") if x) if len(widths) == 1 else ()
    short = b.shortfall(width, samples, len(seeds))
    if short:
        return Outcome("inconclusive", f"inconclusive: budget ({'; '.join(short)}); {text}")
    return Outcome("not reproduced", f"{m} learned on none of {len(seeds)} seeds with the original's widths and at "
                   f"least its {b.samples:.3g} samples, its positive controls learning in the same pipeline; {text}")


def _framework(claim, s: pd.DataFrame, labels) -> tuple[dict, dict, dict, int]:
    """({part: Outcome}, competence {label: (passed, why)}, stats, failed units) of one framework's rows."""
    ok = s[s["status"] == "ok"]
    bad = s[s["status"] != "ok"]
    failed = {m: f"{len(g)} of {len(s[s['model'] == m])} seeds failed ("
              + (", ".join(sorted({k for k in g.get("failure", ()) if isinstance(k, str)})) or "no result") + ")"
              for m, g in bad.groupby("model") if m in labels}
    v = model_stats(ok)
    rows = seed_rows(s)
    _, _, per = competence(claim.bars, rows)
    per.update(added_competence(claim.bars, rows, {m.label for m in claim.models}))
    return {p.name: _decide_part(p, v, per, failed, rows) for p in _active(claim, labels)}, per, v, len(bad)


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
                    "interval": {fw: {**o.interval.to_dict(), "thresholds": list(o.thresholds),
                                      "distance": o.distance}
                                 for fw, o in res.items() if o.interval is not None},
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


def _seed(x):
    try:
        return int(x)
    except (TypeError, ValueError):
        return x


def _preregistration(claim, profile: str, registrations: dict, adopted: dict | None) -> dict:
    if adopted is None:
        raise TypeError("judge: registrations given without adopted (tuned.json's records)")
    tuning = tuning_of(claim, profile, adopted)
    return {**registration.status(claim, profile, registrations, adopted), "tuning": tuning,
            "equal_tuning": tuned.equal(tuning)}


def judge(claim, units: pd.DataFrame, profile: str | None = None, registrations: dict | None = None,
          adopted: dict | None = None) -> dict:
    """The claim's verdict from ``units`` (rows of any claims; see the module docstring). ``registrations``:
    registrations.json's records, ``adopted``: tuned.json's; with a profile they add the preregistration."""
    sub = units[units["claim"] == claim.id] if len(units) else units
    entry = {"id": claim.id, "kind": claim.kind, "verdict": "not run", "reason": "no finished units",
             "by_framework": {}, "parts": [], "variants": [], "flags": [], "values": {}, "competence": {},
             "failed_units": {}}
    if profile is not None and registrations is not None:
        entry["preregistration"] = _preregistration(claim, profile, registrations, adopted)
    if not len(sub):
        return entry
    entry["seeds"] = sorted({int(s) for s in sub["seed"]})
    # a profile's models; without one, the models that ran (a report of an unnamed profile)
    labels = claim.labels(profile) if profile is not None else [m for m in claim.labels() if m in set(sub["model"])]
    detail, parts, by_fw = _judge_parts(claim, sub, labels)
    for fw, (per, v, n_bad) in detail.items():
        if n_bad:
            entry["failed_units"][fw] = n_bad
        entry["competence"][fw] = {m: {"passed": p, "why": w,
                                       "per_seed": [{"seed": _seed(x["seed"]), "passed": bool(x["passed"]),
                                                     "value": x["value"], "why": x["why"]} for x in ps]}
                                   for m, (p, w, ps) in per.items()}
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


def judge_all(units: pd.DataFrame, profile: str | None, registrations: dict | None = None,
              adopted: dict | None = None) -> list:
    from lagbench.replication.claims import CLAIMS

    return [judge(c, units, profile, registrations, adopted) for c in CLAIMS.values()]


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


def write_summary(out, profile: str, split: str = "dev", registrations: dict | None = None,
                  adopted: dict | None = None) -> dict:
    """summary/units.csv and summary/verdicts.json of the units of `split` in `out`."""
    df = of_split(collect_units(out), split)
    R.write_csv(Path(out) / "summary" / "units.csv", df)
    judged = [{**v, "split": split} for v in judge_all(df, profile, registrations, adopted)]
    verdicts = {"schema": R.SCHEMA, "profile": profile, "split": split, "headline": headline(judged),
                "claims": judged}
    return R.write_json(Path(out) / "summary" / "verdicts.json", verdicts)
