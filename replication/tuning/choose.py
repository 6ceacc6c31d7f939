"""How a search chooses: the score of a unit, a configuration's score, and the choice among configurations.

`score_metric(result, claim)`, `score_name(result, claim)`: a unit's score, lower is better: the metric the claim's verdict reads
(`claim.metric`; `heldout_l1` where the evaluation does not give it); a pooled claim (a pace study: claims 6
and 7) by its pace, the samples to leave the plateau (+inf: never). +inf is the worst score; NaN none.
`config_scores(rows, claim) -> {model: {config: score}}`: per model and configuration, the mean over seeds
(a pooled claim: the median over its cohort of seeds, +inf kept); a configuration with a failed or unscored
seed scores None (never chosen over one that scored).
`best(scores) -> config`: the lowest score; a tie goes to the earlier configuration (the registered first).
`joint(scores) -> ({config: mean rank}, config)`: one configuration for every arm of an ablation (claims 6
and 7 compare arms at one architecture): each arm ranks the configurations by its score (ties share a rank,
None last), and the configuration with the lowest mean rank over the arms is chosen, ties to the earlier.
`hand_chosen(claim, profile, labels) -> {setting: {model: value}}`: the protocol and input settings outside
the search that differ between the claim's trained models (chosen by hand per model, not searched).
"""
from __future__ import annotations

import math

import pandas as pd

PACE = "samples_to_leave"   # a pooled claim's score: training samples until the plateau is left (+inf: never)
SEARCHED = ("schedule.lr", "scouting.schedule.lr")   # the knobs' settings: searched, not hand-chosen


def score_name(result: dict, claim) -> str:
    """The name of the metric a unit is scored by."""
    if claim.pooled:   # a pace study decides by pace, so its search is scored by pace
        return PACE
    return claim.metric if claim.metric in (result.get("metrics") or {}) else "heldout_l1"


def score_metric(result: dict, claim) -> float | None:
    """+inf (never left the plateau, never reached the line, diverged) is a score, the worst; NaN is none."""
    v = (result.get("metrics") or {}).get(score_name(result, claim))
    return float(v) if isinstance(v, int | float) and not math.isnan(v) and v > -math.inf else None


def scored_by(claim) -> str:
    return (f"median {PACE} over the seeds (+inf: never left)" if claim.pooled
            else f"mean over seeds of {claim.metric} (the metric the verdict reads; heldout_l1 where absent)")


def config_scores(rows: pd.DataFrame, claim) -> dict[str, dict[int, float | None]]:
    out = {}
    for label, g in rows.groupby("model", sort=False):
        out[label] = {}
        for k, c in g.groupby("config"):
            s = c["score"]
            if s.isna().any():
                out[label][int(k)] = None
            else:
                v = float(s.median() if claim.pooled else s.mean())
                out[label][int(k)] = v
    return out


def best(scores: dict[int, float | None]) -> int | None:
    scored = {k: v for k, v in scores.items() if v is not None}
    return min(scored, key=lambda k: (scored[k], k)) if scored else None


def joint(scores: dict[str, dict[int, float | None]]) -> tuple[dict[int, float], int]:
    configs = sorted({k for s in scores.values() for k in s})
    ranks = {k: 0.0 for k in configs}
    for s in scores.values():
        r = pd.Series({k: (math.inf if s.get(k) is None else s[k]) for k in configs}).rank(method="average")
        for k in configs:
            ranks[k] += float(r[k]) / len(scores)
    return ranks, min(configs, key=lambda k: (ranks[k], k))


def _flat(d: dict, prefix: str = "") -> dict:
    out = {}
    for k, v in d.items():
        if isinstance(v, dict):
            out.update(_flat(v, f"{prefix}{k}."))
        else:
            out[f"{prefix}{k}"] = v
    return out


def hand_chosen(claim, profile: str, labels) -> dict[str, dict[str, object]]:
    base = claim.protocol(profile)
    settings = {}
    for e in claim.models:
        if e.label in labels:
            p = _flat(e.protocol(base, profile).to_dict())
            p = {k: v for k, v in p.items() if k not in SEARCHED}
            p["input_scale"] = e.spec_fields(profile).get("input_scale")
            settings[e.label] = p
    keys = sorted({k for p in settings.values() for k in p})
    differ = {}
    for k in keys:
        values = {label: p.get(k) for label, p in settings.items()}
        if len({repr(v) for v in values.values()}) > 1:
            differ[k] = values
    return differ
