"""The scorecard that opens the report, and the per-claim competence and parts tables.

``scorecard_section(res)``: a page that stands alone: the headline count of paper claims (checks apart), how
to read a row, then one row per paper claim and one per check: what it says and where, the verdict
(recomputed from the unit files), why (each part under its reason's category, with its interval, level and
seed counts: ``reports.reasons``), the key model's claim metric per framework with its unit (seed mean and
range, a yes/no metric as k/n seeds), its published number ("like for like" only when of the same kind and
measured under the same conditions, else "context") and the flags (far from published, near a threshold, did
not learn, sizes that differ); then every published number beside ours (``reports.published``), the variants
(departures from the paper, each with its own verdict, never a claim's) and the parts whose frameworks
disagree (a defect to investigate).
``competence_table(res, claim)``: each model's competence bar per framework; ``parts_table(res, claim)``:
each part per framework with its interval and its verdict at half and twice the suite's threshold.
"""

from __future__ import annotations

import re

import pandas as pd

from lagbench.reports import glossary, sections_registration
from lagbench.reports.confounds import sizes_differ
from lagbench.reports.document import NOT_RUN, Para, Section, Table
from lagbench.reports.fmt import cell, num
from lagbench.reports.load import Results
from lagbench.reports.published import published_short, published_table
from lagbench.reports.reasons import flags, why_text
from lagbench.reports.tables import FRAMEWORK_NAMES, per_framework, published_entry, verdict_text


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


def _unit_words(metric: str) -> str:
    u = glossary.unit(metric)
    return "" if u in ("", "–", "count") else f" ({u})"


def key_number(res: Results, claim: dict, key: str, metric: str) -> str:
    """The key model's claim metric with its unit, per framework: the seed mean with the range over seeds,
    or "k/n seeds" for a yes/no metric; where every seed diverged, "inf on n/n seeds"."""
    if not key or not metric:
        return NOT_RUN
    return f"{key} {metric}{_unit_words(metric)}: " + (per_framework(res, claim, key, metric) or NOT_RUN)


def scorecard_table(res: Results, kind: str = "claim") -> pd.DataFrame:
    """One row per claim of `kind`: what it says and where, its verdict, why (the reason's category per part,
    with the interval, its level and seed counts), its key model's number per framework, the published one
    and the flags (far from published, near a threshold, did not learn, sizes that differ)."""
    rows = []
    for claim in res.claims:
        if _kind(res, claim) != kind:
            continue
        cid = claim["id"]
        key = claim.get("key") or next(iter(claim.get("models") or []), "")
        metric = claim.get("metric") or (published_entry(claim, key) or {}).get("metric") or ""
        ran = bool(res.usable(cid))
        rows.append({
            "#": cell(claim.get("number"), "–"),
            "claim": f"{cid}: {cell(claim.get('title'), 'untitled')} "
                     f"({cell(claim.get('paper'), '?')} {cell(claim.get('section'), '')})".replace(" )", ")"),
            "verdict": verdict_text(res, claim),
            "why": why_text(res, claim) if ran else NOT_RUN,
            "key number": key_number(res, claim, key, metric) if ran else NOT_RUN,
            "published": published_short(res, claim, key) if key else NOT_RUN,
            "flags": (flags(res, claim, sizes_differ(res, claim)) or "none") if ran else NOT_RUN})
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
    "test": "Decided on the test split: training seeds from 1000 on, and held-out draws, rollout initial conditions "
            "and sampled states that no trial, study or protocol choice has read (replication/run/splits.py); the "
            "protocols were frozen before this run, chosen on the development split (`lagbench tune` where the "
            "registered protocols table says so, else by hand: docs/decisions/, docs/lab/).",
    "dev": "Development split (seeds from 0, the development draws): the data the protocols were tuned on. "
           "These numbers are for development; verdicts of record come from the test split (`lagbench run`, "
           "its default).",
}

READING = ("How to read a row. Verdict: the runner's own rule (replication/claims/verdicts.py) recomputed from the "
           "unit files, part by part; checks (the second table) are not counted among the claims. Why: each part "
           "under its reason's category: BELOW BAR (a model passed its competence bar, an error at most a set "
           "fraction, usually 0.1, of the null predictor's that learned nothing, on k/n seeds; 'did not learn': "
           "its error sat at the null's), FAILED SEEDS, NOT RUN, STRADDLES THRESHOLD (the 90 % confidence "
           "interval over the seeds of the ratio the rule reads holds the rule's threshold: the seeds cannot "
           "tell), NEAR THRESHOLD (decided, the interval within 25 % of it), UNDECIDED (another reason of the "
           "rule's) or decided, each with its interval, level and seed counts. Key number: the key model's claim "
           "metric with its unit, seed mean (lowest to highest seed, n seeds), a yes/no metric as k/n seeds. "
           "Published: 'like for like' only for the same kind of number under the same conditions, else context "
           "(in full, with ours beside it: the appendix's published numbers). Flags: far from published (over 2x or "
           "under half), near the threshold, did not learn, sizes differ (parameters). Every term and metric "
           "name: the Glossary, next page.")


def scorecard_section(res: Results) -> Section:
    s = Section("Scorecard")
    s.add(Para(headline(res)))
    s.add(Para(made_by(res) + " " + SPLIT_TEXT.get(res.split, f"Split: {res.split}.")))
    s.add(Para(READING))
    if res.unfinished or res.planned_missing:
        s.add(Para(f"This run is unfinished: {len(res.planned_missing)} planned unit(s) have no result "
                   "(see Run status); the verdicts below rest on the units present."))
    s.add(Table("Scorecard", scorecard_table(res, "claim"), ["claims.json", "units/*/*/*/seed*/result.json"]))
    checks = scorecard_table(res, "check")
    if "#" in checks.columns:
        s.add(Table("Checks", checks, ["claims.json", "units/*/*/*/seed*/result.json"]))
    s.add(Para(sections_registration.summary(res)))
    flagged = [f"{cid}: {f}" for cid, v in res.verdicts.items() for f in (v or {}).get("flags") or []]
    s.add(Para("Defects to investigate (parts on which the two frameworks, started from the same weights and "
               "batches, reach different verdicts): " + "; ".join(flagged) + "." if flagged else
               "No part has frameworks that disagree."))
    return s


def scorecard_appendix(res: Results) -> Section:
    """The appendix's scorecard tables: the published numbers beside ours, every part with its interval, the
    variants (each claim's page names its own), the reasons in full, the registration and tuning of each claim's protocol."""
    s = Section("Parts, reasons and registrations")
    published = published_table(res)
    if published is not None:
        s.add(Table("Published numbers beside ours", published, ["claims.json", "units/*/*/*/seed*/result.json"],
                    note="Each model's published value with where it is printed, our seed mean of the same metric "
                         "(range over seeds) and the ratio of the two; far from published: over 2x or under half."))
    for kind, title in (("claim", "Parts of the paper claims"), ("check", "Parts of the checks")):
        parts = all_parts_table(res, kind)
        if parts is not None:
            s.add(Table(title, parts, ["summary/verdicts.json", "units/*/*/*/seed*/result.json"],
                        note="Each part is decided per framework on the interval shown (point [low, high], its "
                             "confidence level and method; a bound reads the range over seeds)."))
    variants = variants_table(res)
    if variants is not None:
        s.add(Table("Variants", variants, ["claims.json", "units/*/*/*/seed*/result.json"],
                    note="A variant is a model with a departure from the paper standing in for the paper's model; "
                         "the claim is judged again with it, on this line only. A variant never decides a claim."))
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


def round_numbers(text: str) -> str:
    """`text` with every decimal number to `num`'s 3 significant digits ("within 1.22474" -> "within 1.22")."""
    return re.sub(r"(?<![\w.])\d+\.\d+(?![\w.])", lambda m: num(float(m[0])), str(text))


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
                         "at half / twice the threshold": "; ".join(f"{round_numbers(k)}: {x}" for k, x in sens.items())
                                                 or "none"})
    return pd.DataFrame(rows) if rows else None
