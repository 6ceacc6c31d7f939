"""The statistics the verdict rules read: a metric over seeds, and the intervals of a comparison.

- ``Stat``: a metric's values over seeds (+inf = a diverged rollout, never NaN).
- ``ratio_interval(a, b)``: mean(a) / mean(b) with the exact range of a_i / b_j over every pair of seeds
  (the seeds of two models are independent runs, so no pairing is privileged; with 3 seeds a model the
  range holds 9 ratios). An ordering read on this interval holds for every seed of both models.
- ``hodges_lehmann(x, y)``: the shift of log10(x) against log10(y) (the median of every pairwise
  difference; +inf for a run that never got there, two such runs tie) with its exact distribution-free
  interval from the Mann-Whitney U distribution (Lehmann 1975, ch. 2): the k-th smallest and largest
  differences, k the largest count with P(U < k) <= alpha / 2.
- ``seeds_needed(alpha, k, margin)``: the seed count a pooled claim needs (its power rule, below).
- ``wilson(k, n)``: the 95 % Wilson interval of a share.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache


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


def _ratio(x: float, y: float) -> float:
    """x / y for non-negative errors: two diverged (or two zero) values tie at 1, x / 0 is +inf."""
    if (math.isinf(x) and math.isinf(y)) or (x == 0 and y == 0):
        return 1.0
    if y == 0 or math.isinf(x):
        return math.inf
    return x / y


@dataclass(frozen=True)
class Interval:
    """A point estimate with its interval, and how the interval was made."""

    what: str
    point: float
    lo: float
    hi: float
    method: str

    def to_dict(self) -> dict:
        return {"what": self.what, "point": self.point, "lo": self.lo, "hi": self.hi, "method": self.method}

    def __str__(self) -> str:
        return f"{self.what} {self.point:.3g} [{self.lo:.3g}, {self.hi:.3g}] ({self.method})"


def ratio_interval(a: Stat, b: Stat, what: str) -> Interval:
    """mean(a) / mean(b) with the range of a_i / b_j over every pair of seeds."""
    pairs = [_ratio(x, y) for x in a.values for y in b.values]
    return Interval(what, _ratio(a.mean, b.mean), min(pairs), max(pairs), f"range over all {len(pairs)} seed pairs")


@cache
def _u_counts(m: int, n: int) -> tuple:
    """The number of orderings of m x's and n y's giving each U = #(x_i > y_j), u = 0..mn (no ties)."""
    if m == 0 or n == 0:
        return (1,)
    a, b = _u_counts(m - 1, n), _u_counts(m, n - 1)
    out = [0] * (m * n + 1)
    for u, c in enumerate(b):          # the largest value is a y: it adds nothing to U
        out[u] += c
    for u, c in enumerate(a):          # the largest value is an x: it exceeds all n y's
        out[u + n] += c
    return tuple(out)


def u_lower_tail(m: int, n: int, k: int) -> float:
    """P(U < k) under no difference, exactly."""
    c = _u_counts(m, n)
    return sum(c[:max(k, 0)]) / math.comb(m + n, m)


def hl_rank(m: int, n: int, alpha: float) -> int:
    """The largest k with P(U < k) <= alpha / 2 (0: no interval this narrow exists at these sizes)."""
    k = 0
    while k < m * n and u_lower_tail(m, n, k + 1) <= alpha / 2:
        k += 1
    return k


def _log10(x: float) -> float:
    return math.inf if math.isinf(x) else math.log10(max(x, 1e-300))


def hodges_lehmann(x, y, alpha: float, what: str) -> Interval:
    """The shift of log10(x) against log10(y) as a ratio 10^shift, with its two-sided 1 - alpha interval
    (values +inf count as never; two of them tie). Below 1: x tends to be smaller."""
    d = []
    for a in x:
        for b in y:
            la, lb = _log10(a), _log10(b)
            d.append(0.0 if math.isinf(la) and math.isinf(lb) else la - lb)
    d.sort()
    n = len(d)
    mid = (d[(n - 1) // 2] + d[n // 2]) / 2 if n else 0.0
    k = hl_rank(len(x), len(y), alpha)
    lo, hi = (d[k - 1], d[n - k]) if k >= 1 else (-math.inf, math.inf)

    def ratio(s):
        return math.inf if s == math.inf else 0.0 if s == -math.inf else 10.0 ** s
    return Interval(what, ratio(mid) if math.isfinite(mid) or n else 1.0, ratio(lo), ratio(hi),
                    f"Hodges-Lehmann, exact {100 * (1 - alpha):.3g} % interval" + ("" if k else ": too few seeds"))


def seeds_needed(alpha: float, k: int, margin: float = 10.0) -> int:
    """The power rule of the pooled claims: the smallest n seeds a model such that a complete separation
    of two models gives a two-sided exact p at least ``margin`` times below alpha / k (the Bonferroni level
    over k rivals), so that a clear difference can reach the level even with a few crossings."""
    n = 1
    while 2 / math.comb(2 * n, n) > alpha / k / margin:
        n += 1
    return n


def wilson(k: int, n: int, z: float = 1.96) -> tuple[float, float]:
    """The Wilson score interval (95 % at z = 1.96) of a share k/n."""
    if n == 0:
        return 0.0, 1.0
    p = k / n
    mid = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return max(0.0, mid - half), min(1.0, mid + half)
