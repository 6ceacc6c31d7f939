"""What a claim's comparison does not control, from the result files: for its claim page and its scorecard flag.

``parameters(unit)``: the parameter count of the unit's model, from the model spec its result.json records
(``lagbench.models.param_shapes``: NumPy only; a user's model, or a spec this code cannot read, by its
checkpoint's arrays; None without either). ``sizes_table(res, claim)``: per compared model (the models the
claim's parts read, else its models) its parameters, hidden widths, training samples and training time
(medians over seeds). ``sizes_differ(res, claim)``: "lnn 3.4e+04 vs baseline 8.7e+03 parameters" where the
largest and smallest compared models differ by more than ``SIZE_RATIO``, else "". ``failing_seeds(res, claim)``:
every seed of a model below its competence bar, with its value (per framework). ``not_tested(res, claim)``: what
the claim's rule leaves out, in words.
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


def sizes_differ(res: Results, claim: dict, sizes: dict | None = None) -> str:
    sizes = model_sizes(res, claim) if sizes is None else sizes
    known = {m: s["params"] for m, s in sizes.items() if s["params"]}
    if len(known) < 2:
        return ""
    big, small = max(known, key=known.get), min(known, key=known.get)
    if known[big] <= SIZE_RATIO * known[small]:
        return ""
    return f"{big} {count(known[big])} vs {small} {count(known[small])} parameters"


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


def not_tested(res: Results, claim: dict, sizes: dict | None = None) -> str:
    """What the claim's rule does not test, from the data: model size, training budget and time, the
    metrics it does not read, and the seed count it rests on."""
    sizes = model_sizes(res, claim) if sizes is None else sizes
    metric = claim.get("metric") or "its metric"
    out = [f"the rule reads {metric} on this split's held-out draw only (other metrics and other data are not tested)"]
    diff = sizes_differ(res, claim, sizes)
    if diff:
        out.append(f"it does not control model size ({diff})")
    for key, what in (("samples", "training samples"), ("seconds", "training time")):
        vals = {m: s[key] for m, s in sizes.items() if s[key]}
        if len(vals) > 1 and max(vals.values()) > SIZE_RATIO * min(vals.values()):
            out.append(f"it does not control {what} (" + ", ".join(f"{m} {num(x, 2)}" for m, x in vals.items()) + ")")
    seeds = (res.verdicts.get(claim["id"]) or {}).get("seeds") or []
    if seeds:
        out.append(f"it rests on {len(seeds)} seed{'s' * (len(seeds) != 1)} per model")
    return "; ".join(out) + "."
