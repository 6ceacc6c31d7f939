"""The verdict rules: one small vocabulary that every claim's rule is built from.

A rule is a function of ``v = {model label: {metric: Stat}}`` (one framework; every model in ``v`` has
passed its competence bar, see ``bars.py``) returning ``(verdict, reason)``. A ``Stat`` holds a
metric's values over seeds; ``values`` may hold +inf (a diverged rollout), never NaN.

Orderings ("a beats b") need more than a smaller mean: the seed ranges must not overlap
(``separated``), else the verdict is "inconclusive" (noise decides). With one seed the range is the
value itself, so the per-seed verdicts that ``replication.claims.verdicts`` takes read as plain comparisons.

- ``better_by(a, b, factor, metric)``: reproduced if mean(a) x factor < mean(b) and the ranges are
  separated; partly if a < b separated but not by the factor; not reproduced if b < a separated.
- ``similar(a, b, within, partly_within, metric)``: the ratio of means inside [1/within, within].
- ``lowest(ours, others, metric)``: ours below every other, separated (partly: below some).
- ``fails(bad, goods, factor, metric)``: bad above factor x every good, separated (partly: above all).
- ``bound(metric, upper=, lower=, models=)``: every seed of the models inside the bounds (exact results,
  tolerances, a property such as a positive definite mass matrix; no ordering).
- ``faster(ours, others, pace)``: samples to reach a level per seed (+inf if never), ours faster than every
  other by a one-sided Mann-Whitney test with Bonferroni (partly: than some), with the share that got there
  and its Wilson interval beside; the seeds are a sample, not separate replications (``pooled``).
- ``never(bad, pace)``: no seed of bad got there (every pace +inf): a model that cannot learn the task, such
  as a plain-ReLU LNN whose velocity Hessian vanishes; paired with ``faster`` (the others must get there).
- ``all_parts(*rules)``: a conjunction (every part reproduced).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

VERDICTS = ("reproduced", "partly", "not reproduced", "inconclusive", "not run")


@dataclass(frozen=True)
class Stat:
    """A metric's values over seeds (+inf = diverged). ``mean`` is +inf if any value is."""

    values: tuple

    @classmethod
    def of(cls, values) -> Stat:
        vs = tuple(float(x) for x in values if x is not None and not math.isnan(float(x)))
        if not vs:
            raise ValueError("Stat.of: no finite or infinite value (all missing or NaN)")
        return cls(vs)

    @property
    def n(self) -> int:
        return len(self.values)

    @property
    def mean(self) -> float:
        return math.inf if any(math.isinf(x) for x in self.values) else sum(self.values) / self.n

    @property
    def std(self) -> float:
        if self.n < 2:
            return 0.0
        if any(math.isinf(x) for x in self.values):
            return math.inf if not all(math.isinf(x) for x in self.values) else 0.0
        m = self.mean
        return math.sqrt(sum((x - m) ** 2 for x in self.values) / (self.n - 1))

    @property
    def lo(self) -> float:
        return min(self.values)

    @property
    def hi(self) -> float:
        return max(self.values)

    def __format__(self, spec) -> str:
        return f"{self.mean:.3g}" if self.n == 1 else f"{self.mean:.3g} [{self.lo:.3g}, {self.hi:.3g}]"


def separated(a: Stat, b: Stat) -> bool:
    """a lies below b beyond the seed spread: every seed of a below every seed of b."""
    return a.hi < b.lo


def _get(v, label, metric):
    return (v.get(label) or {}).get(metric)


def _missing(v, labels, metric):
    gone = [x for x in labels if _get(v, x, metric) is None]
    return ("not run", "missing " + ", ".join(gone)) if gone else None


def better_by(a: str, b: str, factor: float, metric: str):
    def rule(v):
        if (m := _missing(v, (a, b), metric)) is not None:
            return m
        x, y = _get(v, a, metric), _get(v, b, metric)
        text = f"{a} {x} vs {b} {y}"
        if x.mean < y.mean and not separated(x, y):
            return "inconclusive", f"{text}: the seed ranges overlap"
        if separated(x, y) and x.mean * factor < y.mean:
            return "reproduced", f"{text}: lower by more than {factor:g}x, seed ranges apart"
        if separated(x, y):
            return "partly", f"{text}: lower, but not by {factor:g}x"
        if separated(y, x):
            return "not reproduced", f"{text}: {b} is lower"
        return "inconclusive", f"{text}: the seed ranges overlap"
    return rule


def similar(a: str, b: str, within: float, partly_within: float, metric: str):
    def rule(v):
        if (m := _missing(v, (a, b), metric)) is not None:
            return m
        x, y = _get(v, a, metric), _get(v, b, metric)
        if not (math.isfinite(x.mean) and math.isfinite(y.mean)) or y.mean <= 0:
            return "not reproduced", f"{a} {x} vs {b} {y}: not finite and positive"
        r = x.mean / y.mean
        text = f"{a}/{b} = {x.mean:.3g}/{y.mean:.3g} = {r:.2f}"
        if 1 / within <= r <= within:
            return "reproduced", f"{text}, within [1/{within:g}, {within:g}]"
        if 1 / partly_within <= r <= partly_within:
            return "partly", f"{text}, within {partly_within:g}x but not {within:g}x"
        return "not reproduced", f"{text}, outside {partly_within:g}x"
    return rule


def lowest(ours: str, others: tuple, metric: str):
    def rule(v):
        if (m := _missing(v, (ours,), metric)) is not None:
            return m
        rest = {k: _get(v, k, metric) for k in others if _get(v, k, metric) is not None}
        if not rest:
            return "not run", "nothing to compare with"
        x = _get(v, ours, metric)
        text = f"{ours} {x}; " + ", ".join(f"{k} {s}" for k, s in rest.items())
        below = [k for k, s in rest.items() if separated(x, s)]
        above = [k for k, s in rest.items() if separated(s, x)]
        if len(below) == len(rest):
            return "reproduced", f"{text}: lowest, seed ranges apart"
        if above and not below:
            return "not reproduced", f"{text}: {', '.join(above)} lower"
        if below:
            return "partly", f"{text}: below {', '.join(below)} only"
        return "inconclusive", f"{text}: the seed ranges overlap"
    return rule


def fails(bad: str, goods: tuple, factor: float, metric: str):
    def rule(v):
        if (m := _missing(v, (bad, *goods), metric)) is not None:
            return m
        x = _get(v, bad, metric)
        gs = {k: _get(v, k, metric) for k in goods}
        text = f"{bad} {x}; " + ", ".join(f"{k} {s}" for k, s in gs.items())
        if all(separated(s, x) and s.mean * factor < x.mean for s in gs.values()):
            return "reproduced", f"{text}: {bad} above {factor:g}x every other, seed ranges apart"
        if all(separated(s, x) for s in gs.values()):
            return "partly", f"{text}: {bad} the worst, but not by {factor:g}x"
        if any(separated(x, s) for s in gs.values()):
            return "not reproduced", f"{text}: {bad} is not the worst"
        return "inconclusive", f"{text}: the seed ranges overlap"
    return rule


def bound(metric: str, *, upper: float | None = None, lower: float | None = None, models: tuple | None = None):
    def rule(v):
        vals = {k: s[metric] for k, s in v.items() if metric in s and (models is None or k in models)}
        if not vals:
            return "not run", f"no {metric}"
        hi, lo = max(s.hi for s in vals.values()), min(s.lo for s in vals.values())
        over = upper is not None and not hi <= upper
        under = lower is not None and not lo > lower
        text = f"{metric} in [{lo:.3g}, {hi:.3g}] over {', '.join(vals)}"
        if over or under:
            return "not reproduced", text + (f", above {upper:g}" if over else "") + (f", not above {lower:g}" if under else "")
        return "reproduced", text + (f", <= {upper:g}" if upper is not None else "") + (f", > {lower:g}" if lower is not None else "")
    return rule


def wilson(k: int, n: int, z: float = 1.96) -> tuple[float, float]:
    """The Wilson score interval (95 % at z = 1.96) of a share k/n."""
    if n == 0:
        return 0.0, 1.0
    p = k / n
    mid = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return max(0.0, mid - half), min(1.0, mid + half)


def _share(k: int, n: int) -> str:
    """k/n with its 95 % Wilson interval."""
    lo, hi = wilson(k, n)
    return f"{k}/{n} [{lo:.2f}, {hi:.2f}]"


def _one_sided_p(x, y) -> float:
    """Mann-Whitney U p-value that x tends to be smaller than y (inf = never, ties allowed); 1 when every
    value is the same."""
    if len(set(x) | set(y)) == 1:
        return 1.0
    from scipy.stats import mannwhitneyu

    big = 1e300   # inf ranks as the largest value, tied with the other infs
    return float(mannwhitneyu([min(a, big) for a in x], [min(b, big) for b in y], alternative="less").pvalue)


def faster(ours: str, others: tuple, pace: str = "samples_to_leave", alpha: float = 0.05):
    """A statistical ordering of training speed over seeds: ``pace`` per seed (samples to reach a level,
    +inf if never: a censored time), compared with a one-sided Mann-Whitney U test against each other
    model at ``alpha`` / (number of others) (Bonferroni). Reproduced if ours is faster than every other,
    partly than some; not reproduced if another is faster than ours; inconclusive if no difference is
    significant, or when no seed of any model got there (a study of which trains faster needs one that
    trained). The share of seeds whose pace is finite (they got there within the budget), with its 95 %
    Wilson interval, and the median pace are reported beside. The seeds are a sample, not separate replications (``pooled``)."""
    def rule(v):
        if (m := _missing(v, (ours,), pace)) is not None:
            return m
        rest = [k for k in others if _get(v, k, pace) is not None]
        if not rest:
            return "not run", "nothing to compare with"
        parts = []
        for k in (ours, *rest):
            vals = _get(v, k, pace).values
            hits = sorted(x for x in vals if math.isfinite(x))
            med = f"median {hits[len(hits) // 2]:.3g}" if hits else "never"
            parts.append(f"{k} {_share(len(hits), len(vals))}, {med}")
        text = (f"{pace} (seeds whose logged training loss got there within the budget, 95 % Wilson "
                "interval, median): " + "; ".join(parts))
        if not any(math.isfinite(x) for k in (ours, *rest) for x in _get(v, k, pace).values):
            return "inconclusive", text + ": no seed of any model got there"
        level = alpha / len(rest)
        mine = _get(v, ours, pace).values
        p_fast = {k: _one_sided_p(mine, _get(v, k, pace).values) for k in rest}
        p_slow = {k: _one_sided_p(_get(v, k, pace).values, mine) for k in rest}
        text += "; one-sided Mann-Whitney p (ours faster): " + ", ".join(f"{k} {p:.2g}" for k, p in p_fast.items())
        quicker = [k for k in rest if p_fast[k] < level]
        slower = [k for k in rest if p_slow[k] < level]
        if slower:
            return "not reproduced", f"{text}: {', '.join(slower)} faster (p < {level:.2g})"
        if len(quicker) == len(rest):
            return "reproduced", f"{text}: {ours} faster than every other (p < {level:.2g})"
        if quicker:
            return "partly", f"{text}: faster than {', '.join(quicker)} only"
        n = min(len(_get(v, k, pace).values) for k in (ours, *rest))
        return "inconclusive", (f"{text}: no difference significant at {level:.2g} with {n} or more seeds a model "
                                "(a sample too small to tell, or no difference)")
    return rule


def never(bad: str, pace: str = "samples_to_leave"):
    """``bad`` cannot learn: no seed of it got there within the budget (pace +inf in every seed). Reproduced
    if none did, not reproduced if any did (one seed that learned shows it can). Alone it would pass a null
    model, which never gets there either: pair it with ``faster(ours, (..., bad))`` in ``all_parts``, which
    reproduces only if ours got there significantly sooner than bad (so some seed of ours got there)."""
    def rule(v):
        if (m := _missing(v, (bad,), pace)) is not None:
            return m
        vals = _get(v, bad, pace).values
        k = sum(math.isfinite(x) for x in vals)
        text = f"{bad} got there in {_share(k, len(vals))} seeds"
        if k:
            return "not reproduced", f"{text}: it can learn"
        return "reproduced", f"{text}: never, within the budget"
    return rule


def all_parts(*rules):
    """Every part reproduced; any part not run or inconclusive decides first, then any success is partly."""
    def rule(v):
        out = [r(v) for r in rules]
        verdicts = [o[0] for o in out]
        reason = "; ".join(o[1] for o in out)
        for first in ("not run", "inconclusive"):
            if first in verdicts:
                return first, reason
        if all(x == "reproduced" for x in verdicts):
            return "reproduced", reason
        if any(x in ("reproduced", "partly") for x in verdicts):
            return "partly", reason
        return "not reproduced", reason
    return rule
