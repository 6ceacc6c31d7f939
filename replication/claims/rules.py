"""The verdict rules: one small vocabulary that every part of every claim is built from.

A rule is a function of ``v = {model label: {metric: Stat}}`` (one framework; every model it reads has
passed its competence bar, see ``bars.py``) returning an ``Outcome``: a part's verdict ("reproduced",
"not reproduced", "inconclusive" or "not run"; never "partly", which only a claim of several parts can
be), its reason, the interval the decision read, the threshold(s) it was read against with the distance
of the interval's nearer end from them (``distance``, a factor >= 1), and the verdict at half and at twice
the suite's own threshold (``sensitivity``). Orderings and similarities read the confidence interval of a
ratio over seeds (``stats.ratio_interval``, at ``stats.LEVEL``: it widens as seeds fall, and one seed a
model decides nothing), and an interval across the threshold is "inconclusive" (noise decides). "Every
seed pair" below means: the whole interval.

- ``better_by(a, b, factor, metric)``: reproduced if a / b < 1 / factor over the interval; not
  reproduced if a / b >= 1 / factor over it (b lower, or a lower by less than the factor).
- ``sooner(a, b, metric)``: ``better_by(a, b, 1, metric)`` on times to reach a level per seed (+inf if never),
  but "inconclusive" where no seed of either got there (two that never arrive say nothing of which is sooner).
- ``similar(a, b, within, metric)``: a / b inside [1 / within, within] over the interval (not reproduced:
  wholly outside, and the reason says which model is the lower); its sensitivity reads sqrt(within) and
  within^2 (half and twice the tolerance in log).
- ``matched_better_by(a, b, factor, metric, level, within)``: ``better_by`` on two models read at matched
  accuracy: decided only if their ``level`` metric (the held-out error where each was read) is within a
  factor ``within`` of each other over the interval, else "inconclusive" (the accuracies differ).
- ``fails(bad, goods, factor, metric)``: bad / good > factor over the interval, for every good.
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

from lagbench.replication.claims.stats import (
    Interval,
    Stat,
    hodges_lehmann,
    ratio_interval,
    separated,
    wilson,
)

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
    thresholds: tuple = ()   # the value(s) the interval was read against

    def __post_init__(self):
        if self.verdict not in PART_VERDICTS:
            raise ValueError(f"a part's verdict is one of {PART_VERDICTS}, not {self.verdict!r}")

    @property
    def distance(self) -> float | None:
        """The factor (>= 1) between the interval's nearer end and the nearest threshold: how far the
        decision is from its edge (inf: an unbounded interval; None: no threshold read)."""
        iv = self.interval
        if iv is None or not self.thresholds:
            return None
        ends = [x for x in (iv.lo, iv.hi) if 0 < x < math.inf]
        if not ends:
            return math.inf
        return min(max(e / t, t / e) for e in ends for t in self.thresholds if t > 0)


def _get(v, label, metric):
    return (v.get(label) or {}).get(metric)


def _missing(v, labels, metric):
    gone = [x for x in labels if _get(v, x, metric) is None]
    return Outcome("not run", "missing " + ", ".join(gone)) if gone else None


def _below(iv: Interval, t: float) -> str:
    """Where the interval lies against threshold t: wholly below, wholly at or above, or across."""
    return "reproduced" if iv.hi < t else "not reproduced" if iv.lo >= t else "inconclusive"


def _ratio_rule(a: str, b: str, metric: str, at, t: float, label: str, why: dict, what: str = "",
                names: tuple = (), edges=lambda t: (t,), varied=lambda t: (t / 2, t * 2)):
    """A rule on the confidence interval of a / b over seeds (``what`` names it; ``names`` the two sides in
    the reason): ``at(interval, t)`` decides, and is also read at ``varied(t)`` (the sensitivity: half and
    twice by default); ``why`` words each verdict (a callable of the interval, or a string); ``edges(t)``
    are the thresholds the interval is read against."""
    shown = names or (a, b)

    def rule(v):
        if (m := _missing(v, (a, b), metric)) is not None:
            return m
        x, y = _get(v, a, metric), _get(v, b, metric)
        iv = ratio_interval(x, y, what or f"{a}/{b}")
        verdict = at(iv, t)
        text = why[verdict](iv) if callable(why[verdict]) else why[verdict]
        return Outcome(verdict, f"{shown[0]} {x} vs {shown[1]} {y}; {iv}: {text}", iv,
                       {f"{label} {w:g}": at(iv, w) for w in varied(t)}, edges(t))
    return rule


def better_by(a: str, b: str, factor: float, metric: str):
    return _ratio_rule(a, b, metric, lambda iv, f: _below(iv, 1.0 / f), factor, "factor",
                       {"reproduced": f"below 1/{factor:g} over the interval",
                        "not reproduced": f"not below 1/{factor:g} anywhere in the interval",
                        "inconclusive": f"across 1/{factor:g}: the seeds cannot tell"}, edges=lambda f: (1.0 / f,))


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
    def outside(iv):
        lower = a if iv.hi < 1 else b
        return (f"outside [1/{within:g}, {within:g}] over the interval: {lower} is lower by more than "
                f"{within:g}x, a difference the claim of similarity does not make")
    return _ratio_rule(a, b, metric, at, within, "within",
                       {"reproduced": f"inside [1/{within:g}, {within:g}] over the interval",
                        "not reproduced": outside,
                        "inconclusive": f"across the edge of [1/{within:g}, {within:g}]"},
                       edges=lambda w: (1.0 / w, w), varied=lambda w: (w ** 0.5, w ** 2))


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
                       out.interval, out.sensitivity, out.thresholds)
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
        why = {"reproduced": f"above {factor:g} over every interval",
               "not reproduced": f"at most {factor:g} over the interval of some model",
               "inconclusive": f"across {factor:g}"}[verdict]
        return Outcome(verdict, f"{text}: {why}", min(ivs, key=lambda iv: iv.lo),
                       {f"factor {factor / 2:g}": at(ivs, factor / 2), f"factor {factor * 2:g}": at(ivs, factor * 2)},
                       (factor,))
    return rule


def bound(metric: str, *, upper: float | None = None, lower: float | None = None, models: tuple | None = None):
    def rule(v):
        vals = {k: s[metric] for k, s in v.items() if metric in s and (models is None or k in models)}
        if not vals or (models is not None and set(models) - set(vals)):
            return Outcome("not run", f"no {metric}" + (f" of {', '.join(models)}" if models else ""))
        hi, lo = max(s.hi for s in vals.values()), min(s.lo for s in vals.values())
        over = upper is not None and not hi <= upper
        under = lower is not None and not lo > lower
        iv = Interval(metric, sum(s.mean for s in vals.values()) / len(vals), lo, hi,
                      "range over seeds (every seed inside the bounds)", None,
                      tuple(s.n + s.dropped for s in vals.values()))
        if any(s.dropped for s in vals.values()):
            return Outcome("inconclusive", f"{metric}: a seed's value is NaN", iv)
        text = f"{metric} in [{lo:.3g}, {hi:.3g}] over {', '.join(vals)}"
        if over or under:
            return Outcome("not reproduced", text + (f", above {upper:g}" if over else "")
                           + (f", not above {lower:g}" if under else ""), iv)
        return Outcome("reproduced", text + (f", <= {upper:g}" if upper is not None else "")
                       + (f", > {lower:g}" if lower is not None else ""), iv)
    return rule


def below_null(metric: str, fraction: float, model: str):
    """``model``'s metric at most ``fraction`` x the null predictor's (``null_<metric>``, recorded beside it),
    over the interval: a statement that the null predictor itself fails."""
    null = f"{model} null"
    rule = _ratio_rule(model, null, metric, _below, fraction, "fraction",
                       {"reproduced": f"below {fraction:g}", "not reproduced": f"not below {fraction:g}",
                        "inconclusive": f"across {fraction:g}"}, what=f"{model} {metric}/null",
                       names=(f"{model} {metric}", "the null's"), edges=lambda f: (f,))

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
                       {f"alpha {alpha / 2:g}": at(x, y, alpha / 2)[1], f"alpha {alpha * 2:g}": at(x, y, alpha * 2)[1]},
                       (1.0,))
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
        iv = Interval(f"{bad} share that got there", k / len(vals), lo, hi, "Wilson 95 %", 0.95, (len(vals),))
        if k:
            return Outcome("not reproduced", f"{bad} got there in {_share(vals)}: it can learn", iv)
        return Outcome("reproduced", f"{bad} got there in {_share(vals)}: never, within the budget", iv)
    return rule
