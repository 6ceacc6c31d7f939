"""What a claim's comparison does not control, from the result files: for its claim page and its scorecard flag.

``parameters(unit)``: the parameter count of the unit's model, from the model spec its result.json records
(``lagbench.models.param_shapes``: NumPy only; a user's model, or a spec this code cannot read, by its
checkpoint's arrays; None without either). ``sizes_table(res, claim)``: per compared model (the models the
claim's parts read, else its models) its parameters, hidden widths, training samples and training time
(medians over seeds). ``sizes_differ(res, claim)``: "lnn 33,793 vs baseline 8,706 parameters" where the
largest and smallest models one part compares differ by more than ``SIZE_RATIO`` (each such part's pair, "; "
between them; models of different parts, e.g. one system's against another's, are never set against each
other), else "". ``failing_seeds(res, claim)``:
every seed of a model below its competence bar, with its value (per framework). ``not_tested(res, claim)``: what
the claim's rule leaves out, in words (`WORDS_UNTESTED`: what a claim says that no part tests).
"""
from __future__ import annotations

import math

import numpy as np
import pandas as pd

from lagbench.reports.fmt import count, num
from lagbench.reports.load import Results, Unit

SIZE_RATIO = 1.5   # compared models whose parameter counts differ by more than this are a confound to state


def parameters(u: Unit) -> float | None:
    spec = u.result.get("model_spec") or {}
    if spec.get("kind") != "user":
        try:
            from lagbench.models.params import param_shapes
            from lagbench.models.spec import ModelSpec

            return float(sum(int(np.prod(s)) for s in param_shapes(ModelSpec.from_dict(spec)).values()))
        except (TypeError, ValueError, KeyError):
            pass
    path = u.path / "checkpoint.npz"
    try:
        with np.load(path, allow_pickle=False) as npz:
            return float(sum(npz[k].size for k in npz.files))
    except (OSError, ValueError):
        return None


def compared(res: Results, claim: dict) -> list[str]:
    """The models the claim's parts compare (in the parts' order), else its models, that have usable units."""
    v = res.verdicts.get(claim["id"]) or {}
    read = [m for p in v.get("parts") or [] if not p.get("check") for m in p.get("reads") or []]
    have = {u.model for u in res.usable(claim["id"])}
    return [m for m in dict.fromkeys(read or claim.get("models") or []) if m in have]


def _median(values) -> float | None:
    vals = [float(x) for x in values if isinstance(x, int | float) and not isinstance(x, bool) and math.isfinite(x)]
    return float(np.median(vals)) if vals else None


def model_sizes(res: Results, claim: dict) -> dict[str, dict]:
    """{model: {params, width, samples, seconds}} of the compared models (medians over their units)."""
    out = {}
    for m in compared(res, claim):
        us = [u for u in res.usable(claim["id"]) if u.model == m]
        widths = {"x".join(map(str, (u.result.get("model_spec") or {}).get("hidden") or [])) for u in us}
        out[m] = {"params": _median([parameters(u) for u in us[:1]]), "width": ", ".join(sorted(w for w in widths if w)),
                  "samples": _median([u.result.get("train_samples") for u in us]),
                  "seconds": _median([u.result.get("train_time_s") for u in us])}
    return out


def compared_groups(res: Results, claim: dict, models) -> list[list[str]]:
    """The sets of models each counted part compares (of `models`, at least two, each set once), else
    `models` as one set where no part names two of them."""
    v = res.verdicts.get(claim["id"]) or {}
    groups = []
    for p in v.get("parts") or []:
        g = [m for m in dict.fromkeys(p.get("reads") or []) if m in models]
        if not p.get("check") and len(g) > 1 and g not in groups:
            groups.append(g)
    return groups or ([list(models)] if len(models) > 1 else [])


def _differ(res: Results, claim: dict, values: dict[str, float]) -> list[tuple[str, str]]:
    """(larger, smaller) per compared set whose values differ by more than `SIZE_RATIO`, each pair once."""
    out = []
    for g in compared_groups(res, claim, [m for m, x in values.items() if x]):
        big, small = max(g, key=values.get), min(g, key=values.get)
        if values[big] > SIZE_RATIO * values[small] and (big, small) not in out:
            out.append((big, small))
    return out


def sizes_differ(res: Results, claim: dict, sizes: dict | None = None) -> str:
    sizes = model_sizes(res, claim) if sizes is None else sizes
    known = {m: s["params"] for m, s in sizes.items() if s["params"]}
    return "; ".join(f"{big} {count(known[big])} vs {small} {count(known[small])} parameters"
                     for big, small in _differ(res, claim, known))


def sizes_table(res: Results, claim: dict, sizes: dict | None = None) -> pd.DataFrame | None:
    sizes = model_sizes(res, claim) if sizes is None else sizes
    rows = [{"model": m, "parameters": count(s["params"]) if s["params"] else "not recorded",
             "hidden widths": s["width"] or "not recorded",
             "training samples": count(s["samples"]) if s["samples"] is not None else "not recorded",
             "training time (s)": num(s["seconds"], 2) if s["seconds"] is not None else "not recorded"}
            for m, s in sizes.items()]
    return pd.DataFrame(rows) if rows else None


def failing_seeds(res: Results, claim: dict) -> pd.DataFrame | None:
    """Every seed of each model below its competence bar (all its seeds, the passing ones too)."""
    comp = (res.verdicts.get(claim["id"]) or {}).get("competence") or {}
    rows = []
    for fw, per in comp.items():
        for model, r in (per or {}).items():
            if r.get("passed"):
                continue
            for s in r.get("per_seed") or []:
                rows.append({"model": model, "framework": fw, "seed": str(s.get("seed")),
                             "bar": "passed" if s.get("passed") else "FAILED",
                             "value": num(s.get("value")) if s.get("value") is not None else "not recorded",
                             "reading": str(s.get("why") or "")})
    return pd.DataFrame(rows) if rows else None


# what a claim's words say that none of its parts tests (the parts as registered in `replication/claims/`)
WORDS_UNTESTED = {
    "delan_arm": "\"most on unseen trajectories and few samples\": each part asks only that DeLaN is better (by 3x on "
                 "unseen trajectories, at all at each pool size); no part compares the size of its advantage "
                 "across them",
}


def not_tested(res: Results, claim: dict, sizes: dict | None = None) -> str:
    """What the claim's rule does not test, from the data: model size, training budget and time, the
    metrics it does not read, the seed count it rests on, and the words of the claim no part tests
    (`WORDS_UNTESTED`)."""
    sizes = model_sizes(res, claim) if sizes is None else sizes
    metric = claim.get("metric") or "its metric"
    out = [f"the rule reads {metric} on this split's held-out draw only (other metrics and other data are not tested)"]
    if claim.get("id") in WORDS_UNTESTED:
        out.append(f"the claim's words {WORDS_UNTESTED[claim['id']]}")
    diff = sizes_differ(res, claim, sizes)
    if diff:
        out.append(f"it does not control model size ({diff})")
    for key, what in (("samples", "training samples"), ("seconds", "training time (s)")):
        vals = {m: s[key] for m, s in sizes.items() if s[key]}
        pairs = _differ(res, claim, vals)
        if pairs:
            out.append(f"it does not control {what} (" + "; ".join(f"{big} {num(vals[big], 2)} vs {small} "
                                                                   f"{num(vals[small], 2)}" for big, small in pairs) + ")")
    seeds = (res.verdicts.get(claim["id"]) or {}).get("seeds") or []
    if seeds:
        out.append(f"it rests on {len(seeds)} seed{'s' * (len(seeds) != 1)} per model")
    return "; ".join(out) + "."
