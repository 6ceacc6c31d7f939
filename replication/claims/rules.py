"""The verdict rules: one small vocabulary that every part of every claim is built from.

A rule is a function of ``v = {model label: {metric: Stat}}`` (one framework; every model it reads has
passed its competence bar, see ``bars.py``) returning an ``Outcome``: a part's verdict ("reproduced",
"not reproduced", "inconclusive" or "not run"; never "partly", which only a claim of several parts can
be), its reason, the interval the decision read, and the verdict at half and at twice the suite's own
threshold (``sensitivity``). Orderings read the interval over seeds (``stats.ratio_interval``: every
pair of seeds), so a verdict holds for every seed of both models, and an interval across the threshold
is "inconclusive" (noise decides).

- ``better_by(a, b, factor, metric)``: reproduced if a / b < 1 / factor over every seed pair; not
  reproduced if a / b >= 1 / factor over every pair (b lower, or a lower by less than the factor).
- ``sooner(a, b, metric)``: ``better_by(a, b, 1, metric)`` on times to reach a level per seed (+inf if never),
  but "inconclusive" where no seed of either got there (two that never arrive say nothing of which is sooner).
- ``similar(a, b, within, metric)``: a / b inside [1 / within, within] over every pair (not reproduced:
  wholly outside).
- ``matched_better_by(a, b, factor, metric, level, within)``: ``better_by`` on two models read at matched
  accuracy: decided only if their ``level`` metric (the held-out error where each was read) is within a
  factor ``within`` of each other for every seed pair, else "inconclusive" (the accuracies differ).
- ``fails(bad, goods, factor, metric)``: bad / good > factor over every pair, for every good.
- ``below_null(metric, fraction, model)``: the model's metric at most fraction x the null predictor's.
- ``bound(metric, upper=, lower=, models=)``: every seed of the models inside the bounds (exact results,
  tolerances; no ordering, no threshold of ours to vary).
- ``faster(ours, other, rivals, pace)``: samples to reach a level per seed (+inf if never), compared as a
  sample (``pooled`` claims): the Hodges-Lehmann ratio of ours to other with its exact two-sided interval
  at alpha / rivals (Bonferroni over the claim's rivals); reproduced if the interval lies below 1, not
  reproduced if above 1 (the other is faster: the direction is reported either way).
- ``never(bad, pace)``: no seed of bad got there (every pace +inf): a model that cannot learn. A null
  model passes it too, so its part needs a positive control (`parts.Part.controls`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from replication.claims.stats import Interval, Stat, hodges_lehmann, ratio_interval, separated, wilson

VERDICTS = ("reproduced", "partly", "not reproduced", "inconclusive", "not run")
PART_VERDICTS = ("reproduced", "not reproduced", "inconclusive", "not run")
__all__ = ["VERDICTS", "PART_VERDICTS", "Outcome", "Stat", "separated", "wilson", "better_by", "sooner", "similar",
           "matched_better_by", "fails", "bound", "below_null", "faster", "never"]


@dataclass(frozen=True)
class Outcome:
    verdict: str
    reason: str
    interval: Interval | None = None
    sensitivity: dict = field(default_factory=dict)   # e.g. {"factor 1.5": "reproduced", "factor 6": ...}

    def __post_init__(self):
        if self.verdict not in PART_VERDICTS:
            raise ValueError(f"a part's verdict is one of {PART_VERDICTS}, not {self.verdict!r}")


def _get(v, label, metric):
    return (v.get(label) or {}).get(metric)


def _missing(v, labels, metric):
    gone = [x for x in labels if _get(v, x, metric) is None]
    return Outcome("not run", "missing " + ", ".join(gone)) if gone else None


def _below(iv: Interval, t: float) -> str:
    """Where the interval lies against threshold t: wholly below, wholly at or above, or across."""
    return "reproduced" if iv.hi < t else "not reproduced" if iv.lo >= t else "inconclusive"


def _ratio_rule(a: str, b: str, metric: str, at, t: float, label: str, why: dict, what: str = "",
                names: tuple = ()):
    """A rule on the interval of a / b over seed pairs (``what`` names it; ``names`` the two sides in the
    reason): ``at(interval, t)`` decides, and is also read at t / 2 and 2 t (the sensitivity); ``why`` words
    each verdict."""
    shown = names or (a, b)

    def rule(v):
        if (m := _missing(v, (a, b), metric)) is not None:
            return m
        x, y = _get(v, a, metric), _get(v, b, metric)
        iv = ratio_interval(x, y, what or f"{a}/{b}")
        verdict = at(iv, t)
        return Outcome(verdict, f"{shown[0]} {x} vs {shown[1]} {y}; {iv}: {why[verdict]}", iv,
                       {f"{label} {t / 2:g}": at(iv, t / 2), f"{label} {t * 2:g}": at(iv, t * 2)})
    return rule


def better_by(a: str, b: str, factor: float, metric: str):
    return _ratio_rule(a, b, metric, lambda iv, f: _below(iv, 1.0 / f), factor, "factor",
                       {"reproduced": f"below 1/{factor:g} for every seed pair",
                        "not reproduced": f"not below 1/{factor:g} for any seed pair",
                        "inconclusive": f"across 1/{factor:g}: the seeds disagree"})


def sooner(a: str, b: str, metric: str):
    ordered = better_by(a, b, 1.0, metric)

    def rule(v):
        if (m := _missing(v, (a, b), metric)) is not None:
            return m
        if all(math.isinf(x) for s in (_get(v, a, metric), _get(v, b, metric)) for x in s.values):
            return Outcome("inconclusive", f"{metric}: no seed of {a} or {b} got there, so neither is sooner")
        return ordered(v)
    return rule


def similar(a: str, b: str, within: float, metric: str):
    def at(iv, w):
        if 1 / w <= iv.lo and iv.hi <= w:
            return "reproduced"
        if iv.hi < 1 / w or iv.lo > w:
            return "not reproduced"
        return "inconclusive"
    return _ratio_rule(a, b, metric, at, within, "within",
                       {"reproduced": f"inside [1/{within:g}, {within:g}] for every seed pair",
                        "not reproduced": f"outside [1/{within:g}, {within:g}] for every seed pair",
                        "inconclusive": f"across the edge of [1/{within:g}, {within:g}]"})


def matched_better_by(a: str, b: str, factor: float, metric: str, level: str, within: float):
    matched, ordered = similar(a, b, within, level), better_by(a, b, factor, metric)

    def rule(v):
        m = matched(v)
        if m.verdict == "not run":
            return m
        if m.verdict != "reproduced":
            return Outcome("inconclusive", f"accuracies not matched within {within:g} ({level}: {m.reason})",
                           m.interval)
        out = ordered(v)
        return Outcome(out.verdict, f"at matched {level} ({m.interval}), {metric} by {factor:g}: {out.reason}",
                       out.interval, out.sensitivity)
    return rule


def fails(bad: str, goods: tuple, factor: float, metric: str):
    """bad worse than factor x every good; the interval shown is that of the good closest to bad."""
    def at(ivs, f):
        if all(iv.lo > f for iv in ivs):
            return "reproduced"
        if any(iv.hi <= f for iv in ivs):
            return "not reproduced"
        return "inconclusive"

    def rule(v):
        if (m := _missing(v, (bad, *goods), metric)) is not None:
            return m
        x = _get(v, bad, metric)
        ivs = [ratio_interval(x, _get(v, g, metric), f"{bad}/{g}") for g in goods]
        verdict = at(ivs, factor)
        text = f"{bad} {x}; " + ", ".join(f"{g} {_get(v, g, metric)}" for g in goods)
        text += "; " + "; ".join(map(str, ivs))
        why = {"reproduced": f"above {factor:g} for every seed pair",
               "not reproduced": f"at most {factor:g} for every seed pair of some model",
               "inconclusive": f"across {factor:g}"}[verdict]
        return Outcome(verdict, f"{text}: {why}", min(ivs, key=lambda iv: iv.lo),
                       {f"factor {factor / 2:g}": at(ivs, factor / 2), f"factor {factor * 2:g}": at(ivs, factor * 2)})
    return rule


def bound(metric: str, *, upper: float | None = None, lower: float | None = None, models: tuple | None = None):
    def rule(v):
        vals = {k: s[metric] for k, s in v.items() if metric in s and (models is None or k in models)}
        if not vals or (models is not None and set(models) - set(vals)):
            return Outcome("not run", f"no {metric}" + (f" of {', '.join(models)}" if models else ""))
        hi, lo = max(s.hi for s in vals.values()), min(s.lo for s in vals.values())
        over = upper is not None and not hi <= upper
        under = lower is not None and not lo > lower
        iv = Interval(metric, sum(s.mean for s in vals.values()) / len(vals), lo, hi, "range over seeds")
        text = f"{metric} in [{lo:.3g}, {hi:.3g}] over {', '.join(vals)}"
        if over or under:
            return Outcome("not reproduced", text + (f", above {upper:g}" if over else "")
                           + (f", not above {lower:g}" if under else ""), iv)
        return Outcome("reproduced", text + (f", <= {upper:g}" if upper is not None else "")
                       + (f", > {lower:g}" if lower is not None else ""), iv)
    return rule


def below_null(metric: str, fraction: float, model: str):
    """``model``'s metric at most ``fraction`` x the null predictor's (``null_<metric>``, recorded beside it),
    for every pair of seeds: a statement that the null predictor itself fails."""
    null = f"{model} null"
    rule = _ratio_rule(model, null, metric, _below, fraction, "fraction",
                       {"reproduced": f"below {fraction:g}", "not reproduced": f"not below {fraction:g}",
                        "inconclusive": f"across {fraction:g}"}, what=f"{model} {metric}/null",
                       names=(f"{model} {metric}", "the null's"))

    def with_null(v):
        if (m := _missing(v, (model,), f"null_{metric}")) is not None:
            return m
        return rule({model: {metric: _get(v, model, metric)}, f"{model} null": {metric: _get(v, model, f"null_{metric}")}})
    return with_null


def _share(vals) -> str:
    """k/n seeds that got there, with the 95 % Wilson interval, and the median of those that did."""
    hits = sorted(x for x in vals if math.isfinite(x))
    lo, hi = wilson(len(hits), len(vals))
    med = f"median {hits[len(hits) // 2]:.3g}" if hits else "never"
    return f"{len(hits)}/{len(vals)} [{lo:.2f}, {hi:.2f}], {med}"


def faster(ours: str, other: str, rivals: int, pace: str = "samples_to_leave", alpha: float = 0.05):
    """``ours`` reaches the level in fewer samples than ``other``, read on the Hodges-Lehmann ratio's exact
    two-sided interval at ``alpha / rivals``."""
    def at(x, y, a):
        iv = hodges_lehmann(x, y, a / rivals, f"{ours}/{other} samples")
        return iv, _below(iv, 1.0) if iv.hi < 1.0 or iv.lo > 1.0 else "inconclusive"

    def rule(v):
        if (m := _missing(v, (ours, other), pace)) is not None:
            return m
        x, y = _get(v, ours, pace).values, _get(v, other, pace).values
        text = f"{pace} (seeds that got there, 95 % Wilson interval, median): {ours} {_share(x)}; {other} {_share(y)}"
        if not any(math.isfinite(s) for s in (*x, *y)):
            return Outcome("inconclusive", text + ": no seed of either got there")
        iv, verdict = at(x, y, alpha)
        why = {"reproduced": f"{ours} faster", "not reproduced": f"{other} faster",
               "inconclusive": "no difference at this level (too few seeds to tell, or none)"}[verdict]
        return Outcome(verdict, f"{text}; {iv}: {why}", iv,
                       {f"alpha {alpha / 2:g}": at(x, y, alpha / 2)[1], f"alpha {alpha * 2:g}": at(x, y, alpha * 2)[1]})
    return rule


def never(bad: str, pace: str = "samples_to_leave"):
    """No seed of ``bad`` got there within the budget. Reproduced if none did, not reproduced if any did
    (one seed that learned shows it can). A null model passes it: its part needs a positive control."""
    def rule(v):
        if (m := _missing(v, (bad,), pace)) is not None:
            return m
        vals = _get(v, bad, pace).values
        k = sum(math.isfinite(x) for x in vals)
        lo, hi = wilson(k, len(vals))
        iv = Interval(f"{bad} share that got there", k / len(vals), lo, hi, "Wilson 95 %")
        if k:
            return Outcome("not reproduced", f"{bad} got there in {_share(vals)}: it can learn", iv)
        return Outcome("reproduced", f"{bad} got there in {_share(vals)}: never, within the budget", iv)
    return rule
