"""Why each verdict stands, in a few categories a reader can check at a glance (the scorecard's "why").

Derived from a claim's verdict record (``replication.claims.verdicts.judge``: each part's verdict, reason and
interval per framework with its level, seed counts, thresholds and distance; each model's competence seed by
seed) and from the unit files; no verdict is changed here. A part's reason falls in one category:

- ``BELOW_BAR``: a model the part reads (or a positive control) passed its competence bar on k of n seeds;
  "did not learn" where its error sat at the null predictor's (at least ``AT_NULL`` of it on every seed);
- ``FAILED``: a unit failed (a failed seed is a failing seed); ``NOT_RUN``: a model did not run;
- ``STRADDLES``: the seeds' confidence interval straddles the rule's threshold (noise decides);
- ``NEAR_T``: decided, the interval's nearer end within ``NEAR`` (a factor) of the threshold;
- ``DECIDED``: decided with the interval clear of the threshold (or every seed inside a bound);
- ``OTHER``: undecided for a reason of the rule's own (e.g. accuracies that do not match).

``claim_why(res, claim)``: the parts' categories in words, parts with the same words grouped; ``why_text`` the
same as the scorecard's line, each group under its category's label (``LABELS``).
``did_not_learn(res, claim)``: {model: words} for models below their bar whose error sat at the null
predictor's on every seed or whose training loss stayed flat. ``published_far(res, claim)``: a model's seed mean more than ``FAR`` times
from (or under 1 / ``FAR`` of) its published value. ``flags(res, claim)``: those, the parts near a threshold,
and models of different sizes (``reports.confounds``), as short phrases.
"""
from __future__ import annotations

import math

import numpy as np

from lagbench.reports.fmt import num, seeds_words
from lagbench.reports.load import Results

BELOW_BAR, FAILED, NOT_RUN, STRADDLES, NEAR_T, DECIDED, OTHER = (
    "below its bar", "failed seeds", "not run", "interval straddles the threshold", "near the threshold",
    "decided", "undecided")
NEAR = 1.25      # a decided part whose interval ends within 25 % of its threshold is "near the threshold"
FAR = 2.0        # a seed mean more than 2x (or under half) its published value is flagged
AT_NULL = 0.5    # an error at least half the null predictor's on every seed: the model did not learn
FLAT = 0.9       # a last logged training loss at least 0.9 x the first on every seed: a flat training loss


def _bars(claim_id: str) -> tuple:
    from lagbench.replication.claims import CLAIMS

    c = CLAIMS.get(claim_id)
    return tuple(c.bars) if c is not None else ()


def _at_null(res: Results, cid: str, model: str) -> str:
    """"heldout_l1 0.409, null 0.402" (means over every unit of the model) when the model's error sat at the
    null predictor's on every seed of every framework, else ""."""
    for bar in _bars(cid):
        if not bar.metric or model not in bar.models:
            continue
        pairs = [(u.metric(bar.metric), u.metric(bar.null_metric)) for u in res.usable(cid) if u.model == model]
        pairs = [(a, b) for a, b in pairs if a is not None and b is not None and b > 0]
        if pairs and all(a >= AT_NULL * b for a, b in pairs):
            a, b = np.mean([p[0] for p in pairs]), np.mean([p[1] for p in pairs])
            return f"{bar.metric} {num(a)}, null {num(b)}"
    return ""


def _flat(res: Results, cid: str, model: str) -> str:
    """"training loss flat (last / first 0.98)" when it stayed flat on every seed, else ""."""
    ratios = []
    for u in res.usable(cid):
        if u.model != model:
            continue
        log = u.table("train_log.csv")
        if log is None or "loss" not in log.columns:
            return ""
        loss = np.asarray(log["loss"], float)
        loss = loss[np.isfinite(loss)]
        if loss.size < 3 or loss[0] <= 0:
            return ""
        ratios.append(float(loss[-1] / loss[0]))
    if ratios and all(r >= FLAT for r in ratios):
        return f"training loss flat (last / first {num(float(np.median(ratios)), 2)})"
    return ""


def compared(res: Results, claim: dict) -> list[str]:
    """The models the claim's counted parts read or control, in their order."""
    parts = (res.verdicts.get(claim["id"]) or {}).get("parts") or []
    return list(dict.fromkeys(m for p in parts if not p.get("check")
                              for m in (*(p.get("reads") or ()), *(p.get("controls") or ()))))


def did_not_learn(res: Results, claim: dict) -> dict[str, str]:
    """{model: why it did not learn} for the models the claim's parts read or control (all its models where
    it has no parts), not past their competence bar, whose error sat at the null predictor's on every seed,
    or whose training loss stayed flat on every seed."""
    cid = claim["id"]
    out = {}
    have = dict.fromkeys(u.model for u in res.usable(cid))
    comp = (res.verdicts.get(cid) or {}).get("competence") or {}
    for model in [m for m in compared(res, claim) if m in have] or list(have):
        bars = [per[model] for per in comp.values() if model in (per or {})]
        if bars and all(b.get("passed") for b in bars):   # a model past its bar learned, whatever its curve
            continue
        why = _at_null(res, cid, model) or _flat(res, cid, model)
        if why:
            out[model] = why
    return out


def _below(v: dict, part: dict, fw: str, dead: dict) -> str:
    """Words for the models of ``part`` below their bar in ``fw`` ("" when none is)."""
    comp = (v.get("competence") or {}).get(fw) or {}
    out = []
    for m in (*part.get("reads", ()), *part.get("controls", ())):
        r = comp.get(m)
        if not r or r.get("passed"):
            continue
        seeds = r.get("per_seed") or []
        k = sum(bool(s.get("passed")) for s in seeds)
        role = "control " if m in part.get("controls", ()) else ""
        text = f"{role}{m} passed on {k}/{len(seeds)} seeds"
        if m in dead:
            text += " (did not learn)"
        out.append(text)
    return "; ".join(out)


def interval_words(iv: dict) -> str:
    """"lnn/baseline 0.95, 90 % confidence interval 0.80 to 1.13 over 2 seeds each" (a range where the record
    holds no confidence level)."""
    level = iv.get("level")
    seeds = iv.get("seeds") or []
    span = f"{num(iv.get('lo'))} to {num(iv.get('hi'))}"
    what = f"{iv.get('what')} {num(iv.get('point'))}"
    if level is None:
        return f"{what}, range {span} over {seeds_words(seeds)}"
    if not (0 < float(iv.get("lo", 0)) or math.isfinite(float(iv.get("hi", math.inf)))):
        return f"{what}, no interval ({iv.get('method')}) over {seeds_words(seeds)}"
    return f"{what}, {num(100 * float(level))} % confidence interval {span} over {seeds_words(seeds)}"


def _threshold_words(iv: dict) -> str:
    ts = iv.get("thresholds") or []
    return "threshold " + " and ".join(num(t) for t in ts) if ts else ""


def part_why(v: dict, part: dict, fw: str, dead: dict) -> tuple[str, str]:
    """(category, words) of one part in one framework."""
    verdict = (part.get("by_framework") or {}).get(fw, part.get("verdict"))
    reason = str((part.get("reason") or {}).get(fw) or "")
    if reason.startswith("a failed seed"):
        return FAILED, reason.split(": ", 1)[-1]
    if verdict == "not run":
        return NOT_RUN, reason or "no unit"
    below = _below(v, part, fw, dead)
    if below:
        return BELOW_BAR, below
    iv = (part.get("interval") or {}).get(fw)
    if iv:
        lo, hi = float(iv.get("lo", 0)), float(iv.get("hi", math.inf))
        ts = [float(t) for t in iv.get("thresholds") or []]
        words = f"{interval_words(iv)}; {_threshold_words(iv)}".rstrip("; ")
        if verdict in ("reproduced", "not reproduced"):
            d = iv.get("distance")
            if d is not None and math.isfinite(d) and d < NEAR:
                return NEAR_T, f"{words} ({100 * (d - 1):.2g} % from it)"
            return DECIDED, words
        if any(lo < t < hi for t in ts):
            return STRADDLES, words
        return OTHER, f"{words}; {reason.split('; ')[-1]}"
    if verdict in ("reproduced", "not reproduced"):
        return DECIDED, reason.split("; ")[-1][:160]
    return OTHER, reason[:160]


def claim_why(res: Results, claim: dict) -> list[tuple[str, str, list[str]]]:
    """[(category, words, [part names])] over the claim's counted parts, parts with the same category and
    words in every framework grouped; a part whose frameworks differ names each framework."""
    v = res.verdicts.get(claim["id"]) or {}
    dead = did_not_learn(res, claim)
    groups: dict[tuple[str, str], list[str]] = {}
    for p in v.get("parts") or []:
        if p.get("check"):
            continue
        per = {fw: part_why(v, p, fw, dead) for fw in (p.get("by_framework") or {})}
        if not per:
            groups.setdefault((NOT_RUN, "no unit"), []).append(p["name"])
            continue
        if len(set(per.values())) == 1:
            groups.setdefault(next(iter(per.values())), []).append(p["name"])
        else:
            cat = next(iter(per.values()))[0]
            words = "; ".join(f"{fw}: {c}, {w}" for fw, (c, w) in per.items())
            groups.setdefault((cat, words), []).append(p["name"])
    return [(cat, words, names) for (cat, words), names in groups.items()]


LABELS = {BELOW_BAR: "BELOW BAR", FAILED: "FAILED SEEDS", NOT_RUN: "NOT RUN", STRADDLES: "STRADDLES THRESHOLD",
          NEAR_T: "NEAR THRESHOLD", DECIDED: "decided", OTHER: "UNDECIDED"}


def why_text(res: Results, claim: dict) -> str:
    """The scorecard's "why": per group of parts, its category's label, the parts and the words."""
    v = res.verdicts.get(claim["id"])
    if not v:
        return "no verdict"
    rows = claim_why(res, claim)
    if not rows:
        return str(v.get("reason") or "no part ran")
    return " ".join(f"{LABELS[cat]} ({', '.join(names)}): {words}." for cat, words, names in rows)


def published_far(res: Results, claim: dict) -> list[str]:
    """"lnn 2.1x its published 0.0689" for each model whose seed mean over every framework is more than
    ``FAR`` times from its published value of the same metric."""
    out = []
    for model, p in (claim.get("published") or {}).items():
        if not isinstance(p, dict) or not isinstance(p.get("value"), int | float) or not p.get("metric"):
            continue
        vals = [u.metric(p["metric"]) for u in res.usable(claim["id"]) if u.model == model]
        vals = [x for x in vals if x is not None and math.isfinite(x)]
        if not vals or p["value"] <= 0:
            continue
        ratio = float(np.mean(vals)) / float(p["value"])
        if ratio >= FAR or ratio <= 1 / FAR:
            out.append(f"{model} {num(ratio, 2)}x its published {num(p['value'])}")
    return out


def near_parts(res: Results, claim: dict) -> list[str]:
    """Decided parts whose interval ends within ``NEAR`` of the threshold, with how near."""
    out = []
    for p in (res.verdicts.get(claim["id"]) or {}).get("parts") or []:
        if p.get("check") or p.get("verdict") not in ("reproduced", "not reproduced"):
            continue
        ds = [iv.get("distance") for iv in (p.get("interval") or {}).values()]
        ds = [d for d in ds if d is not None and math.isfinite(d)]
        if ds and min(ds) < NEAR:
            out.append(f"{p['name']}: {100 * (min(ds) - 1):.2g} % from its threshold")
    return out


def flags(res: Results, claim: dict, sizes: str = "") -> str:
    """The claim's flags in a line ("" for none): far from published, near a threshold, did not learn, sizes."""
    far, near, dead = published_far(res, claim), near_parts(res, claim), did_not_learn(res, claim)
    out = [f"far from published: {', '.join(far)}"] * bool(far) + [f"near the threshold: {', '.join(near)}"] * bool(near)
    out += [f"did not learn: {', '.join(f'{m} ({w})' for m, w in dead.items())}"] * bool(dead)
    out += [f"sizes differ: {sizes}"] * bool(sizes)
    return "; ".join(out)
