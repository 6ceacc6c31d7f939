"""The scorecard that opens the report, and the per-claim competence and parts tables.

``scorecard_section(res)``: the headline count of paper claims (checks apart); one row per paper claim,
then one per check: the verdict (recomputed from the unit files), the key model's reproduced number per
framework beside its published number, marked "like for like" only when the published value is of the
same kind and measured under the same conditions (else "context", with its note), the reason, and each
part's verdict with the interval it read; then the variants (departures from the paper, each with its own
verdict, never a claim's) and the parts whose frameworks disagree (a defect to investigate).
``competence_table(res, claim)``: each model's competence bar per framework; ``parts_table(res, claim)``:
each part per framework with its interval and its verdict at half and twice the suite's threshold.
"""

from __future__ import annotations

import pandas as pd

from lagbench.reports import sections_registration
from lagbench.reports.document import NOT_RUN, Para, Section, Table
from lagbench.reports.fmt import cell, num, stat, summarise
from lagbench.reports.load import Results
from lagbench.reports.tables import published_cell, published_entry, verdict_text

REASON_CHARS = 120
FRAMEWORK_NAMES = {"jax": "JAX", "torch": "PyTorch"}


def _metric_of(u, name: str):
    if name == "final_train_loss":
        v = u.result.get("final_train_loss")
        return float(v) if isinstance(v, int | float) and not isinstance(v, bool) else None
    return u.metric(name)


def _reproduced(res: Results, claim: dict, model: str, metric: str, fw: str) -> str:
    us = [u for u in res.usable(claim["id"]) if u.model == model and u.framework == fw]
    vals = [_metric_of(u, metric) for u in us]
    s = summarise(vals)
    n_inf = sum(v is not None and v == float("inf") for v in vals)
    text = "inf" if n_inf == len(vals) and vals else (stat(**s) if s["n"] else NOT_RUN)
    if n_inf and n_inf < len(vals):
        text = f"inf ({n_inf} of {len(vals)} seeds diverged; finite: {stat(**s)})"
    return text


def _short(text: str) -> str:
    return text if len(text) <= REASON_CHARS else text[: REASON_CHARS - 1] + "…"


def _reason(v: dict | None) -> str:
    """The claim's own reason, in its first sentence (the parts' reasons in full: `reasons_table`)."""
    if not v:
        return "no verdict"
    return _short(str(v.get("reason") or "").split(". ", 1)[0])


def reasons_table(res: Results) -> pd.DataFrame | None:
    """Every part not reproduced, per framework, with its reason in full (the scorecard's reasons are short)."""
    rows = []
    for claim in res.claims:
        for p in (res.verdicts.get(claim["id"]) or {}).get("parts") or []:
            if p.get("verdict") == "reproduced":
                continue
            for fw, why in (p.get("reason") or {}).items():
                rows.append({"#": cell(claim.get("number"), "–"), "claim": claim["id"], "part": cell(p.get("name")),
                             "framework": fw, "verdict": cell(p.get("verdict")), "reason": cell(why)})
    return pd.DataFrame(rows) if rows else None


def all_parts_table(res: Results, kind: str = "claim") -> pd.DataFrame | None:
    """Every part of every claim of `kind`: its verdict and the interval it read per framework."""
    rows = []
    for claim in res.claims:
        if _kind(res, claim) != kind:
            continue
        for p in (res.verdicts.get(claim["id"]) or {}).get("parts") or []:
            ivs = p.get("interval") or {}
            row = {"#": cell(claim.get("number"), "–"), "claim": claim["id"],
                   "part": cell(p.get("name")) + (" [check]" if p.get("check") else ""),
                   "verdict": cell(p.get("verdict")) + (f" ({p['flag']})" if p.get("flag") else ""),
                   "interval of": cell(next(iter(ivs.values())).get("what") if ivs else None, "–")}
            for fw in res.frameworks:
                iv = ivs.get(fw)
                row[FRAMEWORK_NAMES.get(fw, fw)] = (f"{num(iv.get('point'))} [{num(iv.get('lo'))}, {num(iv.get('hi'))}]"
                                                    if iv else "–")
            rows.append(row)
    return pd.DataFrame(rows) if rows else None


def interval_text(p: dict) -> str:
    """A part's interval per framework: 'jax 0.21 [0.18, 0.25]; torch ...' ("" when it read none)."""
    ivs = p.get("interval") or {}
    return "; ".join(f"{fw} {num(iv.get('point'))} [{num(iv.get('lo'))}, {num(iv.get('hi'))}]"
                     for fw, iv in ivs.items())


def part_text(p: dict) -> str:
    text = f"{p.get('name')}: {p.get('verdict')}"
    if p.get("flag"):
        text += f" ({p['flag']})"
    ivs = p.get("interval") or {}
    if ivs:
        what = next(iter(ivs.values())).get("what", "")
        text += f" ({what}: {interval_text(p)})"
    return text


def _kind(res: Results, claim: dict) -> str:
    return str((res.verdicts.get(claim["id"]) or {}).get("kind") or claim.get("kind") or "claim")


def scorecard_table(res: Results, kind: str = "claim") -> pd.DataFrame:
    """One row per claim of `kind`: what it says and where, its verdict, its key model's number per framework
    beside the published one, and the reason in short."""
    rows = []
    for claim in res.claims:
        if _kind(res, claim) != kind:
            continue
        cid = claim["id"]
        key = claim.get("key") or next(iter(claim.get("models") or []), "")
        p = published_entry(claim, key)
        metric = (p or {}).get("metric") or claim.get("metric") or ""
        row = {"#": cell(claim.get("number"), "–"), "claim": cid, "says": cell(claim.get("title"), "untitled"),
               "paper": f"{cell(claim.get('paper'), '?')} {cell(claim.get('section'), '')}".strip(),
               "verdict": verdict_text(res, claim), "key number": f"{key} {metric}" if key else NOT_RUN}
        for fw in res.frameworks:
            row[FRAMEWORK_NAMES.get(fw, fw)] = _reproduced(res, claim, key, metric, fw) if key else NOT_RUN
        row["published"] = published_cell(claim, key, [u for u in res.usable(cid) if u.model == key])
        row["why"] = _reason(res.verdicts.get(cid))
        rows.append(row)
    return pd.DataFrame(rows) if rows else pd.DataFrame({"claim": [NOT_RUN], "verdict": [NOT_RUN]})


def variants_table(res: Results) -> pd.DataFrame | None:
    rows = []
    for claim in res.claims:
        for var in (res.verdicts.get(claim["id"]) or {}).get("variants") or []:
            rows.append({"claim": claim["id"], "variant": cell(var.get("name")),
                         "departure": cell(var.get("departure")), "verdict": cell(var.get("verdict")),
                         "parts": "; ".join(part_text(x) for x in var.get("parts") or [] if not x.get("check"))
                         or cell(var.get("reason"))})
    return pd.DataFrame(rows) if rows else None


FRAMEWORK_NAMES = {"jax": "JAX", "torch": "PyTorch"}


def made_by(res: Results) -> str:
    """Which run this is: profile, split, frameworks, commit, hardware and date, from run.json."""
    run = res.run or {}
    hw = run.get("hardware") or {}
    where = f"{hw.get('cpu', 'unknown CPU')}, {hw.get('cores', '?')} cores" + (f", GPU {hw['gpu']}" if hw.get("gpu") else "")
    names = [FRAMEWORK_NAMES.get(f, f) for f in res.frameworks]
    fws = f"{names[0]} alone" if len(names) == 1 else " and ".join(names) if names else "no framework"
    return (f"Profile {run.get('profile') or res.verdict_profile or 'unknown'}, {res.split} split, {fws}; commit "
            f"{run.get('commit') or 'unknown'}; {where}; started {run.get('started') or 'unknown'}"
            + (f", finished {run['finished']}." if run.get("finished") else ", not finished."))


def headline(res: Results) -> str:
    out = []
    for kind, name in (("claim", "Paper claims"), ("check", "Checks (implementation and numerics)")):
        counts = {}
        for claim in res.claims:
            if _kind(res, claim) == kind:
                x = str((res.verdicts.get(claim["id"]) or {}).get("verdict") or NOT_RUN)
                counts[x] = counts.get(x, 0) + 1
        if counts:
            out.append(f"{name}: " + ", ".join(f"{n} {x}" for x, n in sorted(counts.items(), key=lambda t: -t[1])))
    return ". ".join(out) + "." if out else "Nothing was judged."


SPLIT_TEXT = {
    "test": "Decided on the test split: training seeds from 1000 on, and a held-out draw, rollout initial "
            "conditions and sampled states from generator seeds that no trial, study or protocol choice has "
            "read (replication/run/splits.py). The protocols were frozen before this run and chosen on the "
            "development split (seeds from 0, the development draws): by `lagbench tune` where the registered "
            "protocols table says so, else by hand (docs/decisions/, docs/lab/).",
    "dev": "Development split (seeds from 0, the development draws): the data the protocols were tuned on. "
           "These numbers are for development; verdicts of record come from the test split (`lagbench run`, "
           "its default).",
}


def scorecard_section(res: Results) -> Section:
    s = Section("Scorecard")
    s.add(Para(headline(res)))
    s.add(Para(made_by(res)))
    s.add(Para(SPLIT_TEXT.get(res.split, f"Split: {res.split}.")))
    s.add(Para("One line per paper claim, then one per check (checks test the implementation and the numerics "
               "and are not counted among the claims). The verdict is recomputed from the unit files by the "
               "runner's own rule (replication/claims/verdicts.py): each claim is decided on the models as the "
               "paper specified them, part by part; a part whose models are below their competence bar on any "
               "seed (held-out error at most a set fraction of a null predictor's, rollouts that do not diverge), "
               "or whose positive control did not learn, is 'inconclusive'; an ordering holds only if it holds "
               "over the 90 % confidence interval of the ratio over seeds (the interval shown: Welch's t on log "
               "ratios, wider with fewer seeds; the range over seed pairs beside it describes). 'partly' means only: the named parts reproduced, the others "
               "did not. Frameworks that disagree on a part make it 'inconclusive' and are listed below as a "
               "defect. A published number is 'like for like' only when it is the same kind of number "
               "(training loss, held-out error, energy error) measured under the same conditions; otherwise it "
               "is context, not a target."))
    if res.unfinished or res.planned_missing:
        s.add(Para(f"This run is unfinished: {len(res.planned_missing)} planned unit(s) have no result "
                   "(see Run status); the verdicts below rest on the units present."))
    s.add(Table("Scorecard", scorecard_table(res, "claim"), ["claims.json", "units/*/*/*/seed*/result.json"]))
    checks = scorecard_table(res, "check")
    if "#" in checks.columns:
        s.add(Table("Checks", checks, ["claims.json", "units/*/*/*/seed*/result.json"]))
    variants = variants_table(res)
    if variants is not None:
        s.add(Table("Variants", variants, ["claims.json", "units/*/*/*/seed*/result.json"],
                    note="A variant is a model with a departure from the paper standing in for the paper's model; "
                         "the claim is judged again with it, on this line only. A variant never decides a claim."))
    s.add(Para(sections_registration.summary(res)))
    flags = [f"{cid}: {f}" for cid, v in res.verdicts.items() for f in (v or {}).get("flags") or []]
    s.add(Para("Defects to investigate (parts on which the two frameworks, started from the same weights and "
               "batches, reach different verdicts): " + "; ".join(flags) + "." if flags else
               "No part has frameworks that disagree."))
    return s


def scorecard_appendix(res: Results) -> Section:
    """The appendix's scorecard tables: every part with its interval, the reasons in full, the registration
    and tuning of each claim's protocol."""
    s = Section("Parts, reasons and registrations")
    for kind, title in (("claim", "Parts of the paper claims"), ("check", "Parts of the checks")):
        parts = all_parts_table(res, kind)
        if parts is not None:
            s.add(Table(title, parts, ["summary/verdicts.json", "units/*/*/*/seed*/result.json"],
                        note="Each part is decided per framework on the interval shown (point [low, high], its "
                             "confidence level and method; a bound reads the range over seeds)."))
    why = reasons_table(res)
    if why is not None:
        s.add(Table("Reasons in full (parts not reproduced)", why, ["summary/verdicts.json"]))
    sections_registration.add_to(s, res)
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


def parts_table(res: Results, claim: dict) -> pd.DataFrame | None:
    """Each part (and check) of the claim and of its variants, per framework: verdict, interval, and the
    verdict at half and twice the suite's own threshold."""
    v = res.verdicts.get(claim["id"]) or {}
    lines = [("claim", p) for p in v.get("parts") or []]
    lines += [(f"variant: {var.get('name')}", p) for var in v.get("variants") or [] for p in var.get("parts") or []]
    rows = []
    for line, p in lines:
        for fw, verdict in (p.get("by_framework") or {}).items():
            iv = (p.get("interval") or {}).get(fw) or {}
            sens = (p.get("sensitivity") or {}).get(fw) or {}
            rows.append({"line": line, "part": cell(p.get("name")) + (" (check)" if p.get("check") else ""),
                         "framework": fw, "verdict": cell(verdict),
                         "interval": (f"{iv.get('what')}: {num(iv.get('point'))} [{num(iv.get('lo'))}, "
                                      f"{num(iv.get('hi'))}] ({iv.get('method')})") if iv else "none",
                         "at half / twice the threshold": "; ".join(f"{k}: {x}" for k, x in sens.items()) or "none"})
    return pd.DataFrame(rows) if rows else None
